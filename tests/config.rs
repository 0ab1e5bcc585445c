//! Integration tests of the configuration stage: parsing, validation messages,
//! derived values (grid, wavelengths) and material loading.

use inksim::config::*;
use num_complex::Complex64;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

mod common;
use common::scene::{PigmentToml, SceneToml};

/// A small valid scene (one red pigment in a 1 µm layer); tests change one
/// thing.
fn base() -> SceneToml {
    SceneToml::grains()
}

/// A second pigment beside the red one.
fn second_pigment() -> PigmentToml {
    PigmentToml::builtin("yellow").pvc(0.2).diameter_nm(200.0)
}

/// The base scene as a user would write it, for the tests where the text
/// itself is the point.
const BY_HAND: &str = r#"
[layer]
thickness_nm = 1000.0
fragment_nm = [2000.0, 2000.0]

[[pigment]]
name = "red"
material = { builtin = "red" }
pvc = 0.2
diameter_nm = 200.0

[grid]
cell_nm = 25.0

[illumination]
wavelengths_nm = [450.0, 550.0, 650.0]
polar_deg = [0.0, 30.0]
"#;

fn parse_text(text: &str) -> Result<Scene, ConfigError> {
    parse_scene(Path::new("cfg/test.toml"), text)
}

fn parse(scene: &SceneToml) -> Result<Scene, ConfigError> {
    parse_text(&scene.toml())
}

/// Parses `scene`, expects `ConfigError::Invalid`, returns (key, full message).
fn invalid(scene: &SceneToml) -> (String, String) {
    match parse(scene) {
        Err(e @ ConfigError::Invalid { .. }) => {
            let shown = e.to_string();
            assert!(shown.starts_with("cfg/test.toml: "), "{shown}");
            assert!(!shown.contains('\n'), "not one line: {shown}");
            let ConfigError::Invalid { key, .. } = e else {
                unreachable!()
            };
            (key, shown)
        }
        other => panic!("expected Invalid, got {other:?}"),
    }
}

#[test]
fn demo_parses_with_expected_values() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/demo.toml");
    let scene = load_scene(&path).unwrap();
    assert_eq!(scene.seed, 7);
    assert_eq!((scene.grid.nx, scene.grid.ny, scene.grid.nz), (80, 80, 100));
    assert_eq!(scene.layer.thickness_nm, 1000.0);
    assert_eq!(
        (scene.layer.fragment_x_nm, scene.layer.fragment_y_nm),
        (2000.0, 2000.0)
    );
    assert_eq!(scene.layer.binder_index, 1.558);
    assert_eq!(scene.species.len(), 1);
    assert_eq!(scene.species[0].name, "red");
    assert_eq!(
        scene.species[0].material.source,
        MaterialSource::Builtin("red".into())
    );
    assert_eq!(scene.species[0].diameter_nm, 200.0);
    assert_eq!(scene.total_pvc(), 0.2);
    assert_eq!(scene.wavelengths_nm, [450.0, 550.0, 650.0]);
    let polar: Vec<f64> = scene.incidence.iter().map(|i| i.polar_deg).collect();
    assert_eq!(polar, [0.0, 30.0, 60.0]);
    assert!(scene.incidence.iter().all(|i| i.azimuth_deg == 0.0));
    assert_eq!(scene.solver.method, Method::Auto);
    assert_eq!(scene.solver.tolerance, 1e-6);
    assert_eq!(scene.solver.max_iterations, 5000);
    assert_eq!(scene.output.dir, PathBuf::from("runs/demo"));
    assert_eq!(scene.output.name, "demo");
    assert_eq!(scene.path(), path.as_path());
    assert_eq!(
        scene.provenance.text,
        std::fs::read_to_string(&path).unwrap()
    );
    let h = &scene.provenance.input_hash;
    assert_eq!(h.len(), 64);
    assert!(h
        .chars()
        .all(|c| c.is_ascii_hexdigit() && !c.is_ascii_uppercase()));
}

/// The base scene as a user would write it: the builder that the tests
/// here vary emits exactly these keys and values, and its edits (a key
/// replaced, a pigment added, a key dropped) land where they are meant to.
#[test]
fn scene_builder_writes_what_a_user_would() {
    let by_hand: toml::Table = BY_HAND.parse().unwrap();
    assert_eq!(base().table(), &by_hand);
    let edited: toml::Table = base()
        .grid_n([8, 8, 4])
        .add_pigment(second_pigment())
        .without("illumination.polar_deg")
        .toml()
        .parse()
        .unwrap();
    assert_eq!(edited["grid"].to_string(), "{ nx = 8, ny = 8, nz = 4 }");
    let pigments = edited["pigment"].as_array().unwrap();
    assert_eq!(pigments.len(), 2);
    assert_eq!(pigments[0], by_hand["pigment"][0]);
    assert_eq!(pigments[1]["material"]["builtin"].as_str(), Some("yellow"));
    assert!(!edited["illumination"]
        .as_table()
        .unwrap()
        .contains_key("polar_deg"));
}

