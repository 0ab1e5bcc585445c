//! The TM half of the shifted vector operator `G_s` on whole spectral rows:
//! per harmonic the same band system as [`column`](super::column) (TM,
//! shift `c`), solved by a reflection-coefficient sweep whose
//! right-hand-side-free coefficients are tabulated once per shift, `W`
//! harmonics per operation (as the scalar [`shift`](crate::solver::shift)
//! table does for TE, which is the scalar kernel).
//!
//! **The sweep.** At interface j the continuity of F and of the normalised
//! flux read, with `a_j = t_j d_j + u_j` carried down from the top boundary,
//! `M (d_j, a_{j+1})ᵀ = R0 + R1 d_{j+1}` with
//! `M = [[(ps+q) t_j + ps+1, −(ps+1)], [(q+kd) t_j − (1+kd), −(1+kd)]]`,
//! `R1 = (ps+q, −(q+kd))`, `R0 = (pb Δb − (ps+q) u_j, kb Δz − (q+kd) u_j)`
//! (`Δb = b_{j+1} − b_j`, `Δz` likewise for `S_z`). Solving gives
//! `a_{j+1} = t_{j+1} d_{j+1} + u_{j+1}` (the Möbius recursion of `t`, a
//! reflection coefficient) and `d_j = v_j d_{j+1} + w_j`; the bottom's
//! outgoing condition closes it and an up sweep recovers every `d_j`. The
//! outputs are `w_f = (ps+φ)(a_j + d_j) + pb b_j` and
//! `w_z = zd (a_j − d_j) + zb S_z,j`.
//!
//! **Storage.** Every coefficient of cell j is a function of `t_j`, and the
//! recursion converges geometrically where the shifted background is lossy;
//! per block of `W` harmonics only the cells until all have settled to
//! rounding are stored (the scalar table's scheme).
//!
//! Near-grazing harmonics ([`green::is_small_gamma`]) come out zero here;
//! the caller applies their contour-averaged column solve.

use super::column::{self, Harmonic, Incident, Pol};
use crate::solver::green;
use crate::solver::lattice::Lattice;
use crate::solver::settle::{self, Packed};
use crate::solver::simd::{self, Cx, RowCells, W};
use ndarray::ArrayViewMut2;
use num_complex::Complex64 as C64;

const ZERO: C64 = C64 { re: 0.0, im: 0.0 };
const ONE: C64 = C64 { re: 1.0, im: 0.0 };

/// One cell's sweep coefficients (one harmonic).
#[derive(Debug, Clone, Copy)]
struct Step {
    /// Output weights of `d_j`: `(ps+φ)(1+t_j)` and `zd (t_j − 1)`.
    gf: C64,
    gz: C64,
    v: C64,
    /// `u_{j+1} = uab Δb + uaz Δz + ub u_j`.
    uab: C64,
    uaz: C64,
    ub: C64,
    /// `w_j = wab Δb + waz Δz + wb u_j`.
    wab: C64,
    waz: C64,
    wb: C64,
}

#[derive(Debug, Clone, Copy)]
struct StepBlock {
    gf: Cx,
    gz: Cx,
    v: Cx,
    uab: Cx,
    uaz: Cx,
    ub: Cx,
    wab: Cx,
    waz: Cx,
    wb: Cx,
}

/// Per-harmonic constants: `hf = ps + φ`, `pb`, `zd`, `zb` (outputs),
/// `u_0 = tb b_0 + tz S_z,0` (top), `d_{N−1} = eb b + ez S_z + eu u`
/// (bottom, last cell) and the last cell's output weights.
#[derive(Debug, Clone, Copy)]
struct Const {
    hf: C64,
    pb: C64,
    zd: C64,
    zb: C64,
    tb: C64,
    tz: C64,
    eb: C64,
    ez: C64,
    eu: C64,
    gfl: C64,
    gzl: C64,
}

#[derive(Debug, Clone, Copy)]
struct ConstBlock {
    hf: Cx,
    pb: Cx,
    zd: Cx,
    zb: Cx,
    tb: Cx,
    tz: Cx,
    eb: Cx,
    ez: Cx,
    eu: Cx,
    gfl: Cx,
    gzl: Cx,
}

/// The TM sweep coefficients of every harmonic of a lattice for one shift.
pub struct TmTable {
    n: usize,
    nb: usize,
    /// Spectral indices ix·ny + iy of the near-grazing harmonics.
    dense: Vec<usize>,
    steps: Packed<StepBlock>,
    harm: Vec<ConstBlock>,
}

/// Per-row scratch of [`TmTable::row`].
pub struct TmRowScratch {
    f: RowCells,
    z: RowCells,
    w: Vec<Cx>,
}

