//! A study's pictures and page: a study run that finishes merges; the plots
//! of L* and C*ab against each axis are written and listed; summary.html's
//! effects table holds the changes computed here from the variants' result
//! files; every link and image of the page names a file that exists; and the
//! page renders in headless Chromium (skipped, saying so, where no Chromium
//! is installed) to a screenshot that is not blank and shows the plots.
use std::path::{Path, PathBuf};
use std::process::Command;

use inksim::optics::colour::{lab_to_lch, lch_se};
use inksim::output::h5::read_measured;
use inksim::output::render::plot::palette;
use inksim::output::render::Canvas;

mod common;
use common::browser::chromium;
use common::cli::inksim_in;

/// Two pigments × two PVCs, two realisations each, 8 × 8 × 4 grids.
const SWEEP: &str = r#"
[study]
name = "page"
seed = 9
output_dir = "out"

[base]
realisations = 2
[base.layer]
thickness_nm = 400.0
fragment_nm = [400.0, 400.0]
pvc = 0.15
[[base.pigment]]
name = "p"
material = { builtin = "red" }
diameter_nm = 100.0
[base.grid]
cell_nm = 50.0
z_cell_nm = 100.0
[base.illumination]
wavelengths_nm = [450.0, 550.0, 650.0]
polar_deg = [0.0]

[[axis]]
name = "pigment"
key = "pigment.0.material.builtin"
values = ["red", "yellow"]

[[axis]]
name = "pvc"
key = "layer.pvc"
values = [0.1, 0.2]
"#;

/// Run the study in a fresh folder: (folder guard, study folder, stdout).
fn run_study() -> (tempfile::TempDir, PathBuf, String) {
    run_sweep(SWEEP)
}

/// Run the sweep file `text` in a fresh folder, as [`run_study`] does.
fn run_sweep(text: &str) -> (tempfile::TempDir, PathBuf, String) {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.toml");
    std::fs::write(&sweep, text).unwrap();
    let (ok, out, err) = inksim_in(dir.path(), &["run", sweep.to_str().unwrap()]);
    assert!(ok, "{err}");
    let study_dir = dir.path().join("out");
    (dir, study_dir, out)
}

/// Every `href="…"` and `src="…"` target of `html`.
fn targets(html: &str) -> Vec<String> {
    let mut out = vec![];
    for attr in ["href=\"", "src=\""] {
        let mut rest = html;
        while let Some(i) = rest.find(attr) {
            rest = &rest[i + attr.len()..];
            let end = rest.find('"').unwrap();
            out.push(rest[..end].replace("&amp;", "&"));
            rest = &rest[end..];
        }
    }
    out
}

/// The 45/0 L*, C*ab, h° and their standard errors of a variant.
fn lch_of(study_dir: &Path, name: &str) -> ([f64; 3], [f64; 3]) {
    let (records, _, _) = read_measured(&study_dir.join(format!("variants/{name}.h5")))
        .unwrap()
        .unwrap();
    let m = records.iter().find(|m| m.geometry == "45/0").unwrap();
    (lab_to_lch(m.lab), lch_se(m.lab, m.lab_se.unwrap()))
}

#[test]
fn finished_study_writes_plots_and_a_page_whose_links_resolve() {
    let (_guard, sd, stdout) = run_study();
    assert!(stdout.contains("merging"), "{stdout}");
    // x = pvc per pigment; no plot against the series axis itself.
    let plot = sd.join("plots/pvc.png");
    assert!(stdout.contains("plot: out/plots/pvc.png"), "{stdout}");
    assert!(!sd.join("plots/pigment.png").exists());
    let img = Canvas::decode_png(&std::fs::read(&plot).unwrap()).unwrap();
    assert!(img.w > 600 && img.h > 250);
    let has = |c: [u8; 3]| img.px.chunks_exact(3).any(|p| p == c);
    assert!(has(palette(0)) && has(palette(1)) && !has(palette(2)));

    let html = std::fs::read_to_string(sd.join("summary.html")).unwrap();
    let links = targets(&html);
    for t in &links {
        assert!(sd.join(t).is_file(), "link {t} does not resolve");
    }
    for want in [
        "summary.h5",
        "plots/pvc.png",
        "variants/red_pvc0.1.h5",
        "variants/yellow_pvc0.2-spectra.png",
    ] {
        assert!(links.iter().any(|l| l == want), "no link to {want}");
    }
    assert!(html.contains(env!("CARGO_PKG_VERSION")) && html.contains("D50, 2°"));

    // The pvc step's ΔL*: mean over the two pigments of the change, with
    // the standard error of that mean.
    let mut d = 0.0;
    let mut var = 0.0;
    for p in ["red", "yellow"] {
        let (a, sa) = lch_of(&sd, &format!("{p}_pvc0.1"));
        let (b, sb) = lch_of(&sd, &format!("{p}_pvc0.2"));
        d += (b[0] - a[0]) / 2.0;
        var += sa[0] * sa[0] + sb[0] * sb[0];
    }
    let cell = format!("<td>{d:+.2} ± {:.2}</td>", var.sqrt() / 2.0);
    let row = html
        .lines()
        .find(|l| l.contains("<td>pvc0.1 → pvc0.2</td>"))
        .expect("the pvc step's row");
    assert!(row.contains(&cell), "{cell} not in {row}");
    assert!(row.contains("<td>2</td>"), "two pairs: {row}");
}

