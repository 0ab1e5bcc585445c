//! `inksim fit-material`: a known material's constants recovered from its
//! own synthetic drawdowns (fast model, instrument-level noise, seeded),
//! within the standard errors the fit states; the fitted table read back
//! as a scene material reproducing the drawdowns through the scene's own
//! baseline; a free grain size; what opaque masstones alone cannot fix;
//! and the command's files and one-line errors.

mod common;

use common::cli::inksim_in;
use inksim::config::{parse_scene, Material, Measurement};
use inksim::optics::baseline::reflectance_factors;
use inksim::pipeline::baseline_input;
use inksim::r#match::fit::synthetic::synthesise;
use inksim::r#match::fit::{self, write, FitOutcome, FitSpec};
use std::path::{Path, PathBuf};

/// Instrument-level noise (1σ of a reflectance factor).
const NOISE: f64 = 0.002;

/// The base scene and the white every fit file here shares.
const BASE: &str = r#"
[white]
name = "rutile"
material = { library = "rutile" }
diameter_nm = 250.0

[base.layer]
thickness_nm = 15000.0
fragment_nm = [2000.0, 2000.0]
binder_index = 1.5
[base.grid]
cell_nm = 50.0
[base.illumination]
wavelengths_nm = [430.0, 700.0]
polar_deg = [0.0]
[base.appearance]
baseline = "kubelka-munk"
"#;

/// A drawdown on a hiding chart (white half of albedo 0.8).
fn chart(name: &str, thickness_nm: f64, pvc: f64, white_pvc: f64) -> String {
    format!(
        "[[drawdown]]\nname = \"{name}\"\nsubstrate = {{ kind = \"chart\", white_albedo = 0.8 }}\n\
         thickness_nm = {thickness_nm}\npvc = {pvc}\nwhite_pvc = {white_pvc}\n\
         csv_black = \"d/{name}-black.csv\"\ncsv_white = \"d/{name}-white.csv\"\n"
    )
}

/// A masstone and two tints with rutile, 15 µm, each on a chart.
fn masstone_and_tints() -> String {
    [
        chart("masstone", 15000.0, 0.10, 0.0),
        chart("tint-1", 15000.0, 0.02, 0.15),
        chart("tint-2", 15000.0, 0.005, 0.15),
    ]
    .concat()
}

/// Write the fit file `fit.toml` in `dir` (`pigment` the `[pigment]`
/// table's body) and its drawdowns' spectra: `material` at `d_nm`, noise
/// [`NOISE`] from `seed`.
fn fit_file(
    dir: &Path,
    unknowns: &str,
    pigment: &str,
    drawdowns: &str,
    material: &Material,
    d_nm: f64,
    seed: u64,
) -> PathBuf {
    let text = format!(
        "[fit]\nname = \"fitted\"\noutput_dir = \"out\"\nunknowns = \"{unknowns}\"\n\
         geometry = \"d/8 SCI\"\nnoise_reflectance = {NOISE}\n\n[pigment]\n{pigment}\n{BASE}\n\
         {drawdowns}"
    );
    let path = dir.join("fit.toml");
    std::fs::write(&path, text).unwrap();
    synthesise(&path, material, d_nm, NOISE, seed).unwrap();
    path
}

/// The fit of the file `path`.
fn fitted(path: &Path) -> (FitSpec, FitOutcome) {
    let spec = FitSpec::load(path).unwrap();
    let out = fit::run(&spec).unwrap();
    (spec, out)
}

/// `(fit − true) / s.e.` of every determined value, with `true` from
/// `truth(λ)` and the value and s.e. from `pick`.
fn z_scores(
    out: &FitOutcome,
    truth: &dyn Fn(f64) -> f64,
    pick: &dyn Fn(&fit::WavelengthFit) -> Option<(f64, f64)>,
) -> Vec<(f64, f64, f64)> {
    out.wavelengths_nm
        .iter()
        .zip(&out.per_wavelength)
        .filter(|(_, w)| w.n_flags.is_empty() && w.k_flags.is_empty())
        .filter_map(|(&l, w)| pick(w).map(|(v, s)| (l, v, (v - truth(l)) / s)))
        .collect()
}

