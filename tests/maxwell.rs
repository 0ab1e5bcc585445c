//! Maxwell's equations in the Bloch slab (METHOD §9) against exact
//! references: the Airy slab in s and p (Brewster's angle included), the
//! scalar solver for TE of a y-invariant structure, energy balance,
//! reciprocity and rotation of a lattice of spheres, and thread-count
//! independence.
use inksim::config::{Background, Linear, Method};
use inksim::optics::farfield::efficiencies;
use inksim::solver::{self, airy::SlabField, Problem, Solution, Wave};
use ndarray::Array3;
use num_complex::Complex64 as C64;

mod common;
use common::airy::{airy, airy_p};
use common::layers::{tight, EPS_B};

fn vector(polarisation: Linear, azimuth_deg: f64) -> Wave {
    Wave::Vector {
        polarisation: polarisation.into(),
        azimuth_deg,
    }
}

fn solve(
    lat: solver::Lattice,
    eps: &Array3<C64>,
    wave: Wave,
    method: Method,
    background: Background,
) -> Solution {
    let p = Problem {
        tensor: None,
        lattice: lat,
        eps,
        eps_binder: EPS_B,
        wave,
    };
    solver::solve(&p, method, &tight(background)).expect("solve")
}

/// The closed-form p slab (H_y with continuous H_y'/ε) against the
/// independent Airy formula in p, and R_p = 0 at Brewster's angle of a
/// lossless slab, for any thickness.
#[test]
fn closed_form_p_slab_matches_airy_and_vanishes_at_brewster() {
    let k0 = 2.0 * std::f64::consts::PI / 550.0;
    for (eps, polar) in [
        (C64::new(EPS_B, 0.0), 0.0),
        (C64::new(EPS_B, 0.0), 60.0),
        (C64::new(1.87, 0.84), 30.0),
        (C64::new(3.36, 3.2), 75.0),
    ] {
        let kap = k0 * f64::to_radians(polar).sin();
        let slab = SlabField::polarised(eps, 730.0, k0, kap, true);
        let (r, t) = airy_p(k0, eps, kap, 730.0);
        let resp = slab.response;
        assert!((resp.r.norm_sqr() - r.norm_sqr()).abs() < 1e-12, "{polar}");
        assert!((resp.t.norm_sqr() - t.norm_sqr()).abs() < 1e-12, "{polar}");
        // The absorption is integrated from the field, not 1 − R − T.
        let balance = resp.r.norm_sqr() + resp.t.norm_sqr() + resp.absorption - 1.0;
        assert!(balance.abs() < 1e-12, "p balance {balance} at {polar}°");
    }
    let brewster = EPS_B.sqrt().atan();
    for h in [137.0, 1000.0] {
        let kap = k0 * brewster.sin();
        let rp = SlabField::polarised(C64::new(EPS_B, 0.0), h, k0, kap, true).response;
        let rs = SlabField::polarised(C64::new(EPS_B, 0.0), h, k0, kap, false).response;
        assert!(
            rp.r.norm_sqr() < 1e-24,
            "R_p at Brewster {}",
            rp.r.norm_sqr()
        );
        assert!(
            rs.r.norm_sqr() > 1e-3,
            "R_s at Brewster {}",
            rs.r.norm_sqr()
        );
    }
}

/// The binder slab itself: the background field is the answer, Born takes
/// no iteration, in s and p, oblique, at an azimuth.
#[test]
fn background_slab_is_exact_in_s_and_p() {
    let nz = 12;
    for polar in [0.0, 40.0, EPS_B.sqrt().atan().to_degrees()] {
        let lat = Problem::lattice([4, 4, nz], [800.0, 800.0, 700.0], 500.0, polar, 25.0);
        let grid = Array3::from_elem((nz, 4, 4), C64::new(EPS_B, 0.0));
        let kap = lat.q[0].hypot(lat.q[1]);
        for (pol, (r, t)) in [
            (Linear::S, airy(lat.k0, C64::new(EPS_B, 0.0), kap, 700.0)),
            (Linear::P, airy_p(lat.k0, C64::new(EPS_B, 0.0), kap, 700.0)),
        ] {
            let sol = solve(
                lat,
                &grid,
                vector(pol, 25.0),
                Method::Born,
                Background::Binder,
            );
            assert_eq!(sol.record.iterations, 0);
            let ff = efficiencies(&sol);
            assert!(
                (ff.total_reflectance - r.norm_sqr()).abs() < 1e-12,
                "{pol:?} {polar}"
            );
            assert!((ff.total_transmittance - t.norm_sqr()).abs() < 1e-12);
            assert!(ff.energy_balance.abs() < 1e-12);
        }
    }
}

