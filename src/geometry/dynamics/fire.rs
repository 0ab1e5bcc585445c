//! FIRE stage of the dynamics packer (inertial relaxation near jamming).

use super::state::{for_each_max, FireSums, State};
use super::CHUNK;
use crate::geometry::periodic::wrap;
use crate::geometry::vec3::{dot, norm, rotate};
use rayon::prelude::*;

/// FIRE stage (Bitzek et al. 2006, PRL 97, 170201; parameters as LAMMPS's
/// `min_style fire`, time in units of `√(m/k)` with `m = k = 1`): initial,
/// largest and smallest time step.
const FIRE_DT0: f64 = 0.1;
const FIRE_DT_MAX: f64 = 10.0 * FIRE_DT0;
const FIRE_DT_MIN: f64 = 0.02 * FIRE_DT0;
/// Steps with positive power before the step grows.
const FIRE_DELAY: u32 = 20;
const FIRE_GROW: f64 = 1.1;
const FIRE_SHRINK: f64 = 0.5;
const FIRE_ALPHA0: f64 = 0.25;
const FIRE_ALPHA_SHRINK: f64 = 0.99;
/// Largest sphere displacement per FIRE step, in units of the particle's
/// smallest radius.
const FIRE_MAX_MOVE: f64 = 0.1;

/// FIRE's adaptive state (reset at every batch).
#[derive(Debug, Clone, Copy)]
pub(super) struct Fire {
    dt: f64,
    alpha: f64,
    n_pos: u32,
    /// FIRE steps taken in this batch.
    steps: u64,
    /// Time step of the last move.
    last_move: f64,
}

impl Fire {
    pub(super) fn new() -> Self {
        Fire {
            dt: FIRE_DT0,
            alpha: FIRE_ALPHA0,
            n_pos: 0,
            steps: 0,
            last_move: 0.0,
        }
    }
}

impl State {
    /// FIRE's sums over particles (mass-weighted metric), per chunk in chunk
    /// order: `F·v + M·Ω`, `|v|² + J|Ω|²`, `|F|² + |M|²/J`.
    pub(super) fn sum_fire_terms(&mut self) {
        let mut sums = std::mem::take(&mut self.fire_sums);
        let this = &*self;
        let n = this.center.len();
        let work = |c: usize| {
            let mut out = FireSums::default();
            for i in c * CHUNK..((c + 1) * CHUNK).min(n) {
                let (f, m, v, om) = (this.force[i], this.torque[i], this.vel[i], this.ang[i]);
                if this.plain_spheres {
                    out.vf += dot(&f, &v);
                    out.vv += dot(&v, &v);
                    out.ff += dot(&f, &f);
                } else {
                    let j = this.specs[this.species[i] as usize].inertia
                        * this.scale[i]
                        * this.scale[i];
                    out.vf += dot(&f, &v) + dot(&m, &om);
                    out.vv += dot(&v, &v) + j * dot(&om, &om);
                    out.ff += dot(&f, &f) + dot(&m, &m) / j;
                }
            }
            out
        };
        let chunks = n.div_ceil(CHUNK);
        if this.parallel() {
            (0..chunks)
                .into_par_iter()
                .map(work)
                .collect_into_vec(&mut sums);
        } else {
            sums.clear();
            sums.extend((0..chunks).map(work));
        }
        self.fire_sums = sums;
    }

    /// Moves particle `p` (centre `c`, axis `a`) for `dt` at its FIRE
    /// velocity and angular velocity.
    #[inline(always)]
    pub(super) fn drift(&self, p: usize, c: &mut [f64; 3], a: &mut [f64; 3], dt: f64) {
        let (v, w) = (self.vel[p], self.ang[p]);
        c[0] = wrap(c[0] + v[0] * dt, self.size[0]);
        c[1] = wrap(c[1] + v[1] * dt, self.size[1]);
        c[2] += v[2] * dt;
        if !self.plain_spheres {
            *a = rotate(a, &w, dt);
        }
    }

