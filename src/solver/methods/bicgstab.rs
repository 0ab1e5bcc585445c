//! BiCGStab on the CBS-preconditioned shifted equation
//! `γ (I − G_s V') u = γ u_s` (the same operator as [`gmres`](super::gmres)).
//! Fixed memory (seven fields), two applications of `G_s` per iteration, no
//! restarts: on
//! low-loss layers, whose slab resonances make restarted GMRES forget what it
//! learned, it needs far fewer applications. Breakdowns (⟨r̂, v⟩ ≈ 0) restart
//! from the current iterate; convergence is confirmed on the true residual.

use super::{restart, run_in_field_storage, Monitor, Outcome, Restart, Solver, Validity};
use crate::config::{Method, Precision};
use crate::solver::storage::{dot, norm_sqr, Storage};
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, SolveError};
use ndarray::{Array3, Zip};
use num_complex::Complex64 as C64;
use rayon::prelude::*;

/// BiCGStab settings.
#[derive(Debug, Clone, Copy)]
pub struct BiCgStab {
    pub shadow: Shadow,
}

/// The shadow vector r̂ of the bi-orthogonality conditions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shadow {
    /// The first (preconditioned) residual of each restart.
    Residual,
    /// A fixed pseudo-random vector (seeded, so every run gives the same
    /// bits), drawn once per solve.
    Random,
}

impl BiCgStab {
    pub const DEFAULT: BiCgStab = BiCgStab {
        shadow: Shadow::Random,
    };
}

impl Solver for BiCgStab {
    fn method(&self) -> Method {
        Method::BiCgStab
    }

    fn bytes_per_voxel(&self, precision: Precision) -> f64 {
        precision.select(165.0, 109.0)
    }

    fn applications_per_iteration(&self) -> f64 {
        2.0
    }

    fn validity(&self, _sys: &mut System, _scr: &mut Scratch, _precision: Precision) -> Validity {
        Validity::Likely(
            "preconditioned BiCGStab; breakdowns restart, time-marching backs it up".into(),
        )
    }

    run_in_field_storage!();
}

impl BiCgStab {
    fn iterate<S: Storage>(
        &self,
        sys: &System,
        scr: &mut Scratch,
        u: &mut Array3<S>,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        let dim = u.dim();
        let z = || Array3::<S>::default(dim);
        let (mut r, mut rh, mut p, mut v, mut s, mut t) = (z(), z(), z(), z(), z(), z());
        let mut iterations = 0;
        let mut applications = 0;
        let mut monitor = Monitor::krylov(Method::BiCgStab);
        let one = C64::new(1.0, 0.0);
        loop {
            applications += 1;
            let (r0, target) = match restart(sys, scr, u, &mut r, &mut monitor, iterations, ctl)? {
                Restart::Converged(residual) => {
                    let note = format!("BiCGStab, {}", sys.describe_background());
                    return Ok(Outcome {
                        method: Method::BiCgStab,
                        iterations,
                        applications,
                        residual,
                        note,
                    });
                }
                Restart::Go { norm, target } => (norm, target),
            };
            match self.shadow {
                Shadow::Residual => rh.assign(&r),
                Shadow::Random if iterations == 0 => fill_random(&mut rh, r0),
                Shadow::Random => {}
            }
            p.fill(S::default());
            v.fill(S::default());
            let (mut rho, mut alpha, mut omega) = (one, one, one);
            // ⟨r̂, r⟩ of the current residual; later iterations take it from
            // the residual's update pass.
            let mut rho_new = dot(&rh, &r);
            while iterations < ctl.max_iterations {
                iterations += 1;
                if rho_new.norm() < 1e-30 * r0 * r0 {
                    break; // breakdown: restart
                }
                let beta = (rho_new / rho) * (alpha / omega);
                rho = rho_new;
                Zip::from(&mut p).and(&r).and(&v).par_for_each(|p, r, v| {
                    *p = S::store(r.load() + beta * (p.load() - omega * v.load()))
                });
                // v = P A p with ⟨v, r̂⟩ in the same pass.
                let rv = sys.apply_pa_sums(scr, &p, &mut v, &rh).1.conj();
                if rv.norm() < 1e-30 * r0 * r0 {
                    break;
                }
                alpha = rho / rv;
                Zip::from(&mut s)
                    .and(&r)
                    .and(&v)
                    .par_for_each(|s, r, v| *s = S::store(r.load() - alpha * v.load()));
                // t = P A s with ‖t‖² and ⟨t, s⟩ in the same pass.
                let (tt, ts) = sys.apply_pa_sums(scr, &s, &mut t, &s);
                applications += 2;
                omega = if tt > 0.0 {
                    ts / tt
                } else {
                    C64::new(0.0, 0.0)
                };
                let (rr, rhr) = update(u, &mut r, [&p, &s, &t, &rh], alpha, omega);
                rho_new = rhr;
                let rn = rr.sqrt();
                // The true residual scales with the preconditioned one
                // from the restart, where `target` is half of tolerance's.
                monitor.tick(iterations, 0.5 * ctl.tolerance * rn / target)?;
                if !rn.is_finite() || rn <= target || omega.norm() == 0.0 {
                    break;
                }
            }
        }
    }
}

/// The iteration's closing updates in one pass over the fields:
/// `u ← u + α p + ω s`, `r ← s − ω t`, returning `(‖r‖², ⟨r̂, r⟩)` of the
/// stored `r` (summed per z-slice, then in a fixed order). Separately they
/// were two updates and two reductions, each a pass over memory.
fn update<S: Storage>(
    u: &mut Array3<S>,
    r: &mut Array3<S>,
    [p, s, t, rh]: [&Array3<S>; 4],
    alpha: C64,
    omega: C64,
) -> (f64, C64) {
    let zero = C64::new(0.0, 0.0);
    let parts: Vec<(f64, C64)> = u
        .outer_iter_mut()
        .into_par_iter()
        .zip(r.outer_iter_mut())
        .zip(p.outer_iter())
        .zip(s.outer_iter())
        .zip(t.outer_iter())
        .zip(rh.outer_iter())
        .map(|(((((mut u, mut r), p), s), t), rh)| {
            let (mut rr, mut d) = (0.0, zero);
            Zip::from(&mut u)
                .and(&mut r)
                .and(&p)
                .and(&s)
                .and(&t)
                .and(&rh)
                .for_each(|u, r, p, s, t, rh| {
                    let sv = s.load();
                    *u = S::store(u.load() + alpha * p.load() + omega * sv);
                    *r = S::store(sv - omega * t.load());
                    let rv = r.load();
                    rr += rv.norm_sqr();
                    d += rh.load().conj() * rv;
                });
            (rr, d)
        })
        .collect();
    parts
        .iter()
        .fold((0.0, zero), |(a, b), &(rr, d)| (a + rr, b + d))
}

/// Complex entries uniform in a square, from a fixed seed, scaled to norm
/// `norm` (so the breakdown tests see the scale of a residual).
fn fill_random<S: Storage>(x: &mut Array3<S>, norm: f64) {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(0x5eed);
    for v in x.iter_mut() {
        *v = S::store(C64::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0)));
    }
    let scale = norm / norm_sqr(x).sqrt();
    x.mapv_inplace(|v| S::store(v.load() * scale));
}
