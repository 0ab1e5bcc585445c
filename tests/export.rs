//! `inksim export`: the CSV tables hold exactly the numbers of the result
//! files, one row per solve, per spectrum point and per colour.
use std::collections::HashMap;
use std::path::Path;

mod common;
use common::cli::inksim_in;
use common::scene::{PigmentToml, SceneToml};
use common::study::StudyToml;
use inksim::output::h5::{read_appearance, read_baseline, read_measured, read_summary};

/// A CSV table as rows of column → field (no field of ours is quoted).
fn table(path: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), header.len(), "{l}");
            header
                .iter()
                .cloned()
                .zip(f.iter().map(|s| s.to_string()))
                .collect()
        })
        .collect()
}

fn num(row: &HashMap<String, String>, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col}: `{}`", row[col]))
}

/// Red spheres on paper, two realisations, with the tile.
fn scene() -> SceneToml {
    SceneToml::grains()
        .seed(3)
        .realisations(2)
        .thickness_nm(400.0)
        .fragment_nm(500.0)
        .pvc(0.15)
        .diameter_nm(150.0)
        .z_cell_nm(40.0)
        .wavelengths_nm(&[450.0, 600.0])
        .polar_deg(&[0.0, 40.0])
        .tolerance(1e-6)
        .quadrature_points(3)
        .paper(0.8)
        .outputs(&["brdf", "tile"])
}

#[test]
fn a_result_exports_its_solves_spectra_and_colours() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = scene().output(&out, "red").write(dir.path());
    let (ok, _, err) = inksim_in(dir.path(), &["run", cfg.to_str().unwrap()]);
    assert!(ok, "{err}");
    let h5 = out.join("red.h5");
    let csv_dir = dir.path().join("csv");
    let (ok, stdout, err) = inksim_in(
        dir.path(),
        &[
            "export",
            h5.to_str().unwrap(),
            "--to",
            csv_dir.to_str().unwrap(),
        ],
    );
    assert!(ok, "{err}");
    assert_eq!(stdout.lines().count(), 3, "{stdout}");

    // Every solve, from above and from below, in the file's order.
    let s = read_summary(&h5).unwrap();
    let solves = table(&csv_dir.join("red-solves.csv"));
    assert_eq!(solves.len(), s.entries.len());
    assert!(solves.iter().any(|r| r["side"] == "below"));
    for (r, e) in solves.iter().zip(&s.entries) {
        assert_eq!(num(r, "wavelength_nm"), e.wavelength_nm);
        assert_eq!(num(r, "reflectance"), e.total_reflectance);
        assert_eq!(num(r, "energy_balance"), e.energy_balance);
        assert_eq!(r["method"], e.method.to_string());
    }

    // Ensemble means with standard errors (two realisations).
    let a = read_appearance(&h5).unwrap().unwrap();
    let spectra = table(&csv_dir.join("red-spectra.csv"));
    assert_eq!(spectra.len(), a.wavelengths_nm.len() * a.above_deg.len());
    for (k, r) in spectra.iter().enumerate() {
        let (l, p) = (k / a.above_deg.len(), k % a.above_deg.len());
        assert_eq!(num(r, "polar_deg"), a.above_deg[p]);
        assert_eq!(num(r, "transmittance"), a.transmittance[[l, p]]);
        assert!(num(r, "reflectance_se") >= 0.0);
    }

    // The measurement geometries, then every tile cell.
    let (measured, illuminant, _) = read_measured(&h5).unwrap().unwrap();
    let colours = table(&csv_dir.join("red-colours.csv"));
    let tile = a.tile_lab.unwrap();
    assert_eq!(colours.len(), measured.len() + tile.dim().0 * tile.dim().1);
    for (r, m) in colours.iter().zip(&measured) {
        assert_eq!(r["geometry"], m.geometry);
        assert_eq!(r["illuminant"], illuminant);
        assert_eq!(num(r, "L_star"), m.lab[0]);
        assert_eq!(num(r, "Y"), m.xyz[1]);
        assert_eq!(num(r, "de00_se"), m.de00_se.unwrap());
        let c = (m.lab[1].powi(2) + m.lab[2].powi(2)).sqrt();
        assert!((num(r, "C_star_ab") - c).abs() < 1e-9);
    }
    let sky = &colours[measured.len()];
    assert_eq!(sky["geometry"], "sky");
    assert_eq!(num(sky, "b_star"), tile[[0, 0, 2]]);
    assert!(num(sky, "L_star_se") > 0.0 && sky["X"].is_empty());
    let cell = &colours[measured.len() + 1];
    assert_eq!(cell["geometry"], "brdf");
    assert_eq!(num(cell, "illumination_deg"), a.illumination_deg[0]);
    assert_eq!(num(cell, "a_star"), tile[[0, 1, 1]]);
}

