//! Convergence bookkeeping shared by the iterative methods: when to stop
//! ([`Monitor`]) and the checked start of a Krylov cycle ([`restart`]).

use crate::config::Method;
use crate::solver::heartbeat::Beats;
use crate::solver::storage::{norm_sqr, Storage};
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, SolveError};
use ndarray::Array3;

/// A residual that is not finite or grows a thousandfold above its best is
/// divergence, one at tolerance is convergence, and a spent iteration budget
/// is a loud failure.
pub struct Monitor {
    method: Method,
    best: f64,
    beats: Beats,
}

impl Monitor {
    pub fn new(method: Method) -> Self {
        Monitor {
            method,
            best: f64::INFINITY,
            beats: Beats::default(),
        }
    }

    /// A heartbeat from inside a Krylov cycle: the relative residual
    /// estimated from the preconditioned one (`heartbeat`).
    pub fn tick(&mut self, iterations: usize, estimate: f64) {
        self.beats.tick(self.method, iterations, estimate, true);
    }

    /// `Ok(true)`: converged; `Ok(false)`: go on; `Err`: stop with this error.
    pub fn check(
        &mut self,
        res: f64,
        iterations: usize,
        ctl: &Controls,
    ) -> Result<bool, SolveError> {
        let method = self.method;
        self.beats.tick(method, iterations, res, false);
        if !res.is_finite() || res > 1e3 * self.best.max(ctl.tolerance) {
            return Err(SolveError::Diverged {
                method,
                iterations,
                residual: res,
            });
        }
        self.best = self.best.min(res);
        if res <= ctl.tolerance {
            return Ok(true);
        }
        if iterations >= ctl.max_iterations {
            return Err(SolveError::NotConverged {
                method,
                iterations,
                residual: res,
                tolerance: ctl.tolerance,
            });
        }
        Ok(false)
    }
}

/// A Krylov (re)start: the true residual, checked, then preconditioned.
pub enum Restart {
    /// The true relative residual is at tolerance.
    Converged(f64),
    /// Go on from `r ← γ r'`: its norm, and the norm the preconditioned
    /// residual must reach for the true one to be at tolerance (with a
    /// safety factor 2).
    Go { norm: f64, target: f64 },
}

/// Shared start of a GMRES cycle or a BiCGStab run: `r ← γ (u_s + G_s V' u − u)`.
pub fn restart<S: Storage>(
    sys: &System,
    scr: &mut Scratch,
    u: &Array3<S>,
    r: &mut Array3<S>,
    monitor: &mut Monitor,
    iterations: usize,
    ctl: &Controls,
) -> Result<Restart, SolveError> {
    let res = sys.residual_shifted(scr, u, r);
    if monitor.check(res, iterations, ctl)? {
        return Ok(Restart::Converged(res));
    }
    sys.precondition(r);
    let norm = norm_sqr(r).sqrt();
    Ok(Restart::Go {
        norm,
        target: 0.5 * norm * ctl.tolerance / res,
    })
}
