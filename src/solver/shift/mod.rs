//! Exact inverse of `I − c G_h` per harmonic: the discrete convergent-Born-
//! series preconditioner.
//!
//! CBS needs the Green's operator of the *shifted* background,
//! `G_s = (G_h⁻¹ − c)⁻¹` with `c = k0²(ε_r + iε_s − ε_b)`, exactly for the
//! discrete operator `G_h` in use; then `G_s G_h⁻¹ = (I − c G_h)⁻¹` and the
//! CBS step is `u += γ (I − c G_h)⁻¹ r`. Shifting the continuous background
//! and taking its Galerkin matrix instead is only right to O(dz²), which is
//! enough to make the march diverge on coarse z grids.
//!
//! **How it is solved in O(N).** `y = (I − c G_h)⁻¹ b` means
//! `y = b + c P w` with `w = G ỹ` the continuous field of the cell-constant
//! source `ỹ`. In cell j, `w'' + γ² w = −y_j` with `y_j` constant, so
//! `w = p_j + a_j e^{iγ(z−z_j)} + d_j e^{iγ(z_{j+1}−z)}` (decaying
//! exponentials only), and the cell-average condition gives
//! `p_j = −(b_j + c φ1 (a_j + d_j)) / γ_s²`, `y_j = −γ² p_j`, with
//! `γ_s² = γ² + c` (the shifted γ², never zero because Im c > 0). Continuity
//! of `w` and `w'` at the N−1 interfaces and the outgoing conditions at
//! `z = 0, H` close the system; it is solved by a reflection-coefficient
//! sweep down and a back-substitution up (see [`ShiftTable::solve_column`]),
//! a few complex operations per cell. Harmonics near `γ = 0` use a dense
//! inverse of the contour-averaged matrix.
//!
//! Takes a [`Lattice`], the binder permittivity and the shift `c`; gives a
//! [`ShiftTable`] that applies `(I − c G_h)⁻¹` or `G_s` to one harmonic's
//! column ([`BandScratch`]) or to a whole spectral row ([`RowScratch`]).
//! This module holds the table and its scratch; `coef` builds the per-cell
//! coefficients of the sweeps (and the dense inverses), `sweep` applies them.

mod coef;
mod sweep;

use super::green;
use super::lattice::Lattice;
use super::settle::{self, Packed};
use super::simd::{Cx, RowCells, W};
use coef::{dense_inverse_shift, sweep_coefficients};
use num_complex::Complex64 as C64;

const ZERO: C64 = C64 { re: 0.0, im: 0.0 };

/// Per-harmonic constants of the banded system. The shift may differ per
/// z cell (a layered background): `κ_j = c_j φ1 / (γ² + c_j)` of the top and
/// bottom cells are kept for the boundary values.
#[derive(Debug, Clone, Copy)]
struct HarmonicShift {
    gamma: C64,
    gamma2: C64,
    beta: C64,
    q: C64,
    phi: C64,
    kappa_top: C64,
    kappa_bottom: C64,
}

/// A near-grazing harmonic: dense `(I − c M)⁻¹`, `G_s = (I − c M)⁻¹ M` and
/// the top/bottom functionals of the contour-averaged `M`.
struct Dense {
    index: usize,
    inv: Vec<C64>,
    gs: Vec<C64>,
    top: Vec<C64>,
    bottom: Vec<C64>,
}

/// Down-sweep coefficients of cell j for `W` harmonics, independent of
/// the right-hand side: `u_{j+1} = ua Δ_j + ub u_j`, `w_j = wa Δ_j + wb u_j`,
/// `d_j = v d_{j+1} + w_j`, and `gt = g_j (1 + t_j)` the output weight of
/// `d_j` (`G_s x` at cell j is `g_j σ_j − x'_j`, `σ_j = (1 + t_j) d_j + u_j`,
/// `g_j = γ² φ1 / (γ² + c_j)`).
#[derive(Debug, Clone, Copy)]
struct StepBlock {
    g: Cx,
    gt: Cx,
    v: Cx,
    ua: Cx,
    ub: Cx,
    wa: Cx,
    wb: Cx,
}

/// Per-harmonic constants of `W` harmonics of one spectral row: the input
/// scale `s = 1/γ_s²` of the bottom cell (and `sn = s/(nx ny)`, which also
/// normalises the inverse FFT; the cells of a layered top zone carry their
/// own factor on top, [`ShiftTable::zone_ratio`]), the top relation
/// `u_0 = top x'_0`, the bottom closure `d_{N−1} = eb x'_{N−1} + eu u_{N−1}`,
/// the bottom cell's output weight `g = γ² φ1 s` and `gtl = g (1 + t_{N−1})`.
/// Near-grazing (dense) harmonics have zeros.
#[derive(Debug, Clone, Copy)]
struct HarmBlock {
    s: Cx,
    sn: Cx,
    top: Cx,
    eb: Cx,
    eu: Cx,
    g: Cx,
    gtl: Cx,
}