/// The stand-in red's k(λ) (n = 1.4 known, 150 nm grains) from a masstone
/// and two tints over black and white with noise 0.002: every k within 4
/// of its standard errors and 6 % (+1e-4) of the truth; the z-scores'
/// RMS near 1 (the stated errors are the real ones) and χ²/dof near 1;
/// nothing flagged.
#[test]
fn recovers_k_of_the_red_stand_in() {
    let dir = tempfile::tempdir().unwrap();
    let red = Material::builtin("red").unwrap();
    let path = fit_file(
        dir.path(),
        "k",
        "name = \"red\"\ndiameter_nm = 150.0\nn = 1.4",
        &masstone_and_tints(),
        &red,
        150.0,
        11,
    );
    let (spec, out) = fitted(&path);
    assert!(
        out.not_determined().is_empty(),
        "{:?}",
        out.not_determined()
    );
    let truth = |l: f64| red.index_at(l).unwrap().im;
    let z = z_scores(&out, &truth, &|w| w.k_se.map(|s| (w.k, s)));
    assert_eq!(z.len(), out.wavelengths_nm.len());
    for &(l, k, zk) in &z {
        assert!(zk.abs() < 4.0, "{l} nm: k {k} vs {} (z {zk})", truth(l));
        assert!(
            (k - truth(l)).abs() < 0.06 * truth(l) + 1e-4,
            "{l} nm: k {k} vs {}",
            truth(l)
        );
    }
    let rms = (z.iter().map(|x| x.2 * x.2).sum::<f64>() / z.len() as f64).sqrt();
    assert!((0.7..1.4).contains(&rms), "z RMS {rms}");
    assert!(
        (0.8..1.25).contains(&out.chi2_per_dof()),
        "{}",
        out.chi2_per_dof()
    );

    // The table the command writes is a scene material: the tints' white
    // halves through the scene's own kubelka-munk baseline (another path
    // than the fit's model) reproduce the measured spectra within the noise.
    let text = std::fs::read_to_string(&path).unwrap();
    let written = write::write_outputs(&spec, &text, &out, &dir.path().join("out")).unwrap();
    for d in &spec.drawdowns {
        let scene_text = format!(
            "[layer]\nthickness_nm = {}\nfragment_nm = [2000.0, 2000.0]\nbinder_index = 1.5\n\
             [grid]\ncell_nm = 50.0\n[illumination]\nwavelengths_nm = [430.0, 700.0]\n\
             polar_deg = [0.0]\n[appearance]\nbaseline = \"kubelka-munk\"\n\
             [substrate]\nkind = \"white\"\nalbedo = 0.8\n\
             [[pigment]]\nname = \"red\"\nmaterial = {{ csv = \"fitted.csv\" }}\ndiameter_nm = 150.0\npvc = {}\n\
             [[pigment]]\nname = \"rutile\"\nmaterial = {{ library = \"rutile\" }}\ndiameter_nm = 250.0\npvc = {}\n",
            d.thickness_nm, d.pvc, d.white_pvc
        );
        let scene = parse_scene(&written.csv.with_file_name("scene.toml"), &scene_text).unwrap();
        assert!(matches!(
            &scene.species[0].material.source,
            inksim::config::MaterialSource::Csv(_)
        ));
        let input = baseline_input(&scene).unwrap().unwrap();
        let f = &reflectance_factors(
            scene.appearance.baseline[0],
            &input,
            &[Measurement::DiffuseEightSci],
        )
        .unwrap()[0];
        let white = &d.readings[1].spectrum;
        let diff: Vec<f64> = input
            .wavelengths_nm
            .iter()
            .zip(f)
            .map(|(&l, v)| v - white.at(l))
            .collect();
        let rms = (diff.iter().map(|x| x * x).sum::<f64>() / diff.len() as f64).sqrt();
        assert!(rms < 1.3 * NOISE, "{}: RMS {rms}", d.name);
    }
}

