//! Live recompute of an effect paint (a `[paint]` file): the fast model
//! (METHOD §10) solved again as a control moves, at the live fidelity
//! (module docs, "Fidelity"), its multi-angle colours and the
//! whole BRDF tabulated for the page.
//!
//! - **Controls.** For flakes their volume fraction, the spread of their
//!   normals and, for an interference flake, the coating's thickness; per
//!   ordinary pigment its volume fraction; per layer its thickness.
//! - **The table.** The model's reflection at every (θi, θo, Δφ) of the
//!   page's grid ([`super::table`]), linear between the model's air nodes
//!   (`optics::flakes::air`); each point's spectrum is taken to linear sRGB
//!   under the paint's illuminant and observer (white = 1, no gains), so the
//!   picture's colour at 45° light and a normal view is the 45as45 colour,
//!   and out-of-gamut highlights are drawn as the page's exposure maps them.
//!   The sky term is the scattered light's directional–hemispherical
//!   reflectance (by reciprocity), the specular term the mirror part
//!   (surface, metal ground).
//! - **Fidelity.** Live: every [`LIVE_STEP_NM`] of the paint's wavelengths,
//!   [`LIVE_NODES`] (trapped, escaping) nodes per unit μ, the series cut at
//!   [`LIVE_MODE_TOLERANCE`], the doubling started at [`LIVE_START`] and
//!   the flakes' lobes sampled at [`LIVE_LOBE_SAMPLING`] of the default
//!   (docs/PERFORMANCE.md, "Effect paints in `inksim view`"). At start the
//!   model is also solved at the paint's own settings, and the largest ΔE00
//!   between the two over the multi-angle geometries is stated on the page
//!   ([`LivePaint::describe`]).

use rayon::prelude::*;

use super::live::{LiveModel, Param};
use super::result::{page_colours, rgb_to_xyz, PageResult, PageSparkle};
use super::table::PageBrdf;
use super::ViewError;
use crate::config::paint::{PaintScene, ReflectorSpec};
use crate::optics::baseline::ordinates::OrdinateParams;
use crate::optics::colour::{self, delta_e2000, Observer};
use crate::optics::flakes::air::AirNodes;
use crate::optics::flakes::kernel::NormalQuadrature;
use crate::optics::flakes::multiangle::{self, AngleColour};
use crate::optics::flakes::normals::Orientation;
use crate::optics::flakes::paint::{ModelParams, PaintReflection};
use crate::optics::flakes::sparkle::{
    cell_area_mm2, cone_probability, flakes_per_mm2, half_vector_tilt, ARCMINUTE_RAD,
};
use crate::output::h5::{MeasuredRecord, MeasuredSpectrum};
use crate::pipeline::paint::{
    lacquer_index, model_params, paint_air_directions, reflect_at, reflector,
};

/// The live wavelengths' spacing: at least this (nm), from the paint's own.
pub const LIVE_STEP_NM: f64 = 20.0;
/// Trapped and escaping nodes per unit μ of the live model.
pub const LIVE_NODES: (usize, usize) = (5, 10);
/// The live model's Fourier-series cut ([`ModelParams::mode_tolerance`]).
pub const LIVE_MODE_TOLERANCE: f64 = 1e-2;
/// The live model's thin-layer start ([`ModelParams::start`]).
pub const LIVE_START: f64 = 1e-2;
/// The live model's sampling of the flakes' lobes
/// ([`NormalQuadrature::lobe_sampling`]).
pub const LIVE_LOBE_SAMPLING: f64 = 0.5;

/// What a control changes.
#[derive(Debug, Clone, Copy)]
enum Knob {
    Thickness(usize),
    Pigment(usize, usize),
    Flakes(usize),
    Spread(usize),
    Coating(usize),
}

/// An effect paint recomputed live (module docs).
pub struct LivePaint {
    scene: PaintScene,
    knobs: Vec<(Knob, Param)>,
    observer: Observer,
    wavelengths_nm: Vec<f64>,
    /// Linear sRGB of a unit reflectance factor at each live wavelength.
    weights: Vec<[f64; 3]>,
    params: ModelParams,
    /// Largest ΔE00 of the live colours from the full model's at start.
    live_error: f64,
}

