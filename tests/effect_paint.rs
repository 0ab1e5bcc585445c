//! The fast effect-paint model (METHOD §10) against exact results: aligned
//! mirror flakes under a lacquer against the two-stream closed form with
//! the Fresnel surface, a clear lacquer on a metal, the white furnace (no
//! absorption: all light comes back out) and reciprocity of the BRDF in
//! every Fourier term.

use inksim::optics::baseline::doubling::Medium;
use inksim::optics::baseline::fresnel::Fresnel;
use inksim::optics::flakes::kernel::FlakeMedium;
use inksim::optics::flakes::normals::Orientation;
use inksim::optics::flakes::paint::{self, Ground, ModelParams, PaintLayer};
use inksim::optics::flakes::reflector::{Layer, Reflector};
use num_complex::Complex64 as C64;

const LACQUER: f64 = 1.5;
const AIR: [f64; 4] = [0.0, 15.0, 45.0, 60.0];

fn clear(thickness_nm: f64, mu_a: f64) -> PaintLayer {
    PaintLayer {
        thickness_nm,
        pigments: Medium {
            mu_a,
            mu_s: 0.0,
            moments: Vec::new(),
        },
        flakes: None,
    }
}

/// Henyey–Greenstein moments `g^l`.
fn hg(g: f64, terms: usize) -> Vec<f64> {
    (0..terms).map(|l| g.powi(l as i32)).collect()
}

/// Fresnel reflectance of natural light from a real `n1` into a complex
/// `n2` at `cos1`, from the amplitudes.
fn fresnel_complex(n1: f64, n2: C64, cos1: f64) -> f64 {
    let sin1 = (1.0 - cos1 * cos1).sqrt();
    let mut cos2 = (C64::new(1.0, 0.0) - (n1 * sin1 / n2).powi(2)).sqrt();
    if (n2 * cos2).im < 0.0 {
        cos2 = -cos2;
    }
    let rs = (n1 * cos1 - n2 * cos2) / (n1 * cos1 + n2 * cos2);
    let rp = (n2 * cos1 - n1 * cos2) / (n2 * cos1 + n1 * cos2);
    0.5 * (rs.norm_sqr() + rp.norm_sqr())
}

#[test]
fn aligned_mirror_flakes_match_the_two_stream_closed_form() {
    let (rf, a, h) = (0.7, 5e-5, 20_000.0);
    let table = Reflector::Spectrum(rf).table(LACQUER, 550.0);
    let layer = PaintLayer {
        thickness_nm: h,
        pigments: Medium {
            mu_a: 0.0,
            mu_s: 0.0,
            moments: Vec::new(),
        },
        flakes: Some(FlakeMedium {
            area_per_nm: a,
            orientation: Orientation { sigma_rad: 0.0 },
            diffraction_rad: 0.0,
            table,
        }),
    };
    let params = ModelParams {
        max_terms: 3,
        ..ModelParams::default()
    };
    let p = paint::reflect(
        LACQUER,
        &[clear(10_000.0, 0.0), layer],
        Ground::Black,
        550.0,
        &AIR,
        &params,
    )
    .unwrap();
    // Per depth, every direction: extinction e = a, back-reflection ρ = a R_f.
    let (e, rho) = (a, a * rf);
    let g = (e * e - rho * rho).sqrt();
    let layer_r = rho * (g * h).sinh() / (g * (g * h).cosh() + e * (g * h).sinh());
    let o = &p.ords;
    let mut worst = 0.0f64;
    for j in 0..o.len() {
        let Some(mu_a) = o.mu_air[j] else { continue };
        let r = Fresnel::Unpolarised.between(LACQUER, o.mu[j], mu_a);
        let exact = r + (1.0 - r).powi(2) * layer_r / (1.0 - r * layer_r);
        // Along the normal a radiance has no azimuth: only term 0 there.
        let terms = if o.mu[j] == 1.0 { 1 } else { p.terms.len() };
        for t in &p.terms[..terms] {
            let got = t[(j, j)] + p.mirror[j];
            worst = worst.max((got - exact).abs());
            let off: f64 = (0..o.len())
                .filter(|&i| i != j)
                .map(|i| t[(i, j)].abs())
                .sum();
            assert!(off < 1e-14, "bin {j}: off-diagonal {off}");
        }
    }
    eprintln!("aligned mirror flakes vs closed form: worst |ΔR| = {worst:.1e}");
    assert!(worst < 1e-8, "{worst}");
}

