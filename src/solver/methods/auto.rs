//! `auto`: Born where its contraction estimate says it converges, then
//! BiCGStab, then time-marching (always convergent) as the last resort, on
//! one system and one field. On the mean background BiCGStab runs without a
//! preconditioner; where it stalls (high-contrast grains) it runs again on
//! the binder background with the CBS preconditioner before the march.
//! Each choice and failure is written into the note, and the record names
//! the method that produced the answer.

use super::{born, Outcome, Solver, Validity};
use crate::config::{Background, Method, Precision};
use crate::solver::storage::Field;
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, SolveError};

/// The automatic choice.
pub struct Auto;

impl Solver for Auto {
    fn method(&self) -> Method {
        Method::Auto
    }

    /// As BiCGStab, which it runs unless Born is chosen.
    fn bytes_per_voxel(&self, precision: Precision) -> f64 {
        Method::BiCgStab.solver().bytes_per_voxel(precision)
    }

    /// As BiCGStab.
    fn applications_per_iteration(&self) -> f64 {
        Method::BiCgStab.solver().applications_per_iteration()
    }

    fn run(
        &self,
        sys: &mut System,
        scr: &mut Scratch,
        u: &mut Field,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError> {
        let born = Method::Born.solver();
        // Each method with the background it switches to first (None: as built).
        let mut chain = vec![
            (Method::BiCgStab.solver(), None),
            (Method::TimeMarching.solver(), None),
        ];
        let mut notes = vec![];
        let mut spent = born::ESTIMATE_APPLICATIONS;
        if sys.background() == Background::Mean {
            // BiCGStab on the mean background needs about as many
            // applications as Born's estimate alone (docs/PERFORMANCE.md).
            notes.push("skipped Born: Krylov on the mean background".to_string());
            sys.release_binder();
            spent = 0;
            chain.insert(1, (Method::BiCgStab.solver(), Some(Background::Binder)));
        } else {
            match born.validity(sys, scr, u.precision()) {
                Validity::Unlikely(why) => {
                    notes.push(format!("skipped Born: {why}"));
                    sys.release_binder();
                }
                Validity::Likely(why) => {
                    notes.push(format!("chose Born: {why}"));
                    chain.insert(0, (born, None));
                }
                Validity::Always => {
                    chain.insert(0, (born, None));
                }
            }
        }
        let mut last_err = None;
        for (i, (m, background)) in chain.into_iter().enumerate() {
            if let Some(bg) = background {
                sys.use_background(bg);
                notes.push(format!(
                    "{} again, {}",
                    m.method(),
                    sys.describe_background()
                ));
            }
            // The first method starts from the field it was given (the
            // start field, or an earlier answer); after a failure, afresh.
            if i > 0 {
                sys.set_start_field(u);
            }
            match m.run(sys, scr, u, ctl) {
                Ok(mut o) => {
                    o.applications += spent;
                    notes.push(o.note);
                    o.note = format!("auto: {}", notes.join("; "));
                    return Ok(o);
                }
                Err(e) => {
                    spent += e.applications();
                    notes.push(format!("{e}; falling back"));
                    last_err = Some(e);
                }
            }
        }
        Err(last_err.expect("at least one method ran"))
    }
}
