//! Movable storage on the cell grid: items `0..n` (particles or spheres)
//! with a doubly linked list per cell, so moving an item to another cell
//! costs O(1).

use super::{CellGrid, EMPTY};

/// Items binned by cell, each movable.
#[derive(Debug, Clone)]
pub(crate) struct LinkedCells {
    grid: CellGrid,
    head: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    cell_of: Vec<u32>,
}

impl LinkedCells {
    /// No items on `grid`, room for `capacity`.
    pub(crate) fn new(grid: CellGrid, capacity: usize) -> Self {
        LinkedCells {
            head: vec![EMPTY; grid.cells()],
            grid,
            next: Vec::with_capacity(capacity),
            prev: Vec::with_capacity(capacity),
            cell_of: Vec::with_capacity(capacity),
        }
    }

    /// The indexing.
    #[inline]
    pub(crate) fn grid(&self) -> &CellGrid {
        &self.grid
    }

    /// First item of cell `f` (`EMPTY`: none).
    #[inline]
    pub(crate) fn head(&self, f: usize) -> u32 {
        self.head[f]
    }

    /// Item after `p` in its cell (`EMPTY`: none).
    #[inline]
    pub(crate) fn next(&self, p: usize) -> u32 {
        self.next[p]
    }

    /// Flat index of the cell holding item `p`.
    #[inline]
    pub(crate) fn cell_of(&self, p: usize) -> u32 {
        self.cell_of[p]
    }

    fn link(&mut self, p: usize, f: usize) {
        let h = self.head[f];
        self.next[p] = h;
        self.prev[p] = EMPTY;
        if h != EMPTY {
            self.prev[h as usize] = p as u32;
        }
        self.head[f] = p as u32;
        self.cell_of[p] = f as u32;
    }

    fn unlink(&mut self, p: usize) {
        let (nx, pv) = (self.next[p], self.prev[p]);
        if pv == EMPTY {
            self.head[self.cell_of[p] as usize] = nx;
        } else {
            self.next[pv as usize] = nx;
        }
        if nx != EMPTY {
            self.prev[nx as usize] = pv;
        }
    }

    /// Adds the next item, at `center`.
    pub(crate) fn push(&mut self, center: &[f64; 3]) {
        let p = self.next.len();
        self.next.push(EMPTY);
        self.prev.push(EMPTY);
        self.cell_of.push(0);
        let f = self.grid.index(center);
        self.link(p, f);
    }

    /// Moves item `p` to the cell of `center` (if it changed).
    pub(crate) fn update(&mut self, p: usize, center: &[f64; 3]) {
        let f = self.grid.index(center);
        if f != self.cell_of[p] as usize {
            self.unlink(p);
            self.link(p, f);
        }
    }

    /// Puts every centre in its cell (each cell lists its items in index
    /// order: deterministic).
    pub(crate) fn relink_all(&mut self, centers: &[[f64; 3]]) {
        let n = centers.len();
        self.next.resize(n, EMPTY);
        self.prev.resize(n, EMPTY);
        self.cell_of.resize(n, 0);
        self.head.iter_mut().for_each(|h| *h = EMPTY);
        for p in (0..n).rev() {
            let f = self.grid.index(&centers[p]);
            self.link(p, f);
        }
    }

    /// Calls `f(item)` for every item in the cells around the cell of `p`
    /// (the 3×3×3 stencil of [`CellGrid::any_cell`]); stops early when `f`
    /// returns true and reports whether it did.
    pub(crate) fn any_near(&self, p: &[f64; 3], mut f: impl FnMut(usize) -> bool) -> bool {
        self.grid.any_cell(self.grid.coords(p), 1, |cell| {
            let mut j = self.head[cell];
            while j != EMPTY {
                let ju = j as usize;
                j = self.next[ju];
                if f(ju) {
                    return true;
                }
            }
            false
        })
    }
}
