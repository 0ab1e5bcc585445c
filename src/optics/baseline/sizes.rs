//! A pigment's grain-size distribution as the baselines see it: a handful
//! of diameters, each holding a share of the species' volume, that the
//! independent-scattering models treat as sub-species.
//!
//! The geometry draws each grain's diameter independently from the
//! distribution (`d (1 + σ z)` or `d e^{σ z}`, `z` a standard normal
//! redrawn outside `|z| ≤ 3`) until the drawn volume reaches the species'
//! volume fraction `f`: the distribution is one of *numbers*, `p(z) ∝
//! e^{−z²/2}` on `[−3, 3]`. The baselines integrate over it with an
//! `n`-node Gauss–Legendre rule in `z` on the truncated range (weights `w_i`,
//! nodes `z_i`, diameters `d_i`): the number density at node `i` is
//! `N_i = f p_i / Σ_j p_j V(d_j)`, `p_i = w_i e^{−z_i²/2}`, `V(d) = π d³/6`,
//! so that `Σ_i N_i V(d_i) = f` exactly. A node's *volume share* is
//! `N_i V(d_i) / f`.
//!
//! **Nodes** ([`SizeQuadrature`]): the integrands, cross sections and
//! phase moments times the weight `e^{−z²/2}`, are smooth in `z` but ripple
//! with the spheres' size resonances, whose number over the range grows
//! with the span of the *internal* size parameter,
//! `S = π max(|n_s|, n_b) (d_max − d_min) / λ` (`n_s` the pigment's index,
//! `n_b` the binder's). Each wavelength gets `max(24, ⌈2.5 S⌉)` nodes (at
//! most [`MAX_NODES`]). Doubling them changed μa and μs by at most 5e-7
//! relative, μs' = μs (1 − g) by 8e-6 (its error magnified by `1/(1 − g)`
//! for forward-peaked large grains), over the four built-in pigments at
//! 50–1500 nm, log-normal σ 0.1–0.5 and normal σ 0.1 and 0.3 (196 cases on
//! 400–700 nm), and the adding–doubling reflectance factors by 1.5e-6 (52
//! of them, three geometries);
//! `max(16, ⌈2 S⌉)` had left 3e-4 in μs' (log-normal σ 0.5 at 200–300 nm,
//! long wavelengths). `tests/baseline_sizes.rs` keeps a subset. A fixed
//! size (or σ = 0) is one node: the single sphere, unchanged.

use super::ordinates::gauss_legendre;
use crate::config::GrainSize;
use std::f64::consts::PI;

/// Standard deviations of `z` at which the geometry truncates its draws.
pub const TRUNCATION: f64 = 3.0;

/// Most nodes a distribution gets at one wavelength.
pub const MAX_NODES: usize = 1024;

/// How finely the baselines integrate over a size distribution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SizeQuadrature {
    /// Fewest Gauss–Legendre nodes (at least one is used).
    pub min_nodes: usize,
    /// Nodes per unit of the span of internal size parameter `S`.
    pub nodes_per_span: f64,
}

impl Default for SizeQuadrature {
    fn default() -> Self {
        SizeQuadrature {
            min_nodes: 24,
            nodes_per_span: 2.5,
        }
    }
}

impl SizeQuadrature {
    /// Twice the nodes everywhere (for convergence checks).
    pub fn doubled(self) -> Self {
        SizeQuadrature {
            min_nodes: 2 * self.min_nodes,
            nodes_per_span: 2.0 * self.nodes_per_span,
        }
    }

    /// Nodes for `size` around nominal diameter `d` at wavelength
    /// `wavelength_nm` (vacuum), `index` the larger of the pigment's `|n_s|`
    /// and the binder's `n_b`: `max(min_nodes, ⌈nodes_per_span S⌉)`, within
    /// `1..=MAX_NODES`.
    pub fn nodes(&self, size: GrainSize, d: f64, index: f64, wavelength_nm: f64) -> usize {
        let (lo, hi) = range(size, d);
        let wanted = (self.nodes_per_span * PI * index * (hi - lo) / wavelength_nm).ceil();
        let n = if wanted.is_finite() && wanted > self.min_nodes as f64 {
            wanted.min(MAX_NODES as f64) as usize
        } else {
            self.min_nodes
        };
        n.clamp(1, MAX_NODES)
    }
}

