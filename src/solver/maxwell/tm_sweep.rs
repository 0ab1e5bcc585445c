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
    /// Output weights of `u_j`: the cell's `hf = ps + φ` and `zd`.
    hf: C64,
    zd: C64,
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
    hf: Cx,
    zd: Cx,
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

/// Bytes the TM table holds per harmonic for each cell of a layered zone:
/// its down-sweep coefficients and the scale of its `S_z` input.
pub const ZONE_CELL_BYTES: usize =
    (std::mem::size_of::<StepBlock>() + std::mem::size_of::<Cx>()) / W;

/// Per-harmonic constants of the bottom cell: `hf = ps + φ`, `pb`, `zd`,
/// `zb` (outputs), `u_0 = tb b_0 + tz S_z,0` (top), `d_{N−1} = eb b + ez S_z
/// + eu u` (bottom, last cell) and the last cell's output weights. Inputs
/// of a layered top zone are first scaled to the bottom cell's `pb`, `kb`
/// ([`TmTable`]'s zone factors), so these serve every cell.
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

/// The TM sweep coefficients of every harmonic of a lattice for one shift
/// profile (`c_j` per z cell).
pub struct TmTable {
    n: usize,
    nb: usize,
    /// The bulk of the profile ([`settle::bulk_run`]): cells
    /// `bulk.0..bulk.1` share one shift; the cells before and after are the
    /// zone (a layered top and bottom).
    pub(super) bulk: (usize, usize),
    /// Per zone cell (the top's, then the bottom's):
    /// `pb_j / pb_bulk = (k0² ε_b + c_bulk)/(k0² ε_b + c_j)` (the same for
    /// every harmonic).
    zone_f: Vec<Cx>,
    /// Per block of `W` harmonics (layout (ix, block)) and zone cell:
    /// `kb_j / kb_bulk = zb_j / zb_bulk = (γ² + c_bulk)/(γ² + c_j)`.
    zone_z: Vec<Cx>,
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
    /// Build for the binder `eps_b` and the shift `c[j]` of each z cell
    /// (Im c > 0 for the table to settle; any profile is exact).
    pub fn new(lat: &Lattice, eps_b: f64, c: &[C64]) -> Self {
        let slab = lat.slab();
        let n = lat.nz;
        assert_eq!(c.len(), n, "one shift per z cell");
        let (nx, ny) = (lat.nx, lat.ny);
        let nb = ny.div_ceil(W);
        let cells = n - 1;
        let bulk = settle::bulk_run(c);
        let cb = c[bulk.0];
        let zone = settle::zone_cells(bulk, n).count();
        let k2e = lat.k0 * lat.k0 * eps_b;
        let zone_f = settle::zone_cells(bulk, n)
            .map(|j| Cx::splat((k2e + cb) / (k2e + c[j])))
            .collect();
        let mut zone_z = vec![Cx::splat(ONE); nx * nb * zone];
        let mut dense = Vec::new();
        let mut harm = vec![ConstBlock::ZERO; nx * nb];
        let mut steps = Packed::new(ny, n - bulk.1);
        let mut full = vec![Step::ZERO; ny * cells];
        let mut ks = Vec::with_capacity(n);
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
                ks.clear();
                let kb = column::cell(&h, g2, Pol::Tm, cb, Incident::None);
                ks.extend(c.iter().map(|&cj| {
                    if cj == cb {
                        kb
                    } else {
                        column::cell(&h, g2, Pol::Tm, cj, Incident::None)
                    }
                }));
                let hc = coefficients(&ks, bulk, col);
                let blk = ix * nb + iy / W;
                harm[blk].set(iy % W, &hc);
                let ratios = &mut zone_z[blk * zone..(blk + 1) * zone];
                for (r, j) in ratios.iter_mut().zip(settle::zone_cells(bulk, n)) {
                    r.set(iy % W, (g2 + cb) / (g2 + c[j]));
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
        TmTable {
            n,
            nb,
            bulk,
            zone_f,
            zone_z,
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
            let steps = self.steps.of(ix, b, n - 1);
            // A layered top and bottom: inputs to the bulk cell's pb, kb.
            let zone = self.zone_f.len();
            let i = ix * nb + b;
            let zz = &self.zone_z[i * zone..(i + 1) * zone];
            let cells = settle::zone_cells(self.bulk, n);
            for ((j, rf), rz) in cells.zip(&self.zone_f).zip(zz) {
                xf[j] = xf[j] * *rf;
                xz[j] = xz[j] * *rz;
            }
            let (mut bf, mut bz) = (xf[0], xz[0]);
            let mut u = hb.tb * bf + hb.tz * bz;
            for j in 0..n - 1 {
                let st = steps.at(j);
                let (nf, nz) = (xf[j + 1], xz[j + 1]);
                let (df, dz) = (nf - bf, nz - bz);
                xf[j] = st.hf * u + hb.pb * bf;
                xz[j] = st.zd * u + hb.zb * bz;
                w[j] = st.wab * df + st.waz * dz + st.wb * u;
                u = st.uab * df + st.uaz * dz + st.ub * u;
                bf = nf;
                bz = nz;
            }
            let mut d = hb.eb * bf + hb.ez * bz + hb.eu * u;
            xf[n - 1] = hb.gfl * d + (hb.hf * u + hb.pb * bf);
            xz[n - 1] = hb.gzl * d + (hb.zd * u + hb.zb * bz);
            for j in (0..n - 1).rev() {
                let st = steps.at(j);
                d = st.v * d + w[j];
                xf[j] = st.gf * d + xf[j];
                xz[j] = st.gz * d + xz[j];
            }
        }
        scr.f.scatter(f);
        scr.z.scatter(z);
    }
}

/// The sweep coefficients of one harmonic (see the module docs) from the
/// cells' coefficients `k` (one per z cell; from `zone` on all the bottom
/// cell's): fills `steps` (N − 1 cells; once `t` has settled below the
/// zone, later cells repeat) and returns the per-harmonic constants.
///
/// With cells j above and j + 1 below interface j, `M` takes `fa, fd, ga,
/// gd` of cell j in its first column (with `t_j`) and of cell j + 1 in its
/// second, `R1` those of cell j + 1, and `R0`'s `u_j` terms cell j's; the
/// inputs are already scaled to the bottom cell's `pb`, `kb`.
fn coefficients(k: &[column::Cell], bulk: (usize, usize), steps: &mut [Step]) -> Const {
    let n = k.len();
    let cells = steps.len();
    // Steps from here on touch the layered bottom's cells.
    let tail_start = cells - (n - bulk.1);
    let kb = &k[bulk.0];
    let (q, pb, kbz) = (kb.q, kb.pb, kb.kb);
    // Per cell: (hf, fa, fd, ga, gd, zd).
    let cell = |j: usize| {
        let c = &k[j];
        (
            c.ps + c.phi,
            c.ps + q,
            c.ps + ONE,
            q + c.kd,
            ONE + c.kd,
            c.zd,
        )
    };
    let (_, fa0, fd0, ga0, gd0, _) = cell(0);
    // Top: ta a_0 + td d_0 = −zin kb S_z,0 − zout pb b_0.
    let ta = kb.zin * gd0 + kb.zout * fd0;
    let td = -kb.zin * ga0 + kb.zout * fa0;
    let mut t = -td / ta;
    let mut last_change = f64::INFINITY;
    let mut j = 0;
    while j < cells {
        let (hf, fa, fd, ga, gd, zd) = cell(j);
        let (_, fan, fdn, gan, gdn, _) = cell(j + 1);
        let m00 = fa * t + fd;
        let m01 = -fdn;
        let m10 = ga * t - gd;
        let m11 = -gdn;
        let inv = ONE / (m00 * m11 - m01 * m10);
        let (r10, r11) = (fan, -gan);
        let t_next = (m00 * r11 - m10 * r10) * inv;
        steps[j] = Step {
            hf,
            zd,
            gf: hf * (ONE + t),
            gz: zd * (t - ONE),
            v: (m11 * r10 - m01 * r11) * inv,
            uab: -m10 * pb * inv,
            uaz: m00 * kbz * inv,
            ub: (m10 * fa - m00 * ga) * inv,
            wab: m11 * pb * inv,
            waz: -m01 * kbz * inv,
            wb: (m01 * ga - m11 * fa) * inv,
        };
        let change = (t_next - t).norm();
        t = t_next;
        if j >= bulk.0 && j + 1 < tail_start && settle::converged(change, last_change, t.norm()) {
            let settled = steps[j];
            steps[j + 1..tail_start].fill(settled);
            j = tail_start;
            last_change = f64::INFINITY;
            continue;
        }
        last_change = change;
        j += 1;
    }
    // Bottom: ba a + bd d = −zin kb S_z + zout pb b, with a = t d + u.
    let (hf, fa, fd, ga, gd, zd) = cell(n - 1);
    let ba = kb.zin * ga - kb.zout * fa;
    let bd = -kb.zin * gd - kb.zout * fd;
    let den = ba * t + bd;
    Const {
        hf,
        pb,
        zd,
        zb: kb.zb,
        tb: -kb.zout * pb / ta,
        tz: -kb.zin * kbz / ta,
        eb: kb.zout * pb / den,
        ez: -kb.zin * kbz / den,
        eu: -ba / den,
        gfl: hf * (ONE + t),
        gzl: zd * (t - ONE),
    }
}

impl Step {
    const ZERO: Step = Step {
        hf: ZERO,
        zd: ZERO,
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

    fn fields(&self) -> [C64; 11] {
        [
            self.hf, self.zd, self.gf, self.gz, self.v, self.uab, self.uaz, self.ub, self.wab,
            self.waz, self.wb,
        ]
    }
}

impl StepBlock {
    const ZERO: StepBlock = StepBlock {
        hf: Cx::ZERO,
        zd: Cx::ZERO,
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
        self.hf.set(k, s.hf);
        self.zd.set(k, s.zd);
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
