//! `inksim match` on the fast model: round trips on synthetic targets
//! (recipe → fast-model colour with instrument-level noise → match), the
//! fewest colourants preferred from a large palette, the closest colour of
//! an unreachable target (checked by an exhaustive scan), the flag on
//! ingredients a target cannot tell apart, the metamerism index of a
//! spectral match, a batch correction, the fast model against the
//! baseline it stands for, and the command's files and errors.

mod common;

use common::cli::inksim_in;
use inksim::config::{Baseline, Measurement};
use inksim::optics::baseline::baseline_colours;
use inksim::optics::colour::delta_e2000;
use inksim::pipeline::baseline_input;
use inksim::r#match::correct::correction_step;
use inksim::r#match::forward::Recipe;
use inksim::r#match::problem::Problem;
use inksim::r#match::{report, run, MatchSpec};
use rand::SeedableRng;
use rand_distr_free::gaussian;
use std::path::Path;

/// Box–Muller normal deviates from the crate's own generator (no extra
/// dependency).
mod rand_distr_free {
    use rand::Rng;
    pub fn gaussian(rng: &mut impl Rng) -> f64 {
        let (u, v): (f64, f64) = (rng.gen_range(1e-12..1.0), rng.gen());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// A palette pigment table.
fn pigment(name: &str, material: &str, d: f64, max: f64) -> String {
    format!(
        "[[palette]]\nname = \"{name}\"\nmaterial = {material}\ndiameter_nm = {d}\npvc_range = [0.0, {max}]\n"
    )
}

/// Stand-ins and library pigments: 12 in all.
fn palette12() -> String {
    [
        pigment("red", "{ builtin = \"red\" }", 150.0, 0.2),
        pigment("yellow", "{ builtin = \"yellow\" }", 150.0, 0.2),
        pigment("blue", "{ builtin = \"blue\" }", 150.0, 0.2),
        pigment("green", "{ builtin = \"green\" }", 150.0, 0.2),
        pigment("red-lorentz", "{ builtin = \"red-lorentz\" }", 100.0, 0.2),
        pigment(
            "yellow-lorentz",
            "{ builtin = \"yellow-lorentz\" }",
            100.0,
            0.2,
        ),
        pigment("blue-lorentz", "{ builtin = \"blue-lorentz\" }", 100.0, 0.2),
        pigment("rutile", "{ library = \"rutile\" }", 250.0, 0.3),
        pigment("hematite", "{ library = \"hematite\" }", 200.0, 0.2),
        pigment("cds", "{ library = \"cds\" }", 200.0, 0.2),
        pigment("soot", "{ library = \"soot\" }", 50.0, 0.05),
        pigment("zno", "{ library = \"zno\" }", 200.0, 0.2),
    ]
    .concat()
}

/// A match file: settings, a CIELAB target (D65, 10°) in `colours`, the
/// base layer of `thickness_nm` on white paper of albedo 0.85, `palette`.
fn match_text(
    settings: &str,
    colours: &[(Measurement, [f64; 3])],
    thickness_nm: f64,
    palette: &str,
) -> String {
    let colours: Vec<String> = colours
        .iter()
        .map(|(m, l)| {
            format!(
                "{{ geometry = \"{}\", lab = [{}, {}, {}] }}",
                m.name(),
                l[0],
                l[1],
                l[2]
            )
        })
        .collect();
    format!(
        "[match]\n{settings}\n\
         [target]\nkind = \"lab\"\nilluminant = \"D65\"\nobserver_deg = 10\nnoise_lab = [0.05, 0.05, 0.05]\n\
         colour = [{}]\n\
         [base.layer]\nthickness_nm = {thickness_nm}\nfragment_nm = [2000.0, 2000.0]\nbinder_index = 1.5\n\
         [base.grid]\ncell_nm = 50.0\n\
         [base.illumination]\nwavelengths_nm = [430.0, 700.0]\npolar_deg = [0.0]\n\
         [base.substrate]\nkind = \"white\"\nalbedo = 0.85\n\
         {palette}",
        colours.join(", ")
    )
}

const GEOMETRIES: [Measurement; 3] = [
    Measurement::DiffuseEightSci,
    Measurement::FortyFiveZero,
    Measurement::DiffuseEightSce,
];

fn spec_of(text: &str) -> MatchSpec {
    MatchSpec::parse(Path::new("match-test.toml"), text).expect("valid match file")
}

/// The fast-model colour of a recipe (palette index, fraction) in every
/// geometry, each L*, a*, b* with Gaussian noise of σ `noise`.
fn target_of(
    settings: &str,
    thickness_nm: f64,
    palette: &str,
    recipe: &[(usize, f64)],
    noise: f64,
    seed: u64,
) -> Vec<(Measurement, [f64; 3])> {
    let placeholder: Vec<_> = GEOMETRIES.iter().map(|m| (*m, [50.0, 0.0, 0.0])).collect();
    let spec = spec_of(&match_text(settings, &placeholder, thickness_nm, palette));
    let p = report::problem(&spec).unwrap();
    let mut fractions = vec![0.0; spec.palette.len()];
    for &(i, f) in recipe {
        fractions[i] = f;
    }
    let r = Recipe {
        fractions,
        thickness_nm,
        paper_albedo: 0.85,
    };
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    GEOMETRIES
        .iter()
        .map(|&m| {
            let l = p.model.lab(&p.observer, &r, m).unwrap();
            (m, l.map(|v| v + noise * gaussian(&mut rng)))
        })
        .collect()
}

fn quiet(_: &str) {}

const SETTINGS: &str = "tolerance_de00 = 0.3\nmax_colourants = 3\nstarts = 4\n";

fn three() -> String {
    [
        pigment("red", "{ builtin = \"red\" }", 150.0, 0.2),
        pigment("yellow", "{ builtin = \"yellow\" }", 150.0, 0.2),
        pigment("blue", "{ builtin = \"blue\" }", 150.0, 0.2),
    ]
    .concat()
}

/// A translucent 2 µm layer on white paper fixes each pigment's amount:
/// the match is within 0.1 ΔE00 of a target with instrument noise (σ 0.02
/// in L*, a*, b*: about 0.03–0.05 ΔE00) and recovers the fractions within
/// 3 % and within 3 standard errors, unflagged.
#[test]
fn round_trip_recovers_a_translucent_recipe() {
    let palette = three();
    let truth = [(0, 0.05), (1, 0.08)];
    for seed in 1..=3 {
        let target = target_of(SETTINGS, 2000.0, &palette, &truth, 0.02, seed);
        let spec = spec_of(&match_text(SETTINGS, &target, 2000.0, &palette));
        let r = run(&spec, &quiet).unwrap();
        let best = &r.recipes[0];
        assert!(best.reached);
        assert_eq!(
            best.candidate.subset,
            vec![0, 1],
            "seed {seed}: {:?}",
            best.candidate
        );
        let de = best.candidate.fit.de00_max();
        assert!(de < 0.1, "seed {seed}: ΔE00 {de}");
        let se = best.uncertainty.se.as_ref().expect("determined");
        for (k, &(_, f)) in truth.iter().enumerate() {
            let got = best.candidate.x[k];
            assert!(
                (got - f).abs() < 0.03 * f,
                "seed {seed}: pigment {k}: {got} vs {f}"
            );
            assert!(
                (got - f).abs() < 3.0 * se[k],
                "seed {seed}: pigment {k}: {got} vs {f} ± {}",
                se[k]
            );
        }
        assert!(
            best.uncertainty.flags.iter().all(String::is_empty),
            "{:?}",
            best.uncertainty.flags
        );
        println!(
            "seed {seed}: ΔE00 {de:.4}, fractions {:?} ± {se:?}",
            best.candidate.x
        );
    }
}

/// An opaque layer shows only the ratio of absorption to scattering: the
/// red and white of a pink are recovered in the right ratio, and flagged as
/// not told apart (correlation near 1).
#[test]
fn opaque_tint_is_flagged_as_not_separable() {
    let palette = [
        three(),
        pigment("rutile", "{ library = \"rutile\" }", 250.0, 0.3),
    ]
    .concat();
    let truth = [(0, 0.03), (3, 0.12)];
    let target = target_of(SETTINGS, 15000.0, &palette, &truth, 0.0, 1);
    let settings = "tolerance_de00 = 0.05\nmax_colourants = 2\nstarts = 4\n";
    let spec = spec_of(&match_text(settings, &target, 15000.0, &palette));
    let r = run(&spec, &quiet).unwrap();
    let best = &r.recipes[0];
    assert_eq!(best.candidate.subset, vec![0, 3]);
    let ratio = best.candidate.x[0] / best.candidate.x[1];
    assert!((ratio - 0.25).abs() < 0.01 * 0.25, "ratio {ratio}");
    let corr = best.uncertainty.correlation.as_ref().unwrap();
    assert!(corr[0][1] > 0.95, "correlation {}", corr[0][1]);
    assert!(
        best.uncertainty.flags[0].contains("not told apart from rutile"),
        "{:?}",
        best.uncertainty.flags
    );
}

/// A target of 2 pigments matched from a palette of 12 returns the
/// 2-pigment recipe first (no single pigment reaches it; no other pair is
/// as close).
#[test]
fn two_pigment_target_from_twelve() {
    let palette = palette12();
    let truth = [(1, 0.06), (2, 0.04)];
    let target = target_of(SETTINGS, 2000.0, &palette, &truth, 0.02, 7);
    let spec = spec_of(&match_text(SETTINGS, &target, 2000.0, &palette));
    assert_eq!(spec.palette.len(), 12);
    let r = run(&spec, &quiet).unwrap();
    let best = &r.recipes[0];
    assert!(best.reached, "{:?}", best.candidate.fit);
    assert_eq!(best.candidate.subset, vec![1, 2]);
    assert_eq!(
        r.largest, 2,
        "3-pigment subsets are not tried once a pair reaches"
    );
    assert!(best.candidate.fit.de00_max() < 0.1);
}

/// A red more saturated than the red and yellow stand-ins make in a thin
/// layer: the report says so and gives the closest reachable colour, which
/// uses both pigments (the red inside its bounds); an exhaustive scan of every
/// 1- and 2-pigment recipe on a fine grid finds none closer.
#[test]
fn unreachable_target_reports_the_closest_colour() {
    let palette = [
        pigment("red", "{ builtin = \"red\" }", 150.0, 0.2),
        pigment("yellow", "{ builtin = \"yellow\" }", 150.0, 0.2),
    ]
    .concat();
    let target = [(Measurement::DiffuseEightSci, [45.0, 75.0, 65.0])];
    let settings = "tolerance_de00 = 1.0\nmax_colourants = 2\nstarts = 6\n";
    let spec = spec_of(&match_text(settings, &target, 2000.0, &palette));
    let r = run(&spec, &quiet).unwrap();
    assert!(!r.reached());
    let best = &r.recipes[0];
    let reported = best.candidate.fit.de00[0];
    assert!(reported > 1.0);
    // The reported distance is the distance of the reported colour.
    assert!((delta_e2000(best.candidate.fit.lab[0], target[0].1) - reported).abs() < 1e-9);
    let p: Problem = report::problem(&spec).unwrap();
    let mut closest = (f64::INFINITY, [0.0; 2]);
    let steps = 200;
    for i in 0..=steps {
        for j in 0..=steps {
            let x = [0.2 * i as f64 / steps as f64, 0.2 * j as f64 / steps as f64];
            let d = p.fit(&p.recipe(&[0, 1], &x)).de00[0];
            if d < closest.0 {
                closest = (d, x);
            }
        }
    }
    // Not a corner of the box: the red is inside its bounds (the yellow is
    // at its most).
    let inside = |v: f64| v > 1e-3 && v < 0.2 - 1e-3;
    assert!(inside(closest.1[0]), "{closest:?}");
    assert_eq!(best.candidate.subset, vec![0, 1]);
    assert!(
        reported <= closest.0 + 1e-6,
        "reported {reported}, scan {closest:?}"
    );
    println!(
        "unreachable: reported {reported:.4} ΔE00 at {:?}, grid scan {:.4} at {:?}",
        best.candidate.x, closest.0, closest.1
    );
}

/// A target spectrum made by a recipe is matched spectrally: the
/// metamerism index under every test source is 0 (to the fit's residual).
#[test]
fn spectral_match_has_zero_metamerism_index() {
    let palette = three();
    let placeholder = [(Measurement::DiffuseEightSci, [50.0, 0.0, 0.0])];
    let spec = spec_of(&match_text(SETTINGS, &placeholder, 2000.0, &palette));
    let p = report::problem(&spec).unwrap();
    let r = Recipe {
        fractions: vec![0.04, 0.0, 0.03],
        thickness_nm: 2000.0,
        paper_albedo: 0.85,
    };
    let f = p.model.factor(&r, Measurement::DiffuseEightSci);
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("wavelength_nm,reflectance\n");
    for (w, v) in p.model.wavelengths_nm().iter().zip(&f) {
        csv.push_str(&format!("{w},{v}\n"));
    }
    std::fs::write(dir.path().join("target.csv"), csv).unwrap();
    let text = match_text(SETTINGS, &placeholder, 2000.0, &palette).replace(
        "kind = \"lab\"",
        "kind = \"spectrum\"\ncsv = \"target.csv\"\ngeometry = \"d/8 SCI\"",
    );
    let text = text
        .lines()
        .filter(|l| !l.starts_with("colour = "))
        .collect::<Vec<_>>()
        .join("\n");
    let path = dir.path().join("m.toml");
    let spec = MatchSpec::parse(&path, &text).unwrap();
    let out = run(&spec, &quiet).unwrap();
    let best = &out.recipes[0];
    assert_eq!(best.candidate.subset, vec![0, 2]);
    assert!(best.candidate.fit.spectral_rms.unwrap() < 1e-5);
    assert_eq!(best.metamerism.len(), 3);
    for (s, m) in &best.metamerism {
        assert!(m.index < 1e-3, "{}: {}", s.name(), m.index);
    }
}

/// A batch whose first pigment is 10 % weaker than the model's measures
/// more than 0.5 ΔE00 off; correcting the recipe by the fast model's
/// Jacobian brings it within 0.5 ΔE00 in at most 2 steps.
#[test]
fn batch_with_strength_error_is_corrected_in_two_steps() {
    let palette = three();
    let truth = [(0, 0.05), (1, 0.08)];
    let target = target_of(SETTINGS, 2000.0, &palette, &truth, 0.0, 1);
    let spec = spec_of(&match_text(SETTINGS, &target, 2000.0, &palette));
    let p = report::problem(&spec).unwrap();
    let subset = [0, 1];
    // What the batch measures: its first pigment at 90 % strength.
    let batch = |x: &[f64]| p.lab_stack(&p.recipe(&subset, &[0.9 * x[0], x[1]]));
    let de = |lab: &[f64]| {
        lab.chunks(3)
            .zip(&p.target_lab)
            .map(|(l, (_, t))| delta_e2000([l[0], l[1], l[2]], *t))
            .fold(0.0, f64::max)
    };
    let mut x = vec![0.05, 0.08];
    let first = de(&batch(&x));
    assert!(first > 0.5, "the strength error shows: {first}");
    let mut steps = 0;
    let mut now = first;
    while now >= 0.5 && steps < 2 {
        x = correction_step(&p, &subset, &x, &batch(&x)).unwrap();
        steps += 1;
        now = de(&batch(&x));
    }
    println!(
        "batch: {first:.3} ΔE00 → {now:.4} in {steps} step(s), red {:.5}",
        x[0]
    );
    assert!(now < 0.5, "after {steps} steps: {now}");
}

/// The fast model is the baseline: its colours equal
/// `baseline::baseline_colours` of the same layer, for both Kubelka–Munk
/// models, any recipe.
#[test]
fn fast_model_equals_the_baseline() {
    let palette = [
        three(),
        pigment("rutile", "{ library = \"rutile\" }", 250.0, 0.3),
    ]
    .concat();
    for model in [Baseline::KubelkaMunk, Baseline::KubelkaMunkScene] {
        let placeholder = [(Measurement::DiffuseEightSci, [50.0, 0.0, 0.0])];
        let text = match_text(SETTINGS, &placeholder, 3000.0, &palette).replace(
            "[base.substrate]",
            &format!(
                "[base.appearance]\nbaseline = \"{}\"\n[base.substrate]",
                model.name()
            ),
        );
        let spec = spec_of(&text);
        let p = report::problem(&spec).unwrap();
        let input = baseline_input(&spec.scene).unwrap().unwrap();
        let fractions = [0.03, 0.01, 0.02, 0.07];
        let r = Recipe {
            fractions: fractions.to_vec(),
            thickness_nm: 4500.0,
            paper_albedo: 0.6,
        };
        let layer = input.with_recipe(&fractions, 4500.0, 0.6);
        let reference =
            baseline_colours(model, &layer, &GEOMETRIES, &|_| None, &p.observer).unwrap();
        for c in reference {
            let f = p.model.factor(&r, c.geometry);
            let diff = f
                .iter()
                .zip(&c.reflectance_factor)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                diff < 1e-12,
                "{} {}: {diff}",
                model.name(),
                c.geometry.name()
            );
        }
    }
}

/// The command: the example runs, writes its HDF5 and CSV, and finds the
/// recipe the target was made of (red 0.03 + rutile 0.12, in ratio).
#[test]
fn command_writes_recipes() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cfg = root.join("configs/match-red-tint.toml");
    let out = dir.path().join("out");
    let (ok, stdout, stderr) = inksim_in(
        dir.path(),
        &[
            "match",
            cfg.to_str().unwrap(),
            "--output-dir",
            out.to_str().unwrap(),
        ],
    );
    assert!(ok, "{stderr}");
    assert!(stdout.contains("within 0.2 ΔE00"), "{stdout}");
    assert!(
        stderr.lines().all(|l| l.contains("Z [inksim] match: ")),
        "{stderr}"
    );
    let csv = std::fs::read_to_string(out.join("match-red-tint-recipes.csv")).unwrap();
    assert!(
        csv.lines()
            .next()
            .unwrap()
            .contains(",de00 d/8 SCI,de00_se d/8 SCI,L* d/8 SCI,"),
        "{csv}"
    );
    assert!(stdout.contains(" ± "), "{stdout}");
    let row = csv.lines().nth(1).unwrap();
    assert!(row.starts_with("1,2,1,\"red "), "{row}");
    assert!(row.contains("; rutile "), "{row}");
    let f = inksim::output::h5::open(out.join("match-red-tint.h5")).unwrap();
    let pvc = f.dataset("recipes/pvc").unwrap().read_2d::<f64>().unwrap();
    let (red, rutile) = (pvc[[0, 0]], pvc[[0, 4]]);
    assert!((red / rutile - 0.25).abs() < 0.01, "{red} {rutile}");
    let units: hdf5::types::VarLenUnicode = f
        .dataset("recipes/pvc")
        .unwrap()
        .attr("units")
        .unwrap()
        .read_scalar()
        .unwrap();
    assert_eq!(units.as_str(), "1");
}

