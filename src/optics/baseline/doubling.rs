//! One homogeneous scattering and absorbing slab by doubling: the
//! reflection and transmission matrices of a thin layer from the diamond
//! initialisation, doubled to the slab's thickness.
//!
//! **Basis.** Matrices act on bin fluxes over the [`Ordinates`] of one
//! hemisphere: column `j` is the flux arriving in bin `j`, row `i` the
//! fraction leaving in bin `i` (azimuthally averaged, Fourier term `m = 0`).
//! Energy is then a column sum: without absorption `Σ_i (R + T)_ij = 1`.
//!
//! **Scattering.** The phase function `p = Σ (2n + 1) χ_n P_n(cos Θ)`
//! (`χ_0 = 1`), averaged over azimuth: `p(μ, μ') = Σ (2n + 1) χ_n P_n(μ)
//! P_n(μ')`. Forward peaks beyond what the nodes resolve are truncated by
//! **δ-M** (Wiscombe 1977): with `2N` moments kept (`N` nodes per
//! hemisphere) the fraction `f = χ_2N` of the scattering is moved into the
//! unscattered beam, `χ'_n = (χ_n − f)/(1 − f)`, `μs' = (1 − f) μs`, μa
//! unchanged (for the study's spheres `l_max` is small and `f` is 0). The
//! discrete phase matrix is then made to conserve energy exactly on the
//! nodes, `½ Σ_i w_i [p(μ_i, μ_j) + p(−μ_i, μ_j)] = 1`, by adding the
//! defect to its forward (diagonal) element, which keeps it symmetric
//! (reciprocity).
//!
//! **Thin layer** (diamond initialisation, Wiscombe 1976): the radiative
//! transfer equation over a layer of optical thickness `Δτ`, the radiance
//! inside taken as the mean of its values on both faces, a linear system
//! of `2N` unknowns per incident direction, solved for the scattered part
//! only (the unscattered light is `e^{−Δτ/μ}` exactly); error
//! `O(Δτ³/μ³)` per layer, `O(τ Δτ²/μ³)` after the doublings. The start is
//! `Δτ ≤ 10⁻⁶ μ_min` ([`START_THICKNESS`]).
//!
//! **Kernels.** The thin layer and the doublings work on any medium that is
//! alike from both faces, given per unit thickness in the flux basis
//! ([`FluxKernel`]): a direction-dependent attenuation of the unscattered
//! light and the flux scattered from bin to bin. The isotropic medium above
//! is one; oriented flakes, whose extinction depends on the direction and
//! whose azimuthal Fourier terms `m > 0` share the same equations, are
//! another (`optics::flakes`).
//!
//! **Doubling.** Two equal layers: `R₂ = R + T (I − R R)⁻¹ R T`,
//! `T₂ = T (I − R R)⁻¹ T` (a homogeneous slab reflects alike from both
//! faces), with the unscattered part kept apart ([`Homogeneous`]).

use super::adding::Slab;
use super::matrix::Matrix;
use super::ordinates::Ordinates;
use super::BaselineError;

/// The scattering medium at one wavelength.
#[derive(Debug, Clone, PartialEq)]
pub struct Medium {
    /// Absorption coefficient, 1/nm.
    pub mu_a: f64,
    /// Scattering coefficient, 1/nm.
    pub mu_s: f64,
    /// Normalised Legendre moments of the phase function, `χ_0 = 1` (`χ_1`
    /// is the asymmetry parameter); empty when nothing scatters.
    pub moments: Vec<f64>,
}

impl Medium {
    /// The medium after δ-M truncation to `kept` moments: `(μs', χ')`.
    pub fn delta_m(&self, kept: usize) -> (f64, Vec<f64>) {
        let f = self.moments.get(kept).copied().unwrap_or(0.0);
        if self.mu_s <= 0.0 || self.moments.is_empty() {
            return (0.0, vec![1.0]);
        }
        if f <= 0.0 || f >= 1.0 {
            let mut chi: Vec<f64> = self.moments.iter().take(kept).copied().collect();
            chi[0] = 1.0;
            return (self.mu_s, chi);
        }
        let chi = self
            .moments
            .iter()
            .take(kept)
            .map(|c| (c - f) / (1.0 - f))
            .collect();
        (self.mu_s * (1.0 - f), chi)
    }
}

