//! Sweep tables that store a cell only until it repeats: shared by the
//! scalar shift table ([`shift`](super::shift)) and Maxwell's TM table
//! ([`maxwell`](super::maxwell)).
//!
//! A down sweep's right-hand-side-free coefficients follow a Möbius
//! recursion from the top boundary; where the background is lossy it
//! converges geometrically, and once it has reached its fixed point to
//! rounding every later cell repeats the last. Per spectral row and block of
//! `W` harmonics only the cells until all lanes have settled are stored
//! ([`Packed`]); a sweep reads cell `min(j, last)`.

use super::simd::W;
use num_complex::Complex64 as C64;

/// Coefficients of later cells differ from the last stored one by at most
/// this, relative to its magnitude: rounding.
pub const SETTLED: f64 = f64::EPSILON;

/// Whether an iterate of size `size` whose last step was `change` (after
/// `last_change`) has reached its fixed point to rounding: with `r` the
/// ratio of successive changes, the distance left is about
/// `change · r / (1 − r)`.
pub fn converged(change: f64, last_change: f64, size: f64) -> bool {
    let r = change / last_change;
    change == 0.0
        || (last_change.is_finite() && r < 1.0 && change * r / (1.0 - r) <= SETTLED * size)
}

/// Every value of `a` within [`SETTLED`] of `b`'s (relative to `a`'s).
pub fn same(a: &[C64], b: &[C64]) -> bool {
    // Squared moduli: no hypot in a table's hottest loop.
    a.iter()
        .zip(b)
        .all(|(a, b)| (a - b).norm_sqr() <= SETTLED * SETTLED * a.norm_sqr())
}

/// The longest run of equal shifts in a profile, `(start, end)`: the bulk
/// of a layered background, whose cells the sweep tables settle in; the
/// cells before `start` (a layered top) and from `end` (a layered bottom)
/// are stored one by one. The first run of that length wins.
pub fn bulk_run(c: &[C64]) -> (usize, usize) {
    let (mut best, mut start) = ((0, 0), 0);
    for j in 1..=c.len() {
        if j == c.len() || c[j] != c[start] {
            if j - start > best.1 - best.0 {
                best = (start, j);
            }
            start = j;
        }
    }
    best
}

/// The zone's cells of a profile of `n` cells whose bulk is `bulk`: the
/// layered top's, then the layered bottom's, the order in which the tables
/// keep their per-cell factors.
pub fn zone_cells(bulk: (usize, usize), n: usize) -> impl Iterator<Item = usize> + Clone {
    (0..bulk.0).chain(bulk.1..n)
}

/// Per block of `W` harmonics, layout (ix, block), its stored cells: the
/// cells until the recursion settles, then the last `tail` cells (a
/// layered bottom) one by one.
pub struct Packed<B> {
    ny: usize,
    nb: usize,
    tail: usize,
    off: Vec<usize>,
    cells: Vec<usize>,
    blocks: Vec<B>,
}

/// One block's stored cells: cell j is `pre[min(j, last)]` before
/// `tail_start` and `tail[j − tail_start]` from there.
pub struct Steps<'a, B> {
    pre: &'a [B],
    last: usize,
    tail: &'a [B],
    tail_start: usize,
}

impl<B> Steps<'_, B> {
    #[inline(always)]
    pub fn at(&self, j: usize) -> &B {
        if j >= self.tail_start {
            &self.tail[j - self.tail_start]
        } else {
            &self.pre[j.min(self.last)]
        }
    }
}

impl<B: Copy> Packed<B> {
    /// Empty, for spectral rows of `ny` harmonics whose last `tail` cells
    /// are kept one by one.
    pub fn new(ny: usize, tail: usize) -> Self {
        Packed {
            ny,
            nb: ny.div_ceil(W),
            tail,
            off: Vec::new(),
            cells: Vec::new(),
            blocks: Vec::new(),
        }
    }

