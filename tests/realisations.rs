//! `realisations = { target_de00, max, min }`: realisations are added until
//! the colour is as certain as asked, or the most allowed are run; the run
//! says how many it took and why, in its plan and its result file.

use inksim::output::h5::read_measured;
use std::path::Path;

mod common;
use common::scene::{PigmentToml, SceneToml};

/// A small layer of blue grains with realisations given by `realisations`
/// (a TOML value), tile only.
fn scene(dir: &Path, realisations: &str) -> SceneToml {
    SceneToml::grains()
        .seed(11)
        .raw("realisations", realisations)
        .thickness_nm(300.0)
        .fragment_nm(600.0)
        .pigment(PigmentToml::builtin("blue").pvc(0.15).diameter_nm(120.0))
        .grid_n([12, 12, 8])
        .polar_deg(&[0.0])
        .tolerance(1e-6)
        .outputs(&["tile"])
        .measurements(&["45/0"])
        .quadrature_points(2)
        .output(dir, "r")
}

fn check_error(dir: &Path, scene: &SceneToml) -> String {
    scene.parse(&scene.write(dir)).unwrap_err().to_string()
}

/// Seeds, the stored attributes of `/realisations` and the stored plan.
fn stored(path: &Path) -> (usize, f64, f64, String, String) {
    let f = inksim::output::h5::open(path).unwrap();
    let g = f.group("realisations").unwrap();
    let seeds = g.dataset("seed").unwrap().read_raw::<u64>().unwrap().len();
    let scalar = |n: &str| g.attr(n).unwrap().read_scalar::<f64>().unwrap();
    let why = g
        .attr("stopped_because")
        .unwrap()
        .read_scalar::<hdf5::types::VarLenUnicode>()
        .unwrap()
        .to_string();
    let plan = f
        .dataset("plan")
        .unwrap()
        .read_scalar::<hdf5::types::VarLenUnicode>()
        .unwrap()
        .to_string();
    (
        seeds,
        scalar("target_de00_se"),
        scalar("achieved_de00_se"),
        why,
        plan,
    )
}

#[test]
fn a_loose_target_stops_at_the_fewest_realisations() {
    let dir = tempfile::tempdir().unwrap();
    let rep = scene(dir.path(), "{ target_de00 = 50.0, max = 6 }").run(dir.path());
    let (seeds, target, achieved, why, plan) = stored(&rep.result_path);
    assert_eq!(seeds, 3, "the default minimum is 3");
    assert!(
        plan.contains("realisations: 3 to 6, added until")
            && plan.contains("realisations: 3 of at most 6"),
        "{plan}"
    );
    assert_eq!(target, 50.0);
    assert!(achieved > 0.0 && achieved <= 50.0, "{achieved}");
    assert_eq!(why, "target standard error reached");
    // The stored standard error is the measured colour's.
    let (measured, _, _) = read_measured(&rep.result_path).unwrap().unwrap();
    let se = measured
        .iter()
        .map(|m| m.de00_se.unwrap())
        .fold(0.0, f64::max);
    assert!((se - achieved).abs() < 1e-12, "{se} vs {achieved}");
    let a = rep.appearance.unwrap();
    assert_eq!(a.spec.realisations, 3);
}

#[test]
fn an_unreachable_target_runs_the_most_allowed_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let rep = scene(dir.path(), "{ target_de00 = 1e-9, min = 2, max = 4 }").run(dir.path());
    let (seeds, _, achieved, why, plan) = stored(&rep.result_path);
    assert_eq!(seeds, 4);
    assert!(plan.contains("realisations: 4, the most allowed"), "{plan}");
    assert!(achieved > 1e-9);
    assert_eq!(why, "most realisations allowed reached");
    // Every solve of the four realisations is in the result.
    let realisations: std::collections::BTreeSet<usize> =
        rep.entries.iter().map(|e| e.realisation).collect();
    assert_eq!(realisations.len(), 4);
}

