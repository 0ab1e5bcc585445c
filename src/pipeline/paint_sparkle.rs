//! The sparkle of an effect paint run: the figures (glints per cell and per
//! mm² under each sparkle light, graininess) and the texture picture (a
//! tile of resolution cells per light and one under diffuse light).

use crate::config::paint::{FlakeSpec, PaintLayerSpec, PaintScene};
use crate::optics::baseline::fresnel::Fresnel;
use crate::optics::colour::{self, Observer};
use crate::optics::flakes::normals::Orientation;
use crate::optics::flakes::paint::PaintReflection;
use crate::optics::flakes::sparkle;
use crate::optics::flakes::sparkle_texture::{self, GlintPopulation, Texture};
use crate::output::h5::{SparkleRecord, SparkleTable};
use crate::output::render::sparkle::{sparkle_png, SparkleCaption, SparkleTile};

use super::paint_optics::{lacquer_index, reflector};
use super::PipelineError;

/// Resolution cells along each side of a texture tile.
pub const TILE_CELLS: usize = 150;

/// One flake layer's glints under a small light.
struct LayerGlints<'a> {
    flakes: &'a FlakeSpec,
    glints_per_mm2: f64,
    glints_per_cell: f64,
    /// Tristimulus values of the flake's reflectance at the glint's local
    /// angle (white `Y` = 100).
    xyz: [f64; 3],
}

fn colour_error(e: colour::ColourError) -> PipelineError {
    crate::optics::baseline::BaselineError::from(e).into()
}

/// The flake layers and their flakes.
fn flaked(scene: &PaintScene) -> Vec<(&PaintLayerSpec, &FlakeSpec)> {
    scene
        .layers
        .iter()
        .filter_map(|l| l.flakes.as_ref().map(|f| (l, f)))
        .collect()
}

/// Flakes per mm² of a layer.
fn flakes_per_mm2(l: &PaintLayerSpec, f: &FlakeSpec) -> f64 {
    sparkle::flakes_per_mm2(
        f.volume_fraction,
        l.thickness_um,
        f.mean_square_diameter_um2().sqrt(),
        f.thickness_nm() / 1000.0,
    )
}

/// Every flake layer's glints under light at `illumination_deg`.
fn layer_glints<'a>(
    scene: &'a PaintScene,
    obs: &Observer,
    illumination_deg: f64,
) -> Result<Vec<LayerGlints<'a>>, PipelineError> {
    let wl = &scene.wavelengths_nm;
    let n = lacquer_index(scene, wl[wl.len() / 2])?;
    let sp = &scene.sparkle;
    let cell = sparkle::cell_area_mm2(sp.viewing_distance_mm, sparkle::ARCMINUTE_RAD);
    let cos_local = sparkle::half_vector_tilt(illumination_deg, n).cos();
    flaked(scene)
        .into_iter()
        .map(|(l, f)| {
            let o = Orientation {
                sigma_rad: f.orientation_sd_deg.to_radians(),
            };
            let s = sparkle::sparkle(
                flakes_per_mm2(l, f),
                &o,
                n,
                cell,
                sp.acceptance_deg.to_radians(),
                Some(illumination_deg),
            );
            let spectrum = wl
                .iter()
                .map(|&w| {
                    Ok(reflector(&f.reflector, w)?
                        .powers(lacquer_index(scene, w)?, w, cos_local)
                        .r)
                })
                .collect::<Result<Vec<f64>, PipelineError>>()?;
            let xyz = colour::xyz_from_reflectance(obs, wl, &spectrum).map_err(colour_error)?;
            Ok(LayerGlints {
                flakes: f,
                glints_per_mm2: s.glints_per_mm2,
                glints_per_cell: s.glints_per_cell,
                xyz,
            })
        })
        .collect()
}

/// The sparkle figures: every flake layer's flakes (their glints add, as
/// independent Poisson counts), the glint's luminous reflectance weighted
/// by the glints of each layer.
pub(super) fn sparkle_table(
    scene: &PaintScene,
    obs: &Observer,
) -> Result<Option<SparkleTable>, PipelineError> {
    let layers = flaked(scene);
    if layers.is_empty() {
        return Ok(None);
    }
    let sp = &scene.sparkle;
    let cell = sparkle::cell_area_mm2(sp.viewing_distance_mm, sparkle::ARCMINUTE_RAD);
    let flakes: f64 = layers.iter().map(|(l, f)| flakes_per_mm2(l, f)).sum();
    let mut rows = Vec::with_capacity(sp.illumination_deg.len());
    for &deg in &sp.illumination_deg {
        let mut row = SparkleRecord {
            illumination_deg: deg,
            glints_per_mm2: 0.0,
            glints_per_cell: 0.0,
            glint_reflectance: 0.0,
        };
        for g in layer_glints(scene, obs, deg)? {
            row.glint_reflectance += g.glints_per_mm2 * g.xyz[1] / 100.0;
            row.glints_per_mm2 += g.glints_per_mm2;
            row.glints_per_cell += g.glints_per_cell;
        }
        if row.glints_per_mm2 > 0.0 {
            row.glint_reflectance /= row.glints_per_mm2;
        }
        rows.push(row);
    }
    let per_cell = flakes * cell;
    Ok(Some(SparkleTable {
        viewing_distance_mm: sp.viewing_distance_mm,
        acceptance_deg: sp.acceptance_deg,
        cell_area_mm2: cell,
        flakes_per_mm2: flakes,
        graininess: if per_cell > 0.0 {
            1.0 / per_cell.sqrt()
        } else {
            0.0
        },
        rows,
    }))
}

