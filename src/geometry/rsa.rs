//! Random sequential addition of spheres (METHOD §2, low PVC).
//!
//! Species are placed one after another by decreasing nominal diameter (ties
//! keep the input order); within a species, grains in the order of their
//! drawn diameters, largest first (a size distribution packs further that
//! way). Each particle's centre is drawn uniformly in
//! `[0,Lx) × [0,Ly) × [r − ρ d, H−r]` (`ρ` the relief fraction, so it never
//! crosses the bottom wall and protrudes through the top by at most `ρ d`)
//! and rejected when it overlaps a placed sphere, nearest periodic image in x
//! and y; touching is allowed. A particle that fails
//! `max_attempts_per_particle` draws in a row ends the packing with
//! [`GeometryError::NotReached`].
//!
//! Agglomeration ([`SpeciesOptions::cluster_size`] > 1): a grain that is not
//! the first of its group is first tried next to a random earlier member of
//! the group (centres `(r₁ + r₂)(1 + 1e-9)` apart, random direction), up to
//! [`CLUSTER_TRIES`] times; failing that it is placed as above and starts a
//! new group. One RNG stream (`Xoshiro256PlusPlus`), consumed sequentially:
//! the result depends on the seed only.

use super::cells::CellList;
use super::shapes::{axis_from_uniforms, Orientation};
use super::{sphere_volume, GeometryError, PackParams, Particle, SpeciesOptions, Sphere};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Directions tried next to the grain's group before it starts a new one.
pub const CLUSTER_TRIES: usize = 64;

/// Uniform draw in `[0, l)`; the product can round up to `l`, which wraps to 0.
#[inline]
fn draw_periodic(rng: &mut Xoshiro256PlusPlus, l: f64) -> f64 {
    let x = rng.gen::<f64>() * l;
    if x >= l {
        0.0
    } else {
        x
    }
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

/// Places every species' spheres (`diameters[s]`); returns the particles in
/// placement order and the number of centres drawn.
pub(crate) fn pack(
    params: &PackParams,
    diameters: &[Vec<f64>],
    options: &[SpeciesOptions],
    seed: u64,
) -> Result<(Vec<Particle>, u64), GeometryError> {
    let size = params.size_nm;
    let total: usize = diameters.iter().map(Vec::len).sum();
    let dmax = diameters.iter().flatten().copied().fold(0.0, f64::max);
    let mut order: Vec<usize> = (0..params.species.len()).collect();
    order.sort_by(|&a, &b| {
        params.species[b]
            .diameter_nm
            .total_cmp(&params.species[a].diameter_nm)
    });
    let relief = params.relief_fraction;

    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut cells = CellList::new(size, dmax.max(f64::MIN_POSITIVE), total);
    let mut particles: Vec<Particle> = Vec::with_capacity(total);
    let mut attempts = 0u64;
    let box_volume = size[0] * size[1] * size[2];
    let mut placed_volume = 0.0;

    for &s in &order {
        let mut ds = diameters[s].clone();
        ds.sort_by(|a, b| b.total_cmp(a));
        let group = options[s].cluster_size.max(1);
        // First particle index of the current group.
        let mut group_start = particles.len();
        for (placed, &d) in ds.iter().enumerate() {
            let r = 0.5 * d;
            let z_lo = r - relief * d;
            let z_span = (size[2] - r - z_lo).max(0.0);
            if placed.is_multiple_of(group) {
                group_start = particles.len();
            }
            let mut center = None;
            if particles.len() > group_start {
                for _ in 0..CLUSTER_TRIES {
                    let m = group_start + rng.gen_range(0..particles.len() - group_start);
                    let other = particles[m].spheres[0];
                    let u = axis_from_uniforms(Orientation::Random, rng.gen(), rng.gen());
                    let dist = (r + other.radius) * (1.0 + 1e-9);
                    let c = [
                        wrap(other.center[0] + dist * u[0], size[0]),
                        wrap(other.center[1] + dist * u[1], size[1]),
                        other.center[2] + dist * u[2],
                    ];
                    attempts += 1;
                    if c[2] >= z_lo && c[2] <= size[2] - r && !cells.overlaps(&c, r) {
                        center = Some(c);
                        break;
                    }
                }
                if center.is_none() {
                    group_start = particles.len();
                }
            }
            let mut fails = 0u64;
            let c = loop {
                if let Some(c) = center {
                    break c;
                }
                let c = [
                    draw_periodic(&mut rng, size[0]),
                    draw_periodic(&mut rng, size[1]),
                    z_lo + rng.gen::<f64>() * z_span,
                ];
                attempts += 1;
                if !cells.overlaps(&c, r) {
                    break c;
                }
                fails += 1;
                if fails >= params.max_attempts_per_particle {
                    let target: f64 = params.species.iter().map(|sp| sp.volume_fraction).sum();
                    return Err(GeometryError::NotReached {
                        species: s,
                        placed,
                        wanted: ds.len(),
                        target,
                        reached: placed_volume / box_volume,
                        attempts,
                    });
                }
            };
            let sphere = Sphere {
                center: c,
                radius: r,
            };
            cells.insert(sphere, particles.len() as u32);
            particles.push(Particle {
                species: s,
                spheres: vec![sphere],
            });
            placed_volume += sphere_volume(r);
        }
    }
    Ok((particles, attempts))
}