/// A homogeneous contrast slab (grains of one ε filling the layer)
/// solved iteratively converges to the exact Airy slab in s and p at
/// second order in the z cell, on both backgrounds; energy balance holds
/// to solver tolerance at every grid.
#[test]
fn contrast_slab_converges_to_airy_in_s_and_p() {
    let h = 600.0;
    // (ε, angle, background, coarsest nz): the rutile-like contrast starts
    // finer, where γ dz is small enough for the asymptotic order.
    for (eps, polar, bg, nz0) in [
        (C64::new(1.96, 0.0), 50.0, Background::Binder, 15),
        (C64::new(1.87, 0.84), 30.0, Background::Mean, 15),
        (C64::new(7.3, 0.0), 65.0, Background::Mean, 60),
    ] {
        for pol in [Linear::S, Linear::P] {
            let mut errors = vec![];
            for nz in [nz0, 2 * nz0, 4 * nz0] {
                let lat = Problem::lattice([2, 2, nz], [400.0, 400.0, h], 550.0, polar, 30.0);
                let grid = Array3::from_elem((nz, 2, 2), eps);
                let sol = solve(lat, &grid, vector(pol, 30.0), Method::BiCgStab, bg);
                let ff = efficiencies(&sol);
                assert!(
                    ff.energy_balance.abs() < 1e-8,
                    "balance {}",
                    ff.energy_balance
                );
                let kap = lat.q[0].hypot(lat.q[1]);
                let (r, _) = match pol {
                    Linear::S => airy(lat.k0, eps, kap, h),
                    Linear::P => airy_p(lat.k0, eps, kap, h),
                };
                errors.push((ff.total_reflectance - r.norm_sqr()).abs());
            }
            assert!(
                errors[2] < 2e-3 && errors[1] / errors[2] > 3.0 && errors[0] / errors[1] > 3.0,
                "{pol:?} ε {eps} at {polar}°: errors {errors:?}"
            );
        }
    }
}

/// TE of a y-invariant structure (stripes along y, incidence in the x-z
/// plane, s polarised: E along the stripes) is exactly the scalar problem:
/// E_y equals the scalar field to solver tolerance, nothing is scattered
/// into p, and the order efficiencies agree.
#[test]
fn te_of_a_y_invariant_grating_is_the_scalar_solution() {
    let (nx, ny, nz) = (20, 2, 20);
    let eps = Array3::from_shape_fn((nz, ny, nx), |(_, _, x)| {
        if (4..12).contains(&x) {
            C64::new(2.0, 0.8)
        } else {
            C64::new(EPS_B, 0.0)
        }
    });
    for polar in [0.0, 30.0] {
        let lat = Problem::lattice([nx, ny, nz], [1000.0, 100.0, 1000.0], 550.0, polar, 0.0);
        let scalar = solve(lat, &eps, Wave::Scalar, Method::BiCgStab, Background::Mean);
        let vec = solve(
            lat,
            &eps,
            vector(Linear::S, 0.0),
            Method::BiCgStab,
            Background::Mean,
        );
        let scale = scalar.field.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for k in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let u = scalar.field[[k, y, x]];
                    let ey = vec.field[[nz + k, y, x]];
                    assert!((u - ey).norm() < 1e-8 * scale, "E_y {ey} vs u {u}");
                    assert!(vec.field[[k, y, x]].norm() < 1e-8 * scale, "E_x ≠ 0");
                    assert!(
                        vec.field[[2 * nz + k, y, x]].norm() < 1e-8 * scale,
                        "E_z ≠ 0"
                    );
                }
            }
        }
        let (a, b) = (efficiencies(&scalar), efficiencies(&vec));
        for (o, p) in a.orders.iter().zip(&b.orders) {
            assert!((o.reflectance - p.reflectance).abs() < 1e-9);
            assert!((o.transmittance - p.transmittance).abs() < 1e-9);
        }
        let rp = &vec.vector.as_ref().unwrap().r_p;
        assert!(rp.iter().all(|v| v.norm() < 1e-9), "s scattered into p");
    }
}

