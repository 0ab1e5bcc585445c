//! Optics — the classical baselines beside the wave solution (METHOD §6):
//! Kubelka–Munk with Saunderson's correction, Kubelka–Munk with the wave
//! scene's boundary, and radiative transfer by adding–doubling with either
//! boundary. Which ones a scene gets is `appearance.baseline`
//! ([`crate::config::Baseline`]).
//!
//! All share the single scatterer and independent scattering:
//! 1. **Single scatterer** ([`sphere`]): each pigment grain is replaced by
//!    the sphere of equal volume (radius `d/2`, `d` the grain's effective
//!    diameter: the shape and any clusters are not seen) in the binder
//!    (real index `n_b`). Its cross sections,
//!    asymmetry parameter `g` and phase function come from the sphere
//!    solution of the scene's equation ([`grain::GrainModel`]) at the
//!    wavelength in the binder `λ/n_b` with relative permittivity
//!    `ε_s/ε_b`, `ε_s = (n + ik)²`: beside the scalar Helmholtz equation the
//!    *scalar* partial-wave sphere ([`sphere`]), beside Maxwell's equations
//!    Mie theory ([`mie`], phase function of natural light) — each the
//!    consistent single scatterer of the equation the wave solution
//!    solves.
//! 2. **Sizes** ([`sizes`]): a fixed size is the one sphere of the nominal
//!    diameter `d` (`diameter_nm`). A size distribution (`pigment.size`,
//!    normal or log-normal, truncated at 3σ as the geometry draws it) is a
//!    Gauss–Legendre quadrature over the diameters, each node a sub-species
//!    holding its share of the volume fraction: number densities in
//!    proportion to the number distribution the geometry draws from, with
//!    `Σ N(d_i) π d_i³/6 = f`, so μa, μs and the phase moments below are
//!    averaged over the *number* of grains of each size at the species'
//!    volume fraction.
//! 3. **Independent scattering**: number density `N_s = f_s / (π d³/6)`
//!    per species (per size node), absorption coefficient
//!    `μa = Σ N_s σ_abs,s`, scattering coefficient
//!    `μs = Σ N_s σ_sca,s`: the grains scatter as if alone (no near-field
//!    coupling, no correlated positions, no dependent scattering at high
//!    PVC). A molecular (dissolved) pigment scatters nothing and absorbs as
//!    its dilute limit `f_s k₀ Im ε_s / n_b` (the small-sphere
//!    `σ_abs = k V Im(ε_s/ε_b)` per volume), so the layer is Beer's law.
//!
//! **Kubelka–Munk** (`kubelka-munk`, [`kubelka_munk`]):
//! 4. **Diffuse light**: `K = 2 μa`, `S = (3/4) μs'`, `μs' = μs (1 − g)` —
//!    the common conversion of the diffusion approximation (light inside
//!    fully diffuse, mean path through a slab twice its thickness; S from
//!    matching the diffusion equation's albedo) — and the KM reflectance of
//!    the layer of thickness `X` on the Lambertian paper `R_g`
//!    ([`km::reflectance`]).
//! 5. **Surface** (Saunderson, [`km::saunderson`]): `r_e` the unpolarised
//!    Fresnel reflectance of the flat binder surface from air at the
//!    geometry's directed angle (45° for 45°/0°, 8° for d/8°), `r_i` the
//!    Fresnel reflectance from inside averaged over a Lambertian hemisphere
//!    (computed). 45°/0° and d/8° SCE leave `r_e` itself out (specular
//!    excluded), d/8° SCI includes it. The paper is in optical contact with
//!    the binder, as Saunderson's correction assumes.
//!
//! **Kubelka–Munk, scene boundary** (`kubelka-munk-scene`): the same body,
//! but under it the wave scene's boundary — the binder's lower surface, an
//! air gap, the paper — as the effective backing
//! `R_g = r_i + (1 − r_i) ρ (1 − r_ed)/(1 − ρ r_ed)` ([`km::scene_backing`]),
//! and every surface with the Fresnel reflectance of the solver's equation
//! ([`fresnel::Fresnel`]: s-like (TE) beside Helmholtz, the mean of s and p
//! beside Maxwell; `r_e`, `r_ed` from air, `r_i` from inside).
//!
//! **Adding–doubling** (`adding-doubling`, scene boundary;
//! `adding-doubling-contact`, paper in optical contact): the radiative
//! transfer equation itself for the same medium, with the phase function,
//! refraction and total internal reflection at the surfaces (the Fresnel
//! law of the solver's equation, as for `kubelka-munk-scene`) and the exact
//! measurement directions ([`transfer`]).
//!
//! **Colour**: the spectrum on the spectral proxy's fine grid, through the
//! scene's observer and illuminant, CIELAB per geometry, and CIEDE2000 to
//! the wave solution's colour in the same geometry.
//!
//! The binder's own absorption and the layer's relief are in none of them.