#[test]
fn defaults_apply() {
    let s = parse(&base()).unwrap();
    assert_eq!(s.seed, 1);
    assert_eq!(s.layer.binder_index, 1.558);
    assert_eq!(s.solver.method, Method::Auto);
    assert_eq!(s.solver.tolerance, 1e-6);
    assert_eq!(s.solver.max_iterations, 5000);
    assert_eq!(s.output.dir, Path::new("runs").join("test"));
    assert_eq!(s.output.name, "test");
    // azimuth default and one incidence per polar angle
    assert_eq!(
        s.incidence,
        [
            Incidence {
                polar_deg: 0.0,
                azimuth_deg: 0.0
            },
            Incidence {
                polar_deg: 30.0,
                azimuth_deg: 0.0
            }
        ]
    );
}

#[test]
fn solver_methods_parse() {
    for (word, want) in [
        ("born", Method::Born),
        ("time-marching", Method::TimeMarching),
        ("auto", Method::Auto),
    ] {
        let s = parse(&base().method(word).max_iterations(7)).unwrap();
        assert_eq!(s.solver.method, want);
        assert_eq!(s.solver.max_iterations, 7);
    }
    let err = parse(&base().method("cg")).unwrap_err();
    assert!(matches!(err, ConfigError::Parse { .. }), "{err}");
    assert!(err.to_string().contains("cg"), "{err}");
}

#[test]
fn solver_precision_parses_and_limits_the_tolerance() {
    assert_eq!(parse(&base()).unwrap().solver.precision, Precision::F64);
    for (word, want) in [("f64", Precision::F64), ("f32", Precision::F32)] {
        let s = parse(&base().precision(word)).unwrap();
        assert_eq!(s.solver.precision, want);
    }
    // f32 fields cannot hold a residual below 1e-6; f64 can.
    let tight = |p| base().precision(p).tolerance(1e-9);
    assert!(parse(&tight("f64")).is_ok());
    let (key, msg) = invalid(&tight("f32"));
    assert_eq!(key, "solver.tolerance");
    assert!(msg.contains("f32") && msg.contains("1e-6"), "{msg}");
    let err = parse(&base().precision("f16")).unwrap_err();
    assert!(err.to_string().contains("f16"), "{err}");
}

#[test]
fn solver_background_parses_and_names_the_allowed_values() {
    assert_eq!(
        parse(&base()).unwrap().solver.background,
        Background::DEFAULT
    );
    for (word, want) in [("binder", Background::Binder), ("mean", Background::Mean)] {
        let s = parse(&base().set("solver.background", word)).unwrap();
        assert_eq!(s.solver.background, want);
        assert_eq!(want.name(), word);
    }
    let err = parse(&base().set("solver.background", "vacuum")).unwrap_err();
    assert!(matches!(err, ConfigError::Parse { .. }), "{err}");
    let shown = err.to_string();
    assert!(
        shown.contains("vacuum") && shown.contains("binder") && shown.contains("mean"),
        "{shown}"
    );
}

#[test]
fn effective_medium_tolerance_defaults_and_is_limited() {
    assert_eq!(
        parse(&base()).unwrap().solver.effective_medium_tolerance,
        1e-3
    );
    for v in [0.0, 0.02, 0.1] {
        let s = parse(&base().effective_medium_tolerance(v)).unwrap();
        assert_eq!(s.solver.effective_medium_tolerance, v);
    }
    for v in [-1e-3, 0.2, f64::NAN] {
        let (key, msg) = invalid(&base().effective_medium_tolerance(v));
        assert_eq!(key, "solver.effective_medium_tolerance");
        assert!(msg.contains("[0, 0.1]"), "{msg}");
    }
}

#[test]
fn energy_balance_limit_defaults_and_is_limited() {
    assert_eq!(parse(&base()).unwrap().solver.energy_balance_limit, 1e-4);
    for v in [1e-8, 1e-3, 1e-2] {
        let s = parse(&base().energy_balance_limit(v)).unwrap();
        assert_eq!(s.solver.energy_balance_limit, v);
    }
    for v in [0.0, -1e-4, 0.05, f64::NAN] {
        let (key, msg) = invalid(&base().energy_balance_limit(v));
        assert_eq!(key, "solver.energy_balance_limit");
        assert!(msg.contains("[1e-8, 1e-2]"), "{msg}");
    }
}

#[test]
fn unknown_key_is_named_on_one_line() {
    // The literal text is the point: the typo sits on line 4, column 1.
    let text = BY_HAND.replacen(
        "thickness_nm = 1000.0\n",
        "thickness_nm = 1000.0\nthicknes_nm = 5.0\n",
        1,
    );
    let err = parse_text(&text).unwrap_err();
    assert!(matches!(err, ConfigError::Parse { .. }), "{err:?}");
    let shown = err.to_string();
    assert!(
        shown.starts_with("cfg/test.toml: line 4, column 1: "),
        "{shown}"
    );
    assert!(shown.contains("unknown field `thicknes_nm`"), "{shown}");
    assert!(!shown.contains('\n'), "{shown}");
}

#[test]
fn negative_thickness_names_key_and_range() {
    let (key, shown) = invalid(&base().thickness_nm(-5.0));
    assert_eq!(key, "layer.thickness_nm");
    assert!(shown.contains("(0, 20000] nm"), "{shown}");
    assert!(shown.contains("got -5"), "{shown}");
}

