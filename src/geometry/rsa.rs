//! Random sequential addition of spheres (METHOD §2, low PVC).
//!
//! Species are placed one after another by decreasing diameter (ties keep the
//! input order). Each particle's centre is drawn uniformly in
//! `[0,Lx) × [0,Ly) × [r, H−r]` (so it never crosses a wall) and rejected when
//! it overlaps a placed sphere, nearest periodic image in x and y; touching is
//! allowed. A particle that fails `max_attempts_per_particle` draws in a row
//! ends the packing with [`GeometryError::NotReached`]. One RNG stream
//! (`Xoshiro256PlusPlus`), consumed sequentially: the result depends on the
//! seed only.

use super::cells::CellList;
use super::{sphere_volume, GeometryError, PackParams, Particle, Sphere};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

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

/// Places `counts[s]` spheres of every species; returns the particles in
/// placement order and the number of centres drawn.
pub(crate) fn pack(
    params: &PackParams,
    counts: &[usize],
    seed: u64,
) -> Result<(Vec<Particle>, u64), GeometryError> {
    let size = params.size_nm;
    let total: usize = counts.iter().sum();
    let dmax = params
        .species
        .iter()
        .zip(counts)
        .filter(|(_, &n)| n > 0)
        .map(|(s, _)| s.diameter_nm)
        .fold(0.0, f64::max);
    let mut order: Vec<usize> = (0..params.species.len()).collect();
    order.sort_by(|&a, &b| {
        params.species[b]
            .diameter_nm
            .total_cmp(&params.species[a].diameter_nm)
    });

    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut cells = CellList::new(size, dmax.max(f64::MIN_POSITIVE), total);
    let mut particles = Vec::with_capacity(total);
    let mut attempts = 0u64;
    let box_volume = size[0] * size[1] * size[2];
    let mut placed_volume = 0.0;

    for &s in &order {
        let r = 0.5 * params.species[s].diameter_nm;
        let z_span = (size[2] - 2.0 * r).max(0.0);
        for placed in 0..counts[s] {
            let mut fails = 0u64;
            loop {
                let c = [
                    draw_periodic(&mut rng, size[0]),
                    draw_periodic(&mut rng, size[1]),
                    r + rng.gen::<f64>() * z_span,
                ];
                attempts += 1;
                if !cells.overlaps(&c, r) {
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
                    break;
                }
                fails += 1;
                if fails >= params.max_attempts_per_particle {
                    let target: f64 = params.species.iter().map(|sp| sp.volume_fraction).sum();
                    return Err(GeometryError::NotReached {
                        species: s,
                        placed,
                        wanted: counts[s],
                        target,
                        reached: placed_volume / box_volume,
                        attempts,
                    });
                }
            }
        }
    }
    Ok((particles, attempts))
}
