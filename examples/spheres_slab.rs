//! A square lattice of spheres in a binder slab, solved with Maxwell's
//! equations (docs/PEERS.md, "Maxwell: spheres in a slab against a T-matrix
//! code"; the exact reference is scripts/treams_reference.py).
//!
//! Vacuum above and below a slab `0 ≤ z ≤ H` of binder (n = 1.558) with
//! the given spheres in each `L × L` cell, lit from above at polar angle θ
//! (azimuth 0, plane of incidence x-z) in s or p. The spheres are
//! rasterised by volume fraction (`inksim::raster`, 4³ sub-samples in the
//! voxels the surface cuts), the cut voxels anisotropic (the default of a
//! Maxwell run; `--voxels average` for volume averaging). For each cell
//! size it prints one
//! `RESULT {json}` line: grid, iterations, CPU and wall seconds (CPU of the
//! raster + solve + far field, this process), and R, T of every
//! propagating order (both outgoing polarisations summed) and absorption.
//!
//! `cargo run --release --example spheres_slab -- --period 800 --thickness 600
//!  --polar 45 --pol p --sphere 400,400,300,150,1.4,0.7 [--sphere ...]
//!  [--tol 1e-8] [--supersample 4] [--voxels anisotropic|average] 20 10`
//! (sphere: x, y, z, radius in nm, then n' and n'' relative to vacuum;
//! cells in nm, equal in x, y and z; each must divide L and H.)

use inksim::config::{Linear, Method};
use inksim::geometry::{Geometry, Particle, Sphere};
use inksim::optics::farfield::efficiencies;
use inksim::raster::{rasterize, Grid};
use inksim::solver::{self, Controls, Problem, Wave};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::time::Instant;

const WAVELENGTH: f64 = 550.0;
const N_BINDER: f64 = 1.558;

struct Args {
    period: f64,
    thickness: f64,
    polar: f64,
    pol: Linear,
    spheres: Vec<([f64; 3], f64, C64)>,
    tolerance: f64,
    supersample: usize,
    anisotropic: bool,
    cells: Vec<f64>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        period: 800.0,
        thickness: 600.0,
        polar: 0.0,
        pol: Linear::S,
        spheres: vec![],
        tolerance: 1e-8,
        supersample: 4,
        anisotropic: true,
        cells: vec![],
    };
    let mut it = std::env::args().skip(1);
    let num = |key: &str, v: Option<String>| -> Result<f64, String> {
        let v = v.ok_or_else(|| format!("{key}: value missing"))?;
        v.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{key}: `{v}` is not a number"))
    };
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--period" => a.period = num("--period", it.next())?,
            "--thickness" => a.thickness = num("--thickness", it.next())?,
            "--polar" => a.polar = num("--polar", it.next())?,
            "--tol" => a.tolerance = num("--tol", it.next())?,
            "--supersample" => a.supersample = num("--supersample", it.next())? as usize,
            "--voxels" => {
                a.anisotropic = match it.next().as_deref() {
                    Some("anisotropic") => true,
                    Some("average") => false,
                    v => return Err(format!("--voxels: {v:?} is not anisotropic or average")),
                }
            }
            "--pol" => {
                a.pol = match it.next().as_deref() {
                    Some("s") => Linear::S,
                    Some("p") => Linear::P,
                    v => return Err(format!("--pol: {v:?} is not s or p")),
                }
            }
            "--sphere" => {
                let v = it.next().ok_or("--sphere: value missing")?;
                let f: Vec<f64> = v
                    .split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|e| format!("--sphere {v}: {e}"))?;
                let [x, y, z, r, n, k] = f[..] else {
                    return Err(format!("--sphere {v}: six numbers expected"));
                };
                a.spheres.push(([x, y, z], r, C64::new(n, k)));
            }
            _ => a.cells.push(num("cell_nm", Some(arg))?),
        }
    }
    if a.spheres.is_empty() {
        return Err("no --sphere given".into());
    }
    if a.cells.is_empty() {
        a.cells = vec![20.0, 10.0];
    }
    Ok(a)
}

/// Number of cells of size `cell` in `length`, which must divide exactly.
fn cells_in(length: f64, cell: f64) -> Result<usize, String> {
    let n = (length / cell).round();
    if n < 1.0 || (n * cell - length).abs() > 1e-9 * length {
        return Err(format!("cell {cell} nm does not divide {length} nm"));
    }
    Ok(n as usize)
}

