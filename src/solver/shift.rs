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

use super::green;
use super::operator::Lattice;
use num_complex::Complex64 as C64;
use simd::{Cx, W};

const ZERO: C64 = C64 { re: 0.0, im: 0.0 };

/// Per-harmonic constants of the banded system.
#[derive(Debug, Clone, Copy)]
struct HarmonicShift {
    gamma: C64,
    gamma2: C64,
    inv_gs2: C64,
    beta: C64,
    q: C64,
    kappa: C64,
    phi: C64,
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
/// `d_j = v d_{j+1} + w_j`, and `gt = g (1 + t_j)` the output weight of
/// `d_j` (`G_s x` at cell j is `g σ_j − x'_j`, `σ_j = (1 + t_j) d_j + u_j`).
#[derive(Debug, Clone, Copy)]
struct StepBlock {
    gt: Cx,
    v: Cx,
    ua: Cx,
    ub: Cx,
    wa: Cx,
    wb: Cx,
}

/// Per-harmonic constants of `W` harmonics of one spectral row: the input
/// scale `s = 1/γ_s²` (and `sn = s/(nx ny)`, which also normalises the inverse
/// FFT), the top relation `u_0 = top x'_0`, the bottom closure
/// `d_{N−1} = eb x'_{N−1} + eu u_{N−1}`, the output weight `g = γ² φ1 s` and
/// `gtl = g (1 + t_{N−1})`. Near-grazing (dense) harmonics have zeros.
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
    pub c: C64,
    /// Spectral layout ix·ny + iy; `None` for dense (near-grazing) harmonics.
    h: Vec<Option<HarmonicShift>>,
    /// Per harmonic: `[top_u, t_0, t_{N−1}]` (for the boundary values).
    ends: Vec<[C64; 3]>,
    dense: Vec<Dense>,
    n: usize,
    ny: usize,
    /// Blocks of `W` harmonics per spectral row.
    nb: usize,
    /// Per block of `W` harmonics, layout (ix, block): index of its first
    /// stored cell in `steps` and the number stored (consecutive cells).
    block_off: Vec<usize>,
    block_cells: Vec<usize>,
    steps: Vec<StepBlock>,
    harm: Vec<HarmBlock>,
}

/// Coefficients of later cells differ from the last stored one by at most
/// this, relative to its magnitude: rounding.
const SETTLED: f64 = f64::EPSILON;

/// One cell's coefficients of one harmonic (scalar form of [`StepBlock`]).
#[derive(Debug, Clone, Copy)]
struct Step {
    gt: C64,
    v: C64,
    ua: C64,
    ub: C64,
    wa: C64,
    wb: C64,
}

impl Step {
    const ZERO: Step = Step {
        gt: ZERO,
        v: ZERO,
        ua: ZERO,
        ub: ZERO,
        wa: ZERO,
        wb: ZERO,
    };

    fn fields(&self) -> [C64; 6] {
        [self.gt, self.v, self.ua, self.ub, self.wa, self.wb]
    }

    /// All fields of `other` within `SETTLED` of ours.
    fn settled(&self, other: &Step) -> bool {
        self.fields()
            .iter()
            .zip(other.fields())
            .all(|(a, b)| (a - b).norm() <= SETTLED * a.norm())
    }
}

