//! Uniform cell grid over the fragment, periodic in x and y, bounded in z,
//! shared by every neighbour search of the geometry stage (RSA, the
//! statistics, Monte Carlo equilibration and the dynamics packer).
//!
//! Takes a box (`size`, optionally shifted in z), a smallest cell width and
//! an expected item count; gives one position → cell mapping
//! ([`CellGrid::coords`], [`CellGrid::flat`]) and one stencil iteration
//! ([`CellGrid::any_cell`]: the cells within `k` cells of a cell, each once,
//! z then y then x). Cells are at least `min_cell` wide along every axis, so
//! with `min_cell` the interaction range every partner lies in the 3×3×3
//! block around a cell. Three storages sit on the same indexing:
//! - [`CellList`]: insert-only spheres with their owners (intrusive singly
//!   linked lists; RSA, statistics, smallest gap);
//! - [`LinkedCells`]: movable items (doubly linked lists, O(1) moves;
//!   Monte Carlo, dynamics);
//! - [`Bins`]: a counting-sort snapshot of positions, each cell's items
//!   contiguous (the dynamics packer's Verlet list build).

mod bins;
mod linked;
mod list;

pub(crate) use bins::Bins;
pub(crate) use linked::LinkedCells;
pub(crate) use list::CellList;

/// End of a cell's list.
pub(crate) const EMPTY: u32 = u32::MAX;

/// Cells per axis for a grid over `size` with cells no narrower than
/// `min_cell`, widened until there are at most ~4 per expected item (so
/// memory stays linear in `capacity`).
fn cell_counts(size: [f64; 3], min_cell: f64, capacity: usize) -> [usize; 3] {
    let limit = (4.0 * capacity as f64).max(1024.0);
    let mut width = min_cell;
    let mut counts = [1.0f64; 3];
    for _ in 0..64 {
        for a in 0..3 {
            counts[a] = (size[a] / width).floor().max(1.0);
        }
        let total = counts[0] * counts[1] * counts[2];
        if total <= limit {
            break;
        }
        width *= (total / limit).cbrt().max(1.01);
    }
    counts.map(|c| c as usize)
}

/// The indexing of a uniform grid of cells over `[0, Lx) × [0, Ly) ×
/// [z0, z0 + Lz]`, periodic in x and y, clamped in z.
#[derive(Debug, Clone)]
pub(crate) struct CellGrid {
    n: [usize; 3],
    cell: [f64; 3],
    z0: f64,
}

impl CellGrid {
    /// A grid over `size` (z from 0) with cells no narrower than
    /// `min_cell`, sized for about `capacity` items: cells are widened when
    /// needed so that there are at most ~4 per expected item.
    pub(crate) fn new(size: [f64; 3], min_cell: f64, capacity: usize) -> Self {
        Self::shifted(0.0, size, min_cell, capacity)
    }

    /// [`Self::new`] over `[z0, z0 + span[2]]` in z.
    pub(crate) fn shifted(z0: f64, span: [f64; 3], min_cell: f64, capacity: usize) -> Self {
        let n = cell_counts(span, min_cell, capacity);
        CellGrid {
            n,
            cell: [0, 1, 2].map(|a| span[a] / n[a] as f64),
            z0,
        }
    }

    /// Cells per axis.
    #[inline]
    pub(crate) fn counts(&self) -> [usize; 3] {
        self.n
    }