impl TmRowScratch {
    pub fn new(n: usize, ny: usize) -> Self {
        TmRowScratch {
            f: RowCells::new(n, ny),
            z: RowCells::new(n, ny),
            w: vec![Cx::ZERO; n],
        }
    }
}

impl TmTable {
    /// Build for the binder `eps_b` and shift `c` (Im c > 0 for the table
    /// to settle; any c is exact).
    pub fn new(lat: &Lattice, eps_b: f64, c: C64) -> Self {
        let slab = lat.slab();
        let n = lat.nz;
        let (nx, ny) = (lat.nx, lat.ny);
        let nb = ny.div_ceil(W);
        let cells = n - 1;
        let mut dense = Vec::new();
        let mut harm = vec![ConstBlock::ZERO; nx * nb];
        let mut steps = Packed::new(ny);
        let mut full = vec![Step::ZERO; ny * cells];
        for ix in 0..nx {
            for iy in 0..ny {
                let col = &mut full[iy * cells..(iy + 1) * cells];
                let h = Harmonic::at(lat, eps_b, ix, iy);
                let g2 = h.gamma2();
                if green::is_small_gamma(&slab, g2) {
                    dense.push(ix * ny + iy);
                    col.fill(Step::ZERO);
                    continue;
                }
                let k = column::cell(&h, g2, Pol::Tm, c, Incident::None);
                let hc = coefficients(&k, col);
                harm[ix * nb + iy / W].set(iy % W, &hc);
            }
            steps.push_row(
                &full,
                cells,
                |a, b| settle::same(&a.fields(), &b.fields()),
                StepBlock::ZERO,
                |b, k, s| b.set(k, s),
            );
        }
        TmTable {
            n,
            nb,
            dense,
            steps,
            harm,
        }
    }

    /// Spectral indices of the harmonics left to the column solve.
    pub fn dense_indices(&self) -> &[usize] {
        &self.dense
    }

    /// Down-sweep cells stored, summed over harmonics.
    pub fn stored_cells(&self) -> usize {
        self.steps.stored_cells()
    }

    /// `(F, S_z) ← G_s (F, S_z)` in TM for every harmonic of spectral row
    /// `ix`: `f` holds `S_κ` in and `E_κ` out, `z` holds `S_z` in and `E_z`
    /// out, each (N, ny); inputs are scaled by `scale` (the inverse FFT's
    /// normalisation) on the way in.
    pub fn row(
        &self,
        ix: usize,
        f: &mut ArrayViewMut2<C64>,
        z: &mut ArrayViewMut2<C64>,
        scr: &mut TmRowScratch,
        scale: f64,
    ) {
        simd::dispatch(
            #[inline(always)]
            || self.row_kernel(ix, f, z, scr, scale),
        );
    }

    #[inline(always)]
    fn row_kernel(
        &self,
        ix: usize,
        f: &mut ArrayViewMut2<C64>,
        z: &mut ArrayViewMut2<C64>,
        scr: &mut TmRowScratch,
        scale: f64,
    ) {
        let (n, nb) = (self.n, self.nb);
        let s = Cx::splat(C64::new(scale, 0.0));
        let hbs = &self.harm[ix * nb..(ix + 1) * nb];
        let fcells = scr.f.gather(f, |_, x| x * s);
        let zcells = scr.z.gather(z, |_, x| x * s);
        let w = &mut scr.w;
        for (b, ((hb, xf), xz)) in hbs.iter().zip(fcells).zip(zcells).enumerate() {
            let steps = self.steps.of(ix, b);
            let last = steps.len().saturating_sub(1);
            let (mut bf, mut bz) = (xf[0], xz[0]);
            let mut u = hb.tb * bf + hb.tz * bz;
            for j in 0..n - 1 {
                let st = &steps[j.min(last)];
                let (nf, nz) = (xf[j + 1], xz[j + 1]);
                let (df, dz) = (nf - bf, nz - bz);
                xf[j] = hb.hf * u + hb.pb * bf;
                xz[j] = hb.zd * u + hb.zb * bz;
                w[j] = st.wab * df + st.waz * dz + st.wb * u;
                u = st.uab * df + st.uaz * dz + st.ub * u;
                bf = nf;
                bz = nz;
            }
            let mut d = hb.eb * bf + hb.ez * bz + hb.eu * u;
            xf[n - 1] = hb.gfl * d + (hb.hf * u + hb.pb * bf);
            xz[n - 1] = hb.gzl * d + (hb.zd * u + hb.zb * bz);
            for j in (0..n - 1).rev() {
                let st = &steps[j.min(last)];
                d = st.v * d + w[j];
                xf[j] = st.gf * d + xf[j];
                xz[j] = st.gz * d + xz[j];
            }
        }
        scr.f.scatter(f);
        scr.z.scatter(z);
    }
}

