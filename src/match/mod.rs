//! Formulation: from a target colour to a recipe (`inksim match`, METHOD
//! §12). The stage after the study; it takes a match file and gives ranked
//! recipes, each with its colour against the target, its metamerism and its
//! uncertainty, written as HDF5 and CSV.
//!
//! - [`config`]: the match file (target, base scene, palette, search) checked
//!   into a [`MatchSpec`].
//! - [`forward`]: the fast forward model, the base scene's Kubelka–Munk
//!   baseline as a function of the recipe.
//! - [`problem`]: the target on the model's grid and what a subset of the
//!   palette's unknowns mean.
//! - [`solve`]: bounded Levenberg–Marquardt and Nelder–Mead, the Jacobian.
//! - [`search`]: subsets of the palette, fewest colourants first, several
//!   starting points each.
//! - [`uncertainty`]: the recipe's standard errors from the target's noise,
//!   and the ingredients it cannot tell apart.
//! - [`correct`]: one correction step of a recipe from a measured colour.
//! - [`verify`]: the best recipes solved by the wave pipeline at the base
//!   scene's fidelity and corrected by the fast–exact difference.
//! - [`report`]: the reported recipes (composition, ΔE00 per geometry,
//!   metamerism indices, uncertainty).
//! - [`write`]: the HDF5 file and the recipes CSV, written atomically.
//! - [`page`]: the page of the target and the recipes side by side, and its
//!   spectra figure.
//! - [`effect`]: the same search for an effect paint: flake concentration,
//!   coating thickness and pigments from multi-angle colours, on the fast
//!   flake model.
//! - [`fit`]: the inverse of a pigment (`inksim fit-material`): its optical
//!   constants from measured drawdowns, on the same fast model.
//!
//! The method, the report's fields and the limits are documented in
//! docs/MATCH.md.

pub mod config;
pub mod correct;
pub mod effect;
pub mod fit;
pub mod forward;
pub mod page;
pub mod problem;
pub mod report;
pub mod search;
pub mod solve;
pub mod uncertainty;
pub mod verify;
pub mod write;
mod write_verify;

pub use config::MatchSpec;
pub use report::{run, MatchReport, RecipeReport};

use std::path::PathBuf;

use crate::optics::colour::ColourError;
use crate::output::h5::IoError;
use crate::pipeline::PipelineError;

/// Everything that can go wrong in a match, each naming the file or what is
/// allowed.
#[derive(Debug, thiserror::Error)]
pub enum MatchError {
    /// A problem in the match file (or its base scene, target or palette).
    #[error("{file}: {message}")]
    Config { file: PathBuf, message: String },
    #[error("match: the fast model is `kubelka-munk` or `kubelka-munk-scene`, not `{0}`")]
    Model(&'static str),
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    #[error("match: colour: {0}")]
    Colour(#[from] ColourError),
    #[error(transparent)]
    Io(#[from] IoError),
}
