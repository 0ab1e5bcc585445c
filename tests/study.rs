//! The study driver end to end: sweep expansion, naming and
//! seeding; plan figures against what a run does; resume after a kill, and
//! truncated or mismatched results redone; shards adding up to the
//! unsharded run bit for bit; bad sweep files rejected before any work;
//! merge. Scenes are tiny (8 × 8 × 4 grids) except the kill test's.
use inksim::output::h5::{read_summary, ResultSummary};
use inksim::study::sweep::{variant_seed, Study};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::cli::inksim_in;
use common::keys::floats;
use common::scene::{PigmentToml, SceneToml};
use common::study::StudyToml;

/// One red pigment of 100 nm at 15 % PVC in a 400 nm layer, 8 × 8 × 4
/// grid, two wavelengths.
fn base() -> SceneToml {
    SceneToml::grains()
        .thickness_nm(400.0)
        .fragment_nm(400.0)
        .layer_pvc(0.15)
        .pigment(PigmentToml::builtin("red").named("p").diameter_nm(100.0))
        .cell_nm(50.0)
        .z_cell_nm(100.0)
        .wavelengths_nm(&[450.0, 600.0])
        .polar_deg(&[0.0])
}

/// Two pigments × two sizes of `base`; profiles `quick` (the default) and
/// `three` (three wavelengths).
fn sweep_of(base: &SceneToml) -> StudyToml {
    StudyToml::new("t", 5, "out", base)
        .profile("quick")
        .profile_key("quick", "realisations", 1)
        .profile_key(
            "three",
            "illumination.wavelengths_nm",
            floats(&[450.0, 550.0, 650.0]),
        )
        .axis(
            "pigment",
            "pigment.0.material.builtin",
            r#"["red", "yellow"]"#,
        )
        .axis("d", "pigment.*.diameter_nm", "[100.0, 150.0]")
}

