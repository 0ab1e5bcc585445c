//! `auto`: Born where its contraction estimate says it converges, then
//! BiCGStab, then time-marching (always convergent) as the last resort, on
//! one system and one field. On the mean background BiCGStab runs without a
//! preconditioner; where it stalls (high-contrast grains) it runs again on
//! the binder background with the CBS preconditioner before the march.
//! Each choice and failure is written into the note, and the record names
//! the method that produced the answer.

use super::{born, Outcome, Solver, Validity};
use crate::config::{Background, Method, Precision};
use crate::solver::storage::{on_field, Field};
use crate::solver::system::{Scratch, System};
use crate::solver::{Controls, SolveError};
use ndarray::Array3;

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
        let methods = chain.len();
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
            // start field, or an earlier answer); after a failure, from the
            // better of the failed method's field and the start field.
            if i > 0 {
                let (kept, residual) = better_start(sys, scr, u);
                spent += 2;
                if kept {
                    notes.push(format!("going on from its field (residual {residual:.1e})"));
                }
            }
            match m.run(sys, scr, u, ctl) {
                Ok(mut o) => {
                    o.applications += spent;
                    notes.push(o.note);
                    o.note = format!("auto: {}", notes.join("; "));
                    return Ok(o);
                }
                Err(e) if i + 1 < methods => {
                    spent += e.applications();
                    notes.push(format!("{e}; falling back"));
                }
                Err(e) => {
                    return Err(SolveError::Exhausted {
                        tried: notes.join("; "),
                        applications: spent + e.applications(),
                        last: Box::new(e),
                    })
                }
            }
        }
        unreachable!("the chain ends in time-marching, which returns")
    }
}

/// After a failed method, the field the next one starts from: `u` (the
/// failed method's last iterate) where its true residual, on the next
/// method's background, is below the start field's, else the start field.
/// A Krylov method that stalls near the tolerance (rutile at 5 % in
/// binder: BiCGStab on the mean background plateaus at 1.1e-3 against a
/// tolerance of 1e-3) thus hands the next one its progress instead of a
/// solve from scratch. A field that is not finite is never kept. Returns
/// whether `u` was kept and the residual the next method starts from; costs
/// two operator applications and one field of scratch.
fn better_start(sys: &System, scr: &mut Scratch, u: &mut Field) -> (bool, f64) {
    on_field!(u, x => {
        let mut out = Array3::default(x.dim());
        let current = sys.residual_shifted(scr, x, &mut out);
        let mut start = x.clone();
        sys.fill_start(&mut start);
        let fresh = sys.residual_shifted(scr, &start, &mut out);
        if current.is_finite() && current < fresh {
            (true, current)
        } else {
            x.assign(&start);
            (false, fresh)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::{Problem, Wave};
    use num_complex::Complex64 as C64;

    fn field_of(u: &Field) -> Array3<C64> {
        match u {
            Field::F64(x) => x.clone(),
            Field::F32(_) => unreachable!("f64 here"),
        }
    }

    /// After a failure the next method goes on from the failed one's field
    /// where it is nearer the answer than the start field, and starts
    /// afresh from a field further away or not finite.
    fn grains() -> Array3<C64> {
        Array3::from_shape_fn((6, 4, 4), |(k, j, i)| {
            if (i + j + k) % 3 == 0 {
                C64::new(3.0, 0.1)
            } else {
                C64::new(2.25, 0.0)
            }
        })
    }

    fn lattice() -> crate::solver::Lattice {
        Problem::lattice([4, 4, 6], [400.0, 400.0, 300.0], 500.0, 20.0, 0.0)
    }

    /// When every method fails, the error says what each reached, in
    /// order, and counts every attempt's applications.
    #[test]
    fn an_exhausted_auto_says_what_it_tried() {
        let eps = grains();
        let p = Problem {
            tensor: None,
            lattice: lattice(),
            eps: &eps,
            eps_binder: 2.25,
            wave: Wave::Scalar,
        };
        let ctl = Controls {
            tolerance: 1e-12,
            max_iterations: 3,
            precision: Precision::F64,
            background: Background::Mean,
        };
        let Err(e) = crate::solver::solve(&p, Method::Auto, &ctl) else {
            panic!("3 iterations cannot reach 1e-12");
        };
        let SolveError::Exhausted {
            tried,
            applications,
            last,
        } = &e
        else {
            panic!("expected an exhausted auto, got {e}");
        };
        assert_eq!(tried.matches("falling back").count(), 2, "{tried}");
        assert!(tried.contains("bicgstab again"), "{tried}");
        assert!(
            matches!(
                **last,
                SolveError::NotConverged {
                    method: Method::TimeMarching,
                    ..
                }
            ),
            "{last}"
        );
        assert!(*applications > last.applications() + 12, "{applications}");
        assert!(e.to_string().starts_with("auto: "), "{e}");
    }

    #[test]
    fn a_fallback_goes_on_from_the_better_field() {
        let lat = lattice();
        let eps = grains();
        let p = Problem {
            tensor: None,
            lattice: lat,
            eps: &eps,
            eps_binder: 2.25,
            wave: Wave::Scalar,
        };
        let ctl = Controls {
            tolerance: 1e-10,
            max_iterations: 2000,
            precision: Precision::F64,
            background: Background::Mean,
        };
        let mut sys = System::new(&p, Background::Mean).unwrap();
        let mut scr = sys.scratch();
        let mut start = Field::zeros(Precision::F64, sys.unknown_dim());
        sys.set_start_field(&mut start);
        let mut u = Field::F64(field_of(&start));
        Method::BiCgStab
            .solver()
            .run(&mut sys, &mut scr, &mut u, &ctl)
            .unwrap();
        let answer = field_of(&u);
        let (kept, residual) = better_start(&sys, &mut scr, &mut u);
        assert!(kept && residual < 1e-9, "{kept} {residual}");
        assert_eq!(field_of(&u), answer);
        for far in [C64::new(100.0, 0.0), C64::new(f64::NAN, 0.0)] {
            let mut u = Field::F64(answer.mapv(|v| v * far));
            let (kept, residual) = better_start(&sys, &mut scr, &mut u);
            assert!(
                !kept && residual.is_finite() && residual > 1e-3,
                "{far}: {residual}"
            );
            assert_eq!(field_of(&u), field_of(&start));
        }
    }
}