/// Bytes the table holds per harmonic for each cell of a layered zone: its
/// down-sweep coefficients and its input scale.
pub const ZONE_CELL_BYTES: usize =
    (std::mem::size_of::<StepBlock>() + std::mem::size_of::<Cx>()) / W;

/// `(I − c G_h)⁻¹` for every harmonic of a lattice.
///
/// **Storage.** The down-sweep recursion `t_{j+1} = f(t_j)` is a Möbius map
/// that converges geometrically (the shifted background is lossy), and every
/// coefficient of cell j is a function of `t_j`. Per spectral row only the
/// cells until all its harmonics' coefficients have settled to within
/// `SETTLED` (relative, i.e. to rounding) are stored; later cells reuse the
/// last stored one. Rows of evanescent harmonics then need a few cells
/// instead of N, and the table stays in cache instead of streaming
/// 96 bytes per voxel on every application.
pub struct ShiftTable {
    /// The shift per z cell, `c_j = k0²(ε_bg,j − ε_b)`.
    pub c: Vec<C64>,
    /// The bulk of the profile ([`settle::bulk_run`]): cells
    /// `bulk.0..bulk.1` share one shift; the cells before (a layered top)
    /// and after (a layered bottom) are the zone.
    bulk: (usize, usize),
    /// Per block of `W` harmonics (layout (ix, block)) and zone cell (the
    /// top's, then the bottom's): the input scale of cell j relative to
    /// `s`, `(γ² + c_bulk)/(γ² + c_j)`.
    zone_ratio: Vec<Cx>,
    /// Spectral layout ix·ny + iy; `None` for dense (near-grazing) harmonics.
    h: Vec<Option<HarmonicShift>>,
    /// Per harmonic: `[top_u, t_0, t_{N−1}]` (for the boundary values).
    ends: Vec<[C64; 3]>,
    dense: Vec<Dense>,
    n: usize,
    ny: usize,
    /// Blocks of `W` harmonics per spectral row.
    nb: usize,
    /// Per block of `W` harmonics, layout (ix, block): its stored cells.
    steps: Packed<StepBlock>,
    harm: Vec<HarmBlock>,
}

/// One cell's coefficients of one harmonic (scalar form of [`StepBlock`]).
#[derive(Debug, Clone, Copy)]
struct Step {
    g: C64,
    gt: C64,
    v: C64,
    ua: C64,
    ub: C64,
    wa: C64,
    wb: C64,
}

/// Scalar per-harmonic constants (one lane of [`HarmBlock`]).
struct HarmConst {
    s: C64,
    top: C64,
    eb: C64,
    eu: C64,
    g: C64,
    gtl: C64,
}

impl ShiftTable {
    /// Build for background `eps_b` (real binder) and one shift `c` in
    /// every cell.
    pub fn new(lat: &Lattice, eps_b: f64, c: C64) -> Self {
        Self::layered(lat, eps_b, &vec![c; lat.nz])
    }

