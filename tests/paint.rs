//! Effect paints from a config file: `[paint]` checked (errors name the
//! file, the key and the allowed range), run end to end through the
//! library against the closed form of a clear lacquer on a Lambertian
//! ground (and its flop index near 0), and configs/metallic.toml and
//! configs/pearl.toml run by the CLI, exported to CSV, with a metallic's
//! flop index high and above a pearl's and a solid paint's.

use inksim::config::{parse_paint, ConfigError};
use inksim::optics::colour::{self, Observer};
use inksim::optics::flakes::multiangle;
use inksim::output::h5::read_paint;
use std::path::Path;

mod common;
use common::cli::inksim_in;

const CLEAR_ON_WHITE: &str = r#"
[paint]
wavelengths_nm = [400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0]
illuminant = "D65"
observer_deg = 10
ground = { kind = "white", albedo = 0.8 }

[[paint.layer]]
name = "clearcoat"
thickness_um = 30.0
lacquer = { index = [1.5, 0.0] }
"#;

fn parse(text: &str) -> Result<inksim::config::paint::PaintScene, ConfigError> {
    parse_paint(Path::new("cfg/paint.toml"), text)
}

fn metallic_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/configs/metallic.toml"
    ))
    .unwrap()
}

#[test]
fn the_shipped_paints_are_valid() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["metallic", "pearl"] {
        let path = root.join(format!("configs/{name}.toml"));
        let text = std::fs::read_to_string(&path).unwrap();
        let scene = parse_paint(&path, &text).unwrap();
        assert_eq!(scene.layers.len(), 3);
        assert!(scene.layers[1].flakes.is_some(), "{name}");
        assert_eq!(scene.wavelengths_nm.len(), 31);
        assert_eq!(scene.provenance.input_hash.len(), 64);
    }
}

#[test]
fn a_misspelt_key_is_refused_with_its_line() {
    let text = metallic_text().replace("orientation_sd_deg", "orientation_sd");
    let e = parse(&text).unwrap_err().to_string();
    assert!(e.starts_with("cfg/paint.toml: line "), "{e}");
    assert!(e.contains("unknown field `orientation_sd`"), "{e}");
}

#[test]
fn values_out_of_range_name_the_key_and_the_range() {
    let cases = [
        (
            "orientation_sd_deg = 10.0",
            "orientation_sd_deg = 60.0",
            "key `paint.layer[1].flakes.orientation_sd_deg`: must be in [0, 45] degrees, got 60",
        ),
        (
            "volume_fraction = 0.02",
            "volume_fraction = 0.5",
            "key `paint.layer[1].flakes.volume_fraction`: must be in (0, 0.3], got 0.5",
        ),
        (
            "name = \"clearcoat\"\nthickness_um = 40.0",
            "name = \"clearcoat\"\nthickness_um = -1.0",
            "key `paint.layer[0].thickness_um`: must be in (0, 1000] µm, got -1",
        ),
        (
            "viewing_distance_mm = 500.0",
            "viewing_distance_mm = 0.0",
            "key `paint.sparkle.viewing_distance_mm`: must be in (0, 100000] mm, got 0",
        ),
        (
            "thickness_nm = 200.0, thickness_sd_nm = 40.0",
            "thickness_nm = 200.0, thickness_sd_nm = 150.0",
            "key `paint.layer[1].flakes.reflector.thickness_sd_nm`: must be in [0, thickness_nm / 2] = [0, 100] nm, got 150",
        ),
        (
            "observer_deg = 10",
            "observer_deg = 5",
            "key `paint.observer_deg`: must be 2 (CIE 1931) or 10 (CIE 1964), got 5",
        ),
    ];
    for (from, to, want) in cases {
        let text = metallic_text();
        assert!(text.contains(from), "{from}");
        let e = parse(&text.replacen(from, to, 1)).unwrap_err().to_string();
        assert_eq!(e, format!("cfg/paint.toml: {want}"), "{to}");
    }
}

#[test]
fn layers_must_share_one_lacquer_index() {
    let text = metallic_text().replacen(
        "name = \"primer\"\nthickness_um = 20.0\nlacquer = { index = [1.5, 0.0] }",
        "name = \"primer\"\nthickness_um = 20.0\nlacquer = { index = [1.6, 0.0] }",
        1,
    );
    let e = parse(&text).unwrap_err().to_string();
    assert!(e.contains("key `paint.layer[2].lacquer`"), "{e}");
    assert!(e.contains("within 0.02 of the top layer's 1.5"), "{e}");
}

