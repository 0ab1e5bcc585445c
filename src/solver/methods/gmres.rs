//! Restarted GMRES(m) on the CBS-preconditioned shifted equation
//! `γ (I − G_s V') u = γ u_s` (see [`marching`](super::marching): the same
//! discrete solution as `u = u_bg + G_b V u`, with `γ = 1 + i(ε − ε_r)/ε_s`).
//!
//! The CBS iteration matrix `I − P A` has norm below one, so the field of
//! values of `P A` excludes zero and restarted GMRES converges for any
//! contrast — and, by building the best combination of the same operator
//! applications instead of summing them, needs far fewer of them on hard
//! cases. Convergence is judged on the true relative residual
//! `‖u_s + G_s V' u − u‖ / ‖u_s‖`, evaluated at every restart. Inner products are
//! summed in a fixed order, so results do not depend on the thread count.

use super::{restart, run_in_field_storage, Monitor, Outcome, Restart, Solver};
use crate::config::{Method, Precision};
use crate::solver::storage::{dot, norm_sqr, Storage};
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, SolveError};
use ndarray::{Array3, Zip};
use num_complex::Complex64 as C64;

/// GMRES settings.
#[derive(Debug, Clone, Copy)]
pub struct Gmres {
    /// Krylov vectors per cycle (memory: restart + 2 fields).
    pub restart: usize,
}

impl Solver for Gmres {
    fn method(&self) -> Method {
        Method::Gmres
    }

    /// Measured for GMRES(20).
    fn bytes_per_voxel(&self, precision: Precision) -> f64 {
        precision.select(421.0, 237.0)
    }

    fn applications_per_iteration(&self) -> f64 {
        1.0
    }

    run_in_field_storage!();
}

impl Gmres {
    /// GMRES(20).
    pub const DEFAULT: Gmres = Gmres { restart: 20 };

    fn iterate<S: Storage>(
        &self,
        sys: &System,
        scr: &mut Scratch,
        u: &mut Array3<S>,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        let m = self.restart.max(1);
        let dim = u.dim();
        let mut basis: Vec<Array3<S>> = (0..=m).map(|_| Array3::default(dim)).collect();
        let mut r = Array3::<S>::default(dim);
        let mut h = vec![C64::new(0.0, 0.0); (m + 1) * m];
        let (mut cs, mut sn) = (vec![C64::new(0.0, 0.0); m], vec![C64::new(0.0, 0.0); m]);
        let mut g = vec![C64::new(0.0, 0.0); m + 1];
        let mut inner = 0;
        let mut applications = 0;
        let mut monitor = Monitor::krylov(Method::Gmres);
        loop {
            applications += 1;
            let (beta, target) = match restart(sys, scr, u, &mut r, &mut monitor, inner, ctl)? {
                Restart::Converged(residual) => {
                    let note = format!("GMRES({m}), {}", sys.describe_background());
                    return Ok(Outcome {
                        method: Method::Gmres,
                        iterations: inner,
                        applications,
                        residual,
                        note,
                    });
                }
                Restart::Go { norm, target } => (norm, target),
            };
            Zip::from(&mut basis[0])
                .and(&r)
                .par_for_each(|v, r| *v = S::store(r.load() / beta));
            g.fill(C64::new(0.0, 0.0));
            g[0] = C64::new(beta, 0.0);
            let mut k_used = 0;
            for k in 0..m {
                let (done, rest) = basis.split_at_mut(k + 1);
                let w = &mut rest[0];
                sys.apply_a_shifted(scr, &done[k], w);
                sys.precondition(w);
                applications += 1;
                inner += 1;
                for (i, vi) in done.iter().enumerate() {
                    let hik = dot(vi, w);
                    h[i * m + k] = hik;
                    Zip::from(&mut *w)
                        .and(vi)
                        .par_for_each(|w, v| *w = S::store(w.load() - hik * v.load()));
                }
                let hn = norm_sqr(w).sqrt();
                h[(k + 1) * m + k] = C64::new(hn, 0.0);
                if hn > 0.0 {
                    w.mapv_inplace(|x| S::store(x.load() / hn));
                }
                for i in 0..k {
                    let (a, b) = (h[i * m + k], h[(i + 1) * m + k]);
                    h[i * m + k] = cs[i].conj() * a + sn[i].conj() * b;
                    h[(i + 1) * m + k] = -sn[i] * a + cs[i] * b;
                }
                let (a, b) = (h[k * m + k], h[(k + 1) * m + k]);
                let nrm = (a.norm_sqr() + b.norm_sqr()).sqrt();
                let (c, s) = if nrm == 0.0 {
                    (C64::new(1.0, 0.0), C64::new(0.0, 0.0))
                } else {
                    (a / nrm, b / nrm)
                };
                cs[k] = c;
                sn[k] = s;
                h[k * m + k] = C64::new(nrm, 0.0);
                h[(k + 1) * m + k] = C64::new(0.0, 0.0);
                g[k + 1] = -s * g[k];
                g[k] = c.conj() * g[k];
                k_used = k + 1;
                // The true residual estimated as in the restart (`target`
                // is half of the tolerance's preconditioned norm).
                monitor.tick(inner, 0.5 * ctl.tolerance * g[k + 1].norm() / target)?;
                if g[k + 1].norm() <= target || hn == 0.0 || inner >= ctl.max_iterations {
                    break;
                }
            }
            // Back-substitute H y = g and update u.
            let mut y = vec![C64::new(0.0, 0.0); k_used];
            for i in (0..k_used).rev() {
                let mut s = g[i];
                for j in i + 1..k_used {
                    s -= h[i * m + j] * y[j];
                }
                y[i] = s / h[i * m + i];
            }
            for (i, yi) in y.iter().enumerate() {
                Zip::from(&mut *u)
                    .and(&basis[i])
                    .par_for_each(|u, v| *u = S::store(u.load() + yi * v.load()));
            }
        }
    }
}