#[test]
fn a_count_and_a_target_agree_where_the_target_stops() {
    // The target run that stops after its minimum of 2 realisations is the
    // same computation as a run of 2 realisations: same seeds, same colour.
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    let ra = scene(&a, "{ target_de00 = 50.0, min = 2, max = 5 }").run(&a);
    let rb = scene(&b, "2").run(&b);
    let la = ra.appearance.unwrap().measured[0].lab;
    let lb = rb.appearance.unwrap().measured[0].lab;
    assert_eq!(la, lb);
}

#[test]
fn bad_targets_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases = [
        (
            "{ target_de00 = 0.0, max = 4 }",
            ["tile"],
            "realisations.target_de00",
        ),
        (
            "{ target_de00 = 0.5, min = 5, max = 4 }",
            ["tile"],
            "realisations.max",
        ),
        (
            "{ target_de00 = 0.5, min = 1, max = 4 }",
            ["tile"],
            "realisations.min",
        ),
        (
            "{ target_de00 = 0.5, max = 4, maximum = 3 }",
            ["tile"],
            "maximum",
        ),
        (
            "{ target_de00 = 0.5, max = 4 }",
            ["brdf"],
            "realisations.target_de00",
        ),
        ("0", ["tile"], "realisations"),
    ];
    for (value, outputs, key) in cases {
        let msg = check_error(d, &scene(d, value).outputs(&outputs));
        assert!(msg.contains(key), "{value}: {msg}");
        assert!(!msg.contains('\n'), "one line: {msg}");
    }
}

/// A 1 µm layer of red grains at 30 % PVC (parsed only, never run).
fn layer(fragment_nm: f64, diameter_nm: f64, realisations: i64) -> SceneToml {
    SceneToml::grains()
        .thickness_nm(1000.0)
        .fragment_nm(fragment_nm)
        .layer_pvc(0.3)
        .pigment(PigmentToml::builtin("red").diameter_nm(diameter_nm))
        .cell_nm(20.0)
        .realisations(realisations)
}

