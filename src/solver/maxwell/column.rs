//! One harmonic of the vector slab problem: the field of cell-constant
//! sources in the background slab, TE (s) or TM (κ, z), exact in z.
//!
//! For a harmonic with lateral wave number κ, `γ² = k0² ε_b − κ²` inside the
//! slab and `β` outside (vacuum), Maxwell's equations with a source
//! `S = k0² P` (P the contrast polarisation, constant in each z cell) split
//! into (METHOD §9):
//!
//! * **TE**: `F = E_s`, `F'' + γ² F = −S_s`; `F` and `F'` continuous;
//!   outgoing `F' = ∓iβF` above and below.
//! * **TM**: `F = E_κ`, `F'' + γ² F = −γ² S_κ / (k0² ε_b)` in each cell,
//!   `E_z = (iκ F' − S_z)/γ²`; `F` and `h = F' − iκE_z` (∝ H_s)
//!   continuous; outgoing `h = ∓i(k0²/β) F`.
//!
//! In cell j the field is `F = p_j + a_j e^{iγ(z−z_j)} + d_j e^{iγ(z_{j+1}−z)}`
//! (decaying exponentials only). The *shifted* operator
//! `G_s = (I − c G_b)⁻¹ G_b` is found the same way: its output `w` is the
//! cell average of the field whose source is `b + c w`, so the cell's
//! particular part `p_j` is eliminated locally in terms of `a_j + d_j` (as the
//! scalar [`shift`](crate::solver::shift) module does), and `c = 0` gives
//! `G_b` itself. Continuity at the N − 1 inner interfaces and the two
//! outgoing conditions give 2N equations for `(a_j, d_j)`, a band matrix of
//! half-width 2 solved by Gaussian elimination with partial pivoting, O(N).
//!
//! The representation degenerates as γ → 0 (a harmonic grazing inside the
//! binder); there the column is the mean over the scalar kernel's circle in
//! γ² ([`green::is_small_gamma`], [`green::contour`]): the answer is
//! analytic in γ², and the nearest guided-mode pole is far outside the
//! circle.
//!
//! Takes the harmonic's constants ([`Harmonic`]) and the source columns;
//! gives the cell averages and the boundary values `F(0)`, `F(H)` of the
//! continuous field. Scratch ([`ColumnScratch`]) is the caller's.

use crate::solver::green::{self, Slab};
use crate::solver::lattice::Lattice;
use num_complex::Complex64 as C64;

const ZERO: C64 = C64 { re: 0.0, im: 0.0 };
const ONE: C64 = C64 { re: 1.0, im: 0.0 };
/// Half-widths of the band (rows × unknowns).
const KL: usize = 2;
const KU: usize = 2;
/// Stored diagonals per column: KL below, KU above and KL of fill-in.
const LD: usize = 2 * KL + KU + 1;

/// Which of the two scalar problems of a harmonic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pol {
    Te,
    Tm,
}

/// The constants of one harmonic.
#[derive(Debug, Clone, Copy)]
pub struct Harmonic {
    pub slab: Slab,
    /// Background permittivity inside the slab (the binder).
    pub eps_b: C64,
    /// |κ|.
    pub kappa: f64,
    /// β in vacuum (Im ≥ 0).
    pub beta: C64,
}

impl Harmonic {
    /// The harmonic at FFT indices (ix, iy) of `lat`, binder `eps_b` inside.
    pub fn at(lat: &Lattice, eps_b: f64, ix: usize, iy: usize) -> Harmonic {
        let [kx, ky] = lat.kappa(ix, iy);
        Harmonic {
            slab: lat.slab(),
            eps_b: C64::new(eps_b, 0.0),
            kappa: kx.hypot(ky),
            beta: lat.beta(ix, iy),
        }
    }

    pub(super) fn gamma2(&self) -> C64 {
        let k0 = self.slab.k0;
        k0 * k0 * self.eps_b - self.kappa * self.kappa
    }
}

