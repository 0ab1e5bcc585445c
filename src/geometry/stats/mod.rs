//! Statistics of a packed fragment, computed from the particles alone (so
//! they check the packers rather than repeat what the packers believe):
//! exact PVC, worst overlap, order parameter, density profile across the
//! thickness, pair correlation of the particle centres and cluster sizes.
//!
//! Choices:
//! - A particle's volume is the exact volume of the union of its spheres
//!   when their centres are collinear (every shape of [`super::Shape`]):
//!   [`union_volume`](super::union_volume) on the offsets along the axis. For a hand-built
//!   non-collinear cluster it is the sum of the sphere volumes minus the
//!   pairwise lenses (exact when no three spheres share a point).
//! - PVC = grain volume / (Lx Ly H), also with surface relief (grains partly
//!   above `z = 0` count fully: PVC measures pigment per area of layer).
//! - Density profile: volume fraction of the grains in `profile_bins` equal
//!   z bins over `[z_top, H]`, `z_top = min(0, highest grain point)`. Exact
//!   for one-sphere particles (spherical-cap formula). For clusters the
//!   union is cut by planes normal to the axis where the dominant sphere
//!   changes (the same breakpoints as [`union_volume`](super::union_volume)); each cross-section
//!   is a disc whose area per z bin is a difference of circular-segment
//!   areas, integrated along the axis by the midpoint rule with steps of at
//!   most 1/8 bin and 1/16 sphere radius (relative error ~1e-4).
//! - Pair correlation of particle centres (the midpoint of the first and
//!   last sphere), nearest periodic image in x and y. The slab walls are
//!   corrected for by normalising with the pair count of uniformly random
//!   points in the same slab: the centres' z spread `W` (observed) gives a
//!   separation density `(1 − |Δz|/W)/(A W)`, so a shell of radius `r`
//!   holds `4πr² f(r) dr / (A W)` per pair, `f = 1 − r/(2W)` for `r ≤ W`
//!   and `W/(2r)` beyond (integrated exactly over each bin). Layering at the
//!   walls is not removed: it is part of the structure.
//! - Clusters: connected components of particles whose spheres come closer
//!   than the contact gap, `contact_gap` × the smallest sphere radius.
//!
//! The parallel parts (profile) sum per fixed chunk of particles and then in
//! chunk order, so results do not depend on the thread count.

mod volume;

use super::cells::CellList;
use super::periodic::dist2;
use super::shapes::order_parameter;
use super::{min_gap_nm, Geometry, Sphere};
use rayon::prelude::*;
use std::f64::consts::PI;
use volume::{add_profile, frame, particle_volume, Frame};

/// Particles per parallel work unit of the profile.
const CHUNK: usize = 1024;

/// Resolution of the statistics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StatsParams {
    /// z bins of the density profile (≥ 1; default 50).
    pub profile_bins: usize,
    /// g(r) bin width in mean effective diameters (> 0; default 0.02).
    pub rdf_bin: f64,
    /// g(r) range in mean effective diameters (> 0; default 3).
    pub rdf_range: f64,
    /// Contact gap of the cluster analysis in units of the smallest sphere
    /// radius (≥ 0; default 0.05).
    pub contact_gap: f64,
}

impl Default for StatsParams {
    fn default() -> Self {
        StatsParams {
            profile_bins: 50,
            rdf_bin: 0.02,
            rdf_range: 3.0,
            contact_gap: 0.05,
        }
    }
}

