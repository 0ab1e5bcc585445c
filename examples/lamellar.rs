//! The peers' problem of issue 7 (docs/PEERS.md): a y-invariant lamellar
//! grating at normal incidence, λ = 550 nm, period 4 µm, a 1 µm binder slab
//! (n = 1.558) with one 0.4 µm stripe of n = 2 + 0.8i through its full
//! thickness, vacuum above and below. Scalar = TE, so one y sample is exact.
//!
//! For each lateral cell (nm; the z cell is the same unless `--dz` is given)
//! and method it solves once and prints one line per solve:
//! `RESULT {json}` with the grid, method used, iterations, operator
//! applications, relative residual, wall time and R_m, T_m for m = −3..3.
//! scripts/peers.py parses these lines.
//!
//! `cargo run --release --example lamellar -- [--tol 1e-8]
//!  [--methods auto,gmres,bicgstab] [--dz nm] [cell_nm ...]`
//! (default cells: 40 20 10 5).

use inksim::config::Method;
use inksim::optics::farfield::efficiencies;
use inksim::solver::{self, Controls, Problem};
use ndarray::{s, Array3};
use num_complex::Complex64 as C64;
use std::time::Instant;

const WAVELENGTH: f64 = 550.0;
const PERIOD: f64 = 4000.0;
const THICKNESS: f64 = 1000.0;
const STRIPE_X0: f64 = 0.0;
const STRIPE_WIDTH: f64 = 400.0;
const N_BINDER: f64 = 1.558;
const N_STRIPE: C64 = C64::new(2.0, 0.8);
const ORDERS: std::ops::RangeInclusive<i32> = -3..=3;

fn method_of(name: &str) -> Result<Method, String> {
    Method::from_config_name(name).ok_or_else(|| {
        format!(
            "--methods: `{name}` is not one of {}",
            Method::config_names().join(", ")
        )
    })
}

struct Args {
    tolerance: f64,
    methods: Vec<(String, Method)>,
    dz: Option<f64>,
    cells: Vec<f64>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        tolerance: 1e-8,
        methods: vec![("auto".into(), Method::Auto)],
        dz: None,
        cells: vec![],
    };
    let mut it = std::env::args().skip(1);
    let num = |key: &str, v: Option<String>| -> Result<f64, String> {
        let v = v.ok_or_else(|| format!("{key}: value missing"))?;
        v.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite() && *x > 0.0)
            .ok_or_else(|| format!("{key}: `{v}` is not a positive number"))
    };
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--tol" => a.tolerance = num("--tol", it.next())?,
            "--dz" => a.dz = Some(num("--dz", it.next())?),
            "--methods" => {
                let v = it.next().ok_or("--methods: value missing")?;
                a.methods = v
                    .split(',')
                    .map(|m| method_of(m).map(|x| (m.to_string(), x)))
                    .collect::<Result<_, _>>()?;
            }
            _ => a.cells.push(num("cell_nm", Some(arg))?),
        }
    }
    if a.cells.is_empty() {
        a.cells = vec![40.0, 20.0, 10.0, 5.0];
    }
    Ok(a)
}

/// Number of cells of size `cell` in `length`, which must divide exactly.
fn cells_in(length: f64, cell: f64, what: &str) -> Result<usize, String> {
    let n = (length / cell).round();
    if n < 1.0 || (n * cell - length).abs() > 1e-9 * length {
        return Err(format!(
            "{what} cell {cell} nm does not divide {length} nm exactly"
        ));
    }
    Ok(n as usize)
}

/// ε on an (nz, 1, nx) grid: binder with the stripe on [x0, x0 + w).
fn epsilon(nx: usize, nz: usize) -> Array3<C64> {
    let dx = PERIOD / nx as f64;
    let mut eps = Array3::from_elem((nz, 1, nx), C64::new(N_BINDER * N_BINDER, 0.0));
    for ix in 0..nx {
        let x = (ix as f64 + 0.5) * dx;
        if (STRIPE_X0..STRIPE_X0 + STRIPE_WIDTH).contains(&x) {
            eps.slice_mut(s![.., 0, ix]).fill(N_STRIPE * N_STRIPE);
        }
    }
    eps
}