    /// Build for background `eps_b` and the shift `c[j]` of each z cell
    /// (a layered background `ε_b + c_j/k0²`; exact for any profile). The
    /// tables settle in the profile's bulk ([`settle::bulk_run`]); the
    /// zone's cells above and below it are stored one by one.
    pub fn layered(lat: &Lattice, eps_b: f64, c: &[C64]) -> Self {
        let slab = lat.slab();
        let n = lat.nz;
        assert_eq!(c.len(), n, "one shift per z cell");
        let dz = slab.dz();
        let (nx, ny) = (lat.nx, lat.ny);
        let nb = ny.div_ceil(W);
        let norm = 1.0 / (nx * ny) as f64;
        let bulk = settle::bulk_run(c);
        let cb = c[bulk.0];
        let zone = settle::zone_cells(bulk, n).count();
        let mut h = Vec::with_capacity(lat.harmonics());
        let mut dense = Vec::new();
        for ix in 0..nx {
            for iy in 0..ny {
                let [kx, ky] = lat.kappa(ix, iy);
                let g2 = C64::new(lat.k0 * lat.k0 * eps_b - kx * kx - ky * ky, 0.0);
                let beta = lat.beta(ix, iy);
                if green::is_small_gamma(&slab, g2) {
                    let (m, top, bottom) = green::dense_small_gamma(&slab, g2, beta);
                    let inv = dense_inverse_shift(&m, n, c);
                    let gs = (0..n * n)
                        .map(|i| {
                            (0..n)
                                .map(|k| inv[(i / n) * n + k] * m[k * n + i % n])
                                .sum()
                        })
                        .collect();
                    dense.push(Dense {
                        index: ix * lat.ny + iy,
                        inv,
                        gs,
                        top,
                        bottom,
                    });
                    h.push(None);
                } else {
                    let gamma = green::sqrt_branch(g2);
                    let x = C64::i() * gamma * dz;
                    let phi = green::phi1(x);
                    let kappa = |c: C64| c * phi * (1.0 / (g2 + c));
                    h.push(Some(HarmonicShift {
                        gamma,
                        gamma2: g2,
                        beta,
                        q: x.exp(),
                        phi,
                        kappa_top: kappa(c[0]),
                        kappa_bottom: kappa(c[n - 1]),
                    }));
                }
            }
        }
        let cells = n - 1;
        let mut ends = vec![[ZERO; 3]; h.len()];
        let mut harm = vec![HarmBlock::ZERO; nx * nb];
        let mut zone_ratio = vec![Cx::splat(C64::new(1.0, 0.0)); nx * nb * zone];
        let mut steps = Packed::new(ny, n - bulk.1);
        // One row's full columns, layout (iy, j).
        let mut full = vec![Step::ZERO; ny * cells];
        for ix in 0..nx {
            for iy in 0..ny {
                let i = ix * ny + iy;
                let col = &mut full[iy * cells..(iy + 1) * cells];
                let Some(hs) = &h[i] else {
                    col.fill(Step::ZERO);
                    continue;
                };
                let (e, hb) = sweep_coefficients(hs, c, bulk, col);
                ends[i] = e;
                let blk = ix * nb + iy / W;
                harm[blk].set(iy % W, &hb, norm);
                let ratios = &mut zone_ratio[blk * zone..(blk + 1) * zone];
                for (r, j) in ratios.iter_mut().zip(settle::zone_cells(bulk, n)) {
                    r.set(iy % W, (hs.gamma2 + cb) / (hs.gamma2 + c[j]));
                }
            }
            steps.push_row(
                &full,
                cells,
                |a, b| settle::same(&a.fields(), &b.fields()),
                StepBlock::ZERO,
                |b, k, s| b.set(k, s),
            );
        }
        ShiftTable {
            c: c.to_vec(),
            bulk,
            zone_ratio,
            h,
            ends,
            dense,
            n,
            ny,
            nb,
            steps,
            harm,
        }
    }

    /// The zone's cells with their input factors, block `b` of row `ix`.
    #[inline(always)]
    fn zone_of(&self, ix: usize, b: usize) -> impl Iterator<Item = (usize, &Cx)> {
        let cells = settle::zone_cells(self.bulk, self.n);
        let zone = cells.clone().count();
        let i = ix * self.nb + b;
        cells.zip(&self.zone_ratio[i * zone..(i + 1) * zone])
    }

    /// `x ← x · ratio` on the zone's cells of one block's cells.
    #[inline(always)]
    fn scale_zone(&self, ix: usize, b: usize, x: &mut [Cx]) {
        for (j, r) in self.zone_of(ix, b) {
            x[j] = x[j] * *r;
        }
    }

    /// The same on lane `k` of a column.
    fn scale_zone_lane(&self, ix: usize, b: usize, k: usize, x: &mut [C64]) {
        for (j, r) in self.zone_of(ix, b) {
            x[j] *= r.lane(k);
        }
    }

    fn dense_of(&self, index: usize) -> &Dense {
        self.dense
            .iter()
            .find(|d| d.index == index)
            .expect("dense harmonic")
    }

    /// Down-sweep cells stored, summed over all harmonics (at most
    /// (N − 1) per harmonic; the rest are reused).
    pub fn stored_cells(&self) -> usize {
        self.steps.stored_cells()
    }

    /// The stored cells of block `b` of row `ix`.
    #[inline(always)]
    fn steps_of(&self, ix: usize, b: usize) -> settle::Steps<'_, StepBlock> {
        self.steps.of(ix, b, self.n - 1)
    }

    /// Spectral indices of the near-grazing (dense) harmonics.
    pub fn dense_indices(&self) -> impl Iterator<Item = usize> + '_ {
        self.dense.iter().map(|d| d.index)
    }
}

/// Scratch for one column solve of N cells.
pub struct BandScratch {
    col: Vec<C64>,
    /// Per cell: `w_j` of the down sweep.
    w: Vec<C64>,
}

impl BandScratch {
    pub fn new(n: usize) -> Self {
        BandScratch {
            col: vec![ZERO; n],
            w: vec![ZERO; n],
        }
    }

    /// The column buffer a caller fills with `b` and reads `y` from.
    pub fn column(&mut self) -> &mut [C64] {
        &mut self.col
    }
}

/// Per-row scratch of [`ShiftTable::shifted_green_row`].
pub struct RowScratch {
    /// The row's cells, layout (block, cell).
    cells: RowCells,
    /// `w_j` of one block.
    w: Vec<Cx>,
}

impl RowScratch {
    pub fn new(n: usize, ny: usize) -> Self {
        RowScratch {
            cells: RowCells::new(n, ny),
            w: vec![Cx::ZERO; n],
        }
    }
}