/// An incident plane wave of unit amplitude from above (harmonic 00 only).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Incident {
    None,
    /// E along ê_s.
    Te,
    /// E along p̂ = (β ê_κ − κ ẑ)/k0: `E_κ = β/k0`, `E_z = −κ/k0`.
    Tm,
}

/// The source and the output of one column solve.
pub struct Column<'a> {
    /// Source of F's equation per cell: `S_s` (TE) or `S_κ` (TM).
    pub b_f: &'a [C64],
    /// `S_z` per cell (TM only; ignored for TE).
    pub b_z: &'a [C64],
    /// Cell averages of F (out).
    pub w_f: &'a mut [C64],
    /// Cell averages of E_z (out, TM only).
    pub w_z: &'a mut [C64],
}

/// Working memory of one column solve.
pub struct ColumnScratch {
    band: Vec<C64>,
    rhs: Vec<C64>,
    acc_f: Vec<C64>,
    acc_z: Vec<C64>,
}

impl ColumnScratch {
    pub fn new(nz: usize) -> ColumnScratch {
        ColumnScratch {
            band: vec![ZERO; 2 * nz * LD],
            rhs: vec![ZERO; 2 * nz],
            acc_f: vec![ZERO; nz],
            acc_z: vec![ZERO; nz],
        }
    }
}

/// Solve one column: `w = G_s b` with the shift `c[j]` of each z cell
/// (`c = 0`: `G_b b`), plus the field of `incident`. Returns `(F(0), F(H))`
/// of the continuous field, incident wave included.
pub fn solve(
    h: &Harmonic,
    pol: Pol,
    c: &[C64],
    incident: Incident,
    col: &mut Column,
    scr: &mut ColumnScratch,
) -> (C64, C64) {
    let g2 = h.gamma2();
    if !green::is_small_gamma(&h.slab, g2) {
        return solve_at(h, g2, pol, c, incident, col, scr);
    }
    // Mean over a circle in γ² (the answer is analytic there).
    let n = h.slab.nz;
    let mut acc_f = std::mem::take(&mut scr.acc_f);
    let mut acc_z = std::mem::take(&mut scr.acc_z);
    acc_f.iter_mut().for_each(|v| *v = ZERO);
    acc_z.iter_mut().for_each(|v| *v = ZERO);
    let (mut top, mut bottom) = (ZERO, ZERO);
    let w = green::CONTOUR_WEIGHT;
    for point in green::contour(&h.slab, g2) {
        let (t, b) = solve_at(h, point, pol, c, incident, col, scr);
        top += w * t;
        bottom += w * b;
        for j in 0..n {
            acc_f[j] += w * col.w_f[j];
            if pol == Pol::Tm {
                acc_z[j] += w * col.w_z[j];
            }
        }
    }
    col.w_f.copy_from_slice(&acc_f);
    if pol == Pol::Tm {
        col.w_z.copy_from_slice(&acc_z);
    }
    scr.acc_f = acc_f;
    scr.acc_z = acc_z;
    (top, bottom)
}

/// The cell coefficients of a harmonic at one γ² (see the module docs);
/// the row sweeps of [`tm_sweep`](super::tm_sweep) take TM's from here.
#[derive(Debug, Clone, Copy)]
pub(super) struct Cell {
    pub(super) q: C64,
    pub(super) phi: C64,
    /// p_j = ps (a_j + d_j) + pb b_f,j.
    pub(super) ps: C64,
    pub(super) pb: C64,
    /// Normalised flux offset f̃_j = kd (a_j − d_j) + kb b_z,j (TM).
    pub(super) kd: C64,
    pub(super) kb: C64,
    /// E_z average: w_z = zd (a_j − d_j) + zb b_z,j (TM).
    pub(super) zd: C64,
    pub(super) zb: C64,
    /// Boundary rows: zin (flux) + zout F = rhs.
    pub(super) zin: C64,
    pub(super) zout: C64,
    pub(super) rhs_top: C64,
}

