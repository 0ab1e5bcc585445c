//! Insert-only storage on the cell grid: spheres kept in insertion order
//! with an intrusive linked list per cell, so inserting and querying cost
//! O(1) amortised and no query allocates.

use super::{CellGrid, EMPTY};
use crate::geometry::periodic::dist2;
use crate::geometry::Sphere;

/// Spheres binned into a uniform grid of cells.
pub(crate) struct CellList {
    size: [f64; 3],
    grid: CellGrid,
    head: Vec<u32>,
    next: Vec<u32>,
    spheres: Vec<Sphere>,
    owner: Vec<u32>,
}

impl CellList {
    /// An empty list over `size` with cells no narrower than `min_cell`,
    /// sized for about `capacity` spheres (see [`CellGrid::new`]).
    pub(crate) fn new(size: [f64; 3], min_cell: f64, capacity: usize) -> Self {
        let grid = CellGrid::new(size, min_cell, capacity);
        CellList {
            size,
            head: vec![EMPTY; grid.cells()],
            grid,
            next: Vec::with_capacity(capacity),
            spheres: Vec::with_capacity(capacity),
            owner: Vec::with_capacity(capacity),
        }
    }

    /// Smallest cell width over the three axes.
    pub(crate) fn min_cell_width(&self) -> f64 {
        self.grid.min_cell_width()
    }

    /// Adds a sphere belonging to particle `owner`.
    pub(crate) fn insert(&mut self, sphere: Sphere, owner: u32) {
        let idx = self.spheres.len() as u32;
        let f = self.grid.index(&sphere.center);
        self.next.push(self.head[f]);
        self.head[f] = idx;
        self.spheres.push(sphere);
        self.owner.push(owner);
    }

    /// Whether a stencil of `k` cells reaches every cell from any cell.
    pub(crate) fn stencil_covers_all(&self, k: usize) -> bool {
        self.grid.covers_all(k)
    }

    /// Calls `f(index, sphere, owner)` for every stored sphere in the cells
    /// within `k` cells of the cell of `p`; stops early when `f` returns true
    /// and reports whether it did.
    pub(crate) fn any_near(
        &self,
        p: &[f64; 3],
        k: usize,
        mut f: impl FnMut(usize, &Sphere, u32) -> bool,
    ) -> bool {
        self.grid.any_cell(self.grid.coords(p), k, |cell| {
            let mut j = self.head[cell];
            while j != EMPTY {
                let ju = j as usize;
                if f(ju, &self.spheres[ju], self.owner[ju]) {
                    return true;
                }
                j = self.next[ju];
            }
            false
        })
    }

    /// Whether a sphere at `center` with `radius` would overlap (centre
    /// distance strictly below the sum of radii) any stored sphere.
    pub(crate) fn overlaps(&self, center: &[f64; 3], radius: f64) -> bool {
        let size = self.size;
        self.any_near(center, 1, |_, s, _| {
            let r = radius + s.radius;
            dist2(center, &s.center, &size) < r * r
        })
    }
}
