//! First-order dynamics packer for high PVC (METHOD §2).
//!
//! Particles are rigid sphere clusters on an axis ([`ShapeTemplate`]). They
//! are thrown in batches into the (overlap-free) ensemble with overlaps
//! allowed, then pushed apart:
//! - two spheres of different particles with overlap depth
//!   `L = R1 + R2 − |AB|` repel along `AB` with `F = k (L + δ)` for `L > 0`
//!   (0 otherwise; largest when the centres coincide, then along +z);
//!   `δ` = half the overlap tolerance is a small offset so that an
//!   overlapping pair separates in a finite number of steps instead of
//!   creeping towards contact, while touching particles (`L ≤ 0`) feel
//!   nothing and can rest;
//! - a wall pushes a sphere back along its normal with `k (d + δ)` for
//!   `d > 0`, `d` how far the sphere sticks out of `[0, H]`;
//! - each particle is a rigid body without inertia: `η v = F`, `J Ω = M`,
//!   `M = Σ r_i × F_i`, with `k = η = 1` (only the path matters, not the time
//!   scale) and `J = η (⟨s²⟩ + 0.4 ⟨r²⟩)`, volume-weighted over its spheres:
//!   the mass-normalised moment of inertia of the spheres about a transverse
//!   axis (rotation about the particle axis is irrelevant for clusters on an
//!   axis and never driven, since every `r_i` is parallel to the axis);
//! - explicit Euler, `dt = min(0.5, 0.2 r_min / (|v| + |Ω| s_max))` chosen per
//!   particle, so no sphere moves more than 0.2 of the particle's smallest
//!   radius in one step (a locally scaled mobility: the overlap-free states
//!   it converges to are the same as with one global step, it just does not
//!   let one deeply overlapped particle slow down all others); the axis is
//!   turned by the rotation vector `Ω dt` (Rodrigues) and renormalised;
//! - an optional alignment ("magnetic") torque
//!   `M = ± field · k r_max² (a·ẑ)(a × ẑ)` turns the axis towards z
//!   (perpendicular mode, +) or towards the plane (in-plane mode, −); it acts
//!   on particles that are being pushed (resting particles do not move);
//! - neighbours come from a grid of particle centres (periodic in x, y) whose
//!   cells are at least one particle length wide, so the 3×3×3 block around a
//!   particle holds every particle it can touch;
//! - the moving list holds the particles that moved in the previous step; any
//!   new contact involves one of them, so resting particles cost nothing. A
//!   pair is evaluated once: by the moving particle, or by the lower index
//!   when both move; a resting particle that is pushed moves in that step.
//!
//! A batch is relaxed until the worst overlap (pairs and walls) is below the
//! tolerance, or fails after `max_steps_per_batch` steps with
//! [`GeometryError::DynamicsNotReached`] and the density of the last
//! overlap-free ensemble. The code is sequential with one RNG stream, so the
//! result depends on the seed only.

use super::cells::{min_image, near_image};
use super::shapes::{axis_from_uniforms, order_parameter, Orientation, Shape, ShapeTemplate};
use super::{min_gap_nm, Geometry, GeometryError, GeometryStats, Particle, Sphere, MAX_PARTICLES};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const EMPTY: u32 = u32::MAX;
/// Spring constant and drag (arbitrary units; only ratios matter).
const K: f64 = 1.0;
/// Largest Euler step (in units of η/k).
const DT_MAX: f64 = 0.5;
/// Largest sphere displacement per step, in units of the smallest radius.
const MAX_MOVE: f64 = 0.2;

/// One species for [`pack_dynamics`].
#[derive(Debug, Clone)]
pub struct DynSpecies {
    pub shape: Shape,
    /// Diameter of the equal-volume sphere, nm (> 0).
    pub effective_diameter_nm: f64,
    /// Target volume fraction of the fragment, in `[0, 1)`.
    pub volume_fraction: f64,
    pub orientation: Orientation,
    /// Alignment torque strength (≥ 0, 0 = none; see the module docs); only
    /// with [`Orientation::InPlane`] or [`Orientation::Perpendicular`].
    pub field: f64,
}

