//! The full effect-paint model (Monte Carlo with explicit disc flakes)
//! against exact results, and the fast model against it.

use inksim::optics::baseline::doubling::Medium;
use inksim::optics::baseline::fresnel::Fresnel;
use inksim::optics::flakes::kernel::FlakeMedium;
use inksim::optics::flakes::montecarlo::{self, McParams};
use inksim::optics::flakes::normals::Orientation;
use inksim::optics::flakes::paint::{Ground, PaintLayer};
use inksim::optics::flakes::reflector::Reflector;

const LACQUER: f64 = 1.5;

fn clear(h: f64) -> PaintLayer {
    PaintLayer {
        thickness_nm: h,
        pigments: Medium {
            mu_a: 0.0,
            mu_s: 0.0,
            moments: vec![],
        },
        flakes: None,
    }
}

fn flakes(h: f64, ad: f64, sigma_deg: f64, reflector: Reflector) -> PaintLayer {
    PaintLayer {
        thickness_nm: h,
        pigments: clear(0.0).pigments,
        flakes: Some(FlakeMedium {
            area_per_nm: ad / h,
            orientation: Orientation {
                sigma_rad: sigma_deg.to_radians(),
            },
            diffraction_rad: 0.0,
            table: reflector.table(LACQUER, 550.0),
        }),
    }
}

/// Light from 45° on aligned mirror flakes (σ = 0, R 0.7) in a 20 µm
/// layer (a d = 1) under a 10 µm clear coat, on black.
fn aligned(diameter_nm: f64) -> (f64, f64, f64) {
    let (rf, ad, h) = (0.7, 1.0, 20_000.0);
    let layers = [clear(10_000.0), flakes(h, ad, 0.0, Reflector::Spectrum(rf))];
    let mc = montecarlo::trace(
        LACQUER,
        &layers,
        &[diameter_nm, diameter_nm],
        Ground::Black,
        550.0,
        45.0,
        &[],
        &McParams {
            rays: 200_000,
            ..McParams::default()
        },
    )
    .unwrap();
    // The fast model's exact case: the two-stream closed form.
    let (e, rho) = (ad / h, ad / h * rf);
    let g = (e * e - rho * rho).sqrt();
    let layer_r = rho * (g * h).sinh() / (g * (g * h).cosh() + e * (g * h).sinh());
    let mu = (1.0 - (45f64.to_radians().sin() / LACQUER).powi(2)).sqrt();
    let r = Fresnel::Unpolarised.between(LACQUER, mu, 45f64.to_radians().cos());
    let exact = (1.0 - r).powi(2) * layer_r / (1.0 - r * layer_r);
    assert!((mc.mirror.mean - r).abs() < 1e-12);
    (mc.scattered.mean, mc.scattered.se, exact)
}

/// Small discs (100 nm, far below the layer's 20 µm and the path between
/// flakes) are the independent scatterers of the two-stream closed form,
/// which the full model must then reproduce; discs 15 µm across (as large
/// as the layer is thick) reflect more: the way back up passes the holes
/// the way down found, which independent sublayers do not know.
#[test]
fn small_aligned_discs_match_the_two_stream_closed_form_and_large_ones_reflect_more() {
    let (small, se, exact) = aligned(100.0);
    eprintln!("aligned 100 nm discs: full {small:.4} ± {se:.4}, closed form {exact:.4}");
    assert!(
        (small - exact).abs() < 4.0 * se + 0.003 * exact,
        "{small} vs {exact}"
    );
    let (large, se, _) = aligned(15_000.0);
    eprintln!("aligned 15 µm discs: full {large:.4} ± {se:.4}");
    assert!(
        large > exact * 1.05 && large - exact > 10.0 * se,
        "{large} vs {exact}"
    );
}

/// Without absorption (lossless mirror flakes, non-absorbing pigments, a
/// white ground) every ray comes back out: scattered + mirror = 1.
#[test]
fn a_paint_without_absorption_returns_all_the_light() {
    let g: f64 = 0.6;
    let mut base = flakes(15_000.0, 1.5, 12.0, Reflector::Spectrum(1.0));
    base.pigments = Medium {
        mu_a: 0.0,
        mu_s: 1e-4,
        moments: (0..48).map(|l| g.powi(l)).collect(),
    };
    let mc = montecarlo::trace(
        LACQUER,
        &[clear(20_000.0), base],
        &[15_000.0, 15_000.0],
        Ground::Lambertian { albedo: 1.0 },
        550.0,
        45.0,
        &[(30.0, 0.0)],
        &McParams {
            rays: 20_000,
            ..McParams::default()
        },
    )
    .unwrap();
    let total = mc.scattered.mean + mc.mirror.mean;
    assert!((total - 1.0).abs() < 1e-9, "{total}");
    assert!(mc.absorbed.mean.abs() < 1e-9, "{}", mc.absorbed.mean);
    assert!(mc.views[0].mean > 0.0);
}

/// Tilted flakes (σ 3° and 10°, R 0.5, a d 0.5, under a 10 µm clear coat,
/// on black) of 300 nm, the fast model's independent scatterers: its
/// scattered hemispherical reflectance at 0° and 45° within 3 % of the full
/// model's.
#[test]
fn the_fast_model_matches_the_full_one_for_small_tilted_flakes() {
    use inksim::optics::flakes::paint::{self, ModelParams};
    for sigma in [3.0, 10.0] {
        let layers = [
            clear(10_000.0),
            flakes(20_000.0, 0.5, sigma, Reflector::Spectrum(0.5)),
        ];
        let fast = paint::reflect(
            LACQUER,
            &layers,
            Ground::Black,
            550.0,
            &[0.0, 45.0],
            &ModelParams::default(),
        )
        .unwrap();
        for incidence in [0.0, 45.0] {
            let j = fast.ords.air_node(incidence).unwrap();
            let f: f64 = (0..fast.ords.len()).map(|i| fast.terms[0][(i, j)]).sum();
            let mc = montecarlo::trace(
                LACQUER,
                &layers,
                &[300.0, 300.0],
                Ground::Black,
                550.0,
                incidence,
                &[],
                &McParams {
                    rays: 100_000,
                    ..McParams::default()
                },
            )
            .unwrap();
            let (m, se) = (mc.scattered.mean, mc.scattered.se);
            eprintln!("σ {sigma}°, {incidence}°: fast {f:.4}, full {m:.4} ± {se:.4}");
            assert!(
                (f - m).abs() < 0.03 * m + 4.0 * se,
                "σ {sigma}, {incidence}°: {f} vs {m}"
            );
        }
    }
}
