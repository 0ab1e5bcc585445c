//! The directions of the adding–doubling baseline: quadrature nodes in
//! `μ = cos θ` over one hemisphere inside the binder, with their weights.
//!
//! Inside a binder of index `n > 1` the hemisphere splits at the critical
//! `μ_c = √(1 − 1/n²)`: below it light is trapped by total internal
//! reflection, above it each direction refracts into one direction in air,
//! `μ_a = √(1 − n²(1 − μ²))`. The nodes follow that split:
//! - **trapped** (`0 < μ < μ_c`): Gauss–Legendre in `μ`;
//! - **escaping**: nodes chosen in the *air* cosine `μ_a ∈ (0, 1]`, where
//!   the Fresnel reflectance is smooth (in the binder's `μ` it has a
//!   square-root edge at `μ_c`), on panels that end at the air directions a
//!   measurement needs (`cos 45°`, `cos 8°`, the normal `μ_a = 1`), each by
//!   right-ended Gauss–Radau, so those directions are nodes themselves.
//!
//! Each node carries its binder weight `w` (for `∫ g(μ) dμ`) and its flux
//! weight `c = 2 μ w`, the share of a Lambertian (isotropic) radiance's flux
//! in the node's bin: `Σ c = 1` exactly (Gauss on the trapped panel and
//! Radau on the escaping ones integrate `μ` exactly). An escaping bin is the
//! same bundle of rays in air, with flux weight `c_a = 2 μ_a w_a = n² c`
//! (étendue, `n² μ dμ = μ_a dμ_a`): flux is carried across the surface bin
//! by bin, so a flat interface is diagonal in this basis.

use super::BaselineError;

/// Gauss–Legendre nodes and weights on `[−1, 1]` (`n ≥ 1`), by Newton's
/// iteration on `P_n` from the usual cosine guesses ([`RULE_CACHE_LIMIT`]
/// rules and smaller kept once computed: the flake kernels and the
/// interference flakes' thickness averages ask for the same rules at every
/// wavelength, and a rule of `n` points costs `O(n²)`).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    type Rules = Mutex<HashMap<usize, (Vec<f64>, Vec<f64>)>>;
    static RULES: OnceLock<Rules> = OnceLock::new();
    if n > RULE_CACHE_LIMIT {
        return compute_gauss_legendre(n);
    }
    let rules = RULES.get_or_init(Default::default);
    if let Some(r) = rules.lock().unwrap_or_else(|e| e.into_inner()).get(&n) {
        return r.clone();
    }
    let r = compute_gauss_legendre(n);
    rules
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(n, r.clone());
    r
}

/// The largest rule [`gauss_legendre`] keeps.
pub const RULE_CACHE_LIMIT: usize = 1024;