fn sweep() -> StudyToml {
    sweep_of(&base())
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn zipped(study: StudyToml) -> StudyToml {
    study.zip(&["pigment", "d"])
}

fn parse(study: &StudyToml) -> Study {
    Study::parse(Path::new("/virtual/sweep.toml"), &study.toml()).unwrap()
}

fn names(study: &StudyToml, profile: Option<&str>) -> Vec<String> {
    parse(study)
        .expand(profile)
        .unwrap()
        .variants
        .into_iter()
        .map(|v| v.name)
        .collect()
}

/// Everything of a summary but its creation time.
fn key(s: &ResultSummary) -> ResultSummary {
    ResultSummary {
        created_unix_s: 0,
        ..s.clone()
    }
}

/// All result summaries of a study folder, by variant name.
fn results(variants: &Path) -> BTreeMap<String, ResultSummary> {
    let mut m = BTreeMap::new();
    for e in std::fs::read_dir(variants).unwrap().flatten() {
        let p = e.path();
        if p.extension().is_some_and(|x| x == "h5") {
            let n = p.file_stem().unwrap().to_string_lossy().into_owned();
            m.insert(n, key(&read_summary(&p).unwrap()));
        }
    }
    m
}

#[test]
fn expansion_order_names_and_seeds() {
    let s = parse(&sweep());
    let e = s.expand(None).unwrap();
    let n: Vec<&str> = e.variants.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(n, ["red_d100", "red_d150", "yellow_d100", "yellow_d150"]);
    assert_eq!(e.profile.as_deref(), Some("quick"));
    assert_eq!(e.study_dir, Path::new("out/quick"));
    for v in &e.variants {
        assert_eq!(v.seed, variant_seed(5, &v.name));
        assert_eq!(v.scene.seed, v.seed);
        assert_eq!(v.scene.output.name, v.name);
        assert_eq!(v.scene.output.dir, Path::new("out/quick/variants"));
        assert_eq!(v.scene.provenance.text, v.text);
    }
    let y150 = &e.variants[3];
    assert_eq!(y150.scene.species[0].material.name, "yellow");
    assert_eq!(y150.scene.species[0].diameter_nm, 150.0);
    assert_eq!(y150.label("d"), Some("d150"));

    // Seeds depend on the name only: other values, other order, same seed.
    let other = sweep()
        .raw("axis.0.values", r#"["yellow", "blue", "red"]"#)
        .raw("axis.1.values", "[150.0, 80.0, 100.0]");
    let e2 = parse(&other).expand(None).unwrap();
    assert_eq!(e2.variants.len(), 9);
    let find = |name: &str| e2.variants.iter().find(|v| v.name == name).unwrap();
    for v in &e.variants {
        let w = find(&v.name);
        assert_eq!(w.seed, v.seed, "{}", v.name);
        assert_eq!(w.text, v.text, "{}", v.name);
    }
    // The profile changes the scenes but not the names or seeds.
    let e3 = s.expand(Some("three")).unwrap();
    assert_eq!(e3.variants[0].scene.wavelengths_nm, [450.0, 550.0, 650.0]);
    assert_eq!(e3.variants[0].seed, e.variants[0].seed);
    assert_eq!(e3.study_dir, Path::new("out/three"));
}

#[test]
fn zip_exclude_explicit_and_compound_values() {
    // Zipped: red with 100, yellow with 150. The explicit variant takes the
    // d axis value (label d150) and then its `set` replaces the pigments.
    let text = zipped(sweep()).variant(
        "mix",
        concat!(
            r#"labels = { d = "d150" }, set = { "pigment" = ["#,
            r#"{ name = "y", material = { builtin = "yellow" }, diameter_nm = 80.0 }, "#,
            r#"{ name = "b", material = { builtin = "blue" }, share = 3.0, diameter_nm = 90.0 }"#,
            "] }",
        ),
    );
    let e = parse(&text).expand(None).unwrap();
    let n: Vec<&str> = e.variants.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(n, ["red_d100", "yellow_d150", "mix"]);
    assert_eq!(e.variants[1].scene.species[0].diameter_nm, 150.0);
    let mix = &e.variants[2];
    assert_eq!(mix.label("d"), Some("d150"));
    assert_eq!(mix.label("pigment"), None);
    assert_eq!(mix.seed, variant_seed(5, "mix"));
    let sp = &mix.scene.species;
    assert_eq!(sp.len(), 2);
    assert!((sp[0].volume_fraction - 0.15 / 4.0).abs() < 1e-12);
    assert!((sp[1].volume_fraction - 0.15 * 3.0 / 4.0).abs() < 1e-12);
    assert_eq!((sp[0].diameter_nm, sp[1].diameter_nm), (80.0, 90.0));

    // Compound axis with wildcard over two pigments, and an exclusion.
    let compound = sweep()
        .compound_axis(
            "grain",
            &[
                ("mol", r#"{ "pigment.*.shape" = { kind = "molecular" } }"#),
                (
                    "cyl",
                    concat!(
                        r#"{ "pigment.*.shape" = { kind = "cylinder", aspect = 3.0, spheres = 5 }, "#,
                        r#""pigment.*.orientation" = "in-plane" }"#,
                    ),
                ),
            ],
        )
        .exclude(&[("pigment", "yellow"), ("grain", "cyl")]);
    let n = names(&compound, None);
    assert_eq!(n.len(), 8 - 2);
    assert!(n.contains(&"red_d150_cyl".to_string()));
    assert!(!n
        .iter()
        .any(|x| x.starts_with("yellow") && x.ends_with("cyl")));
}

/// A bad sweep: the CLI fails with one `error:` line containing every
/// needle, before any work (no output folder).
fn expect_error(study: StudyToml, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &study.toml());
    for cmd in ["run", "plan"] {
        let (ok, _, err) = inksim_in(dir.path(), &[cmd, p.to_str().unwrap()]);
        assert!(!ok, "{cmd} should fail: {needles:?}");
        assert!(!err.contains("panicked"), "{err}");
        let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(lines.len(), 1, "one line expected: {err}");
        assert!(lines[0].starts_with("error: "), "{err}");
        assert!(err.contains("sweep.toml"), "file not named: {err}");
        for n in needles {
            assert!(err.contains(n), "`{n}` not in: {err}");
        }
        assert!(!dir.path().join("out").exists(), "work started: {err}");
    }
}

#[test]
fn bad_sweep_files_are_rejected_before_any_work() {
    // An axis naming an unknown key: the scene schema rejects it, the
    // message names the axis and the key path.
    expect_error(
        sweep().set("axis.1.key", "pigment.*.diametre_nm"),
        &["axis `d`", "diametre_nm", "unknown field"],
    );
    expect_error(
        sweep().set("axis.0.key", "layer.pigment_colour"),
        &["axis `pigment`", "pigment_colour"],
    );
    // An out-of-range index.
    expect_error(
        sweep().set("axis.1.key", "pigment.1.diameter_nm"),
        &["axis `d`", "index 1 is out of range"],
    );
    // An empty axis.
    expect_error(
        sweep().raw("axis.1.values", "[]"),
        &["axis `d`", "no values"],
    );
    // An exclusion that matches nothing (zipped, red never meets d150).
    expect_error(
        zipped(sweep()).exclude(&[("pigment", "red"), ("d", "d150")]),
        &["[[exclude]] 1", "matches no combination"],
    );
    // An exclusion naming a label that does not exist.
    expect_error(
        sweep().exclude(&[("d", "d999")]),
        &["axis `d` has no label `d999`", "d100, d150"],
    );
    // Two variants with the same name.
    expect_error(
        sweep().variant("red_d100", ""),
        &["two variants are named `red_d100`"],
    );
    expect_error(
        sweep().raw("axis.1.labels", r#"["x+", "x*"]"#),
        &["two variants are named `red_x-`"],
    );
    // An unknown profile, a reserved key, an invalid value.
    expect_error(
        sweep().profile("fast"),
        &["unknown profile `fast`", "quick, three"],
    );
    expect_error(
        sweep().set("axis.1.key", "seed"),
        &["axis `d`", "`seed`", "cannot be overridden"],
    );
    expect_error(
        sweep().raw("axis.1.values", "[100.0, 500.0]"),
        &["variant `red_d500`", "diameter_nm", "axis `d`"],
    );
}

#[test]
fn plan_figures_match_the_run_and_merge_needs_every_variant() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &sweep().toml());
    let ps = p.to_str().unwrap();
    let (ok, plan, err) = inksim_in(dir.path(), &["plan", ps, "--profile", "three"]);
    assert!(ok, "{err}");
    assert!(plan.contains("calibrated now on this machine"), "{plan}");
    assert!(
        plan.contains("grid 8×8×4 (helmholtz, f64 fields): setup"),
        "{plan}"
    );
    // The fragment's statistics: 0.15 × 400³ nm³ holds 18.3 grains of
    // 100 nm and 5.43 of 150 nm, so s.e. ≤ 1 takes ⌈49 / 5.43⌉ = 10
    // realisations of the coarse variants (C = 7).
    assert!(
        plan.contains(
            "fragment s.e. ≤ 1 for every variant (4 need more realisations): \
             `realisations = { target_de00 = 1, min = 2, max = 10 }`"
        ),
        "{plan}"
    );
    // Per-variant rows: "#  name  solves  grid  voxels  real. ..."
    let mut planned = BTreeMap::new();
    for l in plan.lines() {
        let f: Vec<&str> = l.split_whitespace().collect();
        if f.len() > 5 && f[0].parse::<usize>().is_ok() {
            assert_eq!(f[3], "8×8×4", "{l}");
            assert_eq!(f[4], "256", "{l}");
            planned.insert(f[1].to_string(), f[2].parse::<usize>().unwrap());
        }
    }
    assert_eq!(planned.len(), 4, "{plan}");
    let study = Study::load(&p).unwrap();
    let quick: usize = study
        .expand(Some("quick"))
        .unwrap()
        .variants
        .iter()
        .map(|v| inksim::pipeline::planned_solves(&v.scene))
        .sum();
    assert!(
        plan.contains(&format!("quick      4 variants, {quick} solves")),
        "{plan}"
    );
    let three = study.expand(Some("three")).unwrap();

    let (ok, _, err) = inksim_in(dir.path(), &["merge", ps, "--profile", "three"]);
    assert!(
        !ok && err.contains("4 of 4 variants are not finished"),
        "{err}"
    );
    assert!(err.contains("red_d100 (no result yet)"), "{err}");

    let (ok, out, err) = inksim_in(dir.path(), &["run", ps, "--profile", "three"]);
    assert!(ok, "{err}");
    assert!(out.contains("4 ran, 0 skipped"), "{out}");
    let got = results(&dir.path().join("out/three/variants"));
    for v in &three.variants {
        let n = planned[&v.name];
        assert_eq!(got[&v.name].entries.len(), n, "{}", v.name);
        assert_eq!(n, inksim::pipeline::planned_solves(&v.scene));
    }
    let (ok, plan2, _) = inksim_in(dir.path(), &["plan", ps, "--profile", "three"]);
    // The finished results' applications against the rates assumed for
    // them, averaged with 1 counted as 5 results; per kind of top, so the
    // flat results leave the surfaces' factor alone.
    // Applications recorded over assumed, over the variants named `prefix…`.
    let rate_of = |prefix: &str| {
        let (mut measured, mut assumed) = (0.0, 0.0);
        for v in three.variants.iter().filter(|v| v.name.starts_with(prefix)) {
            for e in &got[&v.name].entries {
                measured += e.operator_applications.expect("recorded") as f64;
                assumed += inksim::study::plan::default_applications(&v.scene);
            }
        }
        measured / assumed
    };
    let r = rate_of("");
    let blended = (5.0 + 4.0 * r) / 9.0;
    assert!(
        ok && plan2.contains(&format!(
            "flat tops × {blended:.2}: the 4 finished result(s) of this kind needed {r:.2}× the \
             assumed rates, averaged with 1× counted as 5 result(s); surfaces × 1.00: no \
             finished result of this kind yet"
        )),
        "{plan2}"
    );
    // Each pigment's own results scale its own rates by the same rule.
    for pigment in ["red", "yellow"] {
        let r = rate_of(pigment);
        let blended = (5.0 + 2.0 * r) / 7.0;
        assert!(
            plan2.contains(&format!(
                "pigments {pigment}, flat tops × {blended:.2}: the 2 finished result(s) of this \
                 pigment needed {r:.2}× the assumed rates, averaged with 1× counted as 5 \
                 result(s)"
            )),
            "{plan2}"
        );
    }
    // And a variant's estimate takes its pigment's factor, not another's.
    {
        use inksim::study::plan;
        // (The run's output folder is relative to where it ran.)
        let mut done = three.variants.clone();
        for v in &mut done {
            v.scene.output.dir = dir.path().join(&v.scene.output.dir);
        }
        let cal = plan::calibrate(&done, &done);
        let mut doubled = cal.clone();
        doubled
            .pigments
            .get_mut(&("red".to_string(), true))
            .expect("red's own factor")
            .0 *= 2.0;
        let of = |name: &str, cal: &plan::Calibration| {
            let v = done.iter().find(|v| v.name.starts_with(name));
            plan::estimate(&v.unwrap().scene, cal).seconds
        };
        assert!(of("red", &doubled) > 1.5 * of("red", &cal));
        assert_eq!(of("yellow", &doubled), of("yellow", &cal));
    }

    let (ok, out, err) = inksim_in(dir.path(), &["merge", ps, "--profile", "three"]);
    assert!(ok, "{err}");
    let sd = dir.path().join("out/three");
    assert!(out.contains("summary.h5"), "{out}");
    let md = std::fs::read_to_string(sd.join("summary.md")).unwrap();
    for name in planned.keys() {
        assert!(
            md.contains(&format!("[{name}](variants/{name}.png)")),
            "{md}"
        );
    }
    let grid = std::fs::read(sd.join("grids/pigment-by-d.png")).unwrap();
    let c = inksim::output::render::canvas::Canvas::decode_png(&grid).unwrap();
    assert!(c.w > 100 && c.h > 100);
    // The summary file reaches every variant's file through its links.
    let f = inksim::output::h5::open(sd.join("summary.h5")).unwrap();
    let names: Vec<hdf5::types::VarLenUnicode> = f.dataset("name").unwrap().read_raw().unwrap();
    assert_eq!(names.len(), 4);
    let r: Vec<f64> = f.dataset("mean_reflectance").unwrap().read_raw().unwrap();
    for (n, r) in names.iter().zip(&r) {
        let g = f.group(&format!("variants/{}", n.as_str())).unwrap();
        let h: hdf5::types::VarLenUnicode = g.attr("input_hash").unwrap().read_scalar().unwrap();
        let s = &got[n.as_str()];
        assert_eq!(h.as_str(), s.input_hash);
        let above: Vec<_> = s
            .entries
            .iter()
            .filter(|e| e.side == inksim::optics::farfield::Side::Above)
            .collect();
        let mean = above.iter().map(|e| e.total_reflectance).sum::<f64>() / above.len() as f64;
        assert!((mean - r).abs() < 1e-15);
    }
    // Typed axis values: the diameters the axis set, as numbers, in the
    // table's order; the pigment axis sets strings, so only its labels.
    let vg = f.group("values/d").unwrap();
    let keys = vg.member_names().unwrap();
    assert_eq!(keys.len(), 1, "{keys:?}");
    let d: Vec<f64> = vg.dataset(&keys[0]).unwrap().read_raw().unwrap();
    for (n, d) in names.iter().zip(&d) {
        let v = three
            .variants
            .iter()
            .find(|v| v.name == n.as_str())
            .unwrap();
        assert_eq!(*d, v.scene.species[0].diameter_nm, "{}", n.as_str());
    }
    assert!(!f.link_exists("values/pigment"));
    // Every variant's measured colours, as its own file has them.
    let lab: Vec<f64> = f.dataset("colour/45_0/lab").unwrap().read_raw().unwrap();
    let lch: Vec<f64> = f.dataset("colour/45_0/lch").unwrap().read_raw().unwrap();
    for (i, n) in names.iter().enumerate() {
        let path = sd.join(format!("variants/{}.h5", n.as_str()));
        let (records, _, _) = inksim::output::h5::read_measured(&path).unwrap().unwrap();
        let own = records.iter().find(|m| m.geometry == "45/0").unwrap();
        assert_eq!(&lab[3 * i..3 * i + 3], &own.lab[..]);
        let c = own.lab[1].hypot(own.lab[2]);
        assert!((lch[3 * i + 1] - c).abs() < 1e-12);
    }
}

/// A high-contrast pigment (n 2.7 in binder of 1.558) is measured by a
/// pilot solve before the study runs, not assumed from the stand-ins'
/// rate: the pilot is the run's own first solve at the middle wavelength
/// and normal incidence (same seed, grid and solver), so its applications
/// are that solve's exactly; the low-contrast variant has no pilot; and the
/// white variant's estimate carries the pilot's factor.
#[test]
fn a_high_contrast_layer_is_planned_from_a_pilot_solve() {
    let dir = tempfile::tempdir().unwrap();
    let base = SceneToml::grains()
        .thickness_nm(400.0)
        .fragment_nm(400.0)
        .layer_pvc(0.2)
        .pigment(PigmentToml::index("p", 1.4, 0.0).diameter_nm(150.0))
        .cell_nm(25.0)
        .z_cell_nm(25.0)
        .wavelengths_nm(&[450.0, 550.0, 650.0])
        .polar_deg(&[0.0, 30.0])
        .tolerance(1e-5);
    let study =
        StudyToml::new("t", 5, "out", &base).axis("n", "pigment.0.material.index.0", "[1.4, 2.7]");
    let p = write(dir.path(), "sweep.toml", &study.toml());
    let ps = p.to_str().unwrap();
    let (ok, plan, err) = inksim_in(dir.path(), &["plan", ps]);
    assert!(ok, "{err}");
    let pilots: Vec<&str> = plan
        .lines()
        .filter(|l| l.contains("high-contrast grains"))
        .collect();
    assert_eq!(pilots.len(), 1, "{plan}");
    let line = pilots[0];
    let parsed = Study::load(&p).unwrap().expand(None).unwrap();
    let white = parsed
        .variants
        .iter()
        .find(|v| inksim::pipeline::species_eps(&v.scene, 550.0).unwrap()[0].re > 7.0)
        .unwrap();
    assert!(
        line.contains("1 variant(s)")
            && line.contains(&format!("pilot solve of {} at 550 nm", white.name)),
        "{line}"
    );
    let applications: f64 = line
        .split(" applications per solve")
        .next()
        .and_then(|s| s.split_whitespace().last())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));

    let (ok, out, err) = inksim_in(dir.path(), &["run", ps]);
    assert!(ok, "{out}{err}");
    let got = results(&dir.path().join("out/variants"));
    let solve = got[&white.name]
        .entries
        .iter()
        .find(|e| {
            e.wavelength_nm == 550.0
                && e.polar_deg == 0.0
                && e.realisation == 0
                && e.side == inksim::optics::farfield::Side::Above
        })
        .unwrap();
    let run = (solve.iterations as f64 + 1.0) * solve.method.solver().applications_per_iteration();
    assert_eq!(applications, run, "{line}");
    let assumed = inksim::study::plan::default_applications(&white.scene);
    assert!(
        line.contains(&format!("{:.1}× the assumed {assumed:.0}", run / assumed)),
        "{line}"
    );
}