impl ShiftTable {
    /// Build for background `eps_b` (real binder) and shift `c`.
    pub fn new(lat: &Lattice, eps_b: f64, c: C64) -> Self {
        let slab = lat.slab();
        let n = lat.nz;
        let dz = slab.dz();
        let (nx, ny) = (lat.nx, lat.ny);
        let nb = ny.div_ceil(W);
        let norm = 1.0 / (nx * ny) as f64;
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
                    let inv_gs2 = 1.0 / (g2 + c);
                    h.push(Some(HarmonicShift {
                        gamma,
                        gamma2: g2,
                        inv_gs2,
                        beta,
                        q: x.exp(),
                        kappa: c * green::phi1(x) * inv_gs2,
                        phi: green::phi1(x),
                    }));
                }
            }
        }
        let cells = n - 1;
        let mut ends = vec![[ZERO; 3]; h.len()];
        let mut harm = vec![HarmBlock::ZERO; nx * nb];
        let mut block_off = Vec::with_capacity(nx * nb);
        let mut block_cells = Vec::with_capacity(nx * nb);
        let mut steps = Vec::new();
        // One row's full columns, layout (iy, j).
        let mut full = vec![Step::ZERO; ny * cells];
        let mut keep = vec![0; nb];
        for ix in 0..nx {
            keep.fill(0);
            for iy in 0..ny {
                let i = ix * ny + iy;
                let col = &mut full[iy * cells..(iy + 1) * cells];
                let Some(hs) = &h[i] else {
                    col.fill(Step::ZERO);
                    continue;
                };
                let (e, hb) = sweep_coefficients(hs, col);
                ends[i] = e;
                harm[ix * nb + iy / W].set(iy % W, &hb, norm);
                // Cells from `settle` on equal the last cell to rounding.
                let mut settle = cells;
                while settle > 0 && col[settle - 1].settled(&col[cells - 1]) {
                    settle -= 1;
                }
                let k = &mut keep[iy / W];
                *k = (*k).max(settle + 1).min(cells);
            }
            for (b, &keep) in keep.iter().enumerate() {
                block_off.push(steps.len());
                block_cells.push(keep);
                for j in 0..keep {
                    let mut sb = StepBlock::ZERO;
                    for k in 0..W.min(ny - b * W) {
                        sb.set(k, &full[(b * W + k) * cells + j]);
                    }
                    steps.push(sb);
                }
            }
        }
        ShiftTable {
            c,
            h,
            ends,
            dense,
            n,
            ny,
            nb,
            block_off,
            block_cells,
            steps,
            harm,
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
        let (nb, ny) = (self.nb, self.ny);
        self.block_cells
            .iter()
            .enumerate()
            .map(|(i, &c)| c * W.min(ny - (i % nb) * W))
            .sum()
    }

    /// The stored cells of block `b` of row `ix` (the last one stands for
    /// all later cells).
    #[inline(always)]
    fn steps_of(&self, ix: usize, b: usize) -> &[StepBlock] {
        let i = ix * self.nb + b;
        &self.steps[self.block_off[i]..][..self.block_cells[i]]
    }
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

