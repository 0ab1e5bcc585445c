//! Every dataset inksim writes explains itself: a scene result with every
//! appearance product, paper and measured colours, and a study's
//! `summary.h5`, walked whole (external links to the variant files left
//! out): each dataset has a string `units` attribute (possibly empty, for
//! text) and a non-empty `description`, its dimensions are labelled, and
//! the axes whose coordinates the file holds have them attached as HDF5
//! dimension scales. A dataset added without them fails here.
use hdf5::types::{VarLenAscii, VarLenUnicode};
use hdf5::{Dataset, Group, LinkType, LocationType};
use std::path::Path;

mod common;
use common::cli::inksim_in;
use common::scene::{PigmentToml, SceneToml};
use common::study::StudyToml;

/// The tiny layer of the study tests: 8 × 8 × 4 grid, two wavelengths.
fn tiny() -> SceneToml {
    SceneToml::grains()
        .thickness_nm(400.0)
        .fragment_nm(400.0)
        .layer_pvc(0.15)
        .pigment(PigmentToml::builtin("red").named("p").diameter_nm(100.0))
        .cell_nm(50.0)
        .z_cell_nm(100.0)
        .wavelengths_nm(&[450.0, 600.0])
        .polar_deg(&[0.0, 30.0])
}

/// Every dataset under `g` reached by hard links, with its path.
fn datasets(g: &Group, prefix: &str, out: &mut Vec<(String, Dataset)>) {
    let links = g
        .iter_visit_default(Vec::new(), |_, name, info, acc| {
            acc.push((name.to_string(), info.link_type));
            true
        })
        .unwrap();
    for (name, link) in links {
        let path = format!("{prefix}/{name}");
        if link != LinkType::Hard {
            continue;
        }
        match g.loc_type_by_name(&name).unwrap() {
            LocationType::Group => datasets(&g.group(&name).unwrap(), &path, out),
            LocationType::Dataset => out.push((path, g.dataset(&name).unwrap())),
            other => panic!("{path}: unexpected object {other:?}"),
        }
    }
}

fn str_attr(d: &Dataset, name: &str) -> Option<String> {
    let a = d.attr(name).ok()?;
    Some(a.read_scalar::<VarLenUnicode>().ok()?.as_str().to_owned())
}

/// Check every dataset of `file`; returns the paths seen and, per path, its
/// dimension labels.
fn check_file(file: &Path) -> Vec<(String, Vec<String>)> {
    let f = inksim::output::h5::open(file).unwrap();
    let mut all = Vec::new();
    datasets(&f, "", &mut all);
    assert!(
        all.len() > 10,
        "{}: only {} datasets",
        file.display(),
        all.len()
    );
    let mut seen = Vec::new();
    let mut missing = Vec::new();
    for (path, d) in &all {
        let units = str_attr(d, "units");
        let description = str_attr(d, "description").unwrap_or_default();
        if units.is_none() || description.trim().is_empty() {
            missing.push(format!(
                "{path} (units {units:?}, description {description:?})"
            ));
            continue;
        }
        assert!(!description.contains('\n'), "{path}: {description:?}");
        let ndim = d.ndim();
        let labels: Vec<String> = if ndim == 0 {
            Vec::new()
        } else {
            let a = d
                .attr("DIMENSION_LABELS")
                .unwrap_or_else(|_| panic!("{path}: no dimension labels"));
            let v: Vec<VarLenAscii> = a.read_raw().unwrap();
            v.iter().map(|s| s.as_str().to_owned()).collect()
        };
        assert_eq!(labels.len(), ndim, "{path}: labels {labels:?}");
        assert!(
            labels.iter().all(|l| !l.is_empty()),
            "{path}: labels {labels:?}"
        );
        seen.push((path.clone(), labels));
    }
    assert!(
        missing.is_empty(),
        "{}: datasets without units or description:\n{}",
        file.display(),
        missing.join("\n")
    );
    seen
}

fn attr_names(f: &hdf5::File, path: &str) -> Vec<String> {
    f.dataset(path).unwrap().attr_names().unwrap()
}

fn labels<'a>(seen: &'a [(String, Vec<String>)], path: &str) -> &'a [String] {
    &seen
        .iter()
        .find(|(p, _)| p == path)
        .unwrap_or_else(|| panic!("{path} not written"))
        .1
}

