//! Force laws of the dynamics packer: sphere pairs of two particles
//! (overlap repulsion, cluster attraction), walls and the alignment torque.

use super::params::Spec;
use super::state::State;
use super::{ATTRACTION, ATTRACTION_CAP, ATTRACTION_RANGE};
use crate::geometry::cells::EMPTY;
use crate::geometry::periodic::{near_image, near_image_select};
use crate::geometry::vec3::{add, cross, norm};

/// Spring constant and drag (arbitrary units; only ratios matter).
pub(super) const K: f64 = 1.0;

/// Forces of one pair, on `i` (`f`, `mi`) and on `j` (`−f`, `mj`).
pub(super) struct PairForce {
    pub(super) f: [f64; 3],
    pub(super) mi: [f64; 3],
    pub(super) mj: [f64; 3],
    /// Worst overlap depth of the pair (−inf when none).
    pub(super) worst: f64,
}

/// Squared distance between the segments `s a`, `|s| ≤ ha`, and `d + t c`,
/// `|t| ≤ hc` (`a`, `c` unit), by clamping the unconstrained closest points
/// (Ericson, Real-Time Collision Detection §5.1.9).
#[inline]
pub(super) fn segment_distance2(a: &[f64; 3], ha: f64, c: &[f64; 3], hc: f64, d: &[f64; 3]) -> f64 {
    // w(s, t) = s a − d − t c; minimise |w|².
    let b = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
    let da = -(a[0] * d[0] + a[1] * d[1] + a[2] * d[2]);
    let dc = -(c[0] * d[0] + c[1] * d[1] + c[2] * d[2]);
    let denom = 1.0 - b * b;
    let mut s = if denom > 1e-12 {
        ((b * dc - da) / denom).clamp(-ha, ha)
    } else {
        0.0
    };
    let mut t = dc + s * b;
    if t < -hc || t > hc {
        t = t.clamp(-hc, hc);
        s = (t * b - da).clamp(-ha, ha);
    }
    let w = [
        s * a[0] - d[0] - t * c[0],
        s * a[1] - d[1] - t * c[1],
        s * a[2] - d[2] - t * c[2],
    ];
    w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
}

/// Adds the alignment torque of a particle of `spec`, diameter `d`, axis `a`.
#[inline]
pub(super) fn add_field_torque(spec: &Spec, d: f64, a: &[f64; 3], m: &mut [f64; 3]) {
    if spec.field != 0.0 {
        let t = cross(a, &[0.0, 0.0, 1.0]);
        let r_max = spec.r_max * d;
        add(m, &t, spec.field * K * r_max * r_max * a[2]);
    }
}

