//! A study whose base is an effect paint (a `[paint]` table): the same sweep
//! file, expansion, naming, seeding and resumable runner as a study of
//! wave-optics layers, each variant computed by the fast model
//! ([`pipeline::run_paint`](crate::pipeline::run_paint)).
//!
//! - `run`: the effect paint's scene as the runner's
//!   [`RunScene`](super::run::RunScene) (its files, its state, its run).
//! - [`plan`]: each variant's time and memory, measured by solving it at
//!   its middle wavelength.
//! - [`merge`]: the summary file, table, grids of the patches and the page
//!   with every variant's flop curve and sparkle figures.
//! - `findings`: what changes along each axis (flop index, colour),
//!   and the hue per label, in numbers and in words.
//!
//! The user documentation is docs/STUDY.md, "An effect study".

mod findings;
pub mod merge;
mod page;
pub mod plan;
mod row;
mod run;
mod summary_h5;

pub use merge::{merge, EffectMergeReport};