#[test]
fn every_dataset_of_a_scene_result_has_units_a_description_and_axes() {
    let dir = tempfile::tempdir().unwrap();
    let report = tiny()
        .realisations(2)
        .paper(0.8)
        .outputs(&["brdf", "btdf", "tile"])
        .measurements(&["45/0", "d/8 SCI"])
        .raw(
            "appearance.baseline",
            r#"["kubelka-munk", "adding-doubling"]"#,
        )
        .output(dir.path(), "r")
        .run(dir.path());
    let seen = check_file(&report.result_path);
    let names: Vec<&str> = seen.iter().map(|(p, _)| p.as_str()).collect();
    // The walk reached every part of the file.
    for p in [
        "/config",
        "/plan",
        "/summary",
        "/picture_png",
        "/geometry/centers_nm",
        "/geometry/statistics/rdf",
        "/realisations/seed",
        "/solves/0000/orders_mn",
        "/appearance/brdf_table_se",
        "/appearance/btdf_diffuse",
        "/appearance/r_dd_up",
        "/appearance/t_d",
        "/appearance/brdf_total",
        "/appearance/tile_lab_realisations",
        "/appearance/tile_png",
        "/appearance/measured/45_0/spectrum",
        "/appearance/measured/d8_sci/de00_se",
        "/appearance/baseline/kubelka-munk/45_0/de00_to_wave",
        "/appearance/baseline/kubelka-munk/d8_sci/reflectance_factor",
        "/appearance/baseline/adding-doubling/45_0/lab",
        "/appearance/baseline/adding-doubling/d8_sci/reflectance_factor",
    ] {
        assert!(names.contains(&p), "{p} missing from {names:?}");
    }
    assert_eq!(
        labels(&seen, "/appearance/brdf_table"),
        ["wavelength_nm", "illumination_deg", "sy", "sx"]
    );
    assert_eq!(
        labels(&seen, "/appearance/tile_srgb8"),
        ["viewing_deg", "tile_column", "rgb"]
    );
    assert_eq!(labels(&seen, "/solves/0000/orders_mn"), ["order", "mn"]);
    let f = inksim::output::h5::open(&report.result_path).unwrap();
    let units = |p: &str| str_attr(&f.dataset(p).unwrap(), "units").unwrap();
    assert_eq!(units("/appearance/wavelengths_nm"), "nm");
    assert_eq!(units("/appearance/brdf_diffuse_se"), "sr-1");
    assert_eq!(units("/solves/0001/orders_theta_deg"), "deg");
    assert_eq!(units("/config"), "");
    // The order convention stays with the order indices.
    let d = str_attr(&f.dataset("/solves/0000/orders_mn").unwrap(), "description").unwrap();
    assert!(d.contains("κ = κ_inc + 2π (m/Lx, n/Ly)"), "{d}");
    // Coordinates are dimension scales, attached where their axis is used.
    for scale in [
        "/appearance/wavelengths_nm",
        "/appearance/viewing_deg",
        "/geometry/species_names",
    ] {
        let a = attr_names(&f, scale);
        for name in ["CLASS", "NAME", "REFERENCE_LIST"] {
            assert!(a.contains(&name.to_string()), "{scale}: {a:?}");
        }
    }
    for p in [
        "/appearance/brdf_total",
        "/appearance/measured/d8_sci/spectrum",
        "/appearance/baseline/kubelka-munk/d8_sci/reflectance_factor",
        "/appearance/baseline/adding-doubling/d8_sci/reflectance_factor",
        "/geometry/statistics/count",
    ] {
        assert!(
            attr_names(&f, p).contains(&"DIMENSION_LIST".to_string()),
            "{p}"
        );
    }
}

#[test]
fn every_dataset_of_a_study_summary_has_units_a_description_and_axes() {
    let dir = tempfile::tempdir().unwrap();
    let study = StudyToml::new("t", 5, "out", &tiny().polar_deg(&[0.0]).realisations(1))
        .axis(
            "pigment",
            "pigment.0.material.builtin",
            r#"["red", "yellow"]"#,
        )
        .axis("d", "pigment.*.diameter_nm", "[100.0, 150.0]");
    let sweep = dir.path().join("sweep.toml");
    std::fs::write(&sweep, study.toml()).unwrap();
    for cmd in ["run", "merge"] {
        let (ok, _, err) = inksim_in(dir.path(), &[cmd, sweep.to_str().unwrap()]);
        assert!(ok, "{cmd}: {err}");
    }
    let summary = dir.path().join("out/summary.h5");
    let seen = check_file(&summary);
    let names: Vec<&str> = seen.iter().map(|(p, _)| p.as_str()).collect();
    for p in [
        "/name",
        "/id",
        "/seed",
        "/mean_reflectance",
        "/natural_srgb8",
        "/has_colour",
        "/labels/pigment",
        "/values/d/pigment.*.diameter_nm",
        "/colour/45_0/lab",
        "/colour/45_0/de00_se",
    ] {
        assert!(names.contains(&p), "{p} missing from {names:?}");
    }
    assert_eq!(labels(&seen, "/colour/45_0/lch"), ["variant", "lch"]);
    let f = inksim::output::h5::open(&summary).unwrap();
    let units = |p: &str| str_attr(&f.dataset(p).unwrap(), "units").unwrap();
    assert_eq!(units("/values/d/pigment.*.diameter_nm"), "nm");
    assert_eq!(units("/mean_reflectance"), "1");
    assert_eq!(units("/labels/d"), "");
    // The variant names are the scale of every per-variant table.
    assert!(attr_names(&f, "/name").contains(&"REFERENCE_LIST".to_string()));
    assert!(attr_names(&f, "/colour/45_0/xyz").contains(&"DIMENSION_LIST".to_string()));
}

#[test]
fn every_dataset_of_a_stack_result_has_units_a_description_and_axes() {
    let dir = tempfile::tempdir().unwrap();
    let layer = |name: &str, h: f64| {
        tiny()
            .thickness_nm(h)
            .pigment(PigmentToml::builtin(name).diameter_nm(100.0))
    };
    let report = tiny()
        .realisations(2)
        .outputs(&["tile"])
        .output(dir.path(), "s")
        .stack_of(
            &[layer("yellow", 200.0), layer("blue", 200.0)],
            "incoherent",
        )
        .run(dir.path());
    let seen = check_file(&report.result_path);
    assert_eq!(
        labels(&seen, "/stack/layer1/r_down"),
        ["wavelength_nm", "node", "node_in"]
    );
    assert_eq!(
        labels(&seen, "/appearance/natural"),
        ["wavelength_nm", "viewing_deg"]
    );
    assert_eq!(labels(&seen, "/appearance/measured/45_0/lab"), ["lab"]);
}
