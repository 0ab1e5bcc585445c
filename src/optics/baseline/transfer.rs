//! The adding–doubling baseline: the layer as a radiative-transfer slab of
//! independent scatterers between the binder's flat surfaces, solved by
//! adding–doubling (METHOD §6).
//!
//! **Medium** (per wavelength, from the same single scatterers as the
//! Kubelka–Munk baseline, [`super::coefficients`]): `μa = Σ N_s σ_abs,s`
//! (plus a dissolved pigment's `f k₀ Im ε / n_b`), `μs = Σ N_s σ_sca,s`, and
//! the phase function of the mixture weighted by `N_s σ_sca,s`: Legendre
//! moments `χ_n = Σ N_s m_n,s / Σ N_s σ_sca,s` from the grain model of the
//! input's equation ([`super::grain::GrainModel`]: the scalar sphere's
//! `|f|²` beside the Helmholtz equation, Mie's `(|S_1|² + |S_2|²)/2` beside
//! Maxwell's), `s` running over the species and,
//! for a size distribution, over its diameters ([`super::sizes`]). No
//! diffusion-approximation factors.
//!
//! **Stack**, from the top: air, the binder's surface, the layer (binder of
//! index `n_b` with the scatterers, [`doubling::homogeneous`]), then the
//! [`Boundary`]: the scene's (binder → air gap → Lambertian paper, as the
//! wave scene is built) or Saunderson's contact (paper in optical contact
//! with the binder). Every flat surface reflects by the [`Fresnel`] law of
//! the input's equation (s-like beside Helmholtz, natural light's beside
//! Maxwell).
//!
//! **Geometries** (azimuthally averaged radiance, Fourier term `m = 0`,
//! suffices for all three): 45°/0° is the bidirectional reflectance factor
//! `π f(45° → 0°)`, and a view along the normal sees only the `m = 0` term;
//! d/8° is directional–hemispherical by reciprocity (the hemispherical
//! reflectance for incidence at 8°), SCI with the mirror reflection and SCE
//! without it. The mirror reflection is the unscattered light's: the
//! surface's Fresnel reflection at 8° plus the direct beam's returns from
//! the lower surface through the layer (what the wave scene's (0,0) order
//! carries).

use super::adding::{self, Slab};
use super::doubling::{self, Medium};
use super::fresnel::Fresnel;
use super::grain::GrainModel;
use super::matrix::Matrix;
use super::ordinates::{OrdinateParams, Ordinates};
use super::{BaselineError, BaselineInput};
use crate::config::Measurement;

/// What lies under the layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// The wave scene's: the binder ends in a flat surface over an air gap,
    /// then the Lambertian paper (in air).
    Scene,
    /// Saunderson's: the Lambertian paper in optical contact with the
    /// binder.
    Contact,
}

/// The air directions the quadrature must contain: the measurement angles.
pub const AIR_DIRECTIONS_DEG: [f64; 3] = [0.0, 8.0, 45.0];

/// The radiative-transfer medium at wavelength index `l` of the grid.
pub fn medium(input: &BaselineInput, l: usize) -> Medium {
    let (mut mu_a, grains) = super::at_wavelength(input, l);
    let model = GrainModel::of(input.equation);
    let mut mu_s = 0.0;
    let mut moments: Vec<f64> = Vec::new();
    for g in &grains {
        mu_a += g.number * g.cross.absorption.max(0.0);
        mu_s += g.number * g.cross.scattering;
        let m = model.phase_moments(g.k, g.eps_rel, g.radius);
        if moments.len() < m.len() {
            moments.resize(m.len(), 0.0);
        }
        for (acc, v) in moments.iter_mut().zip(&m) {
            *acc += g.number * v;
        }
    }
    if mu_s > 0.0 && moments.first().is_some_and(|&m0| m0 > 0.0) {
        let m0 = moments[0];
        for v in &mut moments {
            *v /= m0;
        }
    } else {
        mu_s = 0.0;
        moments.clear();
    }
    Medium {
        mu_a,
        mu_s,
        moments,
    }
}

/// The reflection matrix (from above, air to air) of the whole stack, and
/// the mirror reflectance per bin.
pub struct StackReflection {
    pub ords: Ordinates,
    /// Flux reflection matrix, air bins (rows and columns of trapped bins
    /// are 0).
    pub r: Matrix,
    /// Reflectance of the unscattered light per bin (the mirror reflection).
    pub specular: Vec<f64>,
}

impl StackReflection {
    /// The reflectance factor an instrument in geometry `m` reads.
    pub fn factor(&self, m: Measurement) -> Result<f64, BaselineError> {
        let node = |deg: f64| {
            self.ords
                .air_node(deg)
                .ok_or(BaselineError::NoDirection(deg))
        };
        Ok(match m {
            Measurement::FortyFiveZero => {
                let (i, j) = (node(0.0)?, node(45.0)?);
                self.r[(i, j)] / self.ords.air_flux_weight(i)
            }
            Measurement::DiffuseEightSci => {
                let j = node(8.0)?;
                (0..self.ords.len()).map(|i| self.r[(i, j)]).sum()
            }
            Measurement::DiffuseEightSce => {
                let j = node(8.0)?;
                let total: f64 = (0..self.ords.len()).map(|i| self.r[(i, j)]).sum();
                total - self.specular[j]
            }
        })
    }
}