#[test]
fn truncated_and_mismatched_results_are_redone() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &sweep().toml());
    let ps = p.to_str().unwrap();
    let (ok, _, err) = inksim_in(dir.path(), &["run", ps]);
    assert!(ok, "{err}");
    let vd = dir.path().join("out/quick/variants");
    let before = results(&vd);
    // Truncate one result, overwrite another with a different variant's file.
    let a = vd.join("red_d100.h5");
    let bytes = std::fs::read(&a).unwrap();
    std::fs::write(&a, &bytes[..bytes.len() / 2]).unwrap();
    std::fs::copy(vd.join("yellow_d100.h5"), vd.join("red_d150.h5")).unwrap();
    let (ok, out, err) = inksim_in(dir.path(), &["run", ps]);
    assert!(ok, "{err}");
    assert!(out.contains("2 ran, 2 skipped"), "{out}");
    assert!(
        err.contains("start red_d100")
            && err.contains("result file unreadable (truncated or corrupt)"),
        "{err}"
    );
    assert!(
        err.contains("start red_d150") && err.contains("computed from a different configuration"),
        "{err}"
    );
    assert_eq!(results(&vd), before);
}

#[test]
fn shards_together_give_the_unsharded_run() {
    let whole = tempfile::tempdir().unwrap();
    let parts = tempfile::tempdir().unwrap();
    let text = sweep().raw("axis.1.values", "[100.0, 120.0, 150.0]").toml();
    let pw = write(whole.path(), "sweep.toml", &text);
    let pp = write(parts.path(), "sweep.toml", &text);
    let (ok, _, err) = inksim_in(
        whole.path(),
        &["--threads", "2", "run", pw.to_str().unwrap()],
    );
    assert!(ok, "{err}");
    let mut ran = 0;
    for i in 0..3 {
        let shard = format!("{i}/3");
        let (ok, out, err) = if i < 2 {
            inksim_in(
                parts.path(),
                &[
                    "--threads",
                    "1",
                    "run",
                    pp.to_str().unwrap(),
                    "--shard",
                    &shard,
                ],
            )
        } else {
            // The last shard as a Slurm array task would see it.
            let o = Command::new(env!("CARGO_BIN_EXE_inksim"))
                .args(["run", pp.to_str().unwrap()])
                .current_dir(parts.path())
                .env("SLURM_ARRAY_TASK_ID", "2")
                .env("SLURM_ARRAY_TASK_COUNT", "3")
                .output()
                .unwrap();
            (
                o.status.success(),
                String::from_utf8_lossy(&o.stdout).into_owned(),
                String::from_utf8_lossy(&o.stderr).into_owned(),
            )
        };
        assert!(ok, "{err}");
        assert!(out.contains("2 variants in this shard: 2 ran"), "{out}");
        assert!(err.contains(&format!("shard {i}/3")), "{err}");
        ran += 2;
    }
    assert_eq!(ran, 6);
    let a = results(&whole.path().join("out/quick/variants"));
    let b = results(&parts.path().join("out/quick/variants"));
    assert_eq!(a.len(), 6);
    assert_eq!(a, b);
}