/// A bad match file: one line naming the file and the key, a non-zero
/// exit, nothing written.
#[test]
fn bad_match_file_is_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/match-red-tint.toml"),
    )
    .unwrap();
    for (bad, key) in [
        (
            good.replace("observer_deg = 10", "observer_deg = 7"),
            "target.observer_deg",
        ),
        (
            good.replace("pvc_range = [0.0, 0.3]", "pvc_range = [0.0, 0.9]"),
            "palette[4].pvc_range",
        ),
        (
            good.replace("tolerance_de00 = 0.2", "tolerance_de00 = -1"),
            "match.tolerance_de00",
        ),
        (
            good.replace("kind = \"lab\"", "kind = \"lab\"\ncolor = 3"),
            "unknown field `color`",
        ),
        (
            good.replace("{ builtin = \"green\" }", "{ builtin = \"mauve\" }"),
            "palette[3].material.builtin",
        ),
        (
            good.replace("diameter_nm = 50.0", "diameter_nm = 50.0\ncolour = 3"),
            "unknown field `colour`",
        ),
        (
            good.replace(
                "baseline = \"kubelka-munk\"",
                "baseline = \"adding-doubling\"",
            ),
            "base.appearance.baseline",
        ),
        (
            format!("{good}\n[match.verify]\nmax_steps = 11\n"),
            "match.verify.max_steps",
        ),
        (
            format!("{good}\n[match.verify]\nrecipes = 6\n"),
            "match.verify.recipes",
        ),
        (
            format!("{good}\n[match.verify]\nwavelength_step_nm = 1.0\n"),
            "match.verify.wavelength_step_nm",
        ),
        (
            format!("{good}\n[match.verify]\nsteps = 2\n"),
            "unknown field `steps`",
        ),
    ] {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, bad.replace("runs/match-red-tint", "out")).unwrap();
        for cmd in ["match", "check"] {
            let (ok, _, stderr) = inksim_in(dir.path(), &[cmd, "bad.toml"]);
            assert!(!ok, "{cmd} {key}");
            let lines: Vec<&str> = stderr
                .lines()
                .filter(|l| !l.contains("[inksim] match:"))
                .collect();
            assert_eq!(lines.len(), 1, "{cmd} {key}: {stderr}");
            // No position in a text the user did not write.
            assert!(!lines[0].contains("column"), "{}", lines[0]);
            assert!(
                lines[0].starts_with("error: ")
                    && lines[0].contains("bad.toml")
                    && lines[0].contains(key),
                "{cmd}: {}",
                lines[0]
            );
        }
        assert!(
            !dir.path().join("out").exists(),
            "{key}: nothing is written"
        );
    }
}

