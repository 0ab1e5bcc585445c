//! inksim — wave-optics simulator for printed ink layers.
//!
//! Data flows one way through the stages, and each module imports only from
//! the stages before it:
//!
//! `config` → `geometry` → `raster` → `solver` → `farfield` → `substrate` → `colour`
//! → `appearance` → `render` → `io`,
//! wired together by [`pipeline`]. [`progress`] is a leaf utility.
//!
//! The physics and numerics follow `METHOD.md` (shipped beside the project);
//! each stage's module docs state what it owns and which choices it made.

pub mod accuracy;
pub mod appearance;
pub mod colour;
pub mod config;
pub mod farfield;
pub mod geometry;
pub mod io;
pub mod merl;
pub mod pipeline;
pub mod progress;
pub mod raster;
pub mod render;
pub mod solver;
pub mod structure;
pub mod study;
pub mod substrate;

/// Version string embedded in every result file.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
