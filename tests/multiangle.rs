//! Multi-angle colour and the flop index: the geometries' directions, the
//! flop index on a worked example, 0 for a Lambertian sample, and a
//! metallic paint of the fast model flopping as metallics do, and its
//! multi-angle factors at the default resolution against a finer one.

use inksim::config::{Illuminant, StandardObserver};
use inksim::optics::baseline::doubling::Medium;
use inksim::optics::baseline::ordinates::OrdinateParams;
use inksim::optics::colour::Observer;
use inksim::optics::flakes::kernel::{FlakeMedium, NormalQuadrature};
use inksim::optics::flakes::multiangle::{self, Geometry};
use inksim::optics::flakes::normals::Orientation;
use inksim::optics::flakes::paint::{self, Ground, ModelParams, PaintLayer};
use inksim::optics::flakes::reflector::{Layer, Reflector};
use num_complex::Complex64 as C64;

#[test]
fn the_views_lie_at_the_aspecular_angles() {
    let view = |i: f64, a: f64| {
        Geometry {
            illumination_deg: i,
            aspecular_deg: a,
        }
        .view()
    };
    assert_eq!(view(45.0, 15.0), (30.0, 0.0));
    assert_eq!(view(45.0, 45.0), (0.0, 0.0));
    assert_eq!(view(45.0, 110.0), (65.0, 180.0));
    assert_eq!(view(45.0, -15.0), (60.0, 0.0));
    assert_eq!(view(15.0, 75.0), (60.0, 180.0));
    // The angle between the view and the mirror direction is |α|.
    for g in multiangle::geometries() {
        let (polar, az) = g.view();
        let s = if az == 0.0 { 1.0 } else { -1.0 };
        let v = [s * polar.to_radians().sin(), polar.to_radians().cos()];
        let t = g.illumination_deg.to_radians();
        let mirror = [t.sin(), t.cos()];
        let angle = (v[0] * mirror[0] + v[1] * mirror[1])
            .clamp(-1.0, 1.0)
            .acos();
        assert!(
            (angle.to_degrees() - g.aspecular_deg.abs()).abs() < 1e-9,
            "{g:?}"
        );
        assert!(polar < 85.0);
    }
    assert_eq!(multiangle::geometries().len(), 11);
}

#[test]
fn flop_index_worked_example_and_a_lambertian_sample() {
    // L*15 = 120, L*45 = 50, L*110 = 20: 100^1.11 = 10^2.22 = 165.959,
    // 50^0.86 = 10^(0.86 × 1.69897) = 28.912, FI = 2.69 × 165.959 / 28.912.
    let fi = multiangle::flop_index(120.0, 50.0, 20.0).unwrap();
    assert!((fi - 15.441).abs() < 2e-3, "{fi}");
    assert_eq!(multiangle::flop_index(60.0, 0.0, 20.0), None);
    // A Lambertian sample: the same reflectance factor in every geometry.
    let obs = Observer::standard(Illuminant::D65, StandardObserver::TenDegree);
    let wl = [400.0, 500.0, 600.0, 700.0];
    let spectrum = vec![0.3, 0.5, 0.6, 0.4];
    let factors = vec![spectrum; multiangle::geometries().len()];
    let colours = multiangle::colours(&obs, &wl, &factors).unwrap();
    assert_eq!(multiangle::flop_index_of(&colours), Some(0.0));
}

#[test]
fn an_aluminium_paint_flops() {
    let obs = Observer::standard(Illuminant::D65, StandardObserver::TenDegree);
    let wl = [400.0, 475.0, 550.0, 625.0, 700.0];
    let air = multiangle::air_directions();
    let aluminium = Reflector::Metal(Layer {
        index: C64::new(0.96, 6.69),
        thickness_nm: 100.0,
        thickness_sd_nm: 0.0,
    });
    let clear = |t: f64| PaintLayer {
        thickness_nm: t,
        pigments: Medium {
            mu_a: 0.0,
            mu_s: 0.0,
            moments: Vec::new(),
        },
        flakes: None,
    };
    let mut base = clear(15_000.0);
    base.flakes = Some(FlakeMedium {
        area_per_nm: 1e-4,
        orientation: Orientation {
            sigma_rad: 12f64.to_radians(),
        },
        diffraction_rad: 0.0,
        table: aluminium.table(1.5, 550.0),
    });
    let layers = [clear(40_000.0), base];
    let ground = Ground::Lambertian { albedo: 0.3 };
    let at = |params: &ModelParams| -> Vec<f64> {
        let p = paint::reflect(1.5, &layers, ground, 550.0, &air, params).unwrap();
        eprintln!("{} Fourier terms", p.terms.len());
        multiangle::geometries()
            .iter()
            .map(|g| {
                let (view, az) = g.view();
                p.factor(g.illumination_deg, view, az).unwrap()
            })
            .collect()
    };
    let coarse = at(&ModelParams::default());
    // The resolution: finer normals, more nodes and terms, a thinner start.
    let defaults = ModelParams::default();
    let fine = ModelParams {
        max_terms: 128,
        mode_tolerance: 1e-6,
        start: 1e-6,
        normals: NormalQuadrature {
            tilts: 48,
            azimuths: 256,
            lobe_sampling: 2.0,
        },
        ordinates: OrdinateParams {
            escape_nodes: 32,
            ..defaults.ordinates
        },
    };
    let fine = at(&fine);
    let worst = coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| ((c - f) / f).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "default vs fine resolution: worst relative difference {worst:.3} ({coarse:.3?} vs {fine:.3?})"
    );
    assert!(worst < 0.1, "{worst}");
    let factors: Vec<Vec<f64>> = coarse.iter().map(|&f| vec![f; wl.len()]).collect();
    let colours = multiangle::colours(&obs, &wl, &factors).unwrap();
    let l: Vec<f64> = colours.iter().take(6).map(|c| c.lab[0]).collect();
    let fi = multiangle::flop_index_of(&colours).unwrap();
    eprintln!("aluminium paint, 45° illumination, L* at −15…110°: {l:.1?}; flop index {fi:.1}");
    // Lightness falls from near the mirror to far from it.
    assert!(l[1] > l[2] && l[2] > l[3] && l[3] > l[4], "{l:?}");
    assert!(fi > 5.0, "{fi}");
}
