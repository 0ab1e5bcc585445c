//! The layers of a stack combined by the adding method: the binder's flat
//! top surface, each layer's [`LayerSlab`] from the top down (incoherently:
//! one layer's fragment is uncorrelated with the next's, so fluxes add),
//! the binder's flat lower surface, and under it the paper in air (the wave
//! scene's boundary) or nothing.
//!
//! The mirror reflection (what a gloss trap removes, d/8° SCE) is the light
//! that met only specular orders on its way: the same adding over each
//! layer's specular part alone, with the paper (a Lambertian reflector,
//! nothing specular) left out.

use super::flux::LayerSlab;
use crate::optics::baseline::adding::{self, Slab};
use crate::optics::baseline::matrix::Matrix;
use crate::optics::baseline::ordinates::Ordinates;
use crate::optics::baseline::transfer::StackReflection;
use crate::optics::baseline::BaselineError;

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
pub fn free_stack(ords: &Ordinates, layers: &[&Slab]) -> Result<Slab, BaselineError> {
    let mut s = adding::surface_air_over_binder(ords);
    for l in layers {
        s = adding::add(&s, l)?;
    }
    adding::add(&s, &adding::surface_binder_over_air(ords))
}

/// The reflection of the stack of `layers` (top first) on `below`, and its
/// mirror part per bin.
pub fn stack_reflection(
    ords: &Ordinates,
    layers: &[LayerSlab],
    below: Below,
) -> Result<StackReflection, BaselineError> {
    let lower = adding::surface_binder_over_air(ords);
    let backing = match below {
        Below::Paper { albedo } => {
            adding::on_backing(&lower, &adding::lambertian_in_air(ords, albedo))?
        }
        Below::Air => lower.r_down.clone(),
    };
    let reflect = |slabs: Vec<&Slab>, backing: &Matrix| -> Result<Matrix, BaselineError> {
        let mut s = adding::surface_air_over_binder(ords);
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