#[test]
fn a_material_without_data_at_a_wavelength_is_named() {
    let text = metallic_text().replace("library = \"anatase\"", "library = \"rutile\"");
    let e = parse(&text).unwrap_err().to_string();
    assert!(
        e.contains("wavelength 400 nm is outside the data range [430, 1100] nm")
            && e.contains("paint.layer[2].pigment[0]"),
        "{e}"
    );
}

/// Fresnel reflectance of natural light from air into a medium of index `n`.
fn fresnel(n: f64, theta: f64) -> f64 {
    let (ci, si) = (theta.cos(), theta.sin());
    let ct = (1.0 - (si / n).powi(2)).sqrt();
    let rs = ((ci - n * ct) / (ci + n * ct)).powi(2);
    let rp = ((n * ci - ct) / (n * ci + ct)).powi(2);
    0.5 * (rs + rp)
}

/// A clear lacquer of index n on a Lambertian ground of albedo a, in
/// optical contact: `π f(i → o) = T_i T_o a / (n² (1 − a r_i))`, `T = 1 − R`
/// from air, `r_i` the surface's reflectance for diffuse light from inside,
/// `1 − r_i = (1 − r_ed)/n²` with `r_ed` the diffuse reflectance from air
/// (Simpson over the hemisphere here).
#[test]
fn a_clear_lacquer_on_a_white_ground_matches_the_closed_form_and_does_not_flop() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = parse(CLEAR_ON_WHITE).unwrap();
    scene.output.dir = dir.path().to_path_buf();
    let report = inksim::pipeline::run_paint(&scene, true).unwrap();
    let (n, a) = (1.5, 0.8);
    let steps = 20_000;
    let h = std::f64::consts::FRAC_PI_2 / steps as f64;
    let g = |t: f64| fresnel(n, t) * 2.0 * t.sin() * t.cos();
    let mut r_ed = g(0.0) + g(std::f64::consts::FRAC_PI_2);
    for k in 1..steps {
        r_ed += if k % 2 == 1 { 4.0 } else { 2.0 } * g(k as f64 * h);
    }
    r_ed *= h / 3.0;
    let r_i = 1.0 - (1.0 - r_ed) / (n * n);
    let obs = Observer::standard(scene.illuminant, scene.observer);
    let mut exact = Vec::new();
    for geo in multiangle::geometries() {
        let (view, _) = geo.view();
        let t = |deg: f64| 1.0 - fresnel(n, f64::to_radians(deg));
        let f = t(geo.illumination_deg) * t(view) * a / (n * n * (1.0 - a * r_i));
        let spectrum = vec![f; scene.wavelengths_nm.len()];
        let xyz = colour::xyz_from_reflectance(&obs, &scene.wavelengths_nm, &spectrum).unwrap();
        exact.push(colour::xyz_to_lab(xyz, obs.white_xyz()));
    }
    let mut worst = 0.0f64;
    for (c, e) in report.colours.iter().zip(&exact) {
        worst = worst.max((c.lab[0] - e[0]).abs());
    }
    eprintln!("clear lacquer on white: worst |ΔL*| against the closed form {worst:.2e}");
    assert!(worst < 1e-4, "{worst}");
    let l = |asp: f64| {
        multiangle::geometries()
            .iter()
            .position(|g| g.illumination_deg == 45.0 && g.aspecular_deg == asp)
            .map(|i| exact[i][0])
            .unwrap()
    };
    let fi_exact = multiangle::flop_index(l(15.0), l(45.0), l(110.0)).unwrap();
    let fi = report.flop_index.unwrap();
    eprintln!("flop index {fi:.4}, closed form {fi_exact:.4}");
    assert!((fi - fi_exact).abs() < 1e-3, "{fi} vs {fi_exact}");
    assert!(
        fi.abs() < 0.5,
        "a Lambertian ground under a lacquer barely flops: {fi}"
    );
    // No flakes: no sparkle figures.
    assert!(report.sparkle.is_none());
}

/// A solid paint: the metallic's layers with a white and black base coat
/// instead of flakes.
const SOLID: &str = r#"
[paint]
wavelength_range_nm = { start = 400.0, stop = 700.0, step = 20.0 }
illuminant = "D65"
observer_deg = 10
ground = { kind = "white", albedo = 0.8 }

[[paint.layer]]
name = "clearcoat"
thickness_um = 40.0
lacquer = { index = [1.5, 0.0] }

[[paint.layer]]
name = "basecoat"
thickness_um = 15.0
lacquer = { index = [1.5, 0.0] }

[[paint.layer.pigment]]
name = "white"
material = { library = "anatase" }
pvc = 0.1
diameter_nm = 250.0

[[paint.layer.pigment]]
name = "black"
material = { library = "soot" }
pvc = 0.005
diameter_nm = 100.0
"#;

