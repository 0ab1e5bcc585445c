//! Hard-particle Monte Carlo equilibration (Brownian settling of the grains
//! in the wet ink before it dries).
//!
//! Neither packer samples an equilibrium ensemble: RSA freezes grains where
//! they land, the dynamics packer leaves them where their overlaps vanished.
//! [`equilibrate`] relaxes a packed fragment towards the equilibrium of hard
//! particles at the same density: Metropolis translation moves of whole
//! particles (rigid; axes unchanged, so the order parameter is kept), a move
//! accepted when no sphere of the particle then overlaps a sphere of another
//! particle by more than `allow` (0 for RSA, the packer's tolerance for the
//! dynamics packer, whose packings touch within it) and no sphere leaves the
//! slab (`z − r ≥ −ρ D − allow`, `z + r ≤ H + allow`; `ρ` the relief
//! fraction, `D` the particle's effective diameter). With hard particles
//! every allowed configuration has the same weight, so this is the Metropolis
//! rule exactly.
//!
//! Agglomerates: with seeded cluster groups (`groups`, one id per particle,
//! `u32::MAX` for none), two spheres of mates whose surfaces are within
//! `contact_nm` stay so — a move that would take them apart is rejected
//! (mates stick once in contact, an irreversible rule: the agglomerates are
//! kept, everything else equilibrates), and every sweep also proposes one
//! rigid translation of each agglomerate as a whole. Non-mates that the
//! packer left touching separate, so contact clusters then measure the
//! agglomerates.
//!
//! One sweep proposes one move per particle, in index order, with a
//! displacement uniform in `[−δ, δ]³`; between sweeps `δ` is scaled by 1.1
//! towards an acceptance of one half (`δ` starts at 0.1 and stays within
//! `[0.001, 1]` of the smallest sphere radius). Serial, one RNG stream: the
//! result depends on the seed only, whatever the thread count. Spheres are
//! kept in a periodic (x, y) cell grid with cells at least one sphere
//! diameter wide, so a move costs O(1).

use super::cells::{CellGrid, LinkedCells};
use super::periodic::{near_image, wrap};
use super::shapes::union_volume;
use super::Particle;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Contact gap of sticking mates, in units of the smallest sphere radius
/// (the default contact gap of the cluster statistics).
pub const CONTACT_GAP: f64 = 0.05;
/// Largest number of sweeps [`equilibrate`] accepts (config limit).
pub const MAX_SWEEPS: u64 = 100_000;

/// What [`equilibrate`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct McReport {
    pub sweeps: u64,
    /// Accepted moves / proposed moves over all sweeps.
    pub acceptance: f64,
    /// Displacement bound `δ` at the end, nm.
    pub step_nm: f64,
}

/// Effective diameter of a particle (equal-volume sphere of its union).
fn effective_diameter(size: &[f64; 3], p: &Particle) -> f64 {
    if p.spheres.len() == 1 {
        return 2.0 * p.spheres[0].radius;
    }
    let o = p.spheres[0].center;
    let axial: Vec<(f64, f64)> = p
        .spheres
        .iter()
        .map(|s| {
            let d = [
                near_image(s.center[0] - o[0], size[0]),
                near_image(s.center[1] - o[1], size[1]),
                s.center[2] - o[2],
            ];
            ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(), s.radius)
        })
        .collect();
    (6.0 * union_volume(&axial) / std::f64::consts::PI).cbrt()
}

