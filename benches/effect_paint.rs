//! Cost of the fast effect-paint model (METHOD §10): the whole BRDF (every
//! Fourier term on the adding–doubling nodes) of configs/metallic.toml —
//! clear coat, a base coat of aluminium flakes, a primer of white and black
//! Mie pigments, on a white ground — at its 31 wavelengths (400–700 nm),
//! the wavelengths in parallel, layers built from the config as a run builds
//! them; and configs/pearl.toml the same. The reference in the same run: a
//! thousand products of two 33 × 33 matrices (the size of the model's flux
//! matrices) by the plain triple loop written here — not the model's own
//! `Matrix::mul`, whose speed is part of what is measured — a yardstick of
//! the machine's speed at that moment, so the ratio model / reference
//! carries over between machines and loads.
//! `cargo bench --bench effect_paint` (figures in docs/PERFORMANCE.md).

use criterion::{criterion_group, criterion_main, Criterion};
use inksim::config::paint::PaintScene;
use inksim::pipeline::paint::{model_params, paint_air_directions, reflect_at};
use rayon::prelude::*;
use std::path::Path;

fn scene(name: &str) -> PaintScene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("configs/{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    inksim::config::parse_paint(&path, &text).unwrap()
}

/// The whole BRDF at every wavelength; the Fourier terms solved.
fn full_brdf(scene: &PaintScene) -> usize {
    let air = paint_air_directions(scene);
    let params = model_params(scene);
    scene
        .wavelengths_nm
        .par_iter()
        .map(|&l| reflect_at(scene, &params, &air, l).unwrap().terms.len())
        .sum()
}

/// `a · b` for row-major `n × n` slices, the plain `i, j, k` loop.
fn naive_product(n: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    for i in 0..n {
        for j in 0..n {
            let mut s = 0.0;
            for k in 0..n {
                s += a[i * n + k] * b[k * n + j];
            }
            out[i * n + j] = s;
        }
    }
}

fn products(a: &[f64], b: &[f64]) -> f64 {
    let mut out = vec![0.0; N * N];
    let mut s = 0.0;
    for _ in 0..1000 {
        naive_product(
            N,
            std::hint::black_box(a),
            std::hint::black_box(b),
            &mut out,
        );
        s += out[3 * N + 5];
    }
    s
}

/// The model's matrix size.
const N: usize = 33;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("effect_paint");
    g.sample_size(10);
    let a: Vec<f64> = (0..N * N)
        .map(|x| 1.0 / (1.0 + (x / N) as f64 + 2.0 * (x % N) as f64))
        .collect();
    let b: Vec<f64> = (0..N * N)
        .map(|x| (((x / N) * 7 + (x % N) * 3) % 11) as f64 / 11.0)
        .collect();
    g.bench_function("reference_1000_products_33", |bn| {
        bn.iter(|| products(&a, &b))
    });
    for name in ["metallic", "pearl"] {
        let s = scene(name);
        g.bench_function(format!("{name}_31_wavelengths"), |bn| {
            bn.iter(|| full_brdf(&s))
        });
        eprintln!(
            "{name}: Fourier terms over the 31 wavelengths: {}",
            full_brdf(&s)
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