    /// Number of cells.
    #[inline]
    pub(crate) fn cells(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    /// Smallest cell width over the three axes.
    pub(crate) fn min_cell_width(&self) -> f64 {
        self.cell[0].min(self.cell[1]).min(self.cell[2])
    }

    /// Cell of position `p`: wrapped in x and y, clamped to the slab in z.
    #[inline]
    pub(crate) fn coords(&self, p: &[f64; 3]) -> [usize; 3] {
        let mut c = [0usize; 3];
        for a in 0..3 {
            let n = self.n[a] as f64;
            let x = if a < 2 { p[a] } else { p[a] - self.z0 };
            let i = (x / self.cell[a]).floor();
            let i = if a < 2 {
                i.rem_euclid(n)
            } else {
                i.clamp(0.0, n - 1.0)
            };
            // NaN casts to 0; the clamp/rem keep the index in range otherwise.
            c[a] = (i as usize).min(self.n[a] - 1);
        }
        c
    }

    /// Flat index of cell `c`.
    #[inline]
    pub(crate) fn flat(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }

    /// Flat index of the cell of position `p`.
    #[inline]
    pub(crate) fn index(&self, p: &[f64; 3]) -> usize {
        self.flat(self.coords(p))
    }

    /// Inclusive range of cell indices (unwrapped) within `k` cells of `i`
    /// along axis `a`, each cell once, and whether it covers the whole axis:
    /// periodic axes wrap (the caller reduces modulo `n`; fewer than
    /// `2k + 1` cells give the whole axis), the z axis is clipped to the slab.
    #[inline]
    fn axis_range(&self, a: usize, i: usize, k: usize) -> (isize, isize, bool) {
        let n = self.n[a] as isize;
        let (i, k) = (i as isize, k as isize);
        if a < 2 {
            if 2 * k + 1 > n {
                (0, n - 1, true)
            } else {
                (i - k, i + k, 2 * k + 1 == n)
            }
        } else {
            ((i - k).max(0), (i + k).min(n - 1), k >= n - 1)
        }
    }

    /// Whether a stencil of `k` cells reaches every cell from any cell.
    pub(crate) fn covers_all(&self, k: usize) -> bool {
        (0..3).all(|a| self.axis_range(a, 0, k).2)
    }

    /// Calls `f(flat index)` for every cell within `k` cells of cell `c`
    /// (each once; z, then y, then x ascending from the lower end of each
    /// range); stops early when `f` returns true and reports whether it did.
    #[inline]
    pub(crate) fn any_cell(
        &self,
        c: [usize; 3],
        k: usize,
        mut f: impl FnMut(usize) -> bool,
    ) -> bool {
        let (z0, z1, _) = self.axis_range(2, c[2], k);
        let (y0, y1, _) = self.axis_range(1, c[1], k);
        let (x0, x1, _) = self.axis_range(0, c[0], k);
        let (nx, ny) = (self.n[0] as isize, self.n[1] as isize);
        for cz in z0..=z1 {
            for cy in y0..=y1 {
                let wy = cy.rem_euclid(ny) as usize;
                for cx in x0..=x1 {
                    let wx = cx.rem_euclid(nx) as usize;
                    if f(self.flat([wx, wy, cz as usize])) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// The cells of the 3×3×3 block around cell `c` (each once, in the
    /// order of [`Self::any_cell`]) into `out`, as `(flat index, is c
    /// itself)`; returns how many.
    pub(crate) fn stencil_cells(&self, c: [usize; 3], out: &mut [(usize, bool); 27]) -> usize {
        let own = self.flat(c);
        let mut k = 0;
        self.any_cell(c, 1, |f| {
            out[k] = (f, f == own);
            k += 1;
            false
        });
        k
    }

    /// Cell `c` and the 13 cells ahead of it (`dz > 0`, or `dz = 0` and
    /// `dy > 0`, or `dz = dy = 0` and `dx > 0`), z clipped to the slab, into
    /// `out` as in [`Self::stencil_cells`]: every pair of neighbouring cells
    /// once, provided the periodic axes have at least 3 cells.
    pub(crate) fn forward_cells(&self, c: [usize; 3], out: &mut [(usize, bool); 27]) -> usize {
        let (nx, ny, nz) = (self.n[0] as isize, self.n[1] as isize, self.n[2] as isize);
        let [x, y, z] = c.map(|v| v as isize);
        out[0] = (self.flat(c), true);
        let mut k = 1;
        for dz in 0..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let ahead = dz > 0 || dy > 0 || (dy == 0 && dx > 0);
                    if !ahead || z + dz >= nz {
                        continue;
                    }
                    out[k] = (
                        self.flat([
                            (x + dx).rem_euclid(nx) as usize,
                            (y + dy).rem_euclid(ny) as usize,
                            (z + dz) as usize,
                        ]),
                        false,
                    );
                    k += 1;
                }
            }
        }
        k
    }
}
