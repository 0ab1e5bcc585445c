//! First-order dynamics packer for high PVC (METHOD §2).
//!
//! Particles are rigid sphere clusters on an axis ([`ShapeTemplate`]), each
//! scaled to its own effective diameter (size distributions, see
//! [`SpeciesOptions`]). They are thrown in batches into the (overlap-free)
//! ensemble with overlaps allowed, then pushed apart:
//! - two spheres of different particles with overlap depth
//!   `L = R1 + R2 − |AB|` repel along `AB` with `F = k (L + δ)` for `L > 0`
//!   (0 otherwise; largest when the centres coincide, then along +z);
//!   `δ` = half the overlap tolerance is a small offset so that an
//!   overlapping pair separates in a finite number of steps instead of
//!   creeping towards contact, while touching particles (`L ≤ 0`) feel
//!   nothing and can rest;
//! - a wall pushes a sphere back along its normal with `k (d + δ)` for
//!   `d > 0`, `d` how far the sphere sticks out of `[−ρ D, H]` (`ρ` the
//!   relief fraction, `D` the particle's effective diameter: grains may
//!   protrude through the top surface `z = 0` by up to `ρ D`);
//! - agglomeration: spheres of two particles seeded in the same cluster
//!   attract with `k_a g` (`k_a` = [`ATTRACTION`] k) when their surface gap
//!   `g` lies in `(δ, a (R1 + R2))`, `a` = [`ATTRACTION_RANGE`]; zero within
//!   `δ` of contact so that bonded pairs come to rest, and zero beyond the
//!   range (a bond that is torn apart stays broken);
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
//!   cells are at least one particle length (plus the attraction range) wide,
//!   so the 3×3×3 block around a particle holds every particle it can touch;
//! - the moving list holds the particles that moved in the previous step; any
//!   new contact involves one of them, so resting particles cost nothing. A
//!   pair is evaluated once: by the moving particle, or by the lower index
//!   when both move; a resting particle that is pushed moves in that step;
//! - for one-sphere particles, while a quarter or more of them move, the
//!   step instead takes every particle's force from the FIRE stage's
//!   Verlet list (below), which then costs less than looking the moving
//!   particles' pairs up in the grid (a step's cost stays linear in the
//!   moving particles, within that factor of 4).
//!
//! Parallel and deterministic: the moving list is cut into chunks of a fixed
//! [`CHUNK`] particles (independent of the thread count); rayon evaluates the
//! chunks' pairs into per-chunk lists of force contributions, which are then
//! added serially in chunk order; the moves are computed in parallel and
//! applied serially. Every floating-point sum is thus taken in an order that
//! depends on the seed only, and the result is bit-identical for any number
//! of threads. The work per step is linear in the number of moving
//! particles.
//!
//! FIRE stage (an addition to METHOD §2, for batches near jamming): a batch
//! not relaxed within [`DynParams::fire_after_steps`] first-order steps
//! continues with FIRE (Bitzek et al. 2006; parameters and integrator as
//! LAMMPS's `min_style fire`, i.e. FIRE 2.0 of Guénolé et al. 2020 with
//! `integrator eulerimplicit` and `halfstepback yes`) on `v̇ = F`,
//! `J Ω̇ = M` (unit mass): when the power `P = F·v + M·Ω` is positive the
//! velocities are mixed towards the force, `v ← (1 − α)(v + dt F) +
//! α (|v|/|F|) F` (norms before the update, mass-weighted metric) and after
//! 20 such steps the step grows; when it is not, every particle goes back
//! half its last move, stops, and the step halves. The overlap and wall
//! forces lose the `δ` offset there (a smooth energy: with the kink at
//! contact the power changes sign every step and FIRE stalls). Every sphere
//! moves at most [`FIRE_MAX_MOVE`] of its particle's smallest radius per
//! step. Forces come from a Verlet list (neighbours within reach + a skin
//! of [`VERLET_SKIN`] r_min, rebuilt when a sphere may have moved half of
//! it since the last build). Below [`PARALLEL_MIN_PARTICLES`] particles the
//! passes run serially and the list holds each pair once (both particles
//! updated); from there on they run on the rayon pool in [`CHUNK`]s with a
//! list holding each pair from both sides (each particle sums its own). The
//! choice depends on the size only, and FIRE's sums are taken per chunk
//! then over chunks in order, so this stage is deterministic for any thread
//! count too. First-order dynamics stays the core: at the 50–55 %
//! targets batches converge in it or need a short FIRE tail; near jamming
//! FIRE's inertia unjams far faster.
//!
//! A batch is relaxed until the worst overlap (pairs and walls) is below the
//! tolerance, or fails after `max_steps_per_batch` steps with
//! [`GeometryError::DynamicsNotReached`] and the density of the last
//! overlap-free ensemble. [`DynamicsPacker`] exposes the batches and steps
//! (for benchmarks); [`pack_dynamics`] runs it to the end.

