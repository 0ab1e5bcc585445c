//! The homogeneous slab solved in closed form (Airy/Fresnel for the scalar
//! wave): the exact answer for a layer without grains, used for the
//! molecular-mixture limit (METHOD §7), where the layer is the slab with the
//! volume-averaged ε, so no grid and no iteration are needed. The `airy`
//! method ([`closed_form`](super::methods::closed_form)) solves a problem
//! with it.
//!
//! Inside the slab `u = a e^{iγz} + b e^{iγ(H−z)}`: both exponentials decay
//! away from the face they are referred to, so no coefficient of the 4×4
//! matching system exceeds 1 in size and large `Im γ H` cannot overflow.
//! The absorption is integrated from that field in closed form
//! (`A = k0² Im ε ∫|u|² dz / β`), independently of `r` and `t`, so the energy
//! balance `|r|² + |t|² + A − 1` stays a real check.
//!
//! [`effective_medium_error`] bounds how far a layer of fine grains is from
//! this slab with the volume-averaged ε: the shortcut's error, measured
//! against full solves (docs/ACCURACY.md, examples/effective_medium.rs).

use super::green::{phi1, sqrt_branch};
use num_complex::Complex64 as C64;

/// Amplitudes and absorption of a homogeneous slab.
#[derive(Debug, Clone, Copy)]
pub struct SlabResponse {
    /// Reflection amplitude of the specular order.
    pub r: C64,
    /// Transmission amplitude (referred to z = H).
    pub t: C64,
    /// Absorbed fraction of the incident power.
    pub absorption: f64,
}

/// Exact response of a slab of permittivity `eps`, `thickness_nm` thick, in
/// vacuum, lit from above at `polar_deg` with vacuum wavelength `wavelength_nm`.
pub fn slab(eps: C64, thickness_nm: f64, wavelength_nm: f64, polar_deg: f64) -> SlabResponse {
    let k0 = 2.0 * std::f64::consts::PI / wavelength_nm;
    let kx = k0 * polar_deg.to_radians().sin();
    SlabField::new(eps, thickness_nm, k0, kx).response
}

/// The exact field of a homogeneous slab: its response and the two waves
/// inside, `u = a e^{iγz} + b e^{iγ(H−z)}`.
#[derive(Debug, Clone, Copy)]
pub struct SlabField {
    pub response: SlabResponse,
    a: C64,
    b: C64,
    gamma: C64,
    thickness: f64,
    /// p polarisation: (ε, k0, κ) for the electric field.
    p: Option<(C64, f64, f64)>,
}

impl SlabField {
    /// The slab of permittivity `eps`, `thickness_nm` thick, in vacuum, lit
    /// from above by a wave of free-space wavenumber `k0` and lateral
    /// wavenumber `kx` (rad/nm): the scalar wave, which is s polarisation.
    pub fn new(eps: C64, thickness_nm: f64, k0: f64, kx: f64) -> SlabField {
        Self::polarised(eps, thickness_nm, k0, kx, false)
    }

    /// As [`SlabField::new`] in s (`p = false`) or p polarisation. In p the
    /// unknown is the magnetic field H_y (continuous with H_y'/ε), and
    /// `r` is the reflected E_p amplitude along p̂ = (β ê_x + κ ẑ)/k0,
    /// which is `−r_H`; `t = t_H`. The absorption integrates
    /// `|E|² = (|γ|² |H_y'/(iγ)|² + κ² |H_y|²)/(k0² |ε|²)` in closed form.
    pub fn polarised(eps: C64, thickness_nm: f64, k0: f64, kx: f64, p: bool) -> SlabField {
        let beta = C64::new((k0 * k0 - kx * kx).max(0.0).sqrt(), 0.0);
        let g = sqrt_branch(eps * k0 * k0 - kx * kx);
        // The derivative rows' inner admittance: γ (s) or γ/ε (p).
        let y = if p { g / eps } else { g };
        let h = thickness_nm;
        let e1 = (C64::i() * g * h).exp();
        let one = C64::new(1.0, 0.0);
        let zero = C64::new(0.0, 0.0);
        // Unknowns x = (r, a, b, t); rows: u and u'/ε (p) continuous at z = 0 and z = H.
        let mut m = [
            [-one, one, e1, zero, one],
            [beta, y, -y * e1, zero, beta],
            [zero, e1, one, -one, zero],
            [zero, y * e1, -y, -beta, zero],
        ];
        let x = solve4(&mut m);
        let (r, a, b, t) = (x[0], x[1], x[2], x[3]);
        // ∫₀ᴴ |a e^{iγz} ± b e^{iγ(H−z)}|² dz in closed form.
        let (gr, gi) = (g.re, g.im);
        let decay = h * phi1(C64::new(-2.0 * gi * h, 0.0)).re;
        let cross = a
            * b.conj()
            * (C64::new(0.0, -gr * h).exp() * (-gi * h).exp())
            * h
            * phi1(C64::new(0.0, 2.0 * gr * h));
        let plus = (a.norm_sqr() + b.norm_sqr()) * decay + 2.0 * cross.re;
        let integral = if p {
            let minus = (a.norm_sqr() + b.norm_sqr()) * decay - 2.0 * cross.re;
            (g.norm_sqr() * minus + kx * kx * plus) / (k0 * k0 * eps.norm_sqr())
        } else {
            plus
        };
        let absorption = k0 * k0 * eps.im * integral / beta.re;
        SlabField {
            response: SlabResponse {
                r: if p { -r } else { r },
                t,
                absorption,
            },
            a,
            b,
            gamma: g,
            thickness: h,
            p: p.then_some((eps, k0, kx)),
        }
    }

