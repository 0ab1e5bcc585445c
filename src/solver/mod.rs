//! Stage 3 — the diffraction problem (METHOD §4).
//!
//! The layer's permittivity is split into the plain binder slab and the grains:
//! `ε = ε_b + Δε`. The scattered field solves `u = u_bg + G_bg [k0² Δε u]`
//! with the exact slab Green's operator ([`operator`], [`green`]): outgoing
//! plane waves above and below are built in, so no absorbing layers and no
//! padding are needed.
//!
//! Every method implements [`IterativeMethod`] and works on the same
//! [`System`] (the discrete equation above). The discrete equation is fixed;
//! methods differ only in how they reach its solution, so they agree to
//! solver tolerance and every solve can be checked by its energy balance.
//!
//! * [`born::Born`]: `u ← u_bg + G V u`; stops and reports divergence.
//! * [`marching::TimeMarching`]: pseudo-time marching `u ← u + dτ P r` with the
//!   convergent-Born-series preconditioner of Osnabrugge et al. (2016).

pub mod airy;
pub mod bicgstab;
pub mod born;
pub mod fft;
pub mod gmres;
pub mod green;
pub mod lattice;
pub mod marching;
pub mod operator;
pub mod shift;
pub mod simd;
pub mod storage;

use crate::config::{Method, Precision};
pub use lattice::Lattice;
use ndarray::{Array2, Array3, Zip};
use num_complex::{Complex32 as C32, Complex64 as C64};
use operator::{GreenTable, Operator, Workspace};
use shift::{BandScratch, ShiftTable};
use std::fmt;
use std::time::Instant;
pub use storage::{dot, Storage};
use storage::{norm_sqr, sum_slices};

/// Which method produced a solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodUsed {
    Born,
    TimeMarching,
    Gmres,
    BiCgStab,
    /// Closed-form homogeneous slab ([`airy`]): no grains, no iteration.
    Airy,
}

impl MethodUsed {
    pub const ALL: [MethodUsed; 5] = [
        MethodUsed::Born,
        MethodUsed::TimeMarching,
        MethodUsed::Gmres,
        MethodUsed::BiCgStab,
        MethodUsed::Airy,
    ];
}

impl std::str::FromStr for MethodUsed {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        MethodUsed::ALL
            .into_iter()
            .find(|m| m.to_string() == s)
            .ok_or_else(|| {
                let names: Vec<String> = MethodUsed::ALL.iter().map(|m| m.to_string()).collect();
                format!("`{s}` is not one of {}", names.join(", "))
            })
    }
}

impl fmt::Display for MethodUsed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MethodUsed::Born => "born",
            MethodUsed::TimeMarching => "time-marching",
            MethodUsed::Gmres => "gmres",
            MethodUsed::BiCgStab => "bicgstab",
            MethodUsed::Airy => "airy",
        })
    }
}

/// What every solve records, stored beside its result.
#[derive(Debug, Clone)]
pub struct SolveRecord {
    pub method: MethodUsed,
    pub iterations: usize,
    /// Number of applications of a background Green's operator.
    pub operator_applications: usize,
    /// Final relative residual ‖u_bg + G V u − u‖ / ‖u_bg‖.
    pub residual: f64,
    pub seconds: f64,
    /// Free text: why this method, fallbacks taken.
    pub note: String,
}

/// Why a solve did not produce a trustworthy answer.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SolveError {
    #[error("{method} diverged: residual grew to {residual:.3e} after {iterations} iterations")]
    Diverged {
        method: MethodUsed,
        iterations: usize,
        residual: f64,
    },
    #[error("{method} did not reach tolerance {tolerance:.1e}: residual {residual:.3e} after {iterations} iterations")]
    NotConverged {
        method: MethodUsed,
        iterations: usize,
        residual: f64,
        tolerance: f64,
    },
    #[error("invalid problem: {0}")]
    Invalid(String),
}

/// One diffraction problem: a permittivity grid, a wavelength, an incidence.
pub struct Problem<'a> {
    pub lattice: Lattice,
    /// Total permittivity per voxel, (nz, ny, nx).
    pub eps: &'a Array3<C64>,
    /// Binder permittivity (real: the binder is transparent).
    pub eps_binder: f64,
}

impl Problem<'_> {
    /// Lattice for a wavelength and incidence (polar, azimuth in degrees).
    pub fn lattice(
        grid: [usize; 3],
        size_nm: [f64; 3],
        wavelength_nm: f64,
        polar_deg: f64,
        azimuth_deg: f64,
    ) -> Lattice {
        let k0 = 2.0 * std::f64::consts::PI / wavelength_nm;
        let (s, p) = (polar_deg.to_radians().sin(), azimuth_deg.to_radians());
        Lattice {
            nx: grid[0],
            ny: grid[1],
            nz: grid[2],
            size_nm,
            k0,
            q: [k0 * s * p.cos(), k0 * s * p.sin()],
        }
    }
}

