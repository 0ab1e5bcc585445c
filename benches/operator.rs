//! One application of the background Green's operator `G_b` and of the
//! shifted operator `G_s` (what the CBS-based methods apply) against the
//! batched 2-D FFTs they contain (forward + inverse over every z-slice). The ratio
//! operator/FFT is the figure of merit (docs/PERFORMANCE.md).
//!
//! `cargo bench --bench operator` (256 × 256 × 64 and 512 × 512 × 96; the
//! larger grid needs about 3 GB).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use inksim::solver::fft::Fft2;
use inksim::solver::operator::{GreenTable, Operator};
use inksim::solver::shift::ShiftTable;
use inksim::solver::Problem;
use ndarray::Array3;
use num_complex::Complex64 as C64;

fn field(nz: usize, ny: usize, nx: usize) -> Array3<C64> {
    Array3::from_shape_fn((nz, ny, nx), |(k, j, i)| {
        C64::new((i + 2 * j) as f64 * 0.01, (k as f64 * 0.1).sin())
    })
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("operator");
    g.sample_size(10);
    for &(n, nz) in &[(256usize, 64usize), (512, 96)] {
        let lat = Problem::lattice(
            [n, n, nz],
            [2560.0 * n as f64 / 256.0, 2560.0 * n as f64 / 256.0, 1000.0],
            500.0,
            30.0,
            0.0,
        );
        let op = Operator::new(lat);
        let table = GreenTable::new(&lat, C64::new(1.558f64.powi(2), 0.0));
        let mut ws = op.workspace();
        let mut u = field(nz, n, n);
        g.bench_with_input(
            BenchmarkId::new("apply", format!("{n}x{n}x{nz}")),
            &(),
            |b, _| b.iter(|| op.apply(&table, &mut u, &mut ws)),
        );
        let c = lat.k0 * lat.k0 * C64::new(2.0 - 1.558f64.powi(2), 0.8);
        let shifted = ShiftTable::new(&lat, 1.558f64.powi(2), c);
        g.bench_with_input(
            BenchmarkId::new("apply_shifted", format!("{n}x{n}x{nz}")),
            &(),
            |b, _| b.iter(|| op.apply_shifted_green(&shifted, &mut u, &mut ws)),
        );
        let fft = Fft2::new(n, n);
        let mut scr = fft.scratch(nz);
        let mut spec = Array3::zeros((nz, n, n));
        let mut v = field(nz, n, n);
        g.bench_with_input(
            BenchmarkId::new("fft_pair", format!("{n}x{n}x{nz}")),
            &(),
            |b, _| {
                b.iter(|| {
                    fft.forward(&mut v, &mut spec, &mut scr);
                    fft.inverse(&mut spec, &mut v, &mut scr);
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