#[test]
fn other_ranges_are_checked() {
    let cases = [
        (base().binder_index(0.9), "layer.binder_index"),
        (
            base().raw("layer.fragment_nm", "[2000.0, 0.0]"),
            "layer.fragment_nm[1]",
        ),
        (
            base().raw("layer.fragment_nm", "[2000.0]"),
            "layer.fragment_nm",
        ),
        (base().pvc(-0.1), "pigment[0].pvc"),
        // 0 is a pigment left out, but one pigment must be present.
        (base().pvc(0.0), "pigment[*].pvc"),
        (base().diameter_nm(1200.0), "pigment[0].diameter_nm"),
        (base().cell_nm(0.0), "grid.cell_nm"),
        (base().cell_nm(0.1), "grid.cell_nm"),
        (base().polar_deg(&[0.0, 90.0]), "illumination.polar_deg[1]"),
        (base().polar_deg(&[30.0, 0.0]), "illumination.polar_deg[1]"),
        (base().polar_deg(&[]), "illumination.polar_deg"),
        (
            base().polar_deg(&[0.0]).azimuth_deg(400.0),
            "illumination.azimuth_deg",
        ),
        (
            base().wavelengths_nm(&[450.0, 450.0]),
            "illumination.wavelengths_nm[1]",
        ),
        (base().wavelengths_nm(&[]), "illumination.wavelengths_nm"),
        (base().seed(-1), "seed"),
        (base().tolerance(0.5), "solver.tolerance"),
        (base().max_iterations(0), "solver.max_iterations"),
        (base().output_name("a/b"), "output.name"),
        (base().set("output.dir", ""), "output.dir"),
        (
            base().set("pigment.0.material.builtin", "purple"),
            "pigment[0].material.builtin",
        ),
    ];
    for (text, want) in cases {
        let (key, shown) = invalid(&text);
        assert_eq!(key, want, "{shown}");
        assert!(shown.contains(&format!("key `{want}`: ")), "{shown}");
    }
}

#[test]
fn pvc_above_packer_limit_is_rejected() {
    let text = base().pvc(0.4).add_pigment(second_pigment().pvc(0.4));
    let (key, shown) = invalid(&text);
    assert!(key.starts_with("pigment") && key.ends_with("pvc"), "{key}");
    assert!(shown.contains("0.55"), "{shown}");
    assert_eq!(MAX_PVC, 0.55);

    // A single species above the limit, too.
    let (key, _) = invalid(&base().pvc(0.56));
    assert!(key.starts_with("pigment") && key.ends_with("pvc"), "{key}");

    // Exactly at the limit (0.35 + 0.2 = 0.5499999999999999 or so in f64) passes.
    let text = base().pvc(0.35).add_pigment(second_pigment());
    let s = parse(&text).unwrap();
    assert_eq!(s.species.len(), 2);
    assert!((s.total_pvc() - 0.55).abs() < 1e-15);
}

#[test]
fn grain_shapes_and_orientation_are_read_and_checked() {
    let rice = base()
        .raw(
            "pigment.0.shape",
            "{ kind = \"rice\", aspect = 4.0, spheres = 9 }",
        )
        .set("pigment.0.orientation", "in-plane")
        .set("pigment.0.alignment_field", 0.5);
    let s = parse(&rice).unwrap();
    assert_eq!(
        s.species[0].shape,
        GrainShape::Rice {
            aspect: 4.0,
            spheres: 9
        }
    );
    assert_eq!(s.species[0].orientation, GrainOrientation::InPlane);
    assert_eq!(s.species[0].alignment_field, 0.5);
    // Defaults: a cylinder of length 6 radii (aspect 3) with 5 spheres.
    let cyl = base().raw("pigment.0.shape", "{ kind = \"cylinder\" }");
    assert_eq!(
        parse(&cyl).unwrap().species[0].shape,
        GrainShape::Cylinder {
            aspect: 3.0,
            spheres: 5
        }
    );
    // Spheres by default, random orientation, no field.
    let s = parse(&base()).unwrap();
    assert_eq!(
        (s.species[0].shape, s.species[0].orientation),
        (GrainShape::Sphere, GrainOrientation::Random)
    );
    // Errors name the key.
    let shape = |text| base().raw("pigment.0.shape", text);
    let bad = [
        (shape("{ kind = \"banana\" }"), "pigment[0].shape"),
        (
            shape("{ kind = \"rice\", spheres = 1 }"),
            "pigment[0].shape.spheres",
        ),
        (
            shape("{ kind = \"cylinder\", aspect = 8.0, spheres = 4 }"),
            "pigment[0].shape.spheres",
        ),
        (
            shape("{ kind = \"rice\", aspect = 0.5 }"),
            "pigment[0].shape.aspect",
        ),
        (
            shape("{ kind = \"rice\" }").set("pigment.0.alignment_field", 1.0),
            "pigment[0].alignment_field",
        ),
        (
            base()
                .set("pigment.0.alignment_field", 1.0)
                .set("pigment.0.orientation", "in-plane"),
            "pigment[0].alignment_field",
        ),
    ];
    for (text, want) in bad {
        let extra = text.table()["pigment"].to_string();
        match parse(&text) {
            Err(ConfigError::Invalid { key, .. }) => assert_eq!(key, want, "{extra}"),
            Err(ConfigError::Parse { message, .. }) => assert!(
                want == "pigment[0].shape" && message.contains("banana"),
                "{message}"
            ),
            other => panic!("{extra}: expected an error, got {other:?}"),
        }
    }
}