    /// Averages of the field over `nz` equal z cells (both waves decay away
    /// from the face they are referred to, so nothing overflows): u, or in
    /// p polarisation H_y (scaled to a unit incident E).
    pub fn cell_averages(&self, nz: usize) -> Vec<C64> {
        self.averages(nz, 1.0)
    }

    /// `(E_κ, E_z)` per z cell of a p-polarised slab (E_κ along the plane of
    /// incidence); `None` in s.
    pub fn p_cell_averages(&self, nz: usize) -> Option<(Vec<C64>, Vec<C64>)> {
        let (eps, k0, kx) = self.p?;
        let ek = self
            .averages(nz, -1.0)
            .into_iter()
            .map(|v| v * self.gamma / (k0 * eps))
            .collect();
        let ez = self
            .averages(nz, 1.0)
            .into_iter()
            .map(|v| -v * kx / (k0 * eps))
            .collect();
        Some((ek, ez))
    }

    /// Cell averages of `a e^{iγz} + sign · b e^{iγ(H−z)}`.
    fn averages(&self, nz: usize, sign: f64) -> Vec<C64> {
        let dz = self.thickness / nz as f64;
        let i = C64::i();
        let cell = phi1(i * self.gamma * dz);
        (0..nz)
            .map(|j| {
                let (top, bottom) = (j as f64 * dz, self.thickness - (j + 1) as f64 * dz);
                cell * (self.a * (i * self.gamma * top).exp()
                    + sign * self.b * (i * self.gamma * bottom).exp())
            })
            .collect()
    }
}

/// One grain species as [`effective_medium_error`] sees it.
#[derive(Debug, Clone, Copy)]
pub struct GrainTerm {
    /// Volume fraction of the species in the layer.
    pub volume_fraction: f64,
    /// Largest grain diameter of the species, nm.
    pub diameter_nm: f64,
    /// `ε_grain − ε_binder` at the wavelength.
    pub delta_eps: C64,
}

/// Largest grain size parameter `k0 d` (d = λ/20) at which the estimate was
/// measured to hold: beyond it single grains scatter strongly (lossless
/// high-index grains broke the linear law at `k0 d` = 0.63), so the shortcut
/// is not offered there whatever the tolerance.
pub const EFFECTIVE_MAX_SIZE_PARAMETER: f64 = std::f64::consts::PI / 10.0;
/// Measured constant of the coherent term (docs/ACCURACY.md).
pub const EFFECTIVE_COHERENT: f64 = 0.5;
/// Measured constant of the incoherent (diffuse) term (docs/ACCURACY.md).
pub const EFFECTIVE_INCOHERENT: f64 = 0.25;

/// The two terms of the effective-medium error, without their constants,
/// at one wavelength and incidence (`k0 = 2π/λ`, `θ_t` the refracted angle
/// in the binder):
///
/// * coherent, `Σ f |Δε| k0 d`: grains confined to the binder leave a
///   depleted skin ~d/2 at each face and a denser interior, a first-order
///   change of the mean profile (plus the `(k0 d)²` corrections of ⟨ε⟩);
/// * incoherent, `Σ f |Δε|² (k0 d)³ k0 H / (24 cos θ_t)`: the power the
///   grains scatter out of the specular order (Rayleigh cross-section of a
///   scalar sphere, `k0⁴ |Δε|² V² / 4π`, times the number along the path),
///   which the slab cannot carry.
pub fn effective_medium_terms(
    grains: &[GrainTerm],
    eps_binder: f64,
    thickness_nm: f64,
    wavelength_nm: f64,
    polar_deg: f64,
) -> (f64, f64) {
    let k0 = 2.0 * std::f64::consts::PI / wavelength_nm;
    let s = polar_deg.to_radians().sin();
    let cos_t = (1.0 - s * s / eps_binder.max(1.0)).max(1e-6).sqrt();
    let mut coherent = 0.0;
    let mut incoherent = 0.0;
    for g in grains {
        let x = k0 * g.diameter_nm;
        let de = g.delta_eps.norm();
        coherent += g.volume_fraction * de * x;
        incoherent += g.volume_fraction * de * de * x.powi(3) * k0 * thickness_nm / (24.0 * cos_t);
    }
    (coherent, incoherent)
}