fn compute_gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (p, dp) = legendre_with_derivative(n, z);
            let dz = p / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let (_, dp) = legendre_with_derivative(n, z);
        x[n - 1 - i] = z;
        w[n - 1 - i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// `P_n(z)` and `P_n'(z)` for `|z| < 1`.
fn legendre_with_derivative(n: usize, z: f64) -> (f64, f64) {
    let (p_prev, p) = legendre_pair(n, z);
    let dp = n as f64 * (z * p - p_prev) / (z * z - 1.0);
    (p, dp)
}

/// `(P_{n−1}(z), P_n(z))` by the three-term recurrence (`P_{−1}` = 0).
fn legendre_pair(n: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (0.0, 1.0);
    for l in 0..n {
        let p2 = ((2 * l + 1) as f64 * z * p1 - l as f64 * p0) / (l + 1) as f64;
        p0 = p1;
        p1 = p2;
    }
    (p0, p1)
}

/// Gauss–Radau nodes and weights on `[−1, 1]` with the node `+1` fixed
/// (`n ≥ 1` nodes, exact to degree `2n − 2`): the mirror of the rule with
/// `−1` fixed, whose free nodes are the roots of `(P_{n−1} + P_n)/(1 + x)`
/// with weights `(1 − x)/(n² P_{n−1}(x)²)`, and `2/n²` at the fixed node.
pub fn gauss_radau_right(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = |x: f64| {
        let (a, b) = legendre_pair(n, x);
        a + b
    };
    let nf = n as f64;
    let mut nodes = vec![-1.0];
    let mut weights = vec![2.0 / (nf * nf)];
    // Bracket the n − 1 free roots by sign changes on a fine grid.
    let steps = 400 * n.max(1);
    let h = 2.0 / steps as f64;
    let mut a = -1.0 + 1e-3 * h;
    for s in 1..=steps {
        let b = if s == steps { 1.0 } else { -1.0 + s as f64 * h };
        let (fa, fb) = (q(a), q(b));
        if fa * fb < 0.0 {
            let (mut lo, mut hi, mut flo) = (a, b, fa);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                let fm = q(mid);
                if fm * flo <= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                    flo = fm;
                }
                if hi - lo < 1e-16 {
                    break;
                }
            }
            let x = 0.5 * (lo + hi);
            let (p_prev, _) = legendre_pair(n, x);
            nodes.push(x);
            weights.push((1.0 - x) / (nf * nf * p_prev * p_prev));
        }
        a = b;
    }
    // Mirror so that +1 is the fixed node, ascending.
    let mut pairs: Vec<(f64, f64)> = nodes.iter().zip(&weights).map(|(x, w)| (-x, *w)).collect();
    pairs.sort_by(|p, q| p.0.total_cmp(&q.0));
    pairs.into_iter().unzip()
}

/// How many nodes the quadrature uses (plain numbers, see [`Ordinates`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrdinateParams {
    /// Gauss–Legendre nodes on the trapped panel `(0, μ_c)`.
    pub trapped_nodes: usize,
    /// Nodes per unit of the air cosine on the escaping panels; each panel
    /// has `max(2, ⌈escape_nodes × panel length⌉)`.
    pub escape_nodes: usize,
}

impl Default for OrdinateParams {
    /// 8 trapped and 12 escaping per unit `μ_a`: 23 nodes with the panels
    /// ending at 45°, 8° and the normal (the quadrature's part of the
    /// error: docs/VALIDATION.md).
    fn default() -> Self {
        OrdinateParams {
            trapped_nodes: 8,
            escape_nodes: 12,
        }
    }
}

/// Quadrature directions of one hemisphere in the binder, ascending `μ`.
#[derive(Debug, Clone, PartialEq)]
pub struct Ordinates {
    /// Binder index `n ≥ 1`.
    pub binder_index: f64,
    /// Direction cosines in the binder.
    pub mu: Vec<f64>,
    /// Weights for `∫₀¹ g(μ) dμ` in the binder.
    pub weight: Vec<f64>,
    /// Flux weights `c = 2 μ w` (sum 1).
    pub flux_weight: Vec<f64>,
    /// Air cosine of an escaping node; None for a trapped one.
    pub mu_air: Vec<Option<f64>>,
}