/// The right-hand-side-independent part of the down sweep (see
/// [`ShiftTable::solve_column`]): fills `steps` (N − 1 cells) and returns
/// `[top_u, t_0, t_{N−1}]` and the per-harmonic constants.
fn sweep_coefficients(hs: &HarmonicShift, steps: &mut [Step]) -> ([C64; 3], HarmConst) {
    let HarmonicShift {
        gamma,
        gamma2,
        inv_gs2,
        beta,
        q,
        kappa,
        phi,
    } = *hs;
    let h = 0.5 * kappa;
    let den = gamma + beta - beta * kappa;
    let mut t = (gamma * q - beta * q + beta * kappa) / den;
    let t0 = t;
    let top_u = beta / den;
    let g = gamma2 * phi * inv_gs2;
    for step in steps.iter_mut() {
        // M (a_{j+1}, d_j)ᵀ = R0 + R1 d_{j+1}, R0 = (−Δ/2 − (h−q) u, Δ/2 + h u), R1 = (h, q − h).
        let m00 = 1.0 - h;
        let m01 = (h - q) * t + h;
        let m10 = h;
        let m11 = 1.0 - h - h * t;
        let inv = 1.0 / (m00 * m11 - m01 * m10);
        let (r1a, r1b) = (h, q - h);
        let t_next = (m11 * r1a - m01 * r1b) * inv;
        let v = (m00 * r1b - m10 * r1a) * inv;
        // R0 = Δ (−1/2, 1/2) + u (q − h, h)
        let (da, db) = (C64::new(-0.5, 0.0), C64::new(0.5, 0.0));
        let (ea, eb) = (q - h, h);
        *step = Step {
            gt: g * (1.0 + t),
            v,
            ua: (m11 * da - m01 * db) * inv,
            ub: (m11 * ea - m01 * eb) * inv,
            wa: (m00 * db - m10 * da) * inv,
            wb: (m00 * eb - m10 * ea) * inv,
        };
        t = t_next;
    }
    // Bottom: outgoing at z = H, d = (−β x' − ca u)/(t ca + cd).
    let ca = gamma * q - beta * q + beta * kappa;
    let cd = -gamma - beta + beta * kappa;
    let den_b = t * ca + cd;
    let hc = HarmConst {
        s: inv_gs2,
        top: top_u,
        eb: -beta / den_b,
        eu: -ca / den_b,
        g,
        gtl: g * (1.0 + t),
    };
    ([top_u, t0, t], hc)
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

impl ShiftTable {
    /// `col ← (I − c G_h)⁻¹ col` for harmonic `index` (column in `scr.col`).
    ///
    /// With `h = κ/2` and `Δ_j = (b_j − b_{j+1})/γ_s²`, continuity at interface
    /// j reads `a_{j+1} = q a_j − s_j`, `d_j = q d_{j+1} + s_j`,
    /// `s_j = Δ_j/2 + h (σ_j − σ_{j+1})`, `σ = a + d`. A down sweep carries the
    /// reflection relation `a_j = t_j d_j + u_j` from the top boundary
    /// (|t_j| ≲ 1: a reflection coefficient, so the sweep is stable), the
    /// bottom boundary closes it, and an up sweep recovers every `d_j`, `a_j`.
    /// Computed as `b + c G_s b` (`(I − c G_h)⁻¹ = I + c G_s`).
    pub fn solve_column(&self, index: usize, scr: &mut BandScratch) {
        if self.h[index].is_none() {
            self.dense_column(index, scr, Output::ShiftInverse);
            return;
        }
        let x = scr.col.clone();
        self.shifted_green_column(index, scr);
        for (y, x) in scr.col.iter_mut().zip(x) {
            *y = x + self.c * *y;
        }
    }

    /// `col ← G_s col` with `G_s = (G_h⁻¹ − c)⁻¹` the shifted Green's
    /// operator, never forming `G_h` (whose guided-mode poles it avoids);
    /// returns the continuous field `w = G_h(x + c G_s x)` at z = 0 and z = H.
    ///
    /// The same arithmetic, operation for operation, as
    /// [`Self::shifted_green_row`] on one lane: with `x' = x/γ_s²`, cell j of
    /// the output is `g σ_j − x'_j = gt_j d_j + (g u_j − x'_j)`; the down
    /// sweep leaves `g u_j − x'_j` in the column and `w_j` in scratch, the up
    /// sweep adds `gt_j d_j`.
    pub fn shifted_green_column(&self, index: usize, scr: &mut BandScratch) -> (C64, C64) {
        let Some(hs) = self.h[index] else {
            return self.dense_column(index, scr, Output::ShiftedGreen);
        };
        let n = self.n;
        let (ix, iy) = (index / self.ny, index % self.ny);
        let (b, k) = (iy / W, iy % W);
        let steps = self.steps_of(ix, b);
        let hb = &self.harm[ix * self.nb + b];
        let (s, top, eb, eu, g, gtl) = (
            hb.s.lane(k),
            hb.top.lane(k),
            hb.eb.lane(k),
            hb.eu.lane(k),
            hb.g.lane(k),
            hb.gtl.lane(k),
        );
        let [_, t0, t_last] = self.ends[index];
        let col = &mut scr.col;
        let x0 = col[0] * s;
        let mut bp = x0;
        let mut u = top * bp;
        let u0 = u;
        for j in 0..n - 1 {
            let st = &steps[j.min(steps.len() - 1)];
            let bn = col[j + 1] * s;
            let delta = bp - bn;
            col[j] = g * u - bp;
            scr.w[j] = st.wa.lane(k) * delta + st.wb.lane(k) * u;
            u = st.ua.lane(k) * delta + st.ub.lane(k) * u;
            bp = bn;
        }
        let mut d = eb * bp + eu * u;
        col[n - 1] = gtl * d + (g * u - bp);
        // w(H) = p + a q + d with p = −x' − κ σ.
        let a = t_last * d + u;
        let wh = -bp - hs.kappa * (a + d) + a * hs.q + d;
        for j in (0..n - 1).rev() {
            let st = &steps[j.min(steps.len() - 1)];
            d = st.v.lane(k) * d + scr.w[j];
            col[j] = st.gt.lane(k) * d + col[j];
        }
        // w(0) = p_0 + a_0 + d_0 q.
        let a = t0 * d + u0;
        let w0 = -x0 - hs.kappa * (a + d) + a + d * hs.q;
        (w0, wh)
    }

    /// The dense path of a near-grazing harmonic.
    fn dense_column(&self, index: usize, scr: &mut BandScratch, out: Output) -> (C64, C64) {
        let n = scr.col.len();
        let d = self.dense_of(index);
        let x = scr.col.clone();
        let m = match out {
            Output::ShiftInverse => &d.inv,
            Output::ShiftedGreen => &d.gs,
        };
        for j in 0..n {
            scr.col[j] = (0..n).map(|k| m[j * n + k] * x[k]).sum();
        }
        // w = G_h (x + c y): its boundary values from the functionals.
        let (mut w0, mut wh) = (ZERO, ZERO);
        if out == Output::ShiftedGreen {
            for (k, (x, y)) in x.iter().zip(&scr.col).enumerate() {
                let src = x + self.c * y;
                w0 += d.top[k] * src;
                wh += d.bottom[k] * src;
            }
        }
        (w0, wh)
    }
}

impl ShiftTable {
    /// `row ← G_s row` for every harmonic of spectral row `ix` at once
    /// (`row` is (N, ny), the cell index outermost), the same arithmetic as
    /// [`Self::shifted_green_column`] on `W` harmonics per operation, so
    /// the loops vectorise. Near-grazing harmonics come out zero (the caller
    /// applies their dense path). With `normalised`, the result is scaled
    /// by `1/(nx ny)` (the inverse FFT's normalisation) at no extra cost.
    pub fn shifted_green_row(
        &self,
        ix: usize,
        row: &mut ndarray::ArrayViewMut2<C64>,
        scr: &mut RowScratch,
        normalised: bool,
    ) {
        simd::dispatch(
            #[inline(always)]
            || self.row_kernel(ix, row, scr, normalised),
        );
    }

    #[inline(always)]
    fn row_kernel(
        &self,
        ix: usize,
        row: &mut ndarray::ArrayViewMut2<C64>,
        scr: &mut RowScratch,
        normalised: bool,
    ) {
        let (n, ny, nb) = (self.n, self.ny, self.nb);
        let hbs = &self.harm[ix * nb..(ix + 1) * nb];
        // The row's cells lie a power of two apart: read them once, scaled,
        // into contiguous scratch, layout (block, cell), with a prefetch one
        // cell ahead, and write the result back at the end.
        let cells = &mut scr.cells[..nb * n];
        for j in 0..n {
            if j + AHEAD < n {
                simd::prefetch(
                    row.row(j + AHEAD)
                        .as_slice()
                        .expect("contiguous spectral row"),
                );
            }
            let r = row.row(j);
            let r = r.as_slice().expect("contiguous spectral row");
            for (b, hb) in hbs.iter().enumerate() {
                cells[b * n + j] = Cx::load(&r[b * W..ny.min((b + 1) * W)]) * scale(hb, normalised);
            }
        }
        let w = &mut scr.w;
        for (b, (hb, x)) in hbs.iter().zip(cells.chunks_exact_mut(n)).enumerate() {
            let steps = self.steps_of(ix, b);
            let last = steps.len().saturating_sub(1);
            // Down sweep: w_j to scratch, g u_j − x'_j in place.
            let mut bp = x[0];
            let mut u = hb.top * bp;
            for j in 0..n - 1 {
                let st = &steps[j.min(last)];
                let bn = x[j + 1];
                let delta = bp - bn;
                x[j] = hb.g * u - bp;
                w[j] = st.wa * delta + st.wb * u;
                u = st.ua * delta + st.ub * u;
                bp = bn;
            }
            // Bottom closure, then the up sweep adding gt_j d_j.
            let mut d = hb.eb * bp + hb.eu * u;
            x[n - 1] = hb.gtl * d + (hb.g * u - bp);
            for j in (0..n - 1).rev() {
                let st = &steps[j.min(last)];
                d = st.v * d + w[j];
                x[j] = st.gt * d + x[j];
            }
        }
        for j in 0..n {
            let mut r = row.row_mut(j);
            let r = r.as_slice_mut().expect("contiguous spectral row");
            for b in 0..nb {
                cells[b * n + j].store(&mut r[b * W..ny.min((b + 1) * W)]);
            }
        }
    }

    /// Spectral indices of the near-grazing (dense) harmonics.
    pub fn dense_indices(&self) -> impl Iterator<Item = usize> + '_ {
        self.dense.iter().map(|d| d.index)
    }
}

