//! `inksim export`: the CSV tables hold exactly the numbers of the result
//! files, one row per solve, per spectrum point and per colour; the Mitsuba
//! 3 measured BSDF is a tensor file of the layout and shapes the `measured`
//! plugin requires, holding albedo/π · cos θo for bare paper at every node.
use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::Path;

mod common;
use common::cli::inksim_in;
use common::scene::{constant_material, PigmentToml, SceneToml};
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

/// A field of a tensor file as read back here: type code, shape, bytes.
struct TensorField {
    dtype: u8,
    shape: Vec<usize>,
    data: Vec<u8>,
}

impl TensorField {
    fn f32s(&self) -> Vec<f32> {
        assert_eq!(self.dtype, 10);
        self.data
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }
}

/// A tensor file read as Mitsuba 3's `TensorFile` reads it: the header,
/// then each field's name, shape, type and offset; fields in file order.
fn read_tensor_file(bytes: &[u8]) -> Vec<(String, TensorField)> {
    assert_eq!(&bytes[..12], b"tensor_file\0");
    assert_eq!(&bytes[12..14], &[1, 0]);
    let mut at = 14;
    let mut take = |n: usize| {
        let s = &bytes[at..at + n];
        at += n;
        s
    };
    let u = |s: &[u8]| s.iter().rev().fold(0u64, |a, &b| (a << 8) | b as u64) as usize;
    let n = u(take(4));
    (0..n)
        .map(|_| {
            let len = u(take(2));
            let name = String::from_utf8(take(len).to_vec()).unwrap();
            let ndim = u(take(2));
            let dtype = take(1)[0];
            let offset = u(take(8));
            let shape: Vec<usize> = (0..ndim).map(|_| u(take(8))).collect();
            let size = match dtype {
                1 => 1,
                10 => 4,
                t => panic!("{name}: type {t}"),
            };
            let end = offset + size * shape.iter().product::<usize>();
            assert_eq!(offset % 8, 0, "{name} at {offset}");
            let data = bytes[offset..end].to_vec();
            (name, TensorField { dtype, shape, data })
        })
        .collect()
}

#[test]
fn tensor_files_read_back_as_written() {
    use inksim::output::tensor_file::{encode, Field, Values};
    let fields = vec![
        Field::new("name", &[3], Values::U8(b"abc".to_vec())).unwrap(),
        Field::new("empty", &[0], Values::U8(vec![])).unwrap(),
        Field::new(
            "grid",
            &[2, 3],
            Values::F32(vec![1.0, -2.5, 3.0, 4.0, 5.0, 1e-7]),
        )
        .unwrap(),
    ];
    assert!(Field::new("bad", &[2, 2], Values::F32(vec![1.0])).is_none());
    let back = read_tensor_file(&encode(&fields));
    assert_eq!(back.len(), 3);
    for (f, (name, r)) in fields.iter().zip(&back) {
        assert_eq!(&f.name, name);
        assert_eq!(f.shape, r.shape);
        match &f.values {
            Values::U8(v) => assert_eq!((r.dtype, &r.data), (1, v)),
            Values::F32(v) => assert_eq!(&r.f32s(), v),
        }
    }
}