    /// One FIRE step (see the module docs; the integrator is LAMMPS's
    /// `min_style fire` with `integrator eulerimplicit`): the power
    /// `P = F·v + M·Ω` decides whether the step grows or everything stops;
    /// then `v += dt F`, mixed towards the force as
    /// `v = (1 − α) v + α (|v| / |F|) F` (norms before the update), and the
    /// move `x += dt' v` with `dt' ≤ dt` so that no sphere moves more than
    /// [`FIRE_MAX_MOVE`] of its particle's smallest radius. Returns the
    /// worst overlap at the current positions; moves only when it is
    /// `≥ tol`. Sums over particles are taken per chunk, then over chunks
    /// in order (deterministic).
    pub(super) fn fire_step(&mut self, tol: f64, fire: &mut Fire) -> f64 {
        self.push = 0.0;
        if self.nb_start.len() != self.center.len() + 1 {
            self.build_neighbours();
        }
        let worst = self.forces_all();
        if worst < tol {
            return worst;
        }
        self.sum_fire_terms();
        let mut total = FireSums::default();
        for s in &self.fire_sums {
            total.vf += s.vf;
            total.vv += s.vv;
            total.ff += s.ff;
        }
        fire.steps += 1;
        let going = total.vf > 0.0;
        let (keep, mix) = if going {
            let mix = if total.ff > 0.0 {
                fire.alpha * (total.vv / total.ff).sqrt()
            } else {
                0.0
            };
            let keep = 1.0 - fire.alpha;
            fire.n_pos += 1;
            if fire.n_pos > FIRE_DELAY {
                fire.dt = (fire.dt * FIRE_GROW).min(FIRE_DT_MAX);
                fire.alpha *= FIRE_ALPHA_SHRINK;
            }
            (keep, mix)
        } else {
            fire.n_pos = 0;
            // As LAMMPS: no shrinking during the first `FIRE_DELAY` steps.
            if fire.steps > u64::from(FIRE_DELAY) {
                fire.dt = (fire.dt * FIRE_SHRINK).max(FIRE_DT_MIN);
                fire.alpha = FIRE_ALPHA0;
            }
            // As LAMMPS (`halfstepback`): go back half the last move.
            let back = -0.5 * fire.last_move;
            let mut center = std::mem::take(&mut self.center);
            let mut axis = std::mem::take(&mut self.axis);
            let this = &*self;
            for_each_max(&mut center, &mut axis, this.parallel(), |p, c, a| {
                this.drift(p, c, a, back);
                0.0
            });
            self.center = center;
            self.axis = axis;
            (0.0, 0.0)
        };
        let dt = fire.dt;
        // v ← keep (v + dt F) + mix F; after a stop v ← dt F.
        let (cv, cf) = if going {
            (keep, keep * dt + mix)
        } else {
            (0.0, dt)
        };
        // Velocities, and the largest speed relative to the smallest radius.
        let mut vel = std::mem::take(&mut self.vel);
        let mut ang = std::mem::take(&mut self.ang);
        let this = &*self;
        let rate = for_each_max(&mut vel, &mut ang, this.parallel(), |p, v, w| {
            let (f, m) = (this.force[p], this.torque[p]);
            for a in 0..3 {
                v[a] = cv * v[a] + cf * f[a];
            }
            let spec = &this.specs[this.species[p] as usize];
            let d = this.scale[p];
            let mut speed = norm(v);
            if !this.plain_spheres {
                let inertia = spec.inertia * d * d;
                for a in 0..3 {
                    w[a] = cv * w[a] + cf * m[a] / inertia;
                }
                speed += norm(w) * spec.s_max * d;
            }
            speed / (spec.r_min * d)
        });
        self.vel = vel;
        self.ang = ang;
        let dt_move = if rate * dt > FIRE_MAX_MOVE {
            FIRE_MAX_MOVE / rate
        } else {
            dt
        };
        fire.last_move = dt_move;
        // Move; track how far each sphere may have gone since the Verlet
        // list was built.
        let mut center = std::mem::take(&mut self.center);
        let mut axis = std::mem::take(&mut self.axis);
        let this = &*self;
        let disp2 = for_each_max(&mut center, &mut axis, this.parallel(), |p, c, a| {
            this.drift(p, c, a, dt_move);
            this.displacement2(p, c, a)
        });
        self.center = center;
        self.axis = axis;
        self.grid_stale = true;
        if 4.0 * disp2 > self.nb_skin * self.nb_skin {
            self.nb_start.clear();
        }
        worst
    }
}