#[inline(always)]
fn scale(hb: &HarmBlock, normalised: bool) -> Cx {
    if normalised {
        hb.sn
    } else {
        hb.s
    }
}

/// Per-row scratch of [`ShiftTable::shifted_green_row`].
pub struct RowScratch {
    /// The row's cells, layout (block, cell).
    cells: Vec<Cx>,
    /// `w_j` of one block.
    w: Vec<Cx>,
}

impl RowScratch {
    pub fn new(n: usize, ny: usize) -> Self {
        RowScratch {
            cells: vec![Cx::ZERO; n * ny.div_ceil(W)],
            w: vec![Cx::ZERO; n],
        }
    }
}

impl StepBlock {
    const ZERO: StepBlock = StepBlock {
        gt: Cx::ZERO,
        v: Cx::ZERO,
        ua: Cx::ZERO,
        ub: Cx::ZERO,
        wa: Cx::ZERO,
        wb: Cx::ZERO,
    };

    fn set(&mut self, k: usize, s: &Step) {
        self.gt.set(k, s.gt);
        self.v.set(k, s.v);
        self.ua.set(k, s.ua);
        self.ub.set(k, s.ub);
        self.wa.set(k, s.wa);
        self.wb.set(k, s.wb);
    }
}

impl HarmBlock {
    const ZERO: HarmBlock = HarmBlock {
        s: Cx::ZERO,
        sn: Cx::ZERO,
        top: Cx::ZERO,
        eb: Cx::ZERO,
        eu: Cx::ZERO,
        g: Cx::ZERO,
        gtl: Cx::ZERO,
    };

