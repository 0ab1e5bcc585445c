//! The effect paint's forward model: the fast flake model of the pipeline
//! (`pipeline::paint::reflect_at`, METHOD §10) as a function of the
//! recipe. A recipe sets, in a copy of the base paint, each varied layer's
//! flake volume fraction and coating thickness and its ordinary pigments'
//! volume fractions (an unused optional pigment is taken out of its
//! layer); the paint is then solved at every wavelength of its grid (in
//! parallel) on the air directions `inksim run` solves it on
//! (`paint_air_directions`, the base's sparkle lights included, so that
//! the colours are those `inksim run` reports for the same paint), and the
//! multi-angle colours are computed as `inksim run` computes them
//! (`multiangle::colours`), under the target's illuminant and observer.
//! Nothing of the model is reimplemented here.

use rayon::prelude::*;

use crate::config::paint::{PaintScene, ReflectorSpec};
use crate::optics::colour::Observer;
use crate::optics::flakes::multiangle::{self, AngleColour};
use crate::optics::flakes::paint::ModelParams;
use crate::pipeline::paint::{model_params, paint_air_directions, reflect_at};

use super::super::MatchError;

/// What a recipe sets in the base paint.
#[derive(Debug, Clone, PartialEq)]
pub enum Setting {
    /// The flakes' volume fraction of layer `layer`.
    Concentration { layer: usize, fraction: f64 },
    /// The coating thickness of layer `layer`'s coated flakes, nm.
    Coating { layer: usize, nm: f64 },
    /// The volume fraction of pigment `pigment` of layer `layer` (0: out of
    /// the layer).
    Pigment {
        layer: usize,
        pigment: usize,
        fraction: f64,
    },
}

/// The fast flake model of the base paint (module docs).
#[derive(Debug, Clone)]
pub struct EffectModel {
    base: PaintScene,
    params: ModelParams,
    air_deg: Vec<f64>,
}

impl EffectModel {
    /// The model of `base` at its own resolution (`[paint.model]`).
    pub fn new(base: &PaintScene) -> EffectModel {
        EffectModel {
            params: model_params(base),
            air_deg: paint_air_directions(base),
            base: base.clone(),
        }
    }

    /// The paint's wavelengths, nm.
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.base.wavelengths_nm
    }

    /// The base paint with `settings` applied.
    pub fn paint(&self, settings: &[Setting]) -> PaintScene {
        let mut p = self.base.clone();
        let mut out: Vec<(usize, usize)> = Vec::new();
        for s in settings {
            match *s {
                Setting::Concentration { layer, fraction } => {
                    if let Some(f) = p.layers[layer].flakes.as_mut() {
                        f.volume_fraction = fraction;
                    }
                }
                Setting::Coating { layer, nm } => {
                    if let Some(f) = p.layers[layer].flakes.as_mut() {
                        if let ReflectorSpec::Coated { coating, .. } = &mut f.reflector {
                            coating.thickness_nm = nm;
                        }
                    }
                }
                Setting::Pigment {
                    layer,
                    pigment,
                    fraction,
                } => {
                    if fraction > 0.0 {
                        p.layers[layer].pigments[pigment].volume_fraction = fraction;
                    } else {
                        out.push((layer, pigment));
                    }
                }
            }
        }
        // Taken out last, highest index first, so the indices above hold.
        out.sort_unstable_by(|a, b| b.cmp(a));
        for (layer, pigment) in out {
            p.layers[layer].pigments.remove(pigment);
        }
        p
    }

    /// The reflectance factor of every multi-angle geometry
    /// ([`multiangle::geometries`] order) of `paint`, per wavelength.
    pub fn factors(&self, paint: &PaintScene) -> Result<Vec<Vec<f64>>, MatchError> {
        let per_wavelength = paint
            .wavelengths_nm
            .par_iter()
            .map(|&wl| {
                let r = reflect_at(paint, &self.params, &self.air_deg, wl)?;
                multiangle::geometries()
                    .iter()
                    .map(|g| {
                        let (view, az) = g.view();
                        r.factor(g.illumination_deg, view, az)
                            .map_err(|e| crate::pipeline::PipelineError::from(e).into())
                    })
                    .collect::<Result<Vec<f64>, MatchError>>()
            })
            .collect::<Result<Vec<Vec<f64>>, MatchError>>()?;
        let geometries = multiangle::geometries().len();
        Ok((0..geometries)
            .map(|g| per_wavelength.iter().map(|f| f[g]).collect())
            .collect())
    }

    /// The multi-angle colours of the base with `settings`, for `observer`.
    pub fn colours(
        &self,
        observer: &Observer,
        settings: &[Setting],
    ) -> Result<Vec<AngleColour>, MatchError> {
        let paint = self.paint(settings);
        let factors = self.factors(&paint)?;
        Ok(multiangle::colours(
            observer,
            &paint.wavelengths_nm,
            &factors,
        )?)
    }
}
