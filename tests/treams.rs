//! Square lattices of spheres in a binder slab, Maxwell's equations against
//! an exact T-matrix code (METHOD §7).
//!
//! tests/fixtures/treams_spheres.json (scripts/treams_reference.py) holds
//! treams' per-order R_mn, T_mn and absorption for one or two spheres per
//! cell in a 600 nm binder slab between vacuum half-spaces, λ = 550 nm, at
//! 0° and 45° in s and p, converged in the multipole order and the
//! plane-wave cutoff to well below 1e-4 (checked here). We rasterise the
//! same spheres by volume fraction (`inksim::raster`, 4³ sub-samples in the
//! cut voxels), with the cut voxels anisotropic (the default of Maxwell
//! runs: the average along the surface, the harmonic mean across it), and
//! solve at 20 and 10 nm cells. The error (largest |ΔR_mn|, |ΔT_mn|, |ΔA|)
//! must fall with the cell and be below a per-case tolerance at 10 nm
//! ([`COMPARED`]), and well below the error of plain volume averaging on
//! the same grid; the error against the other polarisation's reference
//! must be well above it (the comparison can fail). The 5 nm grid is an
//! ignored test: `cargo test --release --test treams -- --ignored`.
use inksim::config::{Background, Linear, Method};
use inksim::geometry::{Geometry, Particle, Sphere};
use inksim::optics::farfield::efficiencies;
use inksim::raster::{rasterize, Anisotropy, Grid};
use inksim::solver::{self, Controls, Problem, Wave};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::collections::BTreeMap;

mod common;
use common::json::Json;

const CTL: Controls = Controls {
    tolerance: 1e-8,
    max_iterations: 20000,
    precision: inksim::config::Precision::F64,
    background: Background::DEFAULT,
};

/// Per-order (R, T) by (m, n), and the absorption.
#[derive(Debug, Clone)]
struct Result {
    orders: BTreeMap<(i32, i32), (f64, f64)>,
    absorption: f64,
}

fn fixture() -> Json {
    let path = format!(
        "{}/tests/fixtures/treams_spheres.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("read {path}: {e}"));
    Json::parse(&text)
}

fn case<'a>(root: &'a Json, name: &str) -> &'a Json {
    root.arr("cases")
        .iter()
        .find(|c| c.str("name") == name)
        .unwrap_or_else(|| panic!("case {name} missing"))
}

/// The reference of one incidence of a case.
fn reference(c: &Json, polar: f64, pol: &str) -> Result {
    let inc = c
        .arr("incidence")
        .iter()
        .find(|i| i.num("polar_deg") == polar && i.str("pol") == pol)
        .unwrap_or_else(|| panic!("{}: {polar}° {pol} missing", c.str("name")));
    Result {
        orders: inc
            .arr("orders")
            .iter()
            .map(|o| {
                (
                    (o.num("m") as i32, o.num("n") as i32),
                    (o.num("R"), o.num("T")),
                )
            })
            .collect(),
        absorption: inc.num("A"),
    }
}

/// Largest |ΔR_mn|, |ΔT_mn|, |ΔA|; the propagating orders must be the same.
fn error(a: &Result, b: &Result) -> f64 {
    assert_eq!(
        a.orders.keys().collect::<Vec<_>>(),
        b.orders.keys().collect::<Vec<_>>(),
        "propagating orders differ"
    );
    a.orders
        .iter()
        .map(|(k, x)| {
            let y = b.orders[k];
            (x.0 - y.0).abs().max((x.1 - y.1).abs())
        })
        .fold((a.absorption - b.absorption).abs(), f64::max)
}

/// How the solves see the voxels a sphere surface cuts.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Voxels {
    /// The volume average of ε.
    Average,
    /// The average along the surface, the harmonic mean across it.
    Anisotropic,
}

