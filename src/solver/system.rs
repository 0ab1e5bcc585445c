//! The discrete equation every iterative method solves, and the scratch to
//! work on it.
//!
//! [`System`] is the equation `u = u_bg + G_b V u` of one [`Problem`]: the
//! operator, the potential `V = k0²(ε − ε_b)`, the source `u_bg`, and the same
//! equation in its shifted (convergent-Born-series) form
//! `u = u_s + G_s V' u` (see [`marching`](super::methods::marching)). It is
//! built once per solve and read by the methods through its operations
//! (residuals, the shifted operator, the preconditioner, the far field).
//! [`Scratch`] is the working memory of those operations, owned by the caller
//! and passed in, so no application allocates.

use super::green;
use super::lattice::Lattice;
use super::operator::{GreenTable, Operator, Workspace};
use super::shift::{BandScratch, ShiftTable};
use super::storage::{norm_sqr, on_field, sum_slices, Field, Storage};
use super::{Problem, Solution, SolveError, SolveRecord};
use ndarray::{Array2, Array3, Zip};
use num_complex::Complex64 as C64;

/// ε_s = SHIFT_MARGIN · max|ε − ε_r| (1 makes CBS stall on the extreme voxels).
pub const SHIFT_MARGIN: f64 = 1.05;

/// The discrete equation `u = u_bg + G_b V u` of one problem, in its plain
/// and its shifted form.
pub struct System<'a> {
    op: Operator,
    /// `G_b`'s tables, built on the first plain residual (Born) and
    /// released by [`System::release_binder`] when Born is not used.
    binder: Option<GreenTable>,
    eps: &'a Array3<C64>,
    eps_binder: f64,
    /// k0².
    k2: f64,
    /// Cell averages of u_bg per z (constant in x, y).
    ubg: Vec<C64>,
    r_bg: C64,
    t_bg: C64,
    ubg_norm: f64,
    /// CBS shift: real centre ε_r, ε_s, c = k0²(ε_r + iε_s − ε_b), and the
    /// exact per-harmonic shifted operators.
    shift: Shift,
    /// u_s = (I − c G_b)⁻¹ u_bg per z cell (harmonic 00 only).
    us: Vec<C64>,
    us_norm: f64,
    /// Top/bottom functionals of G_b for harmonic 00 (never resonant: it propagates).
    top00: Vec<C64>,
    bottom00: Vec<C64>,
}

/// The CBS shift of a problem (Osnabrugge et al. 2016): background
/// `ε_r + iε_s` with `ε_s = margin · max|ε − ε_r|`.
struct Shift {
    er: f64,
    es: f64,
    c: C64,
    table: ShiftTable,
}

