//! The dyadic Green's operator of the background slab on the 3-D grid
//! (METHOD §9): Maxwell's equations in the same Bloch slab as the scalar
//! [`operator`](super::operator).
//!
//! The unknown is the electric field's three Cartesian components stacked
//! along the first axis, `(3 nz, ny, nx)`: E_x in slices `0..nz`, E_y in
//! `nz..2nz`, E_z in `2nz..3nz`. Every iterative method therefore works on
//! it as on a scalar field. One application: a forward 2-D FFT of every
//! slice (three times the scalar operator's), per harmonic a rotation of
//! (E_x, E_y) to (E_κ, E_s), the TE column solve on E_s and the TM column
//! solve on (E_κ, E_z) ([`column`]), the rotation back and the inverse FFTs.
//! For a harmonic with κ = 0 (normal incidence's specular order) ê_κ is the
//! plane of incidence's azimuth, so that s and p keep their meaning there.
//!
//! Takes a [`Lattice`], the binder permittivity and the shift `c`; applies
//! `G_s = (I − c G_b)⁻¹ G_b` (`c = 0`: `G_b`) to a field, gives the boundary
//! amplitudes of its continuous field per order in s and p, and the
//! background slab's own response to an s or p plane wave.

pub mod column;
mod shifted;
mod tm_sweep;
pub(crate) use tm_sweep::ZONE_CELL_BYTES as TM_ZONE_CELL_BYTES;

pub use shifted::VectorShift;

use super::fft::{Fft2, FftScratch};
use super::jones::Jones;
use super::lattice::Lattice;
use super::operator::for_each_row;
use crate::config::Linear;
use column::{Column, ColumnScratch, Harmonic, Incident, Pol};
use ndarray::{Array2, Array3, ArrayViewMut2, Axis};
use num_complex::Complex64 as C64;
use shifted::RowPair;

const ZERO: C64 = C64 { re: 0.0, im: 0.0 };

/// FFT plans, the lattice and the in-plane reference direction.
pub struct VectorOperator {
    pub lat: Lattice,
    fft: Fft2,
    eps_b: f64,
    /// Unit vector ê_κ for a harmonic with κ = 0.
    reference: [f64; 2],
}

/// Scratch of one application, owned by the caller.
pub struct VectorWorkspace {
    spec: Array3<C64>,
    fft: FftScratch,
    tasks: Vec<HarmonicScratch>,
    /// The near-grazing harmonics' columns of the row path.
    dense: Vec<C64>,
}

/// One task's columns (sources and outputs in (s, κ, z)) and rows.
struct HarmonicScratch {
    col: ColumnScratch,
    rows: RowPair,
    bs: Vec<C64>,
    bk: Vec<C64>,
    bz: Vec<C64>,
    ws: Vec<C64>,
    wk: Vec<C64>,
    wz: Vec<C64>,
}

impl HarmonicScratch {
    fn new(nz: usize, ny: usize) -> Self {
        let z = || vec![ZERO; nz];
        HarmonicScratch {
            col: ColumnScratch::new(nz),
            rows: RowPair::new(nz, ny),
            bs: z(),
            bk: z(),
            bz: z(),
            ws: z(),
            wk: z(),
            wz: z(),
        }
    }
}

/// Boundary values of one harmonic: (s, κ) components at z = 0 and z = H.
#[derive(Debug, Clone, Copy, Default)]
pub struct Boundary {
    pub top_s: C64,
    pub top_k: C64,
    pub bottom_s: C64,
    pub bottom_k: C64,
}

/// The background slab's answer to one incident plane wave: the cell
/// averages of (E_x, E_y, E_z) per z (constant in x, y), and the specular
/// order's amplitudes in s and p.
pub struct BackgroundField {
    /// Length 3 nz, in the stacked layout.
    pub rows: Vec<C64>,
    pub r: [C64; 2],
    pub t: [C64; 2],
}

impl VectorOperator {
    /// The operator of `lat` with the binder `eps_b` inside the slab; the
    /// plane of incidence's azimuth gives ê_κ where κ = 0.
    pub fn new(lat: Lattice, eps_b: f64, azimuth_deg: f64) -> Self {
        let a = azimuth_deg.to_radians();
        VectorOperator {
            fft: Fft2::new(lat.nx, lat.ny),
            lat,
            eps_b,
            reference: [a.cos(), a.sin()],
        }
    }

