//! Homogeneous slab against the Airy formula (METHOD §7).
use inksim::config::Method;
use inksim::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;

mod common;
use common::layers::{in_binder, EPS_B};

fn slab_solve(
    eps: C64,
    polar: f64,
    nz: usize,
    method: Method,
) -> (f64, f64, f64, f64, f64, solver::Solution) {
    let lambda = 500.0;
    let h = 1000.0;
    let lat = Problem::lattice([4, 4, nz], [800.0, 800.0, h], lambda, polar, 20.0);
    let grid = Array3::from_elem((nz, 4, 4), eps);
    let p = in_binder(lat, &grid);
    let sol = solver::solve(
        &p,
        method,
        &Controls {
            tolerance: 1e-11,
            max_iterations: 20000,
            precision: inksim::config::Precision::F64,
            background: inksim::config::Background::DEFAULT,
        },
    )
    .expect("solve");
    let kap = lat.q[0].hypot(lat.q[1]);
    let (r, t) = common::airy::airy(lat.k0, eps, kap, h);
    let ff = inksim::optics::farfield::efficiencies(&sol);
    (
        ff.total_reflectance,
        ff.total_transmittance,
        r.norm_sqr(),
        t.norm_sqr(),
        ff.energy_balance,
        sol,
    )
}

#[test]
fn background_slab_is_exact() {
    for polar in [0.0, 35.0] {
        let (rr, tt, r0, t0, eb, sol) = slab_solve(C64::new(EPS_B, 0.0), polar, 16, Method::Born);
        assert!(
            (rr - r0).abs() < 1e-10 && (tt - t0).abs() < 1e-10,
            "{rr} {r0} {tt} {t0}"
        );
        assert!(eb.abs() < 1e-10);
        assert_eq!(sol.record.iterations, 0);
    }
}

#[test]
fn slab_in_delta_eps_converges_second_order() {
    // Real (Born converges) and absorbing (time-marching), normal and oblique.
    // nz = 100 is the default 10 nm z cell for this 1 µm slab.
    let cases = [
        (C64::new(2.3, 0.0), 0.0, Method::Born),
        (C64::new(2.3, 0.02), 50.0, Method::Born),
        (C64::new(2.0, 0.0), 0.0, Method::TimeMarching),
        (C64::new(1.96, 0.3), 0.0, Method::TimeMarching),
        (C64::new(1.96, 0.3), 40.0, Method::TimeMarching),
    ];
    for (eps, polar, method) in cases {
        let mut errs = vec![];
        for nz in [50, 100, 200] {
            let (rr, tt, r0, t0, eb, sol) = slab_solve(eps, polar, nz, method);
            let err = (rr - r0).abs().max((tt - t0).abs());
            eprintln!(
                "eps {eps} polar {polar} nz {nz}: err {err:.3e} energy {eb:.1e} iters {}",
                sol.record.iterations
            );
            assert!(eb.abs() < 1e-8);
            errs.push(err);
        }
        assert!(errs[1] < 1e-3, "{errs:?}");
        for w in errs.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!(order > 1.8 && order < 2.3, "order {order}: {errs:?}");
        }
    }
}
