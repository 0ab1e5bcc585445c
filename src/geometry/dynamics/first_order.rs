//! First-order (overdamped) steps: forces of the moving list from the
//! cell grid, or of every particle from the Verlet list, and the explicit Euler
//! move.

use super::state::Contribution;
use super::state::{for_each_max, State};
use super::CHUNK;
use crate::geometry::cells::EMPTY;
use crate::geometry::periodic::wrap;
use crate::geometry::vec3::{add, norm, rotate};
use rayon::prelude::*;

/// Largest Euler step (in units of η/k).
const DT_MAX: f64 = 0.5;
/// Largest sphere displacement per step, in units of the smallest radius.
const MAX_MOVE: f64 = 0.2;
/// For one-sphere particles, the first-order step takes every particle's
/// force from the Verlet list while at least 1 / `VERLET_SHARE` of them
/// move (for grains of several spheres the lists die within a step or two
/// of first-order moves and their builds cost more than the grid path).
const VERLET_SHARE: usize = 4;

impl State {
    /// Forces on moving particle `i` from the walls and from every neighbour
    /// whose pair it owns; contributions go to `buf` (neighbours first, then
    /// `i` itself). Returns the worst overlap seen.
    pub(super) fn gather(&self, i: usize, ep: u64, buf: &mut Vec<Contribution>) -> f64 {
        let (mut fi, mut mi, mut worst) = self.walls(i);
        let mut cells = [(0usize, false); 27];
        let count = self
            .grid
            .grid()
            .stencil_cells(self.grid.grid().coords(&self.center[i]), &mut cells);
        for &(f, _) in &cells[..count] {
            let mut j = self.grid.head(f);
            while j != EMPTY {
                let ju = j as usize;
                j = self.grid.next(ju);
                if ju == i || (self.moving_mark[ju] == ep && ju < i) {
                    continue;
                }
                if let Some(pf) = self.pair(i, ju) {
                    worst = worst.max(pf.worst);
                    add(&mut fi, &pf.f, 1.0);
                    add(&mut mi, &pf.mi, 1.0);
                    buf.push((ju as u32, [-pf.f[0], -pf.f[1], -pf.f[2]], pf.mj));
                }
            }
        }
        buf.push((i as u32, fi, mi));
        worst
    }

    /// New centre and axis of particle `p`, now at `c0` with axis `a`, after
    /// one Euler step under its accumulated force and torque (alignment
    /// torque included); `None` when neither acts.
    pub(super) fn advance(
        &self,
        p: usize,
        c0: &[f64; 3],
        a: &[f64; 3],
    ) -> Option<([f64; 3], [f64; 3])> {
        let (f, m) = (self.force[p], self.torque[p]);
        if norm(&f) == 0.0 && norm(&m) == 0.0 {
            return None;
        }
        let spec = &self.specs[self.species[p] as usize];
        let d = self.scale[p];
        let inertia = spec.inertia * d * d;
        let v = f; // η = 1
        let om = [m[0] / inertia, m[1] / inertia, m[2] / inertia];
        let speed = norm(&v) + norm(&om) * spec.s_max * d;
        let mut dt = DT_MAX;
        if speed * dt > MAX_MOVE * spec.r_min * d {
            dt = MAX_MOVE * spec.r_min * d / speed;
        }
        let c = [
            wrap(c0[0] + v[0] * dt, self.size[0]),
            wrap(c0[1] + v[1] * dt, self.size[1]),
            c0[2] + v[2] * dt,
        ];
        Some((c, rotate(a, &om, dt)))
    }