/// The sweep coefficients of one harmonic (see the module docs): fills
/// `steps` (N − 1 cells; once `t` has settled, later cells repeat) and
/// returns the per-harmonic constants.
fn coefficients(k: &column::Cell, steps: &mut [Step]) -> Const {
    let (q, ps, pb, kd, kb) = (k.q, k.ps, k.pb, k.kd, k.kb);
    let hf = ps + k.phi;
    let (fa, fd) = (ps + q, ps + ONE);
    let (ga, gd) = (q + kd, ONE + kd);
    // Top: ta a_0 + td d_0 = −zin kb S_z,0 − zout pb b_0.
    let ta = k.zin * gd + k.zout * fd;
    let td = -k.zin * ga + k.zout * fa;
    let mut t = -td / ta;
    let mut last_change = f64::INFINITY;
    let mut settled_from = steps.len();
    for (j, step) in steps.iter_mut().enumerate() {
        let m00 = fa * t + fd;
        let m01 = -fd;
        let m10 = ga * t - gd;
        let m11 = -gd;
        let inv = ONE / (m00 * m11 - m01 * m10);
        let (r10, r11) = (fa, -ga);
        let t_next = (m00 * r11 - m10 * r10) * inv;
        *step = Step {
            gf: hf * (ONE + t),
            gz: k.zd * (t - ONE),
            v: (m11 * r10 - m01 * r11) * inv,
            uab: -m10 * pb * inv,
            uaz: m00 * kb * inv,
            ub: (m10 * fa - m00 * ga) * inv,
            wab: m11 * pb * inv,
            waz: -m01 * kb * inv,
            wb: (m01 * ga - m11 * fa) * inv,
        };
        let change = (t_next - t).norm();
        t = t_next;
        if settle::converged(change, last_change, t.norm()) {
            settled_from = j + 1;
            break;
        }
        last_change = change;
    }
    settle::repeat_from(steps, settled_from);
    // Bottom: ba a + bd d = −zin kb S_z + zout pb b, with a = t d + u.
    let ba = k.zin * ga - k.zout * fa;
    let bd = -k.zin * gd - k.zout * fd;
    let den = ba * t + bd;
    Const {
        hf,
        pb,
        zd: k.zd,
        zb: k.zb,
        tb: -k.zout * pb / ta,
        tz: -k.zin * kb / ta,
        eb: k.zout * pb / den,
        ez: -k.zin * kb / den,
        eu: -ba / den,
        gfl: hf * (ONE + t),
        gzl: k.zd * (t - ONE),
    }
}

impl Step {
    const ZERO: Step = Step {
        gf: ZERO,
        gz: ZERO,
        v: ZERO,
        uab: ZERO,
        uaz: ZERO,
        ub: ZERO,
        wab: ZERO,
        waz: ZERO,
        wb: ZERO,
    };

    fn fields(&self) -> [C64; 9] {
        [
            self.gf, self.gz, self.v, self.uab, self.uaz, self.ub, self.wab, self.waz, self.wb,
        ]
    }
}

impl StepBlock {
    const ZERO: StepBlock = StepBlock {
        gf: Cx::ZERO,
        gz: Cx::ZERO,
        v: Cx::ZERO,
        uab: Cx::ZERO,
        uaz: Cx::ZERO,
        ub: Cx::ZERO,
        wab: Cx::ZERO,
        waz: Cx::ZERO,
        wb: Cx::ZERO,
    };

    fn set(&mut self, k: usize, s: &Step) {
        self.gf.set(k, s.gf);
        self.gz.set(k, s.gz);
        self.v.set(k, s.v);
        self.uab.set(k, s.uab);
        self.uaz.set(k, s.uaz);
        self.ub.set(k, s.ub);
        self.wab.set(k, s.wab);
        self.waz.set(k, s.waz);
        self.wb.set(k, s.wb);
    }
}

impl ConstBlock {
    const ZERO: ConstBlock = ConstBlock {
        hf: Cx::ZERO,
        pb: Cx::ZERO,
        zd: Cx::ZERO,
        zb: Cx::ZERO,
        tb: Cx::ZERO,
        tz: Cx::ZERO,
        eb: Cx::ZERO,
        ez: Cx::ZERO,
        eu: Cx::ZERO,
        gfl: Cx::ZERO,
        gzl: Cx::ZERO,
    };

    fn set(&mut self, k: usize, c: &Const) {
        self.hf.set(k, c.hf);
        self.pb.set(k, c.pb);
        self.zd.set(k, c.zd);
        self.zb.set(k, c.zb);
        self.tb.set(k, c.tb);
        self.tz.set(k, c.tz);
        self.eb.set(k, c.eb);
        self.ez.set(k, c.ez);
        self.eu.set(k, c.eu);
        self.gfl.set(k, c.gfl);
        self.gzl.set(k, c.gzl);
    }
}