#[test]
fn summary_page_renders_in_headless_chromium() {
    let Some(browser) = chromium() else {
        eprintln!(
            "SKIPPED summary_page_renders_in_headless_chromium: no chromium, chromium-browser \
             or google-chrome on PATH (apt-get install -y chromium; scripts/setup.sh \
             --with-browser installs it)"
        );
        return;
    };
    let (guard, sd, _) = run_study();
    let profile = guard.path().join("chromium-profile");
    let shot = guard.path().join("shot.png");
    let page = sd.join("summary.html").canonicalize().unwrap();
    let out = Command::new(&browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--no-first-run",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1400,2000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", page.display()))
        .output()
        .unwrap();
    assert!(
        shot.is_file(),
        "{} wrote no screenshot: {}",
        browser.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let img = Canvas::decode_png(&std::fs::read(&shot).unwrap()).unwrap();
    assert_eq!((img.w, img.h), (1400, 2000));
    let px: Vec<&[u8]> = img.px.chunks_exact(3).collect();
    let inked = px.iter().filter(|p| p.iter().any(|&v| v < 200)).count();
    assert!(
        inked * 100 > px.len(),
        "blank: {inked} of {} pixels inked",
        px.len()
    );
    // The plots loaded: their first series colour is on the screen (scaled
    // images blend edges, so within a small distance).
    let near = |c: [u8; 3]| {
        px.iter()
            .any(|p| (0..3).all(|k| (p[k] as i32 - c[k] as i32).abs() <= 12))
    };
    assert!(
        near(palette(0)) && near(palette(1)),
        "the plots did not load"
    );
}

/// A study whose variants carry classical baselines lists, on both pages,
/// each model's ΔE00 to the wave colour as the result files hold it, beside
/// the wave colour's own standard error; a study without them has no such
/// section (the other tests' page).
#[test]
fn the_page_lists_each_baselines_de00_to_the_wave_colour() {
    let sweep = SWEEP.replace(
        "polar_deg = [0.0]\n",
        "polar_deg = [0.0]\n[base.appearance]\nbaseline = [\"kubelka-munk\", \"adding-doubling\"]\n",
    );
    assert_ne!(sweep, SWEEP);
    let (_guard, study_dir, _) = run_sweep(&sweep);
    let md = std::fs::read_to_string(study_dir.join("summary.md")).unwrap();
    let html = std::fs::read_to_string(study_dir.join("summary.html")).unwrap();
    assert!(md.contains("## Classical baselines"), "{md}");
    assert!(html.contains("<h2>Classical baselines</h2>"));
    let mut variants = 0;
    for entry in std::fs::read_dir(study_dir.join("variants")).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().and_then(|e| e.to_str()) != Some("h5") {
            continue;
        }
        let name = p.file_stem().unwrap().to_str().unwrap().to_string();
        let (measured, _, _) = read_measured(&p).unwrap().unwrap();
        let m = measured.iter().find(|m| m.geometry == "45/0").unwrap();
        let b = inksim::output::h5::read_baseline(&p).unwrap();
        let de = |model: &str| {
            let r = b.iter().find(|r| r.model == model && r.geometry == "45/0");
            format!("{:.2}", r.unwrap().de00_to_wave.unwrap())
        };
        let tail = format!(
            "| {:.2} | {} | {} |",
            m.de00_se.unwrap(),
            de("kubelka-munk"),
            de("adding-doubling")
        );
        let head = format!("| {name} |");
        assert!(
            md.lines()
                .any(|l| l.starts_with(&head) && l.ends_with(&tail)),
            "{head} … {tail}\n{md}"
        );
        variants += 1;
    }
    assert_eq!(variants, 4);
    let (_guard, plain, _) = run_study();
    let md = std::fs::read_to_string(plain.join("summary.md")).unwrap();
    assert!(!md.contains("Classical baselines"));
}

/// The page says which wave equation the colours came from: one fact line
/// for a study in one equation, and a column per variant when an axis sets
/// `solver.equation`.
#[test]
fn the_page_names_the_wave_equation_of_every_colour() {
    let sweep = SWEEP.replace(
        "values = [0.1, 0.2]\n",
        "values = [0.1]\n\n[[axis]]\nname = \"wave\"\n\
         [[axis.value]]\nlabel = \"scalar\"\nset = { \"solver.equation\" = \"helmholtz\" }\n\
         [[axis.value]]\nlabel = \"vector\"\nset = { \"solver.equation\" = \"maxwell\" }\n",
    );
    assert_ne!(sweep, SWEEP);
    let (_guard, study_dir, _) = run_sweep(&sweep);
    let md = std::fs::read_to_string(study_dir.join("summary.md")).unwrap();
    let html = std::fs::read_to_string(study_dir.join("summary.html")).unwrap();
    assert!(
        md.contains("- wave equation: helmholtz for 2 variants, maxwell for 2"),
        "{md}"
    );
    assert!(html.contains("helmholtz for 2 variants, maxwell for 2"));
    let header = md
        .lines()
        .find(|l| l.starts_with("| # | name |"))
        .expect("variants table");
    assert!(header.contains("| equation |"), "{header}");
    for (label, name) in [("scalar", "helmholtz"), ("vector", "maxwell")] {
        let rows = md
            .lines()
            .filter(|l| l.contains(&format!("| {label} | {name} |")))
            .count();
        assert_eq!(rows, 2, "{name}\n{md}");
    }
    let (_guard, plain, _) = run_study();
    let md = std::fs::read_to_string(plain.join("summary.md")).unwrap();
    assert!(
        md.contains("- wave equation: helmholtz for every variant"),
        "{md}"
    );
    let header = md.lines().find(|l| l.starts_with("| # | name |")).unwrap();
    assert!(!header.contains("equation"), "{header}");
}
