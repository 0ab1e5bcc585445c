//! What accuracy costs in time: for representative layers, vary
//! one fidelity knob at a time from a baseline, run each variant through the
//! `inksim` CLI (under `/usr/bin/time` for wall time, CPU time and peak
//! memory) and compare what users look at against the knob's converged
//! value: the tile's colours (CIEDE2000, max and mean over its cells), the
//! BRDF of layer + paper (relative L2), and R, T, A (max abs difference).
//!
//! `cargo run --release --example accuracy -- [case ...] [--out DIR] [--knob K ...]
//!  [--set KEY=VALUE ...]`
//!
//! `--set` changes the baseline of every variant (a dotted key and a TOML
//! value, e.g. `--set solver.equation='"maxwell"'`). `--against FILE.h5`
//! compares every variant with that result (e.g. another model's converged
//! run) instead of the knob's own reference value.
//!
//! Cases: `weak` (red, 15 % PVC, 100 nm spheres), `typical` (red, 30 %,
//! 200 nm), `hard` (blue, 50 %, 250 nm, dynamics packing); default all.
//! Prints one Markdown table per case (the tables of docs/ACCURACY.md).
//! Identical variants (the baseline recurs in every knob) run once, and a
//! variant finished in the same `--out` folder by an earlier run is reused.
//! Colours are the ones the run stored (`/appearance/tile_lab`).

use inksim::optics::colour::{self, Observer};
use inksim::output::h5::{read_appearance, AppearanceArrays};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use toml::Value;

struct Case {
    name: &'static str,
    material: &'static str,
    pvc: f64,
    diameter_nm: f64,
}

const CASES: [Case; 3] = [
    Case {
        name: "weak",
        material: "red",
        pvc: 0.15,
        diameter_nm: 100.0,
    },
    Case {
        name: "typical",
        material: "red",
        pvc: 0.30,
        diameter_nm: 200.0,
    },
    Case {
        name: "hard",
        material: "blue",
        pvc: 0.50,
        diameter_nm: 250.0,
    },
];

/// Knob: TOML key, values (the last is the converged reference), baseline.
fn knobs() -> Vec<(&'static str, Vec<Value>)> {
    let f = |v: &[f64]| v.iter().map(|&x| Value::Float(x)).collect::<Vec<_>>();
    let frag = |v: &[f64]| {
        v.iter()
            .map(|&x| Value::Array(vec![Value::Float(x), Value::Float(x)]))
            .collect::<Vec<_>>()
    };
    let s = |v: &[&str]| {
        v.iter()
            .map(|&x| Value::String(x.into()))
            .collect::<Vec<_>>()
    };
    let i = |v: &[i64]| v.iter().map(|&x| Value::Integer(x)).collect::<Vec<_>>();
    // Spheres per particle: rice grains (aspect 3) of the case's effective
    // diameter, built of n spheres.
    let rice = |v: &[i64]| {
        v.iter()
            .map(|&n| {
                let mut t = toml::map::Map::new();
                t.insert("kind".into(), Value::String("rice".into()));
                t.insert("aspect".into(), Value::Float(3.0));
                t.insert("spheres".into(), Value::Integer(n));
                Value::Table(t)
            })
            .collect::<Vec<_>>()
    };
    vec![
        ("grid.cell_nm", f(&[50.0, 33.4, 25.0, 20.0, 16.7])),
        ("grid.z_cell_nm", f(&[25.0, 20.0, 10.0, 5.0])),
        ("solver.tolerance", f(&[1e-2, 1e-3, 1e-4, 1e-6, 1e-9])),
        (
            "illumination.wavelength_range_nm.step",
            f(&[100.0, 50.0, 30.0, 20.0, 15.0, 10.0]),
        ),
        ("appearance.quadrature_points", i(&[2, 4, 6, 12])),
        ("realisations", i(&[1, 2, 4, 8])),
        ("layer.fragment_nm", frag(&[700.0, 1000.0, 1500.0, 2000.0])),
        ("solver.method", s(&["time-marching", "gmres", "bicgstab"])),
        ("solver.precision", s(&["f32", "f64"])),
        ("pigment.0.shape", rice(&[3, 5, 7, 11])),
    ]
}

fn base(case: &Case, out: &Path) -> Value {
    let text = format!(
        r#"
seed = 5
realisations = 1
[layer]
thickness_nm = 1000.0
fragment_nm = [1000.0, 1000.0]
[[pigment]]
name = "{m}"
material = {{ builtin = "{m}" }}
pvc = {pvc}
diameter_nm = {d}
[grid]
cell_nm = 25.0
z_cell_nm = 10.0
[illumination]
wavelength_range_nm = {{ start = 400.0, stop = 700.0, step = 50.0 }}
polar_deg = [0.0, 30.0, 60.0]
[solver]
method = "auto"
tolerance = 1e-6
max_iterations = 20000
[appearance]
quadrature_points = 4
[output]
dir = "{dir}"
name = "x"
"#,
        m = case.material,
        pvc = case.pvc,
        d = case.diameter_nm,
        dir = out.display()
    );
    toml::from_str(&text).expect("valid base scene")
}

