//! The effective-medium shortcut: a layer of grains fine against
//! the wavelength is the homogeneous slab of the volume-averaged ε, taken in
//! closed form when the measured estimate is within the scene's tolerance.
//! Checked against the same scene forced through the full solve, and the
//! estimate against full solves of a few layers (docs/ACCURACY.md).

use inksim::config::{Material, Method, Precision};
use inksim::geometry::{pack_rsa, PackParams, SpeciesParams};
use inksim::optics::farfield::efficiencies;
use inksim::pipeline::RunPlan;
use inksim::raster::{rasterize, Grid};
use inksim::solver::airy::{self, GrainTerm};
use inksim::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::path::Path;

mod common;
use common::scene::{PigmentToml, SceneToml};

/// Red grains of `d` nm at 10 % PVC in a 400 nm layer on paper, tile only.
fn grains_scene(dir: &Path, d: f64) -> SceneToml {
    SceneToml::grains()
        .seed(5)
        .thickness_nm(400.0)
        .fragment_nm(400.0)
        .layer_pvc(0.1)
        .pigment(PigmentToml::builtin("red").diameter_nm(d))
        .cell_nm(12.5)
        .polar_deg(&[0.0, 40.0])
        .outputs(&["tile"])
        .quadrature_points(2)
        .paper(0.9)
        .tolerance(1e-7)
        .output(dir, "grains")
}

/// The estimate the plan reports (`estimated error in R/T/A <e> (…`).
fn planned_estimate(plan: &RunPlan) -> f64 {
    let line = plan
        .lines
        .iter()
        .find(|l| l.contains("estimated error in R/T/A"))
        .expect("an effective-medium line");
    let tail = line.split("estimated error in R/T/A ").nth(1).unwrap();
    tail.split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn fine_grains_take_the_slab_and_agree_with_the_full_solve() {
    let dir = tempfile::tempdir().unwrap();
    let tol = 1e-2;
    let text = grains_scene(dir.path(), 6.0).effective_medium_tolerance(tol);
    let s = text.scene(dir.path());
    let plan = RunPlan::of(&s);
    assert!(plan.analytic, "{:#?}", plan.lines);
    assert!(
        plan.lines[0].starts_with("geometry: none — effective-medium shortcut: estimated error"),
        "{}",
        plan.lines[0]
    );
    let estimate = planned_estimate(&plan);
    assert!(estimate > 0.0 && estimate <= tol, "{estimate}");
    let short = text.run(dir.path());
    assert!(short.geometry.is_none());
    assert!(short
        .entries
        .iter()
        .all(|e| e.record.method == Method::Airy && e.record.iterations == 0));
    let stored = inksim::output::h5::read_summary(&dir.path().join("grains.h5"))
        .unwrap()
        .plan;
    assert!(stored.contains("effective-medium shortcut"), "{stored}");

    // The same scene with the shortcut disabled: packed, rasterised, solved.
    let full_dir = tempfile::tempdir().unwrap();
    let full_text = grains_scene(full_dir.path(), 6.0).effective_medium_tolerance(0.0);
    let full_plan = RunPlan::of(&full_text.scene(full_dir.path()));
    assert!(!full_plan.analytic);
    assert!(full_plan
        .lines
        .iter()
        .any(|l| l.contains("refused — solver.effective_medium_tolerance = 0")));
    let full = full_text.run(full_dir.path());
    assert!(full.geometry.is_some());
    assert_eq!(full.entries.len(), short.entries.len());
    let mut worst: f64 = 0.0;
    for (a, b) in short.entries.iter().zip(&full.entries) {
        assert_eq!((a.wavelength_nm, a.side), (b.wavelength_nm, b.side));
        assert_eq!(a.incidence.polar_deg, b.incidence.polar_deg);
        assert!(b.record.method != Method::Airy && b.record.iterations > 0);
        let (x, y) = (&a.efficiencies, &b.efficiencies);
        for d in [
            x.total_reflectance - y.total_reflectance,
            x.total_transmittance - y.total_transmittance,
            x.absorption - y.absorption,
        ] {
            worst = worst.max(d.abs());
        }
    }
    // Within the planned estimate (hence the tolerance), and not trivially.
    assert!(
        worst <= estimate,
        "error {worst:.3e} > estimate {estimate:.3e}"
    );
    assert!(
        worst > 1e-5,
        "grains that change nothing test nothing: {worst}"
    );
    // Colours: natural reflectance of layer + paper (T enters twice through
    // the paper term, so its error is at most ~2× that of R/T/A) and the
    // tile itself.
    let (sa, fa) = (short.appearance.unwrap(), full.appearance.unwrap());
    let (sn, fn_) = (sa.natural.unwrap(), fa.natural.unwrap());
    let dn = sn
        .iter()
        .zip(fn_.iter())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        dn <= 2.0 * estimate,
        "natural reflectance differs by {dn:.3e}"
    );
    let (sc, fc) = (sa.colours.unwrap(), fa.colours.unwrap());
    let de = sc
        .natural_lab
        .iter()
        .zip(&fc.natural_lab)
        .map(|(a, b)| inksim::optics::colour::delta_e2000(*a, *b))
        .fold(0.0, f64::max);
    let dpx = sc
        .tile_srgb8
        .iter()
        .zip(fc.tile_srgb8.iter())
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap();
    eprintln!(
        "shortcut vs full: R/T/A {worst:.3e} (estimate {estimate:.3e}), natural {dn:.3e}, \
         ΔE00 {de:.3}, tile levels {dpx}"
    );
    assert!(de < 1.0 && dpx <= 3, "ΔE00 {de:.3}, tile levels {dpx}");
}