    pub fn workspace(&self) -> VectorWorkspace {
        let (nx, ny, nz) = (self.lat.nx, self.lat.ny, self.lat.nz);
        let tasks = nx.min(4 * rayon::current_num_threads()).max(1);
        VectorWorkspace {
            spec: Array3::zeros((3 * nz, nx, ny)),
            fft: self.fft.scratch(3 * nz),
            tasks: (0..tasks).map(|_| HarmonicScratch::new(nz, ny)).collect(),
            dense: Vec::new(),
        }
    }

    /// ê_κ and the harmonic's constants at FFT indices (ix, iy).
    fn harmonic(&self, ix: usize, iy: usize) -> ([f64; 2], Harmonic) {
        let [kx, ky] = self.lat.kappa(ix, iy);
        let h = Harmonic::at(&self.lat, self.eps_b, ix, iy);
        let unit = if h.kappa > 1e-12 * self.lat.k0 {
            [kx / h.kappa, ky / h.kappa]
        } else {
            self.reference
        };
        (unit, h)
    }

    /// `field ← G_s field` with the shift `c[j]` of each z cell (`c = 0`:
    /// the binder's `G_b`).
    pub fn apply(&self, c: &[C64], field: &mut Array3<C64>, ws: &mut VectorWorkspace) {
        let (nx, ny) = (self.lat.nx, self.lat.ny);
        let norm = 1.0 / (nx * ny) as f64;
        self.fft.forward(field, &mut ws.spec, &mut ws.fft);
        for_each_row(&mut ws.spec, &mut ws.tasks, |ix, row, scr| {
            for iy in 0..ny {
                self.column(ix, iy, iy, c, row, scr, norm);
            }
        });
        self.fft.inverse(&mut ws.spec, field, &mut ws.fft);
    }

    /// Load harmonic (ix, iy)'s column from column `at` of `row` ((3nz, ·),
    /// its spectral row or a copy of the one column), solve, store back.
    #[allow(clippy::too_many_arguments)]
    fn column(
        &self,
        ix: usize,
        iy: usize,
        at: usize,
        c: &[C64],
        row: &mut ArrayViewMut2<C64>,
        scr: &mut HarmonicScratch,
        norm: f64,
    ) -> Boundary {
        let nz = self.lat.nz;
        let ([ux, uy], h) = self.harmonic(ix, iy);
        for j in 0..nz {
            let (ex, ey) = (row[[j, at]], row[[nz + j, at]]);
            scr.bk[j] = (ux * ex + uy * ey) * norm;
            scr.bs[j] = (-uy * ex + ux * ey) * norm;
            scr.bz[j] = row[[2 * nz + j, at]] * norm;
        }
        let (top_s, bottom_s) = column::solve(
            &h,
            Pol::Te,
            c,
            Incident::None,
            &mut Column {
                b_f: &scr.bs,
                b_z: &scr.bz,
                w_f: &mut scr.ws,
                w_z: &mut scr.wz,
            },
            &mut scr.col,
        );
        let (top_k, bottom_k) = column::solve(
            &h,
            Pol::Tm,
            c,
            Incident::None,
            &mut Column {
                b_f: &scr.bk,
                b_z: &scr.bz,
                w_f: &mut scr.wk,
                w_z: &mut scr.wz,
            },
            &mut scr.col,
        );
        for j in 0..nz {
            let (ek, es) = (scr.wk[j], scr.ws[j]);
            row[[j, at]] = ux * ek - uy * es;
            row[[nz + j, at]] = uy * ek + ux * es;
            row[[2 * nz + j, at]] = scr.wz[j];
        }
        Boundary {
            top_s,
            top_k,
            bottom_s,
            bottom_k,
        }
    }

    /// Boundary values of the continuous field `G_b(x + C G_s x)` per
    /// harmonic for a real-space source `x` (consumed as scratch), as order
    /// amplitudes in s and p: `r[0], t[0]` s, `r[1], t[1]` p, each (nx, ny).
    pub fn boundary_amplitudes(
        &self,
        c: &[C64],
        source: &mut Array3<C64>,
        ws: &mut VectorWorkspace,
        r: &mut [Array2<C64>; 2],
        t: &mut [Array2<C64>; 2],
    ) {
        let (nx, ny) = (self.lat.nx, self.lat.ny);
        let norm = 1.0 / (nx * ny) as f64;
        self.fft.forward(source, &mut ws.spec, &mut ws.fft);
        let scr = &mut ws.tasks[0];
        for ix in 0..nx {
            let mut row = ws.spec.index_axis_mut(Axis(1), ix);
            for iy in 0..ny {
                let b = self.column(ix, iy, iy, c, &mut row, scr, norm);
                let p = self.p_factor(ix, iy);
                r[0][[ix, iy]] = b.top_s;
                t[0][[ix, iy]] = b.bottom_s;
                r[1][[ix, iy]] = b.top_k * p;
                t[1][[ix, iy]] = b.bottom_k * p;
            }
        }
    }