/// The phase function of normalised Legendre moments `χ` at `cos Θ = x`:
/// `p(x) = Σ_l (2l + 1) χ_l P_l(x)`, whose mean over all directions is
/// `χ_0` (1 for a normalised one).
pub fn phase_series(chi: &[f64], x: f64) -> f64 {
    let (mut p0, mut p1) = (1.0, x);
    let mut s = chi.first().copied().unwrap_or(0.0);
    for (l, c) in chi.iter().enumerate().skip(1) {
        s += (2 * l + 1) as f64 * c * p1;
        let p2 = ((2 * l + 1) as f64 * x * p1 - l as f64 * p0) / (l + 1) as f64;
        p0 = p1;
        p1 = p2;
    }
    s
}

/// The phase matrices `(p(μ_i, μ_j), p(μ_i, −μ_j))` on the nodes, with the
/// diagonal energy correction.
pub fn phase_matrices(ords: &Ordinates, chi: &[f64]) -> (Matrix, Matrix) {
    let n = ords.len();
    // P_l(μ_i) for every kept order.
    let legendre: Vec<Vec<f64>> = ords
        .mu
        .iter()
        .map(|&x| {
            let mut p = Vec::with_capacity(chi.len());
            let (mut p0, mut p1) = (1.0, x);
            for l in 0..chi.len() {
                if l == 0 {
                    p.push(1.0);
                    continue;
                }
                p.push(p1);
                let p2 = ((2 * l + 1) as f64 * x * p1 - l as f64 * p0) / (l + 1) as f64;
                p0 = p1;
                p1 = p2;
            }
            p
        })
        .collect();
    let kernel = |i: usize, j: usize, sign: f64| {
        let mut s = 0.0;
        let mut parity = 1.0;
        for (l, c) in chi.iter().enumerate() {
            s += (2 * l + 1) as f64 * c * legendre[i][l] * legendre[j][l] * parity;
            parity *= sign;
        }
        s
    };
    let mut same = Matrix::from_fn(n, |i, j| kernel(i, j, 1.0));
    let opposite = Matrix::from_fn(n, |i, j| kernel(i, j, -1.0));
    for j in 0..n {
        let s: f64 = (0..n)
            .map(|i| 0.5 * ords.weight[i] * (same[(i, j)] + opposite[(i, j)]))
            .sum();
        same[(j, j)] += 2.0 * (1.0 - s) / ords.weight[j];
    }
    (same, opposite)
}

/// The unscattered part of a slab of extinction `mu_ext` (1/nm) and
/// `thickness_nm`: `T = diag(e^{−τ/μ_i})`, no reflection.
pub fn direct(ords: &Ordinates, mu_ext: f64, thickness_nm: f64) -> Slab {
    let t: Vec<f64> = ords
        .mu
        .iter()
        .map(|mu| (-mu_ext * thickness_nm / mu).exp())
        .collect();
    Slab::symmetric(Matrix::zeros(ords.len()), Matrix::diagonal(&t))
}

/// A homogeneous slab's matrices during doubling, the unscattered light
/// kept apart: `T = diag(direct) + scattered`. The direct part is the exact
/// `e^{−e_i z}` of the current thickness `z` (not squared from the thin
/// layer's: squaring doubles a relative error, 30 squarings make 10⁻¹⁶ into
/// 10⁻⁷), and the scattered parts start small, so no `1 − small` is formed
/// and rounding does not grow with the number of layers.
#[derive(Debug, Clone, PartialEq)]
pub struct Homogeneous {
    /// Reflection (alike from both faces).
    pub r: Matrix,
    /// Transmission of scattered light.
    pub scattered: Matrix,
    /// Transmission of unscattered light per bin, `e^{−e_i z}`.
    pub direct: Vec<f64>,
    /// Attenuation of the unscattered light per unit thickness and bin,
    /// `e_i` (`1/μ_i` when the thickness is an optical thickness).
    pub rate: Vec<f64>,
    /// The thickness `z`, in the unit `rate` is per.
    pub depth: f64,
}

impl Homogeneous {
    /// The layer as a [`Slab`].
    pub fn to_slab(&self) -> Slab {
        let mut t = self.scattered.clone();
        for (i, d) in self.direct.iter().enumerate() {
            t[(i, i)] += d;
        }
        Slab::symmetric(self.r.clone(), t)
    }
}