/// The stack's reflection for `medium` in a layer `thickness_nm` thick of
/// binder index `binder_index` on paper of `albedo` under `boundary`, the
/// flat surfaces reflecting by `fresnel`.
pub fn stack(
    ords: Ordinates,
    medium: &Medium,
    thickness_nm: f64,
    albedo: f64,
    boundary: Boundary,
    fresnel: Fresnel,
) -> Result<StackReflection, BaselineError> {
    stack_of_layers(ords, &[(medium, thickness_nm)], albedo, boundary, fresnel)
}

/// The same for several layers of one binder, top first, each a medium and
/// its thickness: their slabs added in order under the binder's surface.
pub fn stack_of_layers(
    ords: Ordinates,
    layers: &[(&Medium, f64)],
    albedo: f64,
    boundary: Boundary,
    fresnel: Fresnel,
) -> Result<StackReflection, BaselineError> {
    let mut body = Slab::transparent(ords.len());
    for &(medium, thickness_nm) in layers {
        body = adding::add(&body, &doubling::homogeneous(&ords, medium, thickness_nm)?)?;
    }
    let backing = match boundary {
        Boundary::Scene => adding::on_backing(
            &adding::surface_binder_over_air(&ords, fresnel),
            &adding::lambertian_in_air(&ords, albedo),
        )?,
        Boundary::Contact => adding::lambertian_in_binder(&ords, albedo),
    };
    let under_surface = adding::on_backing(&body, &backing)?;
    let r = adding::on_backing(
        &adding::surface_air_over_binder(&ords, fresnel),
        &under_surface,
    )?;
    let specular = mirror_reflectance(&ords, layers, boundary, fresnel);
    Ok(StackReflection { ords, r, specular })
}

/// The unscattered light's reflectance per bin: the surface's Fresnel
/// reflection `r_t` plus the direct beam's (transmittance `t` through the
/// layers, δ-M extinction) returns from the lower surface (`r_b`, 0 in
/// optical contact): `r_t + (1 − r_t)² t² r_b / (1 − r_t r_b t²)`.
pub fn mirror_reflectance(
    ords: &Ordinates,
    layers: &[(&Medium, f64)],
    boundary: Boundary,
    fresnel: Fresnel,
) -> Vec<f64> {
    let direct: Vec<Slab> = layers
        .iter()
        .map(|&(medium, thickness_nm)| {
            let (mu_s, _) = medium.delta_m(2 * ords.len());
            doubling::direct(ords, medium.mu_a + mu_s, thickness_nm)
        })
        .collect();
    (0..ords.len())
        .map(|i| {
            let Some(mu_a) = ords.mu_air[i] else {
                return 0.0;
            };
            let rt = fresnel.between(ords.binder_index, ords.mu[i], mu_a);
            let rb = match boundary {
                Boundary::Scene => rt,
                Boundary::Contact => 0.0,
            };
            let t2: f64 = direct.iter().map(|d| d.t_down[(i, i)].powi(2)).product();
            rt + (1.0 - rt).powi(2) * t2 * rb / (1.0 - rt * rb * t2)
        })
        .collect()
}

/// The reflectance factor of every geometry in `measurements` (outer) at
/// every wavelength of the grid (inner).
pub fn reflectance_factors(
    input: &BaselineInput,
    boundary: Boundary,
    measurements: &[Measurement],
    params: OrdinateParams,
) -> Result<Vec<Vec<f64>>, BaselineError> {
    stack_reflectance_factors(std::slice::from_ref(input), boundary, measurements, params)
}

/// The same for a stack of layers (top first) of one binder on one grid:
/// the binder, the paper, the grid and the equation are the top layer's.
pub fn stack_reflectance_factors(
    inputs: &[BaselineInput],
    boundary: Boundary,
    measurements: &[Measurement],
    params: OrdinateParams,
) -> Result<Vec<Vec<f64>>, BaselineError> {
    let Some(top) = inputs.first() else {
        return Ok(vec![Vec::new(); measurements.len()]);
    };
    let ords = Ordinates::new(top.binder_index, params, &AIR_DIRECTIONS_DEG)?;
    let fresnel = Fresnel::of(top.equation);
    let mut out = vec![Vec::with_capacity(top.wavelengths_nm.len()); measurements.len()];
    for l in 0..top.wavelengths_nm.len() {
        let media: Vec<Medium> = inputs.iter().map(|i| medium(i, l)).collect();
        let layers: Vec<(&Medium, f64)> = media
            .iter()
            .zip(inputs)
            .map(|(m, i)| (m, i.thickness_nm))
            .collect();
        let s = stack_of_layers(ords.clone(), &layers, top.paper_albedo, boundary, fresnel)?;
        for (g, &geometry) in measurements.iter().enumerate() {
            out[g].push(s.factor(geometry)?);
        }
    }
    Ok(out)
}

/// A slab's reflection and transmission on its own, for checks: the
/// homogeneous layer of `medium` between the binder's two surfaces, in air,
/// reflecting by `fresnel`.
pub fn free_layer(
    ords: &Ordinates,
    medium: &Medium,
    thickness_nm: f64,
    fresnel: Fresnel,
) -> Result<Slab, BaselineError> {
    let layer = doubling::homogeneous(ords, medium, thickness_nm)?;
    let lower = adding::add(&layer, &adding::surface_binder_over_air(ords, fresnel))?;
    adding::add(&adding::surface_air_over_binder(ords, fresnel), &lower)
}
