//! The discrete equation every iterative method solves, and the scratch to
//! work on it.
//!
//! [`System`] is the equation `u = u_bg + G_b V u` of one [`Problem`]: the
//! operator, the potential `V = k0²(ε − ε_b)`, the source `u_bg`, and the same
//! equation in its shifted form `u = u_s + G_s V' u` on one of two
//! backgrounds ([`Background`]): the convergent-Born-series shift
//! `ε_r + iε_s` with its preconditioner (see
//! [`marching`](super::methods::marching)), or the layer's mean permittivity
//! `⟨ε⟩` with a loss floor ([`MEAN_LOSS_FLOOR`]) and no preconditioner
//! (METHOD §4, "The mean background"). It is
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
use crate::config::Background;
use ndarray::{Array2, Array3, Zip};
use num_complex::Complex64 as C64;

/// ε_s = SHIFT_MARGIN · max|ε − ε_r| (1 makes CBS stall on the extreme voxels).
pub const SHIFT_MARGIN: f64 = 1.05;

/// The mean background's loss floor: `Im ε_bg ≥ MEAN_LOSS_FLOOR · max|ε − ⟨ε⟩|²`.
/// A lossless mean slab has sharp guided resonances that Krylov methods
/// resolve slowly; a loss growing with the square of the contrast (as the
/// scattering loss of the coherent wave does) damps them where scattering is
/// strong and leaves weak layers alone. 0.1 was the best of 0–0.25 on the
/// layers of docs/PERFORMANCE.md ("The mean background").
pub const MEAN_LOSS_FLOOR: f64 = 0.1;

/// How the shifted form's background is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShiftParams {
    pub background: Background,
    /// CBS: `ε_s = margin · max|ε − ε_r|`, in [1, 100].
    pub margin: f64,
    /// Mean: the loss floor factor, in [0, 100].
    pub mean_loss_floor: f64,
}

impl ShiftParams {
    /// The defaults for `background`.
    pub const fn of(background: Background) -> ShiftParams {
        ShiftParams {
            background,
            margin: SHIFT_MARGIN,
            mean_loss_floor: MEAN_LOSS_FLOOR,
        }
    }
}

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
    /// The background of the shifted form, its exact operator and source.
    shift: Shift,
    /// Kept to rebuild the shift for another background.
    params: ShiftParams,
    /// Top/bottom functionals of G_b for harmonic 00 (never resonant: it propagates).
    top00: Vec<C64>,
    bottom00: Vec<C64>,
}

/// The background of the shifted form `u = u_s + G_s V' u`: permittivity
/// `ε_s` inside the slab (vacuum stays outside), `c = k0²(ε_s − ε_b)`, the
/// exact per-harmonic operators, `u_s = (I − c G_b)⁻¹ u_bg` (harmonic 00
/// only, per z cell) and, for the CBS shift, its preconditioner.
struct Shift {
    kind: Background,
    eps: C64,
    /// CBS: real centre ε_r and ε_s of `γ = 1 + i(ε − ε_r)/ε_s`; `None` for
    /// the unpreconditioned mean background.
    cbs: Option<(f64, f64)>,
    c: C64,
    table: ShiftTable,
    us: Vec<C64>,
    us_norm: f64,
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
        .map(|e| (e - er).norm_sqr())
        .fold((eps_binder - er).powi(2), f64::max)
        .sqrt();
    (er, rad)
}

impl<'a> System<'a> {
    /// The system of `p` with the Krylov methods' background `bg`.
    pub fn new(p: &Problem<'a>, bg: Background) -> Result<Self, SolveError> {
        Self::with_params(p, ShiftParams::of(bg))
    }