/// Conservative estimate of the largest absolute error in R, T or A when a
/// layer of grains is replaced by the homogeneous slab of the volume-averaged
/// ε: `C_coh · coherent + C_inc · incoherent` ([`effective_medium_terms`])
/// with the measured constants [`EFFECTIVE_COHERENT`], [`EFFECTIVE_INCOHERENT`];
/// measured to hold for `k0 d ≤` [`EFFECTIVE_MAX_SIZE_PARAMETER`], PVC ≤ 0.3,
/// spheres dispersed by random sequential addition inside a flat binder.
pub fn effective_medium_error(
    grains: &[GrainTerm],
    eps_binder: f64,
    thickness_nm: f64,
    wavelength_nm: f64,
    polar_deg: f64,
) -> f64 {
    let (c, i) = effective_medium_terms(grains, eps_binder, thickness_nm, wavelength_nm, polar_deg);
    EFFECTIVE_COHERENT * c + EFFECTIVE_INCOHERENT * i
}

/// Gaussian elimination with partial pivoting on a 4×5 augmented matrix.
fn solve4(m: &mut [[C64; 5]; 4]) -> [C64; 4] {
    for c in 0..4 {
        let p = (c..4)
            .max_by(|&i, &j| m[i][c].norm().total_cmp(&m[j][c].norm()))
            .unwrap_or(c);
        m.swap(c, p);
        for r in c + 1..4 {
            let f = m[r][c] / m[c][c];
            let pivot = m[c];
            for (x, v) in m[r][c..].iter_mut().zip(&pivot[c..]) {
                *x -= f * v;
            }
        }
    }
    let mut x = [C64::new(0.0, 0.0); 4];
    for r in (0..4).rev() {
        let mut s = m[r][4];
        for k in r + 1..4 {
            s -= m[r][k] * x[k];
        }
        x[r] = s / m[r][r];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Textbook Airy formula (field reflection), for a thin, weakly absorbing
    /// slab where nothing can overflow.
    fn textbook(eps: C64, h: f64, wl: f64, polar: f64) -> (C64, C64) {
        let k0 = 2.0 * std::f64::consts::PI / wl;
        let kx = k0 * polar.to_radians().sin();
        let b = C64::new((k0 * k0 - kx * kx).sqrt(), 0.0);
        let g = sqrt_branch(eps * k0 * k0 - kx * kx);
        let r12 = (b - g) / (b + g);
        let t12 = 2.0 * b / (b + g);
        let t21 = 2.0 * g / (b + g);
        let p = (C64::i() * g * h).exp();
        let den = 1.0 - r12 * r12 * p * p;
        let r = r12 - t12 * t21 * r12 * p * p / den;
        let t = t12 * t21 * p / den;
        (r, t)
    }

    #[test]
    fn matches_the_textbook_formula_and_balances_energy() {
        for (eps, h, wl, polar) in [
            (C64::new(2.4, 0.0), 1000.0, 550.0, 0.0),
            (C64::new(2.2, 0.3), 700.0, 450.0, 40.0),
            (C64::new(1.96, 0.05), 1500.0, 650.0, 75.0),
        ] {
            let s = slab(eps, h, wl, polar);
            let (r, t) = textbook(eps, h, wl, polar);
            assert!((s.r - r).norm() < 1e-12 && (s.t - t).norm() < 1e-12);
            let balance = s.r.norm_sqr() + s.t.norm_sqr() + s.absorption - 1.0;
            assert!(balance.abs() < 1e-12, "balance {balance}");
        }
    }

    #[test]
    fn opaque_slab_stays_finite() {
        // Im γ H ≈ 1e4: the transmitted wave underflows to 0, nothing overflows.
        let s = slab(C64::new(1.0, 30.0), 20_000.0, 400.0, 60.0);
        assert!(s.r.is_finite() && s.t.is_finite() && s.absorption.is_finite());
        assert!(s.t.norm() < 1e-300_f64.sqrt());
        assert!((s.r.norm_sqr() + s.absorption - 1.0).abs() < 1e-12);
    }
}