/// Fragment and species for [`pack_dynamics`].
#[derive(Debug, Clone)]
pub struct DynParams {
    /// `[Lx, Ly, H]`, nm.
    pub size_nm: [f64; 3],
    pub species: Vec<DynSpecies>,
    /// Largest overlap accepted, as a fraction of the smallest sphere radius
    /// of all species, in `(0, 0.5]` (default 0.01).
    pub overlap_tolerance: f64,
    /// Volume fraction added per batch, in `(0, 1]` (default 0.1).
    pub batch_fraction: f64,
    /// Relaxation steps allowed per batch (≥ 1, default 20 000).
    pub max_steps_per_batch: u64,
}

impl DynParams {
    /// Parameters with the defaults above.
    pub fn new(size_nm: [f64; 3], species: Vec<DynSpecies>) -> Self {
        DynParams {
            size_nm,
            species,
            overlap_tolerance: 0.01,
            batch_fraction: 0.1,
            max_steps_per_batch: 20_000,
        }
    }
}

/// One species after validation, lengths in nm.
struct Spec {
    /// `(axial offset, radius)`.
    spheres: Vec<(f64, f64)>,
    half_length: f64,
    r_min: f64,
    r_max: f64,
    s_max: f64,
    inertia: f64,
    volume: f64,
    count: usize,
}

fn validate(p: &DynParams) -> Result<Vec<Spec>, GeometryError> {
    let [lx, ly, h] = p.size_nm;
    for (name, v) in [("Lx", lx), ("Ly", ly), ("H", h)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(GeometryError::Invalid(format!(
                "fragment size {name} = {v} nm must be finite and > 0"
            )));
        }
    }
    let tol = p.overlap_tolerance;
    if !(tol.is_finite() && tol > 0.0 && tol <= 0.5) {
        return Err(GeometryError::Invalid(format!(
            "overlap_tolerance {tol} must be in (0, 0.5]"
        )));
    }
    let b = p.batch_fraction;
    if !(b.is_finite() && b > 0.0 && b <= 1.0) {
        return Err(GeometryError::Invalid(format!(
            "batch_fraction {b} must be in (0, 1]"
        )));
    }
    if p.max_steps_per_batch == 0 {
        return Err(GeometryError::Invalid(
            "max_steps_per_batch must be ≥ 1".into(),
        ));
    }
    let volume = lx * ly * h;
    let mut total = 0.0;
    let mut out = Vec::with_capacity(p.species.len());
    for (i, s) in p.species.iter().enumerate() {
        let tpl = ShapeTemplate::new(s.shape)
            .map_err(|e| GeometryError::Invalid(format!("species {i}: {e}")))?;
        let d = s.effective_diameter_nm;
        if !(d.is_finite() && d > 0.0) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: effective diameter {d} nm must be finite and > 0"
            )));
        }
        let spheres: Vec<(f64, f64)> = tpl.spheres.iter().map(|&(o, r)| (o * d, r * d)).collect();
        let half_length = tpl.half_length() * d;
        let r_max = tpl.max_radius() * d;
        // Thinnest extent along z the particle can take in its mode.
        let need_z = match s.orientation {
            Orientation::Perpendicular => 2.0 * half_length,
            _ => 2.0 * r_max,
        };
        if need_z > h {
            return Err(GeometryError::GrainTooLarge {
                species: i,
                diameter_nm: need_z,
                thickness_nm: h,
            });
        }
        let half = 0.5 * lx.min(ly);
        if 2.0 * half_length > half {
            return Err(GeometryError::Invalid(format!(
                "species {i}: particle length {} nm exceeds half the lateral period \
                 ({half} nm); allowed length ≤ min(Lx, Ly)/2",
                2.0 * half_length
            )));
        }
        let f = s.volume_fraction;
        if !(f.is_finite() && (0.0..1.0).contains(&f)) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: volume fraction {f} must be in [0, 1)"
            )));
        }
        let fld = s.field;
        if !(fld.is_finite() && fld >= 0.0) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: field {fld} must be finite and ≥ 0"
            )));
        }
        if fld > 0.0 && s.orientation == Orientation::Random {
            return Err(GeometryError::Invalid(format!(
                "species {i}: field {fld} needs orientation in-plane or perpendicular \
                 (random has no field direction); allowed 0 for random"
            )));
        }
        total += f;
        let v = std::f64::consts::PI / 6.0 * d * d * d;
        let n = (f * volume / v).round();
        if n > MAX_PARTICLES as f64 {
            return Err(GeometryError::Invalid(format!(
                "species {i}: {n} particles needed; at most {MAX_PARTICLES} allowed"
            )));
        }
        let w: f64 = spheres.iter().map(|&(_, r)| r * r * r).sum();
        let inertia = spheres
            .iter()
            .map(|&(o, r)| r * r * r * (o * o + 0.4 * r * r))
            .sum::<f64>()
            / w;
        out.push(Spec {
            half_length,
            r_min: tpl.min_radius() * d,
            r_max,
            s_max: spheres.iter().map(|&(o, _)| o.abs()).fold(0.0, f64::max),
            inertia,
            volume: v,
            count: n as usize,
            spheres,
        });
    }
    // Random close packing of equal spheres is ≈ 0.64; ordered packings
    // reach 0.74. Beyond that no packer can go.
    if total >= 0.74 {
        return Err(GeometryError::Invalid(format!(
            "total volume fraction {total} beyond reach; allowed < 0.74"
        )));
    }
    if out.iter().map(|s| s.count).sum::<usize>() > MAX_PARTICLES {
        return Err(GeometryError::Invalid(format!(
            "more than {MAX_PARTICLES} particles in total"
        )));
    }
    Ok(out)
}

