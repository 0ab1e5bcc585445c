//! Formulation of an effect paint (`inksim match` of a file whose target
//! is `kind = "multi-angle"`): from the multi-angle colours of an effect
//! finish to the flake concentration, the coating thickness of
//! interference flakes and the ordinary pigments' volume fractions of a
//! base paint, on the fast flake model. The search, its uncertainty and
//! its ranking are the scene match's ([`super::search`],
//! [`super::uncertainty`] through [`super::problem::Inverse`]).
//!
//! - [`config`]: the effect match file checked into an [`EffectSpec`].
//! - [`forward`]: the base paint with a recipe's settings, solved by the
//!   pipeline's fast flake model, its multi-angle colours.
//! - [`problem`]: the target, the unknowns and their bounds as an
//!   [`super::problem::Inverse`].
//! - [`report`]: the search and the reported recipes (ΔE00 per geometry
//!   with its standard error, flop index).
//! - [`write`] and [`page`]: the HDF5 file, the recipes CSV and the page.
//!
//! The method, the file's keys and the limits: docs/MATCH.md, "Effect
//! paints".

pub mod config;
pub mod forward;
pub mod page;
pub mod problem;
pub mod report;
pub mod write;

pub use config::EffectSpec;
pub use report::{run, EffectRecipe, EffectReport};