/// A match file whose base scene is a wave scene: a `thickness_nm` layer
/// of `palette` on white paper (0.85), `grid` lines added to `[base]`,
/// verified by the wave solver (`verify` is the `[match.verify]` body).
fn wave_match_text(
    colours: &[(Measurement, [f64; 3])],
    thickness_nm: f64,
    base: &str,
    verify: &str,
    palette: &str,
) -> String {
    match_text(
        &format!("{SETTINGS}[match.verify]\n{verify}\n"),
        colours,
        thickness_nm,
        palette,
    )
    .replace(
        "[base.grid]\ncell_nm = 50.0\n",
        &format!("{base}\n[base.grid]\ncell_nm = 50.0\n"),
    )
}

/// The wave solution's colour of a recipe (palette index, fraction) in the
/// target geometries, from the verification's own scene.
fn wave_target(text: &str, recipe: &[(usize, f64)], dir: &Path) -> Vec<(Measurement, [f64; 3])> {
    let mut spec = spec_of(text);
    spec.output_dir = dir.to_path_buf();
    let mut fractions = vec![0.0; spec.palette.len()];
    for &(i, f) in recipe {
        fractions[i] = f;
    }
    let scene =
        inksim::r#match::verify::scene(&spec, &fractions, spec.scene.layer.thickness_nm, "truth")
            .unwrap();
    let report = inksim::pipeline::run_with(&scene, true, None).unwrap();
    let measured = report.appearance.unwrap().measured;
    spec.target
        .geometries()
        .iter()
        .map(|m| {
            let c = measured.iter().find(|c| c.geometry == *m).unwrap();
            (*m, c.lab)
        })
        .collect()
}

