//! The layers of a stack combined by the adding method: the binder's flat
//! top surface, each layer's [`LayerSlab`] from the top down (incoherently:
//! one layer's fragment is uncorrelated with the next's, so fluxes add),
//! the binder's flat lower surface, and under it the paper in air (the wave
//! scene's boundary) or nothing. The flat surfaces reflect by the law of
//! the equation the layers were solved in ([`Fresnel::of`]): s-like beside
//! Helmholtz, natural light's beside Maxwell (whose layers' fluxes are then
//! natural light's too, combined without tracking the polarisation between
//! layers).
//!
//! The mirror reflection (what a gloss trap removes, d/8° SCE) is the light
//! that met only specular orders on its way: the same adding over each
//! layer's specular part alone, with the paper (a Lambertian reflector,
//! nothing specular) left out.
//!
//! The BRDF in the plane of incidence adds the layers' azimuthal Fourier
//! terms `m ≥ 1` ([`plane_factors`]) the same way, term by term: the flat
//! surfaces and the specular orders keep a ray's azimuth, so they enter
//! every term alike, and the Lambertian paper, the same in every azimuth,
//! enters the mean only.

use super::flux::LayerSlab;
use crate::optics::baseline::adding::{self, Slab};
use crate::optics::baseline::fresnel::Fresnel;
use crate::optics::baseline::matrix::Matrix;
use crate::optics::baseline::ordinates::Ordinates;
use crate::optics::baseline::transfer::StackReflection;
use crate::optics::baseline::BaselineError;
use ndarray::Array2;

/// What lies under the stack's lower surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Below {
    /// The Lambertian paper of this albedo, in air (the wave scene's).
    Paper { albedo: f64 },
    /// Air.
    Air,
}

/// The stack of `layers` (top first) between the binder's two flat
/// surfaces, in air on both sides: reflection and transmission of the whole.
/// The surfaces reflect by `fresnel`.
pub fn free_stack(
    ords: &Ordinates,
    layers: &[&Slab],
    fresnel: Fresnel,
) -> Result<Slab, BaselineError> {
    let mut s = adding::surface_air_over_binder(ords, fresnel);
    for l in layers {
        s = adding::add(&s, l)?;
    }
    adding::add(&s, &adding::surface_binder_over_air(ords, fresnel))
}

/// The reflection of the stack of `layers` (top first) on `below`, and its
/// mirror part per bin; the surfaces reflect by `fresnel`.
pub fn stack_reflection(
    ords: &Ordinates,
    layers: &[&LayerSlab],
    below: Below,
    fresnel: Fresnel,
) -> Result<StackReflection, BaselineError> {
    let lower = adding::surface_binder_over_air(ords, fresnel);
    let backing = match below {
        Below::Paper { albedo } => {
            adding::on_backing(&lower, &adding::lambertian_in_air(ords, albedo))?
        }
        Below::Air => lower.r_down.clone(),
    };
    let reflect = |slabs: Vec<&Slab>, backing: &Matrix| -> Result<Matrix, BaselineError> {
        let mut s = adding::surface_air_over_binder(ords, fresnel);
        for l in slabs {
            s = adding::add(&s, l)?;
        }
        adding::on_backing(&s, backing)
    };
    let r = reflect(layers.iter().map(|l| &l.total).collect(), &backing)?;
    let mirror = reflect(layers.iter().map(|l| &l.specular).collect(), &lower.r_down)?;
    let specular = (0..ords.len()).map(|i| mirror[(i, i)]).collect();
    Ok(StackReflection {
        ords: ords.clone(),
        r,
        specular,
    })
}

/// The white-sky radiance factor seen from air direction `polar_deg`: by
/// reciprocity the hemispherical reflectance for light from there, specular
/// included (the single layer's `natural`).
pub fn white_sky(s: &StackReflection, polar_deg: f64) -> Result<f64, BaselineError> {
    let j = s
        .ords
        .air_node(polar_deg)
        .ok_or(BaselineError::NoDirection(polar_deg))?;
    Ok((0..s.ords.len()).map(|i| s.r[(i, j)]).sum())
}

/// The stack's diffuse reflectance factor `π f` (the mirror reflection left
/// out) in the plane of incidence on the specular side (`φ_o = φ_i`), for
/// light from air direction `illumination_deg[c]` seen from
/// `viewing_deg[v]`, as `(illumination, viewing)`: with the azimuthal mean
/// `sr` of the same stack on `below`,
/// `π f = [R⁰ + 2 Σ_{m≥1} Rᵐ − mirror]_{vc} / w_v`, `w_v` the viewing bin's
/// flux weight in air. The sum runs over the layers' terms (`azimuthal`,
/// the same number in every layer). The surfaces reflect by `fresnel`, as
/// in `sr`.
pub fn plane_factors(
    ords: &Ordinates,
    layers: &[&LayerSlab],
    sr: &StackReflection,
    illumination_deg: &[f64],
    viewing_deg: &[f64],
    fresnel: Fresnel,
) -> Result<Array2<f64>, BaselineError> {
    let node = |deg: f64| ords.air_node(deg).ok_or(BaselineError::NoDirection(deg));
    let terms = layers.first().map_or(0, |l| l.azimuthal.len());
    let lower = adding::surface_binder_over_air(ords, fresnel);
    let mut sum = sr.r.clone();
    for m in 0..terms {
        let mut s = adding::surface_air_over_binder(ords, fresnel);
        for l in layers {
            s = adding::add(&s, &l.azimuthal[m])?;
        }
        let rm = adding::on_backing(&s, &lower.r_down)?;
        for i in 0..ords.len() {
            for j in 0..ords.len() {
                sum[(i, j)] += 2.0 * rm[(i, j)];
            }
        }
    }
    let mut out = Array2::zeros((illumination_deg.len(), viewing_deg.len()));
    for (c, &ill) in illumination_deg.iter().enumerate() {
        let j = node(ill)?;
        for (v, &view) in viewing_deg.iter().enumerate() {
            let i = node(view)?;
            // The mirror part is along the light's own direction, in
            // every term alike: once in the mean, twice per term.
            let mirror = if i == j {
                sr.specular[j] * (1 + 2 * terms) as f64
            } else {
                0.0
            };
            out[[c, v]] = (sum[(i, j)] - mirror) / ords.air_flux_weight(i);
        }
    }
    Ok(out)
}
