//! Every reference case against every method, through one shared check
//! helper (the macro at the bottom instantiates it per method). A method
//! either reproduces the reference or — only where it declares itself not
//! valid (Born on strong scattering) — fails loudly; it never returns a wrong
//! answer. Each case runs with f64 and with f32 field storage, and on both
//! backgrounds of the shifted form (binder with the CBS shift, layer mean).
use inksim::config::{Background, Method, Precision};
use inksim::optics::farfield::efficiencies;
use inksim::solver::methods::born::Born;
use inksim::solver::{self, Controls, Problem, SolveError, Solver, System, Validity};
use ndarray::Array3;
use num_complex::Complex64 as C64;

mod common;
use common::layers::{in_binder, layer_eps, packed_rsa};
const CTL: Controls = Controls {
    tolerance: 1e-9,
    max_iterations: 20000,
    precision: Precision::F64,
    background: Background::Binder,
};
/// f32 field storage: the tolerance it can reach (config enforces ≥ 1e-6).
const CTL32: Controls = Controls {
    tolerance: 1e-6,
    max_iterations: 20000,
    precision: Precision::F32,
    background: Background::Binder,
};

/// The same on the mean background.
const CTL_MEAN: Controls = Controls {
    background: Background::Mean,
    ..CTL
};
const CTL32_MEAN: Controls = Controls {
    background: Background::Mean,
    ..CTL32
};

/// What a solve at `ctl` must reproduce: (energy balance, agreement with
/// the f64 reference at 1e-9).
fn bounds(ctl: &Controls) -> (f64, f64) {
    match ctl.precision {
        Precision::F64 => (1e-8, 1e-6),
        Precision::F32 => (1e-6, 1e-6),
    }
}

/// Solve, or check that a failure is one the method announced.
fn solve_or_declared_failure(
    p: &Problem,
    method: Method,
    ctl: &Controls,
) -> Option<solver::Solution> {
    match solver::solve(p, method, ctl) {
        Ok(s) => {
            assert!(
                s.record.residual <= ctl.tolerance,
                "{method:?}: residual {}",
                s.record.residual
            );
            Some(s)
        }
        Err(e) => {
            assert_eq!(method, Method::Born, "{method:?} must converge: {e}");
            assert!(
                matches!(
                    e,
                    SolveError::Diverged { .. } | SolveError::NotConverged { .. }
                ),
                "{e}"
            );
            let mut sys = System::new(p, ctl.background).unwrap();
            let mut scr = sys.scratch();
            assert!(
                matches!(
                    Born.validity(&mut sys, &mut scr, Precision::F64),
                    Validity::Unlikely(_)
                ),
                "Born failed where it claimed validity: {e}"
            );
            None
        }
    }
}

/// Homogeneous slabs (weak and strong, real and absorbing, normal and
/// oblique) put into Δε over the binder: R and T within 1e-3 of Airy on a
/// 4 nm z grid (the z error is O(dz²); its constant grows with how resonant
/// the slab is, so the grazing real slab needs finer cells than the default
/// 10 nm — see tests/solver_slab.rs for the convergence order), exact energy
/// balance.
fn check_airy(method: Method, ctl: &Controls) {
    let (balance, _) = bounds(ctl);
    let h = 1000.0;
    let cases = [
        (C64::new(2.3, 0.0), 0.0),
        (C64::new(2.3, 0.05), 50.0),
        (C64::new(1.96, 0.3), 0.0),
        ((C64::new(1.4, 0.8)) * C64::new(1.4, 0.8), 30.0),
        (C64::new(2.0, 0.0), 75.0),
    ];
    let mut solved = 0;
    for (eps, polar) in cases {
        let lat = Problem::lattice([4, 4, 250], [800.0, 800.0, h], 500.0, polar, 15.0);
        let grid = Array3::from_elem((250, 4, 4), eps);
        let p = in_binder(lat, &grid);
        let Some(sol) = solve_or_declared_failure(&p, method, ctl) else {
            continue;
        };
        let ff = efficiencies(&sol);
        let (r0, t0) = common::airy::airy_power(lat.k0, eps, lat.q[0].hypot(lat.q[1]), h);
        let err = (ff.total_reflectance - r0)
            .abs()
            .max((ff.total_transmittance - t0).abs());
        assert!(
            err < 1e-3,
            "{method:?} eps {eps} polar {polar}: error {err}"
        );
        assert!(
            ff.energy_balance.abs() < balance,
            "{method:?}: balance {}",
            ff.energy_balance
        );
        solved += 1;
    }
    assert!(solved >= 1, "{method:?} solved none of the slab cases");
}