/// Iteration controls.
#[derive(Debug, Clone, Copy)]
pub struct Controls {
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Field storage of the iterative methods ([`storage`]).
    pub precision: Precision,
}

/// How far a method can be trusted on a problem, before running it.
#[derive(Debug, Clone, PartialEq)]
pub enum Validity {
    /// Converges for any problem of this kind.
    Always,
    /// Expected to converge; the estimate behind it.
    Likely(String),
    /// Expected to fail; why.
    Unlikely(String),
}

/// Result of running one method.
pub struct Outcome {
    pub iterations: usize,
    pub applications: usize,
    pub residual: f64,
    pub note: String,
}

/// Bookkeeping shared by the iterative methods: a residual that is not
/// finite or grows a thousandfold above its best is divergence, one at
/// tolerance is convergence, and a spent iteration budget is a loud failure.
pub struct Monitor {
    method: MethodUsed,
    best: f64,
}

impl Monitor {
    pub fn new(method: MethodUsed) -> Self {
        Monitor {
            method,
            best: f64::INFINITY,
        }
    }

    /// `Ok(true)`: converged; `Ok(false)`: go on; `Err`: stop with this error.
    pub fn check(
        &mut self,
        res: f64,
        iterations: usize,
        ctl: &Controls,
    ) -> Result<bool, SolveError> {
        let method = self.method;
        if !res.is_finite() || res > 1e3 * self.best.max(ctl.tolerance) {
            return Err(SolveError::Diverged {
                method,
                iterations,
                residual: res,
            });
        }
        self.best = self.best.min(res);
        if res <= ctl.tolerance {
            return Ok(true);
        }
        if iterations >= ctl.max_iterations {
            return Err(SolveError::NotConverged {
                method,
                iterations,
                residual: res,
                tolerance: ctl.tolerance,
            });
        }
        Ok(false)
    }
}

/// A Krylov (re)start: the true residual, checked, then preconditioned.
pub enum Restart {
    /// The true relative residual is at tolerance.
    Converged(f64),
    /// Go on from `r ← γ r'`: its norm, and the norm the preconditioned
    /// residual must reach for the true one to be at tolerance (with a
    /// safety factor 2).
    Go { norm: f64, target: f64 },
}

impl System<'_> {
    /// Shared start of a GMRES cycle or a BiCGStab run.
    pub fn restart<S: Storage>(
        &mut self,
        u: &Array3<S>,
        r: &mut Array3<S>,
        monitor: &mut Monitor,
        iterations: usize,
        ctl: &Controls,
    ) -> Result<Restart, SolveError> {
        let res = self.residual_shifted(u, r);
        if monitor.check(res, iterations, ctl)? {
            return Ok(Restart::Converged(res));
        }
        self.precondition(r);
        let norm = norm_sqr(r).sqrt();
        Ok(Restart::Go {
            norm,
            target: 0.5 * norm * ctl.tolerance / res,
        })
    }
}

/// An iterative method for the shared discrete equation, with its fields
/// stored as `S` ([`storage`]).
pub trait IterativeMethod<S: Storage> {
    fn kind(&self) -> MethodUsed;
    /// A cheap a-priori statement of where the method is valid.
    fn validity(&self, sys: &mut System) -> Validity;
    /// Improve `u` in place until the relative residual is below tolerance.
    fn run(
        &self,
        sys: &mut System,
        u: &mut Array3<S>,
        ctl: &Controls,
    ) -> Result<Outcome, SolveError>;
}

/// The discrete equation `u = u_bg + G_b V u` and the scratch to work on it.
pub struct System<'a> {
    pub op: Operator,
    /// `G_b`'s tables, built on the first plain residual (Born) and
    /// released by [`System::release_binder`] when Born is not used.
    binder: Option<GreenTable>,
    pub eps: &'a Array3<C64>,
    pub eps_binder: f64,
    /// k0².
    k2: f64,
    /// Cell averages of u_bg per z (constant in x, y).
    pub ubg: Vec<C64>,
    pub r_bg: C64,
    pub t_bg: C64,
    ubg_norm: f64,
    /// CBS shift: real centre ε_r, ε_s, c = k0²(ε_r + iε_s − ε_b), and the
    /// exact per-harmonic shifted operators.
    pub shift: Shift,
    /// u_s = (I − c G_b)⁻¹ u_bg per z cell (harmonic 00 only).
    pub us: Vec<C64>,
    us_norm: f64,
    /// Top/bottom functionals of G_b for harmonic 00 (never resonant: it propagates).
    top00: Vec<C64>,
    bottom00: Vec<C64>,
    pub ws: Workspace,
    /// The f64 field every operator application works on (V u or V' u in,
    /// G of it out); the methods' own fields may be f32.
    pub tmp: Array3<C64>,
}