impl Ordinates {
    /// The nodes for a binder of index `binder_index` (≥ 1) with the air
    /// directions `air_polar_deg` (each in [0°, 90°)) among the nodes.
    pub fn new(
        binder_index: f64,
        params: OrdinateParams,
        air_polar_deg: &[f64],
    ) -> Result<Ordinates, BaselineError> {
        let n = binder_index;
        if !(n >= 1.0 && n.is_finite()) {
            return Err(BaselineError::BinderIndex(n));
        }
        if params.trapped_nodes == 0 || params.escape_nodes == 0 {
            return Err(BaselineError::Nodes);
        }
        let mut out = Ordinates {
            binder_index: n,
            mu: Vec::new(),
            weight: Vec::new(),
            flux_weight: Vec::new(),
            mu_air: Vec::new(),
        };
        let mu_c = (1.0 - 1.0 / (n * n)).sqrt();
        if mu_c > 0.0 {
            let (x, w) = gauss_legendre(params.trapped_nodes);
            for (x, w) in x.iter().zip(&w) {
                let mu = 0.5 * mu_c * (x + 1.0);
                let wt = 0.5 * mu_c * w;
                out.push(mu, wt, None);
            }
        }
        let mut ends: Vec<f64> = air_polar_deg
            .iter()
            .map(|d| d.to_radians().cos())
            .filter(|c| *c > 0.0 && *c < 1.0)
            .collect();
        ends.push(1.0);
        ends.sort_by(f64::total_cmp);
        ends.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        let mut start = 0.0;
        for end in ends {
            let len = end - start;
            let m = ((params.escape_nodes as f64 * len).ceil() as usize).max(2);
            let (x, w) = gauss_radau_right(m);
            for (x, w) in x.iter().zip(&w) {
                let mu_a = start + 0.5 * len * (x + 1.0);
                let w_a = 0.5 * len * w;
                let mu = (1.0 - (1.0 - mu_a * mu_a) / (n * n)).sqrt();
                // dμ = μ_a dμ_a / (n² μ).
                out.push(mu, w_a * mu_a / (n * n * mu), Some(mu_a));
            }
            start = end;
        }
        Ok(out)
    }

    fn push(&mut self, mu: f64, w: f64, mu_air: Option<f64>) {
        self.mu.push(mu);
        self.weight.push(w);
        self.flux_weight.push(2.0 * mu * w);
        self.mu_air.push(mu_air);
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.mu.len()
    }

    /// True without nodes (never for a built quadrature).
    pub fn is_empty(&self) -> bool {
        self.mu.is_empty()
    }

    /// The node of the air direction `polar_deg`, if it is one.
    pub fn air_node(&self, polar_deg: f64) -> Option<usize> {
        let c = polar_deg.to_radians().cos();
        self.mu_air
            .iter()
            .position(|m| m.is_some_and(|m| (m - c).abs() < 1e-9))
    }

    /// Flux weight of node `i` on the air side, `n² c_i` (0 when trapped).
    pub fn air_flux_weight(&self, i: usize) -> f64 {
        match self.mu_air[i] {
            Some(_) => self.binder_index * self.binder_index * self.flux_weight[i],
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_polynomials_exactly() {
        for n in 1..=12 {
            let (x, w) = gauss_legendre(n);
            for p in 0..2 * n {
                let num: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
                let exact = if p % 2 == 1 {
                    0.0
                } else {
                    2.0 / (p + 1) as f64
                };
                assert!((num - exact).abs() < 1e-13, "GL {n}, degree {p}: {num}");
            }
            let (x, w) = gauss_radau_right(n);
            assert_eq!(x.len(), n);
            assert_eq!(*x.last().unwrap(), 1.0);
            for p in 0..2 * n - 1 {
                let num: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p as i32)).sum();
                let exact = if p % 2 == 1 {
                    0.0
                } else {
                    2.0 / (p + 1) as f64
                };
                assert!((num - exact).abs() < 1e-12, "Radau {n}, degree {p}: {num}");
            }
        }
    }

    #[test]
    fn flux_weights_sum_to_one_and_hit_the_air_directions() {
        for n in [1.0, 1.33, 1.558, 2.0] {
            let o = Ordinates::new(n, OrdinateParams::default(), &[45.0, 8.0, 0.0]).unwrap();
            let sum: f64 = o.flux_weight.iter().sum();
            assert!((sum - 1.0).abs() < 1e-13, "n {n}: {sum}");
            let air: f64 = (0..o.len()).map(|i| o.air_flux_weight(i)).sum();
            assert!((air - 1.0).abs() < 1e-13, "n {n}: {air}");
            for deg in [45.0, 8.0, 0.0] {
                assert!(o.air_node(deg).is_some(), "n {n}: {deg}°");
            }
            assert!(o.mu.windows(2).all(|p| p[0] < p[1]));
        }
        assert!(Ordinates::new(0.9, OrdinateParams::default(), &[]).is_err());
    }
}