impl State {
    /// Forces of the pair `(i, j)`; `None` when none acts.
    pub(super) fn pair(&self, i: usize, j: usize) -> Option<PairForce> {
        let (ci, cj) = (self.center[i], self.center[j]);
        let d = [
            near_image(cj[0] - ci[0], self.size[0]),
            near_image(cj[1] - ci[1], self.size[1]),
            cj[2] - ci[2],
        ];
        let (si, sj) = (
            &self.specs[self.species[i] as usize],
            &self.specs[self.species[j] as usize],
        );
        let (di, dj) = (self.scale[i], self.scale[j]);
        let bonded = self.cluster[i] != EMPTY && self.cluster[i] == self.cluster[j];
        // Farthest surface gap at which a force can act.
        let reach_gap = if bonded {
            ATTRACTION_RANGE * 2.0 * (si.r_max * di).max(sj.r_max * dj)
        } else {
            self.skin
        };
        let reach = si.half_length * di + sj.half_length * dj + reach_gap;
        let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if d2 >= reach * reach {
            return None;
        }
        if si.spheres.len() == 1 && sj.spheres.len() == 1 && !bonded {
            // Two one-sphere particles (centred spheres, no torque).
            let rsum = (si.spheres[0].1 * di) + (sj.spheres[0].1 * dj);
            if d2 >= rsum * rsum {
                return None;
            }
            let dist = d2.sqrt();
            let l = rsum - dist;
            let mag = -K * (l + self.push);
            let f = if dist > 1e-12 * rsum {
                [mag * d[0] / dist, mag * d[1] / dist, mag * d[2] / dist]
            } else {
                [0.0, 0.0, -mag]
            };
            return Some(PairForce {
                f,
                mi: [0.0; 3],
                mj: [0.0; 3],
                worst: l,
            });
        }
        let (ai, aj) = (self.axis[i], self.axis[j]);
        if si.spheres.len() > 1 || sj.spheres.len() > 1 {
            // Exact reject: every sphere centre lies on its particle's axis
            // segment, so segments farther apart than the largest radii plus
            // the reach cannot interact (1e-9 relative slack for rounding).
            let g = segment_distance2(&ai, si.s_max * di, &aj, sj.s_max * dj, &d);
            let r = (si.r_max * di + sj.r_max * dj + reach_gap) * (1.0 + 1e-9);
            if g >= r * r {
                return None;
            }
        }
        let mut worst = f64::NEG_INFINITY;
        let mut any = false;
        let (mut fi, mut mi, mut mj) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        let reach_j = sj.half_length * dj + reach_gap;
        for &(oi, ri) in &si.spheres {
            let (oi, ri) = (oi * di, ri * di);
            let pi = [oi * ai[0], oi * ai[1], oi * ai[2]];
            // Skip spheres that cannot reach particle j's bounding sphere.
            let q = [pi[0] - d[0], pi[1] - d[1], pi[2] - d[2]];
            let rr = ri + reach_j;
            if q[0] * q[0] + q[1] * q[1] + q[2] * q[2] >= rr * rr {
                continue;
            }
            for &(oj, rj) in &sj.spheres {
                let (oj, rj) = (oj * dj, rj * dj);
                let pj = [d[0] + oj * aj[0], d[1] + oj * aj[1], d[2] + oj * aj[2]];
                let ab = [pi[0] - pj[0], pi[1] - pj[1], pi[2] - pj[2]];
                let dist = norm(&ab);
                let l = ri + rj - dist;
                let mag = if l > 0.0 {
                    worst = worst.max(l);
                    K * (l + self.push)
                } else if bonded && -l > self.skin && -l < ATTRACTION_RANGE * (ri + rj) {
                    (K * ATTRACTION * l).max(-ATTRACTION_CAP * self.skin)
                } else {
                    continue;
                };
                any = true;
                let f = if dist > 1e-12 * (ri + rj) {
                    [mag * ab[0] / dist, mag * ab[1] / dist, mag * ab[2] / dist]
                } else {
                    [0.0, 0.0, mag]
                };
                add(&mut fi, &f, 1.0);
                add(&mut mi, &cross(&pi, &f), 1.0);
                let rj_vec = [oj * aj[0], oj * aj[1], oj * aj[2]];
                add(&mut mj, &cross(&rj_vec, &f), -1.0);
            }
        }
        any.then_some(PairForce {
            f: fi,
            mi,
            mj,
            worst,
        })
    }

    /// Forces on sphere particle `i` from each of the sphere particles `js`
    /// (components `[x, y, z][lane]`) and the overlaps: the lanes are
    /// independent, so the compiler can vectorise a block of them.
    #[inline(always)]
    pub(super) fn sphere_pairs<const N: usize>(
        &self,
        i: usize,
        js: &[u32; N],
    ) -> ([[f64; N]; 3], [f64; N]) {
        let ci = self.center[i];
        let ri = self.radius0[i];
        let mut d = [[0.0; N]; 3];
        let mut rsum = [0.0; N];
        for k in 0..N {
            let j = js[k] as usize;
            let cj = self.center[j];
            d[0][k] = cj[0] - ci[0];
            d[1][k] = cj[1] - ci[1];
            d[2][k] = cj[2] - ci[2];
            rsum[k] = ri + self.radius0[j];
        }
        let mut f = [[0.0; N]; 3];
        let mut l = [0.0; N];
        for k in 0..N {
            let dx = near_image_select(d[0][k], self.size[0]);
            let dy = near_image_select(d[1][k], self.size[1]);
            let dz = d[2][k];
            let dist = (dx * dx + dy * dy + dz * dz).sqrt();
            let lk = rsum[k] - dist;
            let mag = -K * (lk.max(0.0) + if lk > 0.0 { self.push } else { 0.0 });
            let tiny = dist <= 1e-12 * rsum[k];
            let s = mag / dist;
            f[0][k] = if tiny { 0.0 } else { s * dx };
            f[1][k] = if tiny { 0.0 } else { s * dy };
            f[2][k] = if tiny { -mag } else { s * dz };
            l[k] = lk;
        }
        (f, l)
    }