#[test]
fn a_result_without_appearance_exports_its_solves_only() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = scene()
        .realisations(1)
        .outputs(&[])
        .output(&out, "bare")
        .write(dir.path());
    assert!(inksim_in(dir.path(), &["run", cfg.to_str().unwrap()]).0);
    let (ok, stdout, err) = inksim_in(dir.path(), &["export", "out/bare.h5"]);
    assert!(ok, "{err}");
    assert_eq!(stdout.trim(), "solves: out/bare-solves.csv");
    assert_eq!(table(&out.join("bare-solves.csv")).len(), 4);
    // A scene config, and a file that is not a result, get one line each.
    for (arg, want) in [
        (
            cfg.to_str().unwrap(),
            "export takes a result file (.h5) or a study",
        ),
        ("out/bare-solves.csv", "bare-solves.csv"),
        ("out/none.h5", "none.h5"),
    ] {
        let (ok, _, err) = inksim_in(dir.path(), &["export", arg]);
        assert!(!ok && err.contains(want), "{arg}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
}

#[test]
fn a_study_exports_every_finished_variants_colours_with_its_labels() {
    let dir = tempfile::tempdir().unwrap();
    let base = scene()
        .realisations(1)
        .pigment(PigmentToml::builtin("red").named("p").diameter_nm(150.0))
        .outputs(&["tile"])
        .raw(
            "appearance.baseline",
            r#"["adding-doubling", "kubelka-munk"]"#,
        );
    let study = StudyToml::new("t", 5, "out", &base).axis("pvc", "pigment.0.pvc", "[0.1, 0.2]");
    std::fs::write(dir.path().join("study.toml"), study.toml()).unwrap();
    let (ok, _, err) = inksim_in(dir.path(), &["run", "study.toml"]);
    assert!(ok, "{err}");
    let (ok, stdout, err) = inksim_in(dir.path(), &["export", "study.toml"]);
    assert!(ok, "{err}");
    let path = stdout.trim().strip_prefix("colours: ").unwrap().to_string();
    let rows = table(&dir.path().join(&path));
    assert_eq!(rows.len(), 2 * 3, "two variants × three geometries");
    let labels: Vec<&str> = rows.iter().map(|r| r["pvc"].as_str()).collect();
    assert_eq!(labels.iter().filter(|l| **l == labels[0]).count(), 3);
    let variants = Path::new(&path).parent().unwrap().join("variants");
    let name = &rows[0]["variant"];
    let (m, _, _) = read_measured(&dir.path().join(&variants).join(format!("{name}.h5")))
        .unwrap()
        .unwrap();
    assert_eq!(num(&rows[0], "L_star"), m[0].lab[0]);
    assert!(
        rows[0]["de00_se"].is_empty(),
        "one realisation: no standard error"
    );
    // Each baseline beside the wave colour, geometry by geometry, its
    // columns named by the model (km_*, ad_*), in the documented order.
    let stored = read_baseline(&dir.path().join(&variants).join(format!("{name}.h5"))).unwrap();
    for r in rows.iter().filter(|r| &r["variant"] == name) {
        for (model, prefix) in [("kubelka-munk", "km"), ("adding-doubling", "ad")] {
            let b = stored
                .iter()
                .find(|b| b.geometry == r["geometry"] && b.model == model)
                .unwrap();
            assert_eq!(num(r, &format!("{prefix}_b_star")), b.lab[2]);
            assert_eq!(
                num(r, &format!("{prefix}_de00_to_wave")),
                b.de00_to_wave.unwrap()
            );
        }
    }
    let header = std::fs::read_to_string(dir.path().join(&path)).unwrap();
    let header = header.lines().next().unwrap();
    let (km, ad) = (
        header.find("km_L_star").unwrap(),
        header.find("ad_L_star").unwrap(),
    );
    assert!(km < ad, "{header}");

    // A variant not finished has no rows, and the user is told.
    std::fs::remove_file(dir.path().join(&variants).join(format!("{name}.h5"))).unwrap();
    let (ok, _, err) = inksim_in(dir.path(), &["export", "study.toml"]);
    assert!(
        ok && err.contains("1 of 2 variants are not finished"),
        "{err}"
    );
    assert_eq!(table(&dir.path().join(&path)).len(), 3);
}

#[test]
fn the_kubelka_munk_baseline_is_exported_beside_the_wave_colours() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = scene()
        .realisations(1)
        .raw(
            "appearance.baseline",
            r#"["kubelka-munk", "kubelka-munk-scene", "adding-doubling", "adding-doubling-contact"]"#,
        )
        .output(&out, "km")
        .write(dir.path());
    assert!(inksim_in(dir.path(), &["run", cfg.to_str().unwrap()]).0);
    let (ok, stdout, err) = inksim_in(dir.path(), &["export", "out/km.h5"]);
    assert!(
        ok && stdout.contains("baseline: out/km-baseline.csv"),
        "{stdout}{err}"
    );
    let rows = table(&out.join("km-baseline.csv"));
    let stored = read_baseline(&out.join("km.h5")).unwrap();
    let (measured, _, _) = read_measured(&out.join("km.h5")).unwrap().unwrap();
    assert_eq!(rows.len(), 4 * measured.len());
    let models = [
        "kubelka-munk",
        "kubelka-munk-scene",
        "adding-doubling",
        "adding-doubling-contact",
    ];
    for (i, (r, b)) in rows.iter().zip(&stored).enumerate() {
        assert_eq!(r["model"], models[i / measured.len()]);
        assert_eq!(r["model"], b.model);
        assert_eq!(r["geometry"], b.geometry);
        assert_eq!(num(r, "L_star"), b.lab[0]);
        assert_eq!(num(r, "de00_to_wave"), b.de00_to_wave.unwrap());
        // The stored difference is to the wave colour of the same geometry.
        let wave = measured.iter().find(|m| m.geometry == b.geometry).unwrap();
        let de = inksim::optics::colour::delta_e2000(b.lab, wave.lab);
        assert!((de - b.de00_to_wave.unwrap()).abs() < 1e-12);
    }
}

