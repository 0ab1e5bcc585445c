//! A dilute lattice of small spheres against the single-scattering limit of
//! the scalar sphere series (METHOD §7), the partial waves of
//! `optics::baseline::sphere`.
//!
//! One sphere (radius a, permittivity ε_s) per period L × L in vacuum (the
//! "binder" has n = 1, so the slab background is plain vacuum). Scalar
//! partial waves: outside `u = Σ iˡ(2l+1)[j_l(kr) + c_l h_l(kr)] P_l(cos θ)`,
//! inside `d_l j_l(k_s r)`; u and ∂u/∂r continuous give
//! `c_l = −[k j_l'(ka) j_l(k_s a) − k_s j_l(ka) j_l'(k_s a)] /
//!        [k h_l'(ka) j_l(k_s a) − k_s h_l(ka) j_l'(k_s a)]`,
//! and the far-field amplitude `f(θ) = (1/ik) Σ (2l+1) c_l P_l(cos θ)`.
//! Summing the lattice of spherical waves by the Weyl expansion, a
//! diffracted order carries `|u_mn| = 2π |f(θ_s)| / (L² β_mn)`, so
//! `R_mn, T_mn = (2π/L²)² |f(θ_s)|² / (β_mn β_00)` with θ_s the angle
//! between the incident direction and the order's. Multiple scattering
//! between the spheres is what the single-scattering limit leaves out; it
//! is of relative order |f| k / 2 (see the test), so the lattice must be
//! weak, not merely sparse.

use inksim::config::Method;
use inksim::optics::baseline::sphere::{amplitude, coefficients};
use inksim::optics::farfield::efficiencies;
use inksim::solver::{self, Controls, Problem};
use num_complex::Complex64 as C64;
use std::f64::consts::PI;

mod common;
use common::layers::one_sphere_lattice;

#[test]
fn lossless_sphere_obeys_the_optical_theorem() {
    // σ_ext = (4π/k) Im f(0) equals σ_sca = (4π/k²) Σ (2l+1)|c_l|².
    let (k, a) = (2.0 * PI / 500.0, 80.0);
    let c = coefficients(k, C64::new(2.25, 0.0), a, 12);
    let ext = 4.0 * PI / k * amplitude(&c, k, 1.0).im;
    let sca: f64 = 4.0 * PI / (k * k)
        * c.iter()
            .enumerate()
            .map(|(l, c)| (2 * l + 1) as f64 * c.norm_sqr())
            .sum::<f64>();
    assert!((ext - sca).abs() < 1e-10 * sca, "{ext} vs {sca}");
}

#[test]
fn rayleigh_limit_of_the_partial_waves() {
    // ka ≪ 1: f → k² a³ (ε − 1)/3 in every direction (scalar Rayleigh).
    let (k, a, eps) = (2.0 * PI / 500.0, 1.0, C64::new(2.25, 0.1));
    let c = coefficients(k, eps, a, 8);
    let f = amplitude(&c, k, 0.3);
    let rayleigh = k * k * a.powi(3) * (eps - 1.0) / 3.0;
    assert!(
        (f - rayleigh).norm() / rayleigh.norm() < 1e-3,
        "{f} vs {rayleigh}"
    );
}

/// Worst relative error of the diffracted orders' R and T against single
/// scattering, for one sphere per period on a grid of `cells` lateral cells.
fn worst_error(eps_s: C64, polar_deg: f64, l: f64, cells: usize) -> f64 {
    let (h, a, wl) = (200.0, 80.0, 500.0);
    let (eps, lattice) = one_sphere_lattice(l, h, a, cells, eps_s, wl, polar_deg);
    let sol = solver::solve(
        &Problem {
            tensor: None,
            lattice,
            eps: &eps,
            eps_binder: 1.0,
            wave: inksim::solver::Wave::Scalar,
        },
        Method::Auto,
        &Controls {
            tolerance: 1e-10,
            max_iterations: 2000,
            precision: inksim::config::Precision::F64,
            background: inksim::config::Background::DEFAULT,
        },
    )
    .unwrap();
    let eff = efficiencies(&sol);
    let k = 2.0 * PI / wl;
    let c = coefficients(k, eps_s, a, 12);
    let s = polar_deg.to_radians();
    let k_in = [s.sin(), 0.0, s.cos()];
    let beta00 = k * s.cos();
    let mut worst: f64 = 0.0;
    let mut count = 0;
    for o in &eff.orders {
        if (o.m, o.n) == (0, 0) || o.theta_deg > 75.0 {
            continue;
        }
        let (t, p) = (o.theta_deg.to_radians(), o.phi_deg.to_radians());
        let beta = k * t.cos();
        for (sign, got) in [(-1.0, o.reflectance), (1.0, o.transmittance)] {
            let k_out = [t.sin() * p.cos(), t.sin() * p.sin(), sign * t.cos()];
            let cos_s = k_in[0] * k_out[0] + k_in[1] * k_out[1] + k_in[2] * k_out[2];
            let f = amplitude(&c, k, cos_s);
            let expect = (2.0 * PI / (l * l)).powi(2) * f.norm_sqr() / (beta * beta00);
            worst = worst.max((got - expect).abs() / expect);
            count += 1;
        }
    }
    assert!(count >= 20, "only {count} orders compared");
    assert!(eff.energy_balance.abs() < 1e-8);
    worst
}

#[test]
fn weak_sphere_lattice_converges_to_single_scattering() {
    // ε_s = 1.01 (ka = 1): the spheres' mutual scattering, of relative
    // order |f| k / 2 (the lattice sum of the propagating orders does not
    // shrink with dilution), is negligible, so what is left is
    // discretisation. Measured worst relative error over all diffracted
    // orders up to 75° at 0°: 5.3e-2, 1.8e-2, 6.6e-3, 4.4e-3 for 30, 15,
    // 10, 7.5 nm cells (about second order); 4.6e-3 at 30° and 10 nm.
    // For ka ≈ 1 and ε_s = 2.25, |f| k / 2 ≈ 0.2: the lattice then differs
    // from single scattering by 3–30 % depending on L/λ (measured), so
    // strong spheres are no test of the single-scattering limit.
    let coarse = worst_error(C64::new(1.01, 0.0), 0.0, 1500.0, 100);
    let fine = worst_error(C64::new(1.01, 0.0), 0.0, 1500.0, 150);
    assert!(fine < 0.5 * coarse && fine < 0.01, "{coarse} → {fine}");
    let oblique = worst_error(C64::new(1.01, 0.01), 30.0, 1500.0, 150);
    assert!(oblique < 0.01, "{oblique}");
}