use super::cells::{min_image, near_image};
use super::shapes::{axis_from_uniforms, order_parameter, Orientation, Shape, ShapeTemplate};
use super::{
    check_relief, draw_all_diameters, min_gap_nm, options_of, Geometry, GeometryError,
    GeometryStats, Particle, SpeciesOptions, Sphere,
};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;

const EMPTY: u32 = u32::MAX;
/// Spring constant and drag (arbitrary units; only ratios matter).
const K: f64 = 1.0;
/// Largest Euler step (in units of η/k).
const DT_MAX: f64 = 0.5;
/// Largest sphere displacement per step, in units of the smallest radius.
const MAX_MOVE: f64 = 0.2;
/// Cluster attraction constant, in units of `K`.
pub const ATTRACTION: f64 = 0.5;
/// Largest cluster attraction per sphere pair, in units of `K δ` (δ = half
/// the overlap tolerance): small enough that a grain pulled by up to
/// `3 / ATTRACTION_CAP` cluster mates into a third one stays within the
/// overlap tolerance (`K (L + δ) = n F` gives `L < 2δ`).
pub const ATTRACTION_CAP: f64 = 0.5;
/// Cluster attraction range, in units of the sum of the two sphere radii.
pub const ATTRACTION_RANGE: f64 = 0.25;
/// Moving particles per parallel work unit (fixed, so results do not depend
/// on the thread count).
pub const CHUNK: usize = 256;
/// Smallest ensemble whose FIRE passes run on the rayon pool; below it the
/// pool's hand-offs cost more than the work.
pub const PARALLEL_MIN_PARTICLES: usize = 4096;

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
/// For one-sphere particles, the first-order step takes every particle's
/// force from the Verlet list while at least 1 / `VERLET_SHARE` of them
/// move (for grains of several spheres the lists die within a step or two
/// of first-order moves and their builds cost more than the grid path).
const VERLET_SHARE: usize = 4;
/// Skin of the Verlet list (FIRE and first-order steps), in units of the
/// smallest sphere radius of all particles.
const VERLET_SKIN: f64 = 0.5;

/// FIRE's sums over the particles of one chunk: `F·v + M·Ω`,
/// `|v|² + J|Ω|²`, `|F|² + |M|²/J`.
#[derive(Debug, Clone, Copy, Default)]
struct FireSums {
    vf: f64,
    vv: f64,
    ff: f64,
}

/// FIRE's adaptive state (reset at every batch).
#[derive(Debug, Clone, Copy)]
struct Fire {
    dt: f64,
    alpha: f64,
    n_pos: u32,
    /// FIRE steps taken in this batch.
    steps: u64,
    /// Time step of the last move.
    last_move: f64,
}

impl Fire {
    fn new() -> Self {
        Fire {
            dt: FIRE_DT0,
            alpha: FIRE_ALPHA0,
            n_pos: 0,
            steps: 0,
            last_move: 0.0,
        }
    }
}

