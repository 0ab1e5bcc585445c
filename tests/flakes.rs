//! Flakes' reflectance (METHOD §10) against closed forms: the transfer
//! matrix against the Airy slab of the wave solver and against Rouard's
//! recursion of Airy's formula, in s and p; a thick film with a thickness
//! spread against the incoherent (grey) sum; the normals' density
//! normalised.

use inksim::optics::flakes::normals::Orientation;
use inksim::optics::flakes::reflector::{Layer, Reflector};
use inksim::optics::flakes::thin_film::{self, Film};
use inksim::solver::airy::SlabField;
use num_complex::Complex64 as C64;
use std::f64::consts::{FRAC_PI_2, PI};

#[test]
fn transfer_matrix_matches_the_airy_slab_in_s_and_p() {
    let lambda = 550.0;
    let k0 = 2.0 * std::f64::consts::PI / lambda;
    let mut worst = 0.0f64;
    for n in [
        C64::new(1.558, 0.0),
        C64::new(2.5, 0.3),
        C64::new(0.96, 6.7),
    ] {
        for h in [80.0, 400.0] {
            for deg in [0.0f64, 30.0, 60.0, 85.0] {
                let c = deg.to_radians().cos();
                for p in [false, true] {
                    let airy = SlabField::polarised(n * n, h, k0, k0 * deg.to_radians().sin(), p);
                    let film = Film {
                        index: n,
                        thickness_nm: h,
                    };
                    let (tmm, _) = thin_film::stack(1.0, &[film], C64::new(1.0, 0.0), lambda, c, p);
                    let (ra, ta) = (airy.response.r.norm_sqr(), airy.response.t.norm_sqr());
                    let d = (tmm.r - ra).abs().max((tmm.t - ta).abs());
                    worst = worst.max(d);
                    assert!(d < 1e-10, "n {n} h {h} {deg}° p {p}: {tmm:?} {ra} {ta}");
                }
            }
        }
    }
    eprintln!("transfer matrix vs Airy slab: worst |ΔR|, |ΔT| = {worst:.1e}");
}

/// Rouard: the stack's reflection from the bottom up, each film adding
/// `r = (r_ij + r_below e^{2iδ})/(1 + r_ij r_below e^{2iδ})`, with the
/// Fresnel amplitudes of s (`(η_i − η_j)/(η_i + η_j)`, `η = N cos θ`) or p
/// (`η = N / cos θ`).
fn rouard(ambient: f64, films: &[(C64, f64)], exit: C64, lambda: f64, c0: f64, p: bool) -> f64 {
    let k0 = 2.0 * std::f64::consts::PI / lambda;
    let kx = ambient * (1.0 - c0 * c0).sqrt();
    let cos_in = |n: C64| {
        let c = (C64::new(1.0, 0.0) - (kx / n) * (kx / n)).sqrt();
        if (n * c).im < 0.0 {
            -c
        } else {
            c
        }
    };
    let eta = |n: C64| {
        let c = cos_in(n);
        if p {
            n / c
        } else {
            n * c
        }
    };
    let mut media: Vec<C64> = vec![C64::new(ambient, 0.0)];
    media.extend(films.iter().map(|f| f.0));
    media.push(exit);
    let fres = |a: C64, b: C64| (eta(a) - eta(b)) / (eta(a) + eta(b));
    let last = media.len() - 1;
    let mut r = fres(media[last - 1], media[last]);
    for j in (0..films.len()).rev() {
        let (n, d) = films[j];
        let phase = (C64::i() * 2.0 * k0 * n * cos_in(n) * d).exp();
        let rij = fres(media[j], media[j + 1]);
        r = (rij + r * phase) / (1.0 + rij * r * phase);
    }
    r.norm_sqr()
}

#[test]
fn an_interference_flake_matches_rouards_recursion() {
    // TiO2 (anatase-like, slightly absorbing) / mica / TiO2 in a lacquer.
    let (lacquer, tio2, mica) = (1.5, C64::new(2.5, 0.01), C64::new(1.58, 0.0));
    let mut worst = 0.0f64;
    for lambda in [420.0, 550.0, 680.0] {
        for deg in [0.0f64, 40.0, 75.0] {
            let c = deg.to_radians().cos();
            let films = [(tio2, 120.0), (mica, 400.0), (tio2, 120.0)];
            for p in [false, true] {
                let fs: Vec<Film> = films
                    .iter()
                    .map(|&(index, thickness_nm)| Film {
                        index,
                        thickness_nm,
                    })
                    .collect();
                let (tmm, _) = thin_film::stack(lacquer, &fs, C64::new(lacquer, 0.0), lambda, c, p);
                let r = rouard(lacquer, &films, C64::new(lacquer, 0.0), lambda, c, p);
                worst = worst.max((tmm.r - r).abs());
                assert!(
                    (tmm.r - r).abs() < 1e-12,
                    "{lambda} {deg} {p}: {} {r}",
                    tmm.r
                );
            }
            // The flake's natural-light reflectance is the mean of the two.
            let flake = Reflector::Coated {
                coating: Layer {
                    index: tio2,
                    thickness_nm: 120.0,
                    thickness_sd_nm: 0.0,
                },
                substrate: Layer {
                    index: mica,
                    thickness_nm: 400.0,
                    thickness_sd_nm: 0.0,
                },
            };
            let mean = 0.5
                * (rouard(lacquer, &films, C64::new(lacquer, 0.0), lambda, c, false)
                    + rouard(lacquer, &films, C64::new(lacquer, 0.0), lambda, c, true));
            let got = flake.powers(lacquer, lambda, c).r;
            assert!((got - mean).abs() < 1e-12, "{got} {mean}");
        }
    }
    eprintln!("transfer matrix vs Rouard: worst |ΔR| = {worst:.1e}");
}