/// A free grain size: the red's 150 nm found from a first guess of 120 nm
/// within 3 standard errors (and 5 nm), with k still within 4 of its own.
#[test]
fn free_grain_size_is_recovered() {
    let dir = tempfile::tempdir().unwrap();
    let red = Material::builtin("red").unwrap();
    let path = fit_file(
        dir.path(),
        "k",
        "name = \"red\"\ndiameter_nm = 120.0\ndiameter_range_nm = [80.0, 300.0]\nn = 1.4",
        &masstone_and_tints(),
        &red,
        150.0,
        12,
    );
    let (_, out) = fitted(&path);
    let se = out.diameter_se.expect("the size is determined");
    assert!(out.diameter_flags.is_empty(), "{}", out.diameter_flags);
    assert!(
        (out.diameter_nm - 150.0).abs() < (3.0 * se).min(5.0),
        "{} ± {se}",
        out.diameter_nm
    );
    let truth = |l: f64| red.index_at(l).unwrap().im;
    for (l, k, z) in z_scores(&out, &truth, &|w| w.k_se.map(|s| (w.k, s))) {
        assert!(z.abs() < 4.0, "{l} nm: k {k} vs {} (z {z})", truth(l));
    }
}

/// n and k of hematite (library, 200 nm grains): wherever the fit says
/// both are determined they are within 4 standard errors of the library's
/// values; where the layer is dark the fit flags what it cannot fix (n and
/// k correlated, or a second solution fitting as well) instead.
#[test]
fn n_and_k_of_hematite_within_their_errors_where_determined() {
    let dir = tempfile::tempdir().unwrap();
    let hem = Material::library("hematite").unwrap();
    let path = fit_file(
        dir.path(),
        "n-and-k",
        "name = \"hematite\"\ndiameter_nm = 200.0\nn_range = [1.5, 3.5]",
        &masstone_and_tints(),
        &hem,
        200.0,
        13,
    );
    let (_, out) = fitted(&path);
    let n_true = |l: f64| hem.index_at(l).unwrap().re;
    let k_true = |l: f64| hem.index_at(l).unwrap().im;
    let zn = z_scores(&out, &n_true, &|w| w.n_se.map(|s| (w.n, s)));
    let zk = z_scores(&out, &k_true, &|w| w.k_se.map(|s| (w.k, s)));
    assert!(zn.len() >= 15, "{} wavelengths determined", zn.len());
    for ((l, n, a), (_, k, b)) in zn.iter().zip(&zk) {
        assert!(a.abs() < 4.0, "{l} nm: n {n} vs {} (z {a})", n_true(*l));
        assert!(b.abs() < 4.0, "{l} nm: k {k} vs {} (z {b})", k_true(*l));
    }
    assert!(!out.not_determined().is_empty());
}

/// Opaque masstones alone (30 % pigment, 200 µm over black and white, no
/// tint): the two grounds read the same, so each wavelength gives one
/// number, R∞ — n and k are not determined apart, and the fit says so at
/// (nearly) every wavelength.
#[test]
fn opaque_masstones_alone_are_flagged() {
    let dir = tempfile::tempdir().unwrap();
    let hem = Material::library("hematite").unwrap();
    let path = fit_file(
        dir.path(),
        "n-and-k",
        "name = \"hematite\"\ndiameter_nm = 200.0\nn_range = [1.5, 3.5]",
        &[
            chart("thick", 200000.0, 0.3, 0.0),
            chart("thicker", 400000.0, 0.3, 0.0),
        ]
        .concat(),
        &hem,
        200.0,
        14,
    );
    let (_, out) = fitted(&path);
    let flagged = out
        .per_wavelength
        .iter()
        .filter(|w| !w.n_flags.is_empty() && !w.k_flags.is_empty())
        .count();
    assert!(
        flagged as f64 >= 0.9 * out.wavelengths_nm.len() as f64,
        "{flagged} of {} flagged",
        out.wavelengths_nm.len()
    );
}

