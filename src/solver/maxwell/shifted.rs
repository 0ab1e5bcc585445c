//! The shifted vector operator `G_s` on whole spectral rows, what the
//! iterative methods apply every step: per row, the rotation of
//! (E_x, E_y) to (E_s, E_κ) in place, TE by the scalar equation's
//! [`ShiftTable`] (TE is the scalar kernel), TM by the [`TmTable`] sweep,
//! both `W` harmonics per operation, and the rotation back. Near-grazing
//! harmonics take the contour-averaged column solve of
//! [`column`](super::column) on their saved columns, as the scalar operator
//! does with its dense path.
//!
//! The column solve ([`VectorOperator::apply`]) stays the reference: the
//! row path equals it to rounding (tests below).

use super::tm_sweep::{TmRowScratch, TmTable};
use super::{VectorOperator, VectorWorkspace};
use crate::solver::operator::for_each_row;
use crate::solver::shift::{RowScratch, ShiftTable};
use ndarray::{s, Array2, Array3, ArrayViewMut2};
use num_complex::Complex64 as C64;

/// The tables of one shift profile (`c[j]` per z cell) for both
/// polarisations, and ê_κ per harmonic.
pub struct VectorShift {
    pub c: Vec<C64>,
    te: ShiftTable,
    tm: TmTable,
    /// ê_κ per spectral index ix·ny + iy.
    units: Vec<[f64; 2]>,
}

/// Per-row scratch of the row path.
pub(super) struct RowPair {
    te: RowScratch,
    tm: TmRowScratch,
}

impl RowPair {
    pub(super) fn new(nz: usize, ny: usize) -> Self {
        RowPair {
            te: RowScratch::new(nz, ny),
            tm: TmRowScratch::new(nz, ny),
        }
    }
}

impl VectorShift {
    /// Down-sweep cells stored by both tables (a measure of their memory;
    /// at most N − 1 per harmonic and table).
    pub fn stored_cells(&self) -> usize {
        self.te.stored_cells() + self.tm.stored_cells()
    }
}

impl VectorOperator {
    /// The row sweeps' tables for the shift `c` in every cell.
    pub fn shift_tables(&self, c: C64) -> VectorShift {
        self.layered_shift_tables(&vec![c; self.lat.nz])
    }

    /// The row sweeps' tables for the shift `c[j]` of each z cell.
    pub fn layered_shift_tables(&self, c: &[C64]) -> VectorShift {
        let (nx, ny) = (self.lat.nx, self.lat.ny);
        let te = ShiftTable::layered(&self.lat, self.eps_b, c);
        let tm = TmTable::new(&self.lat, self.eps_b, c);
        debug_assert!(te.dense_indices().eq(tm.dense_indices().iter().copied()));
        let units = (0..nx * ny)
            .map(|i| self.harmonic(i / ny, i % ny).0)
            .collect();
        VectorShift {
            c: c.to_vec(),
            te,
            tm,
            units,
        }
    }

    /// `field ← G_s field` for the shift of `tables`; equals
    /// [`Self::apply`] with the same `c`.
    pub fn apply_shifted(
        &self,
        tables: &VectorShift,
        field: &mut Array3<C64>,
        ws: &mut VectorWorkspace,
    ) {
        self.fft.forward(field, &mut ws.spec, &mut ws.fft);
        self.shifted_spectral(tables, ws);
        self.fft.inverse(&mut ws.spec, field, &mut ws.fft);
    }

    /// [`VectorOperator::apply_shifted`] of the source whose rows
    /// `load(k, plane)` makes (row `k` of the stacked unknowns, (ny, nx)),
    /// each output row handed to `store(k, plane, out's row k)`: no
    /// whole field is stored between ([`Fft2::forward_from`]).
    pub fn apply_shifted_with<S: Send + Sync, R: Send>(
        &self,
        tables: &VectorShift,
        ws: &mut VectorWorkspace,
        load: impl Fn(usize, &mut [C64]) + Sync,
        out: &mut Array3<S>,
        store: impl Fn(usize, &[C64], ArrayViewMut2<S>) -> R + Sync,
    ) -> Vec<R> {
        self.fft.forward_from(&mut ws.spec, &mut ws.fft, load);
        self.shifted_spectral(tables, ws);
        self.fft.inverse_into(&mut ws.spec, &mut ws.fft, out, store)
    }

