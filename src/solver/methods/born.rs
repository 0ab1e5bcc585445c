//! The Born series `u_{j+1} = u_bg + G V u_j`.
//!
//! Cheapest per step (one operator application) but converges only when the
//! spectral radius of `G V` is below one (weak scattering). Divergence is
//! detected from residual growth and reported as an error, never returned as
//! a result. [`Solver::validity`] estimates the contraction from a few steps
//! of the series itself and from a few steps of the power iteration of
//! `G V` on a pseudo-random field: the series from the background field can
//! contract at first and diverge later, when the mode that grows starts
//! small in it (Maxwell's E_z in a low-index layer, lit in p, did).

use super::{run_in_field_storage, Outcome, Solver, Validity};
use crate::config::{Method, Precision};
use crate::solver::heartbeat::Beats;
use crate::solver::storage::{norm_sqr, with_storage, Storage};
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, SolveError};
use ndarray::{Array3, Zip};
use rand::{Rng, SeedableRng};
use rand_xoshiro::SplitMix64;

/// Steps spent on the a-priori contraction estimate from the background
/// field.
pub const ESTIMATE_STEPS: usize = 4;
/// Steps of the power iteration on a pseudo-random field beside it.
pub const POWER_STEPS: usize = 6;
/// Seed of the power iteration's start field.
const POWER_SEED: u64 = 0x0B0E_5EED;
/// Operator applications of the whole estimate.
pub const ESTIMATE_APPLICATIONS: usize = ESTIMATE_STEPS + POWER_STEPS;
/// Estimated contraction above which Born is not attempted by `auto`.
pub const MAX_CONTRACTION: f64 = 0.8;

/// The Born series.
pub struct Born;

impl Solver for Born {
    fn method(&self) -> Method {
        Method::Born
    }

    /// Counted as time-marching (the same fields).
    fn bytes_per_voxel(&self, precision: Precision) -> f64 {
        Method::TimeMarching.solver().bytes_per_voxel(precision)
    }

    fn applications_per_iteration(&self) -> f64 {
        1.0
    }

    fn validity(&self, sys: &mut System, scr: &mut Scratch, precision: Precision) -> Validity {
        with_storage!(precision, S => self.estimate::<S>(sys, scr))
    }

    run_in_field_storage!();
}

impl Born {
    /// The contraction estimate behind [`Solver::validity`], with fields
    /// stored as `S`.
    fn estimate<S: Storage>(&self, sys: &mut System, scr: &mut Scratch) -> Validity {
        let dim = sys.unknown_dim();
        let (mut u, mut r) = (Array3::<S>::default(dim), Array3::<S>::default(dim));
        sys.set_background(&mut u);
        let mut prev = f64::NAN;
        let mut ratio = 0.0;
        for _ in 0..ESTIMATE_STEPS {
            let res = sys.residual(scr, &u, &mut r);
            if res == 0.0 {
                return Validity::Likely("no scatterers (Δε = 0)".into());
            }
            if prev.is_finite() {
                ratio = res / prev;
            }
            prev = res;
            Zip::from(&mut u)
                .and(&r)
                .par_for_each(|u, r| *u = S::store(u.load() + r.load()));
        }
        let ratio = ratio.max(self.power_ratio::<S>(sys, scr));
        if ratio.is_finite() && ratio < MAX_CONTRACTION {
            Validity::Likely(format!(
                "Born contraction estimate {ratio:.3} < {MAX_CONTRACTION}"
            ))
        } else {
            Validity::Unlikely(format!(
                "Born contraction estimate {ratio:.3} ≥ {MAX_CONTRACTION}"
            ))
        }
    }

    /// `‖G V d‖ / ‖d‖` after [`POWER_STEPS`] steps of `d ← G V d / ‖G V d‖`
    /// from a pseudo-random field (filled in order from a fixed seed: the
    /// same for any thread count), a lower estimate of the spectral radius that
    /// every mode enters from the start.
    fn power_ratio<S: Storage>(&self, sys: &mut System, scr: &mut Scratch) -> f64 {
        let dim = sys.unknown_dim();
        let mut d = Array3::<S>::default(dim);
        let mut out = Array3::<S>::default(dim);
        let mut ubg = Array3::<S>::default(dim);
        sys.set_background(&mut ubg);
        let mut rng = SplitMix64::seed_from_u64(POWER_SEED);
        for v in d.iter_mut() {
            let (re, im): (f64, f64) = (rng.gen(), rng.gen());
            *v = S::store(num_complex::Complex64::new(re - 0.5, im - 0.5));
        }
        let mut ratio = f64::NAN;
        for _ in 0..POWER_STEPS {
            let before = norm_sqr(&d).sqrt();
            if before == 0.0 || !before.is_finite() {
                return ratio;
            }
            // residual(d) = u_bg + G V d − d, so G V d = it + d − u_bg.
            sys.residual(scr, &d, &mut out);
            Zip::from(&mut out)
                .and(&d)
                .and(&ubg)
                .par_for_each(|o, d, b| *o = S::store(o.load() + d.load() - b.load()));
            let after = norm_sqr(&out).sqrt();
            ratio = after / before;
            let scale = if after > 0.0 { 1.0 / after } else { 0.0 };
            Zip::from(&mut d)
                .and(&out)
                .par_for_each(|d, o| *d = S::store(o.load() * scale));
        }
        ratio
    }

    fn iterate<S: Storage>(
        &self,
        sys: &mut System,
        scr: &mut Scratch,
        u: &mut Array3<S>,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        let mut r = Array3::<S>::default(u.dim());
        let mut best = f64::INFINITY;
        let mut growing = 0;
        let mut beats = Beats::default();
        for it in 0..=ctl.max_iterations {
            let res = sys.residual(scr, u, &mut r);
            beats.tick(Method::Born, it, res, false);
            if res <= ctl.tolerance {
                return Ok(Outcome {
                    method: Method::Born,
                    iterations: it,
                    applications: it + 1,
                    residual: res,
                    note: String::new(),
                });
            }
            let diverged = !res.is_finite() || res > 1e3 * best.min(1.0) || growing >= 5;
            if diverged {
                return Err(SolveError::Diverged {
                    method: Method::Born,
                    iterations: it,
                    residual: res,
                });
            }
            growing = if res > best { growing + 1 } else { 0 };
            best = best.min(res);
            if it == ctl.max_iterations {
                return Err(SolveError::NotConverged {
                    method: Method::Born,
                    iterations: it,
                    residual: res,
                    tolerance: ctl.tolerance,
                });
            }
            Zip::from(&mut *u)
                .and(&r)
                .par_for_each(|u, r| *u = S::store(u.load() + r.load()));
        }
        unreachable!("loop returns")
    }
}
