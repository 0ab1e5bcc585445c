//! The packer step by step ([`DynamicsPacker`]) and the whole loop
//! ([`pack_dynamics`]): batches inserted, relaxed first-order then with
//! FIRE, the particles returned as a [`Geometry`].

use super::fire::Fire;
use super::params::{validate, DynParams};
use super::state::State;
use super::verlet::VERLET_SKIN;
use super::ATTRACTION_RANGE;
use crate::geometry::cells::{Bins, CellGrid, LinkedCells, EMPTY};
use crate::geometry::periodic::{min_image, wrap};
use crate::geometry::shapes::{axis_from_uniforms, order_parameter, Orientation};
use crate::geometry::vec3::norm;
use crate::geometry::{min_gap_nm, Geometry, GeometryError, GeometryStats, Particle, Sphere};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// What one relaxation step saw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Particles on the moving list when the step started.
    pub moving: usize,
    /// Worst overlap (pairs and walls) at the start of the step, nm.
    pub worst_overlap_nm: f64,
}

/// The dynamics packer step by step: [`DynamicsPacker::insert_batch`] adds
/// the next batch, [`DynamicsPacker::step`] / [`DynamicsPacker::relax`]
/// relax it, [`DynamicsPacker::geometry`] returns the particles.
/// [`pack_dynamics`] is the whole loop.
#[derive(Debug, Clone)]
pub struct DynamicsPacker {
    params: DynParams,
    st: State,
    rng: Xoshiro256PlusPlus,
    /// Diameters per species, in placement order.
    diameters: Vec<Vec<f64>>,
    /// Current particle index of every placed grain, per species.
    index_of: Vec<Vec<u32>>,
    batches: usize,
    next_batch: usize,
    tol: f64,
    steps: u64,
    placed_volume: f64,
    /// Placed volume before the last batch.
    volume_before: f64,
    next_cluster: u32,
}

impl DynamicsPacker {
    /// Checks `params`, draws the diameters; no particle placed yet.
    pub fn new(params: &DynParams, seed: u64) -> Result<Self, GeometryError> {
        let (specs, diameters) = validate(params, seed)?;
        let size = params.size_nm;
        let total: usize = diameters.iter().map(Vec::len).sum();
        let target: f64 = params.species.iter().map(|s| s.volume_fraction).sum();
        let r_min_all = specs
            .iter()
            .zip(&diameters)
            .flat_map(|(s, ds)| ds.iter().map(move |&d| s.r_min * d))
            .fold(f64::INFINITY, f64::min);
        let tol = params.overlap_tolerance
            * if r_min_all.is_finite() {
                r_min_all
            } else {
                0.0
            };
        let cell = specs
            .iter()
            .zip(&diameters)
            .filter(|(_, ds)| !ds.is_empty())
            .map(|(s, ds)| {
                let d = ds.iter().copied().fold(0.0, f64::max);
                let attract = if s.group > 1 {
                    ATTRACTION_RANGE * 2.0 * s.r_max * d
                } else {
                    0.0
                };
                2.0 * s.half_length * d + attract
            })
            .fold(0.0, f64::max)
            + 0.5 * tol;
        let plain_spheres = specs.iter().all(|s| s.spheres.len() == 1 && s.group <= 1);
        let st = State {
            size,
            relief: params.relief_fraction,
            grid: LinkedCells::new(
                CellGrid::new(size, cell.max(f64::MIN_POSITIVE), total),
                total,
            ),
            specs,
            center: Vec::with_capacity(total),
            axis: Vec::with_capacity(total),
            species: Vec::with_capacity(total),
            scale: Vec::with_capacity(total),
            cluster: Vec::with_capacity(total),
            force: Vec::with_capacity(total),
            torque: Vec::with_capacity(total),
            vel: Vec::with_capacity(total),
            ang: Vec::with_capacity(total),
            nb_start: Vec::new(),
            nb: Vec::new(),
            nb_skin: VERLET_SKIN
                * if r_min_all.is_finite() {
                    r_min_all
                } else {
                    0.0
                },
            nb_ref: Vec::new(),
            nb_ext: Vec::new(),
            nb_bins: Bins::default(),
            nb_half: false,
            grid_stale: false,
            nb_grid: None,
            max_reach: cell,
            plain_spheres,
            radius0: Vec::new(),
            fire_sums: Vec::new(),
            moving_mark: Vec::with_capacity(total),
            touched_mark: Vec::with_capacity(total),
            epoch: 0,
            moving: Vec::with_capacity(total),
            touched: Vec::with_capacity(total),
            bufs: Vec::new(),
            moves: Vec::new(),
            skin: 0.5 * tol,
            push: 0.5 * tol,
        };
        let batches = ((target / params.batch_fraction).ceil() as usize).max(1);
        Ok(DynamicsPacker {
            params: params.clone(),
            st,
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
            index_of: diameters
                .iter()
                .map(|d| Vec::with_capacity(d.len()))
                .collect(),
            diameters,
            batches,
            next_batch: 0,
            tol,
            steps: 0,
            placed_volume: 0.0,
            volume_before: 0.0,
            next_cluster: 0,
        })
    }

