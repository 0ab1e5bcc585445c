//! The column and row solves of [`ShiftTable`]: `(I − c G_h)⁻¹` and `G_s`
//! on one harmonic's column (scalar, with the boundary values of the
//! continuous field), and `G_s` on a whole spectral row, `W` harmonics per
//! operation, with the same arithmetic lane by lane.

use super::{BandScratch, HarmBlock, RowScratch, ShiftTable, ZERO};
use crate::solver::simd::{self, Cx, W};
use num_complex::Complex64 as C64;

impl ShiftTable {
    /// `col ← (I − G_h C)⁻¹ col` for harmonic `index` (column in `scr.col`).
    ///
    /// With `h = κ/2` and `Δ_j = (b_j − b_{j+1})/γ_s²`, continuity at interface
    /// j reads `a_{j+1} = q a_j − s_j`, `d_j = q d_{j+1} + s_j`,
    /// `s_j = Δ_j/2 + h (σ_j − σ_{j+1})`, `σ = a + d`. A down sweep carries the
    /// reflection relation `a_j = t_j d_j + u_j` from the top boundary
    /// (|t_j| ≲ 1: a reflection coefficient, so the sweep is stable), the
    /// bottom boundary closes it, and an up sweep recovers every `d_j`, `a_j`.
    /// With a shift `C` that differs between cells the inverse is
    /// `(I − G_h C)⁻¹ = I + G_s C` (what turns the incident field into the
    /// shifted background's, `u_s`); with one shift both orders agree.
    pub fn solve_column(&self, index: usize, scr: &mut BandScratch) {
        if self.h[index].is_none() {
            self.dense_column(index, scr, Output::ShiftInverse);
            return;
        }
        let x = scr.col.clone();
        if self.bulk == (0, self.n) {
            // One shift: `b + c G_s b`.
            let c = self.c[0];
            self.shifted_green_column(index, scr);
            for (y, x) in scr.col.iter_mut().zip(x) {
                *y = x + c * *y;
            }
            return;
        }
        for (y, c) in scr.col.iter_mut().zip(&self.c) {
            *y *= c;
        }
        self.shifted_green_column(index, scr);
        for (y, x) in scr.col.iter_mut().zip(x) {
            *y += x;
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
        // x' = x s, times the layered zone's own factor (as the row kernel).
        for x in col.iter_mut() {
            *x *= s;
        }
        self.scale_zone_lane(ix, b, k, col);
        let x0 = col[0];
        let mut bp = x0;
        let mut u = top * bp;
        let u0 = u;
        for j in 0..n - 1 {
            let st = steps.at(j);
            let bn = col[j + 1];
            let delta = bp - bn;
            col[j] = st.g.lane(k) * u - bp;
            scr.w[j] = st.wa.lane(k) * delta + st.wb.lane(k) * u;
            u = st.ua.lane(k) * delta + st.ub.lane(k) * u;
            bp = bn;
        }
        let mut d = eb * bp + eu * u;
        col[n - 1] = gtl * d + (g * u - bp);
        // w(H) = p + a q + d with p = −x' − κ σ.
        let a = t_last * d + u;
        let wh = -bp - hs.kappa_bottom * (a + d) + a * hs.q + d;
        for j in (0..n - 1).rev() {
            let st = steps.at(j);
            d = st.v.lane(k) * d + scr.w[j];
            col[j] = st.gt.lane(k) * d + col[j];
        }
        // w(0) = p_0 + a_0 + d_0 q.
        let a = t0 * d + u0;
        let w0 = -x0 - hs.kappa_top * (a + d) + a + d * hs.q;
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
                let src = x + self.c[k] * y;
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
        let (n, nb) = (self.n, self.nb);
        let hbs = &self.harm[ix * nb..(ix + 1) * nb];
        let cells = scr.cells.gather(row, |b, x| x * scale(&hbs[b], normalised));
        let w = &mut scr.w;
        for (b, (hb, x)) in hbs.iter().zip(cells).enumerate() {
            let steps = self.steps_of(ix, b);
            self.scale_zone(ix, b, x);
            // Down sweep: w_j to scratch, g u_j − x'_j in place.
            let mut bp = x[0];
            let mut u = hb.top * bp;
            for j in 0..n - 1 {
                let st = steps.at(j);
                let bn = x[j + 1];
                let delta = bp - bn;
                x[j] = st.g * u - bp;
                w[j] = st.wa * delta + st.wb * u;
                u = st.ua * delta + st.ub * u;
                bp = bn;
            }
            // Bottom closure, then the up sweep adding gt_j d_j.
            let mut d = hb.eb * bp + hb.eu * u;
            x[n - 1] = hb.gtl * d + (hb.g * u - bp);
            for j in (0..n - 1).rev() {
                let st = steps.at(j);
                d = st.v * d + w[j];
                x[j] = st.gt * d + x[j];
            }
        }
        scr.cells.scatter(row);
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

/// What a column sweep returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Output {
    ShiftInverse,
    ShiftedGreen,
}

#[cfg(test)]
mod tests {
    use super::super::coef::dense_inverse_shift;
    use super::*;
    use crate::solver::green;

    /// A layered shift: air-like cells on top of a lossy mean, the mean,
    /// and two other cells at the bottom.
    fn layered(k0: f64, eps_b: f64, n: usize) -> Vec<C64> {
        (0..n)
            .map(|j| {
                let e = match j {
                    0 => C64::new(1.05, 0.3),
                    1 => C64::new(1.4, 0.4),
                    2 => C64::new(2.0, 0.2),
                    j if j + 1 == n => C64::new(1.1, 0.3),
                    j if j + 2 == n => C64::new(1.6, 0.5),
                    _ => C64::new(1.9, 0.7),
                };
                k0 * k0 * (e - eps_b)
            })
            .collect()
    }

    /// The sweep against a dense solve of (I − C G_h) y = b built from the
    /// Galerkin entries, for propagating, evanescent and near-grazing
    /// harmonics, with one shift in every cell and with a layered top.
    #[test]
    fn sweep_matches_dense() {
        let n = 12;
        let lambda = 500.0;
        let k0 = 2.0 * std::f64::consts::PI / lambda;
        let eps_b = 1.558f64.powi(2);
        let size = [900.0, 900.0, 600.0];
        let uniform = vec![k0 * k0 * C64::new(1.9 - eps_b, 0.7); n];
        for (polar, c) in [
            (0.0, &uniform),
            (30.0, &uniform),
            (0.0, &layered(k0, eps_b, n)),
            (30.0, &layered(k0, eps_b, n)),
        ] {
            let lat = crate::solver::Problem::lattice([6, 6, n], size, lambda, polar, 0.0);
            let table = ShiftTable::layered(&lat, eps_b, c);
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
                    let src: Vec<C64> = (0..n).map(|k| b[k] + c[k] * gs_b[k]).collect();
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

    /// The row-vectorised sweep equals the column sweep bit for bit, with
    /// one shift and with a layered top.
    #[test]
    fn row_sweep_equals_column_sweep() {
        let n = 10;
        let lat =
            crate::solver::Problem::lattice([5, 7, n], [900.0, 700.0, 600.0], 480.0, 25.0, 10.0);
        let eps_b = 1.558f64.powi(2);
        let c = lat.k0 * lat.k0 * C64::new(1.7 - eps_b, 0.9);
        for table in [
            ShiftTable::new(&lat, eps_b, c),
            ShiftTable::layered(&lat, eps_b, &layered(lat.k0, eps_b, n)),
        ] {
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
}