/// Dyes in a 1.5 µm film on white paper: the fast model (Kubelka–Munk with
/// Saunderson's surface) takes the film's light as diffuse and misses its
/// interference, so its recipe for a colour the exact (closed-form film)
/// solution made is 16–19 ΔE00 off; the verification says so, and the
/// correction by the fast–exact difference (learnt step by step) brings it
/// within the tolerance and recovers the true fractions far better than
/// the fast model's recipe.
#[test]
fn verification_corrects_the_fast_recipe_to_the_wave_colour() {
    let dir = tempfile::tempdir().unwrap();
    let dye = |name: &str, max: f64| {
        format!(
            "[[palette]]\nname = \"{name}\"\nmaterial = {{ builtin = \"{name}\" }}\n\
             shape = {{ kind = \"molecular\" }}\npvc_range = [0.0, {max}]\n"
        )
    };
    let palette = [dye("red", 0.3), dye("yellow", 0.3)].concat();
    let truth = [(0, 0.10), (1, 0.15)];
    let placeholder: Vec<_> = GEOMETRIES[..2]
        .iter()
        .map(|m| (*m, [50.0, 0.0, 0.0]))
        .collect();
    let verify = "max_steps = 8\nwavelength_step_nm = 10.0";
    let text = wave_match_text(&placeholder, 1500.0, "", verify, &palette);
    let target = wave_target(&text, &truth, dir.path());
    let text = wave_match_text(&target, 1500.0, "", verify, &palette);
    let mut spec = spec_of(&text);
    spec.output_dir = dir.path().join("out");
    let r = run(&spec, &quiet).unwrap();
    assert_eq!(r.verified.len(), 1);
    let v = &r.verified[0];
    let (first, last) = (&v.steps[0], v.last());
    println!("outcome: {}", v.outcome);
    for s in &v.steps {
        println!(
            "  pvc {:?}: wave ΔE00 {:?}, fast vs wave {:?}",
            s.fractions,
            s.de00,
            s.model_error()
        );
    }
    assert!(
        first.de00_max() > spec.search.tolerance_de00,
        "the fast recipe must miss the film's colour: {:?}",
        first.de00
    );
    assert!(v.verified, "{}", v.outcome);
    assert!(last.de00_max() <= spec.search.tolerance_de00);
    assert!(v.steps.len() >= 2 && v.steps.len() <= 9);
    // The fast model's own error on dyes in a thin film is large (its
    // diffuse K = 2 μa against the film's collimated light, no
    // interference): the correction does not need it small, only smooth.
    assert!(
        first.model_error().iter().all(|&e| e > 5.0),
        "{:?}",
        first.model_error()
    );
    let off = |s: &inksim::r#match::verify::VerifyStep| {
        truth
            .iter()
            .map(|&(i, f)| (s.fractions[i] / f - 1.0).abs())
            .fold(0.0, f64::max)
    };
    assert!(
        off(last) < off(first),
        "corrected {:?} vs fast {:?}",
        last.fractions,
        first.fractions
    );
    // Every step's wave result is kept, its scene inside.
    for s in &v.steps {
        assert!(s.result.exists(), "{}", s.result.display());
    }
}