/// Every `step` nm of `wavelengths` (the first and the last kept).
fn thinned(wavelengths: &[f64], step: f64) -> Vec<f64> {
    let mut out: Vec<f64> = vec![];
    for &w in wavelengths {
        if out.last().is_none_or(|&l| w - l >= step - 1e-9) {
            out.push(w);
        }
    }
    if let (Some(&last), Some(&l)) = (wavelengths.last(), out.last()) {
        if last != l {
            out.push(last);
        }
    }
    out
}

impl LivePaint {
    pub fn new(scene: PaintScene) -> Result<LivePaint, ViewError> {
        // The flakes' controls first (what moves an effect finish most),
        // then the pigments', then the thicknesses.
        let (mut flakes, mut pigments, mut thicknesses) = (vec![], vec![], vec![]);
        let param =
            |key: String, label: String, unit: &str, [min, max, step]: [f64; 3], value: f64| {
                Param::ranged(key, label, unit, (min, max, step), value.clamp(min, max))
            };
        for (k, l) in scene.layers.iter().enumerate() {
            thicknesses.push((
                Knob::Thickness(k),
                param(
                    format!("layer{k}_thickness_um"),
                    format!("{}: thickness", l.name),
                    "µm",
                    [0.5, 100.0, 0.5],
                    l.thickness_um,
                ),
            ));
            for (p, pig) in l.pigments.iter().enumerate() {
                pigments.push((
                    Knob::Pigment(k, p),
                    param(
                        format!("layer{k}_pigment{p}"),
                        format!("{}: volume fraction of {}", l.name, pig.name),
                        "1",
                        [0.0, 0.5, 0.002],
                        pig.volume_fraction,
                    ),
                ));
            }
            if let Some(f) = &l.flakes {
                flakes.push((
                    Knob::Flakes(k),
                    param(
                        format!("layer{k}_flakes"),
                        format!("{}: volume fraction of flakes", l.name),
                        "1",
                        [0.0, 0.2, 0.001],
                        f.volume_fraction,
                    ),
                ));
                flakes.push((
                    Knob::Spread(k),
                    param(
                        format!("layer{k}_spread_deg"),
                        format!("{}: spread of the flakes' normals", l.name),
                        "°",
                        [1.0, 40.0, 0.5],
                        f.orientation_sd_deg,
                    ),
                ));
                if let ReflectorSpec::Coated { coating, .. } = &f.reflector {
                    flakes.push((
                        Knob::Coating(k),
                        param(
                            format!("layer{k}_coating_nm"),
                            format!("{}: the flakes' coating thickness", l.name),
                            "nm",
                            [10.0, 600.0, 5.0],
                            coating.thickness_nm,
                        ),
                    ));
                }
            }
        }
        let knobs: Vec<(Knob, Param)> = flakes
            .into_iter()
            .chain(pigments)
            .chain(thicknesses)
            .collect();
        let full = model_params(&scene);
        let params = ModelParams {
            ordinates: OrdinateParams {
                trapped_nodes: LIVE_NODES.0,
                escape_nodes: LIVE_NODES.1,
            },
            mode_tolerance: LIVE_MODE_TOLERANCE,
            start: LIVE_START,
            normals: NormalQuadrature {
                lobe_sampling: LIVE_LOBE_SAMPLING,
                ..full.normals
            },
            ..full
        };
        let observer = Observer::standard(scene.illuminant, scene.observer);
        let wavelengths_nm = thinned(&scene.wavelengths_nm, LIVE_STEP_NM);
        let weights = rgb_weights(&observer, &wavelengths_nm)?;
        let mut live = LivePaint {
            scene,
            knobs,
            observer,
            wavelengths_nm,
            weights,
            params,
            live_error: f64::NAN,
        };
        // The live fidelity's cost in colour at the starting values.
        let fine = live.solve(&live.scene, &full, &live.scene.wavelengths_nm)?;
        let coarse = live.solve(&live.scene, &live.params, &live.wavelengths_nm)?;
        let (_, a) = live.colours(&fine, &live.scene.wavelengths_nm)?;
        let (_, b) = live.colours(&coarse, &live.wavelengths_nm)?;
        live.live_error = a
            .iter()
            .zip(&b)
            .map(|(x, y)| delta_e2000(x.lab, y.lab))
            .fold(0.0, f64::max);
        Ok(live)
    }