/// One species for [`pack_dynamics`].
#[derive(Debug, Clone)]
pub struct DynSpecies {
    pub shape: Shape,
    /// Diameter of the equal-volume sphere, nm (> 0); the nominal one with a
    /// size distribution ([`DynParams::options`]).
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
    /// of all particles, in `(0, 0.5]` (default 0.01).
    pub overlap_tolerance: f64,
    /// Volume fraction added per batch, in `(0, 1]` (default 0.1).
    pub batch_fraction: f64,
    /// Relaxation steps allowed per batch (≥ 1, default 100 000).
    pub max_steps_per_batch: u64,
    /// First-order steps of a batch after which, if it has not converged,
    /// its relaxation continues with FIRE (default 200; 0: FIRE from the
    /// start, `u64::MAX`: never).
    pub fire_after_steps: u64,
    /// Size distribution and clustering per species; empty: defaults.
    pub options: Vec<SpeciesOptions>,
    /// Grains may protrude through the top surface `z = 0` by up to this
    /// fraction of their effective diameter, `[0, MAX_RELIEF_FRACTION]`
    /// (default 0: flat top).
    pub relief_fraction: f64,
    /// Hard-particle Monte Carlo sweeps run on the packed fragment
    /// ([`super::mc::equilibrate`], moves may not deepen an overlap beyond
    /// the tolerance), `[0, mc::MAX_SWEEPS]` (default 0: none).
    pub equilibrate_sweeps: u64,
}

impl DynParams {
    /// Parameters with the defaults above.
    pub fn new(size_nm: [f64; 3], species: Vec<DynSpecies>) -> Self {
        DynParams {
            size_nm,
            species,
            overlap_tolerance: 0.01,
            batch_fraction: 0.1,
            max_steps_per_batch: 100_000,
            fire_after_steps: 200,
            options: Vec::new(),
            relief_fraction: 0.0,
            equilibrate_sweeps: 0,
        }
    }
}

/// One species after validation, lengths for effective diameter 1.
#[derive(Debug, Clone)]
struct Spec {
    /// `(axial offset, radius)`.
    spheres: Vec<(f64, f64)>,
    half_length: f64,
    r_min: f64,
    r_max: f64,
    s_max: f64,
    inertia: f64,
    /// Signed alignment strength (+ towards z, − towards the plane).
    field: f64,
    /// Grains per seeded cluster.
    group: usize,
}

