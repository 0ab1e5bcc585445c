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

pub mod config;
pub mod geometry;
pub mod optics;
pub mod output;
pub mod pipeline;
pub mod raster;
pub mod solver;
pub mod study;

/// Version string embedded in every result file.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
