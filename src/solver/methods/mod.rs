//! The solution methods and their registry.
//!
//! Every method implements [`Solver`]: it carries its [`Method`] (whose
//! name scenes and result files use), its measured peak bytes per voxel for
//! f64 and f32 field storage, its operator applications per iteration (the
//! study's time model), an a-priori [`Validity`] estimate, and its solve. The
//! iterative methods only [`Solver::run`] on a built [`System`]; the provided
//! [`Solver::solve`] builds the system around them. [`Method::solver`] is the
//! registry: it gives each method's implementation.
//!
//! Takes a [`Problem`] and [`Controls`]; gives a [`Solution`] or a
//! [`SolveError`].

pub mod auto;
pub mod bicgstab;
pub mod born;
pub mod closed_form;
pub mod gmres;
pub mod marching;
mod monitor;

pub use monitor::{restart, Monitor, Restart, STALL_ITERATIONS};

/// [`Solver::run`] for a method whose inherent `iterate::<S>` does the
/// work on fields stored as `S`: unwraps the [`Field`] into its storage.
macro_rules! run_in_field_storage {
    () => {
        fn run(
            &self,
            sys: &mut $crate::solver::System,
            scr: &mut $crate::solver::Scratch,
            u: &mut $crate::solver::Field,
            ctl: &$crate::solver::Controls,
        ) -> Result<$crate::solver::Outcome, $crate::solver::SolveError> {
            $crate::solver::storage::on_field!(u, u => self.iterate(sys, scr, u, ctl))
        }
    };
}
use run_in_field_storage;

use super::storage::Field;
use super::system::{Scratch, System};
use super::{Controls, Problem, Solution, SolveError, SolveRecord};
use crate::config::{Background, Method, Precision};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::time::Instant;

/// The registry: each [`Method`] (named by the scene schema) to its
/// implementation, with its default settings.
impl Method {
    pub fn solver(self) -> &'static dyn Solver {
        match self {
            Method::Born => &born::Born,
            Method::TimeMarching => &marching::TimeMarching::DEFAULT,
            Method::Gmres => &gmres::Gmres::DEFAULT,
            Method::BiCgStab => &bicgstab::BiCgStab::DEFAULT,
            Method::Auto => &auto::Auto,
            Method::Airy => &closed_form::Airy,
        }
    }
}

/// How far a method can be trusted on a problem, before running it.
#[derive(Debug, Clone, PartialEq)]
pub enum Validity {
    /// Converges for any problem of this kind.
    Always,
    /// Expected to converge; the estimate behind it.
    Likely(String),
    /// Expected to fail; why.
    Unlikely(String),
}

/// Result of running one method.
pub struct Outcome {
    /// The method that produced it (for `auto`, the one it ended with).
    pub method: Method,
    pub iterations: usize,
    pub applications: usize,
    pub residual: f64,
    pub note: String,
}

impl Outcome {
    /// The solve record of this outcome on `background`, `seconds` long.
    pub fn record(&self, background: Background, seconds: f64) -> SolveRecord {
        SolveRecord {
            method: self.method,
            background,
            iterations: self.iterations,
            operator_applications: self.applications,
            residual: self.residual,
            seconds,
            note: self.note.clone(),
        }
    }
}

/// A solution method.
pub trait Solver: Sync {
    /// Which method this is (its name and where scenes may use it are
    /// [`Method`]'s).
    fn method(&self) -> Method;

    /// Peak bytes per voxel of a solve with fields stored at `precision`
    /// (measured by `examples/solver_memory`, docs/PERFORMANCE.md).
    fn bytes_per_voxel(&self, precision: Precision) -> f64;

    /// Operator applications per iteration; a solve of `n` iterations is
    /// counted as `(n + 1) ×` this (the last residual).
    fn applications_per_iteration(&self) -> f64;

    /// A cheap a-priori statement of where the method is valid on `sys`,
    /// with fields stored at `precision`.
    fn validity(&self, _sys: &mut System, _scr: &mut Scratch, _precision: Precision) -> Validity {
        Validity::Always
    }

    /// Improve `u` in place until the relative residual is below tolerance.
    /// Only iterative methods have this step.
    fn run(
        &self,
        _sys: &mut System,
        _scr: &mut Scratch,
        _u: &mut Field,
        _ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        Err(SolveError::Invalid(format!(
            "{} does not iterate on a system",
            self.method()
        )))
    }

    /// Solve one problem: build its [`System`], start from its start field (u_bg for Born)
    /// stored at `ctl.precision` and [`Solver::run`].
    fn solve(&self, p: &Problem, ctl: &Controls) -> Result<Solution, SolveError> {
        self.solve_from(p, ctl, None)
    }

    /// As [`Solver::solve`], starting from `start` where given (the field
    /// of an earlier solve of the same problem, e.g. at a looser
    /// tolerance; the unknown is the same on either background).
    fn solve_from(
        &self,
        p: &Problem,
        ctl: &Controls,
        start_field: Option<&Array3<C64>>,
    ) -> Result<Solution, SolveError> {
        let start = Instant::now();
        let mut sys = System::new(p, ctl.background)?;
        let mut scr = sys.scratch();
        let mut u = Field::zeros(ctl.precision, sys.unknown_dim());
        match start_field {
            Some(f) if f.dim() == sys.unknown_dim() => u.load_from(f),
            // Born iterates the plain equation, from u_bg on any background.
            _ if self.method() == Method::Born => sys.set_background_field(&mut u),
            _ => sys.set_start_field(&mut u),
        }
        let out = self.run(&mut sys, &mut scr, &mut u, ctl)?;
        let mut record = out.record(sys.background(), start.elapsed().as_secs_f64());
        if ctl.precision == Precision::F32 {
            record.note.push_str("; f32 field storage");
        }
        Ok(sys.into_solution(scr, u, record))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_method_is_registered_as_itself() {
        for m in Method::ALL {
            assert_eq!(m.solver().method(), m);
        }
    }
}
