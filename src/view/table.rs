//! The layer's reflection as the page's shader reads it: the diffuse BRDF of
//! layer + substrate over (θi, θo, Δφ), its reflectance under a uniform sky
//! and the specular order's reflectance against the viewing angle, in linear
//! sRGB, with the per-channel gains that carry the colour of the result's
//! measured 45°/0° colour.
//!
//! - **Grid.** θi and θo every [`THETA_STEP_DEG`] over [0°, 90°], Δφ every
//!   [`PHI_STEP_DEG`] over [0°, 180°] (the layer is isotropic in azimuth, so
//!   the BRDF is even in Δφ). Δφ is the angle between the projections of the
//!   directions towards the light and towards the viewer on the surface:
//!   0° the viewer on the light's side (back-scatter), 180° the mirror side.
//!   The shader interpolates the table linearly in all three.
//! - **Values.** [`RgbBrdf::eval`] (the MERL export's and the preview's
//!   evaluation: the diffuse tables interpolated between the solved
//!   illumination angles and held beyond the largest, the paper term),
//!   [`RgbBrdf::sky`] and [`RgbBrdf::specular`].
//! - **Colour.** The RGB BRDF weights the solved wavelengths linearly; the
//!   result's colours integrate the fine spectrum through the spectral proxy.
//!   As the preview matches its sky colour to the tile, the table is scaled
//!   per channel so that `π f(45°, 0°)` is the result's measured 45°/0° colour
//!   under the result's illuminant and observer, gamut mapped as the tile
//!   draws it (lightness and hue kept): gain = target / solved within
//!   [[`GAIN_MIN`], [`GAIN_MAX`]] of the preview. Without a measured 45°/0°
//!   colour the table is the solved wavelengths' RGB as it is, and
//!   [`PageBrdf::anchor`] says so.

use rayon::prelude::*;
use serde::Serialize;

use crate::optics::colour::{gamut, Observer};
use crate::output::merl::RgbBrdf;
use crate::output::render::preview::{GAIN_MAX, GAIN_MIN};

/// Spacing of the polar angles θi, θo of the table (deg).
pub const THETA_STEP_DEG: f64 = 5.0;
/// Spacing of the azimuth difference Δφ (deg).
pub const PHI_STEP_DEG: f64 = 10.0;

/// The diffuse BRDF at `(θi, θo)` (deg) for each `Δφ` of a slice (deg):
/// one row of [`PageBrdf::tabulate`]'s table.
pub type BrdfRow<'a> = dyn Fn(f64, f64, &[f64]) -> Vec<[f64; 3]> + Sync + 'a;

/// The table shipped to the page (module docs); JSON field names as here.
#[derive(Debug, Clone, Serialize)]
pub struct PageBrdf {
    /// Nodes along θi and θo (0° … 90°).
    pub n_theta: usize,
    /// Nodes along Δφ (0° … 180°).
    pub n_phi: usize,
    /// Diffuse BRDF (1/sr) in linear sRGB, gains applied, flattened
    /// `((θi · n_theta + θo) · n_phi + Δφ) · 3 + channel`.
    pub brdf: Vec<f32>,
    /// Reflectance of the diffuse BRDF under a uniform sky against θo,
    /// `θo · 3 + channel`.
    pub sky: Vec<f32>,
    /// The specular order's reflectance against θo, `θo · 3 + channel`.
    pub specular: Vec<f32>,
    /// The per-channel gains applied (1 where nothing was matched).
    pub gain: [f64; 3],
    /// How the colour was set, in words, for the page.
    pub anchor: String,
}

fn nodes(step: f64, max: f64) -> Vec<f64> {
    let n = (max / step).round() as usize;
    (0..=n).map(|k| k as f64 * step).collect()
}

fn polar(theta_deg: f64, phi_deg: f64) -> [f64; 3] {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
}

/// Linear sRGB of the CIELAB colour `lab` (under `obs`) as sRGB shows it:
/// gamut mapped as the tile draws it.
pub fn display_rgb(obs: &Observer, lab: [f64; 3]) -> [f64; 3] {
    gamut::lab_to_linear_srgb(obs, gamut::map_lab(obs, lab).lab)
}

