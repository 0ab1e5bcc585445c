//! Verlet list of the dynamics packer and the force passes over it.

use super::state::State;
use super::{ATTRACTION_RANGE, CHUNK};
use crate::geometry::cells::{CellGrid, EMPTY};
use crate::geometry::periodic::near_image;
use crate::geometry::vec3::{add, dot, norm};
use rayon::prelude::*;

/// Skin of the Verlet list (FIRE and first-order steps), in units of the
/// smallest sphere radius of all particles.
pub(super) const VERLET_SKIN: f64 = 0.5;
/// Verlet-list entries whose sphere pair forces are computed together.
const LANES: usize = 4;

impl State {
    /// Builds the Verlet list of every particle (neighbours within their
    /// interaction reach plus `nb_skin`, in cell order: deterministic).
    pub(super) fn build_neighbours(&mut self) {
        let n = self.center.len();
        // A grid whose 3×3×3 stencil covers reach + skin; the FIRE stage
        // moves particles without updating any cell, so it is relinked.
        let min_cell = self.max_reach + self.nb_skin;
        let grid = self
            .nb_grid
            .get_or_insert_with(|| CellGrid::new(self.size, min_cell, n));
        self.nb_bins.fill(grid, &self.center);
        self.radius0.clear();
        if self.plain_spheres {
            self.radius0.extend(
                (0..n).map(|p| self.specs[self.species[p] as usize].spheres[0].1 * self.scale[p]),
            );
        }
        self.nb_start.clear();
        self.nb.clear();
        self.nb_ref.clear();
        self.nb_ref
            .extend(self.center.iter().copied().zip(self.axis.iter().copied()));
        // Half length of every particle, nm.
        let mut ext = std::mem::take(&mut self.nb_ext);
        ext.clear();
        ext.extend(
            (0..n).map(|p| self.specs[self.species[p] as usize].half_length * self.scale[p]),
        );
        self.nb_half = !self.parallel();
        let half = self.nb_half;
        let grid = self.nb_grid.as_ref().expect("built above");
        let bins = &self.nb_bins;
        // A half list takes the cell's own particles of higher index and the
        // 13 cells "ahead" (each pair of cells once); that needs at least 3
        // cells across each periodic axis, otherwise the full stencil with
        // the index test.
        let forward = half && grid.counts()[0] >= 3 && grid.counts()[1] >= 3;
        let mut cells = [(0usize, false); 27];
        self.nb_start.push(0);
        for i in 0..n {
            let ci = self.center[i];
            let si = &self.specs[self.species[i] as usize];
            let di = self.scale[i];
            let cc = grid.coords(&ci);
            let count = if forward {
                grid.forward_cells(cc, &mut cells)
            } else {
                grid.stencil_cells(cc, &mut cells)
            };
            for &(f, own) in &cells[..count] {
                let cell = bins.start[f] as usize..bins.start[f + 1] as usize;
                // Branch-free compaction: every candidate is written, the
                // write position advances only for a neighbour (the tests
                // are coin tosses for the predictor).
                let lower_ok = !half || (forward && !own);
                let mut w = self.nb.len();
                self.nb.resize(w + cell.len(), 0);
                for &(j, cj) in &bins.items[cell] {
                    let ju = j as usize;
                    let d = [
                        near_image(cj[0] - ci[0], self.size[0]),
                        near_image(cj[1] - ci[1], self.size[1]),
                        cj[2] - ci[2],
                    ];
                    let gap = if self.cluster[i] != EMPTY && self.cluster[i] == self.cluster[ju] {
                        let sj = &self.specs[self.species[ju] as usize];
                        let dj = self.scale[ju];
                        ATTRACTION_RANGE * 2.0 * (si.r_max * di).max(sj.r_max * dj)
                    } else {
                        self.skin
                    };
                    let reach = ext[i] + ext[ju] + gap + self.nb_skin;
                    let keep = (dot(&d, &d) < reach * reach) & (ju != i) & (lower_ok | (ju > i));
                    self.nb[w] = j;
                    w += usize::from(keep);
                }
                self.nb.truncate(w);
            }
            self.nb_start.push(self.nb.len() as u32);
        }
        self.nb_ext = ext;
    }