#[test]
fn duplicate_pigment_names_are_rejected() {
    let text = base()
        .pvc(0.1)
        .add_pigment(second_pigment().named("red").pvc(0.1));
    let (key, shown) = invalid(&text);
    assert_eq!(key, "pigment[1].name");
    assert!(
        shown.contains("duplicate") && shown.contains("`red`"),
        "{shown}"
    );
    let (key, _) = invalid(&base().set("pigment.0.name", " "));
    assert_eq!(key, "pigment[0].name");
}

#[test]
fn missing_pigments_are_rejected() {
    let (key, _) = invalid(&base().without("pigment"));
    assert_eq!(key, "pigment");
}

#[test]
fn wavelength_outside_material_range_is_rejected() {
    let (key, shown) = invalid(&base().wavelengths_nm(&[350.0, 450.0]));
    assert_eq!(key, "illumination.wavelengths_nm");
    assert!(shown.contains("350 nm"), "{shown}");
    assert!(shown.contains("`red`"), "{shown}");
    assert!(shown.contains("[380, 780] nm"), "{shown}");

    let (key, shown) = invalid(&base().wavelength_range_nm(400.0, 800.0, 100.0));
    assert_eq!(key, "illumination.wavelength_range_nm");
    assert!(shown.contains("800 nm"), "{shown}");
}

#[test]
fn grid_forms() {
    // both
    let (key, shown) = invalid(&base().set("grid.nx", 80));
    assert_eq!(key, "grid");
    assert!(shown.contains("not both"), "{shown}");
    // neither
    let (key, _) = invalid(&base().set("grid", toml::Table::new()));
    assert_eq!(key, "grid");
    // incomplete explicit form
    let (key, _) = invalid(&base().grid_n([80, 80, 1]).without("grid.nz"));
    assert_eq!(key, "grid.nz");
    // nx must be FFT-friendly
    let (key, shown) = invalid(&base().grid_n([7, 8, 10]));
    assert_eq!(key, "grid.nx");
    assert!(
        shown.contains("2^a 3^b 5^c") && shown.contains("8"),
        "{shown}"
    );
    let (key, _) = invalid(&base().grid_n([8, 8, 1]));
    assert_eq!(key, "grid.nz");
    let (key, _) = invalid(&base().grid_n([8192, 8, 2]));
    assert_eq!(key, "grid.nx");
    // valid explicit form; nz needs no factorisation
    let g = parse(&base().grid_n([90, 1, 7])).unwrap().grid;
    assert_eq!((g.nx, g.ny, g.nz), (90, 1, 7));
    // from a cell: 2000/30 = 66.7 -> 67 -> 72 = 2^3 3^2; z cell defaults to 10 nm -> 100
    let g = parse(&base().cell_nm(30.0)).unwrap().grid;
    assert_eq!((g.nx, g.ny, g.nz), (72, 72, 100));
    // explicit z cell: 1000/30 -> 34
    let g = parse(&base().cell_nm(30.0).z_cell_nm(30.0)).unwrap().grid;
    assert_eq!((g.nx, g.ny, g.nz), (72, 72, 34));
    // z_cell_nm only goes with cell_nm
    let (key, _) = invalid(&base().grid_n([8, 8, 4]).z_cell_nm(5.0));
    assert_eq!(key, "grid.z_cell_nm");
    // rounding noise does not add a cell: 1.1/0.1 = 11.000000000000002 in f64
    let text = base()
        .thickness_nm(1.1)
        .fragment_nm(1.1)
        .diameter_nm(1.0)
        .cell_nm(0.1);
    let g = parse(&text).unwrap().grid;
    assert_eq!((g.nx, g.ny, g.nz), (12, 12, 11));
}

#[test]
fn wavelength_range_expansion() {
    let range = |start, stop, step| {
        parse(&base().wavelength_range_nm(start, stop, step)).map(|s| s.wavelengths_nm)
    };
    assert_eq!(
        range(400.0, 700.0, 50.0).unwrap(),
        [400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0]
    );
    // stop off the step grid is not included
    assert_eq!(
        range(400.0, 690.0, 50.0).unwrap(),
        [400.0, 450.0, 500.0, 550.0, 600.0, 650.0]
    );
    assert_eq!(range(500.0, 500.0, 10.0).unwrap(), [500.0]);
    // 0.1 is inexact in binary; stop is still included, exactly
    let w = range(400.0, 401.0, 0.1).unwrap();
    assert_eq!(w.len(), 11);
    assert_eq!(w[10], 401.0);
    assert!(range(500.0, 400.0, 10.0).is_err());
    assert!(range(400.0, 500.0, 0.0).is_err());
    // both forms at once
    let text = base().wavelengths_nm(&[450.0]).raw(
        "illumination.wavelength_range_nm",
        "{ start = 400.0, stop = 700.0, step = 50.0 }",
    );
    let (key, _) = invalid(&text);
    assert_eq!(key, "illumination");
}

/// Writes `config.toml` (the base scene with a CSV pigment) and `data/ink.csv` into a
/// temporary folder; returns the folder and the config path.
fn csv_scene(csv: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("data")).unwrap();
    std::fs::write(dir.path().join("data/ink.csv"), csv).unwrap();
    let text = base().raw("pigment.0.material", "{ csv = \"data/ink.csv\" }");
    let cfg = dir.path().join("config.toml");
    std::fs::write(&cfg, text.toml()).unwrap();
    (dir, cfg)
}

const INK_CSV: &str = "# measured ink\nwavelength_nm,n,k\n400,1.0,0.0\n500,2.0,0.5\n700,1.5,0.1\n";

