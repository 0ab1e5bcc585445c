//! The discrete equation every iterative method solves, and the scratch to
//! work on it.
//!
//! [`System`] is the equation `u = u_bg + G_b V u` of one [`Problem`]: the
//! operator, the potential `V = k0²(ε − ε_b)`, the source `u_bg`, and the same
//! equation in its shifted form `u = u_s + G_s V' u` on one of two
//! backgrounds ([`Background`]): the convergent-Born-series shift
//! `ε_r + iε_s` with its preconditioner (see
//! [`marching`](super::methods::marching)), or the layer's mean permittivity
//! `⟨ε⟩` with a loss floor, per cell where a face holds air, and no
//! preconditioner (METHOD §4, "The mean background"; chosen in
//! [`background`](super::background)). It is
//! built once per solve and read by the methods through its operations
//! (residuals, the shifted operator, the preconditioner, the far field).
//! [`Scratch`] is the working memory of those operations, owned by the caller
//! and passed in, so no application allocates.

use super::background::{self, mean_profile, shift_of, ShiftParams};
use super::green;
use super::lattice::Lattice;
use super::maxwell::{VectorOperator, VectorShift, VectorWorkspace};
use super::operator::{GreenTable, Operator, Workspace};
use super::shift::{BandScratch, ShiftTable};
use super::storage::{dot, norm_sqr, on_field, sum_slices, Field, Storage};
use super::tensor;
use super::{Jones, Problem, Solution, SolveError, SolveRecord, VectorAmplitudes, Wave};
use crate::config::Background;
use crate::raster::Anisotropy;
use ndarray::{s, Array2, Array3, ArrayViewMut2, Ix3, Zip};
use num_complex::Complex64 as C64;

/// The discrete equation `u = u_bg + G_b V u` of one problem, in its plain
/// and its shifted form.
pub struct System<'a> {
    /// The background Green's operator of the equation solved.
    op: BackgroundOperator,
    lat: Lattice,
    eps: &'a Array3<C64>,
    /// The tensor part of the permittivity (Maxwell; None: isotropic or
    /// no terms).
    tensor: Option<&'a Anisotropy>,
    eps_binder: f64,
    /// k0².
    k2: f64,
    /// Cell averages of u_bg per row of the unknowns (z cells; for Maxwell
    /// the three components' z cells), constant in x, y.
    ubg: Vec<C64>,
    /// The background's specular amplitudes: `[s, p]` for Maxwell, `[u, 0]`
    /// for the scalar wave.
    r_bg: [C64; 2],
    t_bg: [C64; 2],
    ubg_norm: f64,
    /// The background of the shifted form, its exact operator and source.
    shift: Shift,
    /// Kept to rebuild the shift for another background.
    params: ShiftParams,
}

/// The two wave equations' background operators (METHOD §4, §9): the same
/// methods iterate on either through [`System`]'s operations.
enum BackgroundOperator {
    /// The scalar Helmholtz equation: the unknowns are (nz, ny, nx).
    Scalar {
        op: Operator,
        /// `G_b`'s tables, built on the first plain residual (Born) and
        /// released by [`System::release_binder`] when Born is not used.
        binder: Option<GreenTable>,
        /// Top/bottom functionals of G_b for harmonic 00 (never resonant:
        /// it propagates).
        top00: Vec<C64>,
        bottom00: Vec<C64>,
    },
    /// Maxwell's equations for one incident polarisation state: the
    /// unknowns are (3 nz, ny, nx), E_x, E_y, E_z stacked.
    Vector {
        op: VectorOperator,
        pol: Jones,
        /// `G_b`'s row tables (shift 0), made on first use (Born).
        binder: Option<Box<VectorShift>>,
    },
}

