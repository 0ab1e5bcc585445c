//! Cost of the fast effect-paint model (METHOD §10): the whole BRDF (every
//! Fourier term on the adding–doubling nodes) of a three-layer metallic
//! paint — clear coat, a base coat of aluminium flakes with an absorbing
//! pigment, a scattering primer — on a diffuse ground, at 31 wavelengths
//! (400–700 nm), the wavelengths in parallel. `cargo bench --bench
//! effect_paint` (figures in docs/PERFORMANCE.md).

use criterion::{criterion_group, criterion_main, Criterion};
use inksim::optics::baseline::doubling::Medium;
use inksim::optics::flakes::kernel::FlakeMedium;
use inksim::optics::flakes::normals::Orientation;
use inksim::optics::flakes::paint::{self, Ground, ModelParams, PaintLayer};
use inksim::optics::flakes::reflector::{Layer, Reflector};
use num_complex::Complex64 as C64;
use rayon::prelude::*;

const AIR: [f64; 9] = [0.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 65.0, 8.0];

fn layers(wavelength_nm: f64) -> Vec<PaintLayer> {
    let aluminium = Reflector::Metal(Layer {
        index: C64::new(0.96, 6.69),
        thickness_nm: 100.0,
        thickness_sd_nm: 20.0,
    });
    let medium = |mu_a: f64, mu_s: f64, g: f64| Medium {
        mu_a,
        mu_s,
        moments: (0..12).map(|l| g.powi(l)).collect(),
    };
    vec![
        PaintLayer {
            thickness_nm: 40_000.0,
            pigments: medium(1e-7, 0.0, 0.0),
            flakes: None,
        },
        PaintLayer {
            thickness_nm: 15_000.0,
            pigments: medium(2e-5 * (550.0 / wavelength_nm), 5e-6, 0.2),
            flakes: Some(FlakeMedium {
                area_per_nm: 8e-5,
                orientation: Orientation {
                    sigma_rad: 10f64.to_radians(),
                },
                table: aluminium.table(1.5, wavelength_nm),
            }),
        },
        PaintLayer {
            thickness_nm: 20_000.0,
            pigments: medium(1e-5, 2e-4, 0.5),
            flakes: None,
        },
    ]
}

fn full_brdf() -> usize {
    let grid: Vec<f64> = (0..31).map(|i| 400.0 + 10.0 * i as f64).collect();
    grid.par_iter()
        .map(|&l| {
            paint::reflect(
                1.5,
                &layers(l),
                Ground::Lambertian { albedo: 0.8 },
                l,
                &AIR,
                &ModelParams::default(),
            )
            .unwrap()
            .terms
            .len()
        })
        .sum()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("effect_paint");
    g.sample_size(10);
    g.bench_function("three_layers_31_wavelengths", |b| b.iter(full_brdf));
    eprintln!("Fourier terms over the 31 wavelengths: {}", full_brdf());
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