/// Our solve of a fixture case on cells of `cell` nm (x, y and z).
fn solve_case(c: &Json, polar: f64, pol: &str, cell: f64, voxels: Voxels) -> Result {
    let (l, h) = (c.num("period_nm"), c.num("thickness_nm"));
    let eps_b = c.num("n_binder").powi(2);
    let spheres = c.arr("spheres");
    let geom = Geometry {
        size_nm: [l, l, h],
        particles: spheres
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let p = s.arr("center_nm");
                Particle {
                    species: i,
                    spheres: vec![Sphere {
                        center: [p[0].as_num(), p[1].as_num(), p[2].as_num()],
                        radius: s.num("radius_nm"),
                    }],
                }
            })
            .collect(),
        stats: Default::default(),
    };
    let eps_s: Vec<C64> = spheres
        .iter()
        .map(|s| {
            let n = s.arr("n");
            C64::new(n[0].as_num(), n[1].as_num()).powi(2)
        })
        .collect();
    let (n, nz) = ((l / cell).round() as usize, (h / cell).round() as usize);
    assert!((n as f64 * cell - l).abs() < 1e-9 && (nz as f64 * cell - h).abs() < 1e-9);
    let grid = Grid {
        nx: n,
        ny: n,
        nz,
        size_nm: [l, l, h],
    };
    let raster = rasterize(&geom, &grid, 4);
    let mut eps = Array3::zeros((nz, n, n));
    raster.epsilon_into(C64::new(eps_b, 0.0), &eps_s, &mut eps);
    let mut tensor = Anisotropy::default();
    raster.anisotropy_into(
        C64::new(eps_b, 0.0),
        &eps_s,
        &[],
        true,
        &mut eps,
        &mut tensor,
    );
    let azimuth = c.num("azimuth_deg");
    let lattice = Problem::lattice(
        [n, n, nz],
        [l, l, h],
        c.num("wavelength_nm"),
        polar,
        azimuth,
    );
    let polarisation = match pol {
        "s" => Linear::S,
        "p" => Linear::P,
        _ => panic!("polarisation {pol}"),
    };
    let p = Problem {
        tensor: (voxels == Voxels::Anisotropic).then_some(&tensor),
        lattice,
        eps: &eps,
        eps_binder: eps_b,
        wave: Wave::Vector {
            polarisation: polarisation.into(),
            azimuth_deg: azimuth,
        },
    };
    let sol = solver::solve(&p, Method::Auto, &CTL).expect("solve");
    let ff = efficiencies(&sol);
    assert!(
        ff.energy_balance.abs() < 1e-6,
        "energy balance {}",
        ff.energy_balance
    );
    let r = &sol.record;
    eprintln!(
        "  {} {polar}° {pol} at {cell} nm ({n}×{n}×{nz}, {voxels:?}): {} iterations, {:.2} s",
        c.str("name"),
        r.iterations,
        r.seconds
    );
    Result {
        orders: ff
            .orders
            .iter()
            .map(|o| ((o.m, o.n), (o.reflectance, o.transmittance)))
            .collect(),
        absorption: ff.absorption,
    }
}

/// The fixture is what the script writes: treams, the homogeneous slab
/// exact, every reference converged in lmax, the plane-wave cutoff and the
/// lattice sums to < 1e-4 (most to ~1e-9), lossless cases conserve energy.
#[test]
fn fixture_is_a_converged_treams_reference() {
    let root = fixture();
    assert_eq!(root.str("package"), "treams");
    assert!(root.get("airy_check").num("max_error") < 1e-10);
    let cases = root.arr("cases");
    assert_eq!(cases.len(), 3);
    for c in cases {
        let lossless = c
            .arr("spheres")
            .iter()
            .all(|s| s.arr("n")[1].as_num() == 0.0);
        let incidences = c.arr("incidence");
        assert_eq!(incidences.len(), 4);
        for inc in incidences {
            let what = format!(
                "{} {}° {}",
                c.str("name"),
                inc.num("polar_deg"),
                inc.str("pol")
            );
            for key in [
                "max_change_from_lmax_minus",
                "max_change_from_bmax_minus",
                "max_change_with_eta",
            ] {
                assert!(inc.num(key) < 1e-4, "{what}: not converged: {key}");
            }
            let (r, t, a) = (inc.num("R"), inc.num("T"), inc.num("A"));
            assert!(
                r > 0.0 && t > 0.0 && a > -1e-9 && r + t <= 1.0 + 1e-9,
                "{what}"
            );
            if lossless {
                assert!(a.abs() < 1e-9, "{what}: lossless A = {a}");
            }
        }
    }
}