/// The command on the example: the material table and the HDF5 result,
/// the table read by the material loader with the stand-in's k at its
/// peak, the HDF5's k with units, progress lines with their UTC time.
#[test]
fn command_writes_material_and_result() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/fit-red.toml");
    let out = dir.path().join("out");
    let (ok, stdout, stderr) = inksim_in(
        dir.path(),
        &[
            "fit-material",
            cfg.to_str().unwrap(),
            "--output-dir",
            out.to_str().unwrap(),
        ],
    );
    assert!(ok, "{stderr}");
    assert!(stdout.contains("chi2/dof"), "{stdout}");
    assert!(!stdout.contains("not determined"), "{stdout}");
    assert!(
        stderr
            .lines()
            .all(|l| l.contains("Z [inksim] fit-material: ")),
        "{stderr}"
    );
    let m = Material::from_csv(&out.join("fit-red.csv")).unwrap();
    let k = m.index_at(540.0).unwrap().im;
    let k_true = Material::builtin("red")
        .unwrap()
        .index_at(540.0)
        .unwrap()
        .im;
    assert!((k - k_true).abs() < 0.05 * k_true, "{k} vs {k_true}");
    let text = std::fs::read_to_string(out.join("fit-red.csv")).unwrap();
    assert!(text.contains("# input sha256 "), "{text}");
    assert!(text.contains("# residuals: RMS "), "{text}");
    let f = inksim::output::h5::open(out.join("fit-red.h5")).unwrap();
    let kh = f.dataset("k").unwrap().read_1d::<f64>().unwrap();
    assert_eq!(kh.len(), 55);
    let units: hdf5::types::VarLenUnicode = f
        .dataset("k_se")
        .unwrap()
        .attr("units")
        .unwrap()
        .read_scalar()
        .unwrap();
    assert_eq!(units.as_str(), "1");
    let (ok, stdout, _) = inksim_in(dir.path(), &["check", cfg.to_str().unwrap()]);
    assert!(ok && stdout.contains("fit file OK"), "{stdout}");
}

/// A bad fit file: one line naming the file and the key, a non-zero exit,
/// nothing written — from `fit-material` and from `check`.
#[test]
fn bad_fit_file_is_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let good = std::fs::read_to_string(root.join("fit-red.toml"))
        .unwrap()
        .replace("runs/fit-red", "out")
        .replace("\"fit-red/", &format!("\"{}/fit-red/", root.display()));
    for (bad, key) in [
        (
            good.replace("noise_reflectance = 0.002", "noise_reflectance = 0.5"),
            "fit.noise_reflectance",
        ),
        (
            good.replace("unknowns = \"k\"", "unknowns = \"n\""),
            "fit.unknowns",
        ),
        (good.replace("n = 1.4", "n = 0.5"), "pigment.n"),
        (good.replace("pvc = 0.005", "pvc = 0.9"), "drawdown[2].pvc"),
        (
            good.replace("white_albedo = 0.8", "white_albedo = 1.8"),
            "drawdown[0].substrate.white_albedo",
        ),
        (
            good.replace("geometry = \"d/8 SCI\"", "geometry = \"d/0\""),
            "fit.geometry",
        ),
        (
            good.replace("name = \"tint-2\"", "name = \"tint-2\"\ncolour = 3"),
            "unknown field `colour`",
        ),
        (
            good.replace("{ library = \"rutile\" }", "{ library = \"rutil\" }"),
            "white.material.library",
        ),
        (
            good.replace("tint-1-white.csv", "missing.csv"),
            "drawdown[1].csv_white",
        ),
    ] {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, bad).unwrap();
        for cmd in ["fit-material", "check"] {
            let (ok, _, stderr) = inksim_in(dir.path(), &[cmd, "bad.toml"]);
            assert!(!ok, "{cmd} {key}");
            let lines: Vec<&str> = stderr
                .lines()
                .filter(|l| !l.contains("[inksim] fit-material:"))
                .collect();
            assert_eq!(lines.len(), 1, "{cmd} {key}: {stderr}");
            assert!(
                lines[0].starts_with("error: ")
                    && lines[0].contains("bad.toml")
                    && lines[0].contains(key),
                "{cmd} {key}: {}",
                lines[0]
            );
        }
        assert!(
            !dir.path().join("out").exists(),
            "{key}: nothing is written"
        );
    }
}