pub mod adding;
pub mod doubling;
pub mod fresnel;
pub mod grain;
pub mod halftone;
pub mod km;
pub mod matrix;
pub mod mie;
pub mod ordinates;
pub mod sizes;
pub mod special;
pub mod sphere;
pub mod transfer;

use crate::config::{Baseline, Equation, GrainSize, Measurement};
use crate::optics::colour::{self, ColourError, Observer};
use fresnel::Fresnel;
use grain::GrainModel;
use num_complex::Complex64 as C64;
use std::f64::consts::PI;
use thiserror::Error;

/// Why a baseline could not be computed.
#[derive(Debug, Error)]
pub enum BaselineError {
    #[error("baseline: the binder index must be at least 1 for adding–doubling, got {0}")]
    BinderIndex(f64),
    #[error("baseline: the quadrature needs at least one node per panel")]
    Nodes,
    #[error("baseline: the layer's optical thickness is not a finite non-negative number ({0})")]
    Thickness(f64),
    #[error("baseline: a matrix of the adding–doubling inter-reflections is singular")]
    Singular,
    #[error("baseline: the quadrature has no node in the air direction {0}°")]
    NoDirection(f64),
    #[error("baseline: {0} is a model of one layer; a stack takes adding-doubling or adding-doubling-contact")]
    StackModel(&'static str),
    #[error("baseline: colour: {0}")]
    Colour(#[from] ColourError),
}

/// One pigment as the baseline sees it.
#[derive(Debug, Clone)]
pub struct BaselineSpecies {
    /// Volume fraction of the layer.
    pub volume_fraction: f64,
    /// Diameter of the equal-volume sphere, nm; 0 for a dissolved pigment.
    /// The nominal diameter of `size`.
    pub diameter_nm: f64,
    /// The distribution of the grains' diameters around `diameter_nm`, as
    /// the geometry draws them ([`sizes`]).
    pub size: GrainSize,
    /// Permittivity `(n + ik)²` at each wavelength of the grid.
    pub eps: Vec<C64>,
}

/// The layer and backing the baseline is computed for.
#[derive(Debug, Clone)]
pub struct BaselineInput {
    /// The fine grid, nm.
    pub wavelengths_nm: Vec<f64>,
    pub binder_index: f64,
    pub thickness_nm: f64,
    pub paper_albedo: f64,
    pub species: Vec<BaselineSpecies>,
    /// The quadrature over each species' size distribution.
    pub size_quadrature: sizes::SizeQuadrature,
    /// The equation of the wave solution the baseline stands beside: it
    /// picks the grains' sphere solution ([`GrainModel::of`]) and the flat
    /// surfaces' Fresnel law ([`surfaces`]).
    pub equation: Equation,
}

impl BaselineInput {
    /// The same layer with other pigment volume fractions (`fractions[s]`
    /// for species `s`; species beyond `fractions` keep theirs), thickness
    /// and paper albedo: what a formulation changes.
    pub fn with_recipe(&self, fractions: &[f64], thickness_nm: f64, paper_albedo: f64) -> Self {
        let mut input = self.clone();
        for (s, f) in input.species.iter_mut().zip(fractions) {
            s.volume_fraction = *f;
        }
        input.thickness_nm = thickness_nm;
        input.paper_albedo = paper_albedo;
        input
    }
}

/// The KM coefficients at one wavelength (1/nm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KmCoefficients {
    /// Absorption coefficient μa.
    pub mu_a: f64,
    /// Reduced scattering coefficient μs'.
    pub mu_s_reduced: f64,
    /// `K = 2 μa`.
    pub k: f64,
    /// `S = (3/4) μs'`.
    pub s: f64,
}

/// One grain species, or one diameter of its size distribution, at one
/// wavelength, as the independent-scattering models see it: number density
/// (1/nm³), the binder's wavenumber `k`, the permittivity relative to the
/// binder, the equal-volume radius and the cross sections of the input's
/// [`GrainModel`].
pub(crate) struct GrainTerms {
    pub number: f64,
    pub k: f64,
    pub eps_rel: C64,
    pub radius: f64,
    pub cross: sphere::CrossSections,
}

/// The layer at wavelength index `l`: the dissolved pigments' absorption
/// coefficient (their dilute limit `f k₀ Im ε / n_b`, 1/nm) and the terms
/// of each grain species' size nodes ([`sizes::size_nodes`]; one for a
/// fixed size), in species order: node `i` of a species holds the volume
/// fraction `f s_i` (`s_i` its volume share) as grains of its diameter.
pub(crate) fn at_wavelength(input: &BaselineInput, l: usize) -> (f64, Vec<GrainTerms>) {
    let nb = input.binder_index;
    let eps_b = nb * nb;
    let k0 = 2.0 * PI / input.wavelengths_nm[l];
    let model = GrainModel::of(input.equation);
    let mut dissolved = 0.0;
    let mut grains = Vec::new();
    for sp in &input.species {
        let eps = sp.eps[l];
        if sp.diameter_nm <= 0.0 {
            dissolved += sp.volume_fraction * k0 * eps.im / nb;
            continue;
        }
        let index = eps.sqrt().norm().max(nb);
        let n =
            input
                .size_quadrature
                .nodes(sp.size, sp.diameter_nm, index, input.wavelengths_nm[l]);
        for node in sizes::size_nodes(sp.size, sp.diameter_nm, n) {
            let d = node.diameter_nm;
            let (k, eps_rel, radius) = (k0 * nb, eps / eps_b, d / 2.0);
            grains.push(GrainTerms {
                number: sp.volume_fraction * node.volume_share / (PI * d.powi(3) / 6.0),
                k,
                eps_rel,
                radius,
                cross: model.cross_sections(k, eps_rel, radius),
            });
        }
    }
    (dissolved, grains)
}

/// μa, μs', K and S of the layer at wavelength index `l` of the grid.
pub fn coefficients(input: &BaselineInput, l: usize) -> KmCoefficients {
    let (mut mu_a, grains) = at_wavelength(input, l);
    let mut mu_s = 0.0;
    for g in &grains {
        mu_a += g.number * g.cross.absorption.max(0.0);
        mu_s += g.number * g.cross.scattering * (1.0 - g.cross.asymmetry);
    }
    KmCoefficients {
        mu_a,
        mu_s_reduced: mu_s,
        k: 2.0 * mu_a,
        s: 0.75 * mu_s,
    }
}

/// The KM body reflectance (inside the surface) on the grid.
pub fn body_reflectance(input: &BaselineInput) -> Vec<f64> {
    (0..input.wavelengths_nm.len())
        .map(|l| {
            let c = coefficients(input, l);
            km::reflectance(c.k, c.s, input.thickness_nm, input.paper_albedo)
        })
        .collect()
}

/// The reflectance factor an instrument in geometry `m` reads from a body
/// reflectance `r` under a binder surface of index `binder_index` that
/// reflects by `fresnel`: Saunderson's correction with its `r_e` and `r_i`.
pub fn measured_factor_of(fresnel: Fresnel, m: Measurement, r: f64, binder_index: f64) -> f64 {
    Saunderson::of(fresnel, m, binder_index).factor(r)
}

/// Saunderson's correction of one geometry with its surface reflectances
/// computed once (`r_i` is a hemisphere integral): for evaluating many body
/// reflectances, as [`measured_factor_of`] does one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Saunderson {
    /// `r_e` at the geometry's directed angle (45° for 45°/0°, 8° for d/8°).
    pub r_e: f64,
    /// `r_i`, diffuse from inside.
    pub r_i: f64,
    /// Whether the geometry sees the specular reflection (d/8° SCI).
    pub specular: bool,
}

