//! Convergence bookkeeping shared by the iterative methods: when to stop
//! ([`Monitor`]) and the checked start of a Krylov cycle ([`restart`]).

use crate::config::Method;
use crate::solver::heartbeat::Beats;
use crate::solver::storage::{norm_sqr, Storage};
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, SolveError};
use ndarray::Array3;

/// Iterations a Krylov method may run without halving its best residual
/// before it is declared stalled. Unpreconditioned on the mean background,
/// BiCGStab and GMRES plateau for good on high-contrast layers (rutile in
/// binder: BiCGStab at 0.11 from iteration ~170 to the 5000th), while the
/// same methods with the CBS preconditioner halve theirs every ~120
/// iterations on the same layer (docs/PERFORMANCE.md, "High contrast").
pub const STALL_ITERATIONS: usize = 500;

/// A residual that is not finite or grows a thousandfold above its best is
/// divergence, one at tolerance is convergence, a Krylov residual that has
/// not halved in [`STALL_ITERATIONS`] is a stall, and a spent iteration
/// budget is a loud failure.
pub struct Monitor {
    method: Method,
    best: f64,
    beats: Beats,
    /// The Krylov methods' progress: the best residual (true or
    /// estimated) and the iteration it was last halved at.
    stall: Option<(f64, usize)>,
}

impl Monitor {
    /// For a method that is never declared stalled (the CBS march, Born).
    pub fn new(method: Method) -> Self {
        Monitor {
            method,
            best: f64::INFINITY,
            beats: Beats::default(),
            stall: None,
        }
    }

    /// For a Krylov method: stalls are detected.
    pub fn krylov(method: Method) -> Self {
        Monitor {
            stall: Some((f64::INFINITY, 0)),
            ..Monitor::new(method)
        }
    }

    /// A heartbeat from inside a Krylov cycle: the relative residual
    /// estimated from the preconditioned one (`heartbeat`), checked for a
    /// stall.
    pub fn tick(&mut self, iterations: usize, estimate: f64) -> Result<(), SolveError> {
        self.beats.tick(self.method, iterations, estimate, true);
        self.progress(iterations, estimate)
    }

    /// `Err(Stalled)` once the residual has gone [`STALL_ITERATIONS`]
    /// without halving its best.
    fn progress(&mut self, iterations: usize, res: f64) -> Result<(), SolveError> {
        let Some((best, since)) = &mut self.stall else {
            return Ok(());
        };
        if res < 0.5 * *best {
            (*best, *since) = (res, iterations);
        } else if iterations >= *since + STALL_ITERATIONS {
            return Err(SolveError::Stalled {
                method: self.method,
                iterations,
                residual: best.min(res),
                window: STALL_ITERATIONS,
            });
        }
        Ok(())
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
        self.progress(iterations, res)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A plateau is a stall one window after its last halving; a residual
    /// that halves every 0.9 windows, however slowly per iteration, is not.
    #[test]
    fn stalls_are_plateaus_not_slow_progress() {
        let mut m = Monitor::krylov(Method::BiCgStab);
        let first = (0..10 * STALL_ITERATIONS).find(|&it| {
            m.tick(
                it,
                if it < 100 {
                    1.0 / (it + 1) as f64
                } else {
                    0.01
                },
            )
            .is_err()
        });
        // Halvings at 0, 2, 6, 14, 30 and 62 (1/63 < half of 1/31); none on the plateau.
        assert_eq!(first, Some(62 + STALL_ITERATIONS), "{first:?}");
        let mut m = Monitor::krylov(Method::Gmres);
        let rate = 0.5f64.powf(1.0 / (0.9 * STALL_ITERATIONS as f64));
        assert!((0..10 * STALL_ITERATIONS).all(|it| m.tick(it, rate.powi(it as i32)).is_ok()));
        let mut m = Monitor::new(Method::TimeMarching);
        assert!((0..10 * STALL_ITERATIONS).all(|it| m.tick(it, 1.0).is_ok()));
    }
}
