//! Dynamic state of the ensemble: the particles, their cells and the
//! scratch of the force passes; bookkeeping shared by every stage.

use super::params::Spec;
use super::{CHUNK, PARALLEL_MIN_PARTICLES};
use crate::geometry::cells::{Bins, CellGrid, LinkedCells};
use rayon::prelude::*;

/// A force contribution to one particle: `(particle, force, torque)`.
pub(super) type Contribution = (u32, [f64; 3], [f64; 3]);

/// FIRE's sums over the particles of one chunk: `F·v + M·Ω`,
/// `|v|² + J|Ω|²`, `|F|² + |M|²/J`.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct FireSums {
    pub(super) vf: f64,
    pub(super) vv: f64,
    pub(super) ff: f64,
}

/// Dynamic state of the ensemble.
#[derive(Debug, Clone)]
pub(super) struct State {
    pub(super) size: [f64; 3],
    pub(super) relief: f64,
    pub(super) specs: Vec<Spec>,
    pub(super) center: Vec<[f64; 3]>,
    pub(super) axis: Vec<[f64; 3]>,
    pub(super) species: Vec<u32>,
    /// Effective diameter, nm.
    pub(super) scale: Vec<f64>,
    /// Seeded cluster (`EMPTY`: none).
    pub(super) cluster: Vec<u32>,
    pub(super) grid: LinkedCells,
    pub(super) force: Vec<[f64; 3]>,
    pub(super) torque: Vec<[f64; 3]>,
    /// Velocity and angular velocity (FIRE stage only; zero otherwise).
    pub(super) vel: Vec<[f64; 3]>,
    pub(super) ang: Vec<[f64; 3]>,
    /// Verlet list (every particle's neighbours within reach + `nb_skin`,
    /// CSR); `nb_start` empty: no valid list.
    pub(super) nb_start: Vec<u32>,
    pub(super) nb: Vec<u32>,
    pub(super) nb_skin: f64,
    /// Centre and axis of every particle when the Verlet list was built.
    pub(super) nb_ref: Vec<([f64; 3], [f64; 3])>,
    /// Centres binned for the list build.
    pub(super) nb_bins: Bins,
    /// Half length of every particle (scratch of the list build).
    pub(super) nb_ext: Vec<f64>,
    /// The Verlet list holds each pair once (serial force pass) rather
    /// than from both sides (parallel force pass).
    pub(super) nb_half: bool,
    /// Particles moved without their cells being updated (Verlet or FIRE
    /// steps); the grid path relinks first.
    pub(super) grid_stale: bool,
    /// Cells of the Verlet list build (at least reach + skin wide).
    pub(super) nb_grid: Option<CellGrid>,
    /// Largest centre distance at which two particles can interact, nm.
    pub(super) max_reach: f64,
    /// Every particle is one sphere and none is in a seeded cluster; then
    /// `radius0` holds the radii (FIRE stage fast path).
    pub(super) plain_spheres: bool,
    pub(super) radius0: Vec<f64>,
    /// FIRE sums per chunk (reused).
    pub(super) fire_sums: Vec<FireSums>,
    pub(super) moving_mark: Vec<u64>,
    pub(super) touched_mark: Vec<u64>,
    pub(super) epoch: u64,
    pub(super) moving: Vec<u32>,
    pub(super) touched: Vec<u32>,
    /// Per-chunk contribution lists (reused).
    pub(super) bufs: Vec<Vec<Contribution>>,
    /// New (centre, axis) of the touched particles (reused).
    pub(super) moves: Vec<Option<([f64; 3], [f64; 3])>>,
    pub(super) skin: f64,
    /// Offset of the overlap and wall forces: `skin` in the first-order
    /// stage, 0 in the FIRE stage (a smooth energy for the inertial step).
    pub(super) push: f64,
}