/// A cubic lattice cell with one absorbing sphere, 3-D.
fn sphere_cell(n: usize, nz: usize, eps: C64) -> Array3<C64> {
    let c = (n as f64 / 2.0, n as f64 / 2.0, nz as f64 / 2.0);
    let r = 0.35 * n as f64;
    Array3::from_shape_fn((nz, n, n), |(k, y, x)| {
        let d = ((x as f64 + 0.5 - c.0).powi(2)
            + (y as f64 + 0.5 - c.1).powi(2)
            + ((k as f64 + 0.5 - c.2) * n as f64 / nz as f64).powi(2))
        .sqrt();
        if d < r {
            eps
        } else {
            C64::new(EPS_B, 0.0)
        }
    })
}

/// Energy balance to solver tolerance in s and p on a 3-D sphere lattice
/// (every method that converges there agrees), and the rotation of the cell
/// by 90° in azimuth (x → y, incidence azimuth 0 → 90°) gives the same
/// totals.
#[test]
fn sphere_lattice_balances_and_rotates() {
    let (n, nz) = (12, 12);
    let eps = sphere_cell(n, nz, C64::new(2.9, 0.6));
    let rotated = Array3::from_shape_fn((nz, n, n), |(k, y, x)| eps[[k, x, y]]);
    for pol in [Linear::S, Linear::P] {
        let lat = Problem::lattice([n, n, nz], [400.0, 400.0, 400.0], 550.0, 35.0, 0.0);
        let lat90 = Problem::lattice([n, n, nz], [400.0, 400.0, 400.0], 550.0, 35.0, 90.0);
        let mut totals = vec![];
        for method in [Method::BiCgStab, Method::Gmres, Method::TimeMarching] {
            let sol = solve(lat, &eps, vector(pol, 0.0), method, Background::Binder);
            let ff = efficiencies(&sol);
            assert!(
                ff.energy_balance.abs() < 1e-7,
                "{pol:?} {method}: {}",
                ff.energy_balance
            );
            totals.push((ff.total_reflectance, ff.total_transmittance, ff.absorption));
        }
        for t in &totals[1..] {
            assert!((t.0 - totals[0].0).abs() < 1e-7 && (t.2 - totals[0].2).abs() < 1e-7);
        }
        let sol = solve(
            lat90,
            &rotated,
            vector(pol, 90.0),
            Method::BiCgStab,
            Background::Mean,
        );
        let ff = efficiencies(&sol);
        assert!(
            (ff.total_reflectance - totals[0].0).abs() < 1e-8,
            "rotated R"
        );
        assert!((ff.absorption - totals[0].2).abs() < 1e-8, "rotated A");
    }
}

/// Reciprocity of the specular order: lit at (θ, φ) and from the reversed
/// lateral direction (θ, φ + 180°) the co- and cross-polarised specular
/// efficiencies agree (a cell symmetric under x → −x, y → −y; an odd grid,
/// whose orders are symmetric).
#[test]
fn specular_reflection_is_reciprocal() {
    let (n, nz) = (11, 10);
    let eps = sphere_cell(n, nz, C64::new(2.2, 0.4));
    for pol in [Linear::S, Linear::P] {
        let a = Problem::lattice([n, n, nz], [350.0, 350.0, 350.0], 500.0, 30.0, 15.0);
        let b = Problem::lattice([n, n, nz], [350.0, 350.0, 350.0], 500.0, 30.0, 195.0);
        let ra = efficiencies(&solve(
            a,
            &eps,
            vector(pol, 15.0),
            Method::BiCgStab,
            Background::Mean,
        ));
        let rb = efficiencies(&solve(
            b,
            &eps,
            vector(pol, 195.0),
            Method::BiCgStab,
            Background::Mean,
        ));
        let spec = |e: &inksim::optics::farfield::Efficiencies| {
            e.orders
                .iter()
                .find(|o| o.m == 0 && o.n == 0)
                .unwrap()
                .reflectance
        };
        assert!((spec(&ra) - spec(&rb)).abs() < 1e-8, "{pol:?}");
    }
}

/// The same problem on 1 and 2 threads gives the same bits.
#[test]
fn threads_do_not_change_the_answer() {
    let eps = sphere_cell(8, 8, C64::new(2.5, 0.5));
    let lat = Problem::lattice([8, 8, 8], [300.0, 300.0, 300.0], 500.0, 20.0, 10.0);
    let run = || {
        let s = solve(
            lat,
            &eps,
            vector(Linear::P, 10.0),
            Method::BiCgStab,
            Background::Mean,
        );
        (s.field, s.absorption)
    };
    let one = common::threads::on_threads(1, run);
    let two = common::threads::on_threads(2, run);
    assert_eq!(one.1.to_bits(), two.1.to_bits());
    assert!(one.0.iter().zip(two.0.iter()).all(|(a, b)| a == b));
}