    /// The paint with the controls at `values`.
    fn with(&self, values: &[f64]) -> PaintScene {
        let mut s = self.scene.clone();
        for ((knob, p), &v) in self.knobs.iter().zip(values) {
            let v = v.clamp(p.min, p.max);
            match *knob {
                Knob::Thickness(k) => s.layers[k].thickness_um = v,
                Knob::Pigment(k, p) => s.layers[k].pigments[p].volume_fraction = v,
                Knob::Flakes(k) => {
                    if let Some(f) = s.layers[k].flakes.as_mut() {
                        f.volume_fraction = v;
                    }
                }
                Knob::Spread(k) => {
                    if let Some(f) = s.layers[k].flakes.as_mut() {
                        f.orientation_sd_deg = v;
                    }
                }
                Knob::Coating(k) => {
                    if let Some(f) = s.layers[k].flakes.as_mut() {
                        if let ReflectorSpec::Coated { coating, .. } = &mut f.reflector {
                            coating.thickness_nm = v;
                        }
                    }
                }
            }
        }
        s
    }

    fn solve(
        &self,
        scene: &PaintScene,
        params: &ModelParams,
        wavelengths_nm: &[f64],
    ) -> Result<Vec<PaintReflection>, ViewError> {
        let air = paint_air_directions(scene);
        wavelengths_nm
            .par_iter()
            .map(|&wl| {
                reflect_at(scene, params, &air, wl).map_err(|e| ViewError::Live(e.to_string()))
            })
            .collect()
    }

    /// The multi-angle geometries' reflectance-factor spectra (per
    /// geometry, per wavelength) and their colours.
    fn colours(
        &self,
        reflections: &[PaintReflection],
        wavelengths_nm: &[f64],
    ) -> Result<(Vec<Vec<f64>>, Vec<AngleColour>), ViewError> {
        let rows = factors(reflections)?;
        let colours = multiangle::colours(&self.observer, wavelengths_nm, &rows)
            .map_err(|e| ViewError::Live(e.to_string()))?;
        Ok((rows, colours))
    }
}

/// The reflectance factor of each multi-angle geometry at each wavelength.
fn factors(reflections: &[PaintReflection]) -> Result<Vec<Vec<f64>>, ViewError> {
    multiangle::geometries()
        .iter()
        .map(|g| {
            let (view, az) = g.view();
            reflections
                .iter()
                .map(|r| {
                    r.factor(g.illumination_deg, view, az)
                        .map_err(|e| ViewError::Live(e.to_string()))
                })
                .collect()
        })
        .collect()
}

/// Linear sRGB (white = 1) of a unit reflectance factor at each wavelength:
/// a spectrum's colour is the sum of its values times these.
fn rgb_weights(obs: &Observer, wavelengths_nm: &[f64]) -> Result<Vec<[f64; 3]>, ViewError> {
    (0..wavelengths_nm.len())
        .map(|l| {
            let mut e = vec![0.0; wavelengths_nm.len()];
            e[l] = 1.0;
            colour::xyz_from_reflectance(obs, wavelengths_nm, &e)
                .map(|xyz| obs.linear_srgb(xyz))
                .map_err(|e| ViewError::Live(e.to_string()))
        })
        .collect()
}