#[test]
fn a_clear_lacquer_on_a_metal_matches_the_closed_form() {
    let (alpha, h) = (2e-5, 30_000.0);
    let metal = C64::new(0.96, 6.69);
    let p = paint::reflect(
        LACQUER,
        &[clear(h, alpha)],
        Ground::Mirror { index: metal },
        550.0,
        &AIR,
        &ModelParams::default(),
    )
    .unwrap();
    let o = &p.ords;
    let mut worst = 0.0f64;
    for j in 0..o.len() {
        let Some(mu_a) = o.mu_air[j] else { continue };
        let r = Fresnel::Unpolarised.between(LACQUER, o.mu[j], mu_a);
        let rm = fresnel_complex(LACQUER, metal, o.mu[j]);
        let t2 = (-2.0 * alpha * h / o.mu[j]).exp();
        let exact = r + (1.0 - r).powi(2) * rm * t2 / (1.0 - r * rm * t2);
        worst = worst.max((p.mirror[j] - exact).abs());
        assert!(p.terms[0][(j, j)].abs() < 1e-14);
    }
    eprintln!("clear lacquer on aluminium vs closed form: worst |ΔR| = {worst:.1e}");
    assert!(worst < 1e-12, "{worst}");
}

/// A three-layer paint: clear coat, a base coat of pearl flakes and
/// scattering pigment, a primer of scattering pigment, on a ground.
fn paint_layers(absorbing: bool, spread_deg: f64) -> Vec<PaintLayer> {
    let tio2 = C64::new(2.5, if absorbing { 0.02 } else { 0.0 });
    let flake = Reflector::Coated {
        coating: Layer {
            index: tio2,
            thickness_nm: 110.0,
            thickness_sd_nm: 5.0,
        },
        substrate: Layer {
            index: C64::new(1.58, 0.0),
            thickness_nm: 400.0,
            thickness_sd_nm: 40.0,
        },
    };
    let mu_a = if absorbing { 2e-6 } else { 0.0 };
    vec![
        clear(40_000.0, mu_a),
        PaintLayer {
            thickness_nm: 15_000.0,
            pigments: Medium {
                mu_a,
                mu_s: 2e-5,
                moments: hg(0.6, 40),
            },
            flakes: Some(FlakeMedium {
                area_per_nm: 4e-5,
                orientation: Orientation {
                    sigma_rad: spread_deg.to_radians(),
                },
                diffraction_rad: 0.0,
                table: flake.table(LACQUER, 550.0),
            }),
        },
        PaintLayer {
            thickness_nm: 20_000.0,
            pigments: Medium {
                mu_a: mu_a * 10.0,
                mu_s: 2e-4,
                moments: hg(0.3, 40),
            },
            flakes: None,
        },
    ]
}

#[test]
fn without_absorption_all_light_comes_back_out() {
    let p = three_layer_paint(false, 12.0, 1.0);
    let o = &p.ords;
    let mut worst = 0.0f64;
    for j in (0..o.len()).filter(|&j| o.mu_air[j].is_some()) {
        worst = worst.max((p.albedo(j) - 1.0).abs());
    }
    eprintln!(
        "white furnace: worst |1 − albedo| = {worst:.1e} ({} Fourier terms)",
        p.terms.len()
    );
    assert!(worst < 1e-9, "{worst}");
    assert!(p.terms.len() > 4);
}

#[test]
fn the_brdf_is_reciprocal_in_every_fourier_term() {
    let p = three_layer_paint(true, 8.0, 0.8);
    let o = &p.ords;
    let air: Vec<usize> = (0..o.len()).filter(|&j| o.mu_air[j].is_some()).collect();
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for t in &p.terms {
        for &i in &air {
            for &j in &air {
                let f_ij = t[(i, j)] / o.air_flux_weight(i);
                let f_ji = t[(j, i)] / o.air_flux_weight(j);
                worst = worst.max((f_ij - f_ji).abs());
                scale = scale.max(f_ij.abs());
            }
        }
    }
    eprintln!("reciprocity: worst |πf(i→o) − πf(o→i)| = {worst:.1e} of {scale:.2}");
    assert!(worst < 1e-10 * scale.max(1.0), "{worst}");
    // And in the plane of incidence at the measuring angles.
    for (a, b) in [(45.0, 15.0), (15.0, 60.0), (0.0, 45.0)] {
        for phi in [0.0, 180.0, 70.0] {
            let (x, y) = (p.factor(a, b, phi).unwrap(), p.factor(b, a, phi).unwrap());
            assert!(
                (x - y).abs() < 1e-10 * x.abs().max(1.0),
                "{a} {b} {phi}: {x} {y}"
            );
        }
    }
}