/// A random absorbing grain layer: energy balance to 1e-4 and agreement
/// between methods (all solve the same discrete equation).
fn check_layer(method: Method, ctl: &Controls) {
    let (balance, agree) = bounds(ctl);
    let size = [800.0, 800.0, 500.0];
    let geom = packed_rsa(size, 160.0, 0.25, 21);
    let (eps, _) = layer_eps(&geom, [32, 32, 50], C64::new(1.4, 0.6));
    let lat = Problem::lattice([32, 32, 50], size, 480.0, 25.0, 30.0);
    let p = in_binder(lat, &eps);
    let reference = solver::solve(&p, Method::TimeMarching, &CTL).unwrap();
    let Some(sol) = solve_or_declared_failure(&p, method, ctl) else {
        return;
    };
    let (a, b) = (efficiencies(&sol), efficiencies(&reference));
    assert!(
        a.energy_balance.abs() < balance.max(1e-4),
        "{method:?}: balance {}",
        a.energy_balance
    );
    assert!(
        (a.total_reflectance - b.total_reflectance).abs() < agree,
        "{method:?} {}: R {} vs time-marching {}",
        ctl.precision,
        a.total_reflectance,
        b.total_reflectance
    );
    assert!(
        (a.absorption - b.absorption).abs() < agree,
        "{method:?} {}: A {} vs time-marching {}",
        ctl.precision,
        a.absorption,
        b.absorption
    );
}

/// Maxwell's equations with a tensor permittivity: a low-index absorbing
/// laminate whose faces cut cells (the cut cells anisotropic), lit in p at
/// 60° so that E_z crosses the faces, against the transfer matrix; exact
/// energy balance. Every method sees the tensor through the same system.
fn check_tensor(method: Method, ctl: &Controls) {
    let (balance, _) = bounds(ctl);
    let (h, z1, z2) = (600.0, 137.0, 411.0);
    let eps_s = C64::new(1.2, 0.4);
    let (eps, tensor) = common::layers::laminate(80, (z1, z2, h), eps_s);
    let lat = Problem::lattice([2, 2, 80], [400.0, 400.0, h], 550.0, 60.0, 20.0);
    let p = Problem {
        tensor: Some(&tensor),
        wave: inksim::solver::Wave::Vector {
            polarisation: inksim::config::Linear::P.into(),
            azimuth_deg: 20.0,
        },
        ..in_binder(lat, &eps)
    };
    let Some(sol) = solve_or_declared_failure(&p, method, ctl) else {
        return;
    };
    let ff = efficiencies(&sol);
    let b = C64::new(common::layers::EPS_B, 0.0);
    let (r0, t0) = common::airy::tmm_p(&[(b, z1), (eps_s, z2 - z1), (b, h - z2)], 550.0, 60.0);
    let err = (ff.total_reflectance - r0)
        .abs()
        .max((ff.total_transmittance - t0).abs());
    assert!(
        err < 1e-4,
        "{method:?}: error {err:.2e} against the transfer matrix"
    );
    assert!(
        ff.energy_balance.abs() < balance,
        "{method:?}: balance {}",
        ff.energy_balance
    );
}

/// One test per (name, check, controls) for one method.
macro_rules! every_case {
    ($method:expr; $($test:ident => $check:ident($ctl:expr)),* $(,)?) => {$(
        #[test]
        fn $test() {
            $check($method, &$ctl);
        }
    )*};
}

macro_rules! every_method {
    ($($name:ident => $method:expr),* $(,)?) => {$(
        mod $name {
            use super::*;
            every_case! {
                $method;
                airy_slabs => check_airy(CTL),
                grain_layer => check_layer(CTL),
                airy_slabs_f32 => check_airy(CTL32),
                grain_layer_f32 => check_layer(CTL32),
                airy_slabs_mean => check_airy(CTL_MEAN),
                grain_layer_mean => check_layer(CTL_MEAN),
                airy_slabs_f32_mean => check_airy(CTL32_MEAN),
                grain_layer_f32_mean => check_layer(CTL32_MEAN),
                tensor_laminate => check_tensor(CTL),
                tensor_laminate_f32 => check_tensor(CTL32),
                tensor_laminate_mean => check_tensor(CTL_MEAN),
                tensor_laminate_f32_mean => check_tensor(CTL32_MEAN),
            }
        }
    )*};
}

every_method! {
    born => Method::Born,
    time_marching => Method::TimeMarching,
    gmres => Method::Gmres,
    bicgstab => Method::BiCgStab,
    auto => Method::Auto,
}
