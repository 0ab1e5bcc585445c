//! Random sequential addition of spheres (METHOD §2, low PVC).
//!
//! Species are placed one after another by decreasing nominal diameter (ties
//! keep the input order); within a species, grains in the order of their
//! drawn diameters, largest first (a size distribution packs further that
//! way). Each particle's centre is drawn uniformly in
//! `[0,Lx) × [0,Ly) × [r − ρ d, H−r]` (`ρ` the relief fraction, so it never
//! crosses the bottom wall and protrudes through the top by at most `ρ d`)
//! and rejected when it overlaps a placed sphere, nearest periodic image in x
//! and y; touching is allowed.
//!
//! Saturation (Zhang & Torquato 2013, Phys. Rev. E 88, 053312): a particle
//! that fails `max_attempts_per_particle` plain draws in a row switches the
//! packer to sampling only the space not yet known to be covered. The centre
//! region is cut into equal boxes (voxels, side ≤ r/2); a voxel is dropped
//! once one exclusion sphere (radius `r + r_j` around a placed centre)
//! contains it whole. A centre is drawn in a random remaining voxel, at a
//! uniform point of it: uniform over the union of the voxels, which holds
//! all available space, so the sequence is still RSA. A rejected draw tests
//! its voxel for coverage; when `2 × voxels + 64` draws in a row fail, every
//! voxel is halved along each axis and the covered halves dropped. The
//! layer is saturated when no voxel is left; the packing then ends with
//! [`GeometryError::NotReached`] and the exact saturation density. (Voxels
//! below [`MIN_VOXEL`] of the radius, or more than [`MAX_VOXELS`] of them,
//! also end it: available space of that size is below any meaningful
//! resolution.) The voxels are kept for the following grains of the same
//! radius and rebuilt when the radius changes (size distributions).
//!
//! Agglomeration ([`SpeciesOptions::cluster_size`] > 1): a grain that is not
//! the first of its group is first tried next to a random earlier member of
//! the group (centres `(r₁ + r₂)(1 + 1e-9)` apart, random direction), up to
//! [`CLUSTER_TRIES`] times; failing that it is placed as above and starts a
//! new group. One RNG stream (`Xoshiro256PlusPlus`), consumed sequentially:
//! the result depends on the seed only.

use super::cells::CellList;
use super::periodic::{min_image, wrap};
use super::shapes::{axis_from_uniforms, Orientation};
use super::{sphere_volume, GeometryError, PackParams, Particle, SpeciesOptions, Sphere};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Directions tried next to the grain's group before it starts a new one.
pub const CLUSTER_TRIES: usize = 64;
/// Smallest voxel side of the saturation search, in units of the radius.
pub const MIN_VOXEL: f64 = 1e-6;
/// Most voxels the saturation search keeps.
pub const MAX_VOXELS: usize = 1 << 26;

/// The uncovered-space sampler (see the module docs): voxels of the centre
/// region of spheres of radius `r` that may still hold an available centre.
struct Voxels {
    r: f64,
    /// Centre region: `[0, Lx) × [0, Ly) × [z_lo, z_lo + span]`.
    z_lo: f64,
    span: f64,
    /// Voxel sides.
    h: [f64; 3],
    /// Lower corners.
    list: Vec<[f64; 3]>,
    scratch: Vec<[f64; 3]>,
}

/// Whether one placed sphere's exclusion sphere (radius `r + r_j`) contains
/// the whole box `[lo, lo + h]`.
fn covered(cells: &CellList, size: &[f64; 3], lo: &[f64; 3], h: &[f64; 3], r: f64) -> bool {
    let c = [lo[0] + 0.5 * h[0], lo[1] + 0.5 * h[1], lo[2] + 0.5 * h[2]];
    cells.any_near(&c, 1, |_, s, _| {
        let dx = min_image(c[0] - s.center[0], size[0]).abs() + 0.5 * h[0];
        let dy = min_image(c[1] - s.center[1], size[1]).abs() + 0.5 * h[1];
        let dz = (c[2] - s.center[2]).abs() + 0.5 * h[2];
        let e = r + s.radius;
        dx * dx + dy * dy + dz * dz < e * e
    })
}

impl Voxels {
    /// Voxels of side ≤ r/2 over the centre region, covered ones dropped.
    fn build(cells: &CellList, size: &[f64; 3], r: f64, z_lo: f64, span: f64) -> Self {
        let side = 0.5 * r;
        let n = [
            (size[0] / side).ceil().max(1.0) as usize,
            (size[1] / side).ceil().max(1.0) as usize,
            if span > 0.0 {
                (span / side).ceil().max(1.0) as usize
            } else {
                1
            },
        ];
        let h = [
            size[0] / n[0] as f64,
            size[1] / n[1] as f64,
            span / n[2] as f64,
        ];
        let mut list = Vec::new();
        for k in 0..n[2] {
            for j in 0..n[1] {
                for i in 0..n[0] {
                    let lo = [i as f64 * h[0], j as f64 * h[1], z_lo + k as f64 * h[2]];
                    if !covered(cells, size, &lo, &h, r) {
                        list.push(lo);
                    }
                }
            }
        }
        Voxels {
            r,
            z_lo,
            span,
            h,
            list,
            scratch: Vec::new(),
        }
    }

