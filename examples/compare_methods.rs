//! Every solver method on the demo layer's solves: iterations, operator
//! applications, wall time and the answer (docs/PERFORMANCE.md).
//!
//! `cargo run --release --example compare_methods [config] [tolerance]`

use inksim::config::{load_scene, Method};
use inksim::optics::farfield::efficiencies;
use inksim::pipeline::{build_geometry, grid_of, SUPERSAMPLE};
use inksim::raster::rasterize;
use inksim::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let path = PathBuf::from(
        args.get(1)
            .map(String::as_str)
            .unwrap_or("configs/demo.toml"),
    );
    let tolerance: f64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(1e-6);
    let scene = load_scene(&path)?;
    let geometry = build_geometry(&scene)?;
    let grid = grid_of(&scene);
    let raster = rasterize(&geometry, &grid, SUPERSAMPLE);
    let eps_b = scene.layer.binder_index.powi(2);
    let ctl = Controls {
        tolerance,
        max_iterations: 20_000,
        precision: inksim::config::Precision::F64,
        background: inksim::config::Background::DEFAULT,
    };
    println!(
        "{}: grid {}×{}×{}, tolerance {tolerance:.0e}",
        path.display(),
        grid.nx,
        grid.ny,
        grid.nz
    );
    println!("| λ nm | θ° | method | iterations | G applications | seconds | R | A | balance |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut eps = Array3::zeros((grid.nz, grid.ny, grid.nx));
    for &lambda in &scene.wavelengths_nm {
        let n = scene.species[0]
            .material
            .index_at(lambda)
            .expect("validated");
        raster.epsilon_into(C64::new(eps_b, 0.0), &[n * n], &mut eps);
        for inc in &scene.incidence {
            let lat = Problem::lattice(
                [grid.nx, grid.ny, grid.nz],
                grid.size_nm,
                lambda,
                inc.polar_deg,
                inc.azimuth_deg,
            );
            let p = Problem {
                tensor: None,
                lattice: lat,
                eps: &eps,
                eps_binder: eps_b,
                wave: inksim::solver::Wave::Scalar,
            };
            for method in [
                Method::Born,
                Method::TimeMarching,
                Method::Gmres,
                Method::BiCgStab,
            ] {
                match solver::solve(&p, method, &ctl) {
                    Ok(s) => {
                        let ff = efficiencies(&s);
                        println!(
                            "| {lambda} | {} | {} | {} | {} | {:.2} | {:.6} | {:.6} | {:.1e} |",
                            inc.polar_deg,
                            s.record.method,
                            s.record.iterations,
                            s.record.operator_applications,
                            s.record.seconds,
                            ff.total_reflectance,
                            ff.absorption,
                            ff.energy_balance
                        );
                    }
                    Err(e) => println!(
                        "| {lambda} | {} | {method:?} | — | — | — | {e} | | |",
                        inc.polar_deg
                    ),
                }
            }
        }
    }
    Ok(())
}