/// Slow enough variants (32 × 32 × 8, four wavelengths) that a kill lands
/// mid-way.
fn slow_sweep() -> String {
    let base = base()
        .cell_nm(12.5)
        .z_cell_nm(50.0)
        .wavelengths_nm(&[450.0, 500.0, 550.0, 600.0]);
    sweep_of(&base)
        .raw("axis.1.values", "[100.0, 120.0, 150.0]")
        .toml()
}

#[test]
fn killed_run_resumes_to_the_uninterrupted_result() {
    let text = slow_sweep();
    let whole = tempfile::tempdir().unwrap();
    let pw = write(whole.path(), "sweep.toml", &text);
    let (ok, _, err) = inksim_in(
        whole.path(),
        &["--threads", "1", "run", pw.to_str().unwrap()],
    );
    assert!(ok, "{err}");
    let reference = results(&whole.path().join("out/quick/variants"));
    assert_eq!(reference.len(), 6);

    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &text);
    let vd = dir.path().join("out/quick/variants");
    let mut child = Command::new(env!("CARGO_BIN_EXE_inksim"))
        .args(["--threads", "1", "run", p.to_str().unwrap(), "--jobs", "1"])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let first = vd.join("red_d100.h5");
    let t = Instant::now();
    while !first.exists() {
        assert!(t.elapsed() < Duration::from_secs(120), "no result appeared");
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    let _ = child.wait();
    let partial = results(&vd);
    assert!(
        !partial.is_empty() && partial.len() < 6,
        "kill should land mid-way: {} results",
        partial.len()
    );
    // Whatever was left under a final name is complete (atomic writes).
    for (n, s) in &partial {
        assert_eq!(s, &reference[n]);
    }
    let (ok, out, err) = inksim_in(dir.path(), &["run", p.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        out.contains(&format!(
            "{} ran, {} skipped",
            6 - partial.len(),
            partial.len()
        )),
        "{out}"
    );
    assert_eq!(results(&vd), reference);
    let leftovers: Vec<_> = std::fs::read_dir(&vd)
        .unwrap()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn interrupted_run_says_what_is_done_and_resumes_to_the_same_result() {
    let text = slow_sweep();
    let whole = tempfile::tempdir().unwrap();
    let pw = write(whole.path(), "sweep.toml", &text);
    let (ok, _, err) = inksim_in(
        whole.path(),
        &["--threads", "1", "run", pw.to_str().unwrap()],
    );
    assert!(ok, "{err}");
    let reference = results(&whole.path().join("out/quick/variants"));

    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &text);
    let vd = dir.path().join("out/quick/variants");
    let child = Command::new(env!("CARGO_BIN_EXE_inksim"))
        .args(["--threads", "1", "run", p.to_str().unwrap(), "--jobs", "1"])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let first = vd.join("red_d100.h5");
    let t = Instant::now();
    while !first.exists() {
        assert!(t.elapsed() < Duration::from_secs(120), "no result appeared");
        std::thread::sleep(Duration::from_millis(2));
    }
    // Ctrl-C, as a terminal sends it.
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    let partial = results(&vd);
    assert!(
        !partial.is_empty() && partial.len() < 6,
        "{}",
        partial.len()
    );
    // The count said is the finished results' (one fewer when the signal
    // lands between a rename and the count's update).
    let last = err.lines().last().unwrap_or("");
    let said = |n: usize| last.contains(&format!("{n} of 6 variants of this shard finished"));
    assert!(
        last.contains("[inksim] interrupted: ")
            && (said(partial.len()) || said(partial.len() - 1))
            && last.contains("run the same command again to resume"),
        "{err}"
    );
    let tmp = |d: &Path| {
        std::fs::read_dir(d)
            .unwrap()
            .flatten()
            .filter(|e| e.path().extension().is_some_and(|x| x == "tmp"))
            .count()
    };
    assert_eq!(tmp(&vd), 0, "the handler removes its temporary files");
    let (ok, out, err) = inksim_in(dir.path(), &["run", p.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert_eq!(reported(&out, "ran"), 6 - partial.len(), "{out}");
    assert_eq!(results(&vd), reference);
}

#[test]
fn a_moved_study_resumes_instead_of_starting_over() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &sweep().toml());
    let (ok, out, err) = inksim_in(dir.path(), &["run", p.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert_eq!(reported(&out, "ran"), 4, "{out}");
    let before = results(&dir.path().join("out/quick/variants"));
    std::fs::rename(dir.path().join("out"), dir.path().join("moved")).unwrap();
    let (ok, out, err) = inksim_in(
        dir.path(),
        &["run", p.to_str().unwrap(), "--output-dir", "moved"],
    );
    assert!(ok, "{err}");
    assert_eq!(reported(&out, "ran"), 0, "{out}");
    assert_eq!(reported(&out, "skipped"), 4, "{out}");
    assert_eq!(results(&dir.path().join("moved/quick/variants")), before);
    // A change that decides results is still noticed.
    let changed = sweep_of(&base().thickness_nm(410.0)).toml();
    let p = write(dir.path(), "sweep.toml", &changed);
    let (ok, out, err) = inksim_in(
        dir.path(),
        &["run", p.to_str().unwrap(), "--output-dir", "moved"],
    );
    assert!(ok, "{err}");
    assert_eq!(reported(&out, "ran"), 4, "{out}");
}

/// The count before `word` in the report line `… N ran, M skipped …`.
fn reported(out: &str, word: &str) -> usize {
    let line = out.lines().find(|l| l.starts_with("study run:")).unwrap();
    let before = &line[..line.find(word).unwrap()];
    before.split_whitespace().last().unwrap().parse().unwrap()
}

#[test]
fn concurrent_runs_of_one_study_compute_each_variant_once() {
    let text = slow_sweep();
    let whole = tempfile::tempdir().unwrap();
    let pw = write(whole.path(), "sweep.toml", &text);
    let (ok, _, err) = inksim_in(
        whole.path(),
        &["--threads", "1", "run", pw.to_str().unwrap()],
    );
    assert!(ok, "{err}");
    let reference = results(&whole.path().join("out/quick/variants"));
    assert_eq!(reference.len(), 6);

    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &text);
    let children: Vec<_> = (0..4)
        .map(|_| {
            Command::new(env!("CARGO_BIN_EXE_inksim"))
                .args(["--threads", "1", "run", p.to_str().unwrap(), "--jobs", "1"])
                .current_dir(dir.path())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut ran = 0;
    for c in children {
        let o = c.wait_with_output().unwrap();
        let out = String::from_utf8_lossy(&o.stdout);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{out}\n{err}");
        assert_eq!(reported(&out, "failed"), 0, "{out}");
        ran += reported(&out, "ran");
    }
    // Each variant computed once, by one of the four, and bit-identical to
    // the single run's.
    assert_eq!(ran, 6);
    let vd = dir.path().join("out/quick/variants");
    assert_eq!(results(&vd), reference);
    let leftovers: Vec<_> = std::fs::read_dir(&vd)
        .unwrap()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn slurm_script_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &sweep().toml());
    let (ok, out, err) = inksim_in(
        dir.path(),
        &["slurm", p.to_str().unwrap(), "--shards", "3", "--cpus", "1"],
    );
    assert!(ok, "{err}");
    let script = dir.path().join("out/quick/t-quick.sbatch");
    assert!(out.contains("t-quick.sbatch"), "{out}");
    let s = std::fs::read_to_string(script).unwrap();
    assert!(s.contains("#SBATCH --array=0-2\n"), "{s}");
    assert!(s.contains("--profile 'quick' --jobs 1"), "{s}");
    assert!(dir.path().join("out/quick/slurm").is_dir());
}

#[test]
fn a_variant_beyond_the_memory_limit_fails_alone_and_the_others_finish() {
    // The sweep × a cell axis: the four 1 nm variants (400 × 400 × 4 cells,
    // ≈ 156 MB) exceed 100 MB, the four 50 nm ones fit.
    let text = sweep().axis("cell", "grid.cell_nm", "[50.0, 1.0]").toml();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "s.toml", &text);
    let (ok, _, err) = inksim_in(d, &["check", "s.toml", "--max-memory", "100M"]);
    assert!(
        !ok && err.contains("s.toml: profile quick, variant "),
        "{err}"
    );
    assert!(err.contains(": grid 400 × 400 × 4, "), "{err}");
    let (_, out, _) = inksim_in(d, &["plan", "s.toml", "--max-memory", "100M"]);
    let over: Vec<&str> = out.lines().filter(|l| l.contains("OVER MEMORY")).collect();
    assert!(
        over.len() == 4 && over.iter().all(|l| l.contains("cell1")),
        "{out}"
    );
    assert!(out.contains("WARNING: 4 variant(s) exceed the memory limit 100 MB"));
    let (ok, out, _) = inksim_in(d, &["run", "s.toml", "--max-memory", "100M"]);
    assert!(!ok, "a failed variant makes the exit non-zero");
    assert!(
        out.contains("4 ran, 0 skipped (already finished), 4 failed"),
        "{out}"
    );
    let results = results(&d.join("out/quick/variants"));
    assert_eq!(results.len(), 4);
    assert!(results.keys().all(|k| k.ends_with("cell50")), "{results:?}");
}

#[test]
fn only_runs_plans_and_merges_a_subset_with_the_full_studys_files() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "sweep.toml", &sweep().toml());
    let p = p.to_str().unwrap();
    let (ok, out, err) = inksim_in(dir.path(), &["plan", p, "--only", "pigment=red"]);
    assert!(ok, "{err}");
    assert!(out.contains("2 variants (only pigment=red)"), "{out}");
    assert!(
        out.contains("red_d150") && !out.contains("yellow_d100"),
        "{out}"
    );

    let (ok, _, err) = inksim_in(
        dir.path(),
        &[
            "--threads",
            "1",
            "run",
            p,
            "--only",
            "pigment=red",
            "--only",
            "d=d100,d150",
        ],
    );
    assert!(ok, "{err}");
    let done: Vec<String> = results(&dir.path().join("out/quick/variants"))
        .into_keys()
        .collect();
    assert_eq!(done, ["red_d100", "red_d150"]);
    // The subset merged alone says it is one, in the page and the file.
    let (ok, _, err) = inksim_in(dir.path(), &["merge", p, "--only", "pigment=red"]);
    assert!(ok, "{err}");
    let page = std::fs::read_to_string(dir.path().join("out/quick/summary.md")).unwrap();
    assert!(
        page.contains("only pigment=red (a subset of the study)"),
        "{page}"
    );
    let f = inksim::output::h5::open(dir.path().join("out/quick/summary.h5")).unwrap();
    let sel: hdf5::types::VarLenUnicode = f.attr("selection").unwrap().read_scalar().unwrap();
    assert_eq!(sel.as_str(), "pigment=red");
    assert_eq!(f.dataset("name").unwrap().shape(), [2]);
    let grid_height = |dir: &Path| {
        let png = std::fs::read(dir.join("out/quick/grids/pigment-by-d.png")).unwrap();
        inksim::output::render::canvas::Canvas::decode_png(&png)
            .unwrap()
            .h
    };
    let subset_height = grid_height(dir.path());
    // One label on every axis: nothing to plot against.
    let (ok, out, err) = inksim_in(
        dir.path(),
        &["merge", p, "--only", "pigment=red", "--only", "d=d100"],
    );
    assert!(ok && !out.contains("plot:"), "{out}\n{err}");
    // The whole study merged now lists what the subset left to do.
    let (ok, _, err) = inksim_in(dir.path(), &["merge", p]);
    assert!(
        !ok && err.contains("2 of 4 variants are not finished"),
        "{err}"
    );
    // A full run resumes from the subset: only the other two run.
    let (ok, out, err) = inksim_in(dir.path(), &["--threads", "1", "run", p]);
    assert!(ok, "{err}");
    assert!(out.contains("2 ran") && out.contains("2 skipped"), "{out}");
    // The subset's grid drew only its own row (pigment red), the whole
    // study's both.
    assert!(subset_height < grid_height(dir.path()), "{subset_height}");

    for (args, needle) in [
        ("colour=red", "no axis `colour`; its axes are pigment, d"),
        (
            "pigment=green",
            "axis `pigment` has no label `green`; its labels are red, yellow",
        ),
        ("pigment", "expected AXIS=LABEL"),
    ] {
        let (ok, _, err) = inksim_in(dir.path(), &["plan", p, "--only", args]);
        assert!(!ok && err.contains(needle), "{args}: {err}");
    }
    let scene = write(dir.path(), "scene.toml", &base().toml());
    let (ok, _, err) = inksim_in(
        dir.path(),
        &["run", scene.to_str().unwrap(), "--only", "pigment=red"],
    );
    assert!(!ok && err.contains("--only apply to studies"), "{err}");
}