#[test]
fn a_thick_film_with_a_thickness_spread_reaches_the_incoherent_limit() {
    // A clear film 50 µm ± 0.5 µm thick in the lacquer: its fringes average
    // out, leaving the incoherent sum of the two faces, per polarisation
    // R = 2 R₁ / (1 + R₁) (R₁ one face's Fresnel reflectance).
    let (lacquer, n) = (1.5, 2.5);
    let flake = thick_film(n, 500.0);
    let mut worst = 0.0f64;
    for lambda in [450.0, 600.0] {
        for deg in [0.0f64, 30.0, 60.0] {
            let c = deg.to_radians().cos();
            let face = |p: bool| {
                let (pw, _) = thin_film::stack(lacquer, &[], C64::new(n, 0.0), lambda, c, p);
                2.0 * pw.r / (1.0 + pw.r)
            };
            let incoherent = 0.5 * (face(false) + face(true));
            let got = flake.powers(lacquer, lambda, c);
            worst = worst.max((got.r - incoherent).abs());
            assert!(
                (got.r - incoherent).abs() < 1e-4,
                "{lambda} {deg}: {} {incoherent}",
                got.r
            );
            assert!((got.r + got.t - 1.0).abs() < 1e-10, "energy {got:?}");
        }
    }
    eprintln!("thick film with spread vs incoherent sum: worst |ΔR| = {worst:.1e}");
    // Without the spread the film is coherent and differs.
    let coherent = thick_film(n, 0.0);
    let (pw, _) = thin_film::stack(lacquer, &[], C64::new(n, 0.0), 450.0, 1.0, false);
    let r = coherent.powers(lacquer, 450.0, 1.0).r;
    assert!((r - 2.0 * pw.r / (1.0 + pw.r)).abs() > 1e-3, "{r}");
}

/// A clear film of index `n` 50 µm thick with thickness spread `sd_nm`.
fn thick_film(n: f64, sd_nm: f64) -> Reflector {
    Reflector::Coated {
        coating: Layer {
            index: C64::new(n, 0.0),
            thickness_nm: 0.0,
            thickness_sd_nm: 0.0,
        },
        substrate: Layer {
            index: C64::new(n, 0.0),
            thickness_nm: 50_000.0,
            thickness_sd_nm: sd_nm,
        },
    }
}

/// `∫ D (m·ẑ) dω = 1`, checked by the midpoint rule on a fine grid (an
/// independent quadrature), for narrow and wide spreads.
#[test]
fn the_density_is_normalised() {
    for deg in [2.0f64, 10.0, 25.0, 60.0] {
        let o = Orientation {
            sigma_rad: deg.to_radians(),
        };
        let density = o.density();
        let steps = 200_000;
        let h = FRAC_PI_2 / steps as f64;
        let sum: f64 = (0..steps)
            .map(|i| {
                let t = (i as f64 + 0.5) * h;
                density(t) * t.cos() * t.sin() * 2.0 * PI * h
            })
            .sum();
        assert!((sum - 1.0).abs() < 1e-6, "σ {deg}°: {sum}");
        let nodes = o.nodes(24, 16);
        let discrete: f64 = nodes.iter().map(|n| n.weight * n.m[2]).sum();
        assert!((discrete - 1.0).abs() < 1e-13);
        // The discrete weights are the density's: Σ W ≈ ∫ D dω.
        let total: f64 = nodes.iter().map(|n| n.weight).sum();
        let exact: f64 = (0..steps)
            .map(|i| {
                let t = (i as f64 + 0.5) * h;
                density(t) * t.sin() * 2.0 * PI * h
            })
            .sum();
        assert!(
            (total - exact).abs() < 1e-6 * exact,
            "σ {deg}°: {total} {exact}"
        );
    }
}

/// The diffraction broadening: Airy's central lobe `(2 J₁(x)/x)²` has the
/// curvature of `exp(−x²/4)` (checked from the Bessel series), which is the
/// spread `σ_ψ = √2 λ/(π n D)` of the deviation, half of it on the normals;
/// it vanishes for large discs.
#[test]
fn the_diffraction_lobe_broadens_small_flakes() {
    let j1 = |x: f64| {
        // J₁(x) = Σ (−1)^k (x/2)^{2k+1} / (k! (k+1)!).
        let (mut term, mut sum) = (x / 2.0, 0.0);
        for k in 0..30 {
            sum += term;
            term *= -(x * x / 4.0) / ((k + 1) as f64 * (k + 2) as f64);
        }
        sum
    };
    for x in [0.05f64, 0.1] {
        let airy = (2.0 * j1(x) / x).powi(2);
        let gauss = (-x * x / 4.0).exp();
        // Equal to second order: they differ at x⁴.
        assert!(
            (airy - gauss).abs() < 0.05 * x.powi(4),
            "{x}: {airy} {gauss}"
        );
    }
    let (lambda, n, d) = (550.0, 1.5, 2000.0);
    let o = Orientation::with_diffraction(0.0, d, lambda, n);
    let psi = 2.0f64.sqrt() * lambda / (PI * n * d);
    assert!((o.sigma_rad - psi / 2.0).abs() < 1e-15);
    let big = Orientation::with_diffraction(0.1, 1e9, lambda, n);
    assert!((big.sigma_rad - 0.1).abs() < 1e-9);
    eprintln!(
        "diffraction of a {} µm flake at {lambda} nm: normals' spread {:.2}°",
        d / 1000.0,
        o.sigma_rad.to_degrees()
    );
}