/// Set a dotted key; a numeric part indexes an array (`pigment.0.shape`).
fn set(v: &mut Value, key: &str, value: Value) {
    let mut cur = v;
    let parts: Vec<&str> = key.split('.').collect();
    for p in &parts[..parts.len() - 1] {
        cur = match p.parse::<usize>() {
            Ok(i) => cur.get_mut(i),
            Err(_) => cur.get_mut(*p),
        }
        .expect("key exists in the base scene");
    }
    cur.as_table_mut()
        .expect("table")
        .insert(parts[parts.len() - 1].to_string(), value);
}

struct Measured {
    wall_s: f64,
    cpu_s: f64,
    peak_mb: f64,
    result: AppearanceArrays,
}

fn run(exe: &Path, scene: &Value, dir: &Path, cache: &mut HashMap<String, PathBuf>) -> Measured {
    let text = toml::to_string(scene).expect("serialisable");
    let n = cache.len();
    let cfg = cache.entry(text.clone()).or_insert_with(|| {
        let d = dir.join(format!("v{n:03}"));
        std::fs::create_dir_all(&d).unwrap();
        let cfg = d.join("scene.toml");
        let timing = d.join("time.txt");
        // A finished variant of an earlier run into the same folder (the
        // same scene text) is read, not run again.
        let same = std::fs::read_to_string(&cfg).is_ok_and(|t| t == text);
        if same && timing.is_file() && d.join("x.h5").is_file() {
            return cfg;
        }
        std::fs::write(&cfg, &text).unwrap();
        let status = Command::new("/usr/bin/time")
            .args(["-f", "%e %U %S %M", "-o"])
            .arg(&timing)
            .arg(exe)
            .args(["run"])
            .arg(&cfg)
            .arg("--output-dir")
            .arg(&d)
            .stderr(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .status()
            .expect("inksim runs");
        assert!(status.success(), "variant {} failed", cfg.display());
        cfg
    });
    let d = cfg.parent().unwrap();
    let t = std::fs::read_to_string(d.join("time.txt")).unwrap();
    let nums: Vec<f64> = t
        .split_whitespace()
        .rev()
        .take(4)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .map(|x| x.parse().unwrap())
        .collect();
    Measured {
        wall_s: nums[0],
        cpu_s: nums[1] + nums[2],
        peak_mb: nums[3] / 1024.0,
        result: read_appearance(&d.join("x.h5"))
            .unwrap()
            .expect("appearance stored"),
    }
}

/// Lab of every tile cell as the run stored it (colour through the spectral
/// proxy), else computed from the stored spectra by linear interpolation.
fn tile_lab(a: &AppearanceArrays, obs: &Observer) -> Vec<[f64; 3]> {
    if let Some(t) = &a.tile_lab {
        let (nv, nc, _) = t.dim();
        return (0..nv)
            .flat_map(|o| (0..nc).map(move |c| [t[[o, c, 0]], t[[o, c, 1]], t[[o, c, 2]]]))
            .collect();
    }
    let (f, sky) = (a.brdf_total.as_ref().unwrap(), a.natural.as_ref().unwrap());
    let wl = &a.wavelengths_nm;
    let white = obs.white_xyz();
    let mut out = Vec::new();
    for o in 0..a.viewing_deg.len() {
        let s: Vec<f64> = (0..wl.len()).map(|l| sky[[l, o]]).collect();
        out.push(colour::xyz_to_lab(
            colour::xyz_from_reflectance(obs, wl, &s).unwrap(),
            white,
        ));
        for i in 0..a.illumination_deg.len() {
            let s: Vec<f64> = (0..wl.len())
                .map(|l| std::f64::consts::PI * f[[l, i, o]])
                .collect();
            out.push(colour::xyz_to_lab(
                colour::xyz_from_reflectance(obs, wl, &s).unwrap(),
                white,
            ));
        }
    }
    out
}

struct Errors {
    de_max: f64,
    de_mean: f64,
    brdf_l2: f64,
    rta_max: f64,
}

fn compare(a: &AppearanceArrays, r: &AppearanceArrays, obs: &Observer) -> Errors {
    let (la, lr) = (tile_lab(a, obs), tile_lab(r, obs));
    let de: Vec<f64> = la
        .iter()
        .zip(&lr)
        .map(|(x, y)| colour::delta_e2000(*x, *y))
        .collect();
    // Common wavelengths (the spectral-step knob uses nested grids).
    let common: Vec<(usize, usize)> = a
        .wavelengths_nm
        .iter()
        .enumerate()
        .filter_map(|(i, w)| r.wavelengths_nm.iter().position(|x| x == w).map(|j| (i, j)))
        .collect();
    let (fa, fr) = (
        a.brdf_total.as_ref().unwrap(),
        r.brdf_total.as_ref().unwrap(),
    );
    let (mut num, mut den, mut rta): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for &(i, j) in &common {
        for ii in 0..a.illumination_deg.len() {
            for o in 0..a.viewing_deg.len() {
                num += (fa[[i, ii, o]] - fr[[j, ii, o]]).powi(2);
                den += fr[[j, ii, o]].powi(2);
            }
        }
        for k in 0..a.above_deg.len() {
            for (x, y) in [
                (&a.reflectance, &r.reflectance),
                (&a.transmittance, &r.transmittance),
                (&a.absorption, &r.absorption),
            ] {
                rta = rta.max((x[[i, k]] - y[[j, k]]).abs());
            }
        }
    }
    Errors {
        de_max: de.iter().copied().fold(0.0, f64::max),
        de_mean: de.iter().sum::<f64>() / de.len() as f64,
        brdf_l2: (num / den).sqrt(),
        rta_max: rta,
    }
}

fn show(v: &Value) -> String {
    match v {
        Value::Array(a) => show(&a[0]),
        Value::Table(t) => match t.get("spheres") {
            Some(n) => format!("rice, {n} spheres"),
            None => v.to_string(),
        },
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut out = PathBuf::from("runs/accuracy");
    let mut cases: Vec<&str> = Vec::new();
    let mut only: Vec<String> = Vec::new();
    let mut overrides: Vec<(String, Value)> = Vec::new();
    let mut against: Option<AppearanceArrays> = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--out" => out = PathBuf::from(it.next().expect("--out DIR")),
            "--knob" => only.push(it.next().expect("--knob KEY").clone()),
            "--against" => {
                let path = PathBuf::from(it.next().expect("--against FILE.h5"));
                against = read_appearance(&path)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
                anyhow::ensure!(
                    against.is_some(),
                    "{}: no appearance stored",
                    path.display()
                );
            }
            "--set" => {
                let kv = it.next().expect("--set KEY=VALUE");
                let (k, v) = kv.split_once('=').expect("--set KEY=VALUE");
                let v: Value = toml::from_str::<toml::Table>(&format!("v = {v}"))
                    .map_err(|e| anyhow::anyhow!("--set {kv}: {e}"))?["v"]
                    .clone();
                overrides.push((k.to_string(), v));
            }
            c => cases.push(c),
        }
    }
    if cases.is_empty() {
        cases = CASES.iter().map(|c| c.name).collect();
    }
    let exe = std::env::current_exe()?
        .parent()
        .and_then(|p| p.parent())
        .map(|p| p.join("inksim"))
        .filter(|p| p.is_file())
        .ok_or_else(|| anyhow::anyhow!("build the CLI first: cargo build --release"))?;
    let obs = Observer::cie1931_d65();
    for case in CASES.iter().filter(|c| cases.contains(&c.name)) {
        let dir = out.join(case.name);
        let mut cache = HashMap::new();
        println!(
            "\n### {}: {} {} % PVC, {} nm spheres, 1 µm layer\n",
            case.name,
            case.material,
            case.pvc * 100.0,
            case.diameter_nm
        );
        println!("| knob | value | wall s | CPU s | peak MB | ΔE00 max | ΔE00 mean | BRDF rel. L2 | max abs ΔR/T/A | cost vs ref |");
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for (key, values) in knobs() {
            if !only.is_empty() && !only.iter().any(|k| k == key) {
                continue;
            }
            let based = || {
                let mut scene = base(case, &dir);
                for (k, v) in &overrides {
                    set(&mut scene, k, v.clone());
                }
                scene
            };
            let mut scene = based();
            let reference = values.last().unwrap().clone();
            set(&mut scene, key, reference.clone());
            let r = run(&exe, &scene, &dir, &mut cache);
            for v in &values {
                let mut scene = based();
                set(&mut scene, key, v.clone());
                let m = run(&exe, &scene, &dir, &mut cache);
                let e = compare(&m.result, against.as_ref().unwrap_or(&r.result), &obs);
                let is_ref = *v == reference;
                println!(
                    "| {key} | {}{} | {:.1} | {:.1} | {:.0} | {:.2} | {:.2} | {:.1e} | {:.1e} | {:.0} % |",
                    show(v),
                    if is_ref { " (ref)" } else { "" },
                    m.wall_s,
                    m.cpu_s,
                    m.peak_mb,
                    e.de_max,
                    e.de_mean,
                    e.brdf_l2,
                    e.rta_max,
                    100.0 * m.cpu_s / r.cpu_s.max(1e-9)
                );
            }
        }
    }
    Ok(())
}
