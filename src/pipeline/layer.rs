//! The three ways a layer is made and solved: the homogeneous slab in closed
//! form (a molecular mixture, or grains fine enough for the effective-medium
//! shortcut), an explicit structure (primitive bodies or an ε grid), or
//! packed grains, one particle set per realisation. Each gives its solves
//! and what the result file records of the layer.

use crate::config::{RealisationTarget, Scene, Structure};
use crate::geometry::Geometry;
use crate::optics::appearance;
use crate::optics::colour::Observer;
use crate::optics::farfield::SolveEntry;
use crate::output::h5::RealisationStop;
use crate::output::progress::Progress;
use crate::raster::structure::{self, EpsGrid};
use crate::raster::{self, Grid, Raster};

use super::appearance::appearance_spec;
use super::grains::{build_geometry_seeded, fragment_nm, grid_of};
use super::plan::RunPlan;
use super::solve::{solve_analytic, solve_layer, solve_realisation, LayerEps};
use super::surface::apply_surface;
use super::{PipelineError, SUPERSAMPLE};

/// A solved layer.
pub struct SolvedLayer {
    /// Every solve, in run order.
    pub entries: Vec<SolveEntry>,
    /// Seed and achieved PVC of each realisation.
    pub realisations: Vec<(u64, f64)>,
    /// The particle set of realisation 0 (generated grains only).
    pub geometry: Option<Geometry>,
    /// The raster of realisation 0, or of explicit primitives.
    pub raster: Option<Raster>,
    /// Why the realisations stopped, for a scene with a target.
    pub stop: Option<RealisationStop>,
}

/// Make and solve the layer the plan calls for.
pub fn solve(
    scene: &Scene,
    plan: &RunPlan,
    progress: &Progress,
) -> Result<SolvedLayer, PipelineError> {
    if plan.analytic {
        homogeneous(scene, plan, progress)
    } else if let Some(st) = &scene.structure {
        explicit(scene, plan, st, progress)
    } else {
        grains(scene, plan, progress)
    }
}

/// The homogeneous slab of the volume-averaged ε, in closed form.
fn homogeneous(
    scene: &Scene,
    plan: &RunPlan,
    progress: &Progress,
) -> Result<SolvedLayer, PipelineError> {
    Ok(SolvedLayer {
        entries: solve_analytic(scene, plan, progress)?,
        realisations: vec![(scene.seed, scene.total_pvc())],
        geometry: None,
        raster: None,
        stop: None,
    })
}

/// An explicit structure: primitives rasterised by volume fraction, or an ε
/// grid read from a file (no fractions: its PVC is recorded as 0).
fn explicit(
    scene: &Scene,
    plan: &RunPlan,
    st: &Structure,
    progress: &Progress,
) -> Result<SolvedLayer, PipelineError> {
    let grid = grid_of(scene);
    match st {
        Structure::Primitives(ps) => {
            // Primitives lie in the layer; cells above it are added empty.
            let layer_grid = Grid {
                nz: scene.grid.nz,
                size_nm: fragment_nm(scene),
                ..grid
            };
            let raster = apply_surface(
                scene,
                structure::rasterize_primitives(ps, &layer_grid)
                    .with_top_cells(grid.nz - layer_grid.nz),
                scene.seed,
            );
            let f: f64 = raster.mean_fractions().iter().sum();
            let entries = solve_layer(scene, plan, LayerEps::Raster(&raster), 0, progress)?;
            Ok(SolvedLayer {
                entries,
                realisations: vec![(scene.seed, f)],
                geometry: None,
                raster: Some(raster),
                stop: None,
            })
        }
        Structure::Hdf5(path) => {
            let eg = EpsGrid::read(path, &grid, &scene.wavelengths_nm)?;
            let entries = solve_layer(scene, plan, LayerEps::Grid(&eg, grid), 0, progress)?;
            Ok(SolvedLayer {
                entries,
                realisations: vec![(scene.seed, 0.0)],
                geometry: None,
                raster: None,
                stop: None,
            })
        }
    }
}

/// Packed grains: per realisation a particle set from its seed, rasterised
/// and solved; realisation 0's geometry and raster are kept.
fn grains(
    scene: &Scene,
    plan: &RunPlan,
    progress: &Progress,
) -> Result<SolvedLayer, PipelineError> {
    let grid = grid_of(scene);
    let mut layer = SolvedLayer {
        entries: Vec::new(),
        realisations: Vec::new(),
        geometry: None,
        raster: None,
        stop: None,
    };
    for (r, &seed) in plan.seeds.iter().enumerate() {
        let geometry = build_geometry_seeded(scene, seed)?;
        let st = &geometry.stats;
        let pvc: f64 = st.achieved_fraction.iter().sum();
        progress.log(&format!(
            "geometry{}: {} particles, PVC {:.4} (target {:.4}), worst overlap {:.3} nm{}",
            if plan.realisations > 1 {
                format!(" #{r} (seed {seed})")
            } else {
                String::new()
            },
            geometry.particles.len(),
            pvc,
            scene.total_pvc(),
            st.worst_overlap_nm,
            st.order_parameter
                .map(|o| format!(", order parameter S = {o:.3}"))
                .unwrap_or_default()
        ));
        let raster = apply_surface(
            scene,
            raster::rasterize_keeping_axes(&geometry, &grid, SUPERSAMPLE, &scene.crystal_tensors()),
            seed,
        );
        if r == 0 {
            progress.log(&format!(
                "raster: {} × {} × {} voxels",
                grid.nx, grid.ny, grid.nz
            ));
        }
        layer
            .entries
            .extend(solve_realisation(scene, plan, &raster, r, progress)?);
        layer.realisations.push((seed, pvc));
        if layer.geometry.is_none() {
            layer.geometry = Some(geometry);
            layer.raster = Some(raster);
        }
        if let Some(target) = scene.realisation_target {
            let n = r + 1;
            if n >= target.min {
                let stop = colour_uncertainty(scene, plan, &layer.entries, n, target)?;
                progress.log(&format!(
                    "realisations: {n} done, ΔE00 standard error {:.3} (target {})",
                    stop.de00_se, target.de00
                ));
                layer.stop = Some(stop);
                if stop.target_met {
                    break;
                }
            }
        }
    }
    Ok(layer)
}

/// The colour uncertainty after the first `n` realisations: the largest
/// standard error of ΔE00 to the mean over the measured colours, against the
/// target.
fn colour_uncertainty(
    scene: &Scene,
    plan: &RunPlan,
    entries: &[SolveEntry],
    n: usize,
    target: RealisationTarget,
) -> Result<RealisationStop, PipelineError> {
    let mut so_far = plan.clone();
    so_far.realisations = n;
    let obs = Observer::standard(scene.appearance.illuminant, scene.appearance.observer);
    let a = appearance::assemble(&appearance_spec(scene, &so_far), entries, &obs)?;
    let de00_se = a
        .measured
        .iter()
        .map(|m| m.de00_se.unwrap_or(f64::INFINITY))
        .fold(0.0, f64::max);
    Ok(RealisationStop {
        target_de00: target.de00,
        de00_se,
        target_met: de00_se <= target.de00,
    })
}
