//! The hard case of issue 7: 50 % PVC, n = 1.4 + 0.8i, 300 nm grains, 1 µm
//! layer, λ = 450 nm, 40° incidence. Operator applications each method needs
//! for relative residual 1e-6 (docs/PERFORMANCE.md).
//!
//! Geometry: 300 nm spheres on a jittered simple-cubic lattice, 50 % within
//! the lattice (three layers fill 914 nm of the 1 µm layer: 45.7 % overall).
//!
//! `cargo run --release --example hard_case [cells_per_side]`

use inksim::config::Method;
use inksim::farfield::efficiencies;
use inksim::geometry::{Geometry, GeometryStats, Particle, Sphere};
use inksim::raster::{rasterize, Grid};
use inksim::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use rand::{Rng, SeedableRng};

fn main() {
    let per_side: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    let d = 300.0;
    let a = d * (std::f64::consts::PI / (6.0 * 0.5)).cbrt();
    let (layers, h) = (3usize, 1000.0);
    let size = [a * per_side as f64, a * per_side as f64, h];
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let slack = (a - d) / 2.0;
    let z0 = (h - layers as f64 * a) / 2.0;
    let mut particles = vec![];
    for i in 0..per_side {
        for j in 0..per_side {
            for k in 0..layers {
                let jit = |r: &mut rand_xoshiro::Xoshiro256PlusPlus| r.gen_range(-slack..=slack);
                let c = [
                    (i as f64 + 0.5) * a + jit(&mut rng),
                    (j as f64 + 0.5) * a + jit(&mut rng),
                    z0 + (k as f64 + 0.5) * a + jit(&mut rng),
                ];
                particles.push(Particle {
                    species: 0,
                    spheres: vec![Sphere {
                        center: c,
                        radius: d / 2.0,
                    }],
                });
            }
        }
    }
    let n_p = particles.len();
    let frac = n_p as f64 * std::f64::consts::PI * d.powi(3) / 6.0 / (size[0] * size[1] * size[2]);
    let stats = GeometryStats {
        count: vec![n_p],
        target_fraction: vec![frac],
        achieved_fraction: vec![frac],
        min_gap_nm: 0.0,
        attempts: n_p as u64,
        ..Default::default()
    };
    let geom = Geometry {
        size_nm: size,
        particles,
        stats,
    };
    let nxy = 16 * per_side;
    let grid = Grid {
        nx: nxy,
        ny: nxy,
        nz: 100,
        size_nm: size,
    };
    let raster = rasterize(&geom, &grid, 4);
    let eps_b = 1.558f64.powi(2);
    let n = C64::new(1.4, 0.8);
    let mut eps = Array3::zeros((grid.nz, grid.ny, grid.nx));
    raster.epsilon_into(C64::new(eps_b, 0.0), &[n * n], &mut eps);
    let lat = Problem::lattice([grid.nx, grid.ny, grid.nz], size, 450.0, 40.0, 0.0);
    let p = Problem {
        lattice: lat,
        eps: &eps,
        eps_binder: eps_b,
    };
    println!(
        "hard case: {n_p} spheres of 300 nm, PVC {:.3} (layer {:.3}), grid {}×{}×{}, λ 450 nm, 40°",
        frac,
        raster.mean_fractions()[0],
        grid.nx,
        grid.ny,
        grid.nz
    );
    println!("| method | iterations | operator applications | seconds | R | A | balance |");
    println!("|---|---|---|---|---|---|---|");
    for method in [
        Method::Born,
        Method::TimeMarching,
        Method::Gmres,
        Method::BiCgStab,
    ] {
        match solver::solve(
            &p,
            method,
            &Controls {
                tolerance: 1e-6,
                max_iterations: 50_000,
            },
        ) {
            Ok(s) => {
                let ff = efficiencies(&s);
                println!(
                    "| {} | {} | {} | {:.1} | {:.5} | {:.5} | {:.1e} |",
                    s.record.method,
                    s.record.iterations,
                    s.record.operator_applications,
                    s.record.seconds,
                    ff.total_reflectance,
                    ff.absorption,
                    ff.energy_balance
                );
            }
            Err(e) => println!("| {method:?} | — | — | — | {e} | | |"),
        }
    }
}