#[test]
fn bare_paper_exports_a_mitsuba_bsdf_of_albedo_over_pi() {
    // A vacuum layer (binder and pigment of index 1) on paper of albedo
    // 0.9: the BRDF is 0.9/π everywhere, so every node of `spectra` holds
    // 0.9/π · cos θo, θo from the node's half vector as the file's layout
    // defines it.
    let dir = tempfile::tempdir().unwrap();
    let csv = constant_material(dir.path(), "plain", 1.0);
    let cfg = SceneToml::slab()
        .seed(3)
        .fragment_nm(1000.0)
        .binder_index(1.0)
        .pigment(PigmentToml::csv("dissolved", &csv).pvc(0.2).molecular())
        .cell_nm(50.0)
        .polar_deg(&[0.0, 40.0])
        .paper(0.9)
        .outputs(&["tile"])
        .output(&dir.path().join("out"), "slab")
        .write(dir.path());
    let (ok, _, err) = inksim_in(dir.path(), &["run", cfg.to_str().unwrap()]);
    assert!(ok, "{err}");
    let h5 = dir.path().join("out/slab.h5");
    let (ok, out, err) = inksim_in(dir.path(), &["export", h5.to_str().unwrap(), "--mitsuba"]);
    assert!(ok, "{err}");
    assert!(out.contains("slab.bsdf"), "{out}");
    let fields = read_tensor_file(&std::fs::read(dir.path().join("out/slab.bsdf")).unwrap());
    let f = |n: &str| &fields.iter().find(|(name, _)| name == n).unwrap().1;
    // What the `measured` plugin checks.
    let (ti, pi, wl) = (f("theta_i").f32s(), f("phi_i"), f("wavelengths").f32s());
    assert_eq!(
        (f("description").dtype, &f("description").data[..]),
        (1, &b"slab"[..])
    );
    assert_eq!(
        (f("jacobian").dtype, &f("jacobian").data[..]),
        (1, &[0u8][..])
    );
    assert_eq!(pi.f32s(), vec![-std::f32::consts::PI, std::f32::consts::PI]);
    assert_eq!(wl, vec![450.0, 550.0, 650.0]);
    for solved in [0.0f32, 40.0] {
        assert!(ti.iter().any(|t| (t.to_degrees() - solved).abs() < 1e-4));
    }
    assert!(
        ti.windows(2).all(|w| w[0] < w[1]) && *ti.last().unwrap() < std::f32::consts::FRAC_PI_2
    );
    let (nt, nl) = (ti.len(), wl.len());
    assert_eq!(f("ndf").shape.len(), 2);
    assert_eq!(f("sigma").shape.len(), 2);
    assert_eq!(&f("vndf").shape[..2], &[2, nt]);
    let n = f("spectra").shape[4];
    assert_eq!(f("spectra").shape, vec![2, nt, nl, n, n]);
    assert_eq!(f("luminance").shape, vec![2, nt, n, n]);
    assert!(f("luminance").f32s().iter().all(|&v| v > 0.0));
    let spectra = f("spectra").f32s();
    let (half, _) = spectra.split_at(spectra.len() / 2);
    assert_eq!(&spectra[spectra.len() / 2..], half);
    let mut above = 0;
    for (it, t) in ti.iter().enumerate() {
        let t = *t as f64;
        let wi = [t.sin(), 0.0, t.cos()];
        for y in 0..n {
            for x in 0..n {
                let u = x as f64 / (n - 1) as f64;
                let (tm, pm) = (
                    u * u * PI / 2.0,
                    (y as f64 / (n - 1) as f64) * 2.0 * PI - PI,
                );
                let m = [tm.sin() * pm.cos(), tm.sin() * pm.sin(), tm.cos()];
                let d = 2.0 * (m[0] * wi[0] + m[2] * wi[2]);
                let cos_o = d * m[2] - wi[2];
                let want = if cos_o > 0.0 { 0.9 / PI * cos_o } else { 0.0 };
                above += usize::from(cos_o > 0.0);
                for l in 0..nl {
                    let got = spectra[((it * nl + l) * n + y) * n + x] as f64;
                    assert!(
                        (got - want).abs() < 1e-6,
                        "θi {t} x {x} y {y}: {got} vs {want}"
                    );
                }
            }
        }
    }
    assert!(above > nt * n * n / 3);
    // The reference evaluations: 0.9/π, and times cos θo.
    for row in table(&dir.path().join("out/slab-bsdf-samples.csv")) {
        assert!((num(&row, "brdf_per_sr") - 0.9 / PI).abs() < 1e-9);
        let c = num(&row, "theta_o_deg").to_radians().cos();
        assert!((num(&row, "brdf_cos") - 0.9 / PI * c).abs() < 1e-9);
    }
}

#[test]
fn mitsuba_export_refuses_a_study_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let study = StudyToml::new("t", 5, "out", &scene()).axis("pvc", "pigment.0.pvc", "[0.1, 0.2]");
    std::fs::write(dir.path().join("study.toml"), study.toml()).unwrap();
    let (ok, _, err) = inksim_in(dir.path(), &["export", "study.toml", "--mitsuba"]);
    assert!(!ok);
    assert!(err.contains("--mitsuba exports a result file"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}
