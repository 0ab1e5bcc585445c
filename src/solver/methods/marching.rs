//! Pseudo-time marching to the steady state with the convergent-Born-series
//! preconditioner (Osnabrugge, Leedumrongwatthanakun & Vellekoop, J. Comput.
//! Phys. 322, 2016).
//!
//! The discrete equation `u = u_bg + G_b V u` is written in its shifted form
//! `u = u_s + G_s V' u` — the same solution, exactly: with the background
//! shifted to `ε_r + iε_s` (`ε_s ≥ max|ε − ε_r|` inside the slab; the vacuum
//! outside stays vacuum and is lossy for outgoing waves),
//! `c = k0²(ε_r + iε_s − ε_b)`, `G_s = (G_b⁻¹ − c)⁻¹` the shifted operator
//! *of the same discrete* `G_b`, `V' = V − c` and `u_s = (I − c G_b)⁻¹ u_bg`.
//! [`shift`](crate::solver::shift) applies `G_s` exactly in O(N) per harmonic without
//! ever forming `G_b`, so guided-mode poles of the binder slab never enter.
//! The march always runs on this shift, also where the Krylov methods use
//! the layer's mean permittivity as background (`solver.background`).
//! We march `du/dτ = γ r'`, `r' = u_s + G_s V' u − u`,
//! `γ = 1 + i(ε − ε_r)/ε_s`, by explicit Euler; with `dτ = 1` this is the CBS
//! iteration, which converges for any contrast (the Galerkin `G_b` is the
//! projection of a passive operator, so `‖G_s‖ ≤ 1/(k0² ε_s)` holds as the
//! proof needs). The residual need not fall monotonically; a solve is
//! declared diverged only if it becomes non-finite or grows a thousandfold
//! above its best. Cost per step: one application of `G_s` between a forward
//! and an inverse 2-D FFT.

use super::{Monitor, Outcome, Solver};
use crate::config::{Background, Method, Precision};
use crate::solver::storage::{on_field, Field, Storage};
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, SolveError};
use ndarray::{Array3, Zip};

/// Time-marching settings.
#[derive(Debug, Clone, Copy)]
pub struct TimeMarching {
    /// Pseudo-time step (1 is the CBS iteration).
    pub step: f64,
}

impl Solver for TimeMarching {
    fn method(&self) -> Method {
        Method::TimeMarching
    }

    fn bytes_per_voxel(&self, precision: Precision) -> f64 {
        precision.select(86.0, 70.0)
    }

    fn applications_per_iteration(&self) -> f64 {
        1.0
    }

    /// Marches on the CBS shift whatever background the system was built
    /// with: without its preconditioner the march need not converge.
    fn run(
        &self,
        sys: &mut System,
        scr: &mut Scratch,
        u: &mut Field,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        sys.use_background(Background::Binder);
        on_field!(u, u => self.iterate(sys, scr, u, ctl))
    }
}

impl TimeMarching {
    /// The CBS iteration.
    pub const DEFAULT: TimeMarching = TimeMarching { step: 1.0 };

    fn iterate<S: Storage>(
        &self,
        sys: &System,
        scr: &mut Scratch,
        u: &mut Array3<S>,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        let mut r = Array3::<S>::default(u.dim());
        let step = self.step;
        let mut monitor = Monitor::new(Method::TimeMarching);
        for it in 0..=ctl.max_iterations {
            let res = sys.residual_shifted(scr, u, &mut r);
            if monitor.check(res, it, ctl)? {
                let note = format!("{}, dτ = {step}", sys.describe_background());
                return Ok(Outcome {
                    method: Method::TimeMarching,
                    iterations: it,
                    applications: it + 1,
                    residual: res,
                    note,
                });
            }
            sys.precondition(&mut r);
            Zip::from(&mut *u)
                .and(&r)
                .par_for_each(|u, w| *u = S::store(u.load() + step * w.load()));
        }
        unreachable!("loop returns")
    }
}