pub(super) fn cell(h: &Harmonic, g2: C64, pol: Pol, c: C64, incident: Incident) -> Cell {
    let gamma = green::sqrt_branch(g2);
    let x = C64::i() * gamma * h.slab.dz();
    let q = x.exp();
    let phi = green::phi1(x);
    let k0 = h.slab.k0;
    let k2e = k0 * k0 * h.eps_b;
    match pol {
        Pol::Te => {
            let den = g2 + c;
            Cell {
                q,
                phi,
                ps: -c * phi / den,
                pb: -ONE / den,
                kd: ZERO,
                kb: ZERO,
                zd: ZERO,
                zb: ZERO,
                zin: gamma,
                zout: h.beta,
                rhs_top: if incident == Incident::Te {
                    2.0 * h.beta
                } else {
                    ZERO
                },
            }
        }
        Pol::Tm => {
            let den = k2e + c;
            let den_z = g2 + c;
            let kap = h.kappa;
            Cell {
                q,
                phi,
                ps: -c * phi / den,
                pb: -ONE / den,
                kd: -c * kap * kap * phi / (k2e * den_z),
                kb: kap * gamma / (k2e * den_z),
                zd: -kap * gamma * phi / den_z,
                zb: -ONE / den_z,
                zin: h.beta,
                zout: gamma / h.eps_b,
                rhs_top: if incident == Incident::Tm {
                    2.0 * h.beta * gamma / (k0 * h.eps_b)
                } else {
                    ZERO
                },
            }
        }
    }
}

/// Band storage: column j holds rows j−KU−KL ..= j+KL.
#[inline(always)]
fn at(band: &mut [C64], i: usize, j: usize) -> &mut C64 {
    &mut band[j * LD + (KL + KU + i - j)]
}

/// The cells' coefficients, recomputed only where the shift changes.
struct Cells<'a> {
    h: &'a Harmonic,
    g2: C64,
    pol: Pol,
    c: &'a [C64],
    incident: Incident,
    at: C64,
    k: Cell,
}

impl<'a> Cells<'a> {
    fn new(h: &'a Harmonic, g2: C64, pol: Pol, c: &'a [C64], incident: Incident) -> Self {
        Cells {
            h,
            g2,
            pol,
            c,
            incident,
            at: c[0],
            k: cell(h, g2, pol, c[0], incident),
        }
    }

    /// Cell j's coefficients.
    fn of(&mut self, j: usize) -> Cell {
        if self.c[j] != self.at {
            self.at = self.c[j];
            self.k = cell(self.h, self.g2, self.pol, self.at, self.incident);
        }
        self.k
    }
}