    /// As [`System::new`] with other shift parameters: the CBS shift
    /// `ε_s = margin · max|ε − ε_r|` (margin ≥ 1; Osnabrugge et al. take 1,
    /// [`SHIFT_MARGIN`] is the default) or the mean background's loss floor.
    pub fn with_params(p: &Problem<'a>, params: ShiftParams) -> Result<Self, SolveError> {
        let margin = params.margin;
        if !(1.0..=100.0).contains(&margin) {
            return Err(SolveError::Invalid(format!(
                "CBS shift margin must be in [1, 100], got {margin}"
            )));
        }
        let floor = params.mean_loss_floor;
        if !(0.0..=100.0).contains(&floor) {
            return Err(SolveError::Invalid(format!(
                "mean background loss floor must be in [0, 100], got {floor}"
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
        let shift = Shift::new(&lat, p.eps, p.eps_binder, &ubg, params);
        let c00 = green::coef_from(&lat.slab(), g2, lat.beta(0, 0));
        let top00 = (0..lat.nz).map(|k| c00.top_weight(lat.nz, k)).collect();
        let bottom00 = (0..lat.nz).map(|k| c00.bottom_weight(lat.nz, k)).collect();
        Ok(System {
            shift,
            params,
            k2,
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

    /// Rebuild the shifted form on background `bg` (time-marching needs the
    /// CBS shift); nothing happens if it is already the one in use.
    pub fn use_background(&mut self, bg: Background) {
        if self.shift.kind != bg {
            self.params.background = bg;
            self.shift = Shift::new(
                &self.op.lat,
                self.eps,
                self.eps_binder,
                &self.ubg,
                self.params,
            );
        }
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

    /// The background of the shifted form in use.
    pub fn background(&self) -> Background {
        self.shift.kind
    }

    /// The shifted form's background permittivity `ε_s` inside the slab.
    pub fn background_eps(&self) -> C64 {
        self.shift.eps
    }

    /// The background for a solve record's note: `ε_r = …, ε_s = …` (CBS)
    /// or `mean background ⟨ε⟩ = …`.
    pub fn describe_background(&self) -> String {
        match self.shift.cbs {
            Some((er, es)) => format!("ε_r = {er:.4}, ε_s = {es:.4}"),
            None => {
                let e = self.shift.eps;
                format!("mean background ⟨ε⟩ = {:.4}{:+.4}i", e.re, e.im)
            }
        }
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

    /// Fill `u` with the iterations' start: on the mean background its own
    /// slab's field `u_s` (the coherent field of the homogenised layer, and
    /// the exact answer where the layer is homogeneous), else `u_bg`.
    pub fn set_start_field(&self, u: &mut Field) {
        let start = match self.shift.kind {
            Background::Mean => &self.shift.us,
            Background::Binder => &self.ubg,
        };
        on_field!(u, u => {
            for (j, mut slice) in u.outer_iter_mut().enumerate() {
                slice.fill(Storage::store(start[j]));
            }
        })
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
        self.finish_residual(scr, &self.shift.us, u, out);
        self.norm(out) * self.ubg_norm / self.shift.us_norm
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
    /// shifted form; the identity on the mean background.
    pub fn precondition<S: Storage>(&self, x: &mut Array3<S>) {
        let Some((er, es)) = self.shift.cbs else {
            return;
        };
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
        let us = &self.shift.us;
        let us_top: C64 = self.top00.iter().zip(us).map(|(w, u)| w * u).sum();
        let us_bottom: C64 = self.bottom00.iter().zip(us).map(|(w, u)| w * u).sum();
        r[[0, 0]] += self.r_bg + c * us_top;
        t[[0, 0]] += self.t_bg + c * us_bottom;
        let dz = lat.size_nm[2] / lat.nz as f64;
        let s = sum_slices(u, |u: &S, e: &C64| e.im * u.load().norm_sqr(), self.eps);
        let beta00 = lat.beta(0, 0).re;
        let absorption = lat.k0 * lat.k0 / beta00 * s * dz / lat.harmonics() as f64;
        (r, t, absorption)
    }
}

/// Mean of the permittivity over every voxel, the mean background.
pub fn mean_eps(eps: &Array3<C64>) -> C64 {
    eps.iter().sum::<C64>() / eps.len() as f64
}

impl Shift {
    fn new(
        lat: &Lattice,
        eps: &Array3<C64>,
        eps_binder: f64,
        ubg: &[C64],
        params: ShiftParams,
    ) -> Shift {
        let kind = params.background;
        let (bg, cbs) = match kind {
            Background::Binder => {
                let (er, rad) = shift_of(eps, eps_binder);
                let es = (params.margin * rad).max(1e-9);
                (C64::new(er, es), Some((er, es)))
            }
            Background::Mean => {
                let m = mean_eps(eps);
                let rad = eps
                    .iter()
                    .map(|e| (e - m).norm_sqr())
                    .fold(0.0, f64::max)
                    .sqrt();
                let floor = params.mean_loss_floor * rad * rad;
                (C64::new(m.re, m.im.max(floor).max(1e-9)), None)
            }
        };
        let k2 = lat.k0 * lat.k0;
        let c = k2 * (bg - eps_binder);
        let table = ShiftTable::new(lat, eps_binder, c);
        let mut scr = BandScratch::new(lat.nz);
        scr.column().copy_from_slice(ubg);
        table.solve_column(0, &mut scr);
        let us = scr.column().to_vec();
        let us_norm =
            (us.iter().map(|c| c.norm_sqr()).sum::<f64>() * lat.harmonics() as f64).sqrt();
        Shift {
            kind,
            eps: bg,
            cbs,
            c,
            table,
            us,
            us_norm,
        }
    }
}