/// The command with `[match.verify]`: it prints the verified recipe and
/// the fidelity, writes `/verify` (every dataset with units) and the
/// verification CSV, one row per step, and keeps each step's result file.
#[test]
fn command_verifies_and_writes_the_steps() {
    let dir = tempfile::tempdir().unwrap();
    let palette = "[[palette]]\nname = \"red\"\nmaterial = { builtin = \"red\" }\n\
                   shape = { kind = \"molecular\" }\npvc_range = [0.0, 0.3]\n";
    let placeholder = [(Measurement::FortyFiveZero, [50.0, 0.0, 0.0])];
    let verify = "max_steps = 3\nwavelength_step_nm = 30.0";
    let text = wave_match_text(&placeholder, 1000.0, "", verify, palette);
    let target = wave_target(&text, &[(0, 0.12)], dir.path());
    let text = wave_match_text(&target, 1000.0, "", verify, palette)
        .replace("[match]\n", "[match]\noutput_dir = \"out\"\nname = \"m\"\n");
    std::fs::write(dir.path().join("m.toml"), text).unwrap();
    let (ok, stdout, stderr) = inksim_in(dir.path(), &["check", "m.toml"]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("verification: the best 1 recipe(s)"),
        "{stdout}"
    );
    let (ok, stdout, stderr) = inksim_in(dir.path(), &["match", "m.toml"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("verified with the wave solver"), "{stdout}");
    assert!(stderr.contains("verify recipe 1 step 0"), "{stderr}");
    let out = dir.path().join("out");
    let csv = std::fs::read_to_string(out.join("m-verify.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert!(rows[0].starts_with("rank,step,verified,thickness_nm,pvc red,de00 45/0"));
    assert!(rows.len() >= 2, "{csv}");
    let f = inksim::output::h5::open(out.join("m.h5")).unwrap();
    let g = f.group("verify/001").unwrap();
    let steps = g.dataset("de00").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(steps.nrows(), rows.len() - 1);
    for name in [
        "lab",
        "lab_se",
        "lab_fast",
        "de00",
        "de00_fast_vs_wave",
        "pvc",
        "seconds",
    ] {
        let units: hdf5::types::VarLenUnicode = g
            .dataset(name)
            .unwrap()
            .attr("units")
            .unwrap()
            .read_scalar()
            .unwrap();
        assert!(
            !units.as_str().is_empty() || name == "result_file",
            "{name}"
        );
    }
    let files = std::fs::read_dir(out.join("verify")).unwrap().count();
    assert!(files >= steps.nrows(), "a result file per step");
    // The page: the target beside the fast recipe and the verified one,
    // and its spectra figure; drawn by a headless browser where there is
    // one, the target's patch on the screen.
    let html = std::fs::read_to_string(out.join("m.html")).unwrap();
    assert!(html.contains("recipe 1 (fast model)") && html.contains("recipe 1 verified (wave)"));
    assert!(html.contains("src=\"m-spectra.png\"") && out.join("m-spectra.png").is_file());
    let Some(browser) = common::browser::chromium() else {
        eprintln!("SKIPPED the match page in headless Chromium: no chromium on PATH");
        return;
    };
    let shot = dir.path().join("shot.png");
    let page = out.join("m.html").canonicalize().unwrap();
    std::process::Command::new(&browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
        ])
        .arg("--window-size=1200,900")
        .arg(format!(
            "--user-data-dir={}",
            dir.path().join("profile").display()
        ))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", page.display()))
        .output()
        .unwrap();
    let img = inksim::output::render::Canvas::decode_png(&std::fs::read(&shot).unwrap()).unwrap();
    let obs = inksim::optics::colour::Observer::standard(
        inksim::config::Illuminant::D65,
        inksim::config::StandardObserver::TenDegree,
    );
    let want = inksim::optics::colour::gamut::map_lab(&obs, target[0].1).srgb8;
    let shown = img
        .px
        .chunks_exact(3)
        .filter(|p| (0..3).all(|k| (p[k] as i32 - want[k] as i32).abs() <= 2))
        .count();
    assert!(shown > 500, "the target's patch {want:?}: {shown} pixels");
}

/// A verification whose wave runs would not fit `--max-memory` is refused
/// by `check` and by `match` before anything runs: one line naming the
/// grid and the limit, nothing written.
#[test]
fn a_verification_beyond_the_memory_limit_is_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/match-red-tint.toml"),
    )
    .unwrap()
    .replace("runs/match-red-tint", "out");
    std::fs::write(
        dir.path().join("m.toml"),
        format!("{good}\n[match.verify]\nmax_steps = 1\n"),
    )
    .unwrap();
    for cmd in ["check", "match"] {
        let (ok, _, stderr) = inksim_in(dir.path(), &[cmd, "m.toml", "--max-memory", "1M"]);
        assert!(!ok, "{cmd}");
        let lines: Vec<&str> = stderr
            .lines()
            .filter(|l| !l.contains("[inksim] match:"))
            .collect();
        assert_eq!(lines.len(), 1, "{cmd}: {stderr}");
        assert!(
            lines[0].contains("exceeds 1 MB (--max-memory)")
                && lines[0].contains("grid 40 × 40 × "),
            "{cmd}: {}",
            lines[0]
        );
        assert!(
            !dir.path().join("out").exists(),
            "{cmd}: nothing is written"
        );
    }
}
