//! Hiding power of a layer over a hiding chart (METHOD §6): the contrast
//! ratio and Kubelka's scattering and absorption coefficients S and K from
//! the layer's reflectance over the chart's black and white halves.
//!
//! - **Contrast ratio** (ISO 6504-3, ASTM D2805): `CR = Y_b / Y_w`, the
//!   luminance factors over black and over white, in every measurement
//!   geometry the scene reports (d/8° SCI is the standards'), under the
//!   scene's illuminant and observer.
//! - **Kubelka's S and K** from the exact hyperbolic solution (P. Kubelka,
//!   J. Opt. Soc. Am. 38, 448 (1948)): with `R_b` over black, `R_w` over a
//!   ground of reflectance `R_g` and thickness `X`,
//!   `a = ½ [R_w + (R_b − R_w + R_g)/(R_b R_g)]`, `b = √(a² − 1)`,
//!   `R∞ = a − b`, `S = arcoth((1 − a R_b)/(b R_b)) / (b X)`,
//!   `K = S (a − 1)`, and `K/S = a − 1 = (1 − R∞)²/(2 R∞)`. The formula for
//!   `a` follows from `R_w = R_b + T² R_g/(1 − R_b R_g)` and Kubelka's
//!   `T² = (a − R_b)² − b²`. Where the reflectances admit no Kubelka layer
//!   (`R_w < R_b`, `R_b ≤ 0`, `R_g ≤ 0`) the coefficients are NaN; a layer
//!   that hides completely (`R_b = R_w`) has `S = ∞`.
//! - **A layer that absorbs nothing measurable.** `a = 1 + K/S` cannot be
//!   below 1 for a Kubelka layer, but readings that include the surface
//!   reflection raise `R_b` more than `R_w` asks for, which lowers `a`: a
//!   nearly lossless white (rutile at 550–650 nm) reads `a < 1` with
//!   `R_w > R_b`. Such readings are taken as the non-absorbing layer,
//!   `K = 0`, `R∞ = 1` and `S X = R_b/(1 − R_b)` (Kubelka's limit `b → 0`,
//!   from the reading over black alone), rather than left undefined: the
//!   bound `K ≥ 0` of the model applied to the readings. S then carries
//!   the surface reflection in `R_b`, as every value here does.
//!
//! S and K are computed from the reflectance factors as measured, surface
//! reflection included (as a lab applies Kubelka's formulas to its
//! instrument's readings), not after a Saunderson correction.
//!
//! Standard errors: every realisation's layer lies over both halves, so each
//! realisation gives its own CR, S and K from its own pair of spectra (and
//! colours); the standard error is their sample standard deviation / √R.
//! The reported values are those of the ensemble-mean spectra, like the
//! colours'.

use crate::config::{GroundReflectance, Measurement};
use crate::optics::appearance::{
    reduce, AppearanceError, AppearanceSpec, Estimate, MeasuredColour,
};
use crate::optics::colour::{self, Observer};
use ndarray::{Array1, Ix1};

/// Kubelka's description of a layer of thickness `X` from its reflectances
/// over two grounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kubelka {
    /// Reflectance of the layer at complete hiding, `R∞ = a − b`.
    pub r_inf: f64,
    /// Scattering coefficient, per unit of `X`.
    pub s: f64,
    /// Absorption coefficient, per unit of `X`.
    pub k: f64,
}

impl Kubelka {
    /// `K/S = a − 1`.
    pub fn k_over_s(&self) -> f64 {
        self.k / self.s
    }
}