    /// `E_p = E_κ k0/β` of an outgoing order (0 for β = 0: no flux).
    pub fn p_factor(&self, ix: usize, iy: usize) -> C64 {
        let beta = self.lat.beta(ix, iy);
        if beta.norm() == 0.0 {
            ZERO
        } else {
            self.lat.k0 / beta
        }
    }

    /// The background slab's response to a unit plane wave of polarisation
    /// state `pol` (harmonic 00): the superposition of its s and p parts.
    pub fn background(&self, pol: Jones) -> BackgroundField {
        let nz = self.lat.nz;
        let mut out = BackgroundField {
            rows: vec![ZERO; 3 * nz],
            r: [ZERO; 2],
            t: [ZERO; 2],
        };
        for (l, a) in [(Linear::S, pol.s), (Linear::P, pol.p)] {
            if a == ZERO {
                continue;
            }
            let f = self.background_linear(l);
            for (o, v) in out.rows.iter_mut().zip(&f.rows) {
                *o += a * v;
            }
            for k in 0..2 {
                out.r[k] += a * f.r[k];
                out.t[k] += a * f.t[k];
            }
        }
        out
    }

    /// The background slab's response to a unit plane wave of linear
    /// polarisation `pol`.
    fn background_linear(&self, pol: Linear) -> BackgroundField {
        let nz = self.lat.nz;
        let ([ux, uy], h) = self.harmonic(0, 0);
        let zero = vec![ZERO; nz];
        let (mut wf, mut wz) = (vec![ZERO; nz], vec![ZERO; nz]);
        let mut scr = ColumnScratch::new(nz);
        let (p, inc) = match pol {
            Linear::S => (Pol::Te, Incident::Te),
            Linear::P => (Pol::Tm, Incident::Tm),
        };
        let (top, bottom) = column::solve(
            &h,
            p,
            &zero,
            inc,
            &mut Column {
                b_f: &zero,
                b_z: &zero,
                w_f: &mut wf,
                w_z: &mut wz,
            },
            &mut scr,
        );
        let mut rows = vec![ZERO; 3 * nz];
        let (mut r, mut t) = ([ZERO; 2], [ZERO; 2]);
        match pol {
            Linear::S => {
                for j in 0..nz {
                    rows[j] = -uy * wf[j];
                    rows[nz + j] = ux * wf[j];
                }
                r[0] = top - 1.0;
                t[0] = bottom;
            }
            Linear::P => {
                for j in 0..nz {
                    rows[j] = ux * wf[j];
                    rows[nz + j] = uy * wf[j];
                    rows[2 * nz + j] = wz[j];
                }
                let f = self.p_factor(0, 0);
                r[1] = (top - h.beta / self.lat.k0) * f;
                t[1] = bottom * f;
            }
        }
        BackgroundField { rows, r, t }
    }

    /// `(G_s b, boundary)` for a harmonic-00 column `b` given as stacked
    /// rows (3 nz): the cell averages of `G_s b` (shift `c[j]` per z cell)
    /// and the s/p amplitudes of the continuous `G_b(b + C G_s b)` at the
    /// boundaries.
    pub fn harmonic00(&self, c: &[C64], rows: &[C64]) -> (Vec<C64>, [C64; 2], [C64; 2]) {
        let nz = self.lat.nz;
        // Harmonic 00's spectral row, one column wide.
        let mut row = Array2::from_shape_fn((3 * nz, 1), |(j, _)| rows[j]);
        let mut scr = HarmonicScratch::new(nz, 1);
        let b = self.column(0, 0, 0, c, &mut row.view_mut(), &mut scr, 1.0);
        let p = self.p_factor(0, 0);
        (
            row.column(0).to_vec(),
            [b.top_s, b.top_k * p],
            [b.bottom_s, b.bottom_k * p],
        )
    }
}
