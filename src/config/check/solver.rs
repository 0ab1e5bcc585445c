//! `[solver]`: the wave equation, the method, tolerance, iteration limit,
//! field precision, the Krylov methods' background, the effective-medium
//! tolerance and the energy-balance limit; and `[illumination] polarisation`, which only Maxwell's
//! equation can honour.

use super::Checker;
use crate::config::raw::{
    RawBackground, RawEquation, RawMethod, RawNaturalLight, RawPolarisation, RawPrecision,
    RawSolver,
};
use crate::config::{
    Background, ConfigError, Equation, Method, NaturalLight, Polarisation, Precision, SolverSpec,
};

const DEFAULT_TOLERANCE: f64 = 1e-6;
const DEFAULT_MAX_ITERATIONS: usize = 5000;
/// Smallest relative residual f32 field storage reaches reliably.
pub const F32_MIN_TOLERANCE: f64 = 1e-6;
const MAX_ITERATIONS: i64 = 10_000_000;
/// Default accepted error of the effective-medium shortcut: the R/T/A error
/// of the recommended 25 nm grid (docs/ACCURACY.md), so the shortcut costs
/// no more accuracy than the discretisation it replaces.
pub const DEFAULT_EFFECTIVE_MEDIUM_TOLERANCE: f64 = 1e-3;
/// Largest accepted error of the effective-medium shortcut.
pub const MAX_EFFECTIVE_MEDIUM_TOLERANCE: f64 = 0.1;
/// Default largest |ΣR + ΣT + A − 1| a solve may leave before it is solved
/// again, tighter: well inside what the colours notice (ΔE00 ~0.01 per
/// 1e-4 of R), so a residual test that converged early cannot pass an
/// energy error on to them.
pub const DEFAULT_ENERGY_BALANCE_LIMIT: f64 = 1e-4;

impl Checker<'_> {
    pub(super) fn solver(
        &self,
        raw: Option<&RawSolver>,
        polarisation: Option<RawPolarisation>,
        random_layer: bool,
        ensemble: bool,
    ) -> Result<SolverSpec, ConfigError> {
        let equation = match raw.and_then(|s| s.equation) {
            Some(RawEquation::Maxwell) => Equation::Maxwell,
            Some(RawEquation::Helmholtz) | None => Equation::Helmholtz,
        };
        let polarisation = match polarisation {
            None | Some(RawPolarisation::Unpolarised) => Polarisation::Unpolarised,
            Some(RawPolarisation::S) => Polarisation::S,
            Some(RawPolarisation::P) => Polarisation::P,
        };
        if equation == Equation::Helmholtz && polarisation != Polarisation::Unpolarised {
            return Err(self.invalid(
                "illumination.polarisation",
                format!(
                    "\"{}\" needs solver.equation = \"maxwell\": the scalar Helmholtz \
                     equation has no polarisation (every surface reflects like s)",
                    polarisation.name()
                ),
            ));
        }
        let natural = equation == Equation::Maxwell && polarisation == Polarisation::Unpolarised;
        let natural_light = match raw.and_then(|s| s.natural_light) {
            Some(RawNaturalLight::TwoSolves) => NaturalLight::TwoSolves,
            Some(RawNaturalLight::RandomPhase) if !natural => {
                return Err(self.invalid(
                    "solver.natural_light",
                    format!(
                        "\"random-phase\" is a way of solving unpolarised light in Maxwell's \
                         equations; this scene is {} with polarisation \"{}\"",
                        equation.name(),
                        polarisation.name()
                    ),
                ))
            }
            Some(RawNaturalLight::RandomPhase) if !random_layer => {
                return Err(self.invalid(
                    "solver.natural_light",
                    "\"random-phase\" averages its s-p cross term out over random \
                     realisations; an explicit structure or a stack is one fixed layer: use \
                     \"two-solves\"",
                ))
            }
            Some(RawNaturalLight::RandomPhase) => NaturalLight::RandomPhase,
            None | Some(RawNaturalLight::Auto) if natural && ensemble => NaturalLight::RandomPhase,
            None | Some(RawNaturalLight::Auto) => NaturalLight::TwoSolves,
        };
        let method = raw
            .and_then(|s| s.method)
            .map_or(Method::Auto, |RawMethod(m)| m);
        let t = raw.and_then(|s| s.tolerance).unwrap_or(DEFAULT_TOLERANCE);
        let tolerance = self.range(
            "solver.tolerance",
            t,
            (1e-12..=1e-1).contains(&t),
            "[1e-12, 1e-1]",
        )?;
        let max_iterations = match raw.and_then(|s| s.max_iterations) {
            None => DEFAULT_MAX_ITERATIONS,
            Some(m) if (1..=MAX_ITERATIONS).contains(&m) => m as usize,
            Some(m) => {
                return Err(self.invalid(
                    "solver.max_iterations",
                    format!("must be in [1, {MAX_ITERATIONS}], got {m}"),
                ))
            }
        };
        let precision = match raw.and_then(|s| s.precision) {
            Some(RawPrecision::F32) => Precision::F32,
            Some(RawPrecision::F64) | None => Precision::F64,
        };
        if precision == Precision::F32 && tolerance < F32_MIN_TOLERANCE {
            return Err(self.invalid(
                "solver.tolerance",
                format!(
                    "must be in [{F32_MIN_TOLERANCE:e}, 1e-1] with precision = \"f32\" \
                     (f32 fields cannot hold a smaller residual), got {tolerance:e}"
                ),
            ));
        }
        let background = match raw.and_then(|s| s.background) {
            Some(RawBackground::Binder) => Background::Binder,
            Some(RawBackground::Mean) => Background::Mean,
            None => Background::default(),
        };
        let e = raw
            .and_then(|s| s.effective_medium_tolerance)
            .unwrap_or(DEFAULT_EFFECTIVE_MEDIUM_TOLERANCE);
        let effective_medium_tolerance = self.range(
            "solver.effective_medium_tolerance",
            e,
            (0.0..=MAX_EFFECTIVE_MEDIUM_TOLERANCE).contains(&e),
            "[0, 0.1] (absolute error in R, T, A; 0 never takes the shortcut)",
        )?;
        let b = raw
            .and_then(|s| s.energy_balance_limit)
            .unwrap_or(DEFAULT_ENERGY_BALANCE_LIMIT);
        let energy_balance_limit = self.range(
            "solver.energy_balance_limit",
            b,
            (1e-8..=1e-2).contains(&b),
            "[1e-8, 1e-2] (largest |R + T + A - 1| before a solve is solved again, tighter)",
        )?;
        Ok(SolverSpec {
            equation,
            polarisation,
            natural_light,
            method,
            tolerance,
            max_iterations,
            precision,
            background,
            effective_medium_tolerance,
            energy_balance_limit,
        })
    }
}