    /// `G_s` on the spectrum in `ws` (between the transforms).
    fn shifted_spectral(&self, tables: &VectorShift, ws: &mut VectorWorkspace) {
        let (nx, ny, nz) = (self.lat.nx, self.lat.ny, self.lat.nz);
        let norm = 1.0 / (nx * ny) as f64;
        let c = &tables.c;
        // Near-grazing harmonics: the column solve on their saved columns.
        let mut dense = std::mem::take(&mut ws.dense);
        dense.clear();
        for &h in tables.tm.dense_indices() {
            let (ix, iy) = (h / ny, h % ny);
            let mut col = Array2::from_shape_fn((3 * nz, 1), |(j, _)| ws.spec[[j, ix, iy]]);
            self.column(ix, iy, 0, c, &mut col.view_mut(), &mut ws.tasks[0], norm);
            dense.extend(col.iter());
        }
        for_each_row(&mut ws.spec, &mut ws.tasks, |ix, row, scr| {
            let units = &tables.units[ix * ny..(ix + 1) * ny];
            // (E_x, E_y) → (E_s, E_κ) in rows 0..nz and nz..2nz.
            rotate(row, nz, units, |ex, ey, [ux, uy]| {
                (-uy * ex + ux * ey, ux * ex + uy * ey)
            });
            let rows = &mut scr.rows;
            tables
                .te
                .shifted_green_row(ix, &mut row.slice_mut(s![0..nz, ..]), &mut rows.te, true);
            let (mut f, mut z) = row.multi_slice_mut((s![nz..2 * nz, ..], s![2 * nz.., ..]));
            tables.tm.row(ix, &mut f, &mut z, &mut rows.tm, norm);
            // (E_s, E_κ) → (E_x, E_y).
            rotate(row, nz, units, |es, ek, [ux, uy]| {
                (ux * ek - uy * es, uy * ek + ux * es)
            });
        });
        for (k, &h) in tables.tm.dense_indices().iter().enumerate() {
            let (ix, iy) = (h / ny, h % ny);
            for j in 0..3 * nz {
                ws.spec[[j, ix, iy]] = dense[k * 3 * nz + j];
            }
        }
        ws.dense = dense;
    }
}

