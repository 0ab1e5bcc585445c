//! Pseudo-time marching to the steady state with the convergent-Born-series
//! preconditioner (Osnabrugge, Leedumrongwatthanakun & Vellekoop, J. Comput.
//! Phys. 322, 2016).
//!
//! We march `du/dτ = P r(u)` with `r = u_bg + G_b V u − u` (the residual of
//! the shared discrete equation) by explicit Euler. The preconditioner is the
//! CBS one: shift the background to `ε_r + iε_s` with `ε_s ≥ max|ε − ε_r|`
//! (inside the slab; the vacuum outside stays vacuum and is lossy for
//! outgoing waves), `γ = 1 + i(ε − ε_r)/ε_s`, and `P = γ G_s G_b⁻¹` with
//! `G_s = (G_b⁻¹ − c)⁻¹`, `c = k0²(ε_r + iε_s − ε_b)` the shifted operator *of
//! the same discrete* `G_b`, so `P = γ (I − c G_b)⁻¹`, applied exactly in
//! O(N) per harmonic by [`shift`](super::shift). With `dτ = 1` this is the CBS
//! iteration for our discrete equation, which converges for any contrast
//! (the discrete `G_b` is a Galerkin matrix of a passive operator, so `G_s`
//! keeps the bound `‖G_s‖ ≤ 1/(k0² ε_s)` the proof needs). The residual
//! need not fall monotonically; a solve is declared diverged only if it
//! becomes non-finite or grows a thousandfold above its best.
//! Cost per step: one operator application and one shifted solve, each
//! between a forward and an inverse 2-D FFT.

use super::shift::ShiftTable;
use super::{Controls, IterativeMethod, MethodUsed, Outcome, SolveError, System, Validity};
use ndarray::{Array3, Zip};
use num_complex::Complex64 as C64;

/// Time-marching settings.
#[derive(Debug, Clone, Copy)]
pub struct TimeMarching {
    /// ε_s = margin · max|ε − ε_r|.
    pub margin: f64,
    /// Pseudo-time step (1 is the CBS iteration).
    pub step: f64,
}

impl Default for TimeMarching {
    fn default() -> Self {
        TimeMarching {
            margin: 1.05,
            step: 1.0,
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

/// The CBS preconditioner `P x = γ (I − c G_b)⁻¹ x` of a system, shared by
/// time-marching and GMRES.
pub struct Cbs {
    pub er: f64,
    pub es: f64,
    table: ShiftTable,
}

impl Cbs {
    /// Shift for the permittivities of `sys`, with `ε_s = margin · radius`.
    pub fn new(sys: &System, margin: f64) -> Self {
        let lat = sys.op.lat;
        let (er, rad) = shift_of(sys.eps, sys.eps_binder);
        let es = (margin * rad).max(1e-9);
        let c = lat.k0 * lat.k0 * (C64::new(er, es) - sys.eps_binder);
        Cbs {
            er,
            es,
            table: ShiftTable::new(&lat, sys.eps_binder, c),
        }
    }

    /// `x ← P x` (one shifted solve between two FFT passes).
    pub fn apply(&self, sys: &mut System, x: &mut Array3<C64>) {
        sys.op.apply_shift_inverse(&self.table, x, &mut sys.ws);
        let (er, es) = (self.er, self.es);
        Zip::from(x).and(sys.eps).par_for_each(|x, e| {
            *x *= 1.0 + C64::i() * (e - er) / es;
        });
    }
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
        let cbs = Cbs::new(sys, self.margin);
        let (er, es) = (cbs.er, cbs.es);
        let mut r = Array3::zeros(u.dim());
        let step = self.step;
        let mut best = f64::INFINITY;
        for it in 0..=ctl.max_iterations {
            let res = sys.residual(u, &mut r);
            if !res.is_finite() || res > 1e3 * best.max(ctl.tolerance) {
                return Err(SolveError::Diverged {
                    method: MethodUsed::TimeMarching,
                    iterations: it,
                    residual: res,
                });
            }
            best = best.min(res);
            if res <= ctl.tolerance {
                let note = format!("ε_r = {er:.4}, ε_s = {es:.4}, dτ = {step}");
                return Ok(Outcome {
                    iterations: it,
                    applications: 2 * it + 1,
                    residual: res,
                    note,
                });
            }
            if it == ctl.max_iterations {
                return Err(SolveError::NotConverged {
                    method: MethodUsed::TimeMarching,
                    iterations: it,
                    residual: res,
                    tolerance: ctl.tolerance,
                });
            }
            cbs.apply(sys, &mut r);
            Zip::from(&mut *u)
                .and(&r)
                .par_for_each(|u, w| *u += step * w);
        }
        unreachable!("loop returns")
    }
}