impl Saunderson {
    /// The correction of geometry `m` under a binder surface of index
    /// `binder_index` that reflects by `fresnel`.
    pub fn of(fresnel: Fresnel, m: Measurement, binder_index: f64) -> Saunderson {
        let deg = match m {
            Measurement::FortyFiveZero => 45.0,
            Measurement::DiffuseEightSce | Measurement::DiffuseEightSci => 8.0,
        };
        Saunderson {
            r_e: fresnel.external(binder_index, deg),
            r_i: fresnel.internal(binder_index),
            specular: m == Measurement::DiffuseEightSci,
        }
    }

    /// The reflectance factor read from body reflectance `r`.
    pub fn factor(&self, r: f64) -> f64 {
        if self.specular {
            km::saunderson(r, self.r_e, self.r_i)
        } else {
            km::saunderson_excluded(r, self.r_e, self.r_i)
        }
    }
}

/// [`measured_factor_of`] the unpolarised surface (Saunderson's, as
/// `kubelka-munk` has it beside either equation).
pub fn measured_factor(m: Measurement, r: f64, binder_index: f64) -> f64 {
    measured_factor_of(Fresnel::Unpolarised, m, r, binder_index)
}

/// The surfaces' Fresnel law of `model` beside a solve of `equation`:
/// `kubelka-munk` keeps Saunderson's unpolarised surface; the models on the
/// wave scene's boundary take the equation's ([`Fresnel::of`]).
pub fn surfaces(model: Baseline, equation: Equation) -> Fresnel {
    match model {
        Baseline::KubelkaMunk => Fresnel::Unpolarised,
        Baseline::KubelkaMunkScene | Baseline::AddingDoubling | Baseline::AddingDoublingContact => {
            Fresnel::of(equation)
        }
    }
}