    /// Worst overlap at the current positions; when it is `≥ tol`, also the
    /// force and torque on every particle of the moving list and on each
    /// neighbour one of them pushes (`force`, `torque` of `touched`).
    pub(super) fn forces(&mut self, tol: f64) -> f64 {
        self.epoch += 1;
        let ep = self.epoch;
        for k in 0..self.moving.len() {
            let p = self.moving[k] as usize;
            self.moving_mark[p] = ep;
        }
        let n_chunks = self.moving.len().div_ceil(CHUNK);
        if self.bufs.len() < n_chunks {
            self.bufs.resize_with(n_chunks, Vec::new);
        }
        let mut bufs = std::mem::take(&mut self.bufs);
        let this = &*self;
        let worst = bufs[..n_chunks]
            .par_iter_mut()
            .enumerate()
            .map(|(c, buf)| {
                buf.clear();
                let lo = c * CHUNK;
                let hi = (lo + CHUNK).min(this.moving.len());
                let mut worst = f64::NEG_INFINITY;
                for &i in &this.moving[lo..hi] {
                    worst = worst.max(this.gather(i as usize, ep, buf));
                }
                worst
            })
            .reduce(|| f64::NEG_INFINITY, f64::max);
        if worst < tol {
            self.bufs = bufs;
            return worst;
        }
        // Add the contributions in chunk order (deterministic).
        self.touched.clear();
        for buf in &bufs[..n_chunks] {
            for &(p, f, m) in buf {
                let pu = p as usize;
                if self.touched_mark[pu] != ep {
                    self.touched_mark[pu] = ep;
                    self.force[pu] = [0.0; 3];
                    self.torque[pu] = [0.0; 3];
                    self.touched.push(p);
                }
                add(&mut self.force[pu], &f, 1.0);
                add(&mut self.torque[pu], &m, 1.0);
            }
        }
        self.bufs = bufs;
        for k in 0..self.touched.len() {
            let p = self.touched[k] as usize;
            let (f, mut m) = (self.force[p], self.torque[p]);
            self.add_field_torque_if_pushed(p, &f, &mut m);
            self.torque[p] = m;
        }
        worst
    }

    /// One first-order relaxation step. Returns the worst overlap at the
    /// current positions; moves the particles only when it is `≥ tol`.
    /// While at least 1/[`VERLET_SHARE`] of the particles move, every
    /// particle's force comes from the Verlet list ([`Self::step_verlet`]);
    /// otherwise only the moving list's pairs are looked up in the grid.
    pub(super) fn step(&mut self, tol: f64) -> f64 {
        self.push = self.skin;
        if self.plain_spheres && self.moving.len() * VERLET_SHARE >= self.center.len() {
            return self.step_verlet(tol);
        }
        if self.grid_stale {
            self.relink();
        }
        let worst = self.forces(tol);
        if worst < tol {
            return worst;
        }
        // Moves the list does not track.
        self.nb_start.clear();
        // Move every particle that felt a force; they form the next moving list.
        let mut moves = std::mem::take(&mut self.moves);
        let this = &*self;
        this.touched
            .par_iter()
            .map(|&p| this.advance(p as usize, &this.center[p as usize], &this.axis[p as usize]))
            .collect_into_vec(&mut moves);
        self.moving.clear();
        for (k, mv) in moves.iter().enumerate() {
            let p = self.touched[k] as usize;
            if let Some((c, a)) = *mv {
                self.center[p] = c;
                self.axis[p] = a;
                self.grid.update(p, &c);
                self.moving.push(p as u32);
            }
        }
        self.moves = moves;
        worst
    }

    /// [`Self::step`](State::step) for every particle, forces from the Verlet list (the
    /// FIRE stage's, with the first-order force's `δ` offset); the cells
    /// are relinked when the grid path takes over again.
    pub(super) fn step_verlet(&mut self, tol: f64) -> f64 {
        if self.nb_start.len() != self.center.len() + 1 {
            self.build_neighbours();
        }
        let worst = self.forces_all();
        if worst < tol {
            return worst;
        }
        self.grid_stale = true;
        let mut center = std::mem::take(&mut self.center);
        let mut axis = std::mem::take(&mut self.axis);
        let this = &*self;
        let disp2 = for_each_max(&mut center, &mut axis, this.parallel(), |p, c, a| {
            if let Some((nc, na)) = this.advance(p, c, a) {
                *c = nc;
                *a = na;
            }
            this.displacement2(p, c, a)
        });
        self.center = center;
        self.axis = axis;
        self.moving.clear();
        for p in 0..self.center.len() {
            if self.force[p] != [0.0; 3] || self.torque[p] != [0.0; 3] {
                self.moving.push(p as u32);
            }
        }
        if 4.0 * disp2 > self.nb_skin * self.nb_skin {
            self.nb_start.clear();
        }
        worst
    }
}