/// The tristimulus values of a spectrum over the scene's wavelengths.
fn xyz_of(scene: &PaintScene, obs: &Observer, spectrum: &[f64]) -> Result<[f64; 3], PipelineError> {
    colour::xyz_from_reflectance(obs, &scene.wavelengths_nm, spectrum).map_err(colour_error)
}

/// The texture tiles: one per sparkle light (the scattered BRDF's colour
/// seen along the normal, plus the glints), then diffuse light (the
/// hemispherical–directional reflectance along the normal, mirror part
/// included, no glints); with the model's glints per cm² of each.
pub(super) fn textures(
    scene: &PaintScene,
    obs: &Observer,
    reflections: &[PaintReflection],
) -> Result<Vec<(Option<f64>, f64, Texture)>, PipelineError> {
    let sp = &scene.sparkle;
    let wl = &scene.wavelengths_nm;
    let n = lacquer_index(scene, wl[wl.len() / 2])?;
    let cell = sparkle::cell_area_mm2(sp.viewing_distance_mm, sparkle::ARCMINUTE_RAD);
    let acceptance = sp.acceptance_deg.to_radians();
    let seed_of = |k: usize| sp.seed ^ (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let mut out = Vec::with_capacity(sp.illumination_deg.len() + 1);
    for (k, &deg) in sp.illumination_deg.iter().enumerate() {
        let base = reflections
            .iter()
            .map(|r| r.factor(deg, 0.0, 0.0))
            .collect::<Result<Vec<f64>, _>>()?;
        let mu_t = (1.0 - (deg.to_radians().sin() / n).powi(2)).sqrt();
        let into = Fresnel::Unpolarised.between(n, mu_t, deg.to_radians().cos());
        let out_of = Fresnel::Unpolarised.between(n, 1.0, 1.0);
        let gain = sparkle_texture::glint_factor(
            1.0,
            cell,
            acceptance,
            n,
            deg,
            (1.0 - into) * (1.0 - out_of),
        );
        let layers = layer_glints(scene, obs, deg)?;
        let populations: Vec<GlintPopulation> = layers
            .iter()
            .map(|g| GlintPopulation {
                per_cell: g.glints_per_cell,
                diameter_um: g.flakes.diameter_um,
                diameter_sd_um: g.flakes.diameter_sd_um,
                xyz_per_um2: g.xyz.map(|v| v * gain),
            })
            .collect();
        let per_cm2 = 100.0 * layers.iter().map(|g| g.glints_per_mm2).sum::<f64>();
        let t = sparkle_texture::texture(
            TILE_CELLS,
            TILE_CELLS,
            xyz_of(scene, obs, &base)?,
            &populations,
            seed_of(k),
        );
        out.push((Some(deg), per_cm2, t));
    }
    let normal = reflections[0]
        .ords
        .air_node(0.0)
        .ok_or(crate::optics::baseline::BaselineError::NoDirection(0.0))?;
    let diffuse: Vec<f64> = reflections.iter().map(|r| r.albedo(normal)).collect();
    let t = sparkle_texture::texture(
        TILE_CELLS,
        TILE_CELLS,
        xyz_of(scene, obs, &diffuse)?,
        &[],
        seed_of(sp.illumination_deg.len()),
    );
    out.push((None, 0.0, t));
    Ok(out)
}

/// The sparkle texture picture of `textures`.
pub(super) fn texture_png(
    scene: &PaintScene,
    obs: &Observer,
    conditions: &str,
    textures: &[(Option<f64>, f64, Texture)],
    graininess: f64,
) -> Result<Vec<u8>, PipelineError> {
    let sp = &scene.sparkle;
    let tiles: Vec<SparkleTile> = textures
        .iter()
        .map(|(deg, per_cm2, t)| SparkleTile {
            illumination_deg: *deg,
            glints_per_cm2: *per_cm2,
            texture: t,
        })
        .collect();
    Ok(sparkle_png(
        &tiles,
        &SparkleCaption {
            name: &scene.output.name,
            observer: obs,
            conditions,
            viewing_distance_mm: sp.viewing_distance_mm,
            cell_mm: sp.viewing_distance_mm * sparkle::ARCMINUTE_RAD,
            acceptance_deg: sp.acceptance_deg,
            graininess,
            seed: sp.seed,
        },
    )?)
}