/// The page's table of the paint's reflections (module docs).
fn table(reflections: &[PaintReflection], weights: &[[f64; 3]], anchor: String) -> PageBrdf {
    let air: Vec<AirNodes> = reflections.iter().map(AirNodes::new).collect();
    let weigh = |f: &dyn Fn(&AirNodes, &PaintReflection) -> f64| -> [f64; 3] {
        let mut rgb = [0.0; 3];
        for ((a, r), w) in air.iter().zip(reflections).zip(weights) {
            let v = f(a, r);
            for ch in 0..3 {
                rgb[ch] += w[ch] * v;
            }
        }
        rgb
    };
    let pi = std::f64::consts::PI;
    let most = reflections.iter().map(|r| r.terms.len()).max().unwrap_or(1);
    // `cos mφ` of every Δφ of the grid (the same in every row), made once.
    let cos_table = std::sync::OnceLock::<Vec<f64>>::new();
    PageBrdf::tabulate(
        &|ti, to, phis| {
            // The page's Δφ is 0 on the light's side; the model's azimuth is
            // 0 on the mirror side.
            let cos = cos_table.get_or_init(|| {
                phis.iter()
                    .flat_map(|&p| {
                        let phi = (180.0 - p).to_radians();
                        (0..most).map(move |m| (m as f64 * phi).cos())
                    })
                    .collect()
            });
            let mut out = vec![[0.0; 3]; phis.len()];
            let mut terms = Vec::new();
            for ((a, r), w) in air.iter().zip(reflections).zip(weights) {
                a.terms(r, ti, to, &mut terms);
                for (o, c) in out.iter_mut().zip(cos.chunks_exact(most)) {
                    let v: f64 = terms.iter().zip(c).map(|(t, c)| t * c).sum::<f64>() / pi;
                    for ch in 0..3 {
                        o[ch] += w[ch] * v;
                    }
                }
            }
            out
        },
        &|t| weigh(&|a, r| a.scattered_albedo(r, t)),
        &|t| weigh(&|a, r| a.mirror(r, t)),
        [1.0; 3],
        anchor,
    )
}

/// The glints of the paint's first layer with flakes, for the page
/// ([`PageSparkle`]); None without flakes.
fn sparkle(
    scene: &PaintScene,
    wavelengths_nm: &[f64],
    weights: &[[f64; 3]],
) -> Result<Option<PageSparkle>, ViewError> {
    let Some((layer, f)) = scene
        .layers
        .iter()
        .find_map(|l| l.flakes.as_ref().map(|f| (l, f)))
    else {
        return Ok(None);
    };
    let live = |e: crate::pipeline::PipelineError| ViewError::Live(e.to_string());
    let cell_mm2 = cell_area_mm2(scene.sparkle.viewing_distance_mm, ARCMINUTE_RAD);
    let per_mm2 = flakes_per_mm2(
        f.volume_fraction,
        layer.thickness_um,
        f.diameter_um,
        f.thickness_nm() / 1000.0,
    );
    let flake_mm2 = std::f64::consts::PI / 4.0 * f.mean_square_diameter_um2() * 1e-6;
    let mut glint = [0.0; 3];
    let mut n_mid = 1.5;
    for (l, (&wl, w)) in wavelengths_nm.iter().zip(weights).enumerate() {
        let n = lacquer_index(scene, wl).map_err(live)?;
        if l == wavelengths_nm.len() / 2 {
            n_mid = n;
        }
        let r = reflector(&f.reflector, wl)
            .map_err(live)?
            .powers(n, wl, 1.0)
            .r;
        for ch in 0..3 {
            glint[ch] += w[ch] * r;
        }
    }
    let per_cell = per_mm2 * cell_mm2;
    let spread = Orientation {
        sigma_rad: f.orientation_sd_deg.to_radians(),
    };
    let p45 = cone_probability(
        &spread,
        half_vector_tilt(45.0, n_mid),
        scene.sparkle.acceptance_deg.to_radians(),
    );
    Ok(Some(PageSparkle {
        flakes_per_cell: per_cell,
        mean_glints_45: per_cell * p45,
        sigma_deg: f.orientation_sd_deg,
        acceptance_deg: scene.sparkle.acceptance_deg,
        lacquer_index: n_mid,
        coverage: (flake_mm2 / cell_mm2).min(1.0),
        glint_rgb: glint,
        cell_mm: cell_mm2.sqrt(),
        viewing_distance_mm: scene.sparkle.viewing_distance_mm,
    }))
}