    fn set(&mut self, k: usize, h: &HarmConst, norm: f64) {
        self.s.set(k, h.s);
        self.sn.set(k, h.s * norm);
        self.top.set(k, h.top);
        self.eb.set(k, h.eb);
        self.eu.set(k, h.eu);
        self.g.set(k, h.g);
        self.gtl.set(k, h.gtl);
    }
}

/// What a column sweep returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Output {
    ShiftInverse,
    ShiftedGreen,
}

/// Dense `(I − c M)⁻¹` by Gauss–Jordan with partial pivoting.
fn dense_inverse_shift(m: &[C64], n: usize, c: C64) -> Vec<C64> {
    let mut a: Vec<C64> = (0..n * n)
        .map(|i| {
            if i / n == i % n {
                1.0 - c * m[i]
            } else {
                -c * m[i]
            }
        })
        .collect();
    let mut inv: Vec<C64> = (0..n * n)
        .map(|i| {
            if i / n == i % n {
                C64::new(1.0, 0.0)
            } else {
                ZERO
            }
        })
        .collect();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&x, &y| a[x * n + k].norm().total_cmp(&a[y * n + k].norm()))
            .unwrap_or(k);
        for t in 0..n {
            a.swap(k * n + t, p * n + t);
            inv.swap(k * n + t, p * n + t);
        }
        let piv = a[k * n + k];
        for t in 0..n {
            a[k * n + t] /= piv;
            inv[k * n + t] /= piv;
        }
        for r in 0..n {
            if r != k {
                let f = a[r * n + k];
                if f != ZERO {
                    for t in 0..n {
                        let (av, iv) = (a[k * n + t], inv[k * n + t]);
                        a[r * n + t] -= f * av;
                        inv[r * n + t] -= f * iv;
                    }
                }
            }
        }
    }
    inv
}

/// How many cells ahead the sweeps prefetch a spectral row.
pub(super) const AHEAD: usize = 3;

/// Complex arithmetic on `W` lanes at once (split real and imaginary
/// parts), written so LLVM vectorises it, and a dispatcher that runs a
/// kernel compiled for the widest vector unit the CPU has. Each lane does
/// exactly the operations of `num_complex` (no fused multiply-add), so
/// every code path gives the same bits.
pub(super) mod simd {
    use num_complex::Complex64 as C64;
    use std::ops::{Add, Mul, Sub};

    /// Lanes per operation: one AVX-512 register of real parts and one of
    /// imaginary parts.
    pub const W: usize = 8;

    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct Cx {
        pub re: [f64; W],
        pub im: [f64; W],
    }

    impl Cx {
        pub const ZERO: Cx = Cx {
            re: [0.0; W],
            im: [0.0; W],
        };

        #[inline(always)]
        pub fn lane(&self, k: usize) -> C64 {
            C64::new(self.re[k], self.im[k])
        }