#[test]
fn csv_material_loads_relative_to_config_and_interpolates() {
    let (dir, cfg) = csv_scene(INK_CSV);
    let scene = load_scene(&cfg).unwrap();
    let m = &scene.species[0].material;
    assert_eq!(m.name, "ink");
    assert_eq!(
        m.source,
        MaterialSource::Csv(dir.path().join("data/ink.csv"))
    );
    assert_eq!(m.range_nm(), (400.0, 700.0));
    assert_eq!(m.table_bytes(), INK_CSV.as_bytes());
    // midpoints of both intervals, exact in binary arithmetic
    assert_eq!(m.index_at(450.0), Some(Complex64::new(1.5, 0.25)));
    assert_eq!(m.index_at(600.0), Some(Complex64::new(1.75, 0.3)));
    assert_eq!(m.index_at(500.0), Some(Complex64::new(2.0, 0.5)));
    assert_eq!(m.index_at(700.0), Some(Complex64::new(1.5, 0.1)));
    assert_eq!(m.index_at(399.0), None);
    assert_eq!(m.index_at(701.0), None);
    // quarter point
    let q = m.index_at(425.0).unwrap();
    assert_eq!(q, Complex64::new(1.25, 0.125));
    // output defaults come from the config file stem
    assert_eq!(scene.output.name, "config");
}

#[test]
fn bad_csv_error_names_file_and_line() {
    let csv = "# measured ink\nwavelength_nm,n,k\n400,1.0,0.0\n500,2.0,0.5\n450,1.5,0.1\n";
    let (_dir, cfg) = csv_scene(csv);
    let err = load_scene(&cfg).unwrap_err();
    assert!(matches!(err, ConfigError::Material { .. }), "{err:?}");
    let shown = err.to_string();
    assert!(shown.starts_with(&cfg.display().to_string()), "{shown}");
    assert!(shown.contains("ink.csv: line 5"), "{shown}");
    assert!(shown.contains("strictly increasing"), "{shown}");
    assert!(!shown.contains('\n'), "{shown}");

    // a missing file names the resolved path
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("c.toml");
    let text = base().raw("pigment.0.material", "{ csv = \"nope.csv\" }");
    std::fs::write(&cfg, text.toml()).unwrap();
    let shown = load_scene(&cfg).unwrap_err().to_string();
    assert!(shown.contains("nope.csv: cannot read"), "{shown}");
}

#[test]
fn a_spreadsheet_table_with_a_byte_order_mark_loads_and_absurd_values_are_refused() {
    // Spreadsheet exports start with a UTF-8 byte-order mark.
    let (_d, cfg) = csv_scene(&format!(
        "\u{feff}{}",
        INK_CSV.replace("# measured ink\n", "")
    ));
    let m = load_scene(&cfg).unwrap().species[0].material.clone();
    assert_eq!(m.wavelengths_nm(), [400.0, 500.0, 700.0]);
    for (bad, said) in [
        ("500,2.0,1e308", "line 4: k must be in [0, 10], got 1e308"),
        ("500,0,0.5", "line 4: n must be in (0, 10], got 0"),
        ("500,2.0,-0.5", "line 4: k must be in [0, 10], got -0.5"),
    ] {
        let (_d, cfg) = csv_scene(&INK_CSV.replace("500,2.0,0.5", bad));
        let e = load_scene(&cfg).unwrap_err().to_string();
        assert!(e.contains("data/ink.csv") && e.contains(said), "{e}");
    }
}

#[test]
fn hash_covers_config_and_tables() {
    let (_d1, cfg1) = csv_scene(INK_CSV);
    let (_d2, cfg2) = csv_scene(INK_CSV);
    let (_d3, cfg3) = csv_scene(&INK_CSV.replace("2.0,0.5", "2.0,0.6"));
    let h1 = load_scene(&cfg1).unwrap().provenance.input_hash;
    let h2 = load_scene(&cfg2).unwrap().provenance.input_hash;
    let h3 = load_scene(&cfg3).unwrap().provenance.input_hash;
    assert_eq!(h1, h2, "same inputs, same hash");
    assert_ne!(h1, h3, "changed table, changed hash");
    // what decides results changes the hash; comments, key order and where
    // results go do not
    let text = base().toml();
    let hash = |t: &str| parse_text(t).unwrap().provenance.input_hash;
    let a = hash(&text);
    assert_eq!(a, hash(&format!("# a note\n{text}\n# comment\n")));
    assert_eq!(
        a,
        hash(&format!(
            "{text}\n[output]\ndir = \"elsewhere\"\nname = \"x\"\n"
        ))
    );
    assert_ne!(a, hash(&base().seed(2).toml()));
    assert_ne!(a, hash(&base().thickness_nm(401.0).toml()));
    // independent reference: sha256(canonical tables without [output] ++ red.csv)
    let canonical = |t: &str| {
        let mut t: toml::Table = t.parse().unwrap();
        t.remove("output");
        toml::to_string(&t).unwrap()
    };
    let red_csv =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("data/pigments/red.csv")).unwrap();
    let mut h = Sha256::new();
    h.update(canonical(&text).as_bytes());
    h.update(&red_csv);
    let want: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    assert_eq!(a, want);
    // and for a CSV material: sha256(canonical config ++ file bytes)
    let mut h = Sha256::new();
    h.update(canonical(&std::fs::read_to_string(&cfg1).unwrap()).as_bytes());
    h.update(INK_CSV.as_bytes());
    let want: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    assert_eq!(h1, want);
}

