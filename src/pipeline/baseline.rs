//! The classical baseline of a scene (`appearance.baseline`): its pigments
//! as the baselines see them (volume fraction, nominal diameter and size
//! distribution, permittivity), on the colour grid of the spectral proxy,
//! beside the wave solution's measured colours.

use crate::config::{GrainShape, Scene, Substrate};
use crate::optics::appearance::Appearance;
use crate::optics::baseline::{self, BaselineInput, BaselineSpecies};
use crate::optics::colour::Observer;

use super::appearance::fine_grid;
use super::eps::species_eps;
use super::PipelineError;

/// The baseline's input for a scene with paper: the pigments' permittivities
/// on the fine colour grid (on the solved wavelengths when a material has no
/// data there, as for the spectral proxy). None without paper.
pub fn baseline_input(scene: &Scene) -> Result<Option<BaselineInput>, PipelineError> {
    let Substrate::Paper { albedo } = scene.substrate else {
        return Ok(None);
    };
    let per_wavelength = |grid: &[f64]| -> Result<Vec<Vec<_>>, PipelineError> {
        grid.iter().map(|&l| species_eps(scene, l)).collect()
    };
    let mut grid = fine_grid(&scene.wavelengths_nm);
    let eps = match per_wavelength(&grid) {
        Ok(e) => e,
        Err(_) => {
            grid = scene.wavelengths_nm.clone();
            per_wavelength(&grid)?
        }
    };
    let species = scene
        .species
        .iter()
        .enumerate()
        .map(|(s, sp)| BaselineSpecies {
            volume_fraction: sp.volume_fraction,
            diameter_nm: if sp.shape == GrainShape::Molecular {
                0.0
            } else {
                sp.diameter_nm
            },
            size: sp.size,
            eps: eps.iter().map(|e| e[s]).collect(),
        })
        .collect();
    Ok(Some(BaselineInput {
        wavelengths_nm: grid,
        binder_index: scene.layer.binder_index,
        thickness_nm: scene.layer.thickness_nm,
        paper_albedo: albedo,
        species,
        size_quadrature: Default::default(),
    }))
}

/// Add the scene's baseline colours, if it asks for any, to its appearance
/// (each model's, in the order the scene lists them).
pub fn add_baseline(
    scene: &Scene,
    appearance: &mut Appearance,
    observer: &Observer,
) -> Result<(), PipelineError> {
    if scene.appearance.baseline.is_empty() {
        return Ok(());
    }
    let Some(input) = baseline_input(scene)? else {
        return Ok(());
    };
    let measured = &appearance.measured;
    let wave = |m| measured.iter().find(|c| c.geometry == m).map(|c| c.lab);
    let mut colours = Vec::new();
    for &model in &scene.appearance.baseline {
        colours.extend(baseline::baseline_colours(
            model,
            &input,
            &scene.appearance.measurements,
            &wave,
            observer,
        )?);
    }
    appearance.baseline = colours;
    Ok(())
}
