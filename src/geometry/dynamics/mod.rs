//! First-order dynamics packer for high PVC (METHOD §2).
//!
//! Particles are rigid sphere clusters on an axis
//! ([`ShapeTemplate`](crate::geometry::ShapeTemplate)), each scaled to its
//! own effective diameter (size distributions, see
//! [`SpeciesOptions`](crate::geometry::SpeciesOptions)). They are thrown in
//! batches into the (overlap-free) ensemble with overlaps allowed, then
//! pushed apart:
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
//! moves at most [`FIRE_MAX_MOVE`](fire::FIRE_MAX_MOVE) of its particle's smallest radius per
//! step. Forces come from a Verlet list (neighbours within reach + a skin
//! of [`VERLET_SKIN`](verlet::VERLET_SKIN) r_min, rebuilt when a sphere may have moved half of
//! it since the last build). Below [`PARALLEL_MIN_PARTICLES`] particles the
//! passes run serially and the list holds each pair once (both particles
//! updated); from there on they run on the rayon pool in [`CHUNK`]s with a
//! list holding each pair from both sides (each particle sums its own). The
//! choice depends on the size only, and FIRE's sums are taken per chunk
//! then over chunks in order, so this stage is deterministic for any thread
//! count too. First-order dynamics stays the core: at the 50–55 % the study asks for
//! targets batches converge in it or need a short FIRE tail; near jamming
//! FIRE's inertia unjams far faster.
//!
//! A batch is relaxed until the worst overlap (pairs and walls) is below the
//! tolerance, or fails after `max_steps_per_batch` steps with
//! [`GeometryError::DynamicsNotReached`](crate::geometry::GeometryError::DynamicsNotReached)
//! and the density of the last overlap-free ensemble. [`DynamicsPacker`]
//! exposes the batches and steps (for benchmarks); [`pack_dynamics`] runs it
//! to the end.
//!
//! Takes [`DynParams`] and a seed, gives a [`Geometry`](crate::geometry::Geometry).
//! Files: `params` (parameters and their validation), `state` (the ensemble,
//! its cells and scratch), `forces` (pair, wall and alignment forces),
//! `first_order` (the overdamped step), `verlet` (the Verlet list and its
//! force passes), `fire` (the FIRE step), `packer` (batches, the step-by-step
//! packer and [`pack_dynamics`]).

mod fire;
mod first_order;
mod forces;
mod packer;
mod params;
mod state;
mod verlet;

pub use packer::{pack_dynamics, particle_axis, DynamicsPacker};
pub use params::{DynParams, DynSpecies};

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
