//! The drawdowns on the fast model: every reading (a drawdown over one
//! ground) as a function of the unknown pigment's `n`, `k` and grain
//! diameter at one wavelength of the colour grid.
//!
//! The unknown pigment's coefficients at volume fraction 1 come from its
//! grain's cross sections by the baselines' own single scatterer
//! ([`baseline::coefficients`]: Mie, or the scalar sphere beside a
//! Helmholtz scene); the white's are the match's fast model's
//! ([`FastModel`]); a drawdown's layer then has `μ = f_p μ_p + f_w μ_w`
//! (independent scattering) and its reading is [`FastModel::layer_factor`]:
//! the two-flux reflectance on the reading's ground and the surface in the
//! fit's geometry.

use num_complex::Complex64 as C64;

use crate::config::{GrainSize, Measurement};
use crate::optics::baseline::{self, BaselineInput, BaselineSpecies};
use crate::pipeline::baseline::baseline_input;
use crate::pipeline::fine_grid;

use super::super::forward::FastModel;
use super::super::MatchError;
use super::config::FitSpec;

/// One reading as the model sees it.
#[derive(Debug, Clone)]
struct Row {
    thickness_nm: f64,
    pvc: f64,
    white_pvc: f64,
    /// The ground's albedo on the grid.
    albedo: Vec<f64>,
    /// The measured reflectance factor on the grid.
    measured: Vec<f64>,
}

/// The fit's forward model (module docs).
#[derive(Debug, Clone)]
pub struct DrawdownModel {
    fast: FastModel,
    /// The layer with the unknown pigment alone at volume fraction 1 (its
    /// `eps` replaced at each evaluation).
    unknown: BaselineInput,
    geometry: Measurement,
    rows: Vec<Row>,
    /// Whether the base has a white.
    white: bool,
}

impl DrawdownModel {
    /// The model of the checked fit file `spec`.
    pub fn new(spec: &FitSpec) -> Result<DrawdownModel, MatchError> {
        let input = baseline_input(&spec.scene)?.ok_or_else(|| MatchError::Config {
            file: spec.path.clone(),
            message: "base: the fast model needs a scene with a ground".into(),
        })?;
        let band = &spec.scene.wavelengths_nm;
        if input.wavelengths_nm.len() < fine_grid(band).len() {
            return Err(MatchError::Config {
                file: spec.path.clone(),
                message: format!(
                    "key `base.illumination.wavelengths_nm`: the white's material has no data \
                     over the whole band {}–{} nm; narrow the band to its range (`inksim \
                     materials` lists them)",
                    band[0],
                    band[band.len() - 1]
                ),
            });
        }
        let mut white = input.clone();
        white.species.remove(0);
        let fast = FastModel::new(spec.model, &white)?;
        let mut unknown = input.clone();
        unknown.species.truncate(1);
        unknown.species[0].volume_fraction = 1.0;
        unknown.species[0].size = GrainSize::Fixed;
        let grid = input.wavelengths_nm.clone();
        let rows = spec
            .drawdowns
            .iter()
            .flat_map(|d| {
                d.readings.iter().map(|r| Row {
                    thickness_nm: d.thickness_nm,
                    pvc: d.pvc,
                    white_pvc: d.white_pvc,
                    albedo: grid.iter().map(|&w| r.ground.at(w)).collect(),
                    measured: grid.iter().map(|&w| r.spectrum.at(w)).collect(),
                })
            })
            .collect();
        Ok(DrawdownModel {
            fast,
            unknown,
            geometry: spec.geometry,
            rows,
            white: spec.white.is_some(),
        })
    }

    /// The colour grid, nm.
    pub fn wavelengths_nm(&self) -> &[f64] {
        self.fast.wavelengths_nm()
    }

    /// Number of readings (every drawdown's grounds).
    pub fn readings(&self) -> usize {
        self.rows.len()
    }

    /// (μa, μs') of the unknown pigment alone at volume fraction 1 at
    /// wavelength index `l`, for index `n + i k` and grain diameter `d_nm`.
    pub fn unit(&self, l: usize, n: f64, k: f64, d_nm: f64) -> [f64; 2] {
        let mut one = self.unknown.clone();
        one.wavelengths_nm = vec![self.unknown.wavelengths_nm[l]];
        one.species = vec![BaselineSpecies {
            volume_fraction: 1.0,
            diameter_nm: d_nm,
            size: GrainSize::Fixed,
            eps: vec![C64::new(n, k).powi(2)],
        }];
        let c = baseline::coefficients(&one, 0);
        [c.mu_a, c.mu_s_reduced]
    }

    /// The model's reflectance factor of every reading at wavelength index
    /// `l` for the unknown's `n`, `k` and diameter `d_nm`.
    pub fn factors(&self, l: usize, n: f64, k: f64, d_nm: f64) -> Vec<f64> {
        let u = self.unit(l, n, k, d_nm);
        self.rows
            .iter()
            .map(|r| {
                let own = [r.pvc * u[0], r.pvc * u[1]];
                let white = if self.white {
                    vec![r.white_pvc]
                } else {
                    Vec::new()
                };
                let mu = self.fast.mix(l, &white, own);
                self.fast
                    .layer_factor(mu, r.thickness_nm, r.albedo[l], self.geometry)
            })
            .collect()
    }

    /// The measured reflectance factor of every reading at wavelength index
    /// `l`.
    pub fn measured(&self, l: usize) -> Vec<f64> {
        self.rows.iter().map(|r| r.measured[l]).collect()
    }
}
