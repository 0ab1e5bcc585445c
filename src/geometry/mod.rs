//! Geometry — the particles of the fragment (METHOD §2).
//!
//! Owns the particle list of one random fragment `[0,Lx) × [0,Ly) × [0,H]`,
//! periodic in x and y with walls at `z = 0` and `z = H`, and the packers that
//! build it. Every particle is a rigid cluster of spheres ([`Particle`]).
//! Two packers: [`pack_rsa`] (random sequential addition of one-sphere
//! particles, PVC ≲ 30 %) and [`pack_dynamics`] (first-order dynamics of
//! sphere-cluster shapes — sphere, cylinder, rice grain, see [`Shape`] — with
//! orientation modes, to 50 % PVC and beyond). Lengths are in nm.
//!
//! Choices:
//! - sphere centres are stored wrapped into `[0,Lx) × [0,Ly)`; distances use
//!   the nearest periodic image, which is exact because a grain may be at most
//!   half the lateral period wide (checked);
//! - particle counts are `N_s = round(f_s · V / v_s)`, so the achieved fraction
//!   differs from the target only by that rounding (reported in
//!   [`GeometryStats`]);
//! - RSA cannot exceed its saturation (jamming) limit (0.384 for spheres in
//!   bulk, lower next to walls); it runs to saturation (sampling only the
//!   uncovered space once plain draws fail) and reports
//!   [`GeometryError::NotReached`] with the exact saturation density.
//!
//! Shared by the packers and the statistics: `cells` (the one cell grid and
//! its storages), `periodic` (wrapping and nearest periodic images) and
//! `vec3` (3-vector helpers). `normal`: the standard normal deviate every
//! stage draws.

mod cells;
mod dynamics;
pub mod mc;
pub mod normal;
mod periodic;
mod rsa;
mod shapes;
mod stacked;
pub mod stats;
mod vec3;

pub use dynamics::{
    pack_dynamics, particle_axis, DynParams, DynSpecies, DynamicsPacker, PARALLEL_MIN_PARTICLES,
};
pub use shapes::{
    axis_from_uniforms, order_parameter, union_volume, Orientation, Shape, ShapeTemplate,
    SizeDistribution,
};
pub use stacked::{stacked, without_grains, StackPart};
pub use stats::{analyse, Statistics, StatsParams};

use cells::CellList;
use periodic::dist2;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// Largest number of grains per seeded cluster ([`SpeciesOptions::cluster_size`]).
pub const MAX_CLUSTER_SIZE: usize = 10_000;
/// Largest [`PackParams::relief_fraction`] / [`DynParams::relief_fraction`].
pub const MAX_RELIEF_FRACTION: f64 = 0.5;

/// Per-species options shared by both packers (size distribution and
/// agglomeration). `Default`: fixed size, no clusters.
///
/// Agglomeration model: the grains of a species are taken in consecutive
/// groups of `cluster_size` (the last group may be smaller); the first grain
/// of a group is placed at random, every further one next to a random
/// earlier member of its group (centre distance = sum of their largest
/// sphere radii, random direction). RSA keeps such a seed only if it
/// overlaps nothing (up to [`rsa::CLUSTER_TRIES`] directions, then the grain
/// starts a new group at a random place); the dynamics packer lets it
/// overlap and, during relaxation, pulls members of one group together with
/// a short-range attraction (see `dynamics`). Whether grains end up in
/// contact is measured independently by [`stats::analyse`] (connected
/// components of grains closer than a contact gap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeciesOptions {
    pub size: SizeDistribution,
    /// Grains per seeded cluster, `1..=MAX_CLUSTER_SIZE` (1: no clusters).
    pub cluster_size: usize,
}

impl Default for SpeciesOptions {
    fn default() -> Self {
        SpeciesOptions {
            size: SizeDistribution::Fixed,
            cluster_size: 1,
        }
    }
}