/// The CBS shift of a problem (Osnabrugge et al. 2016): background
/// `ε_r + iε_s` with `ε_s = margin · max|ε − ε_r|`.
pub struct Shift {
    pub er: f64,
    pub es: f64,
    pub c: C64,
    pub table: ShiftTable,
}

/// ε_s = SHIFT_MARGIN · max|ε − ε_r| (1 makes CBS stall on the extreme voxels).
pub const SHIFT_MARGIN: f64 = 1.05;

impl<'a> System<'a> {
    pub fn new(p: &Problem<'a>) -> Result<Self, SolveError> {
        Self::with_margin(p, SHIFT_MARGIN)
    }

    /// As [`System::new`] with the CBS shift `ε_s = margin · max|ε − ε_r|`
    /// (margin ≥ 1; Osnabrugge et al. take 1, [`SHIFT_MARGIN`] is the default).
    pub fn with_margin(p: &Problem<'a>, margin: f64) -> Result<Self, SolveError> {
        if !(1.0..=100.0).contains(&margin) {
            return Err(SolveError::Invalid(format!(
                "CBS shift margin must be in [1, 100], got {margin}"
            )));
        }
        let lat = p.lattice;
        if p.eps.dim() != (lat.nz, lat.ny, lat.nx) {
            return Err(SolveError::Invalid(format!(
                "permittivity grid {:?} does not match lattice",
                p.eps.dim()
            )));
        }
        if p.eps
            .iter()
            .any(|e| !e.re.is_finite() || !e.im.is_finite() || e.im < 0.0)
        {
            return Err(SolveError::Invalid(
                "permittivity must be finite with Im ε ≥ 0 (passive)".into(),
            ));
        }
        let op = Operator::new(lat);
        let k2 = lat.k0 * lat.k0;
        let mut ubg = vec![C64::new(0.0, 0.0); lat.nz];
        let g2 = C64::new(k2 * p.eps_binder - lat.q[0].powi(2) - lat.q[1].powi(2), 0.0);
        let (r_bg, t_bg) = green::background_response(&lat.slab(), g2, lat.beta(0, 0), &mut ubg);
        let ubg_norm =
            (ubg.iter().map(|c| c.norm_sqr()).sum::<f64>() * lat.harmonics() as f64).sqrt();
        let (er, rad) = marching::shift_of(p.eps, p.eps_binder);
        let es = (margin * rad).max(1e-9);
        let c = k2 * (C64::new(er, es) - p.eps_binder);
        let table = ShiftTable::new(&lat, p.eps_binder, c);
        let mut scr = BandScratch::new(lat.nz);
        scr.column().copy_from_slice(&ubg);
        table.solve_column(0, &mut scr);
        let us = scr.column().to_vec();
        let us_norm =
            (us.iter().map(|c| c.norm_sqr()).sum::<f64>() * lat.harmonics() as f64).sqrt();
        let c00 = green::coef_from(&lat.slab(), g2, lat.beta(0, 0));
        let top00 = (0..lat.nz).map(|k| c00.top_weight(lat.nz, k)).collect();
        let bottom00 = (0..lat.nz).map(|k| c00.bottom_weight(lat.nz, k)).collect();
        let shift = Shift { er, es, c, table };
        let ws = op.workspace();
        let tmp = Array3::zeros(p.eps.dim());
        Ok(System {
            shift,
            k2,
            us,
            us_norm,
            top00,
            bottom00,
            op,
            binder: None,
            eps: p.eps,
            eps_binder: p.eps_binder,
            ubg,
            r_bg,
            t_bg,
            ubg_norm,
            ws,
            tmp,
        })
    }

    /// Fill `u` with the background field.
    pub fn set_background<S: Storage>(&self, u: &mut Array3<S>) {
        for (j, mut slice) in u.outer_iter_mut().enumerate() {
            slice.fill(S::store(self.ubg[j]));
        }
    }

    /// `tmp ← (V − shift) x` with `V = k0²(ε − ε_b)`.
    fn load_scaled<S: Storage>(&mut self, x: &Array3<S>, shift: C64) {
        let (k2, eb) = (self.k2, self.eps_binder);
        Zip::from(&mut self.tmp)
            .and(x)
            .and(self.eps)
            .par_for_each(|t, x, e| *t = (k2 * (e - eb) - shift) * x.load());
    }

