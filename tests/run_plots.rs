//! The plots of a run (spectra, in-plane BRDF, polar BRDF map): written next
//! to the other pictures and named on stdout, drawn from the run's own
//! numbers (series colours present, a colour scale covering the table), and
//! the geometry picture's grey-scale bar.
use std::process::Command;

use inksim::output::render::plot::colour_map::viridis;
use inksim::output::render::plot::palette;
use inksim::output::render::{self, Canvas};

const SCENE: &str = r#"
seed = 5
realisations = 2
[layer]
thickness_nm = 400.0
fragment_nm = [600.0, 600.0]
[[pigment]]
name = "red"
material = { builtin = "red" }
pvc = 0.2
diameter_nm = 150.0
[grid]
cell_nm = 50.0
z_cell_nm = 25.0
[illumination]
wavelengths_nm = [450.0, 550.0, 650.0]
polar_deg = [0.0, 40.0]
[solver]
tolerance = 1e-6
[appearance]
outputs = ["brdf", "tile"]
measurements = []
[substrate]
kind = "paper"
albedo = 0.9
[output]
name = "plots"
"#;

/// The test scene with its results in `dir`.
fn scene_in(dir: &std::path::Path) -> inksim::config::Scene {
    let mut scene = inksim::config::parse_scene(&dir.join("scene.toml"), SCENE).unwrap();
    scene.output.dir = dir.to_path_buf();
    scene
}

fn decode(path: &std::path::Path) -> Canvas {
    Canvas::decode_png(&std::fs::read(path).unwrap()).unwrap()
}

fn has_colour(img: &Canvas, c: [u8; 3]) -> bool {
    img.px.chunks_exact(3).any(|p| p == c)
}

#[test]
fn a_run_writes_and_lists_its_plots() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("scene.toml");
    std::fs::write(&cfg, SCENE).unwrap();
    let out = dir.path().join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_inksim"))
        .args(["run", cfg.to_str().unwrap(), "--output-dir"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    for suffix in ["spectra", "brdf-plane", "brdf-polar"] {
        let p = out.join(format!("plots-{suffix}.png"));
        assert!(
            stdout.contains(&format!("plot: {}", p.display())),
            "{suffix} not listed: {stdout}"
        );
        let img = decode(&p);
        assert!(
            img.w >= 500 && img.h >= 300,
            "{suffix}: {} × {}",
            img.w,
            img.h
        );
    }
    // Spectra: one colour per angle solved from above (0° and 40°).
    let spectra = decode(&out.join("plots-spectra.png"));
    assert!(has_colour(&spectra, palette(0)) && has_colour(&spectra, palette(1)));
    assert!(!has_colour(&spectra, palette(2)));
}

#[test]
fn plots_are_drawn_from_the_runs_appearance() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_in(dir.path());
    let report = inksim::pipeline::run_with(&scene, true, None).unwrap();
    let a = report.appearance.as_ref().unwrap();
    assert_eq!(report.plot_paths.len(), 3);

    // The map's colour scale covers every value it draws (nodes within
    // 85° of the normal), and the polar map shows both ends of its ramp.
    let scale = render::map_scale(a).unwrap();
    let spec = a.spec.table;
    let max_s = 85f64.to_radians().sin();
    let mut hi = 0.0f64;
    for ((_, _, j, i), &d) in a.brdf_table.mean.indexed_iter() {
        let (sx, sy) = (spec.coord(i), spec.coord(j));
        if sx * sx + sy * sy <= max_s * max_s {
            hi = hi.max(d / (1.0 - sx * sx - sy * sy).sqrt());
        }
    }
    assert!(
        hi > 0.0 && scale.hi >= hi * (1.0 - 1e-12),
        "{scale:?} vs {hi}"
    );
    assert!(scale.lo <= hi);
    let polar = Canvas::decode_png(&render::brdf_polar_png(a, "p").unwrap()).unwrap();
    assert!(has_colour(&polar, viridis(1.0)) && has_colour(&polar, viridis(0.0)));

    // In-plane: with two realisations each incidence gets a band (a light
    // tint of its colour) and its line.
    let plane = Canvas::decode_png(&render::brdf_plane_png(a, "p").unwrap()).unwrap();
    for k in 0..2 {
        let c = palette(k);
        let light = c.map(|v| (v as f64 * 0.3 + 255.0 * 0.7) as u8);
        assert!(
            has_colour(&plane, c) && has_colour(&plane, light),
            "series {k}"
        );
    }
}

#[test]
fn geometry_picture_has_a_grey_scale_bar() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_in(dir.path());
    let rep = inksim::pipeline::run_geometry(&scene).unwrap();
    let img = decode(&rep.picture_path);
    // The ramp's ends: binder (fraction 0) and pigment (fraction 1) greys,
    // in a column right of both views.
    let grey = |f: f64| {
        let v = (40.0 + 215.0 * f).round() as u8;
        [v, v, (v as f64 * 0.9) as u8]
    };
    let column_with = |c: [u8; 3]| {
        (0..img.w)
            .rev()
            .find(|&x| (0..img.h).any(|y| img.get(x as i64, y as i64) == Some(c)))
    };
    let (top, bottom) = (
        column_with(grey(1.0)).unwrap(),
        column_with(grey(0.0)).unwrap(),
    );
    assert!(
        top > img.w * 3 / 4 && bottom > img.w * 3 / 4,
        "{top} {bottom} of {}",
        img.w
    );
}

#[test]
fn a_run_writes_exactly_the_outputs_asked_for_and_check_lists_them() {
    let names = |dir: &std::path::Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    for (outputs, expected) in [
        ("[]", vec!["plots.h5"]),
        (
            "[\"tile\"]",
            vec![
                "plots-brdf-plane.png",
                "plots-brdf-polar.png",
                "plots-spectra.png",
                "plots.h5",
                "plots.png",
            ],
        ),
        (
            "[\"brdf\"]",
            vec![
                "plots-brdf-plane.png",
                "plots-brdf-polar.png",
                "plots-orders.png",
                "plots-spectra.png",
                "plots.h5",
                "plots.png",
            ],
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let text = SCENE
            .replace(
                "outputs = [\"brdf\", \"tile\"]",
                &format!("outputs = {outputs}"),
            )
            .replace("realisations = 2", "realisations = 1");
        let mut scene = inksim::config::parse_scene(&dir.path().join("s.toml"), &text).unwrap();
        let out = dir.path().join("out");
        scene.output.dir = out.clone();
        // `check` names the same files the run writes.
        let listed: Vec<String> = inksim::pipeline::output_files(&scene)
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        let mut listed_sorted = listed.clone();
        listed_sorted.sort();
        assert_eq!(listed_sorted, expected, "outputs = {outputs}");
        let rep = inksim::pipeline::run_with(&scene, true, None).unwrap();
        assert_eq!(names(&out), expected, "outputs = {outputs}");
        assert_eq!(rep.picture_path.is_some(), expected.contains(&"plots.png"));
    }
}
