//! What a trustworthy colour costs, path against path: representative
//! layers solved at several wavelengths and angles along each solver path in
//! one run, every path in a child process of its own (so its CPU time and
//! peak memory are its own), compared with a converged reference.
//!
//! `cargo run --release --example study_cost [-- layer ...]`
//!
//! Layers: `weak`, `typical`, `hard` (the layers of docs/ACCURACY.md: red
//! 15 % 100 nm, red 30 % 200 nm, blue 50 % 250 nm spheres, 1 × 1 × 1 µm,
//! 25 nm cells, 10 nm in z), `hard-case` (examples/hard_case.rs: 300 nm
//! grains of n = 1.4 + 0.8i at 50 %, 1.28 × 1.28 × 1 µm, 20 nm cells),
//! `clear` (lossless grains of n = 2.4, 30 %, 200 nm: a white pigment, the
//! hardest case for a lossless background) and `standard` (the typical layer
//! at the standard study profile's 2 × 2 µm and 20 nm cells, 100 × 100 × 100);
//! default all. Each is solved at 400, 475, 550, 625 and 700 nm and at 0° and
//! 45°.
//!
//! Paths: today's `auto` on the binder background (CBS shift and
//! preconditioner), `auto` on the mean background (BiCGStab with a random
//! shadow vector, started from the mean slab's field), and single changes of
//! the latter (started from the binder slab's field, residual shadow vector,
//! no loss floor, GMRES(20)), all to the standard profile's tolerance 1e-5;
//! then both `auto` paths at 1e-3. Per layer and path it prints the operator
//! applications summed over the solves, CPU seconds, peak resident memory,
//! the largest energy balance, the largest |ΔR|, |ΔA| against the reference,
//! and ΔE00 (CIELAB, D50, 2° observer) of the colour of the total reflectance
//! spectrum at each angle against the reference's (the larger of the two
//! angles). The reference is BiCGStab on the binder background to relative
//! residual 1e-10.

use inksim::config::{parse_scene, Background, Illuminant, Precision, StandardObserver};
use inksim::optics::colour::{self, Observer};
use inksim::optics::farfield::efficiencies;
use inksim::pipeline::{self, SUPERSAMPLE};
use inksim::raster::rasterize;
use inksim::solver::methods::auto::Auto;
use inksim::solver::methods::bicgstab::{BiCgStab, Shadow};
use inksim::solver::methods::gmres::Gmres;
use inksim::solver::{Controls, Field, Problem, ShiftParams, Solver, System};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::path::Path;
use std::process::Command;

const WAVELENGTHS_NM: [f64; 5] = [400.0, 475.0, 550.0, 625.0, 700.0];
const POLAR_DEG: [f64; 2] = [0.0, 45.0];

/// A solver path: method, background and tolerance.
struct SolverPath {
    name: &'static str,
    solver: &'static dyn Solver,
    shift: ShiftParams,
    tolerance: f64,
    /// Start from the binder slab's field u_bg instead of the system's start.
    from_ubg: bool,
}

const BINDER: ShiftParams = ShiftParams::of(Background::Binder);
const MEAN: ShiftParams = ShiftParams::of(Background::Mean);
const BICGSTAB_R0: BiCgStab = BiCgStab {
    shadow: Shadow::Residual,
};

const REFERENCE: SolverPath = SolverPath {
    name: "reference",
    solver: &BiCgStab::DEFAULT,
    shift: BINDER,
    tolerance: 1e-10,
    from_ubg: false,
};

/// The paths compared, today's first (the standard profile's tolerance).
const PATHS: [SolverPath; 8] = [
    SolverPath {
        name: "binder (auto)",
        solver: &Auto,
        shift: BINDER,
        tolerance: 1e-5,
        from_ubg: false,
    },
    SolverPath {
        name: "mean (auto)",
        solver: &Auto,
        shift: MEAN,
        tolerance: 1e-5,
        from_ubg: false,
    },
    SolverPath {
        name: "mean, start u_bg",
        solver: &BiCgStab::DEFAULT,
        shift: MEAN,
        tolerance: 1e-5,
        from_ubg: true,
    },
    SolverPath {
        name: "mean, shadow r0",
        solver: &BICGSTAB_R0,
        shift: MEAN,
        tolerance: 1e-5,
        from_ubg: false,
    },
    SolverPath {
        name: "mean, no loss floor",
        solver: &BiCgStab::DEFAULT,
        shift: ShiftParams {
            mean_loss_floor: 0.0,
            ..MEAN
        },
        tolerance: 1e-5,
        from_ubg: false,
    },
    SolverPath {
        name: "mean, gmres(20)",
        solver: &Gmres::DEFAULT,
        shift: MEAN,
        tolerance: 1e-5,
        from_ubg: false,
    },
    SolverPath {
        name: "binder (auto), 1e-3",
        solver: &Auto,
        shift: BINDER,
        tolerance: 1e-3,
        from_ubg: false,
    },
    SolverPath {
        name: "mean (auto), 1e-3",
        solver: &Auto,
        shift: MEAN,
        tolerance: 1e-3,
        from_ubg: false,
    },
];