/// Kubelka's exact inversion: `r_black` over a ground reflecting nothing,
/// `r_white` over a ground of reflectance `r_ground`, thickness `x`.
pub fn kubelka(r_black: f64, r_white: f64, r_ground: f64, x: f64) -> Kubelka {
    const NAN: Kubelka = Kubelka {
        r_inf: f64::NAN,
        s: f64::NAN,
        k: f64::NAN,
    };
    if !(r_black > 0.0 && r_ground > 0.0 && x > 0.0 && r_black < 1.0) {
        return NAN;
    }
    let a = 0.5 * (r_white + (r_black - r_white + r_ground) / (r_black * r_ground));
    if a.is_nan() || r_white < r_black {
        return NAN;
    }
    // K ≥ 0: readings of a < 1 are the non-absorbing layer's (module doc).
    let a = a.max(1.0);
    let b = (a * a - 1.0).sqrt();
    if r_black == r_white && b > 0.0 {
        // Complete hiding: the layer is its own R∞, S X = ∞ (the general
        // formula's arcoth(1), up to rounding).
        return Kubelka {
            r_inf: r_black,
            s: f64::INFINITY,
            k: f64::INFINITY,
        };
    }
    if b == 0.0 {
        // No absorption: the limit b → 0, S X = R_b / (1 − R_b).
        return Kubelka {
            r_inf: 1.0,
            s: r_black / ((1.0 - r_black) * x),
            k: 0.0,
        };
    }
    let y = (1.0 - a * r_black) / (b * r_black);
    // arcoth y = ½ ln((y + 1)/(y − 1)) = ½ ln(1 + 2/(y − 1)), y > 1.
    let arcoth = if y > 1.0 {
        0.5 * (2.0 / (y - 1.0)).ln_1p()
    } else if y == 1.0 {
        f64::INFINITY
    } else {
        return NAN;
    };
    let s = arcoth / (b * x);
    Kubelka {
        r_inf: a - b,
        s,
        k: s * (a - 1.0),
    }
}

/// Kubelka's forward formula: the reflectance of a layer of `S`, `K` and
/// thickness `x` over a ground of reflectance `r_ground`,
/// `R = [1 − R_g (a − b coth(bSX))] / [a − R_g + b coth(bSX)]`.
pub fn kubelka_reflectance(s: f64, k: f64, x: f64, r_ground: f64) -> f64 {
    let a = 1.0 + k / s;
    let b = (a * a - 1.0).sqrt();
    if b == 0.0 {
        let sx = s * x;
        return (r_ground + sx * (1.0 - r_ground)) / (1.0 + sx * (1.0 - r_ground));
    }
    let coth = 1.0 / (b * s * x).tanh();
    (1.0 - r_ground * (a - b * coth)) / (a - r_ground + b * coth)
}

/// The contrast ratio `Y_b / Y_w`.
pub fn contrast_ratio(y_black: f64, y_white: f64) -> f64 {
    y_black / y_white
}

/// A value and its standard error (None with one realisation of a random
/// layer; 0 for a deterministic one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scalar {
    pub value: f64,
    pub se: Option<f64>,
}

/// Hiding power over a chart in one measurement geometry.
#[derive(Debug, Clone)]
pub struct Hiding {
    pub geometry: Measurement,
    /// The white half's reflectance `R_g` at the solved wavelengths.
    pub ground_reflectance: Array1<f64>,
    /// Luminance factors (white Y = 100) over black, over white, and of the
    /// white half itself, under the scene's illuminant and observer.
    pub y_black: f64,
    pub y_white: f64,
    pub y_ground: f64,
    /// `Y_b / Y_w`.
    pub contrast_ratio: Scalar,
    /// At the solved wavelengths: `R∞`, S and K (per µm) and `K/S`.
    pub r_inf: Estimate<Ix1>,
    pub s_per_um: Estimate<Ix1>,
    pub k_per_um: Estimate<Ix1>,
    pub k_over_s: Estimate<Ix1>,
    /// The same from the luminance factors `Y/100`.
    pub r_inf_y: Scalar,
    pub s_y_per_um: Scalar,
    pub k_y_per_um: Scalar,
    pub k_over_s_y: Scalar,
    /// The largest `K/S` over the solved wavelengths and where it is: the
    /// colour pigment's absorption maximum as the solves see it, for a
    /// tinting strength (the ratio of a tint's value to a reference's).
    pub k_over_s_max: Scalar,
    pub k_over_s_max_wavelength_nm: f64,
}