/// Options of species `i` (`options` empty: defaults for every species).
pub(crate) fn options_of(
    options: &[SpeciesOptions],
    n_species: usize,
) -> Result<Vec<SpeciesOptions>, GeometryError> {
    if options.is_empty() {
        return Ok(vec![SpeciesOptions::default(); n_species]);
    }
    if options.len() != n_species {
        return Err(GeometryError::Invalid(format!(
            "{} species options for {n_species} species; give one per species or none",
            options.len()
        )));
    }
    for (i, o) in options.iter().enumerate() {
        o.size
            .check()
            .map_err(|e| GeometryError::Invalid(format!("species {i}: {e}")))?;
        if !(1..=MAX_CLUSTER_SIZE).contains(&o.cluster_size) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: cluster size {} must be in [1, {MAX_CLUSTER_SIZE}]",
                o.cluster_size
            )));
        }
    }
    Ok(options.to_vec())
}

/// Checks a relief fraction against `[0, MAX_RELIEF_FRACTION]`.
pub(crate) fn check_relief(f: f64) -> Result<f64, GeometryError> {
    if f.is_finite() && (0.0..=MAX_RELIEF_FRACTION).contains(&f) {
        Ok(f)
    } else {
        Err(GeometryError::Invalid(format!(
            "relief fraction {f} must be in [0, {MAX_RELIEF_FRACTION}]"
        )))
    }
}

/// Checks a number of Monte Carlo sweeps against `[0, mc::MAX_SWEEPS]`.
pub(crate) fn check_sweeps(n: u64) -> Result<u64, GeometryError> {
    if n <= mc::MAX_SWEEPS {
        Ok(n)
    } else {
        Err(GeometryError::Invalid(format!(
            "equilibrate_sweeps {n} must be in [0, {}]",
            mc::MAX_SWEEPS
        )))
    }
}

/// Effective diameters of the grains of one species whose equal-volume
/// sphere has volume `unit_volume · D³` (π/6 for every template).
///
/// Fixed size: `round(f V / v)` grains. Otherwise diameters are drawn from
/// `rng` until the drawn volume reaches `f V`; the last draw is kept only if
/// that brings the total closer to `f V`, so the achieved fraction is within
/// half a grain's volume of the target.
pub(crate) fn draw_diameters(
    species: usize,
    d: f64,
    fraction: f64,
    box_volume: f64,
    size: SizeDistribution,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<Vec<f64>, GeometryError> {
    let unit = std::f64::consts::PI / 6.0;
    let target = fraction * box_volume;
    let estimate = target / (unit * d * d * d * size.mean_cube_ratio());
    if estimate.round() > MAX_PARTICLES as f64 {
        return Err(GeometryError::Invalid(format!(
            "species {species}: about {} grains of {d} nm needed; at most {MAX_PARTICLES} allowed",
            estimate.round()
        )));
    }
    if size == SizeDistribution::Fixed {
        return Ok(vec![d; (target / (unit * d * d * d)).round() as usize]);
    }
    let mut out = Vec::with_capacity(estimate as usize + 16);
    let mut total = 0.0;
    while total < target {
        let di = size.sample(d, rng);
        let v = unit * di * di * di;
        if total + v > target && total + v - target > target - total {
            break;
        }
        total += v;
        out.push(di);
        if out.len() > MAX_PARTICLES {
            return Err(GeometryError::Invalid(format!(
                "species {species}: more than {MAX_PARTICLES} grains needed"
            )));
        }
    }
    Ok(out)
}

/// The RNG stream of the size draws of a packing with `seed` (separate from
/// the placement stream, so fixed-size packings are unchanged by it).
pub(crate) fn size_rng(seed: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x5157_e5d1_a7b3_c0de)
}

/// Diameters of every species, `(effective diameter, volume fraction)` each,
/// drawn from one generator seeded by `seed` in species order (so the draw
/// does not depend on the packer), with the total bounded by
/// [`MAX_PARTICLES`].
pub(crate) fn draw_all_diameters(
    species: &[(f64, f64)],
    options: &[SpeciesOptions],
    box_volume: f64,
    seed: u64,
) -> Result<Vec<Vec<f64>>, GeometryError> {
    let mut rng = size_rng(seed);
    let mut out = Vec::with_capacity(species.len());
    let mut n = 0usize;
    for (i, &(d, f)) in species.iter().enumerate() {
        let ds = draw_diameters(i, d, f, box_volume, options[i].size, &mut rng)?;
        n += ds.len();
        out.push(ds);
    }
    if n > MAX_PARTICLES {
        return Err(GeometryError::Invalid(format!(
            "{n} particles in total; at most {MAX_PARTICLES} allowed"
        )));
    }
    Ok(out)
}