/// Equilibrates `particles` in the fragment `size` by `sweeps` Monte Carlo
/// sweeps (see the module docs). Particles must start without overlaps
/// beyond `allow_nm` and inside the slab.
pub fn equilibrate(
    size: [f64; 3],
    particles: &mut [Particle],
    groups: &[u32],
    relief_fraction: f64,
    allow_nm: f64,
    sweeps: u64,
    seed: u64,
) -> McReport {
    let contact_nm = CONTACT_GAP
        * particles
            .iter()
            .flat_map(|p| &p.spheres)
            .map(|s| s.radius)
            .fold(f64::INFINITY, f64::min);
    let sticky = groups.len() == particles.len() && groups.iter().any(|&g| g != u32::MAX);
    let n = particles.len();
    if n == 0 || sweeps == 0 {
        return McReport::default();
    }
    let z_min: Vec<f64> = particles
        .iter()
        .map(|p| -relief_fraction * effective_diameter(&size, p) - allow_nm)
        .collect();
    let mut start = Vec::with_capacity(n + 1);
    let mut pos: Vec<[f64; 3]> = Vec::new();
    let mut rad: Vec<f64> = Vec::new();
    let mut owner: Vec<u32> = Vec::new();
    start.push(0usize);
    for (i, p) in particles.iter().enumerate() {
        for s in &p.spheres {
            pos.push(s.center);
            rad.push(s.radius);
            owner.push(i as u32);
        }
        start.push(pos.len());
    }
    let r_max = rad.iter().copied().fold(0.0, f64::max);
    let r_min = rad.iter().copied().fold(f64::INFINITY, f64::min);
    let z_lo = pos
        .iter()
        .zip(&rad)
        .map(|(c, r)| c[2] - r)
        .fold(0.0, f64::min)
        .min(-relief_fraction * 2.0 * r_max);
    // Cells wide enough that every mate in contact with a sphere's old place
    // is found around its trial place (δ ≤ r_min).
    let width = 2.0 * r_max
        + allow_nm.max(0.0)
        + if sticky {
            contact_nm + 2.0 * r_min
        } else {
            0.0
        };
    let span = [size[0], size[1], size[2] - z_lo + allow_nm.max(0.0)];
    let mut cells = LinkedCells::new(CellGrid::shifted(z_lo, span, width, pos.len()), pos.len());
    for c in &pos {
        cells.push(c);
    }

    // Members of every seeded agglomerate of two or more particles.
    let mut agglomerates: Vec<Vec<usize>> = Vec::new();
    if sticky {
        let mut by_group: Vec<(u32, usize)> = groups
            .iter()
            .enumerate()
            .filter(|(_, &g)| g != u32::MAX)
            .map(|(p, &g)| (g, p))
            .collect();
        by_group.sort_unstable();
        for run in by_group.chunk_by(|a, b| a.0 == b.0) {
            if run.len() > 1 {
                agglomerates.push(run.iter().map(|&(_, p)| p).collect());
            }
        }
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x3c6e_f372_fe94_f82b);
    let mut step = 0.1 * r_min;
    let (mut accepted, mut proposed) = (0u64, 0u64);
    let mut trial: Vec<[f64; 3]> = Vec::new();
    let h = size[2];
    for _ in 0..sweeps {
        let mut acc_sweep = 0u64;
        for p in 0..n {
            let dv = [
                step * (2.0 * rng.gen::<f64>() - 1.0),
                step * (2.0 * rng.gen::<f64>() - 1.0),
                step * (2.0 * rng.gen::<f64>() - 1.0),
            ];
            proposed += 1;
            trial.clear();
            let mut ok = true;
            for q in start[p]..start[p + 1] {
                let c = pos[q];
                let t = [
                    wrap(c[0] + dv[0], size[0]),
                    wrap(c[1] + dv[1], size[1]),
                    c[2] + dv[2],
                ];
                if t[2] - rad[q] < z_min[p] || t[2] + rad[q] > h + allow_nm {
                    ok = false;
                    break;
                }
                trial.push(t);
            }
            if ok {
                let g = groups.get(p).copied().unwrap_or(u32::MAX);
                for (k, t) in trial.iter().enumerate() {
                    let r = rad[start[p] + k];
                    let clash = cells.any_near(t, |o| {
                        if owner[o] as usize == p {
                            return false;
                        }
                        let b = pos[o];
                        let dx = near_image(t[0] - b[0], size[0]);
                        let dy = near_image(t[1] - b[1], size[1]);
                        let dz = t[2] - b[2];
                        let reach = r + rad[o] - allow_nm;
                        let d2 = dx * dx + dy * dy + dz * dz;
                        if reach > 0.0 && d2 < reach * reach {
                            return true;
                        }
                        if sticky && g != u32::MAX && groups[owner[o] as usize] == g {
                            let touch = r + rad[o] + contact_nm;
                            let a = pos[start[p] + k];
                            let old = [
                                near_image(a[0] - b[0], size[0]),
                                near_image(a[1] - b[1], size[1]),
                                a[2] - b[2],
                            ];
                            let o2 = old[0] * old[0] + old[1] * old[1] + old[2] * old[2];
                            if o2 <= touch * touch && d2 > touch * touch {
                                return true;
                            }
                        }
                        false
                    });
                    if clash {
                        ok = false;
                        break;
                    }
                }
            }
            if !ok {
                continue;
            }
            acc_sweep += 1;
            for (k, t) in trial.iter().enumerate() {
                let q = start[p] + k;
                pos[q] = *t;
                cells.update(q, t);
            }
        }
        // One rigid move per agglomerate, so that agglomerates left touching
        // by the packer can drift apart.
        for members in &agglomerates {
            let dv = [
                step * (2.0 * rng.gen::<f64>() - 1.0),
                step * (2.0 * rng.gen::<f64>() - 1.0),
                step * (2.0 * rng.gen::<f64>() - 1.0),
            ];
            let g = groups[members[0]];
            trial.clear();
            let mut ok = true;
            'members: for &p in members {
                for q in start[p]..start[p + 1] {
                    let c = pos[q];
                    let t = [
                        wrap(c[0] + dv[0], size[0]),
                        wrap(c[1] + dv[1], size[1]),
                        c[2] + dv[2],
                    ];
                    if t[2] - rad[q] < z_min[p] || t[2] + rad[q] > h + allow_nm {
                        ok = false;
                        break 'members;
                    }
                    let clash = cells.any_near(&t, |o| {
                        if groups[owner[o] as usize] == g {
                            return false;
                        }
                        let b = pos[o];
                        let dx = near_image(t[0] - b[0], size[0]);
                        let dy = near_image(t[1] - b[1], size[1]);
                        let dz = t[2] - b[2];
                        let reach = rad[q] + rad[o] - allow_nm;
                        reach > 0.0 && dx * dx + dy * dy + dz * dz < reach * reach
                    });
                    if clash {
                        ok = false;
                        break 'members;
                    }
                    trial.push(t);
                }
            }
            if !ok {
                continue;
            }
            let mut moved = trial.iter();
            for &p in members {
                for (q, t) in (start[p]..start[p + 1]).zip(&mut moved) {
                    pos[q] = *t;
                    cells.update(q, t);
                }
            }
        }
        accepted += acc_sweep;
        let rate = acc_sweep as f64 / n as f64;
        step = if rate > 0.5 { step * 1.1 } else { step / 1.1 }.clamp(1e-3 * r_min, r_min);
    }
    for (p, part) in particles.iter_mut().enumerate() {
        for (k, s) in part.spheres.iter_mut().enumerate() {
            s.center = pos[start[p] + k];
        }
    }
    McReport {
        sweeps,
        acceptance: accepted as f64 / proposed.max(1) as f64,
        step_nm: step,
    }
}