/// Hiding power in every geometry from the colours over the black half
/// (`black`) and over the white half (`white`, the same geometries in the
/// same order), the white half being the ground `ground`.
pub fn of_chart(
    spec: &AppearanceSpec,
    black: &[MeasuredColour],
    white: &[MeasuredColour],
    ground: &GroundReflectance,
    observer: &Observer,
) -> Result<Vec<Hiding>, AppearanceError> {
    let x_um = spec.thickness_nm / 1000.0;
    let wl = &spec.wavelengths_nm;
    let r_g: Array1<f64> = wl.iter().map(|&w| ground.at(w)).collect();
    black
        .iter()
        .zip(white)
        .map(|(b, w)| {
            let y_ground = match ground.constant() {
                Some(a) => 100.0 * a,
                None => {
                    let grid = &w.spectrum_wavelengths_nm;
                    let g: Vec<f64> = grid.iter().map(|&l| ground.at(l)).collect();
                    colour::xyz_from_reflectance(observer, grid, &g)?[1]
                }
            };
            Ok(hiding_in(b, w, &r_g, y_ground, x_um, wl))
        })
        .collect()
}

fn hiding_in(
    b: &MeasuredColour,
    w: &MeasuredColour,
    r_g: &Array1<f64>,
    y_ground: f64,
    x_um: f64,
    wl: &[f64],
) -> Hiding {
    let nl = r_g.len();
    let spectral = |rb: &Array1<f64>, rw: &Array1<f64>| -> [Array1<f64>; 4] {
        let ks: Vec<Kubelka> = (0..nl)
            .map(|l| kubelka(rb[l], rw[l], r_g[l], x_um))
            .collect();
        [
            ks.iter().map(|k| k.r_inf).collect(),
            ks.iter().map(|k| k.s).collect(),
            ks.iter().map(|k| k.k).collect(),
            ks.iter().map(|k| k.k_over_s()).collect(),
        ]
    };
    let at_y = |yb: f64, yw: f64| -> [f64; 5] {
        let k = kubelka(yb / 100.0, yw / 100.0, y_ground / 100.0, x_um);
        [contrast_ratio(yb, yw), k.r_inf, k.s, k.k, k.k_over_s()]
    };
    let mean = spectral(&b.reflectance.mean, &w.reflectance.mean);
    let y = at_y(b.xyz[1], w.xyz[1]);
    // Per realisation (R ≥ 2), or exactly 0 for a deterministic layer.
    let rr = b
        .realisation_reflectance
        .len()
        .min(w.realisation_reflectance.len());
    let deterministic = rr == 0 && w.de00_se == Some(0.0) && b.de00_se == Some(0.0);
    let (spectral_se, y_se): (Option<[Array1<f64>; 4]>, Option<[f64; 5]>) = if rr >= 2 {
        let per: Vec<[Array1<f64>; 4]> = (0..rr)
            .map(|r| spectral(&b.realisation_reflectance[r], &w.realisation_reflectance[r]))
            .collect();
        let se = |i: usize| {
            let samples: Vec<Array1<f64>> = per.iter().map(|p| p[i].clone()).collect();
            reduce(&samples).se.expect("two or more realisations")
        };
        let per_y: Vec<Array1<f64>> = (0..rr)
            .map(|r| Array1::from(at_y(b.realisation_xyz[r][1], w.realisation_xyz[r][1]).to_vec()))
            .collect();
        let sy = reduce(&per_y).se.expect("two or more realisations");
        (
            Some([se(0), se(1), se(2), se(3)]),
            Some([sy[0], sy[1], sy[2], sy[3], sy[4]]),
        )
    } else if deterministic {
        (
            Some(std::array::from_fn(|_| Array1::zeros(nl))),
            Some([0.0; 5]),
        )
    } else {
        (None, None)
    };
    let [r_inf, s, k, ks] = mean;
    let est = |m: Array1<f64>, i: usize| Estimate {
        mean: m,
        se: spectral_se.as_ref().map(|s| s[i].clone()),
    };
    let scalar = |i: usize| Scalar {
        value: y[i],
        se: y_se.map(|s| s[i]),
    };
    let k_over_s = est(ks, 3);
    let imax = (0..nl)
        .filter(|&l| k_over_s.mean[l].is_finite())
        .max_by(|&p, &q| k_over_s.mean[p].total_cmp(&k_over_s.mean[q]))
        .unwrap_or(0);
    Hiding {
        geometry: w.geometry,
        ground_reflectance: r_g.clone(),
        y_black: b.xyz[1],
        y_white: w.xyz[1],
        y_ground,
        contrast_ratio: scalar(0),
        r_inf: est(r_inf, 0),
        s_per_um: est(s, 1),
        k_per_um: est(k, 2),
        k_over_s_max: Scalar {
            value: k_over_s.mean[imax],
            se: k_over_s.se.as_ref().map(|s| s[imax]),
        },
        k_over_s_max_wavelength_nm: wl[imax],
        k_over_s,
        r_inf_y: scalar(1),
        s_y_per_um: scalar(2),
        k_y_per_um: scalar(3),
        k_over_s_y: scalar(4),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kubelka_inverts_its_forward_formula() {
        for (s, k, x, rg) in [
            (2.0, 0.1, 1.5, 0.8),
            (0.3, 0.02, 4.0, 0.9),
            (5.0, 3.0, 0.2, 0.5),
            (1.0, 1e-6, 1.0, 0.8),
        ] {
            let rb = kubelka_reflectance(s, k, x, 0.0);
            let rw = kubelka_reflectance(s, k, x, rg);
            let got = kubelka(rb, rw, rg, x);
            assert!((got.s / s - 1.0).abs() < 1e-9, "S {s} {got:?}");
            assert!((got.k / k - 1.0).abs() < 1e-6, "K {k} {got:?}");
            let a = 1.0 + k / s;
            assert!((got.r_inf - (a - (a * a - 1.0).sqrt())).abs() < 1e-12);
        }
    }

    #[test]
    fn no_absorption_and_complete_hiding_are_the_limits() {
        let (s, x, rg) = (2.0, 0.5, 0.8);
        let rb = kubelka_reflectance(s, 0.0, x, 0.0);
        assert!((rb - s * x / (1.0 + s * x)).abs() < 1e-15);
        let rw = kubelka_reflectance(s, 0.0, x, rg);
        let got = kubelka(rb, rw, rg, x);
        assert!((got.s - s).abs() < 1e-6 && got.k.abs() < 1e-6, "{got:?}");
        // Over black and white alike: hiding is complete.
        let r = 0.6;
        let h = kubelka(r, r, rg, x);
        assert!((h.r_inf - r).abs() < 1e-12 && h.s == f64::INFINITY);
        // No Kubelka layer: darker over white than over black.
        assert!(kubelka(0.5, 0.4, rg, x).s.is_nan());
        // A non-absorbing layer read with a surface reflection of 0.05 on
        // both halves: a < 1 without the bound; K = 0 and S from R_b.
        let (rb_s, rw_s) = (rb + 0.05, rw + 0.05);
        let a = 0.5 * (rw_s + (rb_s - rw_s + rg) / (rb_s * rg));
        assert!(a < 1.0, "{a}");
        let got = kubelka(rb_s, rw_s, rg, x);
        assert_eq!(got.k, 0.0);
        assert_eq!(got.r_inf, 1.0);
        assert!((got.s - rb_s / ((1.0 - rb_s) * x)).abs() < 1e-12, "{got:?}");
    }
}