/// The background of the shifted form `u = u_s + G_s V' u`: permittivity
/// `ε_s` inside the slab (vacuum stays outside), `c = k0²(ε_s − ε_b)`, the
/// exact per-harmonic operators, `u_s = (I − c G_b)⁻¹ u_bg` (harmonic 00
/// only, per z cell) and, for the CBS shift, its preconditioner.
struct Shift {
    kind: Background,
    /// ε_s of the bulk: every cell but the layered zones'.
    eps: C64,
    /// The layered zones of the mean background: ε_s of each of their
    /// cells, the top's and the bottom's (empty where both faces are flat).
    top: Vec<C64>,
    bottom: Vec<C64>,
    /// CBS: real centre ε_r and ε_s of `γ = 1 + i(ε − ε_r)/ε_s`; `None` for
    /// the unpreconditioned mean background.
    cbs: Option<(f64, f64)>,
    /// `c_j = k0²(ε_s,j − ε_b)` per z cell.
    c: Vec<C64>,
    /// The row sweeps' tables of the shifted operator.
    table: ShiftTables,
    /// u_s per row of the unknowns.
    us: Vec<C64>,
    us_norm: f64,
    /// Boundary amplitudes of `G_b C u_s` (harmonic 00): `[s, p]` (Maxwell)
    /// or `[u, 0]`.
    us_top: [C64; 2],
    us_bottom: [C64; 2],
}

/// The shifted operator's tables of either equation.
enum ShiftTables {
    Scalar(Box<ShiftTable>),
    Vector(Box<VectorShift>),
}

/// Working memory of a [`System`]'s operations, sized for its lattice.
pub struct Scratch {
    /// The operator's own scratch (spectra, FFT and sweep buffers).
    op: OpWorkspace,
    /// The f64 field every operator application works on (V u or V' u in,
    /// G of it out); the methods' own fields may be f32.
    field: Array3<C64>,
}

/// The scratch of either operator.
enum OpWorkspace {
    Scalar(Workspace),
    Vector(VectorWorkspace),
}

impl<'a> System<'a> {
    /// The system of `p` with the Krylov methods' background `bg` and the
    /// defaults of its equation ([`ShiftParams::for_wave`]).
    pub fn new(p: &Problem<'a>, bg: Background) -> Result<Self, SolveError> {
        Self::with_params(p, ShiftParams::for_wave(bg, &p.wave))
    }

