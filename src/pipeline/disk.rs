//! The disk model of a run and the preflight that refuses a run whose
//! results the output's file system cannot hold, before any solve.
//!
//! Bytes a run of one scene writes, on the safe side (a demo-sized result
//! is about a quarter of the estimate; `tests/disk.rs` holds the estimate
//! between the actual size and ten times it):
//! - each PNG written ([`super::output_files`]) [`PNG_BYTES`], and each
//!   PNG embedded in the result file (the picture and the tile's);
//! - the result file: [`FILE_BYTES`], per solve [`SOLVE_BYTES`] of HDF5
//!   metadata plus [`ORDER_BYTES`] per propagating order (about
//!   π Lx Ly / λ², half again for both faces' orders), per realisation
//!   [`SPHERE_BYTES`] per sphere of its geometry (grains from the PVC over
//!   the grain volume, times the spheres of the grain's shape), and the
//!   appearance tables (8 bytes per value, doubled for standard errors);
//! - a MERL export, its fixed 90 × 90 × 180 × 3 doubles.
//!
//! The run's temporary files are written beside their outputs and renamed
//! onto them, so a result being replaced briefly takes twice its size: the
//! estimate is compared with the free space as it is.

use crate::config::{GrainShape, Scene};
use crate::output::space;

use super::memory::human_bytes;
use super::{output_files, PipelineError, RunPlan};

/// Upper bound of one PNG picture (measured: 130–330 kB for the demo's).
pub const PNG_BYTES: f64 = 1e6;
/// A result file's fixed part: config, plan, summary, attributes and the
/// HDF5 library's own structures (measured: 176 kB for a result of four
/// solves and no products).
pub const FILE_BYTES: f64 = 256e3;
/// HDF5 metadata of one solve's group (measured: 6.4 kB).
pub const SOLVE_BYTES: f64 = 8e3;
/// One propagating order's data: (m, n), θ, φ, R, T.
pub const ORDER_BYTES: f64 = 40.0;
/// One sphere of the stored geometry: centre, radius, particle index.
pub const SPHERE_BYTES: f64 = 48.0;
/// The MERL export.
pub const MERL_BYTES: f64 = 12.0 + 90.0 * 90.0 * 180.0 * 3.0 * 8.0;

/// Estimated bytes a run of `scene` following `plan` writes (module docs).
pub fn estimate_bytes(scene: &Scene, plan: &RunPlan) -> f64 {
    let files = output_files(scene);
    let pngs = files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .count() as f64;
    let merl = if scene.appearance.products.merl {
        MERL_BYTES
    } else {
        0.0
    };
    let lambda_min = scene
        .wavelengths_nm
        .iter()
        .cloned()
        .fold(f64::INFINITY, f64::min);
    let l = &scene.layer;
    let orders =
        1.5 * std::f64::consts::PI * l.fragment_x_nm * l.fragment_y_nm / lambda_min.powi(2) + 8.0;
    let volume = l.thickness_nm * l.fragment_x_nm * l.fragment_y_nm;
    let spheres: f64 = scene
        .species
        .iter()
        .filter(|s| s.diameter_nm > 0.0)
        .map(|s| {
            let per_grain = match s.shape {
                GrainShape::Sphere | GrainShape::Molecular => 1,
                GrainShape::Cylinder { spheres, .. } | GrainShape::Rice { spheres, .. } => spheres,
            } as f64;
            s.volume_fraction * volume / (std::f64::consts::PI / 6.0 * s.diameter_nm.powi(3))
                * per_grain
        })
        .sum();
    let r = plan.realisations as f64;
    let se = if plan.realisations >= 2 { 2.0 } else { 1.0 };
    let n = plan.table.n() as f64;
    let tables = 8.0
        * se
        * scene.wavelengths_nm.len() as f64
        * scene.incidence.len() as f64
        * n
        * n
        * if scene.appearance.products.btdf {
            2.0
        } else {
            1.0
        };
    // The picture (`<name>.png`) and the tile's PNG are embedded too.
    let p = scene.appearance.products;
    let embedded = f64::from(u8::from(p.tile || p.brdf || p.btdf) + u8::from(p.tile));
    let result = FILE_BYTES
        + embedded * PNG_BYTES
        + plan.solves(scene) as f64 * (SOLVE_BYTES + ORDER_BYTES * orders)
        + r * SPHERE_BYTES * spheres
        + tables;
    result + pngs * PNG_BYTES + merl
}

/// Refuse a run whose results (`need` bytes) do not fit the free space of
/// `dir`'s file system; where the system does not say, go on.
pub fn preflight(dir: &std::path::Path, need: f64) -> Result<(), PipelineError> {
    match space::available_bytes(dir) {
        Some(free) if (free as f64) < need => Err(PipelineError::Output {
            path: dir.to_path_buf(),
            message: format!(
                "not enough disk space: {} free, the results need about {}; free some \
                 space or give another --output-dir",
                human_bytes(free as f64),
                human_bytes(need)
            ),
        }),
        _ => Ok(()),
    }
}
