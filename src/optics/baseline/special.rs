//! Special functions of the single scatterers ([`super::sphere`],
//! [`super::mie`]): spherical Bessel and Hankel functions, and the Legendre
//! moments of an intensity over the scattering angle.

use num_complex::Complex64 as C64;
use std::f64::consts::PI;

/// Spherical Bessel j_0..=j_lmax of a complex argument by Miller's downward
/// recurrence, normalised by j_0 = sin z / z.
pub fn bessel_j(z: C64, lmax: usize) -> Vec<C64> {
    let start = lmax + 30 + z.norm() as usize;
    let mut j = vec![C64::new(0.0, 0.0); start + 2];
    j[start + 1] = C64::new(0.0, 0.0);
    j[start] = C64::new(1e-30, 0.0);
    for l in (1..=start).rev() {
        j[l - 1] = (2 * l + 1) as f64 / z * j[l] - j[l + 1];
        // Keep the recurrence in range for large orders.
        if j[l - 1].norm() > 1e250 {
            for v in &mut j[l - 1..] {
                *v *= 1e-250;
            }
        }
    }
    let scale = (z.sin() / z) / j[0];
    j.truncate(lmax + 1);
    j.iter().map(|v| v * scale).collect()
}

/// Spherical Hankel h_l^(1) of a real argument by upward recurrence (stable).
pub fn hankel(x: f64, lmax: usize) -> Vec<C64> {
    let i = C64::i();
    let mut h = vec![-i * (i * x).exp() / x];
    h.push((i * x).exp() * (-i / (x * x) - 1.0 / x));
    for l in 1..lmax {
        let next = (2 * l + 1) as f64 / x * h[l] - h[l - 1];
        h.push(next);
    }
    h.truncate(lmax + 1);
    h
}

/// Spherical Bessel y_0..=y_lmax of a real argument `x > 0` by upward
/// recurrence from `y_0 = −cos x / x`, `y_1 = −cos x / x² − sin x / x`
/// (the growing solution, so the recurrence is stable).
pub fn bessel_y(x: f64, lmax: usize) -> Vec<f64> {
    let (s, c) = x.sin_cos();
    let mut y = vec![-c / x, -c / (x * x) - s / x];
    for l in 1..lmax {
        let next = (2 * l + 1) as f64 / x * y[l] - y[l - 1];
        y.push(next);
    }
    y.truncate(lmax + 1);
    y
}

/// Legendre moments of an intensity over the scattering angle,
/// `m_n = 2π ∫₋₁¹ i(μ) P_n(μ) dμ` for `n = 0..=degree`, where `i` is a
/// polynomial of degree at most `degree` in `μ = cos θ`: Gauss–Legendre with
/// `degree + 2` nodes, exact for these integrands (degree ≤ 2 degree).
pub fn legendre_moments(degree: usize, intensity: impl Fn(f64) -> f64) -> Vec<f64> {
    let (x, w) = super::ordinates::gauss_legendre(degree + 2);
    let mut m = vec![0.0; degree + 1];
    for (&x, &w) in x.iter().zip(&w) {
        let f2 = intensity(x) * w * 2.0 * PI;
        let (mut p0, mut p1) = (1.0, x);
        m[0] += f2;
        for (n, mn) in m.iter_mut().enumerate().skip(1) {
            *mn += f2 * p1;
            let p2 = ((2 * n + 1) as f64 * x * p1 - n as f64 * p0) / (n + 1) as f64;
            p0 = p1;
            p1 = p2;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bessel_functions_match_closed_forms() {
        // j_2, y_2 and h_2 in closed form at a few arguments (the closed
        // form of j_2 cancels to about 1e-12 at x = 0.3).
        for x in [0.3, 2.0, 17.5] {
            let (s, c) = f64::sin_cos(x);
            let j2 = (3.0 / (x * x) - 1.0) * s / x - 3.0 * c / (x * x);
            let y2 = -(3.0 / (x * x) - 1.0) * c / x - 3.0 * s / (x * x);
            let j = bessel_j(C64::new(x, 0.0), 4)[2];
            let y = bessel_y(x, 4)[2];
            let h = hankel(x, 4)[2];
            assert!((j.re - j2).abs() < 1e-11 * j2.abs(), "{x}: {j} {j2}");
            assert!((y - y2).abs() < 1e-12 * y2.abs(), "{x}: {y} {y2}");
            assert!((h - C64::new(j2, y2)).norm() < 1e-12 * y2.abs().max(1.0));
        }
    }

    #[test]
    fn moments_of_polynomials_are_exact() {
        // i(μ) = μ²: m_0 = 2π · 2/3, m_1 = 0, m_2 = 2π · 4/15.
        let m = legendre_moments(2, |x| x * x);
        assert!((m[0] - 4.0 * PI / 3.0).abs() < 1e-14);
        assert!(m[1].abs() < 1e-14);
        assert!((m[2] - 8.0 * PI / 15.0).abs() < 1e-14, "{m:?}");
    }
}