/// Most particles one fragment may hold (guards memory against tiny grains).
pub const MAX_PARTICLES: usize = 50_000_000;

/// A sphere of a particle, centre in world coordinates (x, y wrapped into
/// `[0, L)` by the packer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub center: [f64; 3],
    pub radius: f64,
}

/// A rigid particle: a cluster of spheres of one species (spheres of one
/// particle may overlap each other).
#[derive(Debug, Clone, PartialEq)]
pub struct Particle {
    pub species: usize,
    pub spheres: Vec<Sphere>,
}

/// One species to pack.
#[derive(Debug, Clone)]
pub struct SpeciesParams {
    /// Sphere diameter, nm (> 0, ≤ H, ≤ half the lateral period); the
    /// nominal one with a size distribution ([`PackParams::options`]), whose
    /// largest draw must fit.
    pub diameter_nm: f64,
    /// Target volume fraction of the fragment, in `[0, 1)`.
    pub volume_fraction: f64,
}

/// Fragment `[0,Lx) × [0,Ly) × [0,H]` (periodic in x, y; walls at `z = 0`
/// and `z = H`) and what to put in it.
#[derive(Debug, Clone)]
pub struct PackParams {
    /// `[Lx, Ly, H]`, nm.
    pub size_nm: [f64; 3],
    pub species: Vec<SpeciesParams>,
    /// Consecutive rejected plain draws after which the packer samples only
    /// the uncovered space (saturation search, see `rsa`), ≥ 1.
    pub max_attempts_per_particle: u64,
    /// Size distribution and clustering per species; empty: defaults.
    pub options: Vec<SpeciesOptions>,
    /// Grains may protrude through the top surface `z = 0` by up to this
    /// fraction of their diameter, `[0, MAX_RELIEF_FRACTION]` (0: flat).
    pub relief_fraction: f64,
    /// Hard-sphere Monte Carlo sweeps run on the packed fragment
    /// ([`mc::equilibrate`]), `[0, mc::MAX_SWEEPS]` (0: none).
    pub equilibrate_sweeps: u64,
}

/// The METHOD §1 default fragment (10 × 10 µm, 1 µm thick), no species,
/// [`PackParams::DEFAULT_MAX_ATTEMPTS`].
impl Default for PackParams {
    fn default() -> Self {
        PackParams::new([10_000.0, 10_000.0, 1_000.0], Vec::new())
    }
}

impl PackParams {
    /// Default limit of consecutive failed draws per particle.
    pub const DEFAULT_MAX_ATTEMPTS: u64 = 100_000;

    /// Parameters with the default attempt limit.
    pub fn new(size_nm: [f64; 3], species: Vec<SpeciesParams>) -> Self {
        PackParams {
            size_nm,
            species,
            max_attempts_per_particle: Self::DEFAULT_MAX_ATTEMPTS,
            options: Vec::new(),
            relief_fraction: 0.0,
            equilibrate_sweeps: 0,
        }
    }
}

/// What the packer achieved (`Default`: empty, for hand-built geometries).
#[derive(Debug, Clone, Default)]
pub struct GeometryStats {
    /// Particles per species.
    pub count: Vec<usize>,
    /// Requested volume fraction per species.
    pub target_fraction: Vec<f64>,
    /// Placed volume / fragment volume per species (exact: no overlaps).
    pub achieved_fraction: Vec<f64>,
    /// Smallest surface-to-surface distance between two particles, periodic
    /// images included; `+inf` with fewer than two particles.
    pub min_gap_nm: f64,
    /// Centres drawn in total (accepted and rejected); for
    /// [`pack_dynamics`], particles inserted.
    pub attempts: u64,
    /// Deepest overlap between two particles, `max(0, −min_gap_nm)`.
    pub worst_overlap_nm: f64,
    /// `S = <P2(cos θ)>`, θ between a particle axis and z, over particles of
    /// more than one sphere; `None` when there are none.
    pub order_parameter: Option<f64>,
    /// Relaxation steps taken ([`pack_dynamics`]; 0 for RSA).
    pub relax_steps: u64,
}

