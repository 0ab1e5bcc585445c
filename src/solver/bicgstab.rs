//! BiCGStab on the CBS-preconditioned shifted equation
//! `γ (I − G_s V') u = γ u_s` (the same operator as [`gmres`](super::gmres)).
//! Fixed memory (seven fields), two applications of `G_s` per iteration, no
//! restarts: on
//! low-loss layers, whose slab resonances make restarted GMRES forget what it
//! learned, it needs far fewer applications. Breakdowns (⟨r̂, v⟩ ≈ 0) restart
//! from the current iterate; convergence is confirmed on the true residual.

use super::storage::norm_sqr;
use super::{
    dot, Controls, IterativeMethod, MethodUsed, Monitor, Outcome, Restart, SolveError, Storage,
    System, Validity,
};
use ndarray::{Array3, Zip};
use num_complex::Complex64 as C64;

/// BiCGStab settings.
#[derive(Debug, Clone, Copy, Default)]
pub struct BiCgStab {}

impl BiCgStab {
    /// `out ← P A x`.
    fn op<S: Storage>(sys: &mut System, x: &Array3<S>, out: &mut Array3<S>) {
        sys.apply_a_shifted(x, out);
        sys.precondition(out);
    }
}

impl<S: Storage> IterativeMethod<S> for BiCgStab {
    fn kind(&self) -> MethodUsed {
        MethodUsed::BiCgStab
    }

    fn validity(&self, _sys: &mut System) -> Validity {
        Validity::Likely(
            "preconditioned BiCGStab; breakdowns restart, time-marching backs it up".into(),
        )
    }

    fn run(
        &self,
        sys: &mut System,
        u: &mut Array3<S>,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        let dim = u.dim();
        let z = || Array3::<S>::default(dim);
        let (mut r, mut rh, mut p, mut v, mut s, mut t) = (z(), z(), z(), z(), z(), z());
        let mut iterations = 0;
        let mut applications = 0;
        let mut monitor = Monitor::new(MethodUsed::BiCgStab);
        let one = C64::new(1.0, 0.0);
        loop {
            applications += 1;
            let (r0, target) = match sys.restart(u, &mut r, &mut monitor, iterations, ctl)? {
                Restart::Converged(residual) => {
                    let note = format!(
                        "BiCGStab, ε_r = {:.4}, ε_s = {:.4}",
                        sys.shift.er, sys.shift.es
                    );
                    return Ok(Outcome {
                        iterations,
                        applications,
                        residual,
                        note,
                    });
                }
                Restart::Go { norm, target } => (norm, target),
            };
            rh.assign(&r);
            p.fill(S::default());
            v.fill(S::default());
            let (mut rho, mut alpha, mut omega) = (one, one, one);
            while iterations < ctl.max_iterations {
                iterations += 1;
                let rho_new = dot(&rh, &r);
                if rho_new.norm() < 1e-30 * r0 * r0 {
                    break; // breakdown: restart
                }
                let beta = (rho_new / rho) * (alpha / omega);
                rho = rho_new;
                Zip::from(&mut p).and(&r).and(&v).par_for_each(|p, r, v| {
                    *p = S::store(r.load() + beta * (p.load() - omega * v.load()))
                });
                Self::op(sys, &p, &mut v);
                let rv = dot(&rh, &v);
                if rv.norm() < 1e-30 * r0 * r0 {
                    break;
                }
                alpha = rho / rv;
                Zip::from(&mut s)
                    .and(&r)
                    .and(&v)
                    .par_for_each(|s, r, v| *s = S::store(r.load() - alpha * v.load()));
                Self::op(sys, &s, &mut t);
                applications += 2;
                let tt = norm_sqr(&t);
                omega = if tt > 0.0 {
                    dot(&t, &s) / tt
                } else {
                    C64::new(0.0, 0.0)
                };
                Zip::from(&mut *u).and(&p).and(&s).par_for_each(|u, p, s| {
                    *u = S::store(u.load() + alpha * p.load() + omega * s.load())
                });
                Zip::from(&mut r)
                    .and(&s)
                    .and(&t)
                    .par_for_each(|r, s, t| *r = S::store(s.load() - omega * t.load()));
                let rn = norm_sqr(&r).sqrt();
                if !rn.is_finite() || rn <= target || omega.norm() == 0.0 {
                    break;
                }
            }
        }
    }
}