/// Grid of particle centres with doubly linked lists per cell.
struct Grid {
    n: [usize; 3],
    cell: [f64; 3],
    head: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    cell_of: Vec<u32>,
}

impl Grid {
    fn new(size: [f64; 3], min_cell: f64, capacity: usize) -> Self {
        let n = super::cells::cell_counts(size, min_cell, capacity);
        Grid {
            n,
            cell: [0, 1, 2].map(|a| size[a] / n[a] as f64),
            head: vec![EMPTY; n[0] * n[1] * n[2]],
            next: Vec::with_capacity(capacity),
            prev: Vec::with_capacity(capacity),
            cell_of: Vec::with_capacity(capacity),
        }
    }

    fn coords(&self, p: &[f64; 3]) -> [usize; 3] {
        let mut c = [0usize; 3];
        for a in 0..3 {
            let n = self.n[a] as f64;
            let i = (p[a] / self.cell[a]).floor();
            let i = if a < 2 {
                i.rem_euclid(n)
            } else {
                i.clamp(0.0, n - 1.0)
            };
            c[a] = (i as usize).min(self.n[a] - 1);
        }
        c
    }

    fn flat(&self, c: [usize; 3]) -> usize {
        (c[2] * self.n[1] + c[1]) * self.n[0] + c[0]
    }

    fn link(&mut self, p: usize, f: usize) {
        let h = self.head[f];
        self.next[p] = h;
        self.prev[p] = EMPTY;
        if h != EMPTY {
            self.prev[h as usize] = p as u32;
        }
        self.head[f] = p as u32;
        self.cell_of[p] = f as u32;
    }

    fn unlink(&mut self, p: usize) {
        let (nx, pv) = (self.next[p], self.prev[p]);
        if pv == EMPTY {
            self.head[self.cell_of[p] as usize] = nx;
        } else {
            self.next[pv as usize] = nx;
        }
        if nx != EMPTY {
            self.prev[nx as usize] = pv;
        }
    }

    fn push(&mut self, center: &[f64; 3]) {
        let p = self.next.len();
        self.next.push(EMPTY);
        self.prev.push(EMPTY);
        self.cell_of.push(0);
        let f = self.flat(self.coords(center));
        self.link(p, f);
    }

    fn update(&mut self, p: usize, center: &[f64; 3]) {
        let f = self.flat(self.coords(center));
        if f != self.cell_of[p] as usize {
            self.unlink(p);
            self.link(p, f);
        }
    }

    /// Cell ranges around `c` along axis `a` (no cell twice).
    fn range(&self, a: usize, c: usize) -> (isize, isize) {
        let n = self.n[a] as isize;
        let c = c as isize;
        if a < 2 {
            if n < 3 {
                (0, n - 1)
            } else {
                (c - 1, c + 1)
            }
        } else {
            ((c - 1).max(0), (c + 1).min(n - 1))
        }
    }
}