/// Per-channel gains taking `π f(45°, 0°)` to the gamut-mapped 45°/0° colour
/// `lab` (CIELAB under `obs`).
fn gains_to(brdf: &RgbBrdf, obs: &Observer, lab: [f64; 3]) -> [f64; 3] {
    let target = display_rgb(obs, lab);
    let solved = brdf.eval(polar(45.0, 0.0), [0.0, 0.0, 1.0]);
    std::array::from_fn(|ch| {
        let s = std::f64::consts::PI * solved[ch];
        if s > 1e-9 {
            (target[ch] / s).clamp(GAIN_MIN, GAIN_MAX)
        } else {
            1.0
        }
    })
}

impl PageBrdf {
    /// A Lambertian body of reflectance `rgb` (linear sRGB) under a flat
    /// surface whose specular reflectance against the polar angle (deg) is
    /// `specular`: `f = rgb/π` everywhere, `sky = rgb`.
    pub fn lambertian(rgb: [f64; 3], specular: &dyn Fn(f64) -> f64, anchor: String) -> PageBrdf {
        let thetas = nodes(THETA_STEP_DEG, 90.0);
        let phis = nodes(PHI_STEP_DEG, 180.0);
        let f = rgb.map(|v| (v / std::f64::consts::PI) as f32);
        let n = thetas.len() * thetas.len() * phis.len();
        PageBrdf {
            n_theta: thetas.len(),
            n_phi: phis.len(),
            brdf: (0..n).flat_map(|_| f).collect(),
            sky: thetas.iter().flat_map(|_| rgb.map(|v| v as f32)).collect(),
            specular: thetas
                .iter()
                .flat_map(|&t| [specular(t) as f32; 3])
                .collect(),
            gain: [1.0; 3],
            anchor,
        }
    }

    /// The table of `brdf`; `anchor_45_0` is the result's measured 45°/0°
    /// colour (CIELAB) and the observer it is under, when it has one.
    pub fn new(brdf: &RgbBrdf, anchor_45_0: Option<([f64; 3], &Observer)>) -> PageBrdf {
        let (gain, anchor) = match anchor_45_0 {
            Some((lab, obs)) => {
                let g = gains_to(brdf, obs, lab);
                (
                    g,
                    format!(
                        "colour matched to the result's 45°/0° colour (gamut mapped): \
                         RGB gains {:.2}, {:.2}, {:.2}",
                        g[0], g[1], g[2]
                    ),
                )
            }
            None => (
                [1.0; 3],
                "colour from the solved wavelengths alone (the result has no measured \
                 45°/0° colour to match)"
                    .to_string(),
            ),
        };
        PageBrdf::tabulate(
            &|ti, to, phis| {
                let wi = polar(ti, 0.0);
                phis.iter().map(|&p| brdf.eval(wi, polar(to, p))).collect()
            },
            &|t| brdf.sky(t),
            &|t| brdf.specular(t),
            gain,
            anchor,
        )
    }

    /// The table on the grid of the module docs: `row(θi, θo, Δφs)` the
    /// diffuse BRDF (1/sr, linear sRGB) at each `Δφ` (deg), `sky(θo)` and
    /// `specular(θo)` as [`PageBrdf`]'s fields, each multiplied by `gain`.
    pub fn tabulate(
        row: &BrdfRow<'_>,
        sky: &dyn Fn(f64) -> [f64; 3],
        specular: &dyn Fn(f64) -> [f64; 3],
        gain: [f64; 3],
        anchor: String,
    ) -> PageBrdf {
        let thetas = nodes(THETA_STEP_DEG, 90.0);
        let phis = nodes(PHI_STEP_DEG, 180.0);
        let table: Vec<f32> = thetas
            .par_iter()
            .flat_map_iter(|&ti| {
                let phis = &phis;
                thetas.iter().flat_map(move |&to| {
                    row(ti, to, phis)
                        .into_iter()
                        .flat_map(move |f| (0..3).map(move |ch| (f[ch] * gain[ch]) as f32))
                })
            })
            .collect();
        let per_theta = |f: &dyn Fn(f64) -> [f64; 3]| -> Vec<f32> {
            thetas
                .iter()
                .flat_map(|&t| {
                    let v = f(t);
                    (0..3).map(move |ch| (v[ch] * gain[ch]) as f32)
                })
                .collect()
        };
        PageBrdf {
            n_theta: thetas.len(),
            n_phi: phis.len(),
            brdf: table,
            sky: per_theta(sky),
            specular: per_theta(specular),
            gain,
            anchor,
        }
    }
}
