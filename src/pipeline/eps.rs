//! Permittivities of a scene's materials at a wavelength: each pigment's,
//! each structure primitive's, and the volume average of the layer; a
//! material without data there is a [`PipelineError::Material`].

use crate::config::{Material, Scene, Structure};
use crate::optics::effective_medium;
use num_complex::Complex64 as C64;

use super::PipelineError;

/// ε = n² of a material at a wavelength.
fn material_eps(m: &Material, lambda: f64) -> Result<C64, PipelineError> {
    m.index_at(lambda)
        .map(|n| n * n)
        .ok_or_else(|| PipelineError::Material {
            material: m.name.clone(),
            wavelength_nm: lambda,
        })
}

/// Permittivity of every species at a wavelength.
pub fn species_eps(scene: &Scene, lambda: f64) -> Result<Vec<C64>, PipelineError> {
    scene
        .species
        .iter()
        .map(|s| material_eps(&s.material, lambda))
        .collect()
}

/// Permittivity of each fraction array of the raster at a wavelength: the
/// pigments', or the structure primitives' materials.
pub fn fraction_eps(scene: &Scene, lambda: f64) -> Result<Vec<C64>, PipelineError> {
    match &scene.structure {
        Some(Structure::Primitives(ps)) => ps
            .iter()
            .map(|p| material_eps(&p.material, lambda))
            .collect(),
        _ => species_eps(scene, lambda),
    }
}

/// The volume-averaged permittivity of the layer, `Σ f ε_s + (1 − Σ f) ε_b`
/// (the molecular-mixture slab).
pub fn mean_eps(scene: &Scene, lambda: f64) -> Result<C64, PipelineError> {
    let eps_b = C64::new(scene.layer.binder_index.powi(2), 0.0);
    let fractions: Vec<f64> = scene.species.iter().map(|s| s.volume_fraction).collect();
    Ok(effective_medium::volume_average(
        eps_b,
        &fractions,
        &species_eps(scene, lambda)?,
    ))
}
