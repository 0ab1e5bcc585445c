//! The scalar sphere: partial-wave solution of the scalar Helmholtz equation
//! for one homogeneous sphere in a homogeneous host (the scalar analogue of
//! Mie theory, the single scatterer consistent with the solver's equation).
//!
//! Host wavenumber `k`, sphere radius `a`, relative permittivity `ε = ε_s/ε_h`
//! (inside wavenumber `k_s = k √ε`). Outside
//! `u = Σ iˡ(2l+1)[j_l(kr) + c_l h_l(kr)] P_l(cos θ)`, inside `d_l j_l(k_s r)`;
//! u and ∂u/∂r continuous give
//! `c_l = −[k j_l'(ka) j_l(k_s a) − k_s j_l(ka) j_l'(k_s a)] /
//!        [k h_l'(ka) j_l(k_s a) − k_s h_l(ka) j_l'(k_s a)]`,
//! the far-field amplitude `f(θ) = (1/ik) Σ (2l+1) c_l P_l(cos θ)`, and
//! - `σ_sca = ∫|f|² dΩ = (4π/k²) Σ (2l+1) |c_l|²`,
//! - `σ_ext = (4π/k) Im f(0) = −(4π/k²) Σ (2l+1) Re c_l` (optical theorem),
//! - `σ_abs = σ_ext − σ_sca`,
//! - `g = ∫|f|² cos θ dΩ / σ_sca = Σ 2(l+1) Re(c_l c*_{l+1}) / Σ (2l+1)|c_l|²`
//!   (from `∫ P_l P_{l+1} x dx = 2(l+1)/((2l+1)(2l+3))`).

use super::special::{bessel_j, hankel, legendre_moments};
use num_complex::Complex64 as C64;
use std::f64::consts::PI;

/// f_l'(z) = f_{l−1}(z) − (l+1)/z f_l(z) for l ≥ 1; f_0' = −f_1.
fn derivative(f: &[C64], z: C64) -> Vec<C64> {
    (0..f.len() - 1)
        .map(|l| {
            if l == 0 {
                -f[1]
            } else {
                f[l - 1] - (l + 1) as f64 / z * f[l]
            }
        })
        .collect()
}

/// Partial-wave coefficients c_l, l = 0..=lmax, of a sphere of radius `a`
/// and relative permittivity `eps_rel` in a host of wavenumber `k`.
pub fn coefficients(k: f64, eps_rel: C64, a: f64, lmax: usize) -> Vec<C64> {
    let ks = eps_rel.sqrt() * k;
    let x = C64::new(k * a, 0.0);
    let xs = ks * a;
    let j = bessel_j(x, lmax + 1);
    let js = bessel_j(xs, lmax + 1);
    let h = hankel(k * a, lmax + 1);
    let (dj, djs, dh) = (derivative(&j, x), derivative(&js, xs), derivative(&h, x));
    (0..=lmax)
        .map(|l| {
            let num = k * dj[l] * js[l] - ks * j[l] * djs[l];
            let den = k * dh[l] * js[l] - ks * h[l] * djs[l];
            -num / den
        })
        .collect()
}

/// Far-field amplitude f at `cos θ` from the coefficients.
pub fn amplitude(c: &[C64], k: f64, cos_t: f64) -> C64 {
    let (mut p0, mut p1) = (1.0, cos_t);
    let mut f = c[0] * p0;
    for (l, cl) in c.iter().enumerate().skip(1) {
        f += cl * (2 * l + 1) as f64 * p1;
        let p2 = ((2 * l + 1) as f64 * cos_t * p1 - l as f64 * p0) / (l + 1) as f64;
        p0 = p1;
        p1 = p2;
    }
    f / (C64::i() * k)
}

/// Enough partial waves for size parameter `x` = k a and inside index `m`:
/// Wiscombe's `x + 4 x^{1/3} + 2` for the larger of x and |m| x, plus margin.
pub fn orders_needed(x: f64, m: f64) -> usize {
    let y = x * m.max(1.0);
    (y + 4.0 * y.cbrt() + 2.0).ceil() as usize + 4
}

/// Cross sections (area units of `a²`) and asymmetry parameter of one sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrossSections {
    pub extinction: f64,
    pub scattering: f64,
    /// `σ_ext − σ_sca`.
    pub absorption: f64,
    /// Mean cosine of the scattering angle, ⟨cos θ⟩ weighted by |f|².
    pub asymmetry: f64,
}

