//! The background Green's operator `G_bg` on the 3-D grid (METHOD §4), shared
//! by every solver.
//!
//! One application = a forward 2-D FFT of every z-slice, per Bloch harmonic
//! two O(Nz) sweeps (down, then up with the assembly) that apply the exact
//! Galerkin matrix of [`green`](super::green), and the inverse 2-D FFT. The
//! sweeps run on blocks of `W` = 8 harmonics of one spectral row at a time
//! (vectorised, see [`simd`](super::simd)), on a contiguous copy of the row. Fields
//! hold the periodic part `v` of the Bloch field `u = v e^{iq·ρ}`, as z-cell
//! averages, stored `(nz, ny, nx)`.
//!
//! A [`GreenTable`] holds everything that depends on the background
//! permittivity (binder for the physical problem, binder shifted by `iε_s` for
//! the convergent-Born-series preconditioner). Scratch lives in
//! [`Workspace`], owned by the caller, so applications never allocate.

use super::fft::{Fft2, FftScratch};
use super::green;
use super::lattice::Lattice;
use super::shift::{BandScratch, RowScratch, ShiftTable};
use super::simd::{self, Cx, RowCells, W};
use ndarray::{Array3, ArrayViewMut2, Axis};
use num_complex::Complex64 as C64;
use rayon::prelude::*;

const ZERO: C64 = C64 { re: 0.0, im: 0.0 };

/// A harmonic near γ = 0, applied with a dense matrix.
struct Special {
    /// Spectral index ix·ny + iy.
    index: usize,
    matrix: Vec<C64>,
}

/// Per-harmonic data of the Green's operator for one background permittivity.
pub struct GreenTable {
    pub eps_bg: C64,
    /// Sweep coefficients, layout (ix, block of `W` harmonics).
    blocks: Vec<GreenBlock>,
    special: Vec<Special>,
}

/// The sweep coefficients of `W` harmonics: `q` and the Galerkin weights
/// `f2, r2n, diag, rf` of [`green::Coef`], each times `K dz/(nx ny)` (the overall
/// factor and the inverse FFT's normalisation). Grazing harmonics have zeros.
#[derive(Debug, Clone, Copy)]
struct GreenBlock {
    q: Cx,
    f2: Cx,
    r2n: Cx,
    diag: Cx,
    rf: Cx,
}

impl GreenTable {
    pub fn new(lat: &Lattice, eps_bg: C64) -> Self {
        let slab = lat.slab();
        let (nx, ny) = (lat.nx, lat.ny);
        let nb = ny.div_ceil(W);
        let norm = 1.0 / (nx * ny) as f64;
        let zero = GreenBlock {
            q: Cx::ZERO,
            f2: Cx::ZERO,
            r2n: Cx::ZERO,
            diag: Cx::ZERO,
            rf: Cx::ZERO,
        };
        let mut blocks = vec![zero; nx * nb];
        let mut special = Vec::new();
        for ix in 0..nx {
            for iy in 0..ny {
                let [kx, ky] = lat.kappa(ix, iy);
                let g2 = lat.k0 * lat.k0 * eps_bg - (kx * kx + ky * ky);
                let beta = lat.beta(ix, iy);
                if green::is_small_gamma(&slab, g2) {
                    let (matrix, _, _) = green::dense_small_gamma(&slab, g2, beta);
                    special.push(Special {
                        index: ix * ny + iy,
                        matrix,
                    });
                    continue;
                }
                let c = green::coef_from(&slab, g2, beta);
                let k = c.kdz * norm;
                let (b, l) = (&mut blocks[ix * nb + iy / W], iy % W);
                b.q.set(l, c.q);
                b.f2.set(l, k * c.f2);
                b.r2n.set(l, k * c.r2n);
                b.diag.set(l, k * c.diag);
                b.rf.set(l, k * c.rf);
            }
        }
        GreenTable {
            eps_bg,
            blocks,
            special,
        }
    }

    /// Number of harmonics treated by the grazing (contour-average) path.
    pub fn special_count(&self) -> usize {
        self.special.len()
    }