/// A medium per unit thickness in the flux basis, for a layer that is
/// alike from both faces (its upside-down is itself): the unscattered
/// light in bin `i` decays as `e^{−e_i z}` and the flux scattered out of
/// bin `j` into bin `i` per unit thickness is `same_ij` (same hemisphere)
/// or `opposite_ij` (the other one); without absorption
/// `Σ_i (same + opposite)_ij = e_j`. Its radiative transfer equation for
/// bin fluxes reads `dF⁺_i/dz = −e_i F⁺_i + Σ_j same_ij F⁺_j + opposite_ij F⁻_j`.
#[derive(Debug, Clone, PartialEq)]
pub struct FluxKernel {
    pub rate: Vec<f64>,
    pub same: Matrix,
    pub opposite: Matrix,
}

impl FluxKernel {
    /// The kernel of an isotropic medium of single-scattering albedo
    /// `albedo` and phase moments `chi`, per unit optical thickness:
    /// `e_i = 1/μ_i`, `same_ij = ω w_i p(μ_i, μ_j)/(2 μ_j)` (and `p(−μ_i,
    /// μ_j)` for `opposite`), the phase matrices of [`phase_matrices`].
    pub fn isotropic(ords: &Ordinates, albedo: f64, chi: &[f64]) -> FluxKernel {
        let n = ords.len();
        let rate: Vec<f64> = ords.mu.iter().map(|mu| 1.0 / mu).collect();
        if albedo <= 0.0 {
            return FluxKernel {
                rate,
                same: Matrix::zeros(n),
                opposite: Matrix::zeros(n),
            };
        }
        let (same, opposite) = phase_matrices(ords, chi);
        let flux = |p: &Matrix| {
            Matrix::from_fn(n, |i, j| {
                0.5 * albedo * ords.weight[i] * p[(i, j)] / ords.mu[j]
            })
        };
        FluxKernel {
            rate,
            same: flux(&same),
            opposite: flux(&opposite),
        }
    }

    /// True when nothing is scattered.
    pub fn scatters_nothing(&self) -> bool {
        self.same.column_sums().iter().all(|&v| v == 0.0)
            && self.opposite.column_sums().iter().all(|&v| v == 0.0)
    }
}

/// The homogeneous slab of `medium`, `thickness_nm` thick (≥ 0).
pub fn homogeneous(
    ords: &Ordinates,
    medium: &Medium,
    thickness_nm: f64,
) -> Result<Slab, BaselineError> {
    let (mu_s, chi) = medium.delta_m(2 * ords.len());
    let mu_e = medium.mu_a + mu_s;
    let tau = mu_e * thickness_nm;
    if !(tau.is_finite() && tau >= 0.0) {
        return Err(BaselineError::Thickness(tau));
    }
    if tau == 0.0 {
        return Ok(Slab::transparent(ords.len()));
    }
    let albedo = if mu_e > 0.0 { mu_s / mu_e } else { 0.0 };
    let kernel = FluxKernel::isotropic(ords, albedo, &chi);
    Ok(slab(&kernel, tau, START_THICKNESS)?.to_slab())
}

/// The slab of `kernel`, `depth` thick, by doubling from a thin layer whose
/// largest attenuation `max_i e_i Δz` is at most `start`.
pub fn slab(kernel: &FluxKernel, depth: f64, start: f64) -> Result<Homogeneous, BaselineError> {
    let rate_max = kernel.rate.iter().copied().fold(0.0, f64::max);
    if !(depth.is_finite() && depth >= 0.0 && rate_max.is_finite()) {
        return Err(BaselineError::Thickness(depth * rate_max));
    }
    let target = start / rate_max.max(f64::MIN_POSITIVE);
    let mut doublings = 0u32;
    let mut dz = depth;
    if !kernel.scatters_nothing() {
        while dz > target && doublings < 200 {
            dz *= 0.5;
            doublings += 1;
        }
    }
    let mut layer = thin_flux(kernel, dz)?;
    for _ in 0..doublings {
        layer = double(&layer)?;
    }
    Ok(layer)
}

/// The thin layer's optical thickness in units of the smallest node's `μ`:
/// the diamond scheme's error is `O((Δτ/μ)²)` relative over the doublings.
pub const START_THICKNESS: f64 = 1e-6;