/// Checks the parameters; returns the species and their diameters.
fn validate(p: &DynParams, seed: u64) -> Result<(Vec<Spec>, Vec<Vec<f64>>), GeometryError> {
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
    let options = options_of(&p.options, p.species.len())?;
    check_relief(p.relief_fraction)?;
    super::check_sweeps(p.equilibrate_sweeps)?;
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
        let dmax = options[i].size.range(d).1;
        let half_length = tpl.half_length();
        let r_max = tpl.max_radius();
        // Thinnest extent along z the largest particle can take in its mode.
        let need_z = dmax
            * match s.orientation {
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
        if 2.0 * half_length * dmax > half {
            return Err(GeometryError::Invalid(format!(
                "species {i}: particle length {} nm exceeds half the lateral period \
                 ({half} nm); allowed length ≤ min(Lx, Ly)/2",
                2.0 * half_length * dmax
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
        let spheres = tpl.spheres.clone();
        let w: f64 = spheres.iter().map(|&(_, r)| r * r * r).sum();
        let inertia = spheres
            .iter()
            .map(|&(o, r)| r * r * r * (o * o + 0.4 * r * r))
            .sum::<f64>()
            / w;
        let sign = match s.orientation {
            Orientation::Perpendicular => 1.0,
            Orientation::InPlane => -1.0,
            Orientation::Random => 0.0,
        };
        out.push(Spec {
            half_length,
            r_min: tpl.min_radius(),
            r_max,
            s_max: spheres.iter().map(|&(o, _)| o.abs()).fold(0.0, f64::max),
            inertia,
            field: sign * fld,
            group: options[i].cluster_size,
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
    let species: Vec<(f64, f64)> = p
        .species
        .iter()
        .map(|s| (s.effective_diameter_nm, s.volume_fraction))
        .collect();
    Ok((out, draw_all_diameters(&species, &options, volume, seed)?))
}
/// Grid of particle centres with doubly linked lists per cell.
#[derive(Debug, Clone)]
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

    /// Puts every centre in its cell (each cell lists its particles in
    /// index order: deterministic).
    fn relink_all(&mut self, centers: &[[f64; 3]]) {
        let n = centers.len();
        self.next.resize(n, EMPTY);
        self.prev.resize(n, EMPTY);
        self.cell_of.resize(n, 0);
        self.head.iter_mut().for_each(|h| *h = EMPTY);
        for p in (0..n).rev() {
            let f = self.flat(self.coords(&centers[p]));
            self.link(p, f);
        }
    }

    /// Bins `centers` by cell into `bins` (a counting sort; each cell's
    /// particles in index order, with their centres, contiguous).
    fn bin(&self, centers: &[[f64; 3]], bins: &mut Bins) {
        let cells = self.head.len();
        bins.cell.clear();
        bins.cell
            .extend(centers.iter().map(|c| self.flat(self.coords(c)) as u32));
        bins.start.clear();
        bins.start.resize(cells + 1, 0);
        for &f in &bins.cell {
            bins.start[f as usize + 1] += 1;
        }
        for f in 0..cells {
            bins.start[f + 1] += bins.start[f];
        }
        bins.items.clear();
        bins.items.resize(centers.len(), (0, [0.0; 3]));
        let mut fill = std::mem::take(&mut bins.fill);
        fill.clear();
        fill.extend_from_slice(&bins.start[..cells]);
        for (p, &f) in bins.cell.iter().enumerate() {
            let k = &mut fill[f as usize];
            bins.items[*k as usize] = (p as u32, centers[p]);
            *k += 1;
        }
        bins.fill = fill;
    }

    /// The cells of the 3×3×3 block around cell `c` (each once; see
    /// [`Self::range`]) into `out`, as `(flat index, is c itself)`;
    /// returns how many.
    fn stencil_cells(&self, c: [usize; 3], out: &mut [(usize, bool); 27]) -> usize {
        let (z0, z1) = self.range(2, c[2]);
        let (y0, y1) = self.range(1, c[1]);
        let (x0, x1) = self.range(0, c[0]);
        let (nx, ny) = (self.n[0] as isize, self.n[1] as isize);
        let own = self.flat(c);
        let mut k = 0;
        for cz in z0..=z1 {
            for cy in y0..=y1 {
                for cx in x0..=x1 {
                    let f = self.flat([
                        cx.rem_euclid(nx) as usize,
                        cy.rem_euclid(ny) as usize,
                        cz as usize,
                    ]);
                    out[k] = (f, f == own);
                    k += 1;
                }
            }
        }
        k
    }

    /// Cell `c` and the 13 cells ahead of it (`dz > 0`, or `dz = 0` and
    /// `dy > 0`, or `dz = dy = 0` and `dx > 0`), z clipped to the slab, into
    /// `out` as in [`Self::stencil_cells`]: every pair of neighbouring cells
    /// once, provided the periodic axes have at least 3 cells.
    fn forward_cells(&self, c: [usize; 3], out: &mut [(usize, bool); 27]) -> usize {
        let (nx, ny, nz) = (self.n[0] as isize, self.n[1] as isize, self.n[2] as isize);
        let [x, y, z] = c.map(|v| v as isize);
        out[0] = (self.flat(c), true);
        let mut k = 1;
        for dz in 0..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let ahead = dz > 0 || dy > 0 || (dy == 0 && dx > 0);
                    if !ahead || z + dz >= nz {
                        continue;
                    }
                    out[k] = (
                        self.flat([
                            (x + dx).rem_euclid(nx) as usize,
                            (y + dy).rem_euclid(ny) as usize,
                            (z + dz) as usize,
                        ]),
                        false,
                    );
                    k += 1;
                }
            }
        }
        k
    }

    /// Cell ranges around `c` along axis `a` (no cell twice).
    fn range(&self, a: usize, c: usize) -> (isize, isize) {
        super::cells::stencil(self.n[a], c, a < 2)
    }
}

/// Particles binned by cell (see [`Grid::bin`]); buffers reused.
#[derive(Debug, Clone, Default)]
struct Bins {
    /// Cell `f` holds `items[start[f]..start[f + 1]]`.
    start: Vec<u32>,
    /// `(particle, centre)`.
    items: Vec<(u32, [f64; 3])>,
    /// Cell of every particle, and the fill pointers (scratch).
    cell: Vec<u32>,
    fill: Vec<u32>,
}

/// A force contribution to one particle: `(particle, force, torque)`.
type Contribution = (u32, [f64; 3], [f64; 3]);

/// Forces of one pair, on `i` (`f`, `mi`) and on `j` (`−f`, `mj`).
struct PairForce {
    f: [f64; 3],
    mi: [f64; 3],
    mj: [f64; 3],
    /// Worst overlap depth of the pair (−inf when none).
    worst: f64,
}

/// Dynamic state of the ensemble.
#[derive(Debug, Clone)]
struct State {
    size: [f64; 3],
    relief: f64,
    specs: Vec<Spec>,
    center: Vec<[f64; 3]>,
    axis: Vec<[f64; 3]>,
    species: Vec<u32>,
    /// Effective diameter, nm.
    scale: Vec<f64>,
    /// Seeded cluster (`EMPTY`: none).
    cluster: Vec<u32>,
    grid: Grid,
    force: Vec<[f64; 3]>,
    torque: Vec<[f64; 3]>,
    /// Velocity and angular velocity (FIRE stage only; zero otherwise).
    vel: Vec<[f64; 3]>,
    ang: Vec<[f64; 3]>,
    /// Verlet list (every particle's neighbours within reach + `nb_skin`,
    /// CSR); `nb_start` empty: no valid list.
    nb_start: Vec<u32>,
    nb: Vec<u32>,
    nb_skin: f64,
    /// Centre and axis of every particle when the Verlet list was built.
    nb_ref: Vec<([f64; 3], [f64; 3])>,
    /// Centres binned for the list build.
    nb_bins: Bins,
    /// Half length of every particle (scratch of the list build).
    nb_ext: Vec<f64>,
    /// The Verlet list holds each pair once (serial force pass) rather
    /// than from both sides (parallel force pass).
    nb_half: bool,
    /// Particles moved without their cells being updated (Verlet or FIRE
    /// steps); the grid path relinks first.
    grid_stale: bool,
    /// Cells of the Verlet list build (at least reach + skin wide).
    nb_grid: Option<Grid>,
    /// Largest centre distance at which two particles can interact, nm.
    max_reach: f64,
    /// Every particle is one sphere and none is in a seeded cluster; then
    /// `radius0` holds the radii (FIRE stage fast path).
    plain_spheres: bool,
    radius0: Vec<f64>,
    /// FIRE sums per chunk (reused).
    fire_sums: Vec<FireSums>,
    moving_mark: Vec<u64>,
    touched_mark: Vec<u64>,
    epoch: u64,
    moving: Vec<u32>,
    touched: Vec<u32>,
    /// Per-chunk contribution lists (reused).
    bufs: Vec<Vec<Contribution>>,
    /// New (centre, axis) of the touched particles (reused).
    moves: Vec<Option<([f64; 3], [f64; 3])>>,
    skin: f64,
    /// Offset of the overlap and wall forces: `skin` in the first-order
    /// stage, 0 in the FIRE stage (a smooth energy for the inertial step).
    push: f64,
}

/// `x` wrapped into `[0, l)`.
#[inline]
fn wrap(x: f64, l: f64) -> f64 {
    let w = if x < 0.0 {
        x + l
    } else if x >= l {
        x - l
    } else {
        return x;
    };
    let w = if (0.0..l).contains(&w) {
        w
    } else {
        w.rem_euclid(l)
    };
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
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn norm(a: &[f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// `a` turned by the rotation vector `om dt` (Rodrigues), renormalised.
#[inline]
fn rotate(a: &[f64; 3], om: &[f64; 3], dt: f64) -> [f64; 3] {
    let no = norm(om);
    let phi = no * dt;
    if phi <= 0.0 {
        return *a;
    }
    let k = [om[0] / no, om[1] / no, om[2] / no];
    let kxa = cross(&k, a);
    let kd = k[0] * a[0] + k[1] * a[1] + k[2] * a[2];
    let (s, co) = phi.sin_cos();
    let mut b = [0.0; 3];
    for ax in 0..3 {
        b[ax] = a[ax] * co + kxa[ax] * s + k[ax] * kd * (1.0 - co);
    }
    let nb = norm(&b);
    [b[0] / nb, b[1] / nb, b[2] / nb]
}

/// Runs `f(p, &mut a[p], &mut b[p])` for every particle `p` in chunks of
/// [`CHUNK`], on the rayon pool when `parallel`, and returns the largest
/// value `f` gave (0 if none): a maximum, so the result does not depend on
/// how the chunks were shared out.
fn for_each_max<A: Send, B: Send>(
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

/// Verlet-list entries whose sphere pair forces are computed together.
const LANES: usize = 4;

/// [`near_image`] for two coordinates wrapped into one period (so
/// `|d| < l`), with selects instead of branches.
#[inline(always)]
fn near_image_select(d: f64, l: f64) -> f64 {
    let h = 0.5 * l;
    d - if d > h { l } else { 0.0 } + if d < -h { l } else { 0.0 }
}

/// Adds the alignment torque of a particle of `spec`, diameter `d`, axis `a`.
#[inline]
fn add_field_torque(spec: &Spec, d: f64, a: &[f64; 3], m: &mut [f64; 3]) {
    if spec.field != 0.0 {
        let t = cross(a, &[0.0, 0.0, 1.0]);
        let r_max = spec.r_max * d;
        add(m, &t, spec.field * K * r_max * r_max * a[2]);
    }
}

impl State {
    fn add_particle(&mut self, s: usize, d: f64, cluster: u32, c: [f64; 3], a: [f64; 3]) {
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
    fn reorder(&mut self) -> Vec<u32> {
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

    /// Forces of the pair `(i, j)`; `None` when none acts.
    fn pair(&self, i: usize, j: usize) -> Option<PairForce> {
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
    fn sphere_pairs<const N: usize>(&self, i: usize, js: &[u32; N]) -> ([[f64; N]; 3], [f64; N]) {
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

    /// [`Self::walls`] for a one-sphere particle: the force's z component
    /// and the penetration (branch-free).
    #[inline]
    fn sphere_walls(&self, i: usize) -> (f64, f64) {
        let r = self.radius0[i];
        let z = self.center[i][2];
        let below = -self.relief * self.scale[i] + r - z;
        let above = z + r - self.size[2];
        let push = |d: f64| K * (d.max(0.0) + if d > 0.0 { self.push } else { 0.0 });
        (push(below) - push(above), below.max(above))
    }

    /// Wall force and torque on particle `i` and its worst penetration.
    #[inline]
    fn walls(&self, i: usize) -> ([f64; 3], [f64; 3], f64) {
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

    /// Forces on moving particle `i` from the walls and from every neighbour
    /// whose pair it owns; contributions go to `buf` (neighbours first, then
    /// `i` itself). Returns the worst overlap seen.
    fn gather(&self, i: usize, ep: u64, buf: &mut Vec<Contribution>) -> f64 {
        let (mut fi, mut mi, mut worst) = self.walls(i);
        let mut cells = [(0usize, false); 27];
        let count = self
            .grid
            .stencil_cells(self.grid.coords(&self.center[i]), &mut cells);
        for &(f, _) in &cells[..count] {
            let mut j = self.grid.head[f];
            while j != EMPTY {
                let ju = j as usize;
                j = self.grid.next[ju];
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
    fn advance(&self, p: usize, c0: &[f64; 3], a: &[f64; 3]) -> Option<([f64; 3], [f64; 3])> {
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
    fn forces(&mut self, tol: f64) -> f64 {
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
    fn step(&mut self, tol: f64) -> f64 {
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

    /// [`Self::step`] for every particle, forces from the Verlet list (the
    /// FIRE stage's, with the first-order force's `δ` offset); the cells
    /// are relinked when the grid path takes over again.
    fn step_verlet(&mut self, tol: f64) -> f64 {
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

    /// Builds the Verlet list of every particle (neighbours within their
    /// interaction reach plus `nb_skin`, in cell order: deterministic).
    fn build_neighbours(&mut self) {
        let n = self.center.len();
        // A grid whose 3×3×3 stencil covers reach + skin; the FIRE stage
        // moves particles without updating any cell, so it is relinked.
        let min_cell = self.max_reach + self.nb_skin;
        let grid = self
            .nb_grid
            .get_or_insert_with(|| Grid::new(self.size, min_cell, n));
        grid.bin(&self.center, &mut self.nb_bins);
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
        let forward = half && grid.n[0] >= 3 && grid.n[1] >= 3;
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
    fn forces_all(&mut self) -> f64 {
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
    /// particles updated): serial, for ensembles below [`PARALLEL_MIN_PARTICLES`].
    fn forces_half(&mut self) -> f64 {
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

    /// Force on sphere particle `i` from sphere particle `j` (same as
    /// `pair` for two one-sphere particles without a cluster bond) and
    /// their overlap depth (negative: a gap). Branch-free: whether a listed
    /// pair touches is a coin toss near jamming, and a mispredicted branch
    /// costs more than the arithmetic.
    #[inline(always)]
    fn sphere_pair(&self, i: usize, j: usize) -> ([f64; 3], f64) {
        let (f, l) = self.sphere_pairs(i, &[j as u32]);
        ([f[0][0], f[1][0], f[2][0]], l[0])
    }

    /// Moves particle `p` (centre `c`, axis `a`) for `dt` at its FIRE
    /// velocity and angular velocity.
    #[inline(always)]
    fn drift(&self, p: usize, c: &mut [f64; 3], a: &mut [f64; 3], dt: f64) {
        let (v, w) = (self.vel[p], self.ang[p]);
        c[0] = wrap(c[0] + v[0] * dt, self.size[0]);
        c[1] = wrap(c[1] + v[1] * dt, self.size[1]);
        c[2] += v[2] * dt;
        if !self.plain_spheres {
            *a = rotate(a, &w, dt);
        }
    }

    /// Square of the farthest any sphere of particle `p`, now at centre `c`
    /// and axis `a`, can be from where it was when the Verlet list was
    /// built (squared: no root for one-sphere particles).
    #[inline(always)]
    fn displacement2(&self, p: usize, c: &[f64; 3], a: &[f64; 3]) -> f64 {
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

    /// Adds the alignment torque to particle `i` when it is pushed (`f`,
    /// `m` its force and torque): resting particles do not turn, as in the
    /// first-order stage.
    #[inline]
    fn add_field_torque_if_pushed(&self, i: usize, f: &[f64; 3], m: &mut [f64; 3]) {
        if *f != [0.0; 3] || *m != [0.0; 3] {
            let spec = &self.specs[self.species[i] as usize];
            add_field_torque(spec, self.scale[i], &self.axis[i], m);
        }
    }

    /// FIRE's sums over particles (mass-weighted metric), per chunk in chunk
    /// order: `F·v + M·Ω`, `|v|² + J|Ω|²`, `|F|² + |M|²/J`.
    fn sum_fire_terms(&mut self) {
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

    /// Whether the per-particle passes run on the rayon pool: only for
    /// ensembles of at least [`PARALLEL_MIN_PARTICLES`] particles (a choice made from the
    /// size, never from the thread count, so results stay bit-identical).
    fn parallel(&self) -> bool {
        self.center.len() >= PARALLEL_MIN_PARTICLES
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
    fn fire_step(&mut self, tol: f64, fire: &mut Fire) -> f64 {
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

    /// Rebuilds every cell list from the particle centres (deterministic:
    /// each cell lists its particles in index order).
    fn relink(&mut self) {
        self.grid.relink_all(&self.center);
        self.grid_stale = false;
    }

    /// Ends a batch's relaxation: puts every particle back in its cell and,
    /// after a FIRE stage (`fired`: every particle may move), sets every
    /// velocity to zero and every particle on the moving list.
    fn stop(&mut self, fired: bool) {
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
            grid: Grid::new(size, cell.max(f64::MIN_POSITIVE), total),
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
        super::mc::equilibrate(
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