    /// `out ← base_j + tmp − u` per z-slice j.
    fn finish_residual<S: Storage>(&self, base: &[C64], u: &Array3<S>, out: &mut Array3<S>) {
        use rayon::prelude::*;
        out.outer_iter_mut()
            .into_par_iter()
            .zip(u.outer_iter().into_par_iter())
            .zip(self.tmp.outer_iter().into_par_iter())
            .zip(base.par_iter())
            .for_each(|(((mut o, u), t), b)| {
                Zip::from(&mut o)
                    .and(&u)
                    .and(&t)
                    .for_each(|o, u, t| *o = S::store(b + t - u.load()));
            });
    }

    /// `out ← u_bg + G V u − u` (the residual); returns ‖out‖ / ‖u_bg‖.
    pub fn residual<S: Storage>(&mut self, u: &Array3<S>, out: &mut Array3<S>) -> f64 {
        self.load_scaled(u, C64::new(0.0, 0.0));
        let lat = self.op.lat;
        let binder = self
            .binder
            .get_or_insert_with(|| GreenTable::new(&lat, C64::new(self.eps_binder, 0.0)));
        self.op.apply(binder, &mut self.tmp, &mut self.ws);
        self.finish_residual(&self.ubg, u, out);
        self.norm(out)
    }

    /// Drop `G_b`'s tables (as large as a field) once Born is ruled out.
    pub fn release_binder(&mut self) {
        self.binder = None;
    }

    /// `out ← u_s + G_s V' u − u`, the residual of the same equation in its
    /// shifted form (`= (I − c G_b)⁻¹ × the plain residual`); returns
    /// ‖out‖ / ‖u_s‖. Never applies `G_b`, so guided-mode poles of the binder
    /// slab cannot enter.
    pub fn residual_shifted<S: Storage>(&mut self, u: &Array3<S>, out: &mut Array3<S>) -> f64 {
        self.load_scaled(u, self.shift.c);
        self.op
            .apply_shifted_green(&self.shift.table, &mut self.tmp, &mut self.ws);
        self.finish_residual(&self.us, u, out);
        self.norm(out) * self.ubg_norm / self.us_norm
    }

    /// `out ← x − G_s V' x` (the shifted operator, without u_s).
    pub fn apply_a_shifted<S: Storage>(&mut self, x: &Array3<S>, out: &mut Array3<S>) {
        self.load_scaled(x, self.shift.c);
        self.op
            .apply_shifted_green(&self.shift.table, &mut self.tmp, &mut self.ws);
        Zip::from(&mut *out)
            .and(x)
            .and(&self.tmp)
            .par_for_each(|o, x, t| *o = S::store(x.load() - t));
    }

    /// `x ← γ x`, γ = 1 + i(ε − ε_r)/ε_s: the CBS preconditioner of the
    /// shifted form.
    pub fn precondition<S: Storage>(&self, x: &mut Array3<S>) {
        let (er, es) = (self.shift.er, self.shift.es);
        Zip::from(x)
            .and(self.eps)
            .par_for_each(|x, e| *x = S::store(x.load() * (1.0 + C64::i() * (e - er) / es)));
    }

    /// ‖x‖ / ‖u_bg‖.
    pub fn norm<S: Storage>(&self, x: &Array3<S>) -> f64 {
        norm_sqr(x).sqrt() / self.ubg_norm
    }

    /// The solved field with its far-field amplitudes and absorption.
    pub fn into_solution<S: Storage>(mut self, u: Array3<S>, record: SolveRecord) -> Solution {
        let (r, t, absorption) = self.outputs(&u);
        let lattice = self.op.lat;
        drop(self);
        Solution {
            lattice,
            field: u.mapv(S::load),
            r,
            t,
            absorption,
            record,
        }
    }

