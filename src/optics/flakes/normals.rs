//! The orientation distribution of the flakes' normals and the quadrature
//! over it.
//!
//! A flake's normal `m` (taken in the upper hemisphere: a flake reflects
//! alike from both faces) leans from the layer normal `ẑ` by `θ_m`, its
//! azimuth uniform. The density is **Gaussian in angle**,
//! `D(m) = C exp(−θ_m²/(2σ²))` on `0 ≤ θ_m ≤ 90°`, normalised as a
//! distribution of facets, `∫ D(m) (m·ẑ) dω = 1`: `a D(m) (m·ẑ) dω` is then
//! the area, projected on the layer's plane, of the flakes whose normals lie
//! in `dω`, per unit volume, when `a` is the flakes' projected area per unit
//! volume. `σ = 0` is the aligned limit, every normal along `ẑ`.
//!
//! Small flakes add the **diffraction lobe** of a disc to their mirror
//! reflection ([`Orientation::with_diffraction`]): below ~20 µm it is
//! comparable to the orientation spread.
//!
//! The quadrature: Gauss–Legendre in `θ_m` over `[0, min(90°, 6σ)]` and the
//! trapezoidal rule in azimuth; its weights are renormalised so that the
//! discrete `Σ W (m·ẑ) = 1` holds exactly.

use crate::optics::baseline::ordinates::gauss_legendre;
use std::f64::consts::{FRAC_PI_2, PI};

/// The normals' equivalent spread of a disc's diffraction for light along
/// the normal, `σ_d = λ/(√2 π n D)` ([`Orientation::with_diffraction`]).
pub fn diffraction_rad(diameter_nm: f64, wavelength_nm: f64, lacquer: f64) -> f64 {
    wavelength_nm / (std::f64::consts::SQRT_2 * PI * lacquer * diameter_nm)
}

/// The smallest incidence cosine the diffraction spread is widened for
/// (`σ_d/μ` stays below 10 σ_d: grazing light in the lacquer).
pub const MIN_DIFFRACTION_COSINE: f64 = 0.1;

/// A Gaussian-in-angle distribution of normals of spread `sigma_rad` (≥ 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orientation {
    pub sigma_rad: f64,
}

/// One node of the quadrature over normals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalNode {
    /// The unit normal (upper hemisphere).
    pub m: [f64; 3],
    /// Weight: `D(m) dω` of the node's cell.
    pub weight: f64,
}

impl Orientation {
    /// The spread `sigma_rad` of the flakes' tilts broadened by the
    /// diffraction of a disc of `diameter_nm` at `wavelength_nm` in a
    /// lacquer of index `lacquer`. A disc's far field is Airy's pattern,
    /// intensity `(2 J₁(x)/x)²`, `x = π n D sin ψ / λ` (first zero at
    /// `sin ψ = 1.22 λ/(n D)`); its central lobe, `1 − x²/4 + …`, is the
    /// Gaussian `exp(−x²/4)` of equal curvature, a spread of the deviation
    /// `ψ` of `σ_ψ = √2 λ/(π n D)`. Reflection doubles a tilt, so the
    /// normals' equivalent spread is `σ_ψ/2`, added in quadrature:
    /// `σ_eff² = σ² + λ²/(2 π² n² D²)`. (The rings beyond the first zero,
    /// 16 % of the power, are folded into the Gaussian's tail.)
    ///
    /// That holds for light along the normal. A normal tilted by `δ` moves
    /// the reflected direction's in-plane component by `2 cos θ δ` at
    /// incidence `θ`, while the disc's far field is fixed in that component
    /// (Kirchhoff's aperture), so at incidence cosine `μ` the equivalent
    /// spread is `σ_d/μ` ([`Orientation::at_incidence`]); a wave solution of
    /// a 2 µm aluminium flake at 45° confirms it (tests/flake_wave.rs).
    pub fn with_diffraction(
        sigma_rad: f64,
        diameter_nm: f64,
        wavelength_nm: f64,
        lacquer: f64,
    ) -> Orientation {
        Orientation { sigma_rad }
            .at_incidence(diffraction_rad(diameter_nm, wavelength_nm, lacquer), 1.0)
    }

    /// This spread broadened by a disc's diffraction `diffraction_rad`
    /// ([`diffraction_rad`]) for light at incidence cosine `mu` to the layer
    /// normal (at least [`MIN_DIFFRACTION_COSINE`]): `σ² + (σ_d/μ)²`.
    pub fn at_incidence(&self, diffraction_rad: f64, mu: f64) -> Orientation {
        if diffraction_rad <= 0.0 {
            return *self;
        }
        let d = diffraction_rad / mu.abs().max(MIN_DIFFRACTION_COSINE);
        Orientation {
            sigma_rad: (self.sigma_rad * self.sigma_rad + d * d).sqrt(),
        }
    }

    /// The largest tilt the quadrature covers (the density is zero
    /// beyond it).
    pub fn extent(&self) -> f64 {
        (6.0 * self.sigma_rad).min(FRAC_PI_2)
    }