#[test]
fn the_fragments_statistical_error_falls_as_one_over_root_grains_times_realisations() {
    use inksim::pipeline::accuracy::{
        expected_error, fragment_c, realisations_for, statistical_de00, FRAGMENT_C_FINE,
        FRAGMENT_C_MIXTURE, FRAGMENT_C_SINGLE,
    };
    // The constant: measured at 100 and 20 nm steps, log–log between, held
    // beyond; one pigment and mixtures alike at 20 nm.
    assert_eq!(fragment_c(false, 100.0), FRAGMENT_C_SINGLE);
    assert_eq!(fragment_c(true, f64::INFINITY), FRAGMENT_C_MIXTURE);
    assert_eq!(fragment_c(true, 20.0), FRAGMENT_C_FINE);
    assert_eq!(fragment_c(false, 10.0), FRAGMENT_C_FINE);
    let mid = fragment_c(true, 20.0 * 5f64.sqrt());
    assert!((mid - (FRAGMENT_C_FINE * FRAGMENT_C_MIXTURE).sqrt()).abs() < 1e-12);
    assert!(fragment_c(true, 50.0) > fragment_c(true, 30.0));
    let dir = tempfile::tempdir().unwrap();
    let at = |s: SceneToml| s.scene(dir.path());
    // 0.3 × 1400² × 1000 nm³ over a 200 nm sphere's volume: 140.4 grains.
    let grains = 0.3 * 1400.0f64.powi(2) * 1000.0 / (std::f64::consts::PI / 6.0 * 200.0f64.powi(3));
    let base = statistical_de00(&at(layer(1400.0, 200.0, 2)), 2);
    let step = |s: &inksim::config::Scene| {
        let w = &s.wavelengths_nm;
        (w[w.len() - 1] - w[0]) / (w.len() - 1) as f64
    };
    let c_single = fragment_c(false, step(&at(layer(1400.0, 200.0, 2))));
    let exact = c_single * (1.0 / (grains * 2.0)).sqrt();
    assert!((base - exact).abs() < 1e-12 * exact, "{base} vs {exact}");
    // Twice the fragment's side (4× the grains) or 4× the realisations halve it.
    let wide = statistical_de00(&at(layer(2800.0, 200.0, 2)), 2);
    assert!((wide - base / 2.0).abs() < 1e-12);
    assert!((statistical_de00(&at(layer(1400.0, 200.0, 8)), 8) - base / 2.0).abs() < 1e-12);
    // Grains twice as large: 8× fewer, √8× the scatter.
    let coarse = statistical_de00(&at(layer(1400.0, 400.0, 2)), 2);
    assert!((coarse - base * 8f64.sqrt()).abs() < 1e-9);
    // Clusters of 8 grains scatter as 8× fewer grains.
    let agglo = layer(1400.0, 200.0, 2).raw("pigment.0.agglomeration", "{ cluster_size = 8 }");
    assert!((statistical_de00(&at(agglo), 2) - base * 8f64.sqrt()).abs() < 1e-9);
    // A mixture of two pigments, half the PVC each: Σ 1/N = 4/N, and its own constant.
    let mix = layer(1400.0, 200.0, 2)
        .pigment(PigmentToml::builtin("yellow").share(1.0).diameter_nm(200.0))
        .add_pigment(PigmentToml::builtin("blue").share(1.0).diameter_nm(200.0));
    let mix = at(mix);
    let m = statistical_de00(&mix, 2);
    let exact = fragment_c(true, step(&mix)) * (4.0 / (grains * 2.0)).sqrt();
    assert!((m - exact).abs() < 1e-9 * exact, "{m} vs {exact}");
    // A dissolved dye is the same in every realisation.
    let dye = SceneToml::grains()
        .layer_pvc(0.3)
        .pigment(PigmentToml::builtin("red").molecular());
    assert_eq!(statistical_de00(&at(dye.clone()), 2), 0.0);
    assert!(!expected_error(&at(dye))
        .iter()
        .any(|l| l.contains("fragment")));
    // Realisations for a target, and the row that names the fragment.
    let s = at(layer(1400.0, 400.0, 2));
    let one = statistical_de00(&s, 1);
    let r = realisations_for(&s, 0.5);
    assert!(
        statistical_de00(&s, r) <= 0.5 && statistical_de00(&s, r - 1) > 0.5,
        "{one} {r}"
    );
    let text = expected_error(&s).join("\n");
    assert!(
        text.contains("fragment 1400 × 1400 nm (17.5 grains), 2 realisation(s)"),
        "{text}"
    );
}

#[test]
fn a_deterministic_layer_runs_once_and_its_colour_is_exact() {
    // A dissolved dye: nothing random, so one realisation of the two asked
    // for, and standard errors of exactly 0 (not unknown).
    let dir = tempfile::tempdir().unwrap();
    let rep = SceneToml::grains()
        .thickness_nm(500.0)
        .layer_pvc(0.3)
        .pigment(PigmentToml::builtin("red").molecular())
        .realisations(2)
        .wavelengths_nm(&[450.0, 550.0, 650.0])
        .polar_deg(&[0.0])
        .outputs(&["tile"])
        .measurements(&["45/0", "d/8 SCI"])
        .output(dir.path(), "dye")
        .run(dir.path());
    let (measured, _, _) = read_measured(&rep.result_path).unwrap().unwrap();
    assert_eq!(measured.len(), 2);
    for m in &measured {
        assert_eq!(m.lab_se, Some([0.0; 3]), "{}", m.geometry);
        assert_eq!(m.de00_se, Some(0.0), "{}", m.geometry);
    }
    // A granular layer with one realisation has no standard error at all.
    let grains = scene(dir.path(), "1")
        .output(dir.path(), "one")
        .run(dir.path());
    let (measured, _, _) = read_measured(&grains.result_path).unwrap().unwrap();
    assert!(measured
        .iter()
        .all(|m| m.lab_se.is_none() && m.de00_se.is_none()));
}
