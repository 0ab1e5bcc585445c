//! A solve's heartbeat: while an iterative solve runs, it reports its
//! iteration, residual and elapsed time at most once per interval, so a
//! solve that takes minutes is not silent.
//!
//! The caller (the pipeline, which knows how to show it) runs a solve inside
//! [`scope`] with a reporting function; the methods call [`Beats::tick`]
//! (through their `Monitor`) and never know who listens. The reporter is
//! held per thread for the duration of the scope: a solve's iterations run
//! on the thread that called it (its inner loops fan out to rayon and come
//! back), and a solve stolen onto this thread by rayon while it waits runs in
//! its own nested scope.

use std::cell::Cell;
use std::time::{Duration, Instant};

use crate::config::Method;

/// Least time between two beats of one solve (and before the first).
pub const INTERVAL: Duration = Duration::from_secs(10);

/// One report of a running solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beat {
    pub method: Method,
    /// Iterations (operator applications for the Krylov methods' inner
    /// steps) so far.
    pub iterations: usize,
    /// The relative residual: exact at a (re)start or a time step,
    /// `estimated` inside a Krylov cycle (from the preconditioned residual).
    pub residual: f64,
    pub estimated: bool,
    pub elapsed_s: f64,
}

type Reporter = *const (dyn Fn(Beat) + 'static);

thread_local! {
    static CURRENT: Cell<Option<(Reporter, Duration)>> = const { Cell::new(None) };
}

/// Run `body` with `report` receiving the beats of the solves it runs on
/// this thread, at most one per `interval` per solve.
pub fn scope<R>(interval: Duration, report: &dyn Fn(Beat), body: impl FnOnce() -> R) -> R {
    let ptr: *const (dyn Fn(Beat) + '_) = report;
    // SAFETY: only the lifetime is erased. The pointer is stored for the
    // duration of `body` and removed by `Restore` when it returns or
    // unwinds; `report` outlives that, since it is borrowed for this call.
    let ptr: Reporter = unsafe { std::mem::transmute(ptr) };
    struct Restore(Option<(Reporter, Duration)>);
    impl Drop for Restore {
        fn drop(&mut self) {
            CURRENT.with(|c| c.set(self.0));
        }
    }
    let _restore = Restore(CURRENT.with(|c| c.replace(Some((ptr, interval)))));
    body()
}

/// The heartbeat of one solve (owned by its monitor).
pub struct Beats {
    start: Instant,
    last: Instant,
}

impl Default for Beats {
    fn default() -> Self {
        let now = Instant::now();
        Beats {
            start: now,
            last: now,
        }
    }
}

impl Beats {
    /// Report where the solve stands, if a reporter listens on this thread
    /// and its interval has passed since the last beat.
    pub fn tick(&mut self, method: Method, iterations: usize, residual: f64, estimated: bool) {
        let Some((report, interval)) = CURRENT.with(Cell::get) else {
            return;
        };
        let now = Instant::now();
        if now.duration_since(self.last) < interval {
            return;
        }
        self.last = now;
        let beat = Beat {
            method,
            iterations,
            residual,
            estimated,
            elapsed_s: now.duration_since(self.start).as_secs_f64(),
        };
        // SAFETY: set by `scope`, whose `report` is alive while the pointer
        // is stored (see there).
        unsafe { (*report)(beat) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    #[test]
    fn beats_reach_the_innermost_scope_and_none_outside() {
        let outer = RefCell::new(Vec::new());
        let inner = RefCell::new(Vec::new());
        let mut b = Beats::default();
        b.tick(Method::Born, 1, 0.5, false); // nobody listens
        scope(Duration::ZERO, &|x| outer.borrow_mut().push(x), || {
            b.tick(Method::Born, 2, 0.25, false);
            scope(Duration::ZERO, &|x| inner.borrow_mut().push(x), || {
                b.tick(Method::Gmres, 3, 0.125, true);
            });
            b.tick(Method::Born, 4, 0.0625, false);
            // A long interval holds beats back.
            scope(
                Duration::from_secs(3600),
                &|x| inner.borrow_mut().push(x),
                || {
                    b.tick(Method::Born, 5, 0.01, false);
                },
            );
        });
        b.tick(Method::Born, 6, 0.001, false);
        let its =
            |v: &RefCell<Vec<Beat>>| v.borrow().iter().map(|b| b.iterations).collect::<Vec<_>>();
        assert_eq!(its(&outer), [2, 4]);
        assert_eq!(its(&inner), [3]);
        assert!(inner.borrow()[0].estimated && inner.borrow()[0].method == Method::Gmres);
    }

    #[test]
    fn a_panic_inside_a_scope_removes_its_reporter() {
        let seen = RefCell::new(0);
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            scope(Duration::ZERO, &|_| *seen.borrow_mut() += 1, || {
                panic!("in a solve")
            })
        }));
        assert!(r.is_err());
        assert!(CURRENT.with(Cell::get).is_none());
        Beats::default().tick(Method::Born, 1, 1.0, false);
        assert_eq!(*seen.borrow(), 0);
    }
}