const LAYERS: [&str; 6] = ["weak", "typical", "hard", "hard-case", "clear", "standard"];

/// The scene of a layer solved along a path.
fn scene_text(layer: &str) -> String {
    let (material, pvc, d, side, cell) = match layer {
        "weak" => ("{ builtin = \"red\" }", 0.15, 100.0, 1000.0, 25.0),
        "typical" => ("{ builtin = \"red\" }", 0.30, 200.0, 1000.0, 25.0),
        "hard" => ("{ builtin = \"blue\" }", 0.50, 250.0, 1000.0, 25.0),
        "hard-case" => ("{ index = [1.4, 0.8] }", 0.50, 300.0, 1280.0, 20.0),
        "clear" => ("{ index = [2.4, 0.0] }", 0.30, 200.0, 1000.0, 25.0),
        "standard" => ("{ builtin = \"red\" }", 0.30, 200.0, 2000.0, 20.0),
        other => panic!("unknown layer {other}; one of {LAYERS:?}"),
    };
    let seed = if layer == "hard-case" { 1 } else { 5 };
    let wl: Vec<String> = WAVELENGTHS_NM.iter().map(|w| format!("{w:.1}")).collect();
    let polar: Vec<String> = POLAR_DEG.iter().map(|p| format!("{p:.1}")).collect();
    format!(
        r#"
seed = {seed}
realisations = 1
[layer]
thickness_nm = 1000.0
fragment_nm = [{side:.1}, {side:.1}]
[[pigment]]
name = "p"
material = {material}
pvc = {pvc}
diameter_nm = {d:.1}
[grid]
cell_nm = {cell:.1}
z_cell_nm = 10.0
[illumination]
wavelengths_nm = [{wl}]
polar_deg = [{polar}]
[substrate]
kind = "none"
"#,
        wl = wl.join(", "),
        polar = polar.join(", "),
    )
}

/// One solve as a child reports it.
#[derive(Clone, Copy)]
struct Solve {
    wavelength_nm: f64,
    polar_deg: f64,
    applications: usize,
    r: f64,
    a: f64,
    balance: f64,
}

/// What one path cost on one layer.
struct Measured {
    solves: Vec<Solve>,
    cpu_s: f64,
    peak_mb: f64,
}

/// Child: solve `layer` along path `name`, print one line per solve and
/// then `cost <cpu s> <peak MB>`.
fn child(layer: &str, name: &str) {
    let path = std::iter::once(&REFERENCE)
        .chain(PATHS.iter())
        .find(|p| p.name == name)
        .expect("known path");
    let scene = parse_scene(Path::new("study_cost.toml"), &scene_text(layer)).unwrap();
    let geometry = pipeline::build_geometry(&scene).unwrap();
    let grid = pipeline::grid_of(&scene);
    let raster = rasterize(&geometry, &grid, SUPERSAMPLE);
    let eps_b = scene.layer.binder_index.powi(2);
    let mut eps = Array3::zeros((grid.nz, grid.ny, grid.nx));
    let ctl = Controls {
        tolerance: path.tolerance,
        max_iterations: 50_000,
        precision: Precision::F64,
        background: path.shift.background,
    };
    for &lambda in &WAVELENGTHS_NM {
        let species = pipeline::fraction_eps(&scene, lambda).unwrap();
        raster.epsilon_into(C64::new(eps_b, 0.0), &species, &mut eps);
        for &polar in &POLAR_DEG {
            let lattice = Problem::lattice(
                [grid.nx, grid.ny, grid.nz],
                grid.size_nm,
                lambda,
                polar,
                0.0,
            );
            let p = Problem {
                tensor: None,
                lattice,
                eps: &eps,
                eps_binder: eps_b,
                wave: inksim::solver::Wave::Scalar,
            };
            let mut sys = System::with_params(&p, path.shift).unwrap();
            let mut scr = sys.scratch();
            let mut u = Field::zeros(ctl.precision, eps.dim());
            if path.from_ubg {
                sys.set_background_field(&mut u);
            } else {
                sys.set_start_field(&mut u);
            }
            let o = path
                .solver
                .run(&mut sys, &mut scr, &mut u, &ctl)
                .unwrap_or_else(|e| panic!("{layer} {name} {lambda} nm {polar}°: {e}"));
            let record = o.record(sys.background(), 0.0);
            let f = efficiencies(&sys.into_solution(scr, u, record));
            println!(
                "solve {lambda} {polar} {} {:e} {:e} {:e}",
                o.applications, f.total_reflectance, f.absorption, f.energy_balance
            );
        }
    }
    println!("cost {} {}", cpu_seconds(), peak_mb());
}