fn solve_at(
    h: &Harmonic,
    g2: C64,
    pol: Pol,
    c: &[C64],
    incident: Incident,
    col: &mut Column,
    scr: &mut ColumnScratch,
) -> (C64, C64) {
    let n = h.slab.nz;
    let m = 2 * n;
    let mut cells = Cells::new(h, g2, pol, c, incident);
    let tm = pol == Pol::Tm;
    let bz = |j: usize| if tm { col.b_z[j] } else { ZERO };
    let band = &mut scr.band[..m * LD];
    band.iter_mut().for_each(|v| *v = ZERO);
    let rhs = &mut scr.rhs[..m];
    let k = cells.of(0);
    let q = k.q;
    // Top: zin[(1+K) a0 − (Q+K) d0 + Kb] + zout[(ps+1) a0 + (ps+Q) d0 + pb b0] = rhs.
    *at(band, 0, 0) = k.zin * (ONE + k.kd) + k.zout * (k.ps + ONE);
    *at(band, 0, 1) = -k.zin * (q + k.kd) + k.zout * (k.ps + q);
    rhs[0] = k.rhs_top - k.zin * k.kb * bz(0) - k.zout * k.pb * col.b_f[0];
    for j in 0..n - 1 {
        // Cells j (above the interface) and j + 1 (below) may differ in shift.
        let (k, l) = (cells.of(j), cells.of(j + 1));
        let (rf, rp) = (2 * j + 1, 2 * j + 2);
        let (a0, d0, a1, d1) = (2 * j, 2 * j + 1, 2 * j + 2, 2 * j + 3);
        // F continuous at z_{j+1}.
        *at(band, rf, a0) = k.ps + q;
        *at(band, rf, d0) = k.ps + ONE;
        *at(band, rf, a1) = -(l.ps + ONE);
        *at(band, rf, d1) = -(l.ps + q);
        rhs[rf] = if l.pb == k.pb {
            k.pb * (col.b_f[j + 1] - col.b_f[j])
        } else {
            l.pb * col.b_f[j + 1] - k.pb * col.b_f[j]
        };
        // Normalised flux continuous.
        *at(band, rp, a0) = q + k.kd;
        *at(band, rp, d0) = -(ONE + k.kd);
        *at(band, rp, a1) = -(ONE + l.kd);
        *at(band, rp, d1) = q + l.kd;
        rhs[rp] = if l.kb == k.kb {
            k.kb * (bz(j + 1) - bz(j))
        } else {
            l.kb * bz(j + 1) - k.kb * bz(j)
        };
    }
    // Bottom: zin[(Q+K) a − (1+K) d + Kb] − zout[(ps+Q) a + (ps+1) d + pb b] = 0.
    let k = cells.of(n - 1);
    let (a, d) = (m - 2, m - 1);
    *at(band, m - 1, a) = k.zin * (q + k.kd) - k.zout * (k.ps + q);
    *at(band, m - 1, d) = -k.zin * (ONE + k.kd) - k.zout * (k.ps + ONE);
    rhs[m - 1] = -k.zin * k.kb * bz(n - 1) + k.zout * k.pb * col.b_f[n - 1];
    band_solve(band, rhs, m);
    for j in 0..n {
        let k = cells.of(j);
        let (aj, dj) = (rhs[2 * j], rhs[2 * j + 1]);
        let p = k.ps * (aj + dj) + k.pb * col.b_f[j];
        col.w_f[j] = p + k.phi * (aj + dj);
        if tm {
            col.w_z[j] = k.zd * (aj - dj) + k.zb * col.b_z[j];
        }
    }
    let k = cells.of(0);
    let (a0, d0) = (rhs[0], rhs[1]);
    let top = k.ps * (a0 + d0) + k.pb * col.b_f[0] + a0 + d0 * q;
    let k = cells.of(n - 1);
    let (al, dl) = (rhs[m - 2], rhs[m - 1]);
    let bottom = k.ps * (al + dl) + k.pb * col.b_f[n - 1] + al * q + dl;
    (top, bottom)
}

