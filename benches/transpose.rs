//! The 2-D transpose inside every FFT pair (`solver::fft`): the `transpose`
//! crate's kernel against a plain 16 × 16 tiled loop (the reference, kept
//! here), on the slice sizes of the study profiles (60², 36²) and of large
//! fragments (256², 512²). `cargo bench --bench transpose`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use num_complex::Complex64 as C64;

/// `dst (cols × rows) = srcᵀ` for `src (rows × cols)`, 16 × 16 tiles.
fn tiled(src: &[C64], dst: &mut [C64], rows: usize, cols: usize) {
    const B: usize = 16;
    for r0 in (0..rows).step_by(B) {
        for c0 in (0..cols).step_by(B) {
            for r in r0..(r0 + B).min(rows) {
                for c in c0..(c0 + B).min(cols) {
                    dst[c * rows + r] = src[r * cols + c];
                }
            }
        }
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("transpose");
    for &n in &[36usize, 60, 256, 512] {
        let src: Vec<C64> = (0..n * n)
            .map(|i| C64::new(i as f64, -(i as f64)))
            .collect();
        let mut dst = vec![C64::new(0.0, 0.0); n * n];
        let mut want = dst.clone();
        tiled(&src, &mut want, n, n);
        transpose::transpose(&src, &mut dst, n, n);
        assert_eq!(dst, want, "the kernels disagree at {n}²");
        g.bench_with_input(BenchmarkId::new("tiled", n), &n, |b, &n| {
            b.iter(|| tiled(&src, &mut dst, n, n))
        });
        g.bench_with_input(BenchmarkId::new("crate", n), &n, |b, &n| {
            b.iter(|| transpose::transpose(&src, &mut dst, n, n))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
