//! Closed-form checks of the Mie series; the comparison with an independent
//! code is tests/mie_reference.rs.

use super::*;

fn c(re: f64, im: f64) -> C64 {
    C64::new(re, im)
}

#[test]
fn rayleigh_limit() {
    // x ≪ 1: Q_sca = (8/3) x⁴ |(m² − 1)/(m² + 2)|², Q_abs = 4x Im((m² − 1)/(m² + 2)),
    // with relative corrections of order x².
    let x = 0.01;
    for m in [c(1.5, 0.0), c(1.5, 0.1), c(2.7, 0.4), c(0.2, 3.0)] {
        let q = coefficients(m, x).efficiencies();
        let alpha = (m * m - 1.0) / (m * m + 2.0);
        let sca = 8.0 / 3.0 * x.powi(4) * alpha.norm_sqr();
        assert!(
            (q.scattering - sca).abs() < 1e-3 * sca,
            "{m}: {q:?} vs {sca}"
        );
        let abs = 4.0 * x * alpha.im;
        if m.im > 0.0 {
            assert!(
                (q.absorption - abs).abs() < 1e-3 * abs,
                "{m}: {q:?} vs {abs}"
            );
        }
        // Dipole scattering: g → 0, and S1 = S2/cos θ.
        assert!(q.asymmetry.abs() < 1e-3, "{q:?}");
        let coeffs = coefficients(m, x);
        let (s1, s2) = coeffs.amplitudes(0.4);
        assert!((s2 - 0.4 * s1).norm() < 1e-3 * s1.norm(), "{s1} {s2}");
    }
}

#[test]
fn lossless_spheres_absorb_nothing() {
    for x in [0.05, 0.7, 3.0, 12.0, 30.0] {
        for m in [1.005, 1.33, 1.75, 3.0] {
            let q = coefficients(c(m, 0.0), x).efficiencies();
            assert!(
                q.absorption.abs() < 1e-12 * q.scattering,
                "x {x}, m {m}: {q:?}"
            );
        }
    }
}

#[test]
fn absorbing_spheres_absorb_and_keep_g_in_range() {
    for x in [0.05, 0.7, 3.0, 12.0, 30.0] {
        for m in [c(1.5, 1e-3), c(1.75, 0.05), c(3.0, 1.0), c(0.3, 3.0)] {
            let q = coefficients(m, x).efficiencies();
            assert!(q.absorption > 0.0, "x {x}, m {m}: {q:?}");
            assert!(q.scattering > 0.0 && q.asymmetry.abs() <= 1.0, "{q:?}");
            assert!(q.extinction.is_finite() && q.extinction < 6.0, "{q:?}");
        }
    }
}

#[test]
fn optical_theorem_and_symmetries_of_the_amplitudes() {
    // Q_ext = (4/x²) Re S(0), S1(0) = S2(0), S1(π) = −S2(π).
    for (m, x) in [(c(1.5, 0.01), 3.0), (c(3.0, 1.0), 30.0), (c(0.3, 3.0), 2.0)] {
        let coeffs = coefficients(m, x);
        let q = coeffs.efficiencies();
        let (f1, f2) = coeffs.amplitudes(1.0);
        assert!((f1 - f2).norm() < 1e-12 * f1.norm());
        let theorem = 4.0 / (x * x) * f1.re;
        assert!((theorem - q.extinction).abs() < 1e-12 * q.extinction);
        let (b1, b2) = coeffs.amplitudes(-1.0);
        assert!(
            (b1 + b2).norm() < 1e-12 * b1.norm().max(1e-300),
            "{b1} {b2}"
        );
    }
}

#[test]
fn moments_hold_the_cross_section_and_asymmetry() {
    // m_0 = σ_sca and m_1/m_0 = g, the latter against the closed-form
    // series of g; and p(θ) = Σ (2n+1) χ_n P_n reproduces (|S1|² + |S2|²)/2.
    let (k, a) = (2.0 * PI / 500.0, 300.0);
    for eps in [c(2.25, 0.0), c(3.0, 0.2), c(-10.0, 1.0)] {
        let cs = cross_sections(k, eps, a);
        let m = phase_moments(k, eps, a);
        assert!(
            (m[0] - cs.scattering).abs() < 1e-10 * cs.scattering,
            "{eps}"
        );
        assert!((m[1] / m[0] - cs.asymmetry).abs() < 1e-10, "{eps}");
        let coeffs = coefficients(eps.sqrt(), k * a);
        for mu in [-0.8, 0.1, 0.95] {
            let (s1, s2) = coeffs.amplitudes(mu);
            let direct = 0.5 * (s1.norm_sqr() + s2.norm_sqr()) / (k * k);
            let (mut p0, mut p1, mut sum) = (1.0, mu, m[0] / (4.0 * PI));
            for (n, mn) in m.iter().enumerate().skip(1) {
                sum += (2 * n + 1) as f64 * mn / (4.0 * PI) * p1;
                let p2 = ((2 * n + 1) as f64 * mu * p1 - n as f64 * p0) / (n + 1) as f64;
                p0 = p1;
                p1 = p2;
            }
            assert!(
                (sum - direct).abs() < 1e-9 * direct,
                "{eps} {mu}: {sum} {direct}"
            );
        }
    }
}

#[test]
fn terms_follow_wiscombe() {
    assert_eq!(terms_needed(0.01), 3);
    assert_eq!(terms_needed(1.0), 6);
    assert_eq!(terms_needed(8.0), 17);
    assert_eq!(terms_needed(30.0), 44);
}

#[test]
fn no_sphere_scatters_nothing() {
    let cs = cross_sections(0.01, c(2.0, 0.1), 0.0);
    assert_eq!(cs.scattering, 0.0);
    assert!(phase_moments(0.01, c(2.0, 0.1), 0.0).is_empty());
    let q = coefficients(c(1.0, 0.0), 5.0).efficiencies();
    assert!(
        q.extinction.abs() < 1e-15 && q.scattering.abs() < 1e-15,
        "{q:?}"
    );
}
