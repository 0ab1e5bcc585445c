//! A run end to end: the output folder checked, the plan logged, the layer
//! made and solved, the appearance assembled, the pictures, the MERL file
//! and the result written; and the geometry-only run of `inksim geometry`.

use std::path::{Path, PathBuf};

use crate::config::{Scene, Structure};
use crate::geometry::{self, Geometry, StatsParams};
use crate::optics::appearance::{self, Appearance};
use crate::optics::colour::Observer;
use crate::optics::farfield::{Side, SolveEntry};
use crate::output::atomic;
use crate::output::h5::RealisationStop;
use crate::output::merl;
use crate::output::render;
use crate::raster::{self, structure, Raster};

use super::appearance::appearance_spec;
use super::grains::{build_geometry, grid_of, Packer};
use super::layer;
use super::memory::{self, MemoryLimit};
use super::plan::{plan_text, RunPlan};
use super::result::{ResultParts, RunReport};
use super::{
    check_output_dir, check_output_files, result_paths, started, PipelineError, SUPERSAMPLE,
};

/// Run a scene end to end and write its result files, with a progress bar
/// (terminal) or log lines, held to the machine's available memory.
pub fn run(scene: &Scene) -> Result<RunReport, PipelineError> {
    run_with(scene, false, MemoryLimit::resolve(None))
}

/// [`run`], optionally without any progress output (variants of a study
/// running side by side report through the study's own bar), held to
/// `limit`: a scene whose memory estimate exceeds it stops before any large
/// allocation ([`memory::preflight`]).
pub fn run_with(
    scene: &Scene,
    quiet: bool,
    limit: Option<MemoryLimit>,
) -> Result<RunReport, PipelineError> {
    if scene.is_incoherent_stack() {
        return super::stack::run(scene, quiet, limit);
    }
    let (result_path, picture_path) = result_paths(scene);
    let orders_path = scene
        .output
        .dir
        .join(format!("{}-orders.png", scene.output.name));
    check_output_files(scene)?;
    check_output_dir(&scene.output.dir)?;
    memory::preflight(scene, limit)?;
    let mut plan = RunPlan::of(scene);
    super::disk::preflight(&scene.output.dir, super::disk::estimate_bytes(scene, &plan))?;
    let total = plan.solves(scene) as u64;
    let progress = started(scene, total, quiet, &plan.lines);
    let layer = layer::solve(scene, &plan, &progress)?;
    if let Some(stop) = layer.stop {
        let line = realisations_done_line(plan.realisations, layer.realisations.len(), stop);
        progress.log(&line);
        plan.lines.push(line);
        plan.realisations = layer.realisations.len();
        plan.seeds.truncate(plan.realisations);
    }
    progress.finish("all solves done");

    let pictures = assemble_products(scene, &plan, &layer.entries)?;
    // Only what `outputs` asks for (`output_files` lists the same).
    let products = scene.appearance.products;
    let orders = products.brdf || products.btdf;
    let orders_picture_path = orders.then_some(orders_path);
    if let Some(p) = &orders_picture_path {
        atomic::write_atomic(p, &pictures.orders_png)?;
    }
    let mut plot_paths = vec![];
    for (suffix, png) in &pictures.plots {
        let p = scene
            .output
            .dir
            .join(format!("{}-{suffix}.png", scene.output.name));
        atomic::write_atomic(&p, png)?;
        plot_paths.push(p);
    }
    let picture = match (&pictures.tile_png, orders) {
        (Some(tile), _) => Some(tile.as_slice()),
        (None, true) => Some(pictures.orders_png.as_slice()),
        (None, false) => None,
    };
    let picture_path = match picture {
        Some(png) => {
            atomic::write_atomic(&picture_path, png)?;
            Some(picture_path)
        }
        None => None,
    };
    ResultParts {
        scene,
        geometry: layer.geometry.as_ref(),
        raster: layer.raster.as_ref(),
        entries: &layer.entries,
        realisations: &layer.realisations,
        realisation_stop: layer.stop,
        plan: &plan_text(&plan, &layer.entries),
        orders_png: &pictures.orders_png,
        tile_png: pictures.tile_png.as_deref(),
        appearance: pictures.appearance.as_ref(),
        stack: None,
    }
    .write(&result_path)?;
    Ok(RunReport {
        result_path,
        picture_path,
        orders_picture_path,
        plot_paths,
        geometry: layer.geometry,
        entries: layer.entries,
        appearance: pictures.appearance,
    })
}