    /// `∫₀^{extent} exp(−θ²/2σ²) cos θ sin θ dθ` by Gauss–Legendre.
    fn radial_integral(&self, nodes: usize) -> f64 {
        let (x, w) = gauss_legendre(nodes);
        let e = self.extent();
        x.iter()
            .zip(&w)
            .map(|(x, w)| {
                let t = 0.5 * e * (x + 1.0);
                0.5 * e * w * self.profile(t) * t.cos() * t.sin()
            })
            .sum()
    }

    /// `exp(−θ²/2σ²)`.
    fn profile(&self, theta: f64) -> f64 {
        let s = self.sigma_rad;
        (-(theta * theta) / (2.0 * s * s)).exp()
    }

    /// `D` against the tilt (rad), its normalisation computed once; not
    /// defined for the aligned limit.
    pub fn density(&self) -> impl Fn(f64) -> f64 + '_ {
        let c = 1.0 / (2.0 * PI * self.radial_integral(96));
        move |theta| {
            if theta > self.extent() {
                0.0
            } else {
                c * self.profile(theta)
            }
        }
    }

    /// `D` against the cosine of the tilt, tabulated on `[cos extent, 1]`
    /// for a hot loop that has the cosine (no `acos`, no `exp`): `θ² =
    /// 4 asin²(√((1 − c)/2))` is analytic in `c`, so `D` is smooth in `c`
    /// and a cubic through four nodes of [`DENSITY_NODES`] reproduces it to
    /// about 10⁻¹⁰ of its peak (the spacing is `1/DENSITY_NODES` of the
    /// range, which spans ≈ 18 σ² in `c` as the density's own scale σ² does).
    /// Not defined for the aligned limit.
    pub fn density_table(&self) -> DensityTable {
        let density = self.density();
        let lo = self.extent().cos();
        let step = (1.0 - lo) / (DENSITY_NODES - 3) as f64;
        // One node below `lo` and one above 1 for the cubic's stencil.
        let values = (0..DENSITY_NODES)
            .map(|k| {
                let c = lo + (k as f64 - 1.0) * step;
                if c > 1.0 {
                    density(0.0)
                } else {
                    density(c.clamp(-1.0, 1.0).acos())
                }
            })
            .collect();
        DensityTable {
            lo,
            inv_step: 1.0 / step,
            values,
        }
    }

    /// The quadrature over normals: `tilts` Gauss–Legendre nodes in `θ_m`,
    /// `azimuths` in `φ_m`; one node along `ẑ` when `σ = 0`.
    pub fn nodes(&self, tilts: usize, azimuths: usize) -> Vec<NormalNode> {
        if self.sigma_rad <= 0.0 {
            return vec![NormalNode {
                m: [0.0, 0.0, 1.0],
                weight: 1.0,
            }];
        }
        let (x, w) = gauss_legendre(tilts.max(1));
        let e = self.extent();
        let dphi = 2.0 * PI / azimuths.max(1) as f64;
        let mut out = Vec::with_capacity(x.len() * azimuths);
        for (x, w) in x.iter().zip(&w) {
            let t = 0.5 * e * (x + 1.0);
            let cell = 0.5 * e * w * t.sin() * dphi * self.profile(t);
            for k in 0..azimuths.max(1) {
                let phi = (k as f64 + 0.5) * dphi;
                out.push(NormalNode {
                    m: [t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos()],
                    weight: cell,
                });
            }
        }
        let norm: f64 = out.iter().map(|n| n.weight * n.m[2]).sum();
        for n in &mut out {
            n.weight /= norm;
        }
        out
    }
}

/// Nodes of a [`DensityTable`].
pub const DENSITY_NODES: usize = 4096;

/// `D` against the cosine of the tilt ([`Orientation::density_table`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DensityTable {
    /// The cosine of the largest tilt: `D` is 0 below it.
    pub lo: f64,
    inv_step: f64,
    values: Vec<f64>,
}

impl DensityTable {
    /// `D` at the tilt whose cosine is `c` (0 below [`DensityTable::lo`]), by
    /// Lagrange's cubic through the four nearest nodes.
    pub fn at_cos(&self, c: f64) -> f64 {
        if c < self.lo {
            return 0.0;
        }
        let x = (c.min(1.0) - self.lo) * self.inv_step + 1.0;
        // `x ≥ 1`: truncation is the floor.
        let k = (x as usize).clamp(1, self.values.len() - 3);
        let t = x - k as f64;
        let v = &self.values[k - 1..k + 3];
        let (a, b) = (t + 1.0, t - 1.0);
        let c2 = t - 2.0;
        // Lagrange weights on the nodes −1, 0, 1, 2 (offsets from k).
        -t * b * c2 / 6.0 * v[0] + a * b * c2 / 2.0 * v[1] - a * t * c2 / 2.0 * v[2]
            + a * t * b / 6.0 * v[3]
    }
}