/// σ_ext, σ_sca, σ_abs and g of a sphere of radius `a` and relative
/// permittivity `eps_rel` in a host of wavenumber `k` (scalar waves).
pub fn cross_sections(k: f64, eps_rel: C64, a: f64) -> CrossSections {
    if a <= 0.0 {
        return CrossSections {
            extinction: 0.0,
            scattering: 0.0,
            absorption: 0.0,
            asymmetry: 0.0,
        };
    }
    let lmax = orders_needed(k * a, eps_rel.sqrt().norm());
    let c = coefficients(k, eps_rel, a, lmax);
    let norm = 4.0 * PI / (k * k);
    let mut sca = 0.0;
    let mut ext = 0.0;
    let mut cos_sum = 0.0;
    for (l, cl) in c.iter().enumerate() {
        let w = (2 * l + 1) as f64;
        sca += w * cl.norm_sqr();
        ext -= w * cl.re;
        if let Some(next) = c.get(l + 1) {
            cos_sum += 2.0 * (l + 1) as f64 * (cl * next.conj()).re;
        }
    }
    let asymmetry = if sca > 0.0 { cos_sum / sca } else { 0.0 };
    let (scattering, extinction) = (norm * sca, norm * ext);
    CrossSections {
        extinction,
        scattering,
        absorption: extinction - scattering,
        asymmetry,
    }
}

/// Legendre moments of the scattered intensity, `m_n = 2π ∫₋₁¹ |f(θ)|² P_n(cos θ) d cos θ`
/// for `n = 0..=2 l_max` (all that are non-zero: `|f|²` is a polynomial of
/// degree `2 l_max` in `cos θ`), of a sphere of radius `a` and relative
/// permittivity `eps_rel` in a host of wavenumber `k`. `m_0 = σ_sca`,
/// `m_1/m_0 = g`, and the normalised phase function is
/// `p(θ) = 4π|f|²/σ_sca = Σ (2n + 1) (m_n/m_0) P_n(cos θ)`. Computed by
/// Gauss–Legendre quadrature with `2 l_max + 2` nodes, exact for these
/// polynomials (empty for `a ≤ 0`).
pub fn phase_moments(k: f64, eps_rel: C64, a: f64) -> Vec<f64> {
    if a <= 0.0 {
        return Vec::new();
    }
    let lmax = orders_needed(k * a, eps_rel.sqrt().norm());
    let c = coefficients(k, eps_rel, a, lmax);
    legendre_moments(2 * lmax, |x| amplitude(&c, k, x).norm_sqr())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lossless_sphere_absorbs_nothing() {
        // The optical theorem: σ_ext = σ_sca, so σ_abs = 0 to rounding.
        for (a, eps) in [(80.0, 2.25), (300.0, 1.2), (20.0, 4.0), (600.0, 2.0)] {
            let k = 2.0 * PI / 500.0;
            let c = cross_sections(k, C64::new(eps, 0.0), a);
            assert!(
                c.absorption.abs() < 1e-10 * c.scattering,
                "a {a}, ε {eps}: {c:?}"
            );
        }
    }

    #[test]
    fn rayleigh_limit() {
        // ka ≪ 1: f = k² a³ (ε − 1)/3 isotropic, so σ_sca = 4π|f|², g → 0,
        // and σ_abs = k V Im ε (the field inside is the incident one).
        let (k, a, eps) = (2.0 * PI / 500.0, 2.0, C64::new(2.25, 0.1));
        let c = cross_sections(k, eps, a);
        let f = k * k * a.powi(3) * (eps - 1.0).norm() / 3.0;
        let sca = 4.0 * PI * f * f;
        assert!((c.scattering - sca).abs() < 1e-3 * sca, "{c:?} vs {sca}");
        let abs = k * 4.0 / 3.0 * PI * a.powi(3) * eps.im;
        assert!((c.absorption - abs).abs() < 1e-3 * abs, "{c:?} vs {abs}");
        assert!(c.asymmetry.abs() < 1e-3, "{c:?}");
    }

    #[test]
    fn absorbing_spheres_absorb() {
        let k = 2.0 * PI / 500.0;
        for a in [5.0, 30.0, 100.0, 400.0] {
            for eps in [
                C64::new(2.25, 0.01),
                C64::new(1.2, 0.5),
                C64::new(-3.0, 1.0),
            ] {
                let c = cross_sections(k, eps, a);
                assert!(c.absorption >= 0.0, "a {a}, ε {eps}: {c:?}");
                assert!(c.scattering > 0.0 && c.asymmetry.abs() <= 1.0);
            }
        }
    }

    #[test]
    fn asymmetry_is_the_mean_cosine_of_the_amplitude() {
        // g from the coefficients against ∫|f|² cos θ dΩ / ∫|f|² dΩ by quadrature.
        let (k, a, eps) = (2.0 * PI / 500.0, 150.0, C64::new(2.4, 0.05));
        let c = coefficients(k, eps, a, orders_needed(k * a, eps.sqrt().norm()));
        let n = 20_000;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            let x = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
            let f2 = amplitude(&c, k, x).norm_sqr();
            num += f2 * x;
            den += f2;
        }
        let g = cross_sections(k, eps, a).asymmetry;
        assert!((g - num / den).abs() < 1e-6, "{g} vs {}", num / den);
        let sca = 2.0 * PI * den * 2.0 / n as f64;
        let s = cross_sections(k, eps, a).scattering;
        assert!((sca - s).abs() < 1e-6 * s, "{sca} vs {s}");
    }
}