#[test]
fn read_and_parse_errors() {
    let missing = Path::new("/nonexistent/dir/scene.toml");
    let err = load_scene(missing).unwrap_err();
    assert!(matches!(err, ConfigError::Read { .. }));
    assert!(err
        .to_string()
        .starts_with("/nonexistent/dir/scene.toml: cannot read"));
    // malformed TOML and wrong types are parse errors on one line
    let thick = base().set("layer.thickness_nm", "thick").toml();
    for text in ["[layer\n", &thick] {
        let shown = parse_text(text).unwrap_err().to_string();
        assert!(shown.starts_with("cfg/test.toml: line "), "{shown}");
        assert!(!shown.contains('\n'), "{shown}");
    }
}

#[test]
fn size_agglomeration_and_relief_keys() {
    let pig = |key: &str, text: &str| base().raw(&format!("pigment.0.{key}"), text);
    let text = pig("size", "{ kind = \"log-normal\", sigma = 0.2 }")
        .raw("pigment.0.agglomeration", "{ cluster_size = 8 }")
        .relief_fraction(0.3);
    let s = parse(&text).unwrap();
    assert_eq!(s.species[0].size, GrainSize::LogNormal { sigma: 0.2 });
    assert_eq!(s.species[0].cluster_size, 8);
    assert_eq!(s.layer.relief_fraction, 0.3);
    let s = parse(&pig("size", "{ kind = \"normal\", sigma = 0.1 }")).unwrap();
    assert_eq!(s.species[0].size, GrainSize::Normal { sigma: 0.1 });
    // Defaults: fixed size, no clusters, flat top.
    let s = parse(&base()).unwrap();
    assert_eq!(s.species[0].size, GrainSize::Fixed);
    assert_eq!(s.species[0].cluster_size, 1);
    assert_eq!(s.layer.relief_fraction, 0.0);
    // The limits are the geometry stage's.
    assert_eq!(
        MAX_NORMAL_SIGMA,
        inksim::geometry::SizeDistribution::MAX_NORMAL_SIGMA
    );
    assert_eq!(
        MAX_LOG_NORMAL_SIGMA,
        inksim::geometry::SizeDistribution::MAX_LOG_NORMAL_SIGMA
    );
    assert_eq!(MAX_CLUSTER_SIZE, inksim::geometry::MAX_CLUSTER_SIZE);
    assert_eq!(MAX_RELIEF_FRACTION, inksim::geometry::MAX_RELIEF_FRACTION);

    for (text, want, range) in [
        (
            pig("size", "{ kind = \"normal\", sigma = 0.4 }"),
            "pigment[0].size.sigma",
            "0.3",
        ),
        (
            pig("size", "{ kind = \"log-normal\", sigma = -0.1 }"),
            "pigment[0].size.sigma",
            "0.5",
        ),
        (
            pig("agglomeration", "{ cluster_size = 0 }"),
            "pigment[0].agglomeration.cluster_size",
            "10000",
        ),
        (base().relief_fraction(0.7), "layer.relief_fraction", "0.5"),
        // Largest draw (3 σ) thicker than the 1000 nm layer: grain larger
        // than the layer.
        (
            pig("size", "{ kind = \"log-normal\", sigma = 0.3 }").diameter_nm(600.0),
            "pigment[0].size",
            "1000",
        ),
    ] {
        let (key, shown) = invalid(&text);
        assert_eq!(key, want, "{shown}");
        assert!(shown.contains(range), "{shown}");
    }
    // Unknown keys and kinds are parse errors naming them.
    for (key, extra, word) in [
        ("size", "{ kind = \"uniform\" }", "uniform"),
        (
            "size",
            "{ kind = \"normal\", sigma = 0.1, mean = 3 }",
            "mean",
        ),
        ("agglomeration", "{ size = 3 }", "size"),
    ] {
        match parse(&pig(key, extra)) {
            Err(ConfigError::Parse { message, .. }) => assert!(message.contains(word), "{message}"),
            other => panic!("{key} = {extra}: expected a parse error, got {other:?}"),
        }
    }
}

#[test]
fn equilibrate_sweeps_key() {
    let text = base().equilibrate_sweeps(200);
    assert_eq!(parse(&text).unwrap().layer.equilibrate_sweeps, 200);
    assert_eq!(parse(&base()).unwrap().layer.equilibrate_sweeps, 0);
    assert_eq!(
        inksim::config::MAX_EQUILIBRATE_SWEEPS,
        inksim::geometry::mc::MAX_SWEEPS
    );
    for bad in [-1, 100001] {
        let (key, shown) = invalid(&base().equilibrate_sweeps(bad));
        assert_eq!(key, "layer.equilibrate_sweeps", "{shown}");
        assert!(shown.contains("100000"), "{shown}");
    }
}