    /// `row ← G_b row / (nx ny)` for the non-grazing harmonics of spectral
    /// row `ix` (`row` is (N, ny)), `W` harmonics per operation.
    ///
    /// With `s_k` the cell sources and `p_m = q^m` (one running product per
    /// application, kept in scratch): down sweep `A_j = Σ_{k<j} q^{j−1−k} s_k`,
    /// `C_j = Σ_{k<j} q^k s_k`, `Sh = Σ q^{N−1−k} s_k`, storing
    /// `f2 A_j + r2n p_{N−1−j} C_j`; up sweep `B_j = Σ_{k>j} q^{k−j−1} s_k`,
    /// `D_j = Σ_{k>j} q^{N−1−k} s_k` and the result
    /// `stored + f2 B_j + r2n p_j D_j + diag s_j + rf (p_j Se + p_{N−1−j} Sh)`,
    /// `Se = C_N` (the Galerkin matrix of [`green::Coef::entry`] applied in O(N)).
    #[inline(always)]
    fn row_kernel(&self, ix: usize, row: &mut ArrayViewMut2<C64>, scr: &mut GreenScratch) {
        let (n, ny) = row.dim();
        let nb = ny.div_ceil(W);
        let blocks = &self.blocks[ix * nb..(ix + 1) * nb];
        let one = {
            let mut o = Cx::ZERO;
            o.re = [1.0; W];
            o
        };
        let cells = scr.cells.gather(row, |_, x| x);
        for (k, s) in blocks.iter().zip(cells) {
            let (p, acc) = (&mut scr.pow, &mut scr.acc);
            p[0] = one;
            for m in 1..n {
                p[m] = p[m - 1] * k.q;
            }
            let (mut a, mut c, mut sh) = (Cx::ZERO, Cx::ZERO, Cx::ZERO);
            for j in 0..n {
                let pm = p[n - 1 - j];
                acc[j] = k.f2 * a + k.r2n * (pm * c);
                a = k.q * a + s[j];
                c = c + p[j] * s[j];
                sh = sh + pm * s[j];
            }
            let (mut bb, mut d) = (Cx::ZERO, Cx::ZERO);
            for j in (0..n).rev() {
                let (sj, pj, pm) = (s[j], p[j], p[n - 1 - j]);
                s[j] = acc[j]
                    + (k.f2 * bb + k.r2n * (pj * d))
                    + k.diag * sj
                    + k.rf * (pj * c + pm * sh);
                bb = k.q * bb + sj;
                d = d + pm * sj;
            }
        }
        scr.cells.scatter(row);
    }
}

/// Per-task scratch of the `G_b` row sweeps: a spectral row and, for one
/// block of harmonics, `q^m` and the down sweep's partial results.
struct GreenScratch {
    cells: RowCells,
    pow: Vec<Cx>,
    acc: Vec<Cx>,
}

/// Scratch buffers for operator applications, sized for one lattice.
pub struct Workspace {
    spec: Array3<C64>,
    fft: FftScratch,
    special_in: Vec<C64>,
    /// One banded-solve scratch per spectral row (ix).
    bands: Vec<BandScratch>,
    /// Row-sweep scratch, one per parallel chunk of spectral rows.
    row_scratch: Vec<RowScratch>,
    green_scratch: Vec<GreenScratch>,
}

/// FFT plans plus the lattice: what every application shares.
pub struct Operator {
    pub lat: Lattice,
    fft: Fft2,
}

impl Operator {
    pub fn new(lat: Lattice) -> Self {
        Operator {
            fft: Fft2::new(lat.nx, lat.ny),
            lat,
        }
    }

    pub fn workspace(&self) -> Workspace {
        let (nx, ny, nz) = (self.lat.nx, self.lat.ny, self.lat.nz);
        // Parallel chunks of spectral rows, each with its own row scratch.
        let tasks = nx.min(4 * rayon::current_num_threads()).max(1);
        Workspace {
            spec: Array3::from_elem((nz, nx, ny), ZERO),
            fft: self.fft.scratch(nz),
            special_in: Vec::new(),
            bands: (0..nx).map(|_| BandScratch::new(nz)).collect(),
            row_scratch: (0..tasks).map(|_| RowScratch::new(nz, ny)).collect(),
            green_scratch: (0..tasks)
                .map(|_| GreenScratch {
                    cells: RowCells::new(nz, ny),
                    pow: vec![Cx::ZERO; nz],
                    acc: vec![Cx::ZERO; nz],
                })
                .collect(),
        }
    }

