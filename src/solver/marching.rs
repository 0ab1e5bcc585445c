//! Pseudo-time marching to the steady state with the convergent-Born-series
//! preconditioner (Osnabrugge, Leedumrongwatthanakun & Vellekoop, J. Comput.
//! Phys. 322, 2016).
//!
//! We march `du/dτ = P r(u)` with `r = u_bg + G_b V u − u` (the residual of
//! the shared discrete equation) by explicit Euler. The preconditioner is the
//! CBS one: shift the background to `ε_r + iε_s` with
//! `ε_s ≥ max|ε − ε_r|` (inside the slab; the vacuum outside stays vacuum and
//! is lossy for outgoing waves), `γ = 1 + i(ε − ε_r)/ε_s`, and
//! `P = γ (1 + k0²(ε_r + iε_s − ε_b) G_s)`, which is `γ G_s G_b⁻¹` of the
//! continuous problem. With step `dτ = 1` this is the CBS iteration, which
//! converges for any contrast. Our discrete `G_b` is a Galerkin matrix, for
//! which the identity holds up to O(dz²), so the march keeps the equation's
//! solution exact (`r = 0` at the fixed point) and halves `dτ` if the residual
//! keeps growing — the safeguard that makes the argument hold discretely too.
//! Cost: two operator applications per step.

use super::operator::GreenTable;
use super::{Controls, IterativeMethod, MethodUsed, Outcome, SolveError, System, Validity};
use ndarray::{Array3, Zip};
use num_complex::Complex64 as C64;

/// Time-marching settings.
#[derive(Debug, Clone, Copy)]
pub struct TimeMarching {
    /// ε_s = margin · max|ε − ε_r|.
    pub margin: f64,
    /// Smallest pseudo-time step before giving up.
    pub min_step: f64,
    /// Consecutive residual increases that halve the step.
    pub patience: usize,
}

impl Default for TimeMarching {
    fn default() -> Self {
        TimeMarching {
            margin: 1.05,
            min_step: 1.0 / 64.0,
            patience: 30,
        }
    }
}

/// Real centre and radius of the permittivity values: (ε_r, max|ε − ε_r|).
pub fn shift_of(eps: &Array3<C64>, eps_binder: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (eps_binder, eps_binder);
    for e in eps.iter() {
        lo = lo.min(e.re);
        hi = hi.max(e.re);
    }
    let er = 0.5 * (lo + hi);
    let rad = eps
        .iter()
        .map(|e| (e - er).norm())
        .fold((eps_binder - er).abs(), f64::max);
    (er, rad)
}

impl IterativeMethod for TimeMarching {
    fn kind(&self) -> MethodUsed {
        MethodUsed::TimeMarching
    }

    fn validity(&self, _sys: &mut System) -> Validity {
        Validity::Always
    }

    fn run(
        &self,
        sys: &mut System,
        u: &mut Array3<C64>,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        let lat = sys.op.lat;
        let k2 = lat.k0 * lat.k0;
        let (er, rad) = shift_of(sys.eps, sys.eps_binder);
        let es = (self.margin * rad).max(1e-9);
        let shifted = GreenTable::new(&lat, C64::new(er, es));
        let c = k2 * (C64::new(er, es) - sys.eps_binder);
        let mut r = Array3::zeros(u.dim());
        let mut w = Array3::zeros(u.dim());
        let mut step = 1.0;
        let mut prev = f64::INFINITY;
        let mut growing = 0;
        let mut halvings = 0;
        let eps = sys.eps;
        for it in 0..=ctl.max_iterations {
            let res = sys.residual(u, &mut r);
            if !res.is_finite() {
                return Err(SolveError::Diverged {
                    method: MethodUsed::TimeMarching,
                    iterations: it,
                    residual: res,
                });
            }
            if res <= ctl.tolerance {
                let note = format!(
                    "ε_r = {er:.4}, ε_s = {es:.4}, final dτ = {step}, {halvings} step halvings"
                );
                return Ok(Outcome {
                    iterations: it,
                    applications: 2 * it + 1,
                    residual: res,
                    note,
                });
            }
            growing = if res > prev { growing + 1 } else { 0 };
            prev = res;
            if growing >= self.patience {
                step *= 0.5;
                halvings += 1;
                growing = 0;
                if step < self.min_step {
                    return Err(SolveError::Diverged {
                        method: MethodUsed::TimeMarching,
                        iterations: it,
                        residual: res,
                    });
                }
            }
            if it == ctl.max_iterations {
                return Err(SolveError::NotConverged {
                    method: MethodUsed::TimeMarching,
                    iterations: it,
                    residual: res,
                    tolerance: ctl.tolerance,
                });
            }
            w.assign(&r);
            sys.op.apply(&shifted, &mut w, &mut sys.ws);
            Zip::from(&mut *u)
                .and(&r)
                .and(&w)
                .and(eps)
                .par_for_each(|u, r, w, e| {
                    let gamma = 1.0 + C64::i() * (e - er) / es;
                    *u += step * gamma * (r + c * w);
                });
        }
        unreachable!("loop returns")
    }
}