    /// Force on sphere particle `i` from sphere particle `j` (same as
    /// `pair` for two one-sphere particles without a cluster bond) and
    /// their overlap depth (negative: a gap). Branch-free: whether a listed
    /// pair touches is a coin toss near jamming, and a mispredicted branch
    /// costs more than the arithmetic.
    #[inline(always)]
    pub(super) fn sphere_pair(&self, i: usize, j: usize) -> ([f64; 3], f64) {
        let (f, l) = self.sphere_pairs(i, &[j as u32]);
        ([f[0][0], f[1][0], f[2][0]], l[0])
    }

    /// [`Self::walls`] for a one-sphere particle: the force's z component
    /// and the penetration (branch-free).
    #[inline]
    pub(super) fn sphere_walls(&self, i: usize) -> (f64, f64) {
        let r = self.radius0[i];
        let z = self.center[i][2];
        let below = -self.relief * self.scale[i] + r - z;
        let above = z + r - self.size[2];
        let push = |d: f64| K * (d.max(0.0) + if d > 0.0 { self.push } else { 0.0 });
        (push(below) - push(above), below.max(above))
    }

    /// Wall force and torque on particle `i` and its worst penetration.
    #[inline]
    pub(super) fn walls(&self, i: usize) -> ([f64; 3], [f64; 3], f64) {
        let (c, a) = (self.center[i], self.axis[i]);
        let h = self.size[2];
        let spec = &self.specs[self.species[i] as usize];
        let d = self.scale[i];
        let top = -self.relief * d;
        let mut worst = f64::NEG_INFINITY;
        let (mut f, mut m) = ([0.0; 3], [0.0; 3]);
        for &(o, r) in &spec.spheres {
            let (o, r) = (o * d, r * d);
            let z = c[2] + o * a[2];
            let below = top + r - z;
            let above = z + r - h;
            worst = worst.max(below).max(above);
            let fz = if below > 0.0 {
                K * (below + self.push)
            } else if above > 0.0 {
                -K * (above + self.push)
            } else {
                continue;
            };
            let fv = [0.0, 0.0, fz];
            f[2] += fz;
            add(&mut m, &cross(&[o * a[0], o * a[1], o * a[2]], &fv), 1.0);
        }
        (f, m, worst)
    }

    /// Adds the alignment torque to particle `i` when it is pushed (`f`,
    /// `m` its force and torque): resting particles do not turn, as in the
    /// first-order stage.
    #[inline]
    pub(super) fn add_field_torque_if_pushed(&self, i: usize, f: &[f64; 3], m: &mut [f64; 3]) {
        if *f != [0.0; 3] || *m != [0.0; 3] {
            let spec = &self.specs[self.species[i] as usize];
            add_field_torque(spec, self.scale[i], &self.axis[i], m);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::segment_distance2;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Segment distance against dense sampling of both segments.
    #[test]
    fn segment_distance_matches_sampling() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let unit = |rng: &mut Xoshiro256PlusPlus| {
            let v: [f64; 3] = [
                rng.gen::<f64>() - 0.5,
                rng.gen::<f64>() - 0.5,
                rng.gen::<f64>() - 0.5,
            ];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [v[0] / n, v[1] / n, v[2] / n]
        };
        for case in 0..300 {
            let a = unit(&mut rng);
            // Every tenth case parallel.
            let c = if case % 10 == 0 { a } else { unit(&mut rng) };
            let (ha, hc) = (rng.gen::<f64>() * 2.0, rng.gen::<f64>() * 2.0);
            let d = [
                3.0 * (rng.gen::<f64>() - 0.5),
                3.0 * (rng.gen::<f64>() - 0.5),
                3.0 * (rng.gen::<f64>() - 0.5),
            ];
            let exact = segment_distance2(&a, ha, &c, hc, &d).sqrt();
            let m = 400;
            let mut best = f64::INFINITY;
            for i in 0..=m {
                let s = -ha + 2.0 * ha * i as f64 / m as f64;
                for k in 0..=m {
                    let t = -hc + 2.0 * hc * k as f64 / m as f64;
                    let w = [
                        s * a[0] - d[0] - t * c[0],
                        s * a[1] - d[1] - t * c[1],
                        s * a[2] - d[2] - t * c[2],
                    ];
                    best = best.min((w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt());
                }
            }
            assert!(
                exact <= best + 1e-12,
                "case {case}: {exact} > sampled {best}"
            );
            assert!(
                best - exact < 0.01,
                "case {case}: {exact} vs sampled {best}"
            );
        }
    }
}