#[test]
fn a_study_with_a_realisation_target_resumes_with_nothing_to_do() {
    // A loose target stops every variant at its minimum of 2 of at most 3
    // realisations: fewer solves than the most allowed, and still finished.
    let dir = tempfile::tempdir().unwrap();
    let study = sweep().profile_key(
        "quick",
        "realisations",
        common::keys::value("{ target_de00 = 1000.0, min = 2, max = 3 }"),
    );
    let p = write(dir.path(), "sweep.toml", &study.toml());
    let p = p.to_str().unwrap();
    let per = |v: &inksim::study::sweep::Variant| {
        inksim::pipeline::planned_solves(&v.scene) / v.scene.realisations
    };
    let expanded = Study::load(Path::new(p)).unwrap().expand(None).unwrap();
    // The plan counts the realisations the target is expected to stop at.
    let (ok, plan, err) = inksim_in(dir.path(), &["plan", p]);
    assert!(ok, "{err}");
    for v in &expanded.variants {
        assert_eq!(v.scene.realisations, 3);
        let row = plan
            .lines()
            .find(|l| l.split_whitespace().nth(1) == Some(v.name.as_str()))
            .unwrap_or_else(|| panic!("{plan}"));
        let solves: usize = row.split_whitespace().nth(2).unwrap().parse().unwrap();
        assert_eq!(solves, 2 * per(v), "{row}");
    }
    let (ok, out, err) = inksim_in(dir.path(), &["--threads", "1", "run", p]);
    assert!(ok, "{err}");
    assert!(out.contains("4 ran, 0 skipped"), "{out}");
    let got = results(&dir.path().join("out/quick/variants"));
    for v in &expanded.variants {
        assert_eq!(got[&v.name].entries.len(), 2 * per(v), "{}", v.name);
    }
    let (ok, out, err) = inksim_in(dir.path(), &["--threads", "1", "run", p]);
    assert!(ok, "{err}");
    assert!(out.contains("0 ran, 4 skipped"), "{out}\n{err}");
    let (ok, _, err) = inksim_in(dir.path(), &["merge", p]);
    assert!(ok, "{err}");
}