fn run(a: &Args) -> Result<(), String> {
    println!(
        "lamellar grating: λ {WAVELENGTH} nm, period {PERIOD} nm, slab {THICKNESS} nm \
         (n {N_BINDER}), stripe {STRIPE_WIDTH} nm of n {N_STRIPE}, tolerance {:.0e}",
        a.tolerance
    );
    let ctl = Controls {
        tolerance: a.tolerance,
        max_iterations: 20_000,
        precision: inksim::config::Precision::F64,
        background: inksim::config::Background::DEFAULT,
    };
    for &cell in &a.cells {
        let nx = cells_in(PERIOD, cell, "lateral")?;
        // The stripe edges must lie on cell boundaries.
        cells_in(STRIPE_WIDTH, cell, "lateral (stripe)")?;
        let dz = a.dz.unwrap_or(cell);
        let nz = cells_in(THICKNESS, dz, "z")?;
        let eps = epsilon(nx, nz);
        let lattice = Problem::lattice(
            [nx, 1, nz],
            [PERIOD, PERIOD, THICKNESS],
            WAVELENGTH,
            0.0,
            0.0,
        );
        let p = Problem {
            tensor: None,
            lattice,
            eps: &eps,
            eps_binder: N_BINDER * N_BINDER,
            wave: inksim::solver::Wave::Scalar,
        };
        for (name, method) in &a.methods {
            let start = Instant::now();
            let sol = solver::solve(&p, *method, &ctl)
                .map_err(|e| format!("cell {cell} nm, {name}: {e}"))?;
            let ff = efficiencies(&sol);
            let wall = start.elapsed().as_secs_f64();
            let pick = |f: fn(&inksim::optics::farfield::Order) -> f64| -> Vec<String> {
                ORDERS
                    .map(|m| {
                        ff.orders
                            .iter()
                            .find(|o| o.m == m && o.n == 0)
                            .map_or("null".to_string(), |o| format!("{:.12e}", f(o)))
                    })
                    .collect()
            };
            let r = &sol.record;
            println!(
                "{name:>8} dx {cell:>5} nm dz {dz:>5} nm ({nx}×{nz}): {} {} iterations, \
                 {} applications, residual {:.1e}, {wall:.3} s, R0 {:.6} T0 {:.6}, balance {:.1e}",
                r.method,
                r.iterations,
                r.operator_applications,
                r.residual,
                ff.orders
                    .iter()
                    .find(|o| o.m == 0 && o.n == 0)
                    .map_or(f64::NAN, |o| o.reflectance),
                ff.orders
                    .iter()
                    .find(|o| o.m == 0 && o.n == 0)
                    .map_or(f64::NAN, |o| o.transmittance),
                ff.energy_balance
            );
            println!(
                "RESULT {{\"requested\":\"{name}\",\"method\":\"{}\",\"dx_nm\":{cell},\"dz_nm\":{dz},\
                 \"nx\":{nx},\"nz\":{nz},\"tolerance\":{:e},\"iterations\":{},\"applications\":{},\
                 \"residual\":{:e},\"seconds\":{wall},\"solver_seconds\":{},\"energy_balance\":{:e},\
                 \"m\":[{}],\"R\":[{}],\"T\":[{}],\"note\":{:?}}}",
                r.method,
                a.tolerance,
                r.iterations,
                r.operator_applications,
                r.residual,
                r.seconds,
                ff.energy_balance,
                ORDERS.map(|m| m.to_string()).collect::<Vec<_>>().join(","),
                pick(|o| o.reflectance).join(","),
                pick(|o| o.transmittance).join(","),
                r.note
            );
        }
    }
    Ok(())
}

fn main() {
    if let Err(e) = parse_args().and_then(|a| run(&a)) {
        eprintln!("lamellar: {e}");
        std::process::exit(2);
    }
}