/// Statistics of one fragment (see the module docs for definitions).
#[derive(Debug, Clone, PartialEq)]
pub struct Statistics {
    /// Particles per species.
    pub count: Vec<usize>,
    /// Exact grain volume per species, nm³.
    pub volume_nm3: Vec<f64>,
    /// Grain volume / (Lx Ly H) per species.
    pub pvc: Vec<f64>,
    /// Sum of [`Statistics::pvc`].
    pub pvc_total: f64,
    /// Smallest surface gap between spheres of different particles
    /// (negative: overlap), nm; `+inf` with fewer than two particles.
    pub min_gap_nm: f64,
    /// `max(0, −min_gap_nm)`, nm.
    pub worst_overlap_nm: f64,
    /// `S = <P2(cos θ)>` over particles of more than one sphere.
    pub order_parameter: Option<f64>,
    /// Number-mean effective diameter (of the equal-volume sphere), nm.
    pub mean_diameter_nm: f64,
    /// How far the highest grain point lies above `z = 0` (≥ 0), nm.
    pub protrusion_nm: f64,
    /// How far the lowest grain point lies below `z = H` (≥ 0), nm.
    pub bottom_excess_nm: f64,
    /// Bin edges of the profile (`profile_bins + 1` values), nm.
    pub profile_z_nm: Vec<f64>,
    /// Grain volume fraction per z bin.
    pub profile_fraction: Vec<f64>,
    /// Centres of the g(r) bins, nm.
    pub rdf_r_nm: Vec<f64>,
    /// Pair correlation of the particle centres per bin.
    pub rdf: Vec<f64>,
    /// Width `W` of the slab of centres used to normalise g(r), nm.
    pub rdf_slab_nm: f64,
    /// Contact gap of the cluster analysis, nm.
    pub contact_gap_nm: f64,
    /// Size of every cluster, largest first.
    pub cluster_sizes: Vec<usize>,
}

impl Statistics {
    /// Mean cluster size over clusters.
    pub fn cluster_mean(&self) -> f64 {
        let n: usize = self.cluster_sizes.iter().sum();
        if self.cluster_sizes.is_empty() {
            0.0
        } else {
            n as f64 / self.cluster_sizes.len() as f64
        }
    }

    /// Mean size of the cluster a particle belongs to (`Σ s² / Σ s`).
    pub fn cluster_weighted_mean(&self) -> f64 {
        let n: usize = self.cluster_sizes.iter().sum();
        let s2: f64 = self.cluster_sizes.iter().map(|&s| (s * s) as f64).sum();
        if n == 0 {
            0.0
        } else {
            s2 / n as f64
        }
    }

    /// Contact value `g(σ+)`: the straight line through the g(r) bins whose
    /// centres lie in `(σ, σ + width]` (least squares), evaluated at `σ`.
    /// `None` with fewer than two such bins.
    pub fn contact_value(&self, sigma_nm: f64, width_nm: f64) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self
            .rdf_r_nm
            .iter()
            .zip(&self.rdf)
            .filter(|(&r, _)| r > sigma_nm && r <= sigma_nm + width_nm)
            .map(|(&r, &g)| (r - sigma_nm, g))
            .collect();
        if pts.len() < 2 {
            return None;
        }
        let n = pts.len() as f64;
        let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
        let (mx, my) = (sx / n, sy / n);
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        Some(my - sxy / sxx * mx)
    }

    /// Human-readable summary, one fact per line.
    pub fn lines(&self) -> Vec<String> {
        let mut l = vec![format!(
            "PVC {:.4} (exact union volumes); {} particles, mean diameter {:.1} nm",
            self.pvc_total,
            self.count.iter().sum::<usize>(),
            self.mean_diameter_nm
        )];
        l.push(format!(
            "worst overlap {:.3} nm; min gap {:.3} nm",
            self.worst_overlap_nm, self.min_gap_nm
        ));
        if let Some(s) = self.order_parameter {
            l.push(format!("order parameter S = {s:.3}"));
        }
        if self.protrusion_nm > 0.0 {
            l.push(format!(
                "grains protrude {:.1} nm above the binder surface",
                self.protrusion_nm
            ));
        }
        l.push(format!(
            "clusters (gap < {:.2} nm): {}, mean size {:.2}, particle-weighted {:.2}, largest {}",
            self.contact_gap_nm,
            self.cluster_sizes.len(),
            self.cluster_mean(),
            self.cluster_weighted_mean(),
            self.cluster_sizes.first().copied().unwrap_or(0)
        ));
        l
    }
}

/// `∫ 4π r² f(r) dr` from 0 to `r` with the slab factor `f` of the module
/// docs (`w` the slab width).
fn shell_integral(r: f64, w: f64) -> f64 {
    if r <= w {
        4.0 * PI * (r * r * r / 3.0 - r * r * r * r / (8.0 * w))
    } else {
        4.0 * PI * (w * w * w / 3.0 - w * w * w / 8.0) + PI * w * (r * r - w * w)
    }
}

