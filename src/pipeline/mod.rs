//! The pipeline: the one module that wires the stages together, from a
//! checked scene to its result files:
//! config → geometry → raster → solver → optics → output.
//!
//! Takes a [`Scene`]; gives the result file, the pictures and a
//! [`RunReport`] (or, for `inksim geometry`, the layer alone: a
//! [`GeometryReport`]). The geometry and the λ-independent raster (volume
//! fractions) are built once per realisation; per wavelength only ε is
//! recomputed; per incidence only the solve. The output folder is checked
//! before any work so a bad path fails fast, and results are written
//! atomically (temp file + rename), so an interrupted run leaves either the
//! previous file or the complete new one.
//!
//! - `plan`: what runs, what is skipped, and why ([`RunPlan`]);
//! - `grains`: the scene's pigments → packer parameters, the packer
//!   choice ([`Packer`]), the particle set of a seed, the raster grid;
//! - `layer`: the three layer modes (closed-form slab, explicit structure,
//!   packed grains), each made and solved;
//! - `solve`: the solves of one layer (iterative, or the closed-form slab);
//! - `eps`: the permittivities of the scene's materials at a wavelength;
//! - `appearance`: what the appearance stage is given;
//! - `baseline`: the classical baselines' colours (Kubelka–Munk,
//!   adding–doubling) beside the wave one, when the scene asks for them;
//! - `paint`: an effect paint by the fast model, end to end ([`run_paint`]);
//! - `result`: the result file assembled from a run's parts;
//! - `run`: a run end to end ([`run`]), and the geometry-only run
//!   ([`run_geometry`]);
//! - [`memory`]: the memory model of a run and the preflight against the
//!   memory limit;
//! - [`disk`]: the bytes a run writes and the preflight against the free
//!   disk space;
//! - [`accuracy`]: the expected error of a scene's fidelity settings.

pub mod accuracy;
mod appearance;
pub mod baseline;
pub mod disk;
mod eps;
mod fine_bodies;
mod grains;
pub mod layer;
pub mod memory;
pub mod model_error;
pub mod paint;
mod paint_optics;
mod paint_sparkle;
mod plan;
mod result;
mod run;
mod solve;
mod stack;
mod stack_proxy;
mod surface;

use std::path::{Path, PathBuf};

use crate::config::Scene;
use crate::geometry;
use crate::optics::appearance as optics_appearance;
use crate::output::h5;
use crate::output::merl;
use crate::output::render;
use crate::raster::structure;
use crate::solver;

pub use appearance::{appearance_spec, fine_grid, PROXY_STEP_NM};
pub use baseline::{add_baseline, baseline_input};
pub use eps::{fraction_eps, species_eps};
pub use grains::{
    build_geometry, build_geometry_seeded, grid_of, largest_grain_nm, realisation_seed, Packer,
    RSA_MAX_PVC,
};
pub use paint::{paint_files, paint_plan, probe_paint, run_paint, PaintProbe, PaintReport};
pub use plan::{plan_text, planned_solves, RunPlan};
pub use result::RunReport;
pub use run::{run, run_geometry, run_with, GeometryReport};
pub use solve::{solve_analytic, solve_layer, solve_realisation, LayerEps};
pub use surface::flat_top;

/// The progress of a run of `total` solves, its plan's lines logged first;
/// hidden when `quiet` (a study's variants report through its own bar).
fn started(
    scene: &Scene,
    total: u64,
    quiet: bool,
    lines: &[String],
) -> crate::output::progress::Progress {
    use crate::output::progress::Progress;
    let progress = if quiet {
        Progress::hidden(total, &scene.output.name)
    } else {
        Progress::new(total, &scene.output.name)
    };
    for l in lines {
        progress.log(l);
    }
    progress
}

/// Sub-samples per voxel edge for partially filled voxels.
pub const SUPERSAMPLE: usize = 4;