/// CPU seconds of this process, user + system, all threads.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap();
    let after = &stat[stat.rfind(')').unwrap() + 2..];
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks: f64 = f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap();
    ticks / 100.0
}

/// Peak resident memory of this process (VmHWM), MB.
fn peak_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status.lines().find(|l| l.starts_with("VmHWM")).unwrap();
    let kb: f64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kb / 1024.0
}

fn run_child(layer: &str, name: &str) -> Measured {
    let out = Command::new(std::env::current_exe().unwrap())
        .args(["--child", layer, name])
        .output()
        .expect("child runs");
    assert!(
        out.status.success(),
        "{layer} {name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut solves = vec![];
    let (mut cpu_s, mut peak_mb) = (f64::NAN, f64::NAN);
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        let num = |i: usize| w[i].parse::<f64>().unwrap();
        match w[0] {
            "solve" => solves.push(Solve {
                wavelength_nm: num(1),
                polar_deg: num(2),
                applications: w[3].parse().unwrap(),
                r: num(4),
                a: num(5),
                balance: num(6),
            }),
            "cost" => (cpu_s, peak_mb) = (num(1), num(2)),
            _ => {}
        }
    }
    Measured {
        solves,
        cpu_s,
        peak_mb,
    }
}

/// ΔE00 of the total-reflectance colour, largest over the angles.
fn delta_e(a: &[Solve], r: &[Solve], obs: &Observer) -> f64 {
    let lab = |s: &[Solve], polar: f64| {
        let refl: Vec<f64> = WAVELENGTHS_NM
            .iter()
            .map(|&w| {
                s.iter()
                    .find(|x| x.wavelength_nm == w && x.polar_deg == polar)
                    .expect("solve present")
                    .r
            })
            .collect();
        let xyz = colour::xyz_from_reflectance(obs, &WAVELENGTHS_NM, &refl).unwrap();
        colour::xyz_to_lab(xyz, obs.white_xyz())
    };
    POLAR_DEG
        .iter()
        .map(|&p| colour::delta_e2000(lab(a, p), lab(r, p)))
        .fold(0.0, f64::max)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--child") {
        child(&args[1], &args[2]);
        return;
    }
    let layers: Vec<&str> = if args.is_empty() {
        LAYERS.to_vec()
    } else {
        args.iter().map(String::as_str).collect()
    };
    let obs = Observer::standard(Illuminant::D50, StandardObserver::TwoDegree);
    println!(
        "{} wavelengths × {} angles per layer; reference: BiCGStab on the binder background to {:e}",
        WAVELENGTHS_NM.len(),
        POLAR_DEG.len(),
        REFERENCE.tolerance
    );
    println!();
    println!("| layer | path | applications | per solve (min–max) | CPU s | peak MB | max balance | max ΔR | max ΔA | ΔE00 | applications vs binder |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for layer in layers {
        let reference = run_child(layer, REFERENCE.name);
        let mut first = None;
        for path in &PATHS {
            let m = run_child(layer, path.name);
            let apps: Vec<usize> = m.solves.iter().map(|s| s.applications).collect();
            let total: usize = apps.iter().sum();
            let base = *first.get_or_insert(total);
            let max_of = |f: &dyn Fn(&Solve, &Solve) -> f64| {
                m.solves
                    .iter()
                    .zip(&reference.solves)
                    .map(|(a, b)| f(a, b))
                    .fold(0.0, f64::max)
            };
            println!(
                "| {layer} | {} | {total} | {}–{} | {:.1} | {:.0} | {:.1e} | {:.1e} | {:.1e} | {:.3} | {:.2}× |",
                path.name,
                apps.iter().min().unwrap(),
                apps.iter().max().unwrap(),
                m.cpu_s,
                m.peak_mb,
                max_of(&|a, _| a.balance.abs()),
                max_of(&|a, b| (a.r - b.r).abs()),
                max_of(&|a, b| (a.a - b.a).abs()),
                delta_e(&m.solves, &reference.solves, &obs),
                base as f64 / total as f64,
            );
        }
    }
}
