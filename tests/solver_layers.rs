//! Solves of real grain layers: energy balance, Born divergence and the
//! time-marching rescue, the molecular-mixture limit, thread independence.
use inksim::config::Method;
use inksim::geometry::{Geometry, GeometryStats, Particle, Sphere};
use inksim::optics::farfield::efficiencies;
use inksim::solver::{self, Controls, Problem, SolveError};
use num_complex::Complex64 as C64;

mod common;
use common::layers::{in_binder, layer_eps, packed_rsa as packed, EPS_B};
use common::threads::on_threads;
const CTL: Controls = Controls {
    tolerance: 1e-8,
    max_iterations: 20000,
    precision: inksim::config::Precision::F64,
    background: inksim::config::Background::DEFAULT,
};

#[test]
fn energy_balance_on_random_absorbing_layer() {
    let size = [1000.0, 1000.0, 600.0];
    let geom = packed(size, 200.0, 0.2, 3);
    let cells = [40, 40, 60];
    let (eps, _) = layer_eps(&geom, cells, C64::new(1.4, 0.5));
    for polar in [0.0, 45.0] {
        let lat = Problem::lattice([40, 40, 60], size, 520.0, polar, 0.0);
        let sol = solver::solve(&in_binder(lat, &eps), Method::TimeMarching, &CTL)
            .expect("time-marching converges");
        let ff = efficiencies(&sol);
        eprintln!(
            "polar {polar}: R {} T {} A {} balance {:.2e} ({} it)",
            ff.total_reflectance,
            ff.total_transmittance,
            ff.absorption,
            ff.energy_balance,
            sol.record.iterations
        );
        assert!(ff.energy_balance.abs() < 1e-4);
        assert!(
            ff.absorption > 0.05 && ff.orders.len() > 5,
            "a real scattering, absorbing case"
        );
        assert!(
            ff.orders
                .iter()
                .any(|o| (o.m, o.n) != (0, 0) && o.reflectance > 1e-6),
            "diffuse orders present"
        );
    }
}

/// Spheres on a jittered cubic lattice at 40 % volume fraction (denser than
/// random sequential addition reaches).
fn dense_lattice() -> (Geometry, [f64; 3]) {
    let d = 180.0;
    let a = d * (std::f64::consts::PI / (6.0 * 0.4)).cbrt();
    let (nl, nzl) = (4usize, 4usize);
    let size = [a * nl as f64, a * nl as f64, a * nzl as f64];
    let mut particles = vec![];
    for i in 0..nl {
        for j in 0..nl {
            for k in 0..nzl {
                let c = [
                    (i as f64 + 0.5) * a,
                    (j as f64 + 0.5) * a,
                    (k as f64 + 0.5) * a,
                ];
                particles.push(Particle {
                    species: 0,
                    spheres: vec![Sphere {
                        center: c,
                        radius: d / 2.0,
                    }],
                });
            }
        }
    }
    let n = particles.len();
    let frac = n as f64 * std::f64::consts::PI * d.powi(3) / 6.0 / (size[0] * size[1] * size[2]);
    let stats = GeometryStats {
        count: vec![n],
        target_fraction: vec![0.4],
        achieved_fraction: vec![frac],
        min_gap_nm: a - d,
        attempts: n as u64,
        worst_overlap_nm: 0.0,
        order_parameter: None,
        relax_steps: 0,
    };
    (
        Geometry {
            size_nm: size,
            particles,
            stats,
        },
        size,
    )
}

#[test]
fn born_reports_divergence_and_time_marching_converges() {
    let (geom, size) = dense_lattice();
    let cells = [32, 32, 64];
    let (eps, f) = layer_eps(&geom, cells, C64::new(1.4, 0.8));
    assert!((f - 0.4).abs() < 0.01, "fill {f}");
    let lat = Problem::lattice([32, 32, 64], size, 450.0, 20.0, 0.0);
    let p = in_binder(lat, &eps);
    match solver::solve(&p, Method::Born, &CTL) {
        Err(SolveError::Diverged { .. }) => {}
        Err(e) => panic!("expected divergence, got {e}"),
        Ok(s) => panic!("Born returned a result with residual {}", s.record.residual),
    }
    let tm = solver::solve(&p, Method::TimeMarching, &CTL).expect("time-marching converges");
    let ff = efficiencies(&tm);
    assert!(
        tm.record.residual <= 1e-8 && ff.energy_balance.abs() < 1e-4,
        "{}",
        ff.energy_balance
    );
    let auto = solver::solve(&p, Method::Auto, &CTL).expect("auto converges");
    // auto must not trust Born here, and must say why.
    assert_ne!(auto.record.method, Method::Born, "{}", auto.record.note);
    assert!(
        auto.record.note.contains("skipped Born") || auto.record.note.contains("falling back"),
        "{}",
        auto.record.note
    );
    assert!((efficiencies(&auto).total_reflectance - ff.total_reflectance).abs() < 1e-6);
}