    /// Far-field amplitudes and absorption of a field.
    fn outputs<S: Storage>(&mut self, u: &Array3<S>) -> (Array2<C64>, Array2<C64>, f64) {
        let lat = self.op.lat;
        let mut r = Array2::zeros((lat.nx, lat.ny));
        let mut t = Array2::zeros((lat.nx, lat.ny));
        // G_b V u = G_b(V' u + c u) = w + c G_b(u − G_s V' u), and at the
        // solution u − G_s V' u = u_s (harmonic 00 only): boundary values of
        // w from the shifted sweep, of G_b u_s from the 00 functionals.
        self.load_scaled(u, self.shift.c);
        self.op.shifted_boundary(
            &self.shift.table,
            &mut self.tmp,
            &mut self.ws,
            &mut r,
            &mut t,
        );
        let c = self.shift.c;
        let us_top: C64 = self.top00.iter().zip(&self.us).map(|(w, u)| w * u).sum();
        let us_bottom: C64 = self.bottom00.iter().zip(&self.us).map(|(w, u)| w * u).sum();
        r[[0, 0]] += self.r_bg + c * us_top;
        t[[0, 0]] += self.t_bg + c * us_bottom;
        let dz = lat.size_nm[2] / lat.nz as f64;
        let s = sum_slices(u, |u: &S, e: &C64| e.im * u.load().norm_sqr(), self.eps);
        let beta00 = lat.beta(0, 0).re;
        let absorption = lat.k0 * lat.k0 / beta00 * s * dz / lat.harmonics() as f64;
        (r, t, absorption)
    }
}

/// A solved problem: the field and what the far field needs.
pub struct Solution {
    pub lattice: Lattice,
    /// Cell-averaged periodic field v, (nz, ny, nx).
    pub field: Array3<C64>,
    /// Reflection amplitudes r_mn (total, u_mn(0) − δ), spectral layout (nx, ny).
    pub r: Array2<C64>,
    /// Transmission amplitudes t_mn, spectral layout (nx, ny).
    pub t: Array2<C64>,
    /// Absorbed fraction of the incident power.
    pub absorption: f64,
    pub record: SolveRecord,
}

/// Solve one problem with the requested method (`Auto` picks and falls
/// back) and the field storage of `ctl.precision`.
pub fn solve(p: &Problem, method: Method, ctl: &Controls) -> Result<Solution, SolveError> {
    match ctl.precision {
        Precision::F64 => solve_stored::<C64>(p, method, ctl),
        Precision::F32 => solve_stored::<C32>(p, method, ctl),
    }
}

fn solve_stored<S: Storage>(
    p: &Problem,
    method: Method,
    ctl: &Controls,
) -> Result<Solution, SolveError> {
    let start = Instant::now();
    let mut sys = System::new(p)?;
    let mut u = Array3::<S>::default(p.eps.dim());
    sys.set_background(&mut u);
    let born = born::Born;
    let gm = gmres::Gmres::default();
    let bi = bicgstab::BiCgStab::default();
    let tm = marching::TimeMarching::default();
    let (used, out) = match method {
        Method::Born => (MethodUsed::Born, born.run(&mut sys, &mut u, ctl)?),
        Method::TimeMarching => (MethodUsed::TimeMarching, tm.run(&mut sys, &mut u, ctl)?),
        Method::Gmres => (MethodUsed::Gmres, gm.run(&mut sys, &mut u, ctl)?),
        Method::BiCgStab => (MethodUsed::BiCgStab, bi.run(&mut sys, &mut u, ctl)?),
        Method::Auto => {
            // Born only where its contraction estimate is good; then BiCGStab;
            // time-marching (always convergent) as the last resort. Each
            // failure is recorded.
            let mut chain: Vec<&dyn IterativeMethod<S>> = vec![&bi, &tm];
            let mut notes = vec![];
            let mut spent = 0;
            match IterativeMethod::<S>::validity(&born, &mut sys) {
                Validity::Unlikely(why) => {
                    notes.push(format!("skipped Born: {why}"));
                    sys.release_binder();
                }
                Validity::Likely(why) => {
                    notes.push(format!("chose Born: {why}"));
                    chain.insert(0, &born);
                }
                Validity::Always => {
                    chain.insert(0, &born);
                }
            }
            spent += born::ESTIMATE_STEPS;
            let mut result = None;
            let mut last_err = None;
            for m in chain {
                sys.set_background(&mut u);
                match m.run(&mut sys, &mut u, ctl) {
                    Ok(o) => {
                        result = Some((m.kind(), o));
                        break;
                    }
                    Err(e) => {
                        notes.push(format!("{e}; falling back"));
                        last_err = Some(e);
                    }
                }
            }
            match result {
                Some((kind, mut o)) => {
                    o.applications += spent;
                    notes.push(o.note);
                    o.note = format!("auto: {}", notes.join("; "));
                    (kind, o)
                }
                None => return Err(last_err.expect("at least one method ran")),
            }
        }
    };
    let mut note = out.note;
    if ctl.precision == Precision::F32 {
        note.push_str("; f32 field storage");
    }
    let record = SolveRecord {
        method: used,
        iterations: out.iterations,
        operator_applications: out.applications,
        residual: out.residual,
        seconds: start.elapsed().as_secs_f64(),
        note,
    };
    Ok(sys.into_solution(u, record))
}