        #[inline(always)]
        pub fn set(&mut self, k: usize, c: C64) {
            self.re[k] = c.re;
            self.im[k] = c.im;
        }

        /// Lanes from `src` (at most `W` values; the rest zero).
        #[inline(always)]
        pub fn load(src: &[C64]) -> Cx {
            let mut x = Cx::ZERO;
            // A full block as an array, so the copy compiles to vector shuffles.
            if let Ok(src) = <&[C64; W]>::try_from(src) {
                for (k, c) in src.iter().enumerate() {
                    x.re[k] = c.re;
                    x.im[k] = c.im;
                }
            } else {
                for (k, c) in src.iter().enumerate() {
                    x.re[k] = c.re;
                    x.im[k] = c.im;
                }
            }
            x
        }

        /// The first `dst.len()` (at most `W`) lanes into `dst`.
        #[inline(always)]
        pub fn store(&self, dst: &mut [C64]) {
            if let Ok(dst) = <&mut [C64; W]>::try_from(&mut *dst) {
                for (k, c) in dst.iter_mut().enumerate() {
                    *c = C64::new(self.re[k], self.im[k]);
                }
            } else {
                for (k, c) in dst.iter_mut().enumerate() {
                    *c = C64::new(self.re[k], self.im[k]);
                }
            }
        }
    }

    impl Add for Cx {
        type Output = Cx;
        #[inline(always)]
        fn add(self, o: Cx) -> Cx {
            let mut r = Cx::ZERO;
            for k in 0..W {
                r.re[k] = self.re[k] + o.re[k];
                r.im[k] = self.im[k] + o.im[k];
            }
            r
        }
    }

    impl Sub for Cx {
        type Output = Cx;
        #[inline(always)]
        fn sub(self, o: Cx) -> Cx {
            let mut r = Cx::ZERO;
            for k in 0..W {
                r.re[k] = self.re[k] - o.re[k];
                r.im[k] = self.im[k] - o.im[k];
            }
            r
        }
    }

    impl Mul for Cx {
        type Output = Cx;
        /// As `num_complex`: `(ac − bd, ad + bc)`.
        #[inline(always)]
        fn mul(self, o: Cx) -> Cx {
            let mut r = Cx::ZERO;
            for k in 0..W {
                r.re[k] = self.re[k] * o.re[k] - self.im[k] * o.im[k];
                r.im[k] = self.re[k] * o.im[k] + self.im[k] * o.re[k];
            }
            r
        }
    }