#[test]
fn colour_conditions_and_measurement_geometries() {
    let s = parse(&base()).unwrap();
    assert_eq!(s.appearance.illuminant, Illuminant::D50);
    assert_eq!(s.appearance.observer, StandardObserver::TwoDegree);
    assert_eq!(s.appearance.measurements, Measurement::ALL.to_vec());
    let text = base()
        .illuminant("a")
        .observer_deg(10)
        .measurements(&["d/8 SCE"]);
    let s = parse(&text).unwrap();
    assert_eq!(s.appearance.illuminant, Illuminant::A);
    assert_eq!(s.appearance.observer, StandardObserver::TenDegree);
    assert_eq!(s.appearance.measurements, [Measurement::DiffuseEightSce]);
    let s = parse(&base().measurements(&[])).unwrap();
    assert!(s.appearance.measurements.is_empty());
    for (text, key, says) in [
        (
            base().illuminant("F2"),
            "appearance.illuminant",
            "allowed: \"D50\", \"D65\", \"A\"",
        ),
        (
            base().observer_deg(5),
            "appearance.observer_deg",
            "must be 2 (CIE 1931) or 10 (CIE 1964), got 5",
        ),
        (
            base().measurements(&["0/45"]),
            "appearance.measurements",
            "allowed: \"45/0\", \"d/8 SCI\"",
        ),
        (
            base().measurements(&["45/0", "45/0"]),
            "appearance.measurements",
            "listed twice",
        ),
    ] {
        let (k, shown) = invalid(&text);
        assert_eq!(k, key);
        assert!(shown.contains(says), "{shown}");
    }
}

#[test]
fn a_material_may_be_given_as_its_complex_permittivity() {
    // ε = 2.21 + 0.6i is (1.5 + 0.2i)²; a metal-like ε = −8.91 + 1.8i is
    // (0.3 + 3i)².
    for (eps, n, k) in [("[2.21, 0.6]", 1.5, 0.2), ("[-8.91, 1.8]", 0.3, 3.0)] {
        let s =
            parse(&base().raw("pigment.0.material", &format!("{{ epsilon = {eps} }}"))).unwrap();
        let idx = s.species[0].material.index_at(550.0).unwrap();
        assert!(
            (idx.re - n).abs() < 1e-12 && (idx.im - k).abs() < 1e-12,
            "{eps}: {idx}"
        );
    }
    // A gain medium, a wrong length and an index beyond the limits are refused.
    for (eps, want) in [
        (
            "[2.0, -0.1]",
            "must be in [0, 100] for Im ε (a medium that absorbs or is lossless)",
        ),
        ("[2.0]", "must be [Re ε, Im ε], got 1 values"),
        ("[-100.0, 0.0]", "is outside n in (0, 10], k in [0, 10]"),
    ] {
        let (key, msg) =
            invalid(&base().raw("pigment.0.material", &format!("{{ epsilon = {eps} }}")));
        assert_eq!(key, "pigment[0].material.epsilon", "{msg}");
        assert!(msg.contains(want), "{eps}: {msg}");
    }
}

/// `solver.equation` and `illumination.polarisation` are read; a
/// polarisation needs Maxwell's equation; what Maxwell mode cannot honour
/// yet (stacks; the baselines, computed for natural light, beside one linear
/// polarisation) is refused, naming the key.
#[test]
fn equation_and_polarisation_are_checked() {
    use inksim::config::{Equation, Polarisation};
    let s = parse(&base()).unwrap();
    assert_eq!(s.solver.equation, Equation::Helmholtz);
    assert_eq!(s.solver.polarisation, Polarisation::Unpolarised);
    let s = parse(
        &base()
            .set("solver.equation", "maxwell")
            .set("illumination.polarisation", "p"),
    )
    .unwrap();
    assert_eq!(s.solver.equation, Equation::Maxwell);
    assert_eq!(s.solver.polarisation, Polarisation::P);
    let (key, msg) = invalid(&base().set("illumination.polarisation", "s"));
    assert_eq!(key, "illumination.polarisation");
    assert!(msg.contains("maxwell"), "{msg}");
    let err = parse(&base().set("solver.equation", "vector")).unwrap_err();
    assert!(err.to_string().contains("helmholtz"), "{err}");
    // Beside a Maxwell solve of natural light the baselines are vector ones;
    // beside one linear polarisation they are refused.
    let s = parse(
        &base()
            .set("solver.equation", "maxwell")
            .set("appearance.baseline", "kubelka-munk"),
    )
    .unwrap();
    assert_eq!(
        s.appearance.baseline,
        [inksim::config::Baseline::KubelkaMunk]
    );
    let (key, msg) = invalid(
        &base()
            .set("solver.equation", "maxwell")
            .set("illumination.polarisation", "p")
            .set("appearance.baseline", "kubelka-munk"),
    );
    assert_eq!(key, "appearance.baseline");
    assert!(msg.contains("natural light"), "{msg}");
}