/// Smallest and largest diameter of `size` around nominal `d` (the
/// geometry's truncated range).
pub fn range(size: GrainSize, d: f64) -> (f64, f64) {
    let t = TRUNCATION;
    match size {
        GrainSize::Fixed => (d, d),
        GrainSize::Normal { sigma } => (d * (1.0 - t * sigma), d * (1.0 + t * sigma)),
        GrainSize::LogNormal { sigma } => (d * (-t * sigma).exp(), d * (t * sigma).exp()),
    }
}

/// One diameter of the quadrature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SizeNode {
    /// Diameter of the equal-volume sphere, nm.
    pub diameter_nm: f64,
    /// Share of the species' volume held by grains of this diameter (the
    /// shares sum to 1).
    pub volume_share: f64,
}

/// The quadrature of `size` around nominal diameter `d` with `nodes`
/// Gauss–Legendre nodes in `z` (at least one is used). A fixed size, or a
/// distribution of width 0, is the single node `(d, 1)`. Nodes whose
/// diameter is not positive (a normal σ above 1/3, which the scene's
/// checks reject) are left out.
pub fn size_nodes(size: GrainSize, d: f64, nodes: usize) -> Vec<SizeNode> {
    let diameter: Box<dyn Fn(f64) -> f64> = match size {
        GrainSize::Normal { sigma } if sigma != 0.0 => Box::new(move |z| d * (1.0 + sigma * z)),
        GrainSize::LogNormal { sigma } if sigma != 0.0 => Box::new(move |z| d * (sigma * z).exp()),
        _ => {
            return vec![SizeNode {
                diameter_nm: d,
                volume_share: 1.0,
            }]
        }
    };
    let (x, w) = gauss_legendre(nodes.max(1));
    let mut out: Vec<SizeNode> = Vec::with_capacity(x.len());
    let mut total = 0.0;
    for (&x, &w) in x.iter().zip(&w) {
        let z = TRUNCATION * x;
        let di = diameter(z);
        if di.is_nan() || di <= 0.0 {
            continue;
        }
        // Number weight p_i times the volume (π/6 cancels in the shares).
        let share = w * (-0.5 * z * z).exp() * di.powi(3);
        total += share;
        out.push(SizeNode {
            diameter_nm: di,
            volume_share: share,
        });
    }
    for n in &mut out {
        n.volume_share /= total;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::SizeDistribution;

    const NODES: usize = 24;

    #[test]
    fn a_fixed_size_is_one_node_of_the_whole_volume() {
        for size in [
            GrainSize::Fixed,
            GrainSize::Normal { sigma: 0.0 },
            GrainSize::LogNormal { sigma: 0.0 },
        ] {
            assert_eq!(
                size_nodes(size, 200.0, NODES),
                vec![SizeNode {
                    diameter_nm: 200.0,
                    volume_share: 1.0
                }],
                "{size:?}"
            );
        }
    }

    #[test]
    fn the_nodes_span_the_truncated_range_and_share_the_volume() {
        for size in [
            GrainSize::Normal { sigma: 0.3 },
            GrainSize::LogNormal { sigma: 0.5 },
        ] {
            let nodes = size_nodes(size, 200.0, NODES);
            assert_eq!(nodes.len(), NODES);
            let sum: f64 = nodes.iter().map(|n| n.volume_share).sum();
            assert!((sum - 1.0).abs() < 1e-14, "{sum}");
            // Within the geometry's range, and reaching near its ends.
            let (lo, hi) = range(size, 200.0);
            let (first, last) = (nodes[0].diameter_nm, nodes[NODES - 1].diameter_nm);
            assert!(first > lo && last < hi, "{first} {last} in ({lo}, {hi})");
            assert!(first < lo * 1.05 && last > hi * 0.95, "{first} {last}");
            assert!(nodes.iter().all(|n| n.volume_share > 0.0));
        }
    }

    #[test]
    fn the_range_is_the_geometrys_and_the_configs() {
        assert_eq!(TRUNCATION, SizeDistribution::TRUNCATION);
        for size in [
            GrainSize::Fixed,
            GrainSize::Normal { sigma: 0.25 },
            GrainSize::LogNormal { sigma: 0.35 },
        ] {
            assert_eq!(
                range(size, 180.0),
                SizeDistribution::from(size).range(180.0)
            );
            assert_eq!(range(size, 180.0).1, size.max_diameter(180.0));
        }
    }

    #[test]
    fn the_nodes_follow_the_span_of_size_parameter() {
        let q = SizeQuadrature::default();
        let ln = GrainSize::LogNormal { sigma: 0.5 };
        // Small grains: the minimum.
        assert_eq!(q.nodes(ln, 20.0, 2.0, 500.0), q.min_nodes);
        // S = π 2 (d e^{1.5} − d e^{−1.5}) / 500 for d = 300: 16.05.
        let (lo, hi) = range(ln, 300.0);
        let span = PI * 2.0 * (hi - lo) / 500.0;
        let wanted = (q.nodes_per_span * span).ceil() as usize;
        assert_eq!(q.nodes(ln, 300.0, 2.0, 500.0), wanted);
        assert!(wanted > q.min_nodes);
        let doubled = (2.0 * q.nodes_per_span * span).ceil() as usize;
        assert_eq!(q.doubled().nodes(ln, 300.0, 2.0, 500.0), doubled);
        // Bounded whatever the input.
        assert_eq!(q.nodes(ln, 1e9, 2.0, 500.0), MAX_NODES);
        assert_eq!(q.nodes(ln, f64::NAN, 2.0, 500.0), q.min_nodes);
        let none = SizeQuadrature {
            min_nodes: 0,
            nodes_per_span: 0.0,
        };
        assert_eq!(none.nodes(ln, 300.0, 2.0, 500.0), 1);
    }

    #[test]
    fn the_mean_volume_is_the_geometrys() {
        // The number-weighted ⟨d³⟩/d³ from the shares, Σ share/d³ = 1/⟨d³⟩,
        // against the geometry's own midpoint estimate of the same draw.
        for size in [
            GrainSize::Normal { sigma: 0.2 },
            GrainSize::LogNormal { sigma: 0.4 },
        ] {
            let d = 300.0;
            let inv: f64 = size_nodes(size, d, NODES)
                .iter()
                .map(|n| n.volume_share / n.diameter_nm.powi(3))
                .sum();
            let ratio = 1.0 / (inv * d.powi(3));
            let geometry = SizeDistribution::from(size).mean_cube_ratio();
            assert!(
                (ratio - geometry).abs() < 1e-6 * geometry,
                "{size:?}: {ratio} vs {geometry}"
            );
        }
    }

    #[test]
    fn no_node_is_asked_for_and_one_is_used() {
        let nodes = size_nodes(GrainSize::LogNormal { sigma: 0.3 }, 100.0, 0);
        assert_eq!(nodes.len(), 1);
        assert!((nodes[0].diameter_nm - 100.0).abs() < 1e-12);
        assert_eq!(nodes[0].volume_share, 1.0);
    }

    #[test]
    fn non_positive_diameters_are_left_out() {
        let nodes = size_nodes(GrainSize::Normal { sigma: 0.6 }, 100.0, 16);
        assert!(!nodes.is_empty() && nodes.len() < 16);
        assert!(nodes.iter().all(|n| n.diameter_nm > 0.0));
        let sum: f64 = nodes.iter().map(|n| n.volume_share).sum();
        assert!((sum - 1.0).abs() < 1e-14);
    }
}
