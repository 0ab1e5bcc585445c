//! The command line as a user meets it: bad input gives one clear line and a
//! non-zero exit, never a panic or a half-written result; a good run writes
//! its files and the same seed gives the same numbers for 1 and 2 threads.
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::scene::{PigmentToml, SceneToml};

fn inksim(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_inksim"))
        .args(args)
        .output()
        .expect("run inksim");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// `inksim run` on `text` written into `dir`, results in `dir/out`:
/// (success, stderr, config path, output folder).
fn run_scene(dir: &Path, scene: &SceneToml) -> (bool, String, PathBuf, PathBuf) {
    let cfg = scene.write(dir);
    let out = dir.join("out");
    let (ok, _, err) = inksim(&[
        "run",
        cfg.to_str().unwrap(),
        "--output-dir",
        out.to_str().unwrap(),
    ]);
    (ok, err, cfg, out)
}

/// Run a broken config; expect failure with one error line mentioning `needle`
/// and nothing written to the output folder.
fn expect_error(scene: SceneToml, needle: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (ok, err, _, out) = run_scene(dir.path(), &scene);
    assert!(!ok, "should fail: {needle}");
    assert!(!err.contains("panicked"), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line expected: {err}");
    assert!(lines[0].starts_with("error: "), "{err}");
    assert!(err.contains(needle), "`{needle}` not in: {err}");
    let written: Vec<_> = std::fs::read_dir(&out)
        .map(|d| d.flatten().collect())
        .unwrap_or_default();
    assert!(written.is_empty(), "files written: {written:?}");
}

#[test]
fn unknown_key_is_named() {
    expect_error(SceneToml::tiny().set("colour", 1), "colour");
}

#[test]
fn negative_thickness_is_named() {
    expect_error(SceneToml::tiny().thickness_nm(-5.0), "layer.thickness_nm");
}

#[test]
fn pvc_beyond_packer_is_named() {
    expect_error(SceneToml::tiny().pvc(0.6), "0.55");
}

#[test]
fn wavelength_outside_pigment_data_is_named() {
    expect_error(SceneToml::tiny().wavelengths_nm(&[500.0, 900.0]), "900");
}

#[test]
fn a_key_of_the_wrong_form_is_told_the_forms_it_takes() {
    expect_error(
        SceneToml::tiny().raw(
            "pigment.0.material",
            r#"{ builtin = "red", index = [1.5, 0.0] }"#,
        ),
        "a material is a table with exactly one of `builtin`, `library`, `csv`, `index`, \
         `epsilon` (e.g. material = { library = \"rutile\" }); this one gives more than one",
    );
    expect_error(
        SceneToml::tiny().raw("pigment.0.material", "{}"),
        "this one gives none",
    );
    expect_error(
        SceneToml::tiny().raw("pigment.0.shape", r#""rice""#),
        "expected a grain shape: { kind = \"sphere\" }",
    );
    expect_error(
        SceneToml::tiny().raw("pigment.0.shape", r#""rice""#),
        r#"got string "rice""#,
    );
    expect_error(
        SceneToml::tiny().raw("pigment.0.shape", "{ aspect = 3.0 }"),
        "`shape` is missing `kind`: expected a grain shape",
    );
    expect_error(
        SceneToml::tiny().raw("layer.surface", r#""rough""#),
        "expected a surface: { kind = \"flat\" }",
    );
}

#[test]
fn limits_and_numbers_read_as_written() {
    // The grain limit is the packer's, not (0, 1).
    expect_error(
        SceneToml::tiny().pvc(1.0),
        "key `pigment[0].pvc`: must be in [0, 0.55] (the most the packer reaches; 0: absent, as the \
         first step of a let-down series), got 1",
    );
    // Huge and tiny numbers in exponent form, not 301 digits.
    expect_error(SceneToml::tiny().diameter_nm(1e300), "got 1e300");
    expect_error(SceneToml::tiny().tolerance(1e-300), "1e-300");
    // Grains so small the layer would hold more than a packer can place.
    expect_error(
        SceneToml::tiny().diameter_nm(1e-9),
        "1e-9 nm grains at PVC 0.15 make about 2.9e34 grains in this layer, more than the \
         2000000 a layer may hold",
    );
    expect_error(
        SceneToml::tiny().diameter_nm(2.0),
        "make about 3580986 grains",
    );
}

#[test]
fn unwritable_output_folder_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = SceneToml::tiny().write(dir.path());
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, b"x").unwrap();
    let out = blocker.join("sub");
    let (ok, _, err) = inksim(&[
        "run",
        cfg.to_str().unwrap(),
        "--output-dir",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && !err.contains("panicked"));
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains(out.to_str().unwrap()), "{err}");
}

#[test]
fn missing_config_file_is_named() {
    let (ok, _, err) = inksim(&["run", "/nonexistent/scene.toml"]);
    assert!(
        !ok && err.contains("/nonexistent/scene.toml") && !err.contains("panicked"),
        "{err}"
    );
}

#[test]
fn run_writes_results_identical_for_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = SceneToml::tiny().write(dir.path());
    let mut summaries = vec![];
    for threads in ["1", "2"] {
        let out = dir.path().join(format!("t{threads}"));
        let (ok, stdout, err) = inksim(&[
            "--threads",
            threads,
            "run",
            cfg.to_str().unwrap(),
            "--output-dir",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        assert!(stdout.contains("tiny.h5"), "{stdout}");
        assert!(out.join("tiny.png").is_file());
        let s = inksim::output::h5::read_summary(&out.join("tiny.h5")).unwrap();
        let scene = inksim::config::load_scene(&cfg).unwrap();
        assert_eq!(s.entries.len(), inksim::pipeline::planned_solves(&scene));
        for e in &s.entries {
            assert!(e.energy_balance.abs() < 1e-4, "{}", e.energy_balance);
        }
        summaries.push(s);
    }
    let key = |s: &inksim::output::h5::ResultSummary| {
        s.entries
            .iter()
            .map(|e| {
                (
                    e.total_reflectance.to_bits(),
                    e.total_transmittance.to_bits(),
                    e.absorption.to_bits(),
                    e.iterations,
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(key(&summaries[0]), key(&summaries[1]));
    assert_eq!(summaries[0].input_hash, summaries[1].input_hash);
    let plan = &summaries[0].plan;
    assert!(
        plan.starts_with("geometry: rsa (spheres at PVC 0.150"),
        "{plan}"
    );
    assert_eq!(
        plan.lines().filter(|l| l.starts_with("solve ")).count(),
        summaries[0].entries.len(),
        "{plan}"
    );
}

/// A grain longer than half the fragment fails at the geometry stage (the
/// config alone cannot know the grain's length): one error line, its cause
/// said once, no result written.
#[test]
fn grain_longer_than_half_the_fragment_is_named_once() {
    let dir = tempfile::tempdir().unwrap();
    let scene = SceneToml::tiny().diameter_nm(200.0).raw(
        "pigment.0.shape",
        "{ kind = \"rice\", aspect = 3.0, spheres = 3 }",
    );
    let (ok, err, _, out) = run_scene(dir.path(), &scene);
    assert!(!ok, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(errors.len(), 1, "{err}");
    assert!(errors[0].contains("half the lateral period"), "{err}");
    assert_eq!(
        errors[0].matches("exceeds").count(),
        1,
        "repeated: {}",
        errors[0]
    );
    assert!(!out.join("tiny.h5").exists());
}

#[test]
fn dense_rice_layer_uses_dynamics_and_runs() {
    let dir = tempfile::tempdir().unwrap();
    let scene = SceneToml::tiny()
        .pvc(0.45)
        .diameter_nm(80.0)
        .raw("pigment.0.shape", "{ kind = \"rice\" }")
        .set("pigment.0.orientation", "in-plane")
        .set("pigment.0.alignment_field", 1.0)
        .wavelengths_nm(&[550.0])
        .polar_deg(&[20.0]);
    let (ok, err, cfg, out) = run_scene(dir.path(), &scene);
    assert!(ok, "{err}");
    assert!(err.contains("geometry: dynamics"), "{err}");
    let s_value: f64 = err
        .split("order parameter S = ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .and_then(|t| t.parse().ok())
        .expect("order parameter logged");
    assert!(s_value < -0.45, "in-plane grains: S = {s_value}");
    let s = inksim::output::h5::read_summary(&out.join("tiny.h5")).unwrap();
    let scene = inksim::config::load_scene(&cfg).unwrap();
    assert_eq!(s.entries.len(), inksim::pipeline::planned_solves(&scene));
    assert!(s.entries.iter().all(|e| e.energy_balance.abs() < 1e-4));
}

#[test]
fn sparse_spheres_use_random_addition() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = SceneToml::tiny().write(dir.path());
    let (ok, out, err) = inksim(&["check", cfg.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.contains("geometry: rsa"), "{out}");
}

#[test]
fn geometry_command_writes_particles_and_picture() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = SceneToml::tiny().write(dir.path());
    let out = dir.path().join("geo");
    let (ok, stdout, err) = inksim(&[
        "geometry",
        cfg.to_str().unwrap(),
        "--output-dir",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        stdout.contains("8 particles by rsa; PVC 0.1414"),
        "{stdout}"
    );
    let png = std::fs::read(out.join("tiny-geometry.png")).unwrap();
    let decoder = png::Decoder::new(std::io::Cursor::new(png));
    let reader = decoder.read_info().unwrap();
    assert!(reader.info().width > 100 && reader.info().height > 100);
    let s = inksim::output::h5::read_summary(&out.join("tiny-geometry.h5")).unwrap();
    assert!(s.entries.is_empty());
    assert!(
        s.plan.contains("solves: none (geometry only)"),
        "{}",
        s.plan
    );
    assert!(!out.join("tiny.h5").exists(), "no solves were run");
}

/// The tiny scene on a 4096 × 4096 × 20 grid: 335.5 M voxels × (213 + 8) B
/// + 25 MB = 74.2 GB by the memory model.
fn huge_scene() -> SceneToml {
    SceneToml::tiny()
        .fragment_nm(4096.0)
        .cell_nm(1.0)
        .z_cell_nm(20.0)
}

/// One line, no panic, naming the grid, the estimate, the limit and what
/// to change.
fn assert_memory_line(err: &str) {
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    for needle in [
        "scene.toml: grid 4096 × 4096 × 20",
        "estimated peak memory 74.2 GB",
        "exceeds 1.0 GB (--max-memory)",
        "cell_nm",
        "raise --max-memory",
    ] {
        assert!(err.contains(needle), "`{needle}` missing: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_scene_beyond_the_memory_limit_fails_check_and_run_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = huge_scene().write(dir.path());
    let cfg = cfg.to_str().unwrap();
    let (ok, _, err) = inksim(&["check", cfg, "--max-memory", "1G"]);
    assert!(!ok);
    assert_memory_line(&err);
    let out = dir.path().join("out");
    let t = std::time::Instant::now();
    let (ok, _, err) = inksim(&[
        "run",
        cfg,
        "--max-memory",
        "1G",
        "--output-dir",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert_memory_line(&err);
    assert!(t.elapsed().as_secs_f64() < 10.0, "no work before the check");
    assert!(!out.exists(), "a refused run leaves nothing behind");
    // Maxwell: 3.2× the method's own 165 B per voxel (f64 BiCGStab) and the
    // 16 B of the warm start, plus the anisotropic cut voxels' 128 B times
    // their estimated share 9 · 0.15 · 7.33 nm / 150 nm = 0.066, named
    // with the equation and the scalar equation as a way out.
    let maxwell = huge_scene().equation("maxwell").write(dir.path());
    let (ok, _, err) = inksim(&["check", maxwell.to_str().unwrap(), "--max-memory", "1G"]);
    assert!(!ok);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    for needle in [
        "f64 fields, maxwell",
        "210.6 GB",
        "precision = \"f32\"",
        "equation = \"helmholtz\"",
    ] {
        assert!(err.contains(needle), "`{needle}` missing: {err}");
    }
    // Only what the scene does not use yet is offered.
    let f32 = huge_scene()
        .equation("maxwell")
        .precision("f32")
        .tolerance(1e-5);
    let f32 = f32.write(dir.path());
    let (ok, _, err) = inksim(&["check", f32.to_str().unwrap(), "--max-memory", "1G"]);
    assert!(!ok);
    assert!(err.contains("f32 fields, maxwell"), "{err}");
    assert!(!err.contains("precision = \"f32\""), "{err}");
    let small = SceneToml::tiny().write(dir.path());
    let (ok, out, _) = inksim(&["check", small.to_str().unwrap(), "--max-memory", "1G"]);
    assert!(ok, "20 × 20 × 20 fits in 1 GB: {out}");
    assert!(
        out.contains("estimated peak memory 27 MB (limit 1.0 GB (--max-memory))"),
        "{out}"
    );
    let (ok, _, err) = inksim(&["check", cfg, "--max-memory", "12X"]);
    assert!(
        !ok && err.contains("--max-memory") && err.contains("unknown unit"),
        "{err}"
    );
}

#[test]
fn a_missing_file_is_not_found_whatever_the_flags() {
    let (ok, _, err) = inksim(&["run", "/nonexistent/nope.toml", "--jobs", "2"]);
    assert!(!ok && err.contains("nope.toml: cannot read"), "{err}");
    assert!(!err.contains("apply to studies"), "{err}");
}

#[test]
fn plan_on_a_scene_says_it_is_not_a_study() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = SceneToml::tiny().write(dir.path());
    let (ok, _, err) = inksim(&["plan", cfg.to_str().unwrap()]);
    assert!(
        !ok && err.contains("scene.toml: not a study (no [study] table)"),
        "{err}"
    );
}

#[test]
fn plan_on_a_file_that_is_not_toml_names_the_line() {
    // A study whose inline table spans two lines (not TOML 1.0): the
    // parser's position, not "no [study] table".
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("broken.toml");
    std::fs::write(&cfg, "[study]\nname = \"s\"\nset = { a = 1,\n  b = 2 }\n").unwrap();
    let (ok, _, err) = inksim(&["plan", cfg.to_str().unwrap()]);
    assert!(
        !ok && err.contains("line 3") && !err.contains("not a study"),
        "{err}"
    );
}

#[test]
fn a_huge_thread_count_is_capped_with_a_message() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = SceneToml::tiny().write(dir.path());
    let (ok, _, err) = inksim(&["--threads", "100000", "check", cfg.to_str().unwrap()]);
    assert!(ok && err.contains("--threads 100000 capped at"), "{err}");
}

#[test]
fn a_folder_where_the_result_goes_fails_check_and_run_before_any_solve() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("tiny.h5")).unwrap();
    let cfg = SceneToml::tiny().output(&out, "tiny").write(dir.path());
    for cmd in ["check", "run"] {
        let (ok, _, err) = inksim(&[cmd, cfg.to_str().unwrap()]);
        assert!(!ok, "{cmd}");
        assert!(
            err.contains("tiny.h5: is a folder where a result file goes"),
            "{cmd}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
    let written: Vec<_> = std::fs::read_dir(&out).unwrap().flatten().collect();
    assert_eq!(written.len(), 1, "nothing but the folder: {written:?}");
}

#[test]
fn a_second_run_of_the_same_result_refuses_while_the_first_holds_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = SceneToml::tiny().output(&out, "tiny").write(dir.path());
    // Another run holds the result's lock (as `inksim run` does while it works).
    let held = inksim::output::lock::OutputLock::try_acquire(&out.join("tiny.h5"))
        .unwrap()
        .unwrap();
    let (ok, _, err) = inksim(&["run", cfg.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains(&format!(
            "another inksim run (pid {} on ",
            std::process::id()
        )) && err.contains("is writing")
            && err.contains("tiny.h5; wait for it to finish"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.join("tiny.h5").exists());
    // What a killed run left beside the result is kept while the other run
    // holds it, and removed by the next run that holds it.
    let stale = out.join("tiny.h5.4242-1.tmp");
    std::fs::write(&stale, b"half a file").unwrap();
    let (ok, _, _) = inksim(&["run", cfg.to_str().unwrap()]);
    assert!(!ok && stale.exists());
    drop(held);
    let (ok, _, err) = inksim(&["run", cfg.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.join("tiny.h5").is_file());
    assert!(!stale.exists());
}

#[test]
fn a_config_is_read_once_so_standard_input_works() {
    use std::io::Write;
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let text = SceneToml::tiny()
        .output(&dir.path().join("out"), "tiny")
        .toml();
    let mut child = Command::new(env!("CARGO_BIN_EXE_inksim"))
        .args(["check", "/dev/stdin"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    let o = child.wait_with_output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.starts_with("/dev/stdin: valid"), "{out}");
    // Not configs: a folder, an endless device.
    let (ok, _, err) = inksim(&["check", dir.path().to_str().unwrap()]);
    assert!(
        !ok && err.contains("cannot read: is a folder, not a config file"),
        "{err}"
    );
    let (ok, _, err) = inksim(&["check", "/dev/zero"]);
    assert!(
        !ok && err.contains("larger than 16 MiB, not a config file"),
        "{err}"
    );
}

#[test]
fn version_names_the_commit_and_log_lines_carry_their_time() {
    let (ok, out, _) = inksim(&["--version"]);
    assert!(ok);
    let v = out.trim().strip_prefix("inksim ").unwrap();
    assert_eq!(v, inksim::VERSION);
    let (pkg, commit) = v.split_once('+').unwrap();
    assert_eq!(pkg, env!("CARGO_PKG_VERSION"));
    assert!(
        commit == "unknown"
            || (commit.len() == 12 && commit.chars().all(|c| c.is_ascii_hexdigit())),
        "{commit}"
    );
    // Off a terminal every progress line of a run starts with its UTC time.
    let dir = tempfile::tempdir().unwrap();
    let (ok, err, _, out) = run_scene(dir.path(), &SceneToml::tiny());
    assert!(ok, "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert!(lines.len() > 3, "{err}");
    for l in lines {
        let b = l.as_bytes();
        assert!(
            b.len() > 21 && b[4] == b'-' && b[10] == b'T' && b[19] == b'Z' && b[20] == b' ',
            "{l}"
        );
    }
    // The result file names the same version.
    let s = inksim::output::h5::read_summary(&out.join("tiny.h5")).unwrap();
    assert_eq!(s.version, inksim::VERSION);
}

#[test]
fn a_long_solve_reports_its_iterations_while_it_runs() {
    // With the heartbeat every 0 s, every iteration of every solve reports:
    // the method, an iteration count that grows, the residual against the
    // tolerance and the time in the solve.
    let dir = tempfile::tempdir().unwrap();
    let cfg = SceneToml::tiny()
        .method("gmres")
        .output(&dir.path().join("out"), "tiny")
        .write(dir.path());
    let o = Command::new(env!("CARGO_BIN_EXE_inksim"))
        .args(["run", cfg.to_str().unwrap()])
        .env("INKSIM_HEARTBEAT_S", "0")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let beats: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("still solving 500 nm, 0° above: gmres iteration"))
        .collect();
    assert!(beats.len() >= 3, "{err}");
    let its: Vec<usize> = beats
        .iter()
        .map(|l| {
            l.split("iteration ")
                .nth(1)
                .unwrap()
                .split(',')
                .next()
                .unwrap()
                .parse()
                .unwrap()
        })
        .collect();
    assert!(
        its.windows(2).all(|w| w[0] <= w[1]) && its.last() > its.first(),
        "{its:?}"
    );
    assert!(beats
        .iter()
        .all(|l| l.contains("(tolerance 1e-7)") && l.ends_with(" s")));
    // By default (10 s) this quick run stays quiet.
    let (ok, _, err) = inksim(&["run", cfg.to_str().unwrap()]);
    assert!(ok && !err.contains("still solving"), "{err}");
}

/// The tiny scene with its pigment made of the library material `name`,
/// results in `dir/out`.
fn library_scene(dir: &Path, name: &str, wavelengths_nm: &[f64]) -> PathBuf {
    SceneToml::tiny()
        .pigment(
            PigmentToml::library(name)
                .named("white")
                .pvc(0.15)
                .diameter_nm(150.0),
        )
        .wavelengths_nm(wavelengths_nm)
        .output(&dir.join("out"), "white")
        .write(dir)
}

/// The files in `dir`, by name.
fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_wavelength_outside_a_library_material_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    // Rutile's tables (Devore 1951) start at 430 nm.
    let cfg = library_scene(dir.path(), "rutile", &[400.0, 550.0]);
    for cmd in ["check", "run"] {
        let (ok, out, err) = inksim(&[cmd, cfg.to_str().unwrap()]);
        assert!(!ok && !err.contains("panicked"), "{cmd}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{cmd}: {err}");
        assert_eq!(
            err.trim(),
            format!(
                "error: {}: key `illumination.wavelengths_nm`: wavelength 400 nm is outside \
                 the data range [430, 1100] nm of material library `rutile` (pigment `white`)",
                cfg.display()
            ),
            "{cmd}"
        );
        assert!(out.is_empty(), "{cmd}: {out}");
        assert_eq!(
            names_in(dir.path()),
            ["scene.toml"],
            "{cmd}: nothing left behind"
        );
    }
    // Inside the range the same scene runs.
    let cfg = library_scene(dir.path(), "rutile", &[450.0, 550.0]);
    let (ok, _, err) = inksim(&["run", cfg.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(dir.path().join("out/white.h5").is_file());
}

#[test]
fn a_ground_spectrum_outside_its_range_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("ground.csv"),
        "wavelength_nm,reflectance\n500,0.8\n700,0.85\n",
    )
    .unwrap();
    let scene = SceneToml::tiny()
        .wavelengths_nm(&[450.0, 600.0])
        .raw("substrate", "{ kind = \"csv\", file = \"ground.csv\" }")
        .output(&dir.path().join("out"), "ground");
    let cfg = scene.write(dir.path());
    for cmd in ["check", "run"] {
        let (ok, out, err) = inksim(&[cmd, cfg.to_str().unwrap()]);
        assert!(!ok && !err.contains("panicked"), "{cmd}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{cmd}: {err}");
        assert_eq!(
            err.trim(),
            format!(
                "error: {}: key `substrate.file`: wavelength 450 nm is outside the data range \
                 [500, 700] nm of the ground reflectance `ground.csv` (tables are never \
                 extrapolated)",
                cfg.display()
            ),
            "{cmd}"
        );
        assert!(out.is_empty(), "{cmd}: {out}");
        assert_eq!(
            names_in(dir.path()),
            ["ground.csv", "scene.toml"],
            "{cmd}: nothing left behind"
        );
    }
    // A chart's white half given as a spectrum is held to the same range.
    let scene = scene.raw(
        "substrate",
        "{ kind = \"chart\", white_csv = \"ground.csv\" }",
    );
    let cfg = scene.write(dir.path());
    let (ok, _, err) = inksim(&["check", cfg.to_str().unwrap()]);
    assert!(!ok && err.trim().lines().count() == 1, "{err}");
    assert!(
        err.contains("key `substrate.white_csv`: wavelength 450 nm"),
        "{err}"
    );
    // Inside the range the same scene runs, and a chart reports its hiding.
    let scene = scene.wavelengths_nm(&[500.0, 600.0]);
    let cfg = scene.write(dir.path());
    let (ok, out, err) = inksim(&["run", cfg.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        out.contains("hiding (d/8 SCI, D50, 2°): contrast ratio "),
        "{out}"
    );
    assert!(dir.path().join("out/ground.h5").is_file());
}

#[test]
fn an_unknown_library_material_lists_the_known_ones() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = library_scene(dir.path(), "titanium-white", &[450.0, 550.0]);
    for cmd in ["check", "run"] {
        let (ok, _, err) = inksim(&[cmd, cfg.to_str().unwrap()]);
        assert!(!ok && !err.contains("panicked"), "{cmd}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{cmd}: {err}");
        assert!(
            err.contains(
                "key `pigment[0].material.library`: unknown library material `titanium-white`; \
                 known: rutile, anatase, zno, calcite, hematite, cds, soot, amorphous-carbon, \
                 aluminium"
            ),
            "{cmd}: {err}"
        );
        assert_eq!(names_in(dir.path()), ["scene.toml"], "{cmd}");
    }
}

#[test]
fn materials_lists_every_stand_in_and_library_material() {
    let (ok, out, err) = inksim(&["materials"]);
    assert!(ok && err.is_empty(), "{err}");
    let row = |name: &str| {
        out.lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no row for {name}: {out}"))
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
    };
    for name in inksim::config::materials::BUILTIN_NAMES {
        assert!(
            row(name).starts_with(&format!("{name} stand-in 380-780 nm MIT OR Apache-2.0")),
            "{}",
            row(name)
        );
    }
    let cc0 = "CC0 1.0 Universal (public domain dedication), refractiveindex.info database";
    for (name, kind, range) in [
        ("rutile", "crystal o+e", "430-1100 nm"),
        ("anatase", "library", "300.2-826.56 nm"),
        ("zno", "library", "300-1100 nm"),
        ("calcite", "crystal o+e", "300-1100 nm"),
        ("hematite", "crystal o+e", "300-1100 nm"),
        ("cds", "crystal o+e", "300.14-1033.2 nm"),
        ("soot", "library", "300-1100 nm"),
        ("amorphous-carbon", "library", "326.3-1033.2 nm"),
        ("aluminium", "library", "309.96-1033.2 nm"),
    ] {
        assert_eq!(row(name), format!("{name} {kind} {range} {cc0}"));
    }
    for reference in [
        "J. R. Devore. Refractive indices of rutile and sphalerite. J. Opt. Soc. Am. 41",
        "[o: main/TiO2/Devore-o, e: main/TiO2/Devore-e]",
        "M. R. Querry. Optical constants, Contractor Report CRDC-CR-85034 (1985)",
        "A. D. Rakić. Algorithm for the determination of intrinsic optical constants",
        "[main/Al/Rakic]",
    ] {
        assert!(out.contains(reference), "{reference}");
    }
    let (ok, help, _) = inksim(&["materials", "--help"]);
    assert!(ok);
    for said in [
        "library = \"rutile\"",
        "CC0 1.0",
        "(2 ε_o + ε_e)/3",
        "crystal o+e",
    ] {
        assert!(help.contains(said), "{said} not in: {help}");
    }
}
