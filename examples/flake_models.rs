//! The fast effect-paint model against the full one (Monte Carlo with
//! explicit disc flakes), per aspecular angle at 45° illumination, on a
//! metallic and a pearl paint at three flake loadings; the table of
//! docs/VALIDATION.md, "Effect paints: fast against full model".
//!
//! `cargo run --release --example flake_models [rays] [diameter_nm]`
//! (default 2 000 000 rays per paint, flakes 15 µm across; small discs,
//! e.g. 300 nm, are the fast model's independent scatterers).
//!
//! The paints, at 550 nm in a lacquer of index 1.5 under a 30 µm clear
//! coat, flakes 15 µm across:
//! - metallic: a 15 µm basecoat of aluminium flakes (n 0.96 + 6.69i, 50 nm,
//!   opaque), spread σ 12°, weak grey pigment (μa 2e-5/nm, μs 5e-5/nm,
//!   Henyey–Greenstein g 0.5), on a grey primer (Lambertian, albedo 0.3);
//! - pearl: a 20 µm basecoat of TiO2/mica/TiO2 flakes (2.5, 80 ± 5 nm;
//!   1.58, 350 ± 30 nm), σ 10°, no pigment, on a black primer.
//!
//! Loadings: the flakes' projected area per volume `a` times the basecoat's
//! thickness `a d` = 0.5, 1.5 and 4 (how many flakes a ray meets crossing
//! the basecoat along the normal).

use inksim::optics::baseline::doubling::Medium;
use inksim::optics::flakes::kernel::FlakeMedium;
use inksim::optics::flakes::montecarlo::{self, McParams};
use inksim::optics::flakes::multiangle::{air_directions, Geometry, ASPECULAR_45_DEG};
use inksim::optics::flakes::normals::Orientation;
use inksim::optics::flakes::paint::{self, Ground, ModelParams, PaintLayer};
use inksim::optics::flakes::reflector::{Layer, Reflector};
use num_complex::Complex64 as C64;

const LACQUER: f64 = 1.5;
const WL: f64 = 550.0;

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

/// The metallic (`true`) or pearl paint at loading `ad`.
pub fn paint(metallic: bool, ad: f64) -> (Vec<PaintLayer>, Ground) {
    let (h, reflector, sigma_deg, pigments, ground) = if metallic {
        let al = Layer {
            index: C64::new(0.96, 6.69),
            thickness_nm: 50.0,
            thickness_sd_nm: 0.0,
        };
        let g: f64 = 0.5;
        (
            15_000.0,
            Reflector::Metal(al),
            12.0,
            Medium {
                mu_a: 2e-5,
                mu_s: 5e-5,
                moments: (0..64).map(|l| g.powi(l)).collect(),
            },
            Ground::Lambertian { albedo: 0.3 },
        )
    } else {
        let coating = Layer {
            index: C64::new(2.5, 0.0),
            thickness_nm: 80.0,
            thickness_sd_nm: 5.0,
        };
        let substrate = Layer {
            index: C64::new(1.58, 0.0),
            thickness_nm: 350.0,
            thickness_sd_nm: 30.0,
        };
        (
            20_000.0,
            Reflector::Coated { coating, substrate },
            10.0,
            clear(0.0).pigments,
            Ground::Black,
        )
    };
    let base = PaintLayer {
        thickness_nm: h,
        pigments,
        flakes: Some(FlakeMedium {
            area_per_nm: ad / h,
            orientation: Orientation {
                sigma_rad: f64::to_radians(sigma_deg),
            },
            diffraction_rad: 0.0,
            table: reflector.table(LACQUER, WL),
        }),
    };
    (vec![clear(30_000.0), base], ground)
}

fn main() {
    let rays: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(2_000_000);
    let diameter: f64 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(15_000.0);
    let geometries: Vec<Geometry> = ASPECULAR_45_DEG
        .iter()
        .map(|&a| Geometry {
            illumination_deg: 45.0,
            aspecular_deg: a,
        })
        .collect();
    let views: Vec<(f64, f64)> = geometries.iter().map(|g| g.view()).collect();
    println!(
        "| paint | a d | model | {} | scattered R |",
        geometries
            .iter()
            .map(|g| format!("{}", g.aspecular_deg))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!("|---|---|---|{}---|", "---|".repeat(geometries.len()));
    for metallic in [true, false] {
        for ad in [0.5, 1.5, 4.0] {
            let (layers, ground) = paint(metallic, ad);
            let t = std::time::Instant::now();
            let fast = paint::reflect(
                LACQUER,
                &layers,
                ground,
                WL,
                &air_directions(),
                &ModelParams::default(),
            )
            .expect("fast model");
            let fast_s = t.elapsed().as_secs_f64();
            let f: Vec<f64> = views
                .iter()
                .map(|&(v, az)| fast.factor(45.0, v, az).expect("node"))
                .collect();
            let j = fast.ords.air_node(45.0).expect("node");
            let fast_r: f64 = (0..fast.ords.len()).map(|i| fast.terms[0][(i, j)]).sum();
            let t = std::time::Instant::now();
            let mc = montecarlo::trace(
                LACQUER,
                &layers,
                &[diameter, diameter],
                ground,
                WL,
                45.0,
                &views,
                &McParams {
                    rays,
                    ..McParams::default()
                },
            )
            .expect("full model");
            let mc_s = t.elapsed().as_secs_f64();
            let name = if metallic { "metallic" } else { "pearl" };
            println!(
                "| {name} | {ad} | fast ({fast_s:.2} s) | {} | {fast_r:.4} |",
                f.iter()
                    .map(|x| format!("{x:.4}"))
                    .collect::<Vec<_>>()
                    .join(" | ")
            );
            println!(
                "| | | full ({mc_s:.0} s) | {} | {:.4} ± {:.4} |",
                mc.views
                    .iter()
                    .map(|e| format!("{:.4} ± {:.4}", e.mean, e.se))
                    .collect::<Vec<_>>()
                    .join(" | "),
                mc.scattered.mean,
                mc.scattered.se
            );
            println!(
                "| | | fast/full − 1 | {} | {:+.1} % |",
                f.iter()
                    .zip(&mc.views)
                    .map(|(a, e)| format!("{:+.1} %", 100.0 * (a / e.mean - 1.0)))
                    .collect::<Vec<_>>()
                    .join(" | "),
                100.0 * (fast_r / mc.scattered.mean - 1.0)
            );
        }
    }
}