#[test]
fn shrinking_grains_approach_the_volume_averaged_slab() {
    let size = [480.0, 480.0, 500.0];
    let n_p = C64::new(1.4, 0.3);
    let cells = [48, 48, 50];
    let lambda = 600.0;
    let mut errs = vec![];
    for d in [160.0, 80.0, 40.0, 20.0] {
        let geom = packed(size, d, 0.2, 11);
        let (eps, f) = layer_eps(&geom, cells, n_p);
        let lat = Problem::lattice([48, 48, 50], size, lambda, 0.0, 0.0);
        let sol = solver::solve(&in_binder(lat, &eps), Method::Auto, &CTL).expect("solve");
        let ff = efficiencies(&sol);
        let mean = (1.0 - f) * EPS_B + f * n_p * n_p;
        let (r0, t0) = common::airy::airy_power(lat.k0, mean, 0.0, size[2]);
        let err = (ff.total_reflectance - r0)
            .abs()
            .max((ff.total_transmittance - t0).abs());
        eprintln!(
            "d {d}: R {} (Airy {r0}) T {} (Airy {t0}) err {err:.2e}",
            ff.total_reflectance, ff.total_transmittance
        );
        errs.push(err);
    }
    assert!(
        errs.windows(2).all(|w| w[1] < w[0]),
        "not monotone: {errs:?}"
    );
    assert!(errs[3] < 0.1 * errs[0] && errs[3] < 2e-3, "{errs:?}");
}

#[test]
fn same_result_for_one_and_two_threads() {
    let size = [600.0, 600.0, 400.0];
    let geom = packed(size, 150.0, 0.2, 5);
    let cells = [24, 24, 30];
    let (eps, _) = layer_eps(&geom, cells, C64::new(1.4, 0.6));
    let run = |threads| {
        on_threads(threads, || {
            let lat = Problem::lattice([24, 24, 30], size, 500.0, 30.0, 10.0);
            let s = solver::solve(&in_binder(lat, &eps), Method::Auto, &CTL).unwrap();
            (s.r, s.t, s.absorption, s.field)
        })
    };
    let a = run(1);
    let b = run(2);
    assert!(a.0 == b.0 && a.1 == b.1 && a.2.to_bits() == b.2.to_bits() && a.3 == b.3);
}

/// Orders exactly at grazing: the period makes the (1,0) order graze in the
/// binder (γ = 0; the contour-average path) or in vacuum (β = 0). No inf or
/// NaN, residual at tolerance, energy balance, for every method that claims
/// validity.
#[test]
fn exactly_grazing_orders_stay_finite() {
    let lambda = 500.0;
    for period in [lambda / 1.558, lambda] {
        let size = [period, period, 400.0];
        let particles = vec![Particle {
            species: 0,
            spheres: vec![Sphere {
                center: [period / 2.0, period / 2.0, 200.0],
                radius: 0.4 * period.min(400.0) / 2.0,
            }],
        }];
        let stats = GeometryStats {
            count: vec![1],
            target_fraction: vec![0.1],
            achieved_fraction: vec![0.1],
            min_gap_nm: f64::INFINITY,
            attempts: 1,
            worst_overlap_nm: 0.0,
            order_parameter: None,
            relax_steps: 0,
        };
        let geom = Geometry {
            size_nm: size,
            particles,
            stats,
        };
        let cells = [16, 16, 40];
        let (eps, _) = layer_eps(&geom, cells, C64::new(1.4, 0.5));
        let lat = Problem::lattice([16, 16, 40], size, lambda, 0.0, 0.0);
        let [kx, _] = lat.kappa(1, 0);
        let grazing_in = if period == lambda { 1.0 } else { 1.558 };
        // In the binder the grazing order must take the contour-average path.
        let table = inksim::solver::operator::GreenTable::new(&lat, C64::new(EPS_B, 0.0));
        assert_eq!(table.special_count() > 0, period != lambda);
        assert!((kx / lat.k0 - grazing_in).abs() < 1e-12);
        for method in [
            Method::TimeMarching,
            Method::BiCgStab,
            Method::Gmres,
            Method::Auto,
        ] {
            let sol = solver::solve(&in_binder(lat, &eps), method, &CTL).expect("converges");
            assert!(sol
                .field
                .iter()
                .all(|c| c.re.is_finite() && c.im.is_finite()));
            let ff = efficiencies(&sol);
            assert!(
                ff.energy_balance.abs() < 1e-4,
                "{method:?} period {period}: {}",
                ff.energy_balance
            );
        }
    }
}