/// The baseline's colour in one measurement geometry.
#[derive(Debug, Clone)]
pub struct BaselineColour {
    /// The model that computed it.
    pub model: Baseline,
    /// Its grains' sphere solution.
    pub grains: GrainModel,
    /// Its flat surfaces' Fresnel law.
    pub surfaces: Fresnel,
    pub geometry: Measurement,
    /// The fine grid, nm.
    pub spectrum_wavelengths_nm: Vec<f64>,
    /// Reflectance factor on that grid.
    pub reflectance_factor: Vec<f64>,
    /// CIELAB L*, a*, b*.
    pub lab: [f64; 3],
    /// CIEDE2000 to the wave solution's colour in the same geometry, when
    /// that was computed.
    pub de00_to_wave: Option<f64>,
}

/// The KM colours of every geometry in `measurements`; `wave` gives the wave
/// solution's CIELAB in a geometry, when known.
pub fn kubelka_munk(
    input: &BaselineInput,
    measurements: &[Measurement],
    wave: &dyn Fn(Measurement) -> Option<[f64; 3]>,
    observer: &Observer,
) -> Result<Vec<BaselineColour>, ColourError> {
    let body = body_reflectance(input);
    let factors: Vec<Vec<f64>> = measurements
        .iter()
        .map(|&m| {
            body.iter()
                .map(|&r| measured_factor(m, r, input.binder_index))
                .collect()
        })
        .collect();
    colours(
        Baseline::KubelkaMunk,
        input,
        measurements,
        factors,
        wave,
        observer,
    )
}

/// The body reflectance of the KM layer on the wave scene's boundary
/// ([`km::scene_backing`] with the surface of the input's equation) on the
/// grid.
pub fn body_reflectance_scene(input: &BaselineInput) -> Vec<f64> {
    let n = input.binder_index;
    let fresnel = Fresnel::of(input.equation);
    let r_g = km::scene_backing(
        input.paper_albedo,
        fresnel.internal(n),
        fresnel.diffuse_external(n),
    );
    (0..input.wavelengths_nm.len())
        .map(|l| {
            let c = coefficients(input, l);
            km::reflectance(c.k, c.s, input.thickness_nm, r_g)
        })
        .collect()
}

/// The reflectance factor of geometry `m` from a KM body reflectance `r`
/// under the scalar (TE) surface of index `binder_index`: Saunderson's
/// correction with the scalar `r_e` and `r_i`.
pub fn measured_factor_scalar(m: Measurement, r: f64, binder_index: f64) -> f64 {
    measured_factor_of(Fresnel::Scalar, m, r, binder_index)
}

/// The reflectance factors of `model` for every geometry in
/// `measurements` (outer) on the input's grid (inner).
pub fn reflectance_factors(
    model: Baseline,
    input: &BaselineInput,
    measurements: &[Measurement],
) -> Result<Vec<Vec<f64>>, BaselineError> {
    let fresnel = surfaces(model, input.equation);
    let km_factors = |body: Vec<f64>| {
        measurements
            .iter()
            .map(|&m| {
                body.iter()
                    .map(|&r| measured_factor_of(fresnel, m, r, input.binder_index))
                    .collect()
            })
            .collect()
    };
    let params = ordinates::OrdinateParams::default();
    Ok(match model {
        Baseline::KubelkaMunk => km_factors(body_reflectance(input)),
        Baseline::KubelkaMunkScene => km_factors(body_reflectance_scene(input)),
        Baseline::AddingDoubling => {
            transfer::reflectance_factors(input, transfer::Boundary::Scene, measurements, params)?
        }
        Baseline::AddingDoublingContact => {
            transfer::reflectance_factors(input, transfer::Boundary::Contact, measurements, params)?
        }
    })
}