/// Dynamic state of the ensemble.
struct State {
    size: [f64; 3],
    specs: Vec<Spec>,
    center: Vec<[f64; 3]>,
    axis: Vec<[f64; 3]>,
    species: Vec<u32>,
    field: Vec<(f64, f64)>, // per species: (signed strength, k r_max²)
    grid: Grid,
    force: Vec<[f64; 3]>,
    torque: Vec<[f64; 3]>,
    moving_mark: Vec<u64>,
    touched_mark: Vec<u64>,
    epoch: u64,
    moving: Vec<u32>,
    touched: Vec<u32>,
    skin: f64,
}

/// `x` wrapped into `[0, l)`.
#[inline]
fn wrap(x: f64, l: f64) -> f64 {
    let w = x.rem_euclid(l);
    if w >= l {
        0.0
    } else {
        w
    }
}

/// Squared distance between the segments `s a`, `|s| ≤ ha`, and `d + t c`,
/// `|t| ≤ hc` (`a`, `c` unit), by clamping the unconstrained closest points
/// (Ericson, Real-Time Collision Detection §5.1.9).
#[inline]
fn segment_distance2(a: &[f64; 3], ha: f64, c: &[f64; 3], hc: f64, d: &[f64; 3]) -> f64 {
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

#[inline]
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
fn add(a: &mut [f64; 3], b: &[f64; 3], s: f64) {
    a[0] += s * b[0];
    a[1] += s * b[1];
    a[2] += s * b[2];
}

#[inline]
fn norm(a: &[f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

impl State {
    fn add_particle(&mut self, s: usize, c: [f64; 3], a: [f64; 3]) {
        self.center.push(c);
        self.axis.push(a);
        self.species.push(s as u32);
        self.grid.push(&c);
        self.force.push([0.0; 3]);
        self.torque.push([0.0; 3]);
        self.moving_mark.push(0);
        self.touched_mark.push(0);
        self.moving.push((self.center.len() - 1) as u32);
    }

    /// Renumbers the particles by grid cell (stable, so deterministic) for
    /// memory locality and rebuilds the cell lists; keeps the moving list.
    fn reorder(&mut self) {
        let n = self.center.len();
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_by_key(|&p| self.grid.cell_of[p as usize]);
        let mut inv = vec![0u32; n];
        for (k, &p) in order.iter().enumerate() {
            inv[p as usize] = k as u32;
        }
        self.center = order.iter().map(|&p| self.center[p as usize]).collect();
        self.axis = order.iter().map(|&p| self.axis[p as usize]).collect();
        self.species = order.iter().map(|&p| self.species[p as usize]).collect();
        for m in self.moving.iter_mut() {
            *m = inv[*m as usize];
        }
        self.moving.sort_unstable();
        self.moving_mark.iter_mut().for_each(|m| *m = 0);
        self.touched_mark.iter_mut().for_each(|m| *m = 0);
        self.grid.head.iter_mut().for_each(|h| *h = EMPTY);
        for p in (0..n).rev() {
            let f = self.grid.flat(self.grid.coords(&self.center[p]));
            self.grid.link(p, f);
        }
    }

    /// Forces of the pair `(i, j)` added to both; returns the worst overlap
    /// depth and whether any force acted.
    fn pair(&mut self, i: usize, j: usize) -> (f64, bool) {
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
        let reach = si.half_length + sj.half_length + self.skin;
        let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if d2 >= reach * reach {
            return (f64::NEG_INFINITY, false);
        }
        let (ai, aj) = (self.axis[i], self.axis[j]);
        if si.spheres.len() > 1 || sj.spheres.len() > 1 {
            // Exact reject: every sphere centre lies on its particle's axis
            // segment, so segments farther apart than the largest radii plus
            // the skin cannot touch (1e-9 relative slack for rounding).
            let g = segment_distance2(&ai, si.s_max, &aj, sj.s_max, &d);
            let r = (si.r_max + sj.r_max + self.skin) * (1.0 + 1e-9);
            if g >= r * r {
                return (f64::NEG_INFINITY, false);
            }
        }
        let mut worst = f64::NEG_INFINITY;
        let mut any = false;
        let (mut fi, mut mi, mut mj) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        let reach_j = sj.half_length + self.skin;
        for &(oi, ri) in &si.spheres {
            let pi = [oi * ai[0], oi * ai[1], oi * ai[2]];
            // Skip spheres that cannot reach particle j's bounding sphere.
            let q = [pi[0] - d[0], pi[1] - d[1], pi[2] - d[2]];
            let rr = ri + reach_j;
            if q[0] * q[0] + q[1] * q[1] + q[2] * q[2] >= rr * rr {
                continue;
            }
            for &(oj, rj) in &sj.spheres {
                let pj = [d[0] + oj * aj[0], d[1] + oj * aj[1], d[2] + oj * aj[2]];
                let ab = [pi[0] - pj[0], pi[1] - pj[1], pi[2] - pj[2]];
                let dist = norm(&ab);
                let l = ri + rj - dist;
                if l <= 0.0 {
                    continue;
                }
                worst = worst.max(l);
                any = true;
                let mag = K * (l + self.skin);
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
        if any {
            add(&mut self.force[i], &fi, 1.0);
            add(&mut self.torque[i], &mi, 1.0);
            add(&mut self.force[j], &fi, -1.0);
            add(&mut self.torque[j], &mj, 1.0);
        }
        (worst, any)
    }

    /// Wall forces on particle `i`; returns the worst penetration.
    fn walls(&mut self, i: usize) -> f64 {
        let (c, a) = (self.center[i], self.axis[i]);
        let h = self.size[2];
        let spec = &self.specs[self.species[i] as usize];
        let mut worst = f64::NEG_INFINITY;
        let (mut f, mut m) = ([0.0; 3], [0.0; 3]);
        for &(o, r) in &spec.spheres {
            let z = c[2] + o * a[2];
            let below = r - z;
            let above = z + r - h;
            worst = worst.max(below).max(above);
            let fz = if below > 0.0 {
                K * (below + self.skin)
            } else if above > 0.0 {
                -K * (above + self.skin)
            } else {
                continue;
            };
            let fv = [0.0, 0.0, fz];
            f[2] += fz;
            add(&mut m, &cross(&[o * a[0], o * a[1], o * a[2]], &fv), 1.0);
        }
        add(&mut self.force[i], &f, 1.0);
        add(&mut self.torque[i], &m, 1.0);
        worst
    }

    /// One relaxation step. Returns the worst overlap at the current
    /// positions; moves the particles only when it is `≥ tol`.
    fn step(&mut self, tol: f64) -> f64 {
        self.epoch += 1;
        let ep = self.epoch;
        self.touched.clear();
        for k in 0..self.moving.len() {
            let p = self.moving[k] as usize;
            self.moving_mark[p] = ep;
            self.touched_mark[p] = ep;
            self.force[p] = [0.0; 3];
            self.torque[p] = [0.0; 3];
            self.touched.push(p as u32);
        }
        let mut worst = f64::NEG_INFINITY;
        for k in 0..self.moving.len() {
            let i = self.moving[k] as usize;
            worst = worst.max(self.walls(i));
            let cc = self.grid.coords(&self.center[i]);
            let (z0, z1) = self.grid.range(2, cc[2]);
            let (y0, y1) = self.grid.range(1, cc[1]);
            let (x0, x1) = self.grid.range(0, cc[0]);
            let (nx, ny) = (self.grid.n[0] as isize, self.grid.n[1] as isize);
            for cz in z0..=z1 {
                for cy in y0..=y1 {
                    let wy = cy.rem_euclid(ny) as usize;
                    for cx in x0..=x1 {
                        let wx = cx.rem_euclid(nx) as usize;
                        let mut j = self.grid.head[self.grid.flat([wx, wy, cz as usize])];
                        while j != EMPTY {
                            let ju = j as usize;
                            j = self.grid.next[ju];
                            if ju == i || (self.moving_mark[ju] == ep && ju < i) {
                                continue;
                            }
                            let fresh = self.touched_mark[ju] != ep;
                            if fresh {
                                self.force[ju] = [0.0; 3];
                                self.torque[ju] = [0.0; 3];
                            }
                            let (w, any) = self.pair(i, ju);
                            worst = worst.max(w);
                            if any && fresh {
                                self.touched_mark[ju] = ep;
                                self.touched.push(ju as u32);
                            }
                        }
                    }
                }
            }
        }
        if worst < tol {
            return worst;
        }
        // Move every particle that felt a force; they form the next moving list.
        self.moving.clear();
        for k in 0..self.touched.len() {
            let p = self.touched[k] as usize;
            let f = self.force[p];
            let mut m = self.torque[p];
            if norm(&f) == 0.0 && norm(&m) == 0.0 {
                continue;
            }
            let sp = self.species[p] as usize;
            let a = self.axis[p];
            let (strength, scale) = self.field[sp];
            if strength != 0.0 {
                let t = cross(&a, &[0.0, 0.0, 1.0]);
                add(&mut m, &t, strength * scale * a[2]);
            }
            let spec = &self.specs[sp];
            let v = f; // η = 1
            let om = [
                m[0] / spec.inertia,
                m[1] / spec.inertia,
                m[2] / spec.inertia,
            ];
            let speed = norm(&v) + norm(&om) * spec.s_max;
            let mut dt = DT_MAX;
            if speed * dt > MAX_MOVE * spec.r_min {
                dt = MAX_MOVE * spec.r_min / speed;
            }
            let c = &mut self.center[p];
            c[0] = wrap(c[0] + v[0] * dt, self.size[0]);
            c[1] = wrap(c[1] + v[1] * dt, self.size[1]);
            c[2] += v[2] * dt;
            let phi = norm(&om) * dt;
            if phi > 0.0 {
                let k = [om[0] / norm(&om), om[1] / norm(&om), om[2] / norm(&om)];
                let kxa = cross(&k, &a);
                let kd = k[0] * a[0] + k[1] * a[1] + k[2] * a[2];
                let (s, co) = phi.sin_cos();
                let mut b = [0.0; 3];
                for ax in 0..3 {
                    b[ax] = a[ax] * co + kxa[ax] * s + k[ax] * kd * (1.0 - co);
                }
                let nb = norm(&b);
                self.axis[p] = [b[0] / nb, b[1] / nb, b[2] / nb];
            }
            let c = self.center[p];
            self.grid.update(p, &c);
            self.moving.push(p as u32);
        }
        worst
    }
}

/// Packs one fragment by batches of random particles relaxed with
/// first-order dynamics (see the module docs).
///
/// Particles come out ordered by grid cell (renumbered after every batch for
/// memory locality), not in insertion order. `stats.attempts` counts the
/// particles inserted, `stats.relax_steps` the relaxation steps of all
/// batches. Deterministic for a seed.
pub fn pack_dynamics(params: &DynParams, seed: u64) -> Result<Geometry, GeometryError> {
    let specs = validate(params)?;
    let size = params.size_nm;
    let box_volume = size[0] * size[1] * size[2];
    let total: usize = specs.iter().map(|s| s.count).sum();
    let target: f64 = params.species.iter().map(|s| s.volume_fraction).sum();
    let r_min_all = specs
        .iter()
        .filter(|s| s.count > 0)
        .map(|s| s.r_min)
        .fold(f64::INFINITY, f64::min);
    let tol = params.overlap_tolerance
        * if r_min_all.is_finite() {
            r_min_all
        } else {
            0.0
        };
    let cell = specs
        .iter()
        .filter(|s| s.count > 0)
        .map(|s| 2.0 * s.half_length)
        .fold(0.0, f64::max)
        + 0.5 * tol;
    let field = params
        .species
        .iter()
        .zip(&specs)
        .map(|(s, sp)| {
            let sign = match s.orientation {
                Orientation::Perpendicular => 1.0,
                Orientation::InPlane => -1.0,
                Orientation::Random => 0.0,
            };
            (sign * s.field, K * sp.r_max * sp.r_max)
        })
        .collect();
    let mut st = State {
        size,
        grid: Grid::new(size, cell.max(f64::MIN_POSITIVE), total),
        specs,
        center: Vec::with_capacity(total),
        axis: Vec::with_capacity(total),
        species: Vec::with_capacity(total),
        field,
        force: Vec::with_capacity(total),
        torque: Vec::with_capacity(total),
        moving_mark: Vec::with_capacity(total),
        touched_mark: Vec::with_capacity(total),
        epoch: 0,
        moving: Vec::with_capacity(total),
        touched: Vec::with_capacity(total),
        skin: 0.5 * tol,
    };
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let batches = ((target / params.batch_fraction).ceil() as usize).max(1);
    let mut steps_total = 0u64;
    let mut placed = vec![0usize; st.specs.len()];
    let mut placed_volume = 0.0;
    for b in 0..batches {
        let volume_before = placed_volume;
        for (s, placed_s) in placed.iter_mut().enumerate() {
            let want =
                (st.specs[s].count as f64 * (b + 1) as f64 / batches as f64).round() as usize;
            let mode = params.species[s].orientation;
            while *placed_s < want.min(st.specs[s].count) {
                let a = axis_from_uniforms(mode, rng.gen(), rng.gen());
                let ext = st.specs[s]
                    .spheres
                    .iter()
                    .map(|&(o, r)| (o * a[2]).abs() + r)
                    .fold(0.0, f64::max);
                let span = size[2] - 2.0 * ext;
                let u: f64 = rng.gen();
                let z = if span > 0.0 {
                    ext + u * span
                } else {
                    0.5 * size[2]
                };
                let x = (rng.gen::<f64>() * size[0]).min(size[0] * (1.0 - f64::EPSILON));
                let y = (rng.gen::<f64>() * size[1]).min(size[1] * (1.0 - f64::EPSILON));
                st.add_particle(s, [x, y, z], a);
                *placed_s += 1;
                placed_volume += st.specs[s].volume;
            }
        }
        st.reorder();
        let mut steps = 0u64;
        loop {
            let worst = st.step(tol);
            if worst < tol {
                break;
            }
            steps += 1;
            if steps > params.max_steps_per_batch {
                return Err(GeometryError::DynamicsNotReached {
                    target,
                    reached: volume_before / box_volume,
                    worst_overlap_nm: worst,
                    steps: steps_total + steps,
                });
            }
        }
        steps_total += steps;
    }
    Ok(finish(params, &st, steps_total, total as u64))
}

fn finish(params: &DynParams, st: &State, relax_steps: u64, attempts: u64) -> Geometry {
    let size = params.size_nm;
    let box_volume = size[0] * size[1] * size[2];
    let particles: Vec<Particle> = (0..st.center.len())
        .map(|p| {
            let (c, a) = (st.center[p], st.axis[p]);
            let s = st.species[p] as usize;
            let spheres = st.specs[s]
                .spheres
                .iter()
                .map(|&(o, r)| Sphere {
                    center: [
                        wrap(c[0] + o * a[0], size[0]),
                        wrap(c[1] + o * a[1], size[1]),
                        c[2] + o * a[2],
                    ],
                    radius: r,
                })
                .collect();
            Particle {
                species: s,
                spheres,
            }
        })
        .collect();
    let axes: Vec<[f64; 3]> = (0..st.center.len())
        .filter(|&p| st.specs[st.species[p] as usize].spheres.len() > 1)
        .map(|p| st.axis[p])
        .collect();
    let min_gap = min_gap_nm(size, &particles);
    Geometry {
        size_nm: size,
        particles,
        stats: GeometryStats {
            count: st.specs.iter().map(|s| s.count).collect(),
            target_fraction: params.species.iter().map(|s| s.volume_fraction).collect(),
            achieved_fraction: st
                .specs
                .iter()
                .map(|s| s.count as f64 * s.volume / box_volume)
                .collect(),
            min_gap_nm: min_gap,
            attempts,
            worst_overlap_nm: (-min_gap).max(0.0),
            order_parameter: order_parameter(&axes),
            relax_steps,
        },
    }
}

/// Unit axes of the particles of `g` (first to last sphere, nearest periodic
/// image), `None` for one-sphere particles.
pub fn particle_axis(g: &Geometry, p: &Particle) -> Option<[f64; 3]> {
    let (a, b) = (p.spheres.first()?, p.spheres.last()?);
    let d = [
        min_image(b.center[0] - a.center[0], g.size_nm[0]),
        min_image(b.center[1] - a.center[1], g.size_nm[1]),
        b.center[2] - a.center[2],
    ];
    let n = norm(&d);
    (p.spheres.len() > 1 && n > 0.0).then(|| [d[0] / n, d[1] / n, d[2] / n])
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