/// Natural light from one mixed state `(ŝ + e^{iφ} p̂)/√2`: every order's
/// power is the mean of the s and p solves plus a cross term linear in
/// `e^{iφ}`, so the mean over φ = 0, π/2, π, 3π/2 is natural light to
/// solver tolerance (while one phase alone is not: the cross term is there
/// to cancel), and the co-polarised specular amplitudes per unit incident
/// amplitude average to the s and p solves' own. The homogeneous slab
/// converts no polarisation: one phase alone is exact there.
#[test]
fn random_phase_states_average_to_natural_light() {
    let (n, nz) = (10, 10);
    let eps = sphere_cell(n, nz, C64::new(2.9, 0.6));
    let lat = Problem::lattice([n, n, nz], [400.0, 400.0, 400.0], 550.0, 35.0, 20.0);
    let mixed = |phi: f64| Wave::Vector {
        polarisation: solver::Jones::phased(phi),
        azimuth_deg: 20.0,
    };
    let s = solve(
        lat,
        &eps,
        vector(Linear::S, 20.0),
        Method::BiCgStab,
        Background::Mean,
    );
    let p = solve(
        lat,
        &eps,
        vector(Linear::P, 20.0),
        Method::BiCgStab,
        Background::Mean,
    );
    let (fs, fp) = (efficiencies(&s), efficiencies(&p));
    let natural: Vec<f64> = fs
        .orders
        .iter()
        .zip(&fp.orders)
        .map(|(a, b)| 0.5 * (a.reflectance + b.reflectance))
        .collect();
    let mut mean = vec![0.0; natural.len()];
    let (mut absorption, mut r_s, mut r_p) = (0.0, C64::new(0.0, 0.0), C64::new(0.0, 0.0));
    let mut largest_cross: f64 = 0.0;
    for k in 0..4 {
        let sol = solve(
            lat,
            &eps,
            mixed(k as f64 * std::f64::consts::FRAC_PI_2),
            Method::BiCgStab,
            Background::Mean,
        );
        let f = efficiencies(&sol);
        assert!(
            f.energy_balance.abs() < 1e-7,
            "balance {}",
            f.energy_balance
        );
        for (i, o) in f.orders.iter().enumerate() {
            mean[i] += o.reflectance / 4.0;
            largest_cross = largest_cross.max((o.reflectance - natural[i]).abs());
        }
        absorption += f.absorption / 4.0;
        let [[rs, _], [rp, _]] = f.specular_amplitudes()[..] else {
            panic!("a mixed state keeps both co-polarised amplitudes")
        };
        r_s += rs / 4.0;
        r_p += rp / 4.0;
    }
    assert!(
        largest_cross > 1e-5,
        "no cross term to cancel: {largest_cross:e}"
    );
    for (i, (m, nat)) in mean.iter().zip(&natural).enumerate() {
        assert!((m - nat).abs() < 1e-8, "order {i}: {m} against {nat}");
    }
    assert!((absorption - 0.5 * (fs.absorption + fp.absorption)).abs() < 1e-8);
    assert!((r_s - fs.r00).norm() < 1e-7 && (r_p - fp.r00).norm() < 1e-7);

    let slab = Array3::from_elem((8, 2, 2), C64::new(1.87, 0.84));
    let lat = Problem::lattice([2, 2, 8], [400.0, 400.0, 600.0], 550.0, 50.0, 0.0);
    let kap = lat.q[0].hypot(lat.q[1]);
    let (rs, _) = airy(lat.k0, C64::new(1.87, 0.84), kap, 600.0);
    let (rp, _) = airy_p(lat.k0, C64::new(1.87, 0.84), kap, 600.0);
    let f = efficiencies(&solve(
        lat,
        &slab,
        mixed(1.1),
        Method::Airy,
        Background::Mean,
    ));
    let r = 0.5 * (rs.norm_sqr() + rp.norm_sqr());
    assert!(
        (f.total_reflectance - r).abs() < 1e-12,
        "slab R {} against {r}",
        f.total_reflectance
    );
    assert!((f.specular_power().0 - r).abs() < 1e-12);
}
