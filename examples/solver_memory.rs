//! Peak memory of one solve, per method and field precision
//! (docs/PERFORMANCE.md, "Memory").
//!
//! `cargo run --release --example solver_memory -- <method> <f64|f32> <nx> <ny> <nz> [iterations] [helmholtz|maxwell]`
//!
//! With `maxwell`, the solve is Maxwell's equations in s polarisation
//! (three field components per voxel).
//!
//! Builds a permittivity grid of the given size (a 10 nm-cell layer of
//! absorbing blocks in binder; the content does not change the memory),
//! runs the method for a few iterations (a `NotConverged` outcome is
//! expected and fine) and prints the process's peak resident memory
//! (`VmHWM`) before and after, in bytes per voxel. The grid itself
//! (complex f64, 16 B/voxel, owned by the caller as in the pipeline) is
//! included in the "after" figure and reported apart.

use inksim::config::{Method, Precision};
use inksim::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::time::Instant;

/// Peak resident set size of this process, bytes (Linux).
fn peak_rss() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    let line = status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .expect("VmHWM line");
    let kb: f64 = line
        .split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .expect("VmHWM value");
    kb * 1024.0
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 5 {
        eprintln!(
            "usage: solver_memory <born|time-marching|gmres|bicgstab> <f64|f32> <nx> <ny> <nz> [iterations] [helmholtz|maxwell]"
        );
        std::process::exit(2);
    }
    let method =
        Method::from_config_name(&args[0]).unwrap_or_else(|| panic!("unknown method {}", args[0]));
    let precision = match args[1].as_str() {
        "f64" => Precision::F64,
        "f32" => Precision::F32,
        p => panic!("unknown precision {p}"),
    };
    let n: Vec<usize> = args[2..5]
        .iter()
        .map(|a| a.parse().expect("size"))
        .collect();
    let iterations: usize = args.get(5).map_or(3, |a| a.parse().expect("iterations"));
    let wave = match args.get(6).map(String::as_str) {
        None | Some("helmholtz") => inksim::solver::Wave::Scalar,
        Some("maxwell") => inksim::solver::Wave::Vector {
            polarisation: inksim::config::Linear::S.into(),
            azimuth_deg: 0.0,
        },
        Some(e) => panic!("unknown equation {e}"),
    };
    let (nx, ny, nz) = (n[0], n[1], n[2]);
    let voxels = (nx * ny * nz) as f64;
    let base = peak_rss();
    let eb = 1.5f64.powi(2);
    let grain = C64::new(1.4, 0.8) * C64::new(1.4, 0.8);
    let eps = Array3::from_shape_fn((nz, ny, nx), |(k, j, i)| {
        if (i / 10 + j / 10 + k / 10) % 3 == 0 {
            grain
        } else {
            C64::new(eb, 0.0)
        }
    });
    let with_grid = peak_rss();
    let size = [10.0 * nx as f64, 10.0 * ny as f64, 10.0 * nz as f64];
    let p = Problem {
        tensor: None,
        lattice: Problem::lattice([nx, ny, nz], size, 450.0, 40.0, 0.0),
        eps: &eps,
        eps_binder: eb,
        wave,
    };
    let ctl = Controls {
        tolerance: 1e-6,
        max_iterations: iterations,
        precision,
        background: inksim::config::Background::DEFAULT,
    };
    let t = Instant::now();
    let outcome = match solver::solve(&p, method, &ctl) {
        Ok(s) => format!("converged in {} iterations", s.record.iterations),
        Err(e) => format!("{e}"),
    };
    let peak = peak_rss();
    println!(
        "{} {} {}x{}x{} ({:.3e} voxels): {:.1} s; {outcome}",
        args[0],
        args[1],
        nx,
        ny,
        nz,
        voxels,
        t.elapsed().as_secs_f64()
    );
    println!(
        "peak {:.2} GB; solver {:.1} B/voxel (+ the caller's ε grid {:.1} B/voxel)",
        peak / 1e9,
        (peak - with_grid) / voxels,
        (with_grid - base) / voxels
    );
}
