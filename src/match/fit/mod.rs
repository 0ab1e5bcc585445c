//! Colourants from drawdowns (`inksim fit-material`): the optical constants
//! of an unknown pigment — `k(λ)` with `n` known, or `n(λ)` and `k(λ)` —
//! and, if asked, its grain diameter, fitted so that the match's fast
//! forward model reproduces measured reflectance spectra of drawdowns
//! (masstones and tints with a known white, over black and white grounds,
//! each of known thickness and volume fractions). The fitted constants
//! are written as a material table the scenes read like any other, with
//! the fit's residuals and provenance in its header.
//!
//! - [`config`]: the fit file checked into a [`FitSpec`].
//! - [`model`]: the drawdowns on the fast model as a function of the
//!   pigment's constants at one wavelength.
//! - [`estimate`]: the per-wavelength least squares, the shared diameter,
//!   the standard errors and what is not determined.
//! - [`write`]: the material CSV and the HDF5 result, written atomically.
//! - [`synthetic`]: drawdown spectra of a known material on the same model
//!   (with seeded noise), for tests and the example.
//!
//! The method and what is identifiable are in docs/MATCH.md, "Colourants
//! from drawdowns".

pub mod config;
pub mod estimate;
pub mod model;
pub mod synthetic;
pub mod write;

pub use config::FitSpec;
pub use estimate::{FitOutcome, WavelengthFit};
pub use model::DrawdownModel;

use super::MatchError;

/// Check `spec`, build its model and fit it.
pub fn run(spec: &FitSpec) -> Result<FitOutcome, MatchError> {
    let model = DrawdownModel::new(spec)?;
    Ok(estimate::fit(spec, &model))
}
