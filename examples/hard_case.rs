//! The hard case of issue 7: 50 % PVC, n = 1.4 + 0.8i, 300 nm grains, 1 µm
//! layer, λ = 450 nm, 40° incidence. Operator applications each method needs
//! for relative residual 1e-6 (docs/PERFORMANCE.md).
//!
//! Geometry: 300 nm spheres packed to 50 % PVC by the first-order dynamics
//! packer in a `side × side × 1000 nm` fragment.
//!
//! `cargo run --release --example hard_case [side_nm] [seed]`

use inksim::config::Method;
use inksim::farfield::efficiencies;
use inksim::geometry::{pack_dynamics, DynParams, DynSpecies, Orientation, Shape};
use inksim::raster::{rasterize, Grid};
use inksim::solver::{self, Controls, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;

fn main() {
    let side: f64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1280.0);
    let seed: u64 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let size = [side, side, 1000.0];
    let species = vec![DynSpecies {
        shape: Shape::Sphere,
        effective_diameter_nm: 300.0,
        volume_fraction: 0.5,
        orientation: Orientation::Random,
        field: 0.0,
    }];
    let geom = pack_dynamics(&DynParams::new(size, species), seed).expect("packing");
    let n_p = geom.particles.len();
    let frac = geom.stats.achieved_fraction[0];
    let nxy = (side / 20.0).round() as usize;
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
                precision: inksim::config::Precision::F64,
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
    // Unrestarted GMRES (restart longer than the iteration count).
    let mut sys = solver::System::new(&p).expect("system");
    let mut u = Array3::<C64>::zeros(eps.dim());
    sys.set_background(&mut u);
    let t = std::time::Instant::now();
    let g = solver::gmres::Gmres { restart: 80 };
    match solver::IterativeMethod::run(
        &g,
        &mut sys,
        &mut u,
        &Controls {
            tolerance: 1e-6,
            max_iterations: 50_000,
            precision: inksim::config::Precision::F64,
        },
    ) {
        Ok(o) => println!(
            "| gmres(80) | {} | {} | {:.1} | | | |",
            o.iterations,
            o.applications,
            t.elapsed().as_secs_f64()
        ),
        Err(e) => println!("| gmres(80) | — | — | — | {e} | | |"),
    }
}
