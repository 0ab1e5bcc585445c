//! Numerical traps of METHOD §4: a harmonic on a guided-mode resonance of the
//! lossless binder slab (1 − ρ²E ≈ 0), and evanescent harmonics with large
//! Im γ·H. No inf or NaN; the solve converges or fails loudly.
use inksim::config::Method;
use inksim::optics::farfield::efficiencies;
use inksim::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;

mod common;
use common::layers::{in_binder, EPS_B};

/// Lateral wavenumber of the lowest guided mode of the binder slab in vacuum
/// (zero of Im(ρ e^{iγH}), |ρ e^{iγH}| = 1 for k0 < κ < k0 n_b), by bisection.
fn guided_kappa(k0: f64, h: f64) -> f64 {
    let f = |kap: f64| {
        let g = (k0 * k0 * EPS_B - kap * kap).sqrt();
        let b = C64::new(0.0, (kap * kap - k0 * k0).sqrt());
        let rho = (g - b) / (g + b);
        (rho * C64::new(0.0, g * h).exp()).im
    };
    let (mut lo, mut hi) = (k0 * 1.5579, k0 * 1.3);
    // Walk down from the light line of the binder to bracket the first sign change.
    let steps = 2000;
    let mut prev = (lo, f(lo));
    for s in 1..=steps {
        let k = k0 * (1.5579 - (1.5579 - 1.0001) * s as f64 / steps as f64);
        let v = f(k);
        if v.signum() != prev.1.signum() {
            lo = prev.0;
            hi = k;
            break;
        }
        prev = (k, v);
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid).signum() == f(lo).signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn stripe_layer(nx: usize, nz: usize, n: C64) -> Array3<C64> {
    Array3::from_shape_fn((nz, 1, nx), |(k, _, i)| {
        if i < nx / 4 && k >= nz / 4 && k < 3 * nz / 4 {
            n * n
        } else {
            C64::new(EPS_B, 0.0)
        }
    })
}

#[test]
fn order_on_a_guided_resonance_stays_finite() {
    let lambda = 550.0;
    let h = 600.0;
    let k0 = 2.0 * std::f64::consts::PI / lambda;
    let kg = guided_kappa(k0, h);
    assert!(kg > k0 && kg < k0 * 1.558);
    // The (1, 0) order at normal incidence sits on the guided mode.
    let period = 2.0 * std::f64::consts::PI / kg;
    let (nx, nz) = (32, 60);
    let eps = stripe_layer(nx, nz, C64::new(1.4, 0.3));
    let lat = Problem::lattice([nx, 1, nz], [period, period, h], lambda, 0.0, 0.0);
    assert!((lat.kappa(1, 0)[0] - kg).abs() < 1e-12 * kg);
    let p = in_binder(lat, &eps);
    for method in [Method::Auto, Method::TimeMarching, Method::BiCgStab] {
        match solver::solve(
            &p,
            method,
            &Controls {
                tolerance: 1e-8,
                max_iterations: 20000,
                precision: inksim::config::Precision::F64,
                background: inksim::config::Background::DEFAULT,
            },
        ) {
            Ok(sol) => {
                assert!(sol
                    .field
                    .iter()
                    .all(|c| c.re.is_finite() && c.im.is_finite()));
                let ff = efficiencies(&sol);
                eprintln!(
                    "{method:?}: R {} T {} A {} balance {:.1e} ({} it)",
                    ff.total_reflectance,
                    ff.total_transmittance,
                    ff.absorption,
                    ff.energy_balance,
                    sol.record.iterations
                );
                assert!(
                    ff.energy_balance.abs() < 1e-4,
                    "{method:?}: {}",
                    ff.energy_balance
                );
            }
            Err(e) => {
                let text = e.to_string();
                eprintln!("{method:?}: {text}");
                assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
                panic!("{method:?} failed on the resonance: {text}");
            }
        }
    }
}

#[test]
fn strongly_evanescent_harmonics_in_a_thick_layer_stay_finite() {
    // 3 µm layer, 10 nm lateral cells: the highest harmonics have
    // Im γ·H ≈ π/10 nm · 3000 nm ≈ 940, beyond e^{±709} overflow if written carelessly.
    let (nx, nz) = (64, 150);
    let period = 640.0;
    let h = 3000.0;
    let eps = stripe_layer(nx, nz, C64::new(1.4, 0.8));
    let lat = Problem::lattice([nx, 1, nz], [period, period, h], 450.0, 40.0, 0.0);
    let p = in_binder(lat, &eps);
    let sol = solver::solve(
        &p,
        Method::Auto,
        &Controls {
            tolerance: 1e-8,
            max_iterations: 20000,
            precision: inksim::config::Precision::F64,
            background: inksim::config::Background::DEFAULT,
        },
    )
    .expect("converges");
    assert!(sol
        .field
        .iter()
        .all(|c| c.re.is_finite() && c.im.is_finite()));
    assert!(sol
        .r
        .iter()
        .chain(sol.t.iter())
        .all(|c| c.re.is_finite() && c.im.is_finite()));
    let ff = efficiencies(&sol);
    assert!(ff.energy_balance.abs() < 1e-4, "{}", ff.energy_balance);
}