/// One packed fragment.
#[derive(Debug, Clone)]
pub struct Geometry {
    /// `[Lx, Ly, H]`, nm.
    pub size_nm: [f64; 3],
    /// Particles in placement order.
    pub particles: Vec<Particle>,
    pub stats: GeometryStats,
}

/// Why a fragment could not be packed.
#[derive(Debug, thiserror::Error)]
pub enum GeometryError {
    #[error(
        "species {species}: grain diameter {diameter_nm} nm exceeds the layer thickness \
         {thickness_nm} nm (allowed: 0 < diameter ≤ thickness)"
    )]
    GrainTooLarge {
        species: usize,
        diameter_nm: f64,
        thickness_nm: f64,
    },
    #[error(
        "random sequential addition saturated: species {species} placed {placed} of {wanted} \
         particles; reached total volume fraction {reached:.4} of target {target:.4} after \
         {attempts} draws, and no room is left for another grain (RSA of spheres saturates \
         at 0.384 in bulk, lower in thin slabs; lower the PVC or use the dynamics packer)"
    )]
    NotReached {
        /// Species being placed when packing stopped.
        species: usize,
        /// Particles of that species already placed.
        placed: usize,
        /// Particles of that species wanted.
        wanted: usize,
        /// Total requested volume fraction (all species).
        target: f64,
        /// Total volume fraction placed when packing stopped.
        reached: f64,
        /// Centres drawn in total.
        attempts: u64,
    },
    #[error(
        "first-order dynamics did not converge: worst overlap {worst_overlap_nm:.4} nm after \
         {steps} steps; reached overlap-free volume fraction {reached:.4} of target \
         {target:.4} (lower the PVC or raise max_steps_per_batch)"
    )]
    DynamicsNotReached {
        /// Total requested volume fraction.
        target: f64,
        /// Volume fraction of the last overlap-free ensemble.
        reached: f64,
        /// Worst overlap left when the step limit was hit, nm.
        worst_overlap_nm: f64,
        /// Relaxation steps taken in total.
        steps: u64,
    },
    #[error("invalid geometry parameters: {0}")]
    Invalid(String),
}

/// Volume of a sphere of radius `r`.
pub fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * r * r * r
}

/// Checks the parameters and draws every species' diameters (sizes RNG
/// stream of `seed`).
fn validate(params: &PackParams, seed: u64) -> Result<Vec<Vec<f64>>, GeometryError> {
    let [lx, ly, h] = params.size_nm;
    for (name, v) in [("Lx", lx), ("Ly", ly), ("H", h)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(GeometryError::Invalid(format!(
                "fragment size {name} = {v} nm must be finite and > 0"
            )));
        }
    }
    if params.max_attempts_per_particle == 0 {
        return Err(GeometryError::Invalid(
            "max_attempts_per_particle must be ≥ 1".into(),
        ));
    }
    let options = options_of(&params.options, params.species.len())?;
    check_relief(params.relief_fraction)?;
    check_sweeps(params.equilibrate_sweeps)?;
    let volume = lx * ly * h;
    let mut total_fraction = 0.0;
    for (i, s) in params.species.iter().enumerate() {
        let d = s.diameter_nm;
        if !(d.is_finite() && d > 0.0) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: diameter {d} nm must be finite and > 0"
            )));
        }
        let dmax = options[i].size.range(d).1;
        if dmax > h {
            return Err(GeometryError::GrainTooLarge {
                species: i,
                diameter_nm: dmax,
                thickness_nm: h,
            });
        }
        let half = 0.5 * lx.min(ly);
        if dmax > half {
            return Err(GeometryError::Invalid(format!(
                "species {i}: diameter {dmax} nm exceeds half the lateral period ({half} nm); \
                 allowed 0 < diameter ≤ min(Lx, Ly)/2"
            )));
        }
        let f = s.volume_fraction;
        if !(f.is_finite() && (0.0..1.0).contains(&f)) {
            return Err(GeometryError::Invalid(format!(
                "species {i}: volume fraction {f} must be in [0, 1)"
            )));
        }
        total_fraction += f;
    }
    if total_fraction >= 1.0 {
        return Err(GeometryError::Invalid(format!(
            "total volume fraction {total_fraction} must be < 1"
        )));
    }
    let species: Vec<(f64, f64)> = params
        .species
        .iter()
        .map(|s| (s.diameter_nm, s.volume_fraction))
        .collect();
    draw_all_diameters(&species, &options, volume, seed)
}