    /// Ask the cache for `data` ahead of its use. The sweeps read a
    /// spectral row's cells a power of two apart, one page each, where the
    /// hardware prefetchers do not reach.
    #[inline(always)]
    pub fn prefetch(data: &[C64]) {
        #[cfg(target_arch = "x86_64")]
        for line in data.chunks(4) {
            // SAFETY: a prefetch hint never faults and changes no state the
            // program can observe; the address lies inside `data`.
            unsafe {
                use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
                _mm_prefetch::<_MM_HINT_T0>(line.as_ptr().cast());
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = data;
    }

    /// Run `f`, compiled for AVX-512 or AVX2 where the CPU has them (the
    /// kernels are `#[inline(always)]`, so they are compiled into these
    /// wrappers with the wider registers).
    #[inline(always)]
    pub fn dispatch<R>(f: impl FnOnce() -> R) -> R {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                // SAFETY: the CPU has AVX-512F (checked just above).
                return unsafe { avx512(f) };
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has AVX2 (checked just above).
                return unsafe { avx2(f) };
            }
        }
        f()
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn avx512<R>(f: impl FnOnce() -> R) -> R {
        f()
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn avx2<R>(f: impl FnOnce() -> R) -> R {
        f()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sweep against a dense solve of (I − c G_h) y = b built from the
    /// Galerkin entries, for propagating, evanescent and near-grazing harmonics.
    #[test]
    fn sweep_matches_dense() {
        let n = 12;
        let lambda = 500.0;
        let k0 = 2.0 * std::f64::consts::PI / lambda;
        let eps_b = 1.558f64.powi(2);
        let size = [900.0, 900.0, 600.0];
        for polar in [0.0, 30.0] {
            let lat = crate::solver::Problem::lattice([6, 6, n], size, lambda, polar, 0.0);
            let c = k0 * k0 * C64::new(1.9 - eps_b, 0.7);
            let table = ShiftTable::new(&lat, eps_b, c);
            let slab = lat.slab();
            for ix in 0..6 {
                for iy in 0..6 {
                    let [kx, ky] = lat.kappa(ix, iy);
                    let g2 = C64::new(k0 * k0 * eps_b - kx * kx - ky * ky, 0.0);
                    let coef = green::coef_from(&slab, g2, lat.beta(ix, iy));
                    let m: Vec<C64> = (0..n * n).map(|i| coef.entry(n, i / n, i % n)).collect();
                    let inv = dense_inverse_shift(&m, n, c);
                    let b: Vec<C64> = (0..n)
                        .map(|j| C64::new((j as f64).sin(), 0.3 * j as f64 - 1.0))
                        .collect();
                    let want: Vec<C64> = (0..n)
                        .map(|j| (0..n).map(|k| inv[j * n + k] * b[k]).sum())
                        .collect();
                    // G_s = (I − c M)⁻¹ M and w = G_h(b + c G_s b) at the boundaries.
                    let gs_b: Vec<C64> = (0..n)
                        .map(|j| {
                            (0..n)
                                .map(|k| {
                                    (0..n).map(|l| inv[j * n + l] * m[l * n + k]).sum::<C64>()
                                        * b[k]
                                })
                                .sum()
                        })
                        .collect();
                    let src: Vec<C64> = (0..n).map(|k| b[k] + c * gs_b[k]).collect();
                    let w0: C64 = (0..n).map(|k| coef.top_weight(n, k) * src[k]).sum();
                    let wh: C64 = (0..n).map(|k| coef.bottom_weight(n, k) * src[k]).sum();
                    let mut scr = BandScratch::new(n);
                    scr.column().copy_from_slice(&b);
                    let (g0, gh) = table.shifted_green_column(ix * 6 + iy, &mut scr);
                    let sc = gs_b.iter().map(|w| w.norm()).fold(0.0, f64::max);
                    for (got, want) in scr.col.iter().zip(&gs_b) {
                        assert!(
                            (got - want).norm() < 1e-9 * sc,
                            "G_s {ix} {iy}: {got} vs {want}"
                        );
                    }
                    assert!(
                        (g0 - w0).norm() < 1e-9 * w0.norm().max(sc),
                        "w(0) {ix} {iy}: {g0} vs {w0}"
                    );
                    assert!(
                        (gh - wh).norm() < 1e-9 * wh.norm().max(sc),
                        "w(H) {ix} {iy}: {gh} vs {wh}"
                    );
                    let mut scr = BandScratch::new(n);
                    scr.column().copy_from_slice(&b);
                    table.solve_column(ix * 6 + iy, &mut scr);
                    let scale = want.iter().map(|w| w.norm()).fold(0.0, f64::max);
                    for (j, (got, want)) in scr.col.iter().zip(&want).enumerate() {
                        assert!(
                            (got - want).norm() < 1e-9 * scale,
                            "{ix} {iy} {j}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    /// The row-vectorised sweep equals the column sweep bit for bit.
    #[test]
    fn row_sweep_equals_column_sweep() {
        let n = 10;
        let lat =
            crate::solver::Problem::lattice([5, 7, n], [900.0, 700.0, 600.0], 480.0, 25.0, 10.0);
        let eps_b = 1.558f64.powi(2);
        let c = lat.k0 * lat.k0 * C64::new(1.7 - eps_b, 0.9);
        let table = ShiftTable::new(&lat, eps_b, c);
        for ix in 0..5 {
            let mut row = ndarray::Array2::from_shape_fn((n, 7), |(j, iy)| {
                C64::new((j * 7 + iy) as f64 * 0.1, (j as f64).cos())
            });
            let orig = row.clone();
            let mut scr = RowScratch::new(n, 7);
            table.shifted_green_row(ix, &mut row.view_mut(), &mut scr, false);
            for iy in 0..7 {
                let mut col = BandScratch::new(n);
                for j in 0..n {
                    col.column()[j] = orig[[j, iy]];
                }
                table.shifted_green_column(ix * 7 + iy, &mut col);
                for j in 0..n {
                    assert_eq!(row[[j, iy]], col.column()[j], "{ix} {iy} {j}");
                }
            }
        }
    }
}