/// What a run with a target uncertainty did: how many realisations it took
/// of the most allowed, and why it stopped.
fn realisations_done_line(max: usize, used: usize, stop: RealisationStop) -> String {
    if stop.target_met {
        format!(
            "realisations: {used} of at most {max} — ΔE00 standard error {:.3} ≤ target {}",
            stop.de00_se, stop.target_de00
        )
    } else {
        format!(
            "realisations: {used}, the most allowed — ΔE00 standard error {:.3} is still above \
             the target {} (raise realisations.max or the target)",
            stop.de00_se, stop.target_de00
        )
    }
}

/// The appearance products of a run and its pictures.
struct RunProducts {
    /// Every reflected order of every solve from above.
    orders_png: Vec<u8>,
    /// The colour tile, when the scene asked for it.
    tile_png: Option<Vec<u8>>,
    /// The plots of the appearance: (file-name suffix, PNG).
    plots: Vec<(&'static str, Vec<u8>)>,
    appearance: Option<Appearance>,
}

/// Draw the orders, assemble the appearance the scene asks for, draw its
/// tile, and write the MERL file when asked.
fn assemble_products(
    scene: &Scene,
    plan: &RunPlan,
    entries: &[SolveEntry],
) -> Result<RunProducts, PipelineError> {
    let above: Vec<SolveEntry> = entries
        .iter()
        .filter(|e| e.side == Side::Above)
        .cloned()
        .collect();
    let orders_png = render::diffuse_brdf_png(&above, &scene.output.name)?;
    let products = scene.appearance.products;
    let wants_appearance =
        products.brdf || products.btdf || products.tile || products.merl || products.preview;
    let obs = Observer::standard(scene.appearance.illuminant, scene.appearance.observer);
    let appearance = if wants_appearance {
        let mut a = appearance::assemble(&appearance_spec(scene, plan), entries, &obs)?;
        super::baseline::add_baseline(scene, &mut a, &obs)?;
        Some(a)
    } else {
        None
    };
    // Colours are computed for the preview too; the tile is drawn when asked.
    let ground = scene.substrate.on_phrase();
    let hiding_line = appearance.as_ref().and_then(|a| {
        let conditions = render::tile::TileCaption {
            name: "",
            observer: &obs,
            ground: "",
            hiding: None,
            azimuth_deg: 0.0,
        }
        .conditions();
        crate::output::hiding::reported(&a.hiding)
            .map(|h| crate::output::hiding::tile_line(h, &conditions))
    });
    let tile_png = match appearance.as_ref() {
        Some(
            a @ Appearance {
                colours: Some(c), ..
            },
        ) if products.tile => Some(render::tile::tile_png(
            &c.tile_srgb8,
            &c.tile_lab,
            &a.spec.viewing_deg,
            &a.spec.illumination_deg,
            &render::tile::TileCaption {
                name: &scene.output.name,
                observer: &obs,
                ground: &ground,
                hiding: hiding_line.as_deref(),
                azimuth_deg: a.spec.azimuth_deg,
            },
        )?),
        _ => None,
    };
    let plots = match appearance.as_ref() {
        Some(a) => {
            let name = &scene.output.name;
            vec![
                (super::PLOTS[0], render::spectra_png(a, name)?),
                (super::PLOTS[1], render::brdf_plane_png(a, name)?),
                (super::PLOTS[2], render::brdf_polar_png(a, name)?),
            ]
        }
        None => vec![],
    };
    if let (Some(a), true) = (appearance.as_ref(), products.merl) {
        let merl = merl::encode(a)?;
        atomic::write_atomic(
            &scene
                .output
                .dir
                .join(format!("{}.binary", scene.output.name)),
            &merl,
        )?;
    }
    if let (Some(a), true) = (appearance.as_ref(), products.preview) {
        atomic::write_atomic(
            &scene
                .output
                .dir
                .join(format!("{}-preview.png", scene.output.name)),
            &render::preview_png(a, &obs, &scene.output.name)?,
        )?;
    }
    Ok(RunProducts {
        orders_png,
        tile_png,
        plots,
        appearance,
    })
}

/// What `inksim geometry` produced.
pub struct GeometryReport {
    pub result_path: PathBuf,
    pub picture_path: PathBuf,
    /// The particle set (None for an explicit structure).
    pub geometry: Option<Geometry>,
    /// Human-readable statistics (also drawn under the picture).
    pub lines: Vec<String>,
}

/// Build and rasterise a scene's layer only: the particle set and its
/// statistics to `<name>-geometry.h5`, a top view and a cross-section to
/// `<name>-geometry.png`. No solves.
pub fn run_geometry(scene: &Scene) -> Result<GeometryReport, PipelineError> {
    let d = &scene.output.dir;
    let name = &scene.output.name;
    let result_path = d.join(format!("{name}-geometry.h5"));
    let picture_path = d.join(format!("{name}-geometry.png"));
    check_output_dir(d)?;
    match &scene.structure {
        Some(Structure::Primitives(ps)) => {
            // Draw the explicit layer's raster: what the solver will see.
            let raster = structure::rasterize_primitives(ps, &grid_of(scene));
            let fr = raster.mean_fractions();
            let mut lines = vec![format!(
                "explicit structure: {} bodies; volume fraction {:.4} in all",
                ps.len(),
                fr.iter().sum::<f64>()
            )];
            for (i, (p, f)) in ps.iter().zip(&fr).enumerate() {
                lines.push(format!("body {i}: {} fraction {f:.4}", p.material.name));
            }
            write_geometry_only(
                scene,
                None,
                &raster,
                fr.iter().sum(),
                &lines,
                (&result_path, &picture_path),
            )?;
            return Ok(GeometryReport {
                result_path,
                picture_path,
                geometry: None,
                lines,
            });
        }
        Some(Structure::Hdf5(p)) => {
            return Err(PipelineError::NoGrains(format!(
                "{}: the layer is an ε grid from {}: nothing to build; use `inksim run`",
                scene.path().display(),
                p.display()
            )))
        }
        None if scene.is_molecular() => {
            return Err(PipelineError::NoGrains(format!(
                "{}: the pigments are dissolved (molecular): the layer is homogeneous, \
                 there are no grains to build",
                scene.path().display()
            )))
        }
        None => {}
    }
    let geometry = build_geometry(scene)?;
    let grid = grid_of(scene);
    let raster = raster::rasterize(&geometry, &grid, SUPERSAMPLE);
    let s = &geometry.stats;
    let (packer, _) = Packer::of(scene);
    let mut lines = vec![format!(
        "{} particles by {packer}; PVC {:.4} (target {:.4}; raster {:.4})",
        geometry.particles.len(),
        s.achieved_fraction.iter().sum::<f64>(),
        scene.total_pvc(),
        raster.mean_fractions().iter().sum::<f64>()
    )];
    // Worst overlap, S, relief, clusters (the PVC line is the one above).
    let stats = geometry::analyse(&geometry, &StatsParams::default());
    lines.extend(stats.lines().into_iter().skip(1));
    let pvc = geometry.stats.achieved_fraction.iter().sum();
    let layer = (geometry, raster);
    write_geometry_only(
        scene,
        Some(&layer.0),
        &layer.1,
        pvc,
        &lines,
        (&result_path, &picture_path),
    )?;
    Ok(GeometryReport {
        result_path,
        picture_path,
        geometry: Some(layer.0),
        lines,
    })
}

/// The picture and the result file of `inksim geometry`: the raster drawn
/// with `lines` under it, and a result set without solves.
fn write_geometry_only(
    scene: &Scene,
    geometry: Option<&Geometry>,
    raster: &Raster,
    pvc: f64,
    lines: &[String],
    (result_path, picture_path): (&Path, &Path),
) -> Result<(), PipelineError> {
    let png = render::geometry_png(raster, &scene.output.name, lines)?;
    atomic::write_atomic(picture_path, &png)?;
    ResultParts {
        scene,
        geometry,
        raster: Some(raster),
        entries: &[],
        realisations: &[(scene.seed, pvc)],
        realisation_stop: None,
        plan: &plan_text(&RunPlan::of(scene), &[]),
        orders_png: &png,
        tile_png: None,
        appearance: None,
        stack: None,
    }
    .write(result_path)
}