    /// As [`System::new`] with other shift parameters: the CBS shift
    /// `ε_s = margin · max|ε − ε_r|` (margin ≥ 1; Osnabrugge et al. take 1,
    /// [`SHIFT_MARGIN`](super::SHIFT_MARGIN) is the default) or the mean background's loss floor.
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
        if params.mean_loss_cap.is_nan() || params.mean_loss_cap < 0.0 {
            return Err(SolveError::Invalid(format!(
                "mean background loss cap must be in [0, ∞], got {}",
                params.mean_loss_cap
            )));
        }
        if !(0.0..=1.0).contains(&params.mean_loss_dilute) {
            return Err(SolveError::Invalid(format!(
                "mean background dilute share must be in [0, 1], got {}",
                params.mean_loss_dilute
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
        let tensor = p.tensor.filter(|a| !a.is_empty());
        if let Some(a) = tensor {
            if p.wave == Wave::Scalar {
                return Err(SolveError::Invalid(
                    "a tensor permittivity needs Maxwell's equations".into(),
                ));
            }
            if let Some(e) = tensor::check(a, p.eps) {
                return Err(SolveError::Invalid(e));
            }
        }
        let k2 = lat.k0 * lat.k0;
        let (op, ubg, r_bg, t_bg) = match p.wave {
            Wave::Scalar => {
                let op = Operator::new(lat);
                let mut ubg = vec![C64::new(0.0, 0.0); lat.nz];
                let g2 = C64::new(k2 * p.eps_binder - lat.q[0].powi(2) - lat.q[1].powi(2), 0.0);
                let (r, t) = green::background_response(&lat.slab(), g2, lat.beta(0, 0), &mut ubg);
                let c00 = green::coef_from(&lat.slab(), g2, lat.beta(0, 0));
                let top00 = (0..lat.nz).map(|k| c00.top_weight(lat.nz, k)).collect();
                let bottom00 = (0..lat.nz).map(|k| c00.bottom_weight(lat.nz, k)).collect();
                let zero = C64::new(0.0, 0.0);
                let op = BackgroundOperator::Scalar {
                    op,
                    binder: None,
                    top00,
                    bottom00,
                };
                (op, ubg, [r, zero], [t, zero])
            }
            Wave::Vector {
                polarisation,
                azimuth_deg,
            } => {
                let op = VectorOperator::new(lat, p.eps_binder, azimuth_deg);
                let bg = op.background(polarisation);
                let op = BackgroundOperator::Vector {
                    op,
                    pol: polarisation,
                    binder: None,
                };
                (op, bg.rows, bg.r, bg.t)
            }
        };
        let ubg_norm =
            (ubg.iter().map(|c| c.norm_sqr()).sum::<f64>() * lat.harmonics() as f64).sqrt();
        let shift = Shift::new(&op, &lat, (p.eps, tensor), p.eps_binder, &ubg, params);
        Ok(System {
            shift,
            params,
            k2,
            op,
            lat,
            eps: p.eps,
            tensor,
            eps_binder: p.eps_binder,
            ubg,
            r_bg,
            t_bg,
            ubg_norm,
        })
    }

    /// The shape of the unknowns: (nz, ny, nx) for the scalar wave, (3 nz,
    /// ny, nx) for Maxwell's three components.
    pub fn unknown_dim(&self) -> (usize, usize, usize) {
        let (nz, ny, nx) = self.eps.dim();
        (self.components() * nz, ny, nx)
    }

    /// Number of field components (1 or 3).
    fn components(&self) -> usize {
        match self.op {
            BackgroundOperator::Scalar { .. } => 1,
            BackgroundOperator::Vector { .. } => 3,
        }
    }

    /// Rebuild the shifted form on background `bg` (time-marching needs the
    /// CBS shift); nothing happens if it is already the one in use.
    pub fn use_background(&mut self, bg: Background) {
        if self.shift.kind != bg {
            self.params.background = bg;
            self.shift = Shift::new(
                &self.op,
                &self.lat,
                (self.eps, self.tensor),
                self.eps_binder,
                &self.ubg,
                self.params,
            );
        }
    }

    /// Fresh working memory for this system's operations.
    pub fn scratch(&self) -> Scratch {
        let op = match &self.op {
            BackgroundOperator::Scalar { op, .. } => OpWorkspace::Scalar(op.workspace()),
            BackgroundOperator::Vector { op, .. } => OpWorkspace::Vector(op.workspace()),
        };
        Scratch {
            op,
            field: Array3::zeros(self.unknown_dim()),
        }
    }

    pub fn lattice(&self) -> &Lattice {
        &self.lat
    }

    /// Total permittivity per voxel, (nz, ny, nx) (its scalar part where
    /// [`System::tensor`] has terms).
    pub fn eps(&self) -> &Array3<C64> {
        self.eps
    }

    /// The tensor part of the permittivity; None: isotropic.
    pub fn tensor(&self) -> Option<&Anisotropy> {
        self.tensor
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
                let mut d = format!("mean background ⟨ε⟩ = {:.4}{:+.4}i", e.re, e.im);
                let (air_top, air_bottom) = background::air_cells(self.eps);
                for (zone, face, air) in [
                    (&self.shift.top, "top", air_top),
                    (&self.shift.bottom, "bottom", air_bottom),
                ] {
                    if let (Some(a), Some(b)) = (zone.first(), zone.last()) {
                        let cells = if air > zone.len() {
                            format!("{} of the {air}", zone.len())
                        } else {
                            zone.len().to_string()
                        };
                        d += &format!(
                            ", layered at the {face} over {cells} cells holding air (each its \
                             own mean, {:.4}{:+.4}i to {:.4}{:+.4}i)",
                            a.re, a.im, b.re, b.im
                        );
                    }
                }
                d
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
        on_field!(u, u => self.fill_start(u))
    }

    /// [`Self::set_start_field`] in one storage.
    pub fn fill_start<S: Storage>(&self, u: &mut Array3<S>) {
        let start = match self.shift.kind {
            Background::Mean => &self.shift.us,
            Background::Binder => &self.ubg,
        };
        for (j, mut slice) in u.outer_iter_mut().enumerate() {
            slice.fill(S::store(start[j]));
        }
    }

    /// `scr.field ← (V − C) x` with `V = k0²(ε − ε_b)` (ε a tensor
    /// where [`System::tensor`] has terms) and `C` the shift of each z cell
    /// (`None`: no shift).
    fn load_scaled<S: Storage>(&self, scr: &mut Scratch, x: &Array3<S>, shift: Option<&[C64]>) {
        let (k2, eb) = (self.k2, self.eps_binder);
        let one = match shift {
            None => Some(C64::new(0.0, 0.0)),
            Some(c) if c.iter().all(|&v| v == c[0]) => Some(c[0]),
            Some(_) => None,
        };
        for comp in 0..self.components() {
            match (one, shift) {
                (Some(c), _) => Zip::from(scr.field.slice_mut(self.block(comp)))
                    .and(x.slice(self.block(comp)))
                    .and(self.eps)
                    .par_for_each(|t, x, e| *t = (k2 * (e - eb) - c) * x.load()),
                (None, Some(cells)) => {
                    Zip::from(scr.field.slice_mut(self.block(comp)).outer_iter_mut())
                        .and(x.slice(self.block(comp)).outer_iter())
                        .and(self.eps.outer_iter())
                        .and(ndarray::ArrayView1::from(cells))
                        .par_for_each(|mut t, x, e, &c| {
                            Zip::from(&mut t)
                                .and(&x)
                                .and(&e)
                                .for_each(|t, x, e| *t = (k2 * (e - eb) - c) * x.load())
                        })
                }
                (None, None) => unreachable!("no shift is one shift"),
            }
        }
        if let Some(a) = self.tensor {
            tensor::add_contrast(a, k2, x, &mut scr.field);
        }
    }

    /// The unknowns of component `c`: z cells `c nz .. (c + 1) nz`, which
    /// meet the permittivity grid voxel for voxel.
    fn block(&self, c: usize) -> ndarray::SliceInfo<[ndarray::SliceInfoElem; 3], Ix3, Ix3> {
        let nz = self.eps.dim().0;
        s![c * nz..(c + 1) * nz, .., ..]
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
        self.load_scaled(scr, u, None);
        let lat = self.lat;
        let eb = self.eps_binder;
        match (&mut self.op, &mut scr.op) {
            (
                BackgroundOperator::Scalar {
                    op, binder: table, ..
                },
                OpWorkspace::Scalar(ws),
            ) => {
                let table = table.get_or_insert_with(|| GreenTable::new(&lat, C64::new(eb, 0.0)));
                op.apply(table, &mut scr.field, ws);
            }
            (BackgroundOperator::Vector { op, binder, .. }, OpWorkspace::Vector(ws)) => {
                let table =
                    binder.get_or_insert_with(|| Box::new(op.shift_tables(C64::new(0.0, 0.0))));
                op.apply_shifted(table, &mut scr.field, ws)
            }
            _ => unreachable!("a system's scratch is made by the system"),
        }
        self.finish_residual(scr, &self.ubg, u, out);
        self.norm(out)
    }

    /// Drop `G_b`'s tables (as large as a field) once Born is ruled out.
    pub fn release_binder(&mut self) {
        match &mut self.op {
            BackgroundOperator::Scalar { binder, .. } => *binder = None,
            BackgroundOperator::Vector { binder, .. } => *binder = None,
        }
    }

    /// `scr.field ← G_s scr.field`, the shifted operator of the equation.
    fn apply_shifted(&self, scr: &mut Scratch) {
        match (&self.op, &mut scr.op, &self.shift.table) {
            (
                BackgroundOperator::Scalar { op, .. },
                OpWorkspace::Scalar(ws),
                ShiftTables::Scalar(table),
            ) => op.apply_shifted_green(table, &mut scr.field, ws),
            (
                BackgroundOperator::Vector { op, .. },
                OpWorkspace::Vector(ws),
                ShiftTables::Vector(table),
            ) => op.apply_shifted(table, &mut scr.field, ws),
            _ => unreachable!("a system's scratch is made by the system"),
        }
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
        self.load_scaled(scr, u, Some(&self.shift.c));
        self.apply_shifted(scr);
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
        self.load_scaled(scr, x, Some(&self.shift.c));
        self.apply_shifted(scr);
        Zip::from(&mut *out)
            .and(x)
            .and(&scr.field)
            .par_for_each(|o, x, t| *o = S::store(x.load() - t));
    }

    /// `out ← P (x − G_s V' x)` (the preconditioned shifted operator, as
    /// [`System::apply_a_shifted`] then [`System::precondition`]), returning
    /// `(‖out‖², ⟨out, w⟩)` of the stored `out`. On the mean background (no
    /// preconditioner) the source `(V − C) x` is made slice by slice as the
    /// forward transform reads it, and the subtraction and both sums are
    /// done slice by slice as the inverse transform writes: no whole field
    /// is stored between, one pass over memory instead of five. The Krylov
    /// methods' vector work is bound by memory traffic, not arithmetic
    /// (docs/PERFORMANCE.md, "Maxwell").
    /// Sums run per z-slice and then in a fixed order (thread-count
    /// independent).
    pub fn apply_pa_sums<S: Storage>(
        &self,
        scr: &mut Scratch,
        x: &Array3<S>,
        out: &mut Array3<S>,
        w: &Array3<S>,
    ) -> (f64, C64) {
        let (k2, eb, nz) = (self.k2, self.eps_binder, self.eps.dim().0);
        let plane = self.lat.nx * self.lat.ny;
        let (c, tensor) = (&self.shift.c, self.tensor);
        let (Some(eps), Some(xs), Some(ws), None) = (
            self.eps.as_slice(),
            x.as_slice(),
            w.as_slice(),
            self.shift.cbs,
        ) else {
            // A preconditioner, or a grid not in standard layout (a layer
            // lit from below is a flipped view): the steps one by one.
            self.apply_a_shifted(scr, x, out);
            self.precondition(out);
            return (norm_sqr(out), dot(out, w));
        };
        let row = |k: usize| k * plane..(k + 1) * plane;
        // Row k of the source (V − C) x: component k / nz, z cell k % nz.
        let load = |k: usize, p: &mut [C64]| {
            let (comp, iz) = (k / nz, k % nz);
            let cz = c[iz];
            for ((p, e), x) in p.iter_mut().zip(&eps[row(iz)]).zip(&xs[row(k)]) {
                *p = (k2 * (e - eb) - cz) * x.load();
            }
            if let Some(a) = tensor {
                tensor::add_contrast_plane(a, k2, xs, comp, iz, p);
            }
        };
        // out = x − G_s (V − C) x, with its sums.
        let store = |k: usize, t: &[C64], mut o: ArrayViewMut2<S>| {
            let o = o.as_slice_mut().expect("contiguous row");
            let (mut nn, mut d) = (0.0, C64::new(0.0, 0.0));
            for (((o, t), x), w) in o.iter_mut().zip(t).zip(&xs[row(k)]).zip(&ws[row(k)]) {
                *o = S::store(x.load() - t);
                let v = o.load();
                nn += v.norm_sqr();
                d += v.conj() * w.load();
            }
            (nn, d)
        };
        let parts = match (&self.op, &mut scr.op, &self.shift.table) {
            (
                BackgroundOperator::Scalar { op, .. },
                OpWorkspace::Scalar(ws),
                ShiftTables::Scalar(table),
            ) => op.apply_shifted_green_with(table, ws, load, out, store),
            (
                BackgroundOperator::Vector { op, .. },
                OpWorkspace::Vector(ws),
                ShiftTables::Vector(table),
            ) => op.apply_shifted_with(table, ws, load, out, store),
            _ => unreachable!("a system's scratch is made by the system"),
        };
        parts
            .iter()
            .fold((0.0, C64::new(0.0, 0.0)), |(a, b), &(nn, d)| {
                (a + nn, b + d)
            })
    }

    /// `x ← γ x`, γ = 1 + i(ε − ε_r)/ε_s: the CBS preconditioner of the
    /// shifted form; the identity on the mean background.
    pub fn precondition<S: Storage>(&self, x: &mut Array3<S>) {
        let Some((er, es)) = self.shift.cbs else {
            return;
        };
        for c in 0..self.components() {
            Zip::from(x.slice_mut(self.block(c)))
                .and(self.eps)
                .par_for_each(|x, e| *x = S::store(x.load() * (1.0 + C64::i() * (e - er) / es)));
        }
        if let Some(a) = self.tensor {
            tensor::add_precondition(a, self.eps.view(), er, es, x);
        }
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
        let lattice = self.lat;
        let vector = match self.op {
            BackgroundOperator::Scalar { .. } => None,
            BackgroundOperator::Vector { pol, .. } => Some(pol),
        };
        drop(scr);
        drop(self);
        let [r_s, r_p] = r;
        let [t_s, t_p] = t;
        Solution {
            lattice,
            field: u.mapv(S::load),
            r: r_s,
            t: t_s,
            absorption,
            record,
            vector: vector.map(|incident| VectorAmplitudes { incident, r_p, t_p }),
        }
    }

    /// Far-field amplitudes (`[s, p]`; `[u, 0]` for the scalar wave) and
    /// the absorption of a field.
    #[allow(clippy::type_complexity)]
    fn outputs<S: Storage>(
        &self,
        scr: &mut Scratch,
        u: &Array3<S>,
    ) -> ([Array2<C64>; 2], [Array2<C64>; 2], f64) {
        let lat = self.lat;
        let z = || Array2::zeros((lat.nx, lat.ny));
        let mut r = [z(), z()];
        let mut t = [z(), z()];
        // G_b V u = G_b(V' u + C u) = w + G_b C(u − G_s V' u), and at the
        // solution u − G_s V' u = u_s (harmonic 00 only): boundary values of
        // w from the shifted sweep, of G_b C u_s precomputed with the shift.
        self.load_scaled(scr, u, Some(&self.shift.c));
        match (&self.op, &mut scr.op, &self.shift.table) {
            (
                BackgroundOperator::Scalar { op, .. },
                OpWorkspace::Scalar(ws),
                ShiftTables::Scalar(table),
            ) => {
                let [r0, _] = &mut r;
                let [t0, _] = &mut t;
                op.shifted_boundary(table, &mut scr.field, ws, r0, t0);
            }
            (BackgroundOperator::Vector { op, .. }, OpWorkspace::Vector(ws), _) => {
                op.boundary_amplitudes(&self.shift.c, &mut scr.field, ws, &mut r, &mut t);
            }
            _ => unreachable!("a system's scratch is made by the system"),
        }
        for k in 0..2 {
            r[k][[0, 0]] += self.r_bg[k] + self.shift.us_top[k];
            t[k][[0, 0]] += self.t_bg[k] + self.shift.us_bottom[k];
        }
        let dz = lat.size_nm[2] / lat.nz as f64;
        let s: f64 = (0..self.components())
            .map(|c| {
                let f = |u: &S, e: &C64| e.im * u.load().norm_sqr();
                sum_slices(u.slice(self.block(c)), f, self.eps.view())
            })
            .sum::<f64>()
            + self.tensor.map_or(0.0, |a| tensor::absorption(a, u));
        let beta00 = lat.beta(0, 0).re;
        let absorption = lat.k0 * lat.k0 / beta00 * s * dz / lat.harmonics() as f64;
        (r, t, absorption)
    }
}

impl Shift {
    fn new(
        op: &BackgroundOperator,
        lat: &Lattice,
        (eps, tensor): (&Array3<C64>, Option<&Anisotropy>),
        eps_binder: f64,
        ubg: &[C64],
        params: ShiftParams,
    ) -> Shift {
        let kind = params.background;
        let nz = lat.nz;
        let (profile, cbs) = match kind {
            Background::Binder => {
                let (er, rad) = shift_of(eps, tensor, eps_binder);
                let es = (params.margin * rad).max(1e-9);
                (vec![C64::new(er, es); nz], Some((er, es)))
            }
            Background::Mean => (mean_profile(eps, tensor, lat, params), None),
        };
        let k2 = lat.k0 * lat.k0;
        let c: Vec<C64> = profile.iter().map(|e| k2 * (e - eps_binder)).collect();
        let zero = vec![C64::new(0.0, 0.0); nz];
        // u_s = (I − G_b C)⁻¹ u_bg = u_bg + G_s C u_bg, and the boundary
        // values of G_b C u_s (C acts on each component's z cell; one shift
        // is applied after the operator, as `c G_s u_bg` and `c G_b u_s`).
        let one = c.iter().all(|&v| v == c[0]);
        let times_c = |rows: &[C64]| -> Vec<C64> {
            if one {
                rows.to_vec()
            } else {
                rows.iter()
                    .enumerate()
                    .map(|(j, v)| c[j % nz] * v)
                    .collect()
            }
        };
        let after = |v: C64| if one { c[0] * v } else { v };
        let (table, us, us_top, us_bottom) = match op {
            BackgroundOperator::Scalar {
                top00, bottom00, ..
            } => {
                let table = ShiftTable::layered(lat, eps_binder, &c);
                let mut scr = BandScratch::new(lat.nz);
                scr.column().copy_from_slice(ubg);
                table.solve_column(0, &mut scr);
                let us = scr.column().to_vec();
                let cus = times_c(&us);
                let top = after(top00.iter().zip(&cus).map(|(w, u)| w * u).sum());
                let bottom = after(bottom00.iter().zip(&cus).map(|(w, u)| w * u).sum());
                (
                    ShiftTables::Scalar(Box::new(table)),
                    us,
                    [top, zero[0]],
                    [bottom, zero[0]],
                )
            }
            BackgroundOperator::Vector { op, .. } => {
                let (gs, _, _) = op.harmonic00(&c, &times_c(ubg));
                let us: Vec<C64> = ubg.iter().zip(&gs).map(|(u, g)| u + after(*g)).collect();
                let (_, top, bottom) = op.harmonic00(&zero, &times_c(&us));
                let (top, bottom) = (top.map(after), bottom.map(after));
                (
                    ShiftTables::Vector(Box::new(op.layered_shift_tables(&c))),
                    us,
                    top,
                    bottom,
                )
            }
        };
        let us_norm =
            (us.iter().map(|c| c.norm_sqr()).sum::<f64>() * lat.harmonics() as f64).sqrt();
        let (b0, b1) = super::settle::bulk_run(&profile);
        Shift {
            kind,
            eps: profile[b0],
            top: profile[..b0].to_vec(),
            bottom: profile[b1..].to_vec(),
            cbs,
            c,
            table,
            us,
            us_norm,
            us_top,
            us_bottom,
        }
    }
}
