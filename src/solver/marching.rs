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
//! [`shift`](super::shift) applies `G_s` exactly in O(N) per harmonic without
//! ever forming `G_b`, so guided-mode poles of the binder slab never enter.
//! We march `du/dτ = γ r'`, `r' = u_s + G_s V' u − u`,
//! `γ = 1 + i(ε − ε_r)/ε_s`, by explicit Euler; with `dτ = 1` this is the CBS
//! iteration, which converges for any contrast (the Galerkin `G_b` is the
//! projection of a passive operator, so `‖G_s‖ ≤ 1/(k0² ε_s)` holds as the
//! proof needs). The residual need not fall monotonically; a solve is
//! declared diverged only if it becomes non-finite or grows a thousandfold
//! above its best. Cost per step: one application of `G_s` between a forward
//! and an inverse 2-D FFT.

use super::{
    Controls, IterativeMethod, MethodUsed, Monitor, Outcome, SolveError, Storage, System, Validity,
};
use ndarray::{Array3, Zip};
use num_complex::Complex64 as C64;
/// Time-marching settings.
#[derive(Debug, Clone, Copy)]
pub struct TimeMarching {
    /// Pseudo-time step (1 is the CBS iteration).
    pub step: f64,
}

impl Default for TimeMarching {
    fn default() -> Self {
        TimeMarching { step: 1.0 }
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

impl<S: Storage> IterativeMethod<S> for TimeMarching {
    fn kind(&self) -> MethodUsed {
        MethodUsed::TimeMarching
    }

    fn validity(&self, _sys: &mut System) -> Validity {
        Validity::Always
    }

    fn run(
        &self,
        sys: &mut System,
        u: &mut Array3<S>,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        let (er, es) = (sys.shift.er, sys.shift.es);
        let mut r = Array3::<S>::default(u.dim());
        let step = self.step;
        let mut monitor = Monitor::new(MethodUsed::TimeMarching);
        for it in 0..=ctl.max_iterations {
            let res = sys.residual_shifted(u, &mut r);
            if monitor.check(res, it, ctl)? {
                let note = format!("ε_r = {er:.4}, ε_s = {es:.4}, dτ = {step}");
                return Ok(Outcome {
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