#[test]
fn a_study_whose_variants_ask_for_no_tile_is_refused_before_any_work() {
    // The merge compares the variants' colours and tiles.
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "sweep.toml",
        &sweep_of(&base().outputs(&["brdf"])).toml(),
    );
    let (ok, _, err) = inksim_in(dir.path(), &["run", p.to_str().unwrap()]);
    assert!(
        !ok && err.contains("appearance.outputs must include \"tile\" in a study"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn the_effects_table_takes_the_declared_steps_and_unknown_labels_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    // Declared: d150 → d100 only (against the default d100 → d150); the
    // pigment axis keeps its default step red → yellow.
    let study = sweep().raw("axis.1.compare", r#"[["d150", "d100"]]"#);
    let p = write(dir.path(), "sweep.toml", &study.toml());
    let p = p.to_str().unwrap();
    let (ok, out, err) = inksim_in(dir.path(), &["--threads", "1", "run", p]);
    assert!(ok, "{out}\n{err}");
    let md = std::fs::read_to_string(dir.path().join("out/quick/summary.md")).unwrap();
    let steps: Vec<&str> = md
        .lines()
        .filter(|l| l.starts_with("| d |") || l.starts_with("| pigment |"))
        .map(|l| l.split('|').nth(2).unwrap().trim())
        .collect();
    assert_eq!(steps, ["red → yellow", "d150 → d100"], "{md}");

    for (compare, needle) in [
        (
            r#"[["d100", "d999"]]"#,
            "axis `d` ([[axis]] 2): compare entry 1 names label `d999`, which the axis does not \
             have; its labels are d100, d150",
        ),
        (
            r#"[["d100"]]"#,
            "compare entry 1 must be two labels [\"from\", \"to\"], got 1 item(s)",
        ),
    ] {
        let bad = sweep().raw("axis.1.compare", compare);
        let p = write(dir.path(), "bad.toml", &bad.toml());
        let (ok, _, err) = inksim_in(dir.path(), &["plan", p.to_str().unwrap()]);
        assert!(!ok && err.contains(needle), "{err}");
    }
}

#[test]
fn each_grid_picture_has_a_de00_heat_map_to_its_reference_cell() {
    use inksim::optics::colour::{delta_e2000, delta_e2000_se};
    use inksim::study::merge::de00_maps;
    let dir = tempfile::tempdir().unwrap();
    // Two realisations, so the colours carry standard errors; an absolute
    // output folder, so this process finds what the run wrote.
    let out = dir.path().join("out");
    let study = sweep()
        .profile_key("quick", "realisations", 2)
        .set("study.output_dir", out.to_str().unwrap());
    let p = write(dir.path(), "sweep.toml", &study.toml());
    let (ok, _, err) = inksim_in(dir.path(), &["run", p.to_str().unwrap()]);
    assert!(ok, "{err}");
    let study = Study::load(&p).unwrap();
    let exp = study.expand(None).unwrap();
    let maps = de00_maps(&study, &exp).unwrap();
    let grids = out.join("quick/grids");
    assert_eq!(maps.len(), study.grids.len());
    let colour = |name: &str| {
        let path = out.join(format!("quick/variants/{name}.h5"));
        let (records, _, _) = inksim::output::h5::read_measured(&path).unwrap().unwrap();
        records.into_iter().find(|m| m.geometry == "45/0").unwrap()
    };
    for m in &maps {
        // The merge wrote the heat map beside its grid.
        assert_eq!(m.file, m.grid_file.replace(".png", "-de00.png"));
        assert!(grids.join(&m.grid_file).is_file(), "{}", m.grid_file);
        let png = std::fs::read(grids.join(&m.file)).unwrap();
        let c = inksim::output::render::canvas::Canvas::decode_png(&png).unwrap();
        assert!(c.w > 300 && c.h > 150, "{} × {}", c.w, c.h);
        // The reference is the first row and column, at 0.
        assert_eq!(m.reference, (0, 0));
        assert_eq!((m.rows.len(), m.cols.len()), (2, 2));
        let r = m.cells[0][0].as_ref().unwrap();
        assert_eq!((r.de00, r.se), (0.0, None));
        let rc = colour(&r.variant);
        for (i, line) in m.cells.iter().enumerate() {
            for (j, cell) in line.iter().enumerate() {
                let cell = cell.as_ref().unwrap();
                let own = colour(&cell.variant);
                assert_eq!(cell.lab, own.lab);
                // The picture's ΔE00 is the colour module's, of the two
                // colours read independently from the result files.
                assert_eq!(cell.de00, delta_e2000(rc.lab, own.lab), "{i} {j}");
                if (i, j) != (0, 0) {
                    assert!(cell.de00 > 0.0);
                    let se =
                        delta_e2000_se(rc.lab, rc.lab_se.unwrap(), own.lab, own.lab_se.unwrap());
                    assert_eq!(cell.se, Some(se));
                    assert!(se > 0.0);
                    assert_eq!(cell.near_zero(), cell.de00 <= 2.0 * se);
                }
                // The colour bar covers every value.
                assert!(m.scale.lo <= cell.de00 && cell.de00 <= m.scale.hi);
            }
        }
        assert_eq!(m.scale.lo, 0.0);
        // summary.html shows the heat map right after its grid.
        let html = std::fs::read_to_string(out.join("quick/summary.html")).unwrap();
        let g = html
            .find(&format!("src=\"grids/{}\"", m.grid_file))
            .unwrap();
        let h = html.find(&format!("src=\"grids/{}\"", m.file)).unwrap();
        // No other picture between them (only the heat map's own <img).
        assert!(g < h && html[g..h].matches("<img").count() == 1, "{html}");
        let md = std::fs::read_to_string(out.join("quick/summary.md")).unwrap();
        assert!(md.contains(&format!("(grids/{})", m.file)), "{md}");
    }
}

#[test]
fn a_dissolved_variant_under_a_realisation_target_is_finished() {
    // A homogeneous layer runs one realisation whatever the target asks;
    // with a target of up to 64, its result is still whole, and the merge
    // takes it (it used to be counted as unfinished, its solves read as a
    // fraction of 64 realisations).
    let dir = tempfile::tempdir().unwrap();
    let study = sweep()
        .profile_key(
            "quick",
            "realisations",
            common::keys::value("{ target_de00 = 1000.0, min = 2, max = 64 }"),
        )
        .compound_axis(
            "grain",
            &[
                ("spheres", r#"{ "pigment.*.shape" = { kind = "sphere" } }"#),
                ("dye", r#"{ "pigment.*.shape" = { kind = "molecular" } }"#),
            ],
        );
    let p = write(dir.path(), "sweep.toml", &study.toml());
    let p = p.to_str().unwrap();
    let (ok, out, err) = inksim_in(dir.path(), &["--threads", "1", "run", p]);
    assert!(ok, "{err}");
    assert!(out.contains("8 ran, 0 skipped"), "{out}");
    let (ok, out, err) = inksim_in(dir.path(), &["--threads", "1", "run", p]);
    assert!(ok && out.contains("0 ran, 8 skipped"), "{out}\n{err}");
    let (ok, _, err) = inksim_in(dir.path(), &["merge", p]);
    assert!(ok, "{err}");
}

/// `plan`'s time model scales its assumed applications per solve by the
/// decades of tolerance asked (`study::plan::tolerance_factor`); a real
/// granular layer, solved at 1e-3 and at 1e-6, needs what it says within 25 %.
#[test]
fn the_time_models_tolerance_factor_matches_the_solver() {
    use inksim::output::progress::Progress;
    use inksim::pipeline::{self, RunPlan};
    use inksim::study::plan::tolerance_factor;
    let applications = |tol: f64| {
        let text = format!(
            "seed = 3\n[layer]\nthickness_nm = 1000.0\nfragment_nm = [600.0, 600.0]\npvc = 0.3\n\
             [[pigment]]\nname = \"red\"\nmaterial = {{ builtin = \"red\" }}\ndiameter_nm = 200.0\n\
             [illumination]\nwavelengths_nm = [450.0, 550.0, 650.0]\npolar_deg = [0.0, 40.0]\n\
             [grid]\ncell_nm = 25.0\n[solver]\ntolerance = {tol:e}\n[appearance]\noutputs = []\n"
        );
        let scene = inksim::config::parse_scene(Path::new("t.toml"), &text).unwrap();
        let layer = pipeline::layer::solve(&scene, &RunPlan::of(&scene), &Progress::hidden(1, "t"))
            .unwrap();
        let total: f64 = layer
            .entries
            .iter()
            .map(|e| {
                (e.record.iterations as f64 + 1.0)
                    * e.record.method.solver().applications_per_iteration()
            })
            .sum();
        total / layer.entries.len() as f64
    };
    let (tight, loose) = (applications(1e-6), applications(1e-3));
    eprintln!("applications per solve: {tight:.1} at 1e-6, {loose:.1} at 1e-3");
    let measured = tight / loose;
    let model = tolerance_factor(1e-6, 1e-3);
    assert!(
        (measured / model - 1.0).abs() < 0.25,
        "1e-6 against 1e-3: measured {measured:.2}×, the model {model:.2}×"
    );
}