    /// Force and torque on every particle (walls, Verlet list, alignment
    /// torque on pushed particles); returns the worst overlap.
    pub(super) fn forces_all(&mut self) -> f64 {
        if self.nb_half {
            return self.forces_half();
        }
        let mut force = std::mem::take(&mut self.force);
        let mut torque = std::mem::take(&mut self.torque);
        let this = &*self;
        let worst = force
            .par_chunks_mut(CHUNK)
            .zip(torque.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(c, (fs, ms))| {
                let mut worst = f64::NEG_INFINITY;
                for (k, (f, m)) in fs.iter_mut().zip(ms.iter_mut()).enumerate() {
                    let i = c * CHUNK + k;
                    let (mut fi, mut mi, mut w) = if this.plain_spheres {
                        let (fz, w) = this.sphere_walls(i);
                        ([0.0, 0.0, fz], [0.0; 3], w)
                    } else {
                        this.walls(i)
                    };
                    let (a, b) = (this.nb_start[i] as usize, this.nb_start[i + 1] as usize);
                    for &j in &this.nb[a..b] {
                        let j = j as usize;
                        if this.plain_spheres {
                            let (fp, l) = this.sphere_pair(i, j);
                            w = w.max(l);
                            add(&mut fi, &fp, 1.0);
                        } else if let Some(pf) = this.pair(i, j) {
                            w = w.max(pf.worst);
                            add(&mut fi, &pf.f, 1.0);
                            add(&mut mi, &pf.mi, 1.0);
                        }
                    }
                    this.add_field_torque_if_pushed(i, &fi, &mut mi);
                    worst = worst.max(w);
                    *f = fi;
                    *m = mi;
                }
                worst
            })
            .reduce(|| f64::NEG_INFINITY, f64::max);
        self.force = force;
        self.torque = torque;
        worst
    }

    /// [`Self::forces_all`] from a half Verlet list (each pair once, both
    /// particles updated): serial, for ensembles below
    /// [`PARALLEL_MIN_PARTICLES`](super::PARALLEL_MIN_PARTICLES).
    pub(super) fn forces_half(&mut self) -> f64 {
        let n = self.center.len();
        let mut force = std::mem::take(&mut self.force);
        let mut torque = std::mem::take(&mut self.torque);
        let mut worst = f64::NEG_INFINITY;
        if self.plain_spheres {
            for (i, f) in force.iter_mut().enumerate() {
                let (fz, w) = self.sphere_walls(i);
                *f = [0.0, 0.0, fz];
                worst = worst.max(w);
            }
            // Nothing but the force in the loop-carried state.
            for i in 0..n {
                let (a, b) = (self.nb_start[i] as usize, self.nb_start[i + 1] as usize);
                let mut fi = force[i];
                let mut wi = f64::NEG_INFINITY;
                let list = &self.nb[a..b];
                let mut blocks = list.chunks_exact(LANES);
                for block in &mut blocks {
                    // Pair forces of a block at once (independent lanes the
                    // compiler can vectorise), then added in list order.
                    let js: &[u32; LANES] = block.try_into().expect("LANES entries");
                    let (f, l) = self.sphere_pairs(i, js);
                    for k in 0..LANES {
                        let j = block[k] as usize;
                        wi = if l[k] > wi { l[k] } else { wi };
                        let fp = [f[0][k], f[1][k], f[2][k]];
                        add(&mut fi, &fp, 1.0);
                        add(&mut force[j], &fp, -1.0);
                    }
                }
                for &j in blocks.remainder() {
                    let j = j as usize;
                    let (fp, l) = self.sphere_pair(i, j);
                    wi = if l > wi { l } else { wi };
                    add(&mut fi, &fp, 1.0);
                    add(&mut force[j], &fp, -1.0);
                }
                force[i] = fi;
                worst = worst.max(wi);
            }
        } else {
            for i in 0..n {
                let (f, m, w) = self.walls(i);
                force[i] = f;
                torque[i] = m;
                worst = worst.max(w);
            }
            for i in 0..n {
                let (a, b) = (self.nb_start[i] as usize, self.nb_start[i + 1] as usize);
                let (mut fi, mut mi) = (force[i], torque[i]);
                for &j in &self.nb[a..b] {
                    let j = j as usize;
                    if let Some(pf) = self.pair(i, j) {
                        worst = worst.max(pf.worst);
                        add(&mut fi, &pf.f, 1.0);
                        add(&mut mi, &pf.mi, 1.0);
                        add(&mut force[j], &pf.f, -1.0);
                        add(&mut torque[j], &pf.mj, 1.0);
                    }
                }
                force[i] = fi;
                torque[i] = mi;
            }
            for i in 0..n {
                self.add_field_torque_if_pushed(i, &force[i], &mut torque[i]);
            }
        }
        self.force = force;
        self.torque = torque;
        worst
    }

    /// Square of the farthest any sphere of particle `p`, now at centre `c`
    /// and axis `a`, can be from where it was when the Verlet list was
    /// built (squared: no root for one-sphere particles).
    #[inline(always)]
    pub(super) fn displacement2(&self, p: usize, c: &[f64; 3], a: &[f64; 3]) -> f64 {
        let (c0, a0) = &self.nb_ref[p];
        let moved = [
            near_image(c[0] - c0[0], self.size[0]),
            near_image(c[1] - c0[1], self.size[1]),
            c[2] - c0[2],
        ];
        if self.plain_spheres {
            return dot(&moved, &moved);
        }
        let turned = [a[0] - a0[0], a[1] - a0[1], a[2] - a0[2]];
        let spec = &self.specs[self.species[p] as usize];
        let d = norm(&moved) + norm(&turned) * spec.s_max * self.scale[p];
        d * d
    }
}
