//! The sweeps' coefficients: per cell and harmonic the right-hand-side-free
//! part of the down sweep (a Möbius recursion from the top boundary), packed
//! `W` harmonics at a time, and the dense inverses of near-grazing harmonics.

use super::{HarmBlock, HarmConst, HarmonicShift, Step, StepBlock, ZERO};
use crate::solver::settle;
use crate::solver::simd::Cx;
use num_complex::Complex64 as C64;

impl Step {
    pub(super) const ZERO: Step = Step {
        gt: ZERO,
        v: ZERO,
        ua: ZERO,
        ub: ZERO,
        wa: ZERO,
        wb: ZERO,
    };

    pub(super) fn fields(&self) -> [C64; 6] {
        [self.gt, self.v, self.ua, self.ub, self.wa, self.wb]
    }
}

/// The right-hand-side-independent part of the down sweep (see
/// [`ShiftTable::solve_column`]): fills `steps` (N − 1 cells) and returns
/// `[top_u, t_0, t_{N−1}]` and the per-harmonic constants.
pub(super) fn sweep_coefficients(hs: &HarmonicShift, steps: &mut [Step]) -> ([C64; 3], HarmConst) {
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
    // The recursion t → t_next is a contraction (the shifted background is
    // lossy): once t has reached its fixed point to rounding
    // (settle::converged), every later cell repeats this one.
    let mut last_change = f64::INFINITY;
    let mut settled_from = steps.len();
    for (j, step) in steps.iter_mut().enumerate() {
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
        let change = (t_next - t).norm_sqr().sqrt();
        t = t_next;
        if settle::converged(change, last_change, t.norm_sqr().sqrt()) {
            settled_from = j + 1;
            break;
        }
        last_change = change;
    }
    settle::repeat_from(steps, settled_from);
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

impl StepBlock {
    pub(super) const ZERO: StepBlock = StepBlock {
        gt: Cx::ZERO,
        v: Cx::ZERO,
        ua: Cx::ZERO,
        ub: Cx::ZERO,
        wa: Cx::ZERO,
        wb: Cx::ZERO,
    };

    pub(super) fn set(&mut self, k: usize, s: &Step) {
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

/// Dense `(I − c M)⁻¹` by Gauss–Jordan with partial pivoting.
pub(super) fn dense_inverse_shift(m: &[C64], n: usize, c: C64) -> Vec<C64> {
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