    /// `field ← G_bg field` for the background of `table`.
    pub fn apply(&self, table: &GreenTable, field: &mut Array3<C64>, ws: &mut Workspace) {
        self.fft.forward(field, &mut ws.spec, &mut ws.fft);
        self.apply_spectral(table, ws);
        self.fft.inverse(&mut ws.spec, field, &mut ws.fft);
    }

    /// `field ← G_s field`, `G_s = (G_b⁻¹ − c)⁻¹` the shifted Green's operator
    /// (exact, per harmonic, free of the guided-mode poles of `G_b`).
    pub fn apply_shifted_green(
        &self,
        table: &ShiftTable,
        field: &mut Array3<C64>,
        ws: &mut Workspace,
    ) {
        self.fft.forward(field, &mut ws.spec, &mut ws.fft);
        self.shifted_spectral(table, ws);
        self.fft.inverse(&mut ws.spec, field, &mut ws.fft);
    }

    /// [`Operator::apply_shifted_green`] of the source whose z-slices
    /// `load(k, plane)` makes, each output slice handed to
    /// `store(k, plane, out's slice k)`: no whole field is stored between
    /// ([`Fft2::forward_from`]).
    pub fn apply_shifted_green_with<S: Send + Sync, R: Send>(
        &self,
        table: &ShiftTable,
        ws: &mut Workspace,
        load: impl Fn(usize, &mut [C64]) + Sync,
        out: &mut Array3<S>,
        store: impl Fn(usize, &[C64], ArrayViewMut2<S>) -> R + Sync,
    ) -> Vec<R> {
        self.fft.forward_from(&mut ws.spec, &mut ws.fft, load);
        self.shifted_spectral(table, ws);
        self.fft.inverse_into(&mut ws.spec, &mut ws.fft, out, store)
    }

    /// `G_s` on the spectrum in `ws` (between the transforms).
    fn shifted_spectral(&self, table: &ShiftTable, ws: &mut Workspace) {
        let (nx, ny, nz) = (self.lat.nx, self.lat.ny, self.lat.nz);
        let norm = 1.0 / (nx * ny) as f64;
        // Near-grazing harmonics: dense path on their saved columns.
        let mut dense = std::mem::take(&mut ws.special_in);
        dense.clear();
        for h in table.dense_indices() {
            let (ix, iy) = (h / ny, h % ny);
            let scr = &mut ws.bands[0];
            for (j, c) in scr.column().iter_mut().enumerate() {
                *c = ws.spec[[j, ix, iy]];
            }
            table.shifted_green_column(h, scr);
            dense.extend_from_slice(scr.column());
        }
        for_each_row(&mut ws.spec, &mut ws.row_scratch, |ix, row, scr| {
            table.shifted_green_row(ix, row, scr, true)
        });
        for (k, h) in table.dense_indices().enumerate() {
            let (ix, iy) = (h / ny, h % ny);
            for j in 0..nz {
                ws.spec[[j, ix, iy]] = dense[k * nz + j] * norm;
            }
        }
        ws.special_in = dense;
    }

    /// Boundary values `w(0)`, `w(H)` of `w = G_b(x + c G_s x)` per harmonic
    /// for a real-space source `x` (consumed as scratch), spectral layout.
    pub fn shifted_boundary(
        &self,
        table: &ShiftTable,
        source: &mut Array3<C64>,
        ws: &mut Workspace,
        r: &mut ndarray::Array2<C64>,
        t: &mut ndarray::Array2<C64>,
    ) {
        let (nx, ny) = (self.lat.nx, self.lat.ny);
        let norm = 1.0 / (nx * ny) as f64;
        self.fft.forward(source, &mut ws.spec, &mut ws.fft);
        let scr = &mut ws.bands[0];
        for ix in 0..nx {
            for iy in 0..ny {
                for (j, c) in scr.column().iter_mut().enumerate() {
                    *c = ws.spec[[j, ix, iy]];
                }
                let (w0, wh) = table.shifted_green_column(ix * ny + iy, scr);
                r[[ix, iy]] = w0 * norm;
                t[[ix, iy]] = wh * norm;
            }
        }
    }