#[test]
fn the_metallic_and_pearl_configs_run_and_export() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::write(dir.path().join("solid.toml"), SOLID).unwrap();
    let mut flop = Vec::new();
    for (name, config) in [
        ("metallic", root.join("configs/metallic.toml")),
        ("pearl", root.join("configs/pearl.toml")),
        ("solid", dir.path().join("solid.toml")),
    ] {
        let out = dir.path().join(name);
        let (ok, stdout, stderr) = inksim_in(
            dir.path(),
            &[
                "run",
                config.to_str().unwrap(),
                "--output-dir",
                out.to_str().unwrap(),
            ],
        );
        assert!(ok, "{name}: {stderr}");
        assert!(stdout.contains("flop index"), "{stdout}");
        // Progress lines carry their UTC time.
        assert!(
            stderr
                .lines()
                .any(|l| l.starts_with("20") && l.contains("Z ")),
            "{stderr}"
        );
        let h5 = out.join(format!("{name}.h5"));
        let pictures = [
            format!("{name}.png"),
            format!("{name}-flop.png"),
            format!("{name}-sparkle.png"),
        ];
        for f in &pictures {
            assert!(out.join(f).is_file(), "{f}");
        }
        assert!(stdout.contains(&format!("{name}-sparkle.png")), "{stdout}");
        // `check` lists every file a run writes.
        let (ok, listed, stderr) = inksim_in(dir.path(), &["check", config.to_str().unwrap()]);
        assert!(ok, "{stderr}");
        for f in &pictures {
            assert!(listed.contains(f.as_str()), "{f} not in {listed}");
        }
        let p = read_paint(&h5).unwrap();
        assert_eq!(p.colours.len(), 11);
        assert_eq!((p.illuminant.as_str(), p.observer_deg), ("D65", 10));
        for c in &p.colours {
            assert!(c.lab.iter().chain(&c.xyz).all(|v| v.is_finite()), "{c:?}");
            assert!(c.lab[0] > 0.0, "{name}: {c:?}");
        }
        let fi = p.flop_index.unwrap();
        eprintln!("{name}: flop index {fi:.2}");
        flop.push(fi);
        assert_eq!(p.sparkle.is_some(), name != "solid");
        if let Some(s) = &p.sparkle {
            assert_eq!(s.rows.len(), 3);
            // Glints fall as the light moves away from the view (the half
            // vector leans further out of the narrow distribution).
            assert!(s.rows[0].glints_per_mm2 > s.rows[1].glints_per_mm2);
            assert!(s.rows[1].glints_per_mm2 > s.rows[2].glints_per_mm2);
            assert!(s.graininess > 0.0 && s.graininess.is_finite());
        }
        let (ok, stdout, stderr) = inksim_in(dir.path(), &["export", h5.to_str().unwrap()]);
        assert!(ok, "{stderr}");
        assert!(stdout.contains("multiangle:"), "{stdout}");
        let csv = std::fs::read_to_string(out.join(format!("{name}-multiangle.csv"))).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 12, "{csv}");
        assert!(lines[0].starts_with("geometry,illumination_deg,aspecular_deg,illuminant"));
        assert!(lines[0].ends_with(",X,Y,Z,flop_index"));
        assert!(lines[2].starts_with("45as15,45,15,D65,10,"), "{}", lines[2]);
        assert_eq!(
            out.join(format!("{name}-sparkle.csv")).is_file(),
            name != "solid"
        );
    }
    let (metallic, pearl, solid) = (flop[0], flop[1], flop[2]);
    assert!(metallic > 5.0, "metallic flop index {metallic}");
    assert!(metallic > pearl, "metallic {metallic} vs pearl {pearl}");
    assert!(solid.abs() < 1.0, "solid paint flop index {solid}");
    assert!(metallic > 5.0 * solid.abs());
}

#[test]
fn a_bad_paint_fails_in_one_line_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let text = metallic_text().replace("volume_fraction = 0.02", "volume_fraction = 2.0");
    std::fs::write(dir.path().join("bad.toml"), text).unwrap();
    for cmd in ["check", "run"] {
        let (ok, stdout, stderr) = inksim_in(dir.path(), &[cmd, "bad.toml"]);
        assert!(!ok);
        assert!(stdout.is_empty(), "{stdout}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains("paint.layer[1].flakes.volume_fraction"),
            "{stderr}"
        );
    }
    assert!(!dir.path().join("runs").exists());
}

#[test]
fn a_command_of_a_wave_scene_refuses_a_paint_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/metallic.toml");
    let (ok, _, stderr) = inksim_in(dir.path(), &["geometry", cfg]);
    assert!(!ok);
    assert!(
        stderr.contains("an effect paint ([paint] table)"),
        "{stderr}"
    );
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
}
