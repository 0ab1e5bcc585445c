//! inksim — wave-optics simulator for printed ink layers.
//!
//! Data flows one way through the stages, one folder each, and a module
//! imports only from its own stage and the stages before it:
//!
//! [`config`] → [`geometry`] → [`raster`] → [`solver`] → [`optics`] (far
//! field, substrate, colour, appearance) → [`output`] (atomic writes, HDF5,
//! pictures, MERL, progress) → [`pipeline`] (one scene) → [`study`] (a sweep
//! of scenes) → [`match`](crate::r#match) (formulation: from a target colour to a
//! recipe) → [`view`] (the interactive page of `inksim view`). `tests/layering.rs` checks the rule on the source: no import
//! from a later stage and no import cycle anywhere.
//!
//! The physics and numerics are explained in `docs/METHOD.md` (the module
//! docs cite its sections as "METHOD §N"); each stage's module docs state what
//! it owns, what it takes and what it gives.

pub mod config;
pub mod geometry;
pub mod r#match;
pub mod optics;
pub mod output;
pub mod pipeline;
pub mod raster;
pub mod solver;
pub mod study;
pub mod view;

/// Version string embedded in every result file.
pub const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "+", env!("INKSIM_COMMIT"));