/// Working memory of a [`System`]'s operations, sized for its lattice.
pub struct Scratch {
    /// The operator's own scratch (spectra, FFT and sweep buffers).
    op: Workspace,
    /// The f64 field every operator application works on (V u or V' u in,
    /// G of it out); the methods' own fields may be f32.
    field: Array3<C64>,
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
        let (er, rad) = shift_of(p.eps, p.eps_binder);
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
        })
    }

    /// Fresh working memory for this system's operations.
    pub fn scratch(&self) -> Scratch {
        Scratch {
            op: self.op.workspace(),
            field: Array3::zeros(self.eps.dim()),
        }
    }

    pub fn lattice(&self) -> &Lattice {
        &self.op.lat
    }

    /// Total permittivity per voxel, (nz, ny, nx).
    pub fn eps(&self) -> &Array3<C64> {
        self.eps
    }

    /// The CBS shift's real centre ε_r and imaginary part ε_s.
    pub fn shift(&self) -> (f64, f64) {
        (self.shift.er, self.shift.es)
    }

    /// Fill `u` with the background field.
    pub fn set_background<S: Storage>(&self, u: &mut Array3<S>) {
        for (j, mut slice) in u.outer_iter_mut().enumerate() {
            slice.fill(S::store(self.ubg[j]));
        }
    }

    /// [`Self::set_background`] in either storage.
    pub fn set_background_field(&self, u: &mut Field) {
        on_field!(u, u => self.set_background(u))
    }

    /// `scr.field ← (V − shift) x` with `V = k0²(ε − ε_b)`.
    fn load_scaled<S: Storage>(&self, scr: &mut Scratch, x: &Array3<S>, shift: C64) {
        let (k2, eb) = (self.k2, self.eps_binder);
        Zip::from(&mut scr.field)
            .and(x)
            .and(self.eps)
            .par_for_each(|t, x, e| *t = (k2 * (e - eb) - shift) * x.load());
    }

    /// `out ← base_j + scr.field − u` per z-slice j.
    fn finish_residual<S: Storage>(
        &self,
        scr: &Scratch,
        base: &[C64],
        u: &Array3<S>,
        out: &mut Array3<S>,
    ) {
        use rayon::prelude::*;
        out.outer_iter_mut()
            .into_par_iter()
            .zip(u.outer_iter().into_par_iter())
            .zip(scr.field.outer_iter().into_par_iter())
            .zip(base.par_iter())
            .for_each(|(((mut o, u), t), b)| {
                Zip::from(&mut o)
                    .and(&u)
                    .and(&t)
                    .for_each(|o, u, t| *o = S::store(b + t - u.load()));
            });
    }

    /// `out ← u_bg + G V u − u` (the residual); returns ‖out‖ / ‖u_bg‖.
    pub fn residual<S: Storage>(
        &mut self,
        scr: &mut Scratch,
        u: &Array3<S>,
        out: &mut Array3<S>,
    ) -> f64 {
        self.load_scaled(scr, u, C64::new(0.0, 0.0));
        let lat = self.op.lat;
        let binder = self
            .binder
            .get_or_insert_with(|| GreenTable::new(&lat, C64::new(self.eps_binder, 0.0)));
        self.op.apply(binder, &mut scr.field, &mut scr.op);
        self.finish_residual(scr, &self.ubg, u, out);
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
    pub fn residual_shifted<S: Storage>(
        &self,
        scr: &mut Scratch,
        u: &Array3<S>,
        out: &mut Array3<S>,
    ) -> f64 {
        self.load_scaled(scr, u, self.shift.c);
        self.op
            .apply_shifted_green(&self.shift.table, &mut scr.field, &mut scr.op);
        self.finish_residual(scr, &self.us, u, out);
        self.norm(out) * self.ubg_norm / self.us_norm
    }

    /// `out ← x − G_s V' x` (the shifted operator, without u_s).
    pub fn apply_a_shifted<S: Storage>(
        &self,
        scr: &mut Scratch,
        x: &Array3<S>,
        out: &mut Array3<S>,
    ) {
        self.load_scaled(scr, x, self.shift.c);
        self.op
            .apply_shifted_green(&self.shift.table, &mut scr.field, &mut scr.op);
        Zip::from(&mut *out)
            .and(x)
            .and(&scr.field)
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

    /// The solved field with its far-field amplitudes and absorption; the
    /// system and its scratch are released before the field is converted.
    pub fn into_solution(self, scr: Scratch, u: Field, record: SolveRecord) -> Solution {
        on_field!(u, u => self.into_solution_stored(scr, u, record))
    }

    fn into_solution_stored<S: Storage>(
        self,
        mut scr: Scratch,
        u: Array3<S>,
        record: SolveRecord,
    ) -> Solution {
        let (r, t, absorption) = self.outputs(&mut scr, &u);
        let lattice = self.op.lat;
        drop(scr);
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
    fn outputs<S: Storage>(
        &self,
        scr: &mut Scratch,
        u: &Array3<S>,
    ) -> (Array2<C64>, Array2<C64>, f64) {
        let lat = self.op.lat;
        let mut r = Array2::zeros((lat.nx, lat.ny));
        let mut t = Array2::zeros((lat.nx, lat.ny));
        // G_b V u = G_b(V' u + c u) = w + c G_b(u − G_s V' u), and at the
        // solution u − G_s V' u = u_s (harmonic 00 only): boundary values of
        // w from the shifted sweep, of G_b u_s from the 00 functionals.
        self.load_scaled(scr, u, self.shift.c);
        self.op.shifted_boundary(
            &self.shift.table,
            &mut scr.field,
            &mut scr.op,
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