/// The colours of a stack of layers (top first, one binder and grid) by the
/// adding–doubling models, which add the layers' radiative-transfer slabs
/// under the surface; the Kubelka–Munk models are for one layer
/// ([`BaselineError::StackModel`]). `wave` as for [`baseline_colours`].
/// Layers printed on part of the area (`halftone`: each layer's coverage
/// and Yule–Nielsen's n) mix their primaries as the wave stack does
/// ([`halftone`]).
pub fn stack_baseline_colours(
    model: Baseline,
    inputs: &[BaselineInput],
    halftone: (&[f64], f64),
    measurements: &[Measurement],
    wave: &dyn Fn(Measurement) -> Option<[f64; 3]>,
    observer: &Observer,
) -> Result<Vec<BaselineColour>, BaselineError> {
    let boundary = match model {
        Baseline::AddingDoubling => transfer::Boundary::Scene,
        Baseline::AddingDoublingContact => transfer::Boundary::Contact,
        Baseline::KubelkaMunk | Baseline::KubelkaMunkScene => {
            return Err(BaselineError::StackModel(model.name()))
        }
    };
    let Some(top) = inputs.first() else {
        return Ok(Vec::new());
    };
    let params = ordinates::OrdinateParams::default();
    let (coverage, n) = halftone;
    let mut parts = Vec::new();
    for p in halftone::primaries(coverage) {
        let factors = if p.layers.is_empty() {
            // The bare paper: Lambertian, no binder on it.
            vec![vec![top.paper_albedo; top.wavelengths_nm.len()]; measurements.len()]
        } else {
            let printed: Vec<BaselineInput> = p.layers.iter().map(|&i| inputs[i].clone()).collect();
            transfer::stack_reflectance_factors(&printed, boundary, measurements, params)?
        };
        parts.push((p.area, factors));
    }
    let factors = (0..measurements.len())
        .map(|g| {
            (0..top.wavelengths_nm.len())
                .map(|l| {
                    let at: Vec<(f64, f64)> = parts.iter().map(|(w, f)| (*w, f[g][l])).collect();
                    halftone::yule_nielsen(n, &at)
                })
                .collect()
        })
        .collect();
    Ok(colours(model, top, measurements, factors, wave, observer)?)
}

/// The colours of `model` in every geometry in `measurements`; `wave` gives
/// the wave solution's CIELAB in a geometry, when known.
pub fn baseline_colours(
    model: Baseline,
    input: &BaselineInput,
    measurements: &[Measurement],
    wave: &dyn Fn(Measurement) -> Option<[f64; 3]>,
    observer: &Observer,
) -> Result<Vec<BaselineColour>, BaselineError> {
    let factors = reflectance_factors(model, input, measurements)?;
    Ok(colours(
        model,
        input,
        measurements,
        factors,
        wave,
        observer,
    )?)
}

/// Colour of each geometry's spectrum (`factors[g]` on the input's grid).
fn colours(
    model: Baseline,
    input: &BaselineInput,
    measurements: &[Measurement],
    factors: Vec<Vec<f64>>,
    wave: &dyn Fn(Measurement) -> Option<[f64; 3]>,
    observer: &Observer,
) -> Result<Vec<BaselineColour>, ColourError> {
    let mut out = Vec::with_capacity(measurements.len());
    for (&m, factor) in measurements.iter().zip(factors) {
        let xyz = colour::xyz_from_reflectance(observer, &input.wavelengths_nm, &factor)?;
        let lab = colour::xyz_to_lab(xyz, observer.white_xyz());
        out.push(BaselineColour {
            model,
            grains: GrainModel::of(input.equation),
            surfaces: surfaces(model, input.equation),
            geometry: m,
            spectrum_wavelengths_nm: input.wavelengths_nm.clone(),
            reflectance_factor: factor,
            lab,
            de00_to_wave: wave(m).map(|w| colour::delta_e2000(lab, w)),
        });
    }
    Ok(out)
}