/// CPU seconds (user + system) of this process so far.
fn cpu_seconds() -> f64 {
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

fn run(a: &Args) -> Result<(), String> {
    // One species per sphere: each gets its own permittivity.
    let geom = Geometry {
        size_nm: [a.period, a.period, a.thickness],
        particles: a
            .spheres
            .iter()
            .enumerate()
            .map(|(i, (c, r, _))| Particle {
                species: i,
                spheres: vec![Sphere {
                    center: *c,
                    radius: *r,
                }],
            })
            .collect(),
        stats: Default::default(),
    };
    let eps_s: Vec<C64> = a.spheres.iter().map(|s| s.2 * s.2).collect();
    let eps_b = N_BINDER * N_BINDER;
    let ctl = Controls {
        tolerance: a.tolerance,
        max_iterations: 20_000,
        precision: inksim::config::Precision::F64,
        background: inksim::config::Background::DEFAULT,
    };
    for &cell in &a.cells {
        let (n, nz) = (cells_in(a.period, cell)?, cells_in(a.thickness, cell)?);
        let (cpu0, wall0) = (cpu_seconds(), Instant::now());
        let grid = Grid {
            nx: n,
            ny: n,
            nz,
            size_nm: geom.size_nm,
        };
        let raster = rasterize(&geom, &grid, a.supersample);
        let mut eps = Array3::zeros((nz, n, n));
        raster.epsilon_into(C64::new(eps_b, 0.0), &eps_s, &mut eps);
        let mut tensor = inksim::raster::Anisotropy::default();
        if a.anisotropic {
            raster.anisotropy_into(
                C64::new(eps_b, 0.0),
                &eps_s,
                &[],
                true,
                &mut eps,
                &mut tensor,
            );
        }
        let lattice = Problem::lattice(
            [n, n, nz],
            [a.period, a.period, a.thickness],
            WAVELENGTH,
            a.polar,
            0.0,
        );
        let p = Problem {
            tensor: Some(&tensor),
            lattice,
            eps: &eps,
            eps_binder: eps_b,
            wave: Wave::Vector {
                polarisation: a.pol.into(),
                azimuth_deg: 0.0,
            },
        };
        let sol = solver::solve(&p, Method::Auto, &ctl).map_err(|e| format!("{cell} nm: {e}"))?;
        let ff = efficiencies(&sol);
        let (cpu, wall) = (cpu_seconds() - cpu0, wall0.elapsed().as_secs_f64());
        let r = &sol.record;
        let orders: Vec<String> = ff
            .orders
            .iter()
            .map(|o| {
                format!(
                    "[{},{},{:.12e},{:.12e}]",
                    o.m, o.n, o.reflectance, o.transmittance
                )
            })
            .collect();
        println!(
            "cell {cell} nm ({n}×{n}×{nz}, {} voxels): {} {} iterations, {} applications, \
             {cpu:.2} CPU s, {wall:.2} s, R {:.6} T {:.6} A {:.6}, balance {:.1e}",
            if a.anisotropic {
                "anisotropic"
            } else {
                "average"
            },
            r.method,
            r.iterations,
            r.operator_applications,
            ff.total_reflectance,
            ff.total_transmittance,
            ff.absorption,
            ff.energy_balance
        );
        println!(
            "RESULT {{\"cell_nm\":{cell},\"nx\":{n},\"nz\":{nz},\"method\":\"{}\",\
             \"iterations\":{},\"applications\":{},\"tolerance\":{:e},\"cpu_seconds\":{cpu},\
             \"wall_seconds\":{wall},\"R\":{},\"T\":{},\"A\":{},\"energy_balance\":{:e},\
             \"orders\":[{}]}}",
            r.method,
            r.iterations,
            r.operator_applications,
            a.tolerance,
            ff.total_reflectance,
            ff.total_transmittance,
            ff.absorption,
            ff.energy_balance,
            orders.join(",")
        );
    }
    Ok(())
}

fn main() {
    if let Err(e) = parse_args().and_then(|a| run(&a)) {
        eprintln!("spheres_slab: {e}");
        std::process::exit(2);
    }
}
