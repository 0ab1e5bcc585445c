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

/// Per cell of the down sweep, independent of the right-hand side:
/// `t_j`, `v_j` and the maps `u_{j+1} = ua Δ_j + ub u_j`, `w_j = wa Δ_j + wb u_j`.
#[derive(Debug, Clone, Copy)]
struct Step {
    t: C64,
    v: C64,
    ua: C64,
    ub: C64,
    wa: C64,
    wb: C64,
}

/// `(I − c G_h)⁻¹` for every harmonic of a lattice.
pub struct ShiftTable {
    pub c: C64,
    /// Spectral layout ix·ny + iy; `None` for dense (near-grazing) harmonics.
    h: Vec<Option<HarmonicShift>>,
    /// Down-sweep coefficients, layout (ix, j, iy): a spectral row's
    /// harmonics are contiguous for each cell j.
    steps: Vec<Step>,
    n: usize,
    ny: usize,
    /// Per harmonic: the top relation's `u_0 = top_u · b_0` factor and the
    /// bottom closure's final t.
    ends: Vec<[C64; 2]>,
    dense: Vec<Dense>,
}

impl ShiftTable {
    /// Build for background `eps_b` (real binder) and shift `c`.
    pub fn new(lat: &Lattice, eps_b: f64, c: C64) -> Self {
        let slab = lat.slab();
        let n = lat.nz;
        let dz = slab.dz();
        let mut h = Vec::with_capacity(lat.harmonics());
        let mut dense = Vec::new();
        for ix in 0..lat.nx {
            for iy in 0..lat.ny {
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
        let mut steps = vec![
            Step {
                t: ZERO,
                v: ZERO,
                ua: ZERO,
                ub: ZERO,
                wa: ZERO,
                wb: ZERO
            };
            h.len() * n
        ];
        let mut ends = vec![[ZERO; 2]; h.len()];
        let ny = lat.ny;
        let mut col = steps[..n].to_vec();
        for (i, hs) in h.iter().enumerate() {
            if let Some(hs) = hs {
                ends[i] = sweep_coefficients(hs, &mut col);
                for (j, st) in col.iter().enumerate() {
                    steps[((i / ny) * n + j) * ny + i % ny] = *st;
                }
            }
        }
        ShiftTable {
            c,
            h,
            dense,
            steps,
            ends,
            n,
            ny,
        }
    }

    fn dense_of(&self, index: usize) -> &Dense {
        self.dense
            .iter()
            .find(|d| d.index == index)
            .expect("dense harmonic")
    }
}

/// The right-hand-side-independent part of the down sweep (see
/// [`ShiftTable::solve_column`]); returns `[top_u, t_last]`.
fn sweep_coefficients(hs: &HarmonicShift, steps: &mut [Step]) -> [C64; 2] {
    let HarmonicShift {
        gamma,
        beta,
        q,
        kappa,
        ..
    } = *hs;
    let h = 0.5 * kappa;
    let den = gamma + beta - beta * kappa;
    let mut t = (gamma * q - beta * q + beta * kappa) / den;
    let top_u = beta / den;
    let n = steps.len();
    for step in steps.iter_mut().take(n - 1) {
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
            t,
            v,
            ua: (m11 * da - m01 * db) * inv,
            ub: (m11 * ea - m01 * eb) * inv,
            wa: (m00 * db - m10 * da) * inv,
            wb: (m00 * eb - m10 * ea) * inv,
        };
        t = t_next;
    }
    steps[n - 1].t = t;
    [top_u, t]
}

/// Scratch for one column solve of N cells.
pub struct BandScratch {
    col: Vec<C64>,
    /// Per cell: t_j, u_j (a_j = t_j d_j + u_j) and v_j, w_j (d_j = v_j d_{j+1} + w_j).
    tuvw: Vec<[C64; 4]>,
}

impl BandScratch {
    pub fn new(n: usize) -> Self {
        BandScratch {
            col: vec![ZERO; n],
            tuvw: vec![[ZERO; 4]; n],
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
    pub fn solve_column(&self, index: usize, scr: &mut BandScratch) {
        self.column(index, scr, Output::ShiftInverse);
    }

    /// `col ← G_s col` with `G_s = (G_h⁻¹ − c)⁻¹` the shifted Green's
    /// operator, never forming `G_h` (whose guided-mode poles it avoids);
    /// returns the continuous field `w = G_h(x + c G_s x)` at z = 0 and z = H.
    pub fn shifted_green_column(&self, index: usize, scr: &mut BandScratch) -> (C64, C64) {
        self.column(index, scr, Output::ShiftedGreen)
    }

    fn column(&self, index: usize, scr: &mut BandScratch, out: Output) -> (C64, C64) {
        let n = scr.col.len();
        let Some(hs) = self.h[index] else {
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
            return (w0, wh);
        };
        let HarmonicShift {
            gamma,
            gamma2,
            inv_gs2,
            beta,
            q,
            kappa,
            phi,
        } = hs;
        let (ix, iy) = (index / self.ny, index % self.ny);
        let step = |j: usize| &self.steps[(ix * self.n + j) * self.ny + iy];
        let [top_u, t_last] = self.ends[index];
        let b = &scr.col;
        let mut u = top_u * b[0] * inv_gs2;
        for j in 0..n - 1 {
            let st = step(j);
            let delta = (b[j] - b[j + 1]) * inv_gs2;
            scr.tuvw[j] = [st.t, u, st.v, st.wa * delta + st.wb * u];
            u = st.ua * delta + st.ub * u;
        }
        // Bottom: outgoing at z = H.
        let ca = gamma * q - beta * q + beta * kappa;
        let cd = -gamma - beta + beta * kappa;
        let mut d = (-beta * b[n - 1] * inv_gs2 - u * ca) / (t_last * ca + cd);
        let mut a = t_last * d + u;
        let mut sig = a + d;
        let last = n - 1;
        // w(H) = p + a q + d with p = −x/γ_s² − κ σ.
        let wh = -scr.col[last] * inv_gs2 - kappa * sig + a * q + d;
        let g_phi = gamma2 * phi * inv_gs2;
        let emit = |x: C64, sig: C64| match out {
            Output::ShiftInverse => gamma2 * (x * inv_gs2 + kappa * sig),
            Output::ShiftedGreen => -x * inv_gs2 + g_phi * sig,
        };
        let x0 = scr.col[0];
        scr.col[last] = emit(scr.col[last], sig);
        for j in (0..n - 1).rev() {
            let [t, uu, v, w] = scr.tuvw[j];
            d = v * d + w;
            a = t * d + uu;
            sig = a + d;
            scr.col[j] = emit(scr.col[j], sig);
        }
        // w(0) = p_0 + a_0 + d_0 q.
        let w0 = -x0 * inv_gs2 - kappa * sig + a + d * q;
        (w0, wh)
    }
}

impl ShiftTable {
    /// `row ← G_s row` for every harmonic of spectral row `ix` at once
    /// (`row` is (N, ny), the cell index outermost), the same arithmetic as
    /// [`Self::shifted_green_column`] with the harmonics innermost so the
    /// loops run over contiguous memory. Near-grazing harmonics take the
    /// dense path.
    pub fn shifted_green_row(
        &self,
        ix: usize,
        row: &mut ndarray::ArrayViewMut2<C64>,
        scr: &mut RowScratch,
    ) {
        let (n, ny) = (self.n, self.ny);
        let hs = &self.h[ix * ny..(ix + 1) * ny];
        let ends = &self.ends[ix * ny..(ix + 1) * ny];
        let steps = &self.steps[ix * n * ny..(ix + 1) * n * ny];
        let (uu, ww) = (&mut scr.u, &mut scr.w);
        let (u, d) = (&mut scr.run_u, &mut scr.run_d);
        // Down sweep.
        {
            let b0 = row.row(0);
            for iy in 0..ny {
                u[iy] = match hs[iy] {
                    Some(h) => ends[iy][0] * b0[iy] * h.inv_gs2,
                    None => ZERO,
                };
            }
        }
        for j in 0..n - 1 {
            let (bj, bn) = (row.row(j), row.row(j + 1));
            let st = &steps[j * ny..(j + 1) * ny];
            let (uj, wj) = (&mut uu[j * ny..(j + 1) * ny], &mut ww[j * ny..(j + 1) * ny]);
            for iy in 0..ny {
                let Some(h) = hs[iy] else { continue };
                let s = &st[iy];
                let delta = (bj[iy] - bn[iy]) * h.inv_gs2;
                uj[iy] = u[iy];
                wj[iy] = s.wa * delta + s.wb * u[iy];
                u[iy] = s.ua * delta + s.ub * u[iy];
            }
        }
        // Bottom closure, then the up sweep writing G_s x in place.
        let last = n - 1;
        {
            let mut bl = row.row_mut(last);
            for iy in 0..ny {
                let Some(h) = hs[iy] else { continue };
                let ca = h.gamma * h.q - h.beta * h.q + h.beta * h.kappa;
                let cd = -h.gamma - h.beta + h.beta * h.kappa;
                let t_last = ends[iy][1];
                d[iy] = (-h.beta * bl[iy] * h.inv_gs2 - u[iy] * ca) / (t_last * ca + cd);
                let sig = t_last * d[iy] + u[iy] + d[iy];
                bl[iy] = -bl[iy] * h.inv_gs2 + h.gamma2 * h.phi * h.inv_gs2 * sig;
            }
        }
        for j in (0..n - 1).rev() {
            let st = &steps[j * ny..(j + 1) * ny];
            let (uj, wj) = (&uu[j * ny..(j + 1) * ny], &ww[j * ny..(j + 1) * ny]);
            let mut bj = row.row_mut(j);
            for iy in 0..ny {
                let Some(h) = hs[iy] else { continue };
                let s = &st[iy];
                d[iy] = s.v * d[iy] + wj[iy];
                let sig = s.t * d[iy] + uj[iy] + d[iy];
                bj[iy] = -bj[iy] * h.inv_gs2 + h.gamma2 * h.phi * h.inv_gs2 * sig;
            }
        }
    }

    /// Spectral indices of the near-grazing (dense) harmonics.
    pub fn dense_indices(&self) -> impl Iterator<Item = usize> + '_ {
        self.dense.iter().map(|d| d.index)
    }
}

/// Per-row scratch of [`ShiftTable::shifted_green_row`].
pub struct RowScratch {
    u: Vec<C64>,
    w: Vec<C64>,
    run_u: Vec<C64>,
    run_d: Vec<C64>,
}

impl RowScratch {
    pub fn new(n: usize, ny: usize) -> Self {
        RowScratch {
            u: vec![ZERO; n * ny],
            w: vec![ZERO; n * ny],
            run_u: vec![ZERO; ny],
            run_d: vec![ZERO; ny],
        }
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
            table.shifted_green_row(ix, &mut row.view_mut(), &mut scr);
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