impl LiveModel for LivePaint {
    fn describe(&self) -> String {
        format!(
            "effect paint, fast model (METHOD §10) recomputed live at {} wavelengths ({}–{} nm) \
             and {}+{} nodes per unit μ: at the starting values its multi-angle colours are within \
             ΔE00 {:.2} of the full model's ({} wavelengths, the paint's nodes)",
            self.wavelengths_nm.len(),
            self.wavelengths_nm.first().copied().unwrap_or(0.0),
            self.wavelengths_nm.last().copied().unwrap_or(0.0),
            LIVE_NODES.0,
            LIVE_NODES.1,
            self.live_error,
            self.scene.wavelengths_nm.len()
        )
    }

    fn params(&self) -> Vec<Param> {
        self.knobs.iter().map(|(_, p)| p.clone()).collect()
    }

    fn compute(&self, values: &[f64]) -> Result<PageResult, ViewError> {
        let scene = self.with(values);
        let wl = &self.wavelengths_nm;
        let reflections = self.solve(&scene, &self.params, wl)?;
        let (rows, angle) = self.colours(&reflections, wl)?;
        // 45as45 (45° light, normal view: the 45°/0° geometry) first.
        let mut order: Vec<usize> = (0..angle.len()).collect();
        order.sort_by_key(|&g| {
            let geo = angle[g].geometry;
            !(geo.illumination_deg == 45.0 && geo.aspecular_deg == 45.0)
        });
        let records: Vec<MeasuredRecord> = order
            .iter()
            .map(|&g| MeasuredRecord {
                geometry: angle[g].geometry.label(),
                lab: angle[g].lab,
                xyz: angle[g].xyz,
                lab_se: None,
                de00_se: None,
            })
            .collect();
        let spectra: Vec<MeasuredSpectrum> = order
            .iter()
            .map(|&g| MeasuredSpectrum {
                geometry: angle[g].geometry.label(),
                wavelengths_nm: wl.clone(),
                spectrum: rows[g].clone(),
                solved_nm: wl.clone(),
                solved: rows[g].clone(),
            })
            .collect();
        let obs = &self.observer;
        let colours = page_colours(&records, &spectra, obs);
        let flop = multiangle::flop_index_of(&angle)
            .map_or("no flop index".into(), |f| format!("flop index {f:.2}"));
        let sparkle = sparkle(&scene, wl, &self.weights)?;
        let glints = sparkle.as_ref().map_or(String::new(), |s| {
            format!(
                "; glints by the sparkle model, a canvas pixel one resolution cell at {:.0} mm \
                 ({:.0} flakes per cell, {:.2} glints per cell under a 45° lamp)",
                s.viewing_distance_mm, s.flakes_per_cell, s.mean_glints_45
            )
        });
        let brdf = table(
            &reflections,
            &self.weights,
            format!(
                "colour from each direction's spectrum ({} wavelengths, no gains); {flop}{glints}",
                wl.len()
            ),
        );
        Ok(PageResult {
            name: format!("{} (live)", self.scene.output.name),
            model: self.describe(),
            conditions: format!(
                "{}, {}°",
                self.scene.illuminant.name(),
                self.scene.observer.degrees()
            ),
            colours,
            brdf,
            labels: vec![],
            rgb_to_xyz: rgb_to_xyz(obs),
            white_xyz: obs.white_xyz(),
            sparkle,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinned_keeps_the_ends_and_the_step() {
        let w: Vec<f64> = (0..31).map(|k| 400.0 + 10.0 * k as f64).collect();
        let t = thinned(&w, 20.0);
        assert_eq!(t.len(), 16);
        assert_eq!((t[0], t[15]), (400.0, 700.0));
        let w: Vec<f64> = (0..30).map(|k| 400.0 + 10.0 * k as f64).collect();
        let t = thinned(&w, 20.0);
        assert_eq!(*t.last().unwrap(), 690.0);
        assert_eq!(t[t.len() - 2], 680.0);
    }
}
