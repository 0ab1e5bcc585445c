//! The sweeps' coefficients: per cell and harmonic the right-hand-side-free
//! part of the down sweep (a Möbius recursion from the top boundary), packed
//! `W` harmonics at a time, and the dense inverses of near-grazing harmonics.

use super::{HarmBlock, HarmConst, HarmonicShift, Step, StepBlock, ZERO};
use crate::solver::settle;
use crate::solver::simd::Cx;
use num_complex::Complex64 as C64;

impl Step {
    pub(super) const ZERO: Step = Step {
        g: ZERO,
        gt: ZERO,
        v: ZERO,
        ua: ZERO,
        ub: ZERO,
        wa: ZERO,
        wb: ZERO,
    };

    pub(super) fn fields(&self) -> [C64; 7] {
        [self.g, self.gt, self.v, self.ua, self.ub, self.wa, self.wb]
    }
}

/// The right-hand-side-independent part of the down sweep (see
/// [`ShiftTable::solve_column`]) for the shift `c[j]` of each cell: fills
/// `steps` (N − 1 cells) and returns `[top_u, t_0, t_{N−1}]` and the
/// per-harmonic constants. Cells from `zone` on share the bottom cell's
/// shift, so the recursion may stop there once it has settled.
///
/// With `h_j = κ_j/2`, `κ_j = c_j φ1/(γ² + c_j)`, interface j reads
/// `M (a_{j+1}, d_j)ᵀ = R0 + R1 d_{j+1}` with
/// `M = [[1 − h_{j+1}, (h_j − q) t_j + h_j], [h_{j+1}, 1 − h_j (1 + t_j)]]`,
/// `R1 = (h_{j+1}, q − h_{j+1})`, `R0 = Δ (−1/2, 1/2) + u_j (q − h_j, h_j)`.
pub(super) fn sweep_coefficients(
    hs: &HarmonicShift,
    c: &[C64],
    bulk: (usize, usize),
    steps: &mut [Step],
) -> ([C64; 3], HarmConst) {
    let HarmonicShift {
        gamma,
        gamma2,
        beta,
        q,
        phi,
        kappa_top,
        kappa_bottom,
        ..
    } = *hs;
    let n = c.len();
    let cells = steps.len();
    // Steps from here on touch the layered bottom's cells.
    let tail_start = cells - (n - bulk.1);
    // Per cell: h_j = κ_j / 2 and the output weight g_j = γ² φ1 / (γ² + c_j).
    let cell = |j: usize| {
        let s = 1.0 / (gamma2 + c[j]);
        (0.5 * c[j] * phi * s, gamma2 * phi * s)
    };
    let den = gamma + beta - beta * kappa_top;
    let mut t = (gamma * q - beta * q + beta * kappa_top) / den;
    let t0 = t;
    let top_u = beta / den;
    // The recursion t → t_next is a contraction (the shifted background is
    // lossy): once t has reached its fixed point to rounding
    // (settle::converged) in the bulk, every step up to the layered bottom
    // repeats this one, and the recursion goes on from there.
    let mut last_change = f64::INFINITY;
    let mut j = 0;
    let (mut h, mut g) = cell(0);
    while j < cells {
        let (hn, gn) = cell(j + 1);
        let m00 = 1.0 - hn;
        let m01 = (h - q) * t + h;
        let m10 = hn;
        let m11 = 1.0 - h - h * t;
        let inv = 1.0 / (m00 * m11 - m01 * m10);
        let (r1a, r1b) = (hn, q - hn);
        let t_next = (m11 * r1a - m01 * r1b) * inv;
        let v = (m00 * r1b - m10 * r1a) * inv;
        // R0 = Δ (−1/2, 1/2) + u (q − h, h)
        let (da, db) = (C64::new(-0.5, 0.0), C64::new(0.5, 0.0));
        let (ea, eb) = (q - h, h);
        steps[j] = Step {
            g,
            gt: g * (1.0 + t),
            v,
            ua: (m11 * da - m01 * db) * inv,
            ub: (m11 * ea - m01 * eb) * inv,
            wa: (m00 * db - m10 * da) * inv,
            wb: (m00 * eb - m10 * ea) * inv,
        };
        let change = (t_next - t).norm_sqr().sqrt();
        t = t_next;
        if j >= bulk.0
            && j + 1 < tail_start
            && settle::converged(change, last_change, t.norm_sqr().sqrt())
        {
            let settled = steps[j];
            steps[j + 1..tail_start].fill(settled);
            j = tail_start;
            (h, g) = cell(j);
            last_change = f64::INFINITY;
            continue;
        }
        (h, g) = (hn, gn);
        last_change = change;
        j += 1;
    }
    // Bottom: outgoing at z = H, d = (−β x' − ca u)/(t ca + cd).
    let ca = gamma * q - beta * q + beta * kappa_bottom;
    let cd = -gamma - beta + beta * kappa_bottom;
    let den_b = t * ca + cd;
    let (_, g) = cell(n - 1);
    let hc = HarmConst {
        s: 1.0 / (gamma2 + c[bulk.0]),
        top: top_u,
        eb: -beta / den_b,
        eu: -ca / den_b,
        g,
        gtl: g * (1.0 + t),
    };
    ([top_u, t0, t], hc)
}

impl StepBlock {
    pub(super) const ZERO: StepBlock = StepBlock {
        g: Cx::ZERO,
        gt: Cx::ZERO,
        v: Cx::ZERO,
        ua: Cx::ZERO,
        ub: Cx::ZERO,
        wa: Cx::ZERO,
        wb: Cx::ZERO,
    };

    pub(super) fn set(&mut self, k: usize, s: &Step) {
        self.g.set(k, s.g);
        self.gt.set(k, s.gt);
        self.v.set(k, s.v);
        self.ua.set(k, s.ua);
        self.ub.set(k, s.ub);
        self.wa.set(k, s.wa);
        self.wb.set(k, s.wb);
    }
}

impl HarmBlock {
    pub(super) const ZERO: HarmBlock = HarmBlock {
        s: Cx::ZERO,
        sn: Cx::ZERO,
        top: Cx::ZERO,
        eb: Cx::ZERO,
        eu: Cx::ZERO,
        g: Cx::ZERO,
        gtl: Cx::ZERO,
    };

    pub(super) fn set(&mut self, k: usize, h: &HarmConst, norm: f64) {
        self.s.set(k, h.s);
        self.sn.set(k, h.s * norm);
        self.top.set(k, h.top);
        self.eb.set(k, h.eb);
        self.eu.set(k, h.eu);
        self.g.set(k, h.g);
        self.gtl.set(k, h.gtl);
    }
}

/// Dense `(I − M C)⁻¹` (`C = diag(c)`, one shift per cell; with one shift
/// in every cell `(I − c M)⁻¹`) by Gauss–Jordan with partial pivoting.
pub(super) fn dense_inverse_shift(m: &[C64], n: usize, c: &[C64]) -> Vec<C64> {
    let mut a: Vec<C64> = (0..n * n)
        .map(|i| {
            if i / n == i % n {
                1.0 - m[i] * c[i % n]
            } else {
                -m[i] * c[i % n]
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