/// A thin layer of optical thickness `dtau`, single-scattering albedo
/// `albedo` and phase moments `chi`, by the diamond scheme; the
/// unscattered light exactly, `e^{−Δτ/μ}`.
pub fn thin(
    ords: &Ordinates,
    albedo: f64,
    chi: &[f64],
    dtau: f64,
) -> Result<Homogeneous, BaselineError> {
    thin_flux(&FluxKernel::isotropic(ords, albedo, chi), dtau)
}

/// A thin layer `dz` thick of `kernel` by the diamond scheme (the bin
/// fluxes inside taken as the mean of their values on both faces, a linear
/// system of `2N` unknowns per incident bin, solved for the scattered part
/// only); the unscattered light exactly, `e^{−e_i Δz}`.
pub fn thin_flux(kernel: &FluxKernel, dz: f64) -> Result<Homogeneous, BaselineError> {
    let n = kernel.rate.len();
    let direct: Vec<f64> = kernel.rate.iter().map(|e| (-e * dz).exp()).collect();
    if kernel.scatters_nothing() {
        return Ok(Homogeneous {
            r: Matrix::zeros(n),
            scattered: Matrix::zeros(n),
            direct,
            rate: kernel.rate.clone(),
            depth: dz,
        });
    }
    // s = Δz/2, h_i = s e_i; the diamond system for (F⁺₁, F⁻₀) given F⁺₀:
    // [[I + H − sQ⁺, −sQ⁻], [−sQ⁻, I + H − sQ⁺]] x = [[I − H + sQ⁺], [sQ⁻]].
    let s = 0.5 * dz;
    let h: Vec<f64> = kernel.rate.iter().map(|e| s * e).collect();
    let (same, opposite) = (&kernel.same, &kernel.opposite);
    let m = 2 * n;
    let lhs = Matrix::from_fn(m, |r, c| {
        let (ri, ci) = (r % n, c % n);
        if (r < n) == (c < n) {
            (r == c) as u8 as f64 * (1.0 + h[ri]) - s * same[(ri, ci)]
        } else {
            -s * opposite[(ri, ci)]
        }
    });
    // Less its unscattered solution x₀ = (diag e_d, 0), e_d = (1 − h)/(1 + h):
    // the right side becomes [[sQ⁺(I + E_d)], [sQ⁻(I + E_d)]], all small.
    let rhs = Matrix::from_fn(m, |r, c| {
        if c >= n {
            return 0.0;
        }
        let ri = r % n;
        let grow = 1.0 + (1.0 - h[c]) / (1.0 + h[c]);
        if r < n {
            s * same[(ri, c)] * grow
        } else {
            s * opposite[(ri, c)] * grow
        }
    });
    let x = lhs.solve(&rhs)?;
    Ok(Homogeneous {
        r: Matrix::from_fn(n, |i, j| x[(n + i, j)]),
        scattered: Matrix::from_fn(n, |i, j| x[(i, j)]),
        direct,
        rate: kernel.rate.clone(),
        depth: dz,
    })
}

/// Two copies of a homogeneous slab on top of each other, with
/// `G = (I − R R)⁻¹ = I + G̃`: `R₂ = R + T R G T`,
/// `T₂ = T G T = E² + [E S + S E + S (S + G̃T) + E G̃T]` (`T = E + S`).
pub fn double(s: &Homogeneous) -> Result<Homogeneous, BaselineError> {
    let n = s.direct.len();
    let rr = s.r.mul(&s.r);
    let g_tilde = rr.identity_minus().solve(&rr)?;
    let t = {
        let mut t = s.scattered.clone();
        for (i, d) in s.direct.iter().enumerate() {
            t[(i, i)] += d;
        }
        t
    };
    let gt_tilde = g_tilde.mul(&t);
    let gt = t.add(&gt_tilde);
    let r = s.r.add(&t.mul(&s.r).mul(&gt));
    // S S + T G̃T = S (S + G̃T) + E G̃T, one product fewer.
    let mut scattered = s.scattered.mul(&s.scattered.add(&gt_tilde));
    for i in 0..n {
        for j in 0..n {
            scattered[(i, j)] +=
                (s.direct[i] + s.direct[j]) * s.scattered[(i, j)] + s.direct[i] * gt_tilde[(i, j)];
        }
    }
    let depth = 2.0 * s.depth;
    Ok(Homogeneous {
        r,
        scattered,
        direct: s.rate.iter().map(|e| (-e * depth).exp()).collect(),
        rate: s.rate.clone(),
        depth,
    })
}