/// `x ← A⁻¹ x` for the band matrix A (m × m, half-widths KL, KU), Gaussian
/// elimination with partial pivoting; A is overwritten.
fn band_solve(band: &mut [C64], x: &mut [C64], m: usize) {
    for k in 0..m {
        let last = (k + KL).min(m - 1);
        let mut p = k;
        let mut best = at(band, k, k).norm_sqr();
        for i in k + 1..=last {
            let v = at(band, i, k).norm_sqr();
            if v > best {
                best = v;
                p = i;
            }
        }
        let right = (k + KL + KU).min(m - 1);
        if p != k {
            for j in k..=right {
                let t = *at(band, k, j);
                *at(band, k, j) = *at(band, p, j);
                *at(band, p, j) = t;
            }
            x.swap(k, p);
        }
        let piv = *at(band, k, k);
        if piv == ZERO {
            continue;
        }
        let inv = ONE / piv;
        for i in k + 1..=last {
            let f = *at(band, i, k) * inv;
            if f == ZERO {
                continue;
            }
            for j in k + 1..=right {
                let v = *at(band, k, j);
                *at(band, i, j) -= f * v;
            }
            let xk = x[k];
            x[i] -= f * xk;
        }
    }
    for k in (0..m).rev() {
        let right = (k + KL + KU).min(m - 1);
        let mut s = x[k];
        for (j, xj) in x.iter().enumerate().take(right + 1).skip(k + 1) {
            s -= *at(band, k, j) * xj;
        }
        x[k] = s / *at(band, k, k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(
        h: &Harmonic,
        pol: Pol,
        c: C64,
        b_f: &[C64],
        b_z: &[C64],
    ) -> (Vec<C64>, Vec<C64>, C64, C64) {
        run_layered(h, pol, &vec![c; h.slab.nz], b_f, b_z)
    }

    fn run_layered(
        h: &Harmonic,
        pol: Pol,
        c: &[C64],
        b_f: &[C64],
        b_z: &[C64],
    ) -> (Vec<C64>, Vec<C64>, C64, C64) {
        let n = h.slab.nz;
        let (mut w_f, mut w_z) = (vec![ZERO; n], vec![ZERO; n]);
        let mut scr = ColumnScratch::new(n);
        let (top, bottom) = solve(
            h,
            pol,
            c,
            Incident::None,
            &mut Column {
                b_f,
                b_z,
                w_f: &mut w_f,
                w_z: &mut w_z,
            },
            &mut scr,
        );
        (w_f, w_z, top, bottom)
    }

    fn close(a: &[C64], b: &[C64], tol: f64, what: &str) {
        let scale = b.iter().map(|v| v.norm()).fold(1e-300, f64::max);
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).norm() <= tol * scale, "{what}: {x} vs {y}");
        }
    }

    fn slab() -> Slab {
        Slab {
            k0: 2.0 * std::f64::consts::PI / 500.0,
            thickness: 400.0,
            nz: 7,
        }
    }

    fn sources() -> (Vec<C64>, Vec<C64>) {
        let b_f = (0..7)
            .map(|j| C64::new(1.0 + j as f64, 0.3 * j as f64))
            .collect();
        let b_z = (0..7)
            .map(|j| C64::new(0.5 - 0.2 * j as f64, 0.7))
            .collect();
        (b_f, b_z)
    }

    fn harmonic(kappa_rel: f64) -> Harmonic {
        let s = slab();
        let kappa = kappa_rel * s.k0;
        let beta = green::sqrt_branch(C64::new(s.k0.powi(2) - kappa * kappa, 0.0));
        Harmonic {
            slab: s,
            eps_b: C64::new(1.558f64.powi(2), 0.0),
            kappa,
            beta,
        }
    }

    /// TE with c = 0 is the scalar Galerkin matrix of the slab kernel
    /// ([`green::Coef::entry`], checked there against quadrature of the
    /// closed form), with its boundary functionals; propagating, evanescent
    /// and near-grazing (contour) harmonics.
    #[test]
    fn te_equals_the_scalar_kernel() {
        let s = slab();
        let (b_f, b_z) = sources();
        let grazing = 1.558 * (1.0 - 1e-7);
        for kappa_rel in [0.0, 0.4, 1.3, 2.5, grazing] {
            let h = harmonic(kappa_rel);
            let g2 = h.gamma2();
            let (m, top_w, bot_w) = if green::is_small_gamma(&s, g2) {
                green::dense_small_gamma(&s, g2, h.beta)
            } else {
                let cf = green::coef_from(&s, g2, h.beta);
                let n = s.nz;
                (
                    (0..n * n).map(|i| cf.entry(n, i / n, i % n)).collect(),
                    (0..n).map(|k| cf.top_weight(n, k)).collect(),
                    (0..n).map(|k| cf.bottom_weight(n, k)).collect(),
                )
            };
            let n = s.nz;
            let want: Vec<C64> = (0..n)
                .map(|j| (0..n).map(|k| m[j * n + k] * b_f[k]).sum())
                .collect();
            let (got, _, top, bottom) = run(&h, Pol::Te, ZERO, &b_f, &b_z);
            close(&got, &want, 1e-6, &format!("TE κ/k0 = {kappa_rel}"));
            let t: C64 = top_w.iter().zip(&b_f).map(|(w, b)| w * b).sum();
            let b: C64 = bot_w.iter().zip(&b_f).map(|(w, b)| w * b).sum();
            close(&[top, bottom], &[t, b], 1e-6, "TE boundary values");
        }
    }

    /// The shifted operator is the exact discrete shift of the plain one:
    /// `G_s b − G_b C (G_s b) = G_b b`, both polarisations, propagating,
    /// evanescent and near-grazing, with one shift `C = c` and with a
    /// layered one (other shifts in the top cells, as a relief's air has).
    #[test]
    fn shift_is_exact_for_both_polarisations() {
        let (b_f, b_z) = sources();
        let k2 = slab().k0.powi(2);
        let n = slab().nz;
        let uniform = vec![k2 * C64::new(-0.4, 0.9); n];
        let mut layered = uniform.clone();
        layered[0] = k2 * C64::new(-1.3, 0.3);
        layered[1] = k2 * C64::new(-0.9, 0.5);
        layered[2] = k2 * C64::new(0.2, 0.1);
        for c in [&uniform, &layered] {
            for kappa_rel in [0.0, 0.4, 1.3, 2.5, 1.558 * (1.0 + 1e-8)] {
                let h = harmonic(kappa_rel);
                for pol in [Pol::Te, Pol::Tm] {
                    let (ws_f, ws_z, _, _) = run_layered(&h, pol, c, &b_f, &b_z);
                    let (gb_f, gb_z, _, _) = run(&h, pol, ZERO, &b_f, &b_z);
                    let cw = |w: &[C64]| w.iter().zip(c).map(|(w, c)| c * w).collect::<Vec<_>>();
                    let (gw_f, gw_z, _, _) = run(&h, pol, ZERO, &cw(&ws_f), &cw(&ws_z));
                    let lhs: Vec<C64> = ws_f.iter().zip(&gw_f).map(|(w, g)| w - g).collect();
                    close(&lhs, &gb_f, 1e-8, &format!("{pol:?} F, κ/k0 = {kappa_rel}"));
                    if pol == Pol::Tm {
                        let lhs: Vec<C64> = ws_z.iter().zip(&gw_z).map(|(w, g)| w - g).collect();
                        close(&lhs, &gb_z, 1e-8, &format!("TM E_z, κ/k0 = {kappa_rel}"));
                    }
                }
            }
        }
    }

    /// At κ = 0 TM is TE (same equation, same outgoing condition, β = k0)
    /// and E_z is local: `E_z = −S_z / (k0² ε_b + c)`.
    #[test]
    fn normal_tm_is_te_with_a_local_ez() {
        let (b_f, b_z) = sources();
        let h = harmonic(0.0);
        for c in [ZERO, slab().k0.powi(2) * C64::new(0.3, 0.5)] {
            let (te, _, t0, t1) = run(&h, Pol::Te, c, &b_f, &b_z);
            let (tm, ez, m0, m1) = run(&h, Pol::Tm, c, &b_f, &b_z);
            close(&tm, &te, 1e-10, "E_κ vs E_s");
            close(&[m0, m1], &[t0, t1], 1e-10, "boundary values");
            let want: Vec<C64> = b_z
                .iter()
                .map(|b| -b / (h.slab.k0 * h.slab.k0 * h.eps_b + c))
                .collect();
            close(&ez, &want, 1e-12, "local E_z");
        }
    }
}