/// [`paint_layers`] on a Lambertian ground of `albedo`, at 550 nm.
fn three_layer_paint(absorbing: bool, spread_deg: f64, albedo: f64) -> paint::PaintReflection {
    paint::reflect(
        LACQUER,
        &paint_layers(absorbing, spread_deg),
        Ground::Lambertian { albedo },
        550.0,
        &AIR,
        &ModelParams::default(),
    )
    .unwrap()
}

/// The pigments' azimuthal terms by the addition theorem against the
/// azimuthal integral itself, `p_m = (1/2π) ∫ p(cos Θ) cos mΔφ dΔφ` by the
/// trapezoidal rule on 2048 azimuths (exact for the Legendre series' degree),
/// for a Henyey–Greenstein phase function of 40 moments, both hemispheres.
#[test]
fn the_pigment_terms_match_the_azimuthal_integral() {
    use inksim::optics::baseline::doubling::phase_series;
    use inksim::optics::baseline::ordinates::{OrdinateParams, Ordinates};
    use inksim::optics::flakes::kernel::pigment_kernels;
    let ords = Ordinates::new(LACQUER, OrdinateParams::default(), &AIR).unwrap();
    let medium = Medium {
        mu_a: 0.0,
        mu_s: 1e-4,
        moments: hg(0.7, 40),
    };
    let (mu_s, chi) = medium.delta_m(2 * ords.len());
    let modes = 24;
    let k = pigment_kernels(&ords, &medium, modes);
    let steps = 2048;
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    let n = ords.len();
    let sin: Vec<f64> = ords.mu.iter().map(|m| (1.0 - m * m).sqrt()).collect();
    for (m, km) in k.iter().enumerate().skip(1) {
        for i in 0..n {
            for j in 0..n {
                for (sign, got) in [(1.0, km.same[(i, j)]), (-1.0, km.opposite[(i, j)])] {
                    let p: f64 = (0..steps)
                        .map(|q| {
                            let dphi = 2.0 * std::f64::consts::PI * q as f64 / steps as f64;
                            let x = sign * ords.mu[i] * ords.mu[j] + sin[i] * sin[j] * dphi.cos();
                            phase_series(&chi, x) * (m as f64 * dphi).cos()
                        })
                        .sum::<f64>()
                        / steps as f64;
                    let exact = 0.5 * mu_s * ords.weight[i] * p / ords.mu[j];
                    worst = worst.max((got - exact).abs());
                    scale = scale.max(exact.abs());
                }
            }
        }
    }
    eprintln!(
        "pigment terms 1–{}: worst |Δ| {worst:.1e} of {scale:.1e}",
        modes - 1
    );
    assert!(worst < 1e-12 * scale, "{worst} of {scale}");
}

/// The reflection at any air angles (`flakes::air`): at the nodes the
/// model's own values (the scattered factor at any azimuth, the mirror part,
/// the scattered albedo); between two nodes the straight line between
/// their values; beyond the outermost node the outermost's value.
#[test]
fn the_reflection_between_nodes_is_the_line_between_their_values() {
    use inksim::optics::flakes::air::AirNodes;
    let p = three_layer_paint(true, 12.0, 0.8);
    let air = AirNodes::new(&p);
    let a = &air.angles_deg;
    assert!(a.len() > 10 && a.windows(2).all(|w| w[0] < w[1]), "{a:?}");
    for &i in &[45.0, 15.0] {
        for &v in &[0.0, 15.0, 60.0] {
            for az in [0.0, 30.0, 90.0, 180.0] {
                let want = p.factor(i, v, az).unwrap();
                let got = air.factor(&p, i, v, az);
                assert!(
                    (got - want).abs() <= 1e-12 * want.abs().max(1e-3),
                    "{i} {v} {az}: {got} vs {want}"
                );
            }
        }
    }
    for (&deg, &j) in a.iter().zip(&air.nodes) {
        assert!((air.mirror(&p, deg) - p.mirror[j]).abs() < 1e-15);
        let scattered = p.albedo(j) - p.mirror[j];
        assert!((air.scattered_albedo(&p, deg) - scattered).abs() < 1e-15);
    }
    // Halfway between two neighbouring nodes: the mean of their values.
    let k = a.len() / 2;
    let mid = 0.5 * (a[k] + a[k + 1]);
    let (f0, f1) = (
        air.factor(&p, 45.0, a[k], 20.0),
        air.factor(&p, 45.0, a[k + 1], 20.0),
    );
    let fm = air.factor(&p, 45.0, mid, 20.0);
    assert!((fm - 0.5 * (f0 + f1)).abs() < 1e-12, "{fm} vs {f0}, {f1}");
    // Beyond the outermost node: held.
    let last = *a.last().unwrap();
    assert!(last < 90.0 && last > 80.0, "{last}");
    assert_eq!(air.mirror(&p, 89.9), air.mirror(&p, last));
}