#[test]
fn a_result_with_the_earlier_single_model_layout_still_reads() {
    // /appearance/baseline/<geometry> with the model as the group's
    // attribute, as files written before the list of models have it.
    use hdf5::types::VarLenUnicode;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.h5");
    {
        let f = inksim::output::h5::create(&path).unwrap();
        let g = f.create_group("appearance/baseline").unwrap();
        let text = |s: &str| s.parse::<VarLenUnicode>().unwrap();
        g.new_attr::<VarLenUnicode>()
            .create("model")
            .unwrap()
            .write_scalar(&text("kubelka-munk"))
            .unwrap();
        let d = g.create_group("45_0").unwrap();
        d.new_attr::<VarLenUnicode>()
            .create("geometry")
            .unwrap()
            .write_scalar(&text("45/0"))
            .unwrap();
        d.new_dataset_builder()
            .with_data(&[50.0, 10.0, -5.0])
            .create("lab")
            .unwrap();
        d.new_dataset_builder()
            .with_data(&[3.5])
            .create("de00_to_wave")
            .unwrap();
    }
    let read = read_baseline(&path).unwrap();
    assert_eq!(read.len(), 1);
    assert_eq!(read[0].model, "kubelka-munk");
    assert_eq!(read[0].geometry, "45/0");
    assert_eq!(read[0].lab, [50.0, 10.0, -5.0]);
    assert_eq!(read[0].de00_to_wave, Some(3.5));
}