/// Errors of a run, each naming what failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    #[error("output folder {path}: {message}")]
    Output { path: PathBuf, message: String },
    #[error("geometry: {0}")]
    Geometry(#[from] geometry::GeometryError),
    #[error("solve at {wavelength_nm} nm, polar {polar_deg}°: {source}")]
    Solve {
        wavelength_nm: f64,
        polar_deg: f64,
        source: solver::SolveError,
    },
    #[error("material `{material}` has no data at {wavelength_nm} nm")]
    Material {
        material: String,
        wavelength_nm: f64,
    },
    #[error(transparent)]
    Io(#[from] h5::IoError),
    #[error("render: {0}")]
    Render(#[from] render::RenderError),
    #[error(transparent)]
    Appearance(#[from] optics_appearance::AppearanceError),
    #[error(transparent)]
    Baseline(#[from] crate::optics::baseline::BaselineError),
    #[error("MERL export: {0}")]
    Merl(#[from] merl::MerlError),
    #[error("structure: {0}")]
    Structure(#[from] structure::StructureError),
    #[error("{0}")]
    NoGrains(String),
    #[error(transparent)]
    Memory(Box<memory::OverMemory>),
}

/// Paths of the result files of a scene.
pub fn result_paths(scene: &Scene) -> (PathBuf, PathBuf) {
    let d = &scene.output.dir;
    (
        d.join(format!("{}.h5", scene.output.name)),
        d.join(format!("{}.png", scene.output.name)),
    )
}

/// Every file a run of `scene` writes, and nothing else (`outputs`
/// decides): the result; the picture `<name>.png` (the tile, or the orders
/// picture when a BRDF or BTDF but no tile was asked for); the orders
/// picture `<name>-orders.png` with a BRDF or BTDF; the plots
/// `<name>-{spectra,brdf-plane,brdf-polar}.png` with any appearance
/// product; the MERL file when asked for. `outputs = []` writes the result
/// alone.
pub fn output_files(scene: &Scene) -> Vec<PathBuf> {
    let (h5, png) = result_paths(scene);
    let d = &scene.output.dir;
    let name = &scene.output.name;
    let p = scene.appearance.products;
    let orders = p.brdf || p.btdf;
    let mut files = vec![h5];
    // A stack solved layer by layer draws its tile alone (no orders, no
    // BRDF plots: it carries the plane of incidence only).
    if scene.is_incoherent_stack() {
        if p.tile {
            files.push(png);
        }
        return files;
    }
    if p.tile || orders {
        files.push(png);
    }
    if orders {
        files.push(d.join(format!("{name}-orders.png")));
    }
    if p.brdf || p.btdf || p.tile || p.merl || p.preview {
        for suffix in PLOTS {
            files.push(d.join(format!("{name}-{suffix}.png")));
        }
    }
    if p.merl {
        files.push(d.join(format!("{name}.binary")));
    }
    if p.preview {
        files.push(d.join(format!("{name}-preview.png")));
    }
    files
}

/// The plots a run with an appearance product draws, as `<name>-<plot>.png`.
pub const PLOTS: [&str; 3] = ["spectra", "brdf-plane", "brdf-polar"];

/// No output path is taken by something a file cannot replace: the output
/// folder is a folder (or not there yet) and no result file's name is a
/// folder. Checked by `check` and before a run's first solve.
pub fn check_output_files(scene: &Scene) -> Result<(), PipelineError> {
    let err = |path: &Path, m: &str| PipelineError::Output {
        path: path.to_path_buf(),
        message: m.to_string(),
    };
    let dir = &scene.output.dir;
    if dir.exists() && !dir.is_dir() {
        return Err(err(dir, "is a file, not a folder"));
    }
    for f in output_files(scene) {
        if f.is_dir() {
            return Err(err(
                &f,
                "is a folder where a result file goes; remove it or choose another [output] name",
            ));
        }
    }
    Ok(())
}

/// The data files a run reads, read and checked as the run reads them: a
/// structure's ε grid (an HDF5 file with `eps_re`, `eps_im` of the scene's
/// grid shape, finite, Im ε ≥ 0, a grid for every wavelength). Pigment
/// tables are read and checked when the config is loaded. Called by `check`,
/// so that a bad file is found before any run starts.
pub fn check_inputs(scene: &Scene) -> Result<(), PipelineError> {
    if let Some(crate::config::Structure::Hdf5(path)) = &scene.structure {
        crate::raster::structure::EpsGrid::read(path, &grid_of(scene), &scene.wavelengths_nm)?;
    }
    Ok(())
}

/// Make sure the output folder exists and accepts files.
pub fn check_output_dir(dir: &Path) -> Result<(), PipelineError> {
    let err = |m: String| PipelineError::Output {
        path: dir.to_path_buf(),
        message: m,
    };
    std::fs::create_dir_all(dir).map_err(|e| err(format!("cannot create: {e}")))?;
    let probe = dir.join(format!(".inksim-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| err(format!("not writable: {e}")))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}
