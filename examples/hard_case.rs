//! The hard case of issue 7: 50 % PVC, n = 1.4 + 0.8i, 300 nm grains, 1 µm
//! layer, λ = 450 nm, 40° incidence. Operator applications each method needs
//! for relative residual 1e-6 (docs/PERFORMANCE.md).
//!
//! Geometry: 300 nm spheres packed to 50 % PVC by the first-order dynamics
//! packer in a `side × side × 1000 nm` fragment.
//!
//! `cargo run --release --example hard_case [side_nm] [seed]`

use inksim::config::{Background, Method, Precision};
use inksim::geometry::{pack_dynamics, DynParams, DynSpecies, Orientation, Shape};
use inksim::optics::farfield::efficiencies;
use inksim::raster::{rasterize, Grid};
use inksim::solver::methods::{bicgstab, gmres, marching};
use inksim::solver::{self, Controls, Field, Problem, ShiftParams, Solver, System, SHIFT_MARGIN};
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
        tensor: None,
        lattice: lat,
        eps: &eps,
        eps_binder: eps_b,
        wave: inksim::solver::Wave::Scalar,
    };
    println!(
        "hard case: {n_p} spheres of 300 nm, PVC {:.3} (layer {:.3}), grid {}×{}×{}, λ 450 nm, 40°",
        frac,
        raster.mean_fractions()[0],
        grid.nx,
        grid.ny,
        grid.nz
    );
    let ctl = Controls {
        tolerance: 1e-6,
        max_iterations: 50_000,
        precision: Precision::F64,
        background: inksim::config::Background::DEFAULT,
    };
    println!("| method | CBS shift margin | iterations | operator applications | seconds | R | A | balance |");
    println!("|---|---|---|---|---|---|---|---|");
    match solver::solve(&p, Method::Born, &ctl) {
        Ok(s) => println!(
            "| born | — | {} | {} | | | | |",
            s.record.iterations, s.record.operator_applications
        ),
        Err(e) => println!("| born | — | — | — | {e} | | | |"),
    }
    // (label, margin, method): plain CBS time-marching is Osnabrugge's
    // ε_s = max|ε − ε_r| (margin 1; 1.01 so the extreme voxels contract).
    let tm = marching::TimeMarching::DEFAULT;
    let g20 = gmres::Gmres::DEFAULT;
    let g80 = gmres::Gmres { restart: 80 };
    let bi = bicgstab::BiCgStab::DEFAULT;
    let runs: [(&str, f64, &dyn Solver); 10] = [
        ("time-marching (plain CBS)", 1.01, &tm),
        ("time-marching (default)", SHIFT_MARGIN, &tm),
        ("time-marching", 1.2, &tm),
        ("gmres(20)", 1.01, &g20),
        ("gmres(20)", SHIFT_MARGIN, &g20),
        ("bicgstab", 1.01, &bi),
        ("bicgstab", SHIFT_MARGIN, &bi),
        ("gmres(80)", 1.01, &g80),
        ("gmres(80)", SHIFT_MARGIN, &g80),
        ("gmres(80)", 1.2, &g80),
    ];
    let mut counts = Vec::new();
    for (label, margin, method) in runs {
        let mut sys = System::with_params(
            &p,
            ShiftParams {
                margin,
                ..ShiftParams::of(Background::Binder)
            },
        )
        .expect("system");
        let mut scr = sys.scratch();
        let mut u = Field::F64(Array3::<C64>::zeros(eps.dim()));
        sys.set_background_field(&mut u);
        let t = std::time::Instant::now();
        match method.run(&mut sys, &mut scr, &mut u, &ctl) {
            Ok(o) => {
                let record = o.record(sys.background(), t.elapsed().as_secs_f64());
                let ff = efficiencies(&sys.into_solution(scr, u, record));
                println!(
                    "| {label} | {margin} | {} | {} | {:.1} | {:.5} | {:.5} | {:.1e} |",
                    o.iterations,
                    o.applications,
                    t.elapsed().as_secs_f64(),
                    ff.total_reflectance,
                    ff.absorption,
                    ff.energy_balance
                );
                counts.push((label, margin, o.applications));
            }
            Err(e) => println!("| {label} | {margin} | — | — | — | {e} | | |"),
        }
    }
    let plain = counts[0].2 as f64;
    let tuned = counts[1].2 as f64;
    for (label, margin, n) in &counts[3..] {
        println!(
            "{label} at margin {margin}: {:.1}× fewer applications than plain CBS time-marching, {:.1}× than the default-margin time-marching",
            plain / *n as f64,
            tuned / *n as f64
        );
    }
}