/// Union–find root with path halving.
fn root(parent: &mut [u32], mut i: usize) -> usize {
    while parent[i] as usize != i {
        parent[i] = parent[parent[i] as usize];
        i = parent[i] as usize;
    }
    i
}

/// Statistics of `g` (see the module docs).
pub fn analyse(g: &Geometry, params: &StatsParams) -> Statistics {
    let size = g.size_nm;
    let [lx, ly, h] = size;
    let n_species = g
        .particles
        .iter()
        .map(|p| p.species + 1)
        .max()
        .unwrap_or(0)
        .max(g.stats.count.len());
    let frames: Vec<Option<Frame>> = g.particles.par_iter().map(|p| frame(size, p)).collect();
    let volumes: Vec<f64> = frames
        .par_iter()
        .map(|f| f.as_ref().map_or(0.0, particle_volume))
        .collect();
    let mut count = vec![0usize; n_species];
    let mut volume_nm3 = vec![0.0; n_species];
    for (p, v) in g.particles.iter().zip(&volumes) {
        count[p.species] += 1;
        volume_nm3[p.species] += v;
    }
    let box_volume = lx * ly * h;
    let pvc: Vec<f64> = volume_nm3.iter().map(|v| v / box_volume).collect();
    let n = g.particles.len();
    let mean_diameter_nm = if n == 0 {
        0.0
    } else {
        volumes.iter().map(|v| (6.0 * v / PI).cbrt()).sum::<f64>() / n as f64
    };
    let spheres = || g.particles.iter().flat_map(|p| p.spheres.iter());
    let top = spheres()
        .map(|s| s.center[2] - s.radius)
        .fold(0.0, f64::min);
    let bottom = spheres().map(|s| s.center[2] + s.radius).fold(h, f64::max);
    let min_gap = min_gap_nm(size, &g.particles);
    let axes: Vec<[f64; 3]> = frames
        .iter()
        .flatten()
        .filter(|f| f.spheres.len() > 1)
        .filter_map(|f| f.axis)
        .collect();

    // Density profile over [top, H].
    let nb = params.profile_bins.max(1);
    let z0 = top;
    let dz = (h - z0) / nb as f64;
    let partial: Vec<Vec<f64>> = frames
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut out = vec![0.0; nb];
            for f in chunk.iter().flatten() {
                add_profile(f, z0, dz, &mut out);
            }
            out
        })
        .collect();
    let mut profile = vec![0.0; nb];
    for p in &partial {
        for (a, b) in profile.iter_mut().zip(p) {
            *a += b;
        }
    }
    let slab = lx * ly * dz;
    profile.iter_mut().for_each(|v| *v /= slab);
    let profile_z_nm = (0..=nb).map(|k| z0 + k as f64 * dz).collect();

    // Pair correlation of the centres.
    let centers: Vec<[f64; 3]> = frames
        .iter()
        .flatten()
        .map(|f| {
            let a = f.axis.unwrap_or([0.0; 3]);
            let (s0, s1) = (f.spheres[0].0, f.spheres[f.spheres.len() - 1].0);
            let t = 0.5 * (s0 + s1);
            [
                (f.origin[0] + t * a[0]).rem_euclid(lx),
                (f.origin[1] + t * a[1]).rem_euclid(ly),
                f.origin[2] + t * a[2],
            ]
        })
        .collect();
    let bin_w = params.rdf_bin.max(1e-6) * mean_diameter_nm;
    let rcut = params.rdf_range.max(1e-6) * mean_diameter_nm;
    let n_bins = if bin_w > 0.0 {
        (rcut / bin_w).round().max(1.0) as usize
    } else {
        0
    };
    let zmin = centers.iter().map(|c| c[2]).fold(f64::INFINITY, f64::min);
    let zmax = centers
        .iter()
        .map(|c| c[2])
        .fold(f64::NEG_INFINITY, f64::max);
    let w = (zmax - zmin).max(0.0);
    let mut hist = vec![0u64; n_bins];
    if n_bins > 0 && centers.len() > 1 {
        let mut cells = CellList::new(size, rcut, centers.len());
        for (i, c) in centers.iter().enumerate() {
            cells.insert(
                Sphere {
                    center: *c,
                    radius: 0.0,
                },
                i as u32,
            );
        }
        let r2max = rcut * rcut;
        for (i, c) in centers.iter().enumerate() {
            cells.any_near(c, 1, |_, s, owner| {
                if owner as usize > i {
                    let d2 = dist2(c, &s.center, &size);
                    if d2 < r2max {
                        let k = (d2.sqrt() / bin_w) as usize;
                        if k < n_bins {
                            hist[k] += 1;
                        }
                    }
                }
                false
            });
        }
    }
    let pairs = {
        let m = centers.len() as f64;
        0.5 * m * (m - 1.0)
    };
    let area = lx * ly;
    let rdf_r_nm: Vec<f64> = (0..n_bins).map(|k| (k as f64 + 0.5) * bin_w).collect();
    let rdf = (0..n_bins)
        .map(|k| {
            let (r1, r2) = (k as f64 * bin_w, (k + 1) as f64 * bin_w);
            let expected = if w > 1e-9 * h {
                pairs * (shell_integral(r2, w) - shell_integral(r1, w)) / (area * w)
            } else {
                pairs * PI * (r2 * r2 - r1 * r1) / area
            };
            if expected > 0.0 {
                hist[k] as f64 / expected
            } else {
                0.0
            }
        })
        .collect();

    // Clusters.
    let r_min = spheres().map(|s| s.radius).fold(f64::INFINITY, f64::min);
    let r_max = spheres().map(|s| s.radius).fold(0.0, f64::max);
    let contact_gap_nm = if r_min.is_finite() {
        params.contact_gap.max(0.0) * r_min
    } else {
        0.0
    };
    let mut parent: Vec<u32> = (0..n as u32).collect();
    if n > 1 {
        let total: usize = g.particles.iter().map(|p| p.spheres.len()).sum();
        let mut cells = CellList::new(
            size,
            (2.0 * r_max + contact_gap_nm).max(f64::MIN_POSITIVE),
            total,
        );
        for (i, p) in g.particles.iter().enumerate() {
            for s in &p.spheres {
                cells.insert(*s, i as u32);
            }
        }
        let mut links: Vec<usize> = Vec::new();
        for (i, p) in g.particles.iter().enumerate() {
            for a in &p.spheres {
                links.clear();
                cells.any_near(&a.center, 1, |_, b, owner| {
                    let o = owner as usize;
                    if o > i {
                        let reach = a.radius + b.radius + contact_gap_nm;
                        if dist2(&a.center, &b.center, &size) < reach * reach {
                            links.push(o);
                        }
                    }
                    false
                });
                for &o in &links {
                    let (ra, rb) = (root(&mut parent, i), root(&mut parent, o));
                    if ra != rb {
                        parent[ra.max(rb)] = ra.min(rb) as u32;
                    }
                }
            }
        }
    }
    let mut sizes = vec![0usize; n];
    for i in 0..n {
        let r = root(&mut parent, i);
        sizes[r] += 1;
    }
    let mut cluster_sizes: Vec<usize> = sizes.into_iter().filter(|&s| s > 0).collect();
    cluster_sizes.sort_unstable_by(|a, b| b.cmp(a));

    Statistics {
        count,
        pvc_total: pvc.iter().sum(),
        volume_nm3,
        pvc,
        min_gap_nm: min_gap,
        worst_overlap_nm: (-min_gap).max(0.0),
        order_parameter: order_parameter(&axes),
        mean_diameter_nm,
        protrusion_nm: -top,
        bottom_excess_nm: bottom - h,
        profile_z_nm,
        profile_fraction: profile,
        rdf_r_nm,
        rdf,
        rdf_slab_nm: w,
        contact_gap_nm,
        cluster_sizes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_integral_is_continuous_and_matches_bulk_for_thick_slabs() {
        let w = 10.0;
        let below = shell_integral(w * (1.0 - 1e-12), w);
        let above = shell_integral(w * (1.0 + 1e-12), w);
        assert!((below - above).abs() < 1e-9 * below);
        // Small r: f ≈ 1, the bulk shell.
        let r = 1e-3;
        assert!((shell_integral(r, 1e6) / (4.0 / 3.0 * PI * r * r * r) - 1.0).abs() < 1e-6);
    }
}