/// Runs `f(p, &mut a[p], &mut b[p])` for every particle `p` in chunks of
/// [`CHUNK`], on the rayon pool when `parallel`, and returns the largest
/// value `f` gave (0 if none): a maximum, so the result does not depend on
/// how the chunks were shared out.
pub(super) fn for_each_max<A: Send, B: Send>(
    a: &mut [A],
    b: &mut [B],
    parallel: bool,
    f: impl Fn(usize, &mut A, &mut B) -> f64 + Sync,
) -> f64 {
    let chunk = |(c, (xs, ys)): (usize, (&mut [A], &mut [B]))| {
        let mut m = 0.0f64;
        for (k, (x, y)) in xs.iter_mut().zip(ys.iter_mut()).enumerate() {
            m = m.max(f(c * CHUNK + k, x, y));
        }
        m
    };
    if parallel {
        a.par_chunks_mut(CHUNK)
            .zip(b.par_chunks_mut(CHUNK))
            .enumerate()
            .map(chunk)
            .reduce(|| 0.0, f64::max)
    } else {
        a.chunks_mut(CHUNK)
            .zip(b.chunks_mut(CHUNK))
            .enumerate()
            .map(chunk)
            .fold(0.0, f64::max)
    }
}

impl State {
    pub(super) fn add_particle(
        &mut self,
        s: usize,
        d: f64,
        cluster: u32,
        c: [f64; 3],
        a: [f64; 3],
    ) {
        self.center.push(c);
        self.axis.push(a);
        self.species.push(s as u32);
        self.scale.push(d);
        self.cluster.push(cluster);
        self.grid.push(&c);
        self.force.push([0.0; 3]);
        self.torque.push([0.0; 3]);
        self.vel.push([0.0; 3]);
        self.ang.push([0.0; 3]);
        self.moving_mark.push(0);
        self.touched_mark.push(0);
        self.moving.push((self.center.len() - 1) as u32);
    }

    /// Renumbers the particles by grid cell (stable, so deterministic) for
    /// memory locality and rebuilds the cell lists; keeps the moving list.
    /// Returns the new index of every old one.
    pub(super) fn reorder(&mut self) -> Vec<u32> {
        let n = self.center.len();
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_by_key(|&p| self.grid.cell_of(p as usize));
        let mut inv = vec![0u32; n];
        for (k, &p) in order.iter().enumerate() {
            inv[p as usize] = k as u32;
        }
        self.center = order.iter().map(|&p| self.center[p as usize]).collect();
        self.axis = order.iter().map(|&p| self.axis[p as usize]).collect();
        self.species = order.iter().map(|&p| self.species[p as usize]).collect();
        self.scale = order.iter().map(|&p| self.scale[p as usize]).collect();
        self.cluster = order.iter().map(|&p| self.cluster[p as usize]).collect();
        self.vel = order.iter().map(|&p| self.vel[p as usize]).collect();
        self.ang = order.iter().map(|&p| self.ang[p as usize]).collect();
        for m in self.moving.iter_mut() {
            *m = inv[*m as usize];
        }
        self.moving.sort_unstable();
        self.moving_mark.iter_mut().for_each(|m| *m = 0);
        self.touched_mark.iter_mut().for_each(|m| *m = 0);
        self.relink();
        self.nb_start.clear();
        inv
    }

    /// Whether the per-particle passes run on the rayon pool: only for
    /// ensembles of at least [`PARALLEL_MIN_PARTICLES`] particles (a choice
    /// made from the size, never from the thread count, so results stay
    /// bit-identical).
    pub(super) fn parallel(&self) -> bool {
        self.center.len() >= PARALLEL_MIN_PARTICLES
    }

    /// Rebuilds every cell list from the particle centres (deterministic:
    /// each cell lists its particles in index order).
    pub(super) fn relink(&mut self) {
        self.grid.relink_all(&self.center);
        self.grid_stale = false;
    }

    /// Ends a batch's relaxation: puts every particle back in its cell and,
    /// after a FIRE stage (`fired`: every particle may move), sets every
    /// velocity to zero and every particle on the moving list.
    pub(super) fn stop(&mut self, fired: bool) {
        if self.grid_stale {
            self.relink();
        }
        if fired {
            self.vel.iter_mut().for_each(|v| *v = [0.0; 3]);
            self.ang.iter_mut().for_each(|w| *w = [0.0; 3]);
            self.moving.clear();
            self.moving.extend(0..self.center.len() as u32);
        }
        self.nb_start.clear();
    }
}