/// `solver.natural_light`: auto by default (random-phase for an ensemble of
/// generated layers, two solves for one realisation); random-phase only for
/// unpolarised light in Maxwell's equations on a random layer.
#[test]
fn natural_light_is_checked() {
    use inksim::config::NaturalLight;
    let maxwell = || base().set("solver.equation", "maxwell");
    let s = parse(&maxwell().realisations(1)).unwrap();
    assert_eq!(s.solver.natural_light, NaturalLight::TwoSolves);
    assert_eq!(s.solver.solves_per_incidence(), 2);
    let s = parse(&maxwell().realisations(4)).unwrap();
    assert!(s.solver.random_phase());
    assert_eq!(s.solver.solves_per_incidence(), 1);
    let s = parse(&maxwell().raw("realisations", "{ target_de00 = 0.5, max = 8 }")).unwrap();
    assert!(s.solver.random_phase());
    let s = parse(
        &maxwell()
            .realisations(4)
            .set("solver.natural_light", "two-solves"),
    )
    .unwrap();
    assert_eq!(s.solver.solves_per_incidence(), 2);
    let s = parse(
        &maxwell()
            .realisations(4)
            .set("illumination.polarisation", "p"),
    )
    .unwrap();
    assert!(!s.solver.random_phase());
    let s = parse(&maxwell().set("solver.natural_light", "random-phase")).unwrap();
    assert!(s.solver.random_phase());
    assert_eq!(s.solver.solves_per_incidence(), 1);
    for scene in [
        base().set("solver.natural_light", "random-phase"),
        maxwell()
            .set("illumination.polarisation", "s")
            .set("solver.natural_light", "random-phase"),
        SceneToml::structure(&[common::scene::PrimitiveToml::slab(0.0, 500.0).index(1.6, 0.0)])
            .set("solver.equation", "maxwell")
            .set("solver.natural_light", "random-phase"),
    ] {
        let (key, msg) = invalid(&scene);
        assert_eq!(key, "solver.natural_light", "{msg}");
    }
    let err = parse(&maxwell().set("solver.natural_light", "alternate")).unwrap_err();
    assert!(err.to_string().contains("random-phase"), "{err}");
}

/// `grid.voxel_permittivity`: auto by default (anisotropic cut voxels in
/// Maxwell, the average in Helmholtz), average anywhere, anisotropic only in
/// Maxwell (refused naming the key and the way out), unknown names listed.
#[test]
fn voxel_permittivity_is_checked() {
    let maxwell = || base().set("solver.equation", "maxwell");
    let s = parse(&base()).unwrap();
    assert_eq!(s.grid.voxel_permittivity, VoxelPermittivity::Auto);
    assert!(!s.grid.voxel_permittivity.anisotropic(s.solver.equation));
    let s = parse(&maxwell()).unwrap();
    assert!(s.grid.voxel_permittivity.anisotropic(s.solver.equation));
    let s = parse(&maxwell().set("grid.voxel_permittivity", "average")).unwrap();
    assert!(!s.grid.voxel_permittivity.anisotropic(s.solver.equation));
    let s = parse(&maxwell().set("grid.voxel_permittivity", "anisotropic")).unwrap();
    assert!(s.grid.voxel_permittivity.anisotropic(s.solver.equation));
    let (key, msg) = invalid(&base().set("grid.voxel_permittivity", "anisotropic"));
    assert_eq!(key, "grid.voxel_permittivity", "{msg}");
    assert!(msg.contains("maxwell"), "{msg}");
    let err = parse(&maxwell().set("grid.voxel_permittivity", "harmonic")).unwrap_err();
    assert!(err.to_string().contains("anisotropic"), "{err}");
}

#[test]
fn a_library_crystal_loads_as_its_orientation_average_and_hashes_both_tables() {
    let scene = base().pigment(PigmentToml::library("hematite").pvc(0.2).diameter_nm(200.0));
    let s = parse(&scene).unwrap();
    let m = &s.species[0].material;
    assert_eq!(m.source, MaterialSource::Library("hematite".into()));
    // Rows of data/materials/hematite-{o,e}.csv at 550 nm (Querry 1985):
    // ε = (2 ε_o + ε_e)/3.
    let (no, ne) = (Complex64::new(3.318, 0.498), Complex64::new(2.927, 0.460));
    let want = (2.0 * no * no + ne * ne) / 3.0;
    let n = m.index_at(550.0).unwrap();
    assert!((n * n - want).norm() < 1e-12, "{n}");
    assert_eq!(m.epsilon_axes_at(550.0), Some((no * no, ne * ne)));
    // The input hash covers the canonical config and both tables' bytes.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/materials");
    let mut tables = std::fs::read(dir.join("hematite-o.csv")).unwrap();
    tables.extend(std::fs::read(dir.join("hematite-e.csv")).unwrap());
    assert_eq!(m.table_bytes(), tables.as_slice());
    let mut t: toml::Table = scene.toml().parse().unwrap();
    t.remove("output");
    let mut h = Sha256::new();
    h.update(toml::to_string(&t).unwrap().as_bytes());
    h.update(&tables);
    let want: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    assert_eq!(s.provenance.input_hash, want);
}

#[test]
fn a_library_material_is_refused_outside_its_range_and_by_unknown_name() {
    let rutile = PigmentToml::library("rutile").pvc(0.2).diameter_nm(200.0);
    let (key, shown) = invalid(
        &base()
            .pigment(rutile.clone())
            .wavelengths_nm(&[420.0, 550.0]),
    );
    assert_eq!(key, "illumination.wavelengths_nm");
    assert!(
        shown.ends_with(
            "wavelength 420 nm is outside the data range [430, 1100] nm of material library \
             `rutile` (pigment `rutile`)"
        ),
        "{shown}"
    );
    assert!(parse(&base().pigment(rutile).wavelengths_nm(&[430.0, 700.0])).is_ok());
    let (key, shown) = invalid(&base().raw("pigment.0.material", "{ library = \"titania\" }"));
    assert_eq!(key, "pigment[0].material.library");
    assert!(
        shown.ends_with(
            "unknown library material `titania`; known: rutile, anatase, zno, calcite, \
                         hematite, cds, soot, amorphous-carbon, aluminium"
        ),
        "{shown}"
    );
}