/// Rows `j` and `nz + j` of `row` as a pair `(a, b) ← f(a, b, ê_κ)` per
/// harmonic, for every `j < nz`.
#[inline(always)]
fn rotate(
    row: &mut ArrayViewMut2<C64>,
    nz: usize,
    units: &[[f64; 2]],
    f: impl Fn(C64, C64, [f64; 2]) -> (C64, C64),
) {
    for j in 0..nz {
        let (mut a, mut b) = row.multi_slice_mut((s![j, ..], s![nz + j, ..]));
        let (a, b) = (
            a.as_slice_mut().expect("contiguous spectral row"),
            b.as_slice_mut().expect("contiguous spectral row"),
        );
        for ((a, b), &u) in a.iter_mut().zip(b.iter_mut()).zip(units) {
            (*a, *b) = f(*a, *b, u);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Problem;

    fn field(nz: usize, ny: usize, nx: usize) -> Array3<C64> {
        Array3::from_shape_fn((3 * nz, ny, nx), |(k, j, i)| {
            C64::new(
                ((i * 7 + j * 3 + k) as f64 * 0.37).sin(),
                ((i + 2 * j + 5 * k) as f64 * 0.21).cos(),
            )
        })
    }

    /// The row path against the column path on one field, to rounding.
    fn paths_agree(op: &VectorOperator, tables: &VectorShift, what: &str) {
        let lat = op.lat;
        let mut ws = op.workspace();
        let mut want = field(lat.nz, lat.ny, lat.nx);
        let mut got = want.clone();
        op.apply(&tables.c, &mut want, &mut ws);
        op.apply_shifted(tables, &mut got, &mut ws);
        let scale = want.iter().map(|w| w.norm()).fold(0.0, f64::max);
        for (g, w) in got.iter().zip(want.iter()) {
            assert!((g - w).norm() < 1e-10 * scale, "{what}: {g} vs {w}");
        }
    }

    /// The row sweeps equal the column solves (band elimination with
    /// pivoting) for a lossy CBS-like shift, a nearly lossless
    /// mean-background shift, no shift and a layered top, at normal and
    /// oblique incidence.
    #[test]
    fn row_path_equals_column_path() {
        let eps_b = 1.558f64.powi(2);
        for (dims, polar) in [([6usize, 5usize, 9usize], 30.0), ([9, 8, 4], 0.0)] {
            let lat = Problem::lattice(dims, [900.0, 800.0, 500.0], 480.0, polar, 20.0);
            let op = VectorOperator::new(lat, eps_b, 20.0);
            // CBS-like, a nearly lossless mean background, and c = 0 (G_b).
            for bg in [
                C64::new(2.1, 0.9),
                C64::new(2.6, 1e-6),
                C64::new(eps_b, 0.0),
            ] {
                let c = lat.k0 * lat.k0 * (bg - eps_b);
                paths_agree(&op, &op.shift_tables(c), &format!("{dims:?} {bg}"));
            }
            // A layered top (air-like cells, then the mean below).
            let mut layered = vec![lat.k0 * lat.k0 * (C64::new(2.3, 0.2) - eps_b); dims[2]];
            layered[0] = lat.k0 * lat.k0 * (C64::new(1.05, 0.2) - eps_b);
            layered[1] = lat.k0 * lat.k0 * (C64::new(1.6, 0.2) - eps_b);
            let tables = op.layered_shift_tables(&layered);
            assert_eq!(tables.tm.bulk, (2, dims[2]));
            paths_agree(&op, &tables, &format!("{dims:?} layered"));
            // ... and a layered bottom as well (a layer lit from below).
            layered[dims[2] - 1] = lat.k0 * lat.k0 * (C64::new(1.1, 0.3) - eps_b);
            let tables = op.layered_shift_tables(&layered);
            if dims[2] > 5 {
                assert_eq!(tables.tm.bulk, (2, dims[2] - 1));
            }
            paths_agree(&op, &tables, &format!("{dims:?} layered at both faces"));
        }
    }

    /// On a lossy shift the sweeps settle: a deep grid stores fewer cells
    /// than N − 1 per harmonic and table, and the sweeps that reuse the last
    /// stored cell still equal the column solves.
    #[test]
    fn settled_cells_are_reused_exactly() {
        let eps_b = 1.558f64.powi(2);
        let lat = Problem::lattice([4, 4, 80], [600.0, 600.0, 8000.0], 480.0, 30.0, 0.0);
        let op = VectorOperator::new(lat, eps_b, 0.0);
        let c = lat.k0 * lat.k0 * (C64::new(2.1, 0.9) - eps_b);
        let tables = op.shift_tables(c);
        let full = lat.harmonics() * (lat.nz - 1);
        assert!(
            tables.tm.stored_cells() < full,
            "{}",
            tables.tm.stored_cells()
        );
        paths_agree(&op, &tables, "settled");
    }

    /// Layered zones of `t` and `b` cells store at most `t + b` cells more
    /// per harmonic in each table than one shift does: what the memory
    /// model counts for them (`solver::zone_cell_bytes`).
    #[test]
    fn layered_zones_store_their_own_cells_and_no_more() {
        let eps_b = 1.558f64.powi(2);
        let lat = Problem::lattice([12, 12, 40], [600.0, 600.0, 800.0], 400.0, 0.0, 0.0);
        let op = VectorOperator::new(lat, eps_b, 0.0);
        let k2 = lat.k0 * lat.k0;
        let bulk = k2 * (C64::new(2.16, 0.19) - eps_b);
        let uniform = op.shift_tables(bulk);
        let (t, b) = (10, 10);
        let mut c = vec![bulk; 40];
        for (j, cj) in c.iter_mut().take(t).enumerate() {
            *cj = k2 * (C64::new(1.02 + 0.1 * j as f64, 0.19) - eps_b);
        }
        for (j, cj) in c.iter_mut().rev().take(b).enumerate() {
            *cj = k2 * (C64::new(2.2 + 0.01 * j as f64, 0.19) - eps_b);
        }
        let layered = op.layered_shift_tables(&c);
        for (name, more) in [
            ("TE", layered.te.stored_cells() - uniform.te.stored_cells()),
            ("TM", layered.tm.stored_cells() - uniform.tm.stored_cells()),
        ] {
            // The cells after the top zone settle as one shift's first cells do.
            assert!(
                more > 0 && more <= lat.harmonics() * (t + b),
                "{name}: {more} more cells"
            );
        }
        paths_agree(&op, &layered, "zones of 10 cells at both faces");
    }

    /// A harmonic grazing inside the binder takes the column path: the
    /// lattice is chosen so that order (1, 0) has κ = k0 n_b exactly.
    #[test]
    fn grazing_harmonic_uses_the_column_path() {
        let eps_b = 1.558f64.powi(2);
        let lambda = 480.0;
        let period = lambda / 1.558;
        let lat = Problem::lattice([4, 4, 6], [period, period, 400.0], lambda, 0.0, 0.0);
        let op = VectorOperator::new(lat, eps_b, 0.0);
        let c = lat.k0 * lat.k0 * C64::new(0.5, 0.7);
        let tables = op.shift_tables(c);
        assert!(!tables.tm.dense_indices().is_empty());
        paths_agree(&op, &tables, "grazing");
    }
}