    /// Halves every voxel along each axis (not along z for a flat region)
    /// and drops the covered halves; false when the voxels would become
    /// smaller than [`MIN_VOXEL`] r or too many.
    fn subdivide(&mut self, cells: &CellList, size: &[f64; 3]) -> bool {
        let h = [
            0.5 * self.h[0],
            0.5 * self.h[1],
            if self.span > 0.0 {
                0.5 * self.h[2]
            } else {
                0.0
            },
        ];
        let nz = if self.span > 0.0 { 2 } else { 1 };
        if h[0].max(h[1]).max(h[2]) < MIN_VOXEL * self.r || self.list.len() * 4 * nz > MAX_VOXELS {
            return false;
        }
        self.scratch.clear();
        for v in &self.list {
            for k in 0..nz {
                for j in 0..2 {
                    for i in 0..2 {
                        let lo = [
                            v[0] + i as f64 * h[0],
                            v[1] + j as f64 * h[1],
                            v[2] + k as f64 * h[2],
                        ];
                        if !covered(cells, size, &lo, &h, self.r) {
                            self.scratch.push(lo);
                        }
                    }
                }
            }
        }
        std::mem::swap(&mut self.list, &mut self.scratch);
        self.h = h;
        true
    }

    /// An available centre for a sphere of radius `r` drawn uniformly from
    /// the uncovered space, or `None` when the region is saturated.
    fn place(
        &mut self,
        cells: &CellList,
        size: &[f64; 3],
        rng: &mut Xoshiro256PlusPlus,
        attempts: &mut u64,
    ) -> Option<[f64; 3]> {
        let z_hi = self.z_lo + self.span;
        let mut fails = 0usize;
        loop {
            if self.list.is_empty() {
                return None;
            }
            let k = rng.gen_range(0..self.list.len());
            let v = self.list[k];
            let c = [
                wrap(v[0] + rng.gen::<f64>() * self.h[0], size[0]),
                wrap(v[1] + rng.gen::<f64>() * self.h[1], size[1]),
                (v[2] + rng.gen::<f64>() * self.h[2]).clamp(self.z_lo, z_hi),
            ];
            *attempts += 1;
            if !cells.overlaps(&c, self.r) {
                return Some(c);
            }
            if covered(cells, size, &v, &self.h, self.r) {
                self.list.swap_remove(k);
                continue;
            }
            fails += 1;
            if fails > 2 * self.list.len() + 64 {
                if !self.subdivide(cells, size) {
                    return None;
                }
                fails = 0;
            }
        }
    }
}

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

/// Places every species' spheres (`diameters[s]`); returns the particles in
/// placement order, the seeded group of each (`u32::MAX`: none) and the
/// number of centres drawn.
pub(crate) fn pack(
    params: &PackParams,
    diameters: &[Vec<f64>],
    options: &[SpeciesOptions],
    seed: u64,
) -> Result<(Vec<Particle>, Vec<u32>, u64), GeometryError> {
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
    let mut groups: Vec<u32> = Vec::with_capacity(total);
    let mut attempts = 0u64;
    let box_volume = size[0] * size[1] * size[2];
    let mut placed_volume = 0.0;
    let mut voxels: Option<Voxels> = None;

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
            // Once the saturation search has begun, later grains of the same
            // radius go straight to it.
            let mut fails = if voxels.as_ref().is_some_and(|v| v.r == r && v.z_lo == z_lo) {
                params.max_attempts_per_particle
            } else {
                0
            };
            let c = loop {
                if let Some(c) = center {
                    break c;
                }
                if fails >= params.max_attempts_per_particle {
                    // Saturation search (voxels of this radius, kept while it lasts).
                    if voxels.as_ref().is_some_and(|v| v.r != r || v.z_lo != z_lo) {
                        voxels = None;
                    }
                    let vox =
                        voxels.get_or_insert_with(|| Voxels::build(&cells, &size, r, z_lo, z_span));
                    if let Some(c) = vox.place(&cells, &size, &mut rng, &mut attempts) {
                        break c;
                    }
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
            };
            let sphere = Sphere {
                center: c,
                radius: r,
            };
            cells.insert(sphere, particles.len() as u32);
            groups.push(if group > 1 {
                group_start as u32
            } else {
                u32::MAX
            });
            particles.push(Particle {
                species: s,
                spheres: vec![sphere],
            });
            placed_volume += sphere_volume(r);
        }
    }
    Ok((particles, groups, attempts))
}