/// Packs one fragment by random sequential addition (see the module docs).
///
/// Deterministic: the same parameters and `seed` give identical particles.
pub fn pack_rsa(params: &PackParams, seed: u64) -> Result<Geometry, GeometryError> {
    let diameters = validate(params, seed)?;
    let options = options_of(&params.options, params.species.len())?;
    let (mut particles, groups, attempts) = rsa::pack(params, &diameters, &options, seed)?;
    mc::equilibrate(
        params.size_nm,
        &mut particles,
        &groups,
        params.relief_fraction,
        0.0,
        params.equilibrate_sweeps,
        seed,
    );
    let volume = params.size_nm.iter().product::<f64>();
    let achieved_fraction = diameters
        .iter()
        .map(|ds| ds.iter().map(|&d| sphere_volume(0.5 * d)).sum::<f64>() / volume)
        .collect();
    let counts = diameters.iter().map(Vec::len).collect();
    let min_gap_nm = min_gap_nm(params.size_nm, &particles);
    Ok(Geometry {
        size_nm: params.size_nm,
        particles,
        stats: GeometryStats {
            count: counts,
            target_fraction: params.species.iter().map(|s| s.volume_fraction).collect(),
            achieved_fraction,
            min_gap_nm,
            attempts,
            worst_overlap_nm: (-min_gap_nm).max(0.0),
            order_parameter: None,
            relax_steps: 0,
        },
    })
}

/// Smallest surface-to-surface distance `|AB| − r_A − r_B` between spheres of
/// different particles, nearest periodic image in x and y (negative for an
/// overlap); `+inf` with fewer than two particles.
///
/// Uses a cell list with a stencil that widens until the result is provably
/// the global minimum, so it costs O(N) for packed fragments.
pub fn min_gap_nm(size_nm: [f64; 3], particles: &[Particle]) -> f64 {
    let spheres: usize = particles.iter().map(|p| p.spheres.len()).sum();
    let rmax = particles
        .iter()
        .flat_map(|p| &p.spheres)
        .map(|s| s.radius)
        .fold(0.0, f64::max);
    if particles.len() < 2 || !size_nm.iter().all(|v| v.is_finite() && *v > 0.0) {
        return f64::INFINITY;
    }
    let mut cells = CellList::new(size_nm, (2.0 * rmax).max(f64::MIN_POSITIVE), spheres);
    for (i, p) in particles.iter().enumerate() {
        for s in &p.spheres {
            cells.insert(*s, i as u32);
        }
    }
    let mut k = 1;
    loop {
        let mut best = f64::INFINITY;
        for (i, p) in particles.iter().enumerate() {
            for a in &p.spheres {
                cells.any_near(&a.center, k, |_, b, owner| {
                    if owner as usize > i {
                        let g = dist2(&a.center, &b.center, &size_nm).sqrt() - a.radius - b.radius;
                        best = best.min(g);
                    }
                    false
                });
            }
        }
        // Any pair closer than `best` has centres within best + 2 rmax.
        if cells.stencil_covers_all(k) || best + 2.0 * rmax <= k as f64 * cells.min_cell_width() {
            return best;
        }
        k += 1;
    }
}