#[test]
fn coarse_grains_and_what_the_slab_cannot_show_refuse_it() {
    let dir = tempfile::tempdir().unwrap();
    // 15 nm grains (λ/30): the estimate is above the default tolerance.
    let text = grains_scene(dir.path(), 15.0)
        .wavelengths_nm(&[550.0])
        .polar_deg(&[0.0])
        .measurements(&[])
        .no_substrate();
    let s = text.scene(dir.path());
    let plan = RunPlan::of(&s);
    assert!(!plan.analytic);
    let line = plan
        .lines
        .iter()
        .find(|l| l.starts_with("effective-medium shortcut: refused"))
        .unwrap();
    assert!(
        line.contains("> solver.effective_medium_tolerance 1.0e-3"),
        "{line}"
    );
    assert!(planned_estimate(&plan) > 1e-3);
    let rep = text.run(dir.path());
    assert!(rep.geometry.is_some());
    assert_eq!(rep.entries.len(), 1);
    let e = &rep.entries[0];
    assert!(e.record.method != Method::Airy && e.record.iterations > 0);
    assert!(e.efficiencies.energy_balance.abs() < 1e-5);

    // Fine grains, but something the slab cannot represent: refused, and why.
    let fine = grains_scene(dir.path(), 6.0).effective_medium_tolerance(1e-2);
    for (edit, why) in [
        (
            fine.clone().outputs(&["brdf", "tile"]),
            "the BRDF table is the grains' diffuse scattering",
        ),
        (
            grains_scene(dir.path(), 30.0).effective_medium_tolerance(0.1),
            "beyond λ/20 at 450 nm",
        ),
        (fine.clone().relief_fraction(0.3), "surface relief"),
        (
            fine.clone()
                .raw("pigment.0.agglomeration", "{ cluster_size = 4 }"),
            "agglomerate",
        ),
    ] {
        let plan = RunPlan::of(&edit.scene(dir.path()));
        assert!(!plan.analytic, "{why}");
        assert!(
            plan.lines
                .iter()
                .any(|l| l.starts_with("effective-medium shortcut: refused") && l.contains(why)),
            "{why}: {:#?}",
            plan.lines
        );
    }
}

/// Largest |ΔR|, |ΔT|, |ΔA| of a full solve of an RSA sphere layer against
/// the slab of the volume-averaged ε, and the estimate for it.
fn measured(material: &Material, d: f64, pvc: f64, wl: f64, polar: f64) -> (f64, f64) {
    let size = [400.0, 400.0, 400.0];
    let params = PackParams::new(
        size,
        vec![SpeciesParams {
            diameter_nm: d,
            volume_fraction: pvc,
        }],
    );
    let geom = pack_rsa(&params, 7).unwrap();
    let grid = Grid {
        nx: 32,
        ny: 32,
        nz: 40,
        size_nm: size,
    };
    let raster = rasterize(&geom, &grid, 4);
    let eps_b = 1.558f64.powi(2);
    let n = material.index_at(wl).unwrap();
    let eps_p = n * n;
    let mut eps = Array3::zeros((grid.nz, grid.ny, grid.nx));
    raster.epsilon_into(C64::new(eps_b, 0.0), &[eps_p], &mut eps);
    let p = Problem {
        tensor: None,
        lattice: Problem::lattice([32, 32, 40], size, wl, polar, 0.0),
        eps: &eps,
        eps_binder: eps_b,
        wave: inksim::solver::Wave::Scalar,
    };
    let ctl = Controls {
        tolerance: 1e-8,
        max_iterations: 10_000,
        precision: Precision::F64,
        background: inksim::config::Background::DEFAULT,
    };
    let e = efficiencies(&solver::solve(&p, Method::Auto, &ctl).unwrap());
    let s = airy::slab(eps_p * pvc + eps_b * (1.0 - pvc), 400.0, wl, polar);
    let err = (e.total_reflectance - s.r.norm_sqr())
        .abs()
        .max((e.total_transmittance - s.t.norm_sqr()).abs())
        .max((e.absorption - s.absorption).abs());
    let term = GrainTerm {
        volume_fraction: pvc,
        diameter_nm: d,
        delta_eps: eps_p - eps_b,
    };
    let est = airy::effective_medium_error(&[term], eps_b, 400.0, wl, polar);
    (err, est)
}

#[test]
fn the_estimate_bounds_measured_errors_and_is_not_vacuous() {
    let strong =
        Material::from_csv_text("strong", "wavelength_nm,n,k\n380,1.4,0.8\n780,1.4,0.8\n").unwrap();
    let white =
        Material::from_csv_text("white", "wavelength_nm,n,k\n380,2.6,0\n780,2.6,0\n").unwrap();
    let blue = Material::builtin("blue").unwrap();
    let red = Material::builtin("red").unwrap();
    let mut tightest = f64::INFINITY;
    for (m, d, pvc, wl, polar) in [
        (&blue, 10.0, 0.1, 400.0, 0.0),
        (&blue, 20.0, 0.3, 550.0, 60.0),
        (&strong, 10.0, 0.1, 400.0, 60.0),
        (&red, 20.0, 0.3, 450.0, 0.0),
        (&white, 10.0, 0.1, 400.0, 60.0),
        (&white, 20.0, 0.3, 550.0, 0.0),
    ] {
        let (err, est) = measured(m, d, pvc, wl, polar);
        assert!(
            err <= est,
            "{} {d} nm {pvc} {wl} nm {polar}°: error {err:.3e} > estimate {est:.3e}",
            m.name
        );
        eprintln!(
            "{} {d} nm {pvc} {wl} nm {polar}°: error {err:.3e}, estimate {est:.3e}",
            m.name
        );
        tightest = tightest.min(est / err);
    }
    assert!(tightest < 10.0, "estimate ≥ {tightest:.1}× every error");
}