/// The incidences compared (a subset: the test's time) and the largest
/// per-order (and absorption) error accepted at 10 nm cells with
/// anisotropic cut voxels. Measured (20 → 10 → 5 nm): absorbing 6.1e-4 →
/// 1.8e-4 → 7.7e-5 (0° s) and 5.3e-4 → 1.5e-4 → 3.0e-5 (45° p); rutile
/// 2.1e-3 → 1.7e-3 → 1.1e-3 (0° s) and 1.2e-2 → 2.5e-3 → 6.1e-4 (45° s);
/// the pair 9.2e-4 → 3.2e-4. Volume averaging on the same grids: about
/// first order, 1.0–1.5e-3 (absorbing) and 2.4–4.3e-2 (rutile) at 10 nm.
const COMPARED: [(&str, f64, &str, f64); 5] = [
    ("absorbing_r150", 0.0, "s", 4e-4),
    ("absorbing_r150", 45.0, "p", 4e-4),
    ("rutile_r110", 0.0, "s", 3e-3),
    ("rutile_r110", 45.0, "s", 5e-3),
    ("pair", 45.0, "s", 6e-4),
];

/// Per-order R, T and A against treams at 20 and 10 nm cells: the error
/// must fall under refinement, be below the case's tolerance at 10 nm and
/// below 1/2.5 of volume averaging's there (measured 3.3–17×), and the same
/// solution against the other polarisation's reference must fail that
/// tolerance by a factor of 2 (where s and p differ).
#[test]
fn sphere_lattices_match_treams() {
    let root = fixture();
    let mut report = vec![];
    for (name, polar, pol, tolerance) in COMPARED {
        let c = case(&root, name);
        let want = reference(c, polar, pol);
        let other = reference(c, polar, if pol == "s" { "p" } else { "s" });
        let coarse = solve_case(c, polar, pol, 20.0, Voxels::Anisotropic);
        let fine = solve_case(c, polar, pol, 10.0, Voxels::Anisotropic);
        let average = solve_case(c, polar, pol, 10.0, Voxels::Average);
        let (e20, e10) = (error(&coarse, &want), error(&fine, &want));
        let e_avg = error(&average, &want);
        let wrong = error(&fine, &other);
        let line = format!(
            "{name} {polar}° {pol}: error {e20:.2e} (20 nm), {e10:.2e} (10 nm), \
             order {:.2}; volume average {e_avg:.2e} (10 nm); against the other \
             polarisation {wrong:.2e}",
            (e20 / e10).log2()
        );
        eprintln!("{line}");
        report.push(line);
        assert!(
            e10 < tolerance && e10 < 0.9 * e20,
            "{name} {polar}° {pol}: {e20:.2e} → {e10:.2e}"
        );
        assert!(
            2.5 * e10 < e_avg,
            "{name} {polar}° {pol}: anisotropic {e10:.2e} against average {e_avg:.2e}"
        );
        // At normal incidence the centred sphere's s and p are the same
        // problem (rotated by 90°): there the test is an s/p swap of the
        // pair only.
        let symmetric = polar == 0.0 && c.arr("spheres").len() == 1;
        if !symmetric {
            assert!(
                wrong > 2.0 * tolerance,
                "{name} {polar}° {pol}: the other polarisation is within {wrong:.2e}"
            );
        }
    }
    eprintln!("{}", report.join("\n"));
}

/// The 5 nm grid of two incidences (minutes): the error keeps falling.
/// `cargo test --release --test treams -- --ignored --nocapture`
#[test]
#[ignore]
fn sphere_lattices_match_treams_at_5_nm() {
    let root = fixture();
    for (name, polar, pol, tolerance) in [COMPARED[1], COMPARED[3]] {
        let c = case(&root, name);
        let want = reference(c, polar, pol);
        let e10 = error(&solve_case(c, polar, pol, 10.0, Voxels::Anisotropic), &want);
        let e5 = error(&solve_case(c, polar, pol, 5.0, Voxels::Anisotropic), &want);
        eprintln!("{name} {polar}° {pol}: error {e10:.2e} (10 nm), {e5:.2e} (5 nm)");
        assert!(
            e5 < 0.8 * e10 && e5 < tolerance / 2.0,
            "{e10:.2e} → {e5:.2e}"
        );
    }
}
