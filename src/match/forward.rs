//! The fast forward model: a one-layer scene's Kubelka–Munk baseline
//! (`kubelka-munk` or `kubelka-munk-scene`, [`crate::optics::baseline`]) as
//! a function of the recipe — each pigment's volume fraction, the layer's
//! thickness and the paper's albedo.
//!
//! Under independent scattering the layer's absorption and reduced
//! scattering coefficients are sums over the pigments of their number
//! density times their grains' cross sections, so they are linear in the
//! volume fractions: `μa(λ) = Σ f_s μa_s(λ)`, `μs'(λ) = Σ f_s μs'_s(λ)`,
//! with `μa_s`, `μs'_s` the coefficients of pigment `s` alone at volume
//! fraction 1 ([`crate::optics::baseline::coefficients`], the grains' Mie
//! or scalar-sphere cross sections over their size distribution). They are
//! computed once; a recipe then costs the two-flux reflectance
//! ([`km::reflectance`], `K = 2 μa`, `S = 3/4 μs'`), the surface
//! (Saunderson's correction, [`Saunderson`], its Fresnel reflectances
//! computed once) and the colour integral per
//! wavelength — microseconds, the same numbers as the baseline itself
//! (tests/match.rs checks them against `baseline::baseline_colours`).
//! The adding–doubling models depend on the phase function, not only on
//! these sums, and are not offered here.

use crate::config::{Baseline, Measurement};
use crate::optics::baseline::{self, km, BaselineInput, Saunderson};
use crate::optics::colour::{self, ColourError, Observer};

use super::MatchError;

/// A recipe: what the search varies.
#[derive(Debug, Clone, PartialEq)]
pub struct Recipe {
    /// Volume fraction of each palette pigment (0 for one not used).
    pub fractions: Vec<f64>,
    /// Layer thickness, nm.
    pub thickness_nm: f64,
    /// The paper's (ground's) Lambertian albedo.
    pub paper_albedo: f64,
}

/// The fast model of a layer of the palette's pigments (module docs).
#[derive(Debug, Clone)]
pub struct FastModel {
    model: Baseline,
    /// The surface in each geometry, in [`Measurement::ALL`] order.
    surfaces: [Saunderson; 3],
    /// `r_i` and `r_ed` of the scene backing (`kubelka-munk-scene`).
    backing: (f64, f64),
    wavelengths_nm: Vec<f64>,
    /// `[species][wavelength]`: (μa, μs') at volume fraction 1, 1/nm.
    unit: Vec<Vec<[f64; 2]>>,
}

impl FastModel {
    /// The model `model` of the layer `input` (its species the palette, their
    /// volume fractions ignored). Kubelka–Munk models only (module docs).
    pub fn new(model: Baseline, input: &BaselineInput) -> Result<FastModel, MatchError> {
        if !matches!(model, Baseline::KubelkaMunk | Baseline::KubelkaMunkScene) {
            return Err(MatchError::Model(model.name()));
        }
        let unit = (0..input.species.len())
            .map(|s| {
                let mut alone = input.clone();
                alone.species = vec![input.species[s].clone()];
                alone.species[0].volume_fraction = 1.0;
                (0..input.wavelengths_nm.len())
                    .map(|l| {
                        let c = baseline::coefficients(&alone, l);
                        [c.mu_a, c.mu_s_reduced]
                    })
                    .collect()
            })
            .collect();
        let fresnel = baseline::surfaces(model, input.equation);
        let n = input.binder_index;
        Ok(FastModel {
            model,
            surfaces: Measurement::ALL.map(|m| Saunderson::of(fresnel, m, n)),
            backing: (fresnel.internal(n), fresnel.diffuse_external(n)),
            wavelengths_nm: input.wavelengths_nm.clone(),
            unit,
        })
    }

    /// The baseline model it computes.
    pub fn model(&self) -> Baseline {
        self.model
    }

    /// Number of palette pigments.
    pub fn species(&self) -> usize {
        self.unit.len()
    }

    /// The spectral grid, nm.
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    /// The reflectance factor geometry `m` reads from the recipe's layer, on
    /// the grid.
    pub fn factor(&self, recipe: &Recipe, m: Measurement) -> Vec<f64> {
        (0..self.wavelengths_nm.len())
            .map(|l| {
                let mu = self.mix(l, &recipe.fractions, [0.0; 2]);
                self.layer_factor(mu, recipe.thickness_nm, recipe.paper_albedo, m)
            })
            .collect()
    }

    /// (μa, μs') of palette pigment `s` alone at volume fraction 1 at
    /// wavelength index `l`, 1/nm.
    pub fn unit(&self, s: usize, l: usize) -> [f64; 2] {
        self.unit[s][l]
    }

    /// (μa, μs') at wavelength index `l` of the palette at volume
    /// `fractions` plus `extra` (another pigment's own share), 1/nm.
    pub fn mix(&self, l: usize, fractions: &[f64], extra: [f64; 2]) -> [f64; 2] {
        let mut mu = extra;
        for (u, f) in self.unit.iter().zip(fractions) {
            mu[0] += f * u[l][0];
            mu[1] += f * u[l][1];
        }
        mu
    }

    /// The reflectance factor geometry `m` reads from a layer of absorption
    /// and reduced scattering coefficients `mu` (1/nm) and thickness
    /// `thickness_nm` on a ground of albedo `albedo` (the paper; 0 for a
    /// black ground): the two-flux reflectance on the model's backing, then
    /// the surface.
    pub fn layer_factor(
        &self,
        mu: [f64; 2],
        thickness_nm: f64,
        albedo: f64,
        m: Measurement,
    ) -> f64 {
        let rg = match self.model {
            Baseline::KubelkaMunkScene => km::scene_backing(albedo, self.backing.0, self.backing.1),
            _ => albedo,
        };
        let surface = self.surfaces[Measurement::ALL.iter().position(|g| *g == m).unwrap_or(0)];
        surface.factor(km::reflectance(2.0 * mu[0], 0.75 * mu[1], thickness_nm, rg))
    }

    /// CIELAB of a reflectance factor on the grid, for `observer`.
    pub fn lab_of(&self, observer: &Observer, factor: &[f64]) -> Result<[f64; 3], ColourError> {
        let xyz = colour::xyz_from_reflectance(observer, &self.wavelengths_nm, factor)?;
        Ok(colour::xyz_to_lab(xyz, observer.white_xyz()))
    }

    /// CIELAB of the recipe in geometry `m`, for `observer`.
    pub fn lab(
        &self,
        observer: &Observer,
        recipe: &Recipe,
        m: Measurement,
    ) -> Result<[f64; 3], ColourError> {
        self.lab_of(observer, &self.factor(recipe, m))
    }
}
