//! The classical baseline of a scene (`appearance.baseline`): its pigments
//! as the baselines see them (volume fraction, nominal diameter and size
//! distribution, permittivity), on the colour grid of the spectral proxy,
//! with the scene's equation (which picks the grains' sphere solution and
//! the surfaces' Fresnel law), beside the wave solution's measured colours.

use crate::config::{GrainShape, Scene};
use crate::optics::appearance::{Appearance, MeasuredColour};
use crate::optics::baseline::{self, BaselineColour, BaselineInput, BaselineSpecies};
use crate::optics::colour::Observer;

use super::appearance::fine_grid;
use super::eps::species_eps;
use super::PipelineError;

/// The baseline's input for a scene with paper: the pigments' permittivities
/// on the fine colour grid (on the solved wavelengths when a material has no
/// data there, as for the spectral proxy). None without paper.
pub fn baseline_input(scene: &Scene) -> Result<Option<BaselineInput>, PipelineError> {
    let Some(albedo) = scene.substrate.ground().and_then(|g| g.constant()) else {
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
        equation: scene.solver.equation,
    }))
}

/// Add the scene's baseline colours, if it asks for any, to its appearance
/// (each model's, in the order the scene lists them).
pub fn add_baseline(
    scene: &Scene,
    appearance: &mut Appearance,
    observer: &Observer,
) -> Result<(), PipelineError> {
    appearance.baseline = baseline_colours(scene, &appearance.measured, observer)?;
    Ok(())
}

/// The scene's baseline colours beside its wave colours `measured` (each
/// model's, in the order the scene lists them; none without paper or when
/// it asks for none). A stack's are the adding–doubling of its layers.
pub fn baseline_colours(
    scene: &Scene,
    measured: &[MeasuredColour],
    observer: &Observer,
) -> Result<Vec<BaselineColour>, PipelineError> {
    if scene.appearance.baseline.is_empty() {
        return Ok(Vec::new());
    }
    let layers: Vec<Scene> = match &scene.stack {
        Some(st) => (0..st.layers.len())
            .filter_map(|i| scene.stack_layer(i))
            .collect(),
        None => vec![scene.clone()],
    };
    let mut inputs = Vec::with_capacity(layers.len());
    for l in &layers {
        match baseline_input(l)? {
            Some(input) => inputs.push(input),
            None => return Ok(Vec::new()),
        }
    }
    let wave = |m| measured.iter().find(|c| c.geometry == m).map(|c| c.lab);
    let mut colours = Vec::new();
    for &model in &scene.appearance.baseline {
        colours.extend(match scene.stack {
            Some(ref st) => baseline::stack_baseline_colours(
                model,
                &inputs,
                (
                    &st.layers.iter().map(|l| l.coverage).collect::<Vec<_>>(),
                    st.yule_nielsen_n,
                ),
                &scene.appearance.measurements,
                &wave,
                observer,
            )?,
            None => baseline::baseline_colours(
                model,
                &inputs[0],
                &scene.appearance.measurements,
                &wave,
                observer,
            )?,
        });
    }
    Ok(colours)
}