    fn apply_spectral(&self, table: &GreenTable, ws: &mut Workspace) {
        let (nx, ny, nz) = (self.lat.nx, self.lat.ny, self.lat.nz);
        let norm = 1.0 / (nx * ny) as f64;
        // Save the columns of grazing harmonics before the sweeps overwrite them.
        ws.special_in.clear();
        for sp in &table.special {
            let (ix, iy) = (sp.index / ny, sp.index % ny);
            for j in 0..nz {
                ws.special_in.push(ws.spec[[j, ix, iy]]);
            }
        }
        for_each_row(&mut ws.spec, &mut ws.green_scratch, |ix, row, scr| {
            simd::dispatch(
                #[inline(always)]
                || table.row_kernel(ix, row, scr),
            )
        });
        for (n, sp) in table.special.iter().enumerate() {
            let (ix, iy) = (sp.index / ny, sp.index % ny);
            let col = &ws.special_in[n * nz..(n + 1) * nz];
            for j in 0..nz {
                let row = &sp.matrix[j * nz..(j + 1) * nz];
                let v: C64 = row.iter().zip(col).map(|(m, x)| m * x).sum();
                ws.spec[[j, ix, iy]] = v * norm;
            }
        }
    }
}

/// `f(ix, row, scratch)` for every spectral row `ix` of `spec` ((nz, nx, ny)),
/// in parallel over chunks of consecutive rows, one scratch per chunk.
pub(super) fn for_each_row<T: Send>(
    spec: &mut Array3<C64>,
    scratch: &mut [T],
    f: impl Fn(usize, &mut ArrayViewMut2<C64>, &mut T) + Sync,
) {
    let rows_per = spec.dim().1.div_ceil(scratch.len());
    spec.axis_chunks_iter_mut(Axis(1), rows_per)
        .into_par_iter()
        .zip(scratch.par_iter_mut())
        .enumerate()
        .for_each(|(chunk, (mut block, scr))| {
            for (k, mut row) in block.axis_iter_mut(Axis(1)).enumerate() {
                f(chunk * rows_per + k, &mut row, scr);
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Problem;

    /// `x ← A⁻¹ x` by Gaussian elimination with partial pivoting (A: n × n).
    fn solve(mut a: Vec<C64>, x: &mut [C64]) {
        let n = x.len();
        for k in 0..n {
            let p = (k..n)
                .max_by(|&r, &s| a[r * n + k].norm().total_cmp(&a[s * n + k].norm()))
                .unwrap();
            for t in 0..n {
                a.swap(k * n + t, p * n + t);
            }
            x.swap(k, p);
            for r in k + 1..n {
                let f = a[r * n + k] / a[k * n + k];
                for t in k..n {
                    let akt = a[k * n + t];
                    a[r * n + t] -= f * akt;
                }
                let xk = x[k];
                x[r] -= f * xk;
            }
        }
        for k in (0..n).rev() {
            let s: C64 = (k + 1..n).map(|t| a[k * n + t] * x[t]).sum();
            x[k] = (x[k] - s) / a[k * n + k];
        }
    }

    /// Both operators against a reference built without FFTs, sweeps or
    /// tables: a naive 2-D DFT, per harmonic the dense Galerkin matrix `M`
    /// (`G_b = M`, `G_s = (I − c M)⁻¹ M`), and the naive inverse DFT. The
    /// grid has a grazing order (dense path), a partial block of harmonics
    /// (ny = 11) and evanescent orders whose shifted tables are truncated.
    #[test]
    fn operators_match_dense_reference() {
        let (nx, ny, nz) = (5, 11, 24);
        let lambda = 500.0;
        let eps_b = 1.558f64.powi(2);
        let lat = Problem::lattice(
            [nx, ny, nz],
            [lambda / 1.558, 150.0, 1000.0],
            lambda,
            0.0,
            0.0,
        );
        let slab = lat.slab();
        let c = lat.k0 * lat.k0 * C64::new(1.9 - eps_b, 0.7);
        let gb = GreenTable::new(&lat, C64::new(eps_b, 0.0));
        let gs = ShiftTable::new(&lat, eps_b, c);
        assert!(gb.special_count() > 0);
        assert!(gs.stored_cells() < nx * ny * (nz - 1));
        let u = Array3::from_shape_fn((nz, ny, nx), |(k, j, i)| {
            C64::new(
                (i as f64 + 0.3 * j as f64).sin() + 0.1 * k as f64,
                (k * j) as f64 * 0.05 - 0.4,
            )
        });
        let tau = 2.0 * std::f64::consts::PI;
        let phase = |ix: usize, iy: usize, x: usize, y: usize| {
            let t = tau * ((ix * x) as f64 / nx as f64 + (iy * y) as f64 / ny as f64);
            C64::new(t.cos(), t.sin())
        };
        // Spectrum (ix, iy) → column over z.
        let spec: Vec<Vec<C64>> = (0..nx * ny)
            .map(|h| {
                let (ix, iy) = (h / ny, h % ny);
                (0..nz)
                    .map(|k| {
                        let mut s = ZERO;
                        for y in 0..ny {
                            for x in 0..nx {
                                s += u[[k, y, x]] * phase(ix, iy, x, y).conj();
                            }
                        }
                        s
                    })
                    .collect()
            })
            .collect();
        let mut want_b: Array3<C64> = Array3::zeros((nz, ny, nx));
        let mut want_s: Array3<C64> = Array3::zeros((nz, ny, nx));
        for (h, col) in spec.iter().enumerate() {
            let (ix, iy) = (h / ny, h % ny);
            let [kx, ky] = lat.kappa(ix, iy);
            let g2 = C64::new(lat.k0 * lat.k0 * eps_b - kx * kx - ky * ky, 0.0);
            let m: Vec<C64> = if green::is_small_gamma(&slab, g2) {
                green::dense_small_gamma(&slab, g2, lat.beta(ix, iy)).0
            } else {
                let cf = green::coef_from(&slab, g2, lat.beta(ix, iy));
                (0..nz * nz).map(|i| cf.entry(nz, i / nz, i % nz)).collect()
            };
            let mut gbx: Vec<C64> = (0..nz)
                .map(|j| (0..nz).map(|k| m[j * nz + k] * col[k]).sum())
                .collect();
            let shifted: Vec<C64> = (0..nz * nz)
                .map(|i| {
                    if i / nz == i % nz {
                        1.0 - c * m[i]
                    } else {
                        -c * m[i]
                    }
                })
                .collect();
            let mut gsx = gbx.clone();
            solve(shifted, &mut gsx);
            for (want, v) in [(&mut want_b, &mut gbx), (&mut want_s, &mut gsx)] {
                for y in 0..ny {
                    for x in 0..nx {
                        for k in 0..nz {
                            want[[k, y, x]] += v[k] * phase(ix, iy, x, y) / (nx * ny) as f64;
                        }
                    }
                }
            }
        }
        let op = Operator::new(lat);
        let mut ws = op.workspace();
        let (mut got_b, mut got_s) = (u.clone(), u.clone());
        op.apply(&gb, &mut got_b, &mut ws);
        op.apply_shifted_green(&gs, &mut got_s, &mut ws);
        for (got, want, what) in [(&got_b, &want_b, "G_b"), (&got_s, &want_s, "G_s")] {
            let scale = want.iter().map(|w| w.norm()).fold(0.0, f64::max);
            for (g, w) in got.iter().zip(want.iter()) {
                assert!((g - w).norm() < 1e-11 * scale, "{what}: {g} vs {w}");
            }
        }
    }
}