    /// Number of batches the target is split into.
    pub fn batches(&self) -> usize {
        self.batches
    }

    /// Particles placed so far.
    pub fn particles(&self) -> usize {
        self.st.center.len()
    }

    /// Particles on the moving list.
    pub fn moving(&self) -> usize {
        self.st.moving.len()
    }

    /// Overlap tolerance in nm (the fraction times the smallest radius).
    pub fn tolerance_nm(&self) -> f64 {
        self.tol
    }

    /// Relaxation steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Adds the next batch of random particles (overlaps allowed); false
    /// when every batch is in.
    pub fn insert_batch(&mut self) -> bool {
        if self.next_batch >= self.batches {
            return false;
        }
        let b = self.next_batch;
        self.next_batch += 1;
        self.volume_before = self.placed_volume;
        let size = self.params.size_nm;
        let relief = self.params.relief_fraction;
        for s in 0..self.diameters.len() {
            let count = self.diameters[s].len();
            let want =
                ((count as f64 * (b + 1) as f64 / self.batches as f64).round() as usize).min(count);
            let mode = self.params.species[s].orientation;
            let group = self.st.specs[s].group;
            while self.index_of[s].len() < want {
                let k = self.index_of[s].len();
                let d = self.diameters[s][k];
                let spec = &self.st.specs[s];
                let a = axis_from_uniforms(mode, self.rng.gen(), self.rng.gen());
                let ext = d * spec
                    .spheres
                    .iter()
                    .map(|&(o, r)| (o * a[2]).abs() + r)
                    .fold(0.0, f64::max);
                let (z_lo, z_hi) = (ext - relief * d, size[2] - ext);
                let cluster = if group > 1 {
                    if k.is_multiple_of(group) {
                        self.next_cluster += 1;
                    }
                    self.next_cluster - 1
                } else {
                    EMPTY
                };
                let c = if group > 1 && !k.is_multiple_of(group) {
                    // Next to a random earlier member of the same group.
                    let first = k - k % group;
                    let m = self.index_of[s][first + self.rng.gen_range(0..k - first)] as usize;
                    let u = axis_from_uniforms(Orientation::Random, self.rng.gen(), self.rng.gen());
                    let dist = spec.r_max * (d + self.st.scale[m]);
                    let cm = self.st.center[m];
                    let z = cm[2] + dist * u[2];
                    [
                        wrap(cm[0] + dist * u[0], size[0]),
                        wrap(cm[1] + dist * u[1], size[1]),
                        if z_hi > z_lo {
                            z.clamp(z_lo, z_hi)
                        } else {
                            0.5 * (z_lo + z_hi)
                        },
                    ]
                } else {
                    let u: f64 = self.rng.gen();
                    let z = if z_hi > z_lo {
                        z_lo + u * (z_hi - z_lo)
                    } else {
                        0.5 * (z_lo + z_hi)
                    };
                    let x = (self.rng.gen::<f64>() * size[0]).min(size[0] * (1.0 - f64::EPSILON));
                    let y = (self.rng.gen::<f64>() * size[1]).min(size[1] * (1.0 - f64::EPSILON));
                    [x, y, z]
                };
                self.index_of[s].push(self.st.center.len() as u32);
                self.st.add_particle(s, d, cluster, c, a);
                self.placed_volume += std::f64::consts::PI / 6.0 * d * d * d;
            }
        }
        let inv = self.st.reorder();
        for list in self.index_of.iter_mut() {
            for p in list.iter_mut() {
                *p = inv[*p as usize];
            }
        }
        true
    }

