//! Uniform cell list over the fragment, periodic in x and y, bounded in z.
//!
//! Cells are at least `min_cell` wide along every axis (the largest sphere
//! diameter), so every sphere that can overlap a query sphere lies in the 3×3×3
//! block around the query's cell; a wider stencil of `k` cells serves distance
//! queries. Spheres are kept in insertion order with an intrusive linked list
//! per cell, so inserting and querying cost O(1) amortised and no query
//! allocates.

use super::Sphere;

const EMPTY: u32 = u32::MAX;

/// Displacement `d` reduced to the nearest periodic image in a period `l`.
#[inline]
pub(crate) fn min_image(d: f64, l: f64) -> f64 {
    d - l * (d / l).round()
}

/// [`min_image`] with a branch for the usual case of coordinates within one
/// period of each other (no rounding call).
#[inline]
pub(crate) fn near_image(d: f64, l: f64) -> f64 {
    let h = 0.5 * l;
    if d > h {
        if d <= 3.0 * h {
            d - l
        } else {
            min_image(d, l)
        }
    } else if d < -h {
        if d >= -3.0 * h {
            d + l
        } else {
            min_image(d, l)
        }
    } else {
        d
    }
}

/// Squared centre distance of two spheres, nearest periodic image in x and y.
#[inline]
pub(crate) fn dist2(a: &[f64; 3], b: &[f64; 3], size: &[f64; 3]) -> f64 {
    let dx = near_image(a[0] - b[0], size[0]);
    let dy = near_image(a[1] - b[1], size[1]);
    let dz = a[2] - b[2];
    dx * dx + dy * dy + dz * dz
}

/// Spheres binned into a uniform grid of cells.
pub(crate) struct CellList {
    size: [f64; 3],
    n: [usize; 3],
    cell: [f64; 3],
    head: Vec<u32>,
    next: Vec<u32>,
    spheres: Vec<Sphere>,
    owner: Vec<u32>,
}

/// Cell range `(lo, hi)` around cell `c` of an axis of `n` cells, each
/// cell once: periodic axes wrap (the caller reduces modulo `n`; fewer than
/// three cells give the whole axis), the z axis is clipped to the slab.
pub(crate) fn stencil(n: usize, c: usize, periodic: bool) -> (isize, isize) {
    let (n, c) = (n as isize, c as isize);
    if periodic {
        if n < 3 {
            (0, n - 1)
        } else {
            (c - 1, c + 1)
        }
    } else {
        ((c - 1).max(0), (c + 1).min(n - 1))
    }
}

/// Cells per axis for a grid over `size` with cells no narrower than
/// `min_cell`, widened until there are at most ~4 per expected item (so
/// memory stays linear in `capacity`).
pub(crate) fn cell_counts(size: [f64; 3], min_cell: f64, capacity: usize) -> [usize; 3] {
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

impl CellList {
    /// An empty list over `size` with cells no narrower than `min_cell`,
    /// sized for about `capacity` spheres. Cells are widened when needed so
    /// that there are at most ~4 per expected sphere (memory stays linear).
    pub(crate) fn new(size: [f64; 3], min_cell: f64, capacity: usize) -> Self {
        let n = cell_counts(size, min_cell, capacity);
        let cell = [
            size[0] / n[0] as f64,
            size[1] / n[1] as f64,
            size[2] / n[2] as f64,
        ];
        CellList {
            size,
            n,
            cell,
            head: vec![EMPTY; n[0] * n[1] * n[2]],
            next: Vec::with_capacity(capacity),
            spheres: Vec::with_capacity(capacity),
            owner: Vec::with_capacity(capacity),
        }
    }

    /// Smallest cell width over the three axes.
    pub(crate) fn min_cell_width(&self) -> f64 {
        self.cell[0].min(self.cell[1]).min(self.cell[2])
    }

    fn cell_index(&self, p: &[f64; 3]) -> [usize; 3] {
        let mut c = [0usize; 3];
        for a in 0..3 {
            let i = (p[a] / self.cell[a]).floor();
            let n = self.n[a] as f64;
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

    fn flat(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }

    /// Adds a sphere belonging to particle `owner`.
    pub(crate) fn insert(&mut self, sphere: Sphere, owner: u32) {
        let idx = self.spheres.len() as u32;
        let f = self.flat(self.cell_index(&sphere.center));
        self.next.push(self.head[f]);
        self.head[f] = idx;
        self.spheres.push(sphere);
        self.owner.push(owner);
    }

    /// Inclusive range of cell indices (unwrapped) within `k` cells of `i`
    /// along axis `a`, and whether the stencil already covers the whole axis.
    fn axis_range(&self, a: usize, i: usize, k: usize) -> (isize, isize, bool) {
        let n = self.n[a] as isize;
        let (i, k) = (i as isize, k as isize);
        if a < 2 {
            if 2 * k + 1 >= n {
                (0, n - 1, true)
            } else {
                (i - k, i + k, false)
            }
        } else {
            let lo = (i - k).max(0);
            let hi = (i + k).min(n - 1);
            (lo, hi, k >= n - 1)
        }
    }

    /// Whether a stencil of `k` cells reaches every cell from any cell.
    pub(crate) fn stencil_covers_all(&self, k: usize) -> bool {
        (0..3).all(|a| self.axis_range(a, 0, k).2)
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
        let c = self.cell_index(p);
        let (z0, z1, _) = self.axis_range(2, c[2], k);
        let (y0, y1, _) = self.axis_range(1, c[1], k);
        let (x0, x1, _) = self.axis_range(0, c[0], k);
        let (nx, ny) = (self.n[0] as isize, self.n[1] as isize);
        for cz in z0..=z1 {
            for cy in y0..=y1 {
                let wy = cy.rem_euclid(ny) as usize;
                for cx in x0..=x1 {
                    let wx = cx.rem_euclid(nx) as usize;
                    let mut j = self.head[self.flat([wx, wy, cz as usize])];
                    while j != EMPTY {
                        let ju = j as usize;
                        if f(ju, &self.spheres[ju], self.owner[ju]) {
                            return true;
                        }
                        j = self.next[ju];
                    }
                }
            }
        }
        false
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
