//! The scene's binder surface applied to a raster: the grid's room above the
//! layer it needs, and its height map per realisation.

use crate::config::{Scene, Surface};
use crate::raster::surface::{self, ROUGH_LIMIT};
use crate::raster::Raster;

/// Whether a scene's top is a plane: no relief, conformal film or rough
/// surface puts air into the grid (an explicit structure may still hold
/// some).
pub fn flat_top(scene: &Scene) -> bool {
    scene.layer.relief_fraction <= 0.0 && scene.layer.surface == Surface::Flat
}

/// Height above `z = 0` (nm) the binder surface may reach: the film over
/// grains that reach `grains_top_nm` above the plane, or the rough
/// surface's highest allowed peak; 0 for the plane.
pub fn surface_top_nm(scene: &Scene, grains_top_nm: f64) -> f64 {
    match scene.layer.surface {
        Surface::Flat => 0.0,
        Surface::Conformal { film_nm } => grains_top_nm.max(0.0) + film_nm,
        Surface::Rough { rms_nm, .. } => ROUGH_LIMIT * rms_nm,
    }
}

/// `raster` with the scene's binder surface; `seed` draws a rough surface
/// (one per realisation).
pub fn apply_surface(scene: &Scene, mut raster: Raster, seed: u64) -> Raster {
    let dz = raster.grid.cell_nm()[2];
    let z_origin = -(raster.top_cells as f64) * dz;
    raster.surface_nm = match scene.layer.surface {
        Surface::Flat => None,
        Surface::Conformal { film_nm } => {
            let top = surface::material_top(&raster.grid, z_origin, &raster.fractions);
            Some(surface::conformal(&raster.grid, z_origin, &top, film_nm))
        }
        Surface::Rough {
            rms_nm,
            correlation_nm,
        } => Some(surface::rough(
            &raster.grid,
            rms_nm,
            correlation_nm,
            seed ^ ROUGH_SEED_SALT,
        )),
    };
    raster
}

/// Mixed into a realisation's seed for its rough surface, so the surface's
/// noise is not the packer's.
const ROUGH_SEED_SALT: u64 = 0x05EE_D0FB_1DE5_u64;

/// The plan's line for the surface.
pub fn surface_line(scene: &Scene) -> String {
    match scene.layer.surface {
        Surface::Flat => "binder surface: flat at z = 0 (grains stay below it; a grain-poor skin \
                          lies at the same depth in every fragment)"
            .to_string(),
        Surface::Conformal { film_nm } => format!(
            "binder surface: conformal, a {film_nm} nm film draped over the topmost material"
        ),
        Surface::Rough {
            rms_nm,
            correlation_nm,
        } => format!(
            "binder surface: rough, RMS {rms_nm} nm, correlation length {correlation_nm} nm, \
             drawn anew per realisation (heights within ±{ROUGH_LIMIT} RMS)"
        ),
    }
}
