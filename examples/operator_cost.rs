//! Wall time of one application of each operator against the 2-D FFT pair it
//! contains, on one grid (docs/PERFORMANCE.md).
//!
//! `cargo run --release --example operator_cost [n] [nz] [reps]`

use inksim::solver::fft::Fft2;
use inksim::solver::operator::{GreenTable, Operator};
use inksim::solver::shift::ShiftTable;
use inksim::solver::Problem;
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::time::Instant;

fn main() {
    let arg = |i: usize, d: usize| {
        std::env::args()
            .nth(i)
            .and_then(|s| s.parse().ok())
            .unwrap_or(d)
    };
    let (n, nz, reps) = (arg(1, 128), arg(2, 64), arg(3, 20));
    let size = 10.0 * n as f64;
    let lat = Problem::lattice([n, n, nz], [size, size, 1000.0], 500.0, 30.0, 0.0);
    let eb = 1.558f64.powi(2);
    let op = Operator::new(lat);
    let gb = GreenTable::new(&lat, C64::new(eb, 0.0));
    let c = lat.k0 * lat.k0 * C64::new(2.0 - eb, 0.8);
    let gs = ShiftTable::new(&lat, eb, c);
    let mut ws = op.workspace();
    let mut u = Array3::from_shape_fn((nz, n, n), |(k, j, i)| {
        C64::new((i + 2 * j) as f64 * 0.01, (k as f64 * 0.1).sin())
    });
    let time = |f: &mut dyn FnMut()| {
        f();
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        t.elapsed().as_secs_f64() * 1e3 / reps as f64
    };
    let fft = Fft2::new(n, n);
    let mut scr = fft.scratch(nz);
    let mut spec = Array3::zeros((nz, n, n));
    let mut v = u.clone();
    let t_fft = time(&mut || {
        fft.forward(&mut v, &mut spec, &mut scr);
        fft.inverse(&mut spec, &mut v, &mut scr);
    });
    let t_gb = time(&mut || op.apply(&gb, &mut u, &mut ws));
    let t_gs = time(&mut || op.apply_shifted_green(&gs, &mut u, &mut ws));
    println!(
        "grid {n}×{n}×{nz}, {} threads",
        rayon::current_num_threads()
    );
    println!("FFT pair      {t_fft:8.2} ms");
    println!("G_b apply     {t_gb:8.2} ms  ({:.2}× FFT)", t_gb / t_fft);
    println!("G_s apply     {t_gs:8.2} ms  ({:.2}× FFT)", t_gs / t_fft);
}