    /// One relaxation step (moves particles only while the worst overlap is
    /// at or above the tolerance).
    pub fn step(&mut self) -> StepReport {
        let moving = self.st.moving.len();
        let worst = self.st.step(self.tol);
        StepReport {
            moving,
            worst_overlap_nm: worst.max(0.0),
        }
    }

    /// Relaxes until the worst overlap is below the tolerance; returns the
    /// steps taken, or [`GeometryError::DynamicsNotReached`] after
    /// `max_steps_per_batch` steps.
    pub fn relax(&mut self) -> Result<u64, GeometryError> {
        // On a pool thread, so that the steps' parallel passes start without
        // handing work over from (and waking) a thread outside the pool.
        rayon::scope(|_| self.relax_here())
    }

    fn relax_here(&mut self) -> Result<u64, GeometryError> {
        let mut steps = 0u64;
        let mut fire = Fire::new();
        loop {
            let worst = if steps < self.params.fire_after_steps {
                self.st.step(self.tol)
            } else {
                self.st.fire_step(self.tol, &mut fire)
            };
            if worst < self.tol {
                self.st.stop(steps > self.params.fire_after_steps);
                self.steps += steps;
                return Ok(steps);
            }
            steps += 1;
            if steps > self.params.max_steps_per_batch {
                let box_volume: f64 = self.params.size_nm.iter().product();
                return Err(GeometryError::DynamicsNotReached {
                    target: self.params.species.iter().map(|s| s.volume_fraction).sum(),
                    reached: self.volume_before / box_volume,
                    worst_overlap_nm: worst,
                    steps: self.steps + steps,
                });
            }
        }
    }

    /// The particles as they are now, with their statistics.
    pub fn geometry(&self) -> Geometry {
        let st = &self.st;
        let size = self.params.size_nm;
        let box_volume = size[0] * size[1] * size[2];
        let particles: Vec<Particle> = (0..st.center.len())
            .map(|p| {
                let (c, a) = (st.center[p], st.axis[p]);
                let s = st.species[p] as usize;
                let d = st.scale[p];
                let spheres = st.specs[s]
                    .spheres
                    .iter()
                    .map(|&(o, r)| Sphere {
                        center: [
                            wrap(c[0] + o * d * a[0], size[0]),
                            wrap(c[1] + o * d * a[1], size[1]),
                            c[2] + o * d * a[2],
                        ],
                        radius: r * d,
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
        let unit = std::f64::consts::PI / 6.0;
        Geometry {
            size_nm: size,
            particles,
            stats: GeometryStats {
                count: self.index_of.iter().map(Vec::len).collect(),
                target_fraction: self
                    .params
                    .species
                    .iter()
                    .map(|s| s.volume_fraction)
                    .collect(),
                achieved_fraction: self
                    .diameters
                    .iter()
                    .zip(&self.index_of)
                    .map(|(ds, placed)| {
                        ds[..placed.len()]
                            .iter()
                            .map(|d| unit * d * d * d)
                            .sum::<f64>()
                            / box_volume
                    })
                    .collect(),
                min_gap_nm: min_gap,
                attempts: st.center.len() as u64,
                worst_overlap_nm: (-min_gap).max(0.0),
                order_parameter: order_parameter(&axes),
                relax_steps: self.steps,
            },
        }
    }
}

/// Packs one fragment by batches of random particles relaxed with
/// first-order dynamics (see the module docs).
///
/// Particles come out ordered by grid cell (renumbered after every batch for
/// memory locality), not in insertion order. `stats.attempts` counts the
/// particles inserted, `stats.relax_steps` the relaxation steps of all
/// batches. Deterministic for a seed, whatever the number of threads.
pub fn pack_dynamics(params: &DynParams, seed: u64) -> Result<Geometry, GeometryError> {
    let mut packer = DynamicsPacker::new(params, seed)?;
    while packer.insert_batch() {
        packer.relax()?;
    }
    let mut g = packer.geometry();
    if params.equilibrate_sweeps > 0 {
        crate::geometry::mc::equilibrate(
            g.size_nm,
            &mut g.particles,
            &packer.st.cluster,
            params.relief_fraction,
            packer.tolerance_nm(),
            params.equilibrate_sweeps,
            seed,
        );
        g.stats.min_gap_nm = min_gap_nm(g.size_nm, &g.particles);
        g.stats.worst_overlap_nm = (-g.stats.min_gap_nm).max(0.0);
    }
    Ok(g)
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