    /// Append one spectral row from its full columns `full` (layout
    /// (iy, cell), `cells` per harmonic): per block, the cells until every
    /// lane equals its last cell before the tail (`same`), then the tail's
    /// cells; lane k of cell j packed by `set(block, k, value)` into a copy
    /// of `zero`.
    pub fn push_row<S>(
        &mut self,
        full: &[S],
        cells: usize,
        same: impl Fn(&S, &S) -> bool,
        zero: B,
        set: impl Fn(&mut B, usize, &S),
    ) {
        let ny = self.ny;
        let head = cells - self.tail;
        for b in 0..self.nb {
            let lanes = W.min(ny - b * W);
            let keep = (0..lanes)
                .map(|k| {
                    let col = &full[(b * W + k) * cells..][..head];
                    let mut settle = head;
                    while settle > 0 && same(&col[settle - 1], &col[head - 1]) {
                        settle -= 1;
                    }
                    (settle + 1).min(head)
                })
                .max()
                .unwrap_or(0);
            self.off.push(self.blocks.len());
            self.cells.push(keep);
            for j in (0..keep).chain(head..cells) {
                let mut block = zero;
                for k in 0..lanes {
                    set(&mut block, k, &full[(b * W + k) * cells + j]);
                }
                self.blocks.push(block);
            }
        }
    }

    /// The stored cells of block `b` of row `ix` (the last before the tail
    /// stands for all later cells up to the tail).
    #[inline(always)]
    pub fn of(&self, ix: usize, b: usize, cells: usize) -> Steps<'_, B> {
        let i = ix * self.nb + b;
        let (keep, tail) = (self.cells[i], self.tail);
        let all = &self.blocks[self.off[i]..][..keep + tail];
        Steps {
            pre: &all[..keep],
            last: keep.saturating_sub(1),
            tail: &all[keep..],
            tail_start: cells - tail,
        }
    }

    /// Cells stored, summed over harmonics.
    pub fn stored_cells(&self) -> usize {
        let (nb, ny) = (self.nb, self.ny);
        self.cells
            .iter()
            .enumerate()
            .map(|(i, &c)| (c + self.tail) * W.min(ny - (i % nb) * W))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Blocks keep the cells until their slowest lane settles; a row of
    /// fewer than `W` harmonics packs partial blocks.
    #[test]
    fn blocks_keep_cells_until_every_lane_settles() {
        let cells = 5;
        let ny = W + 2;
        // Harmonic iy settles from cell min(iy, 4) on (values then repeat).
        let full: Vec<f64> = (0..ny)
            .flat_map(|iy| (0..cells).map(move |j| j.min(iy.min(cells - 1)) as f64))
            .collect();
        let mut p = Packed::new(ny, 0);
        p.push_row(&full, cells, |a, b| a == b, [0.0; W], |b, k, v| b[k] = *v);
        // Block 0 holds iy 0..W: the slowest settles at cell 4 → 5 cells.
        assert_eq!(p.of(0, 0, cells).pre.len(), 5);
        // Block 1 holds iy W, W+1 (both settle at cell 4).
        assert_eq!(p.of(0, 1, cells).pre.len(), 5);
        assert_eq!(p.of(0, 0, cells).at(2)[1], 1.0);
        assert_eq!(p.of(0, 0, cells).at(2)[3], 2.0);
        let mut q = Packed::new(3, 0);
        let quick: Vec<f64> = vec![0.0; 3 * cells];
        q.push_row(&quick, cells, |a, b| a == b, [0.0; W], |b, k, v| b[k] = *v);
        assert_eq!(q.of(0, 0, cells).pre.len(), 1);
        assert_eq!(q.stored_cells(), 3);
        // A tail of 2 cells after a settled run: cells 0..3 settle at once,
        // the tail's two are kept one by one.
        let tailed: Vec<f64> = [0.0, 0.0, 0.0, 7.0, 9.0].repeat(3);
        let mut t = Packed::new(3, 2);
        t.push_row(&tailed, cells, |a, b| a == b, [0.0; W], |b, k, v| b[k] = *v);
        let s = t.of(0, 0, cells);
        assert_eq!(s.pre.len(), 1);
        let got: Vec<f64> = (0..cells).map(|j| s.at(j)[1]).collect();
        assert_eq!(got, tailed[..cells]);
        assert_eq!(t.stored_cells(), 9);
        assert_eq!(bulk_run(&[C64::new(1.0, 0.0); 4]), (0, 4));
        let c = |v: f64| C64::new(v, 0.0);
        assert_eq!(
            bulk_run(&[c(3.0), c(2.0), c(1.0), c(1.0), c(1.0), c(5.0)]),
            (2, 5)
        );
        assert!(converged(0.0, 1.0, 1.0));
        assert!(!converged(0.5, 1.0, 1.0));
        assert!(converged(1e-18, 1e-17, 1.0));
    }
}
