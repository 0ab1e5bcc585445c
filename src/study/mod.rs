//! The study driver: a sweep of scene variants, run resumably on one machine
//! or sharded over a cluster. The last stage.
//!
//! Takes a sweep file (a base scene, profiles, axes, zips, exclusions,
//! explicit variants, grids). Gives, before any work starts, every variant
//! as a named, seeded scene checked by [`config`](crate::config); then runs
//! the variants through [`pipeline::run`](crate::pipeline::run) (each result
//! file written atomically, finished ones skipped by their input hash), and
//! merges the finished results, read back through
//! [`output::h5`](crate::output::h5), into a summary file, a summary page
//! and comparison grids drawn with [`output::render`](crate::output::render).
//! It owns the sweep format, the variant naming and seeding, sharding, the
//! cost model of `plan` and the sbatch script; errors are [`StudyError`]s
//! naming the file and what is allowed.
//!
//! - [`sweep`]: the sweep file, checked into a [`Study`] and expanded per
//!   profile into [`Variant`]s — every error is found before any work.
//! - [`plan`]: the work and the estimated time and memory of each variant.
//! - [`run`]: runs the variants (in parallel, sharded, resumable).
//! - [`merge`]: the summary HDF5, the comparison grids and the summary page.
//! - [`slurm`]: a ready sbatch array script.
//! - [`export`]: the variants' measured colours as one CSV table.
//! - [`effect`]: a study whose base is an effect paint (`[paint]`): the
//!   same sweep, expansion and runner, the fast model's plan and merge.
//!
//! The user documentation of the format and the commands is docs/STUDY.md.

mod cpu;
pub mod effect;
pub mod export;
pub mod merge;
pub mod pilot;
pub mod plan;
pub mod run;
pub mod slurm;
pub mod sweep;

pub use sweep::{is_study_text, Study, Variant};

use std::path::PathBuf;

/// Everything that can go wrong in a study, each naming the file and what
/// is allowed.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error("{file}: cannot read: {source}")]
    Read {
        file: PathBuf,
        source: std::io::Error,
    },
    /// A problem in the sweep file (or the variants it defines).
    #[error("{file}: {message}")]
    Sweep { file: PathBuf, message: String },
    #[error(transparent)]
    Io(#[from] crate::output::h5::IoError),
    #[error("{path}: HDF5 error: {source}")]
    Hdf5 { path: PathBuf, source: hdf5::Error },
    #[error("render: {0}")]
    Render(#[from] crate::output::render::RenderError),
    /// `merge` before every variant is finished.
    #[error("{0}")]
    Incomplete(String),
    #[error("{0}")]
    Usage(String),
}
