//! Raster — the fragment on a uniform grid (METHOD §3).
//!
//! Owns the volume fraction of every species in every voxel; the permittivity
//! for a wavelength is then a per-voxel linear mix ([`Raster::epsilon_into`]),
//! so the geometry is rasterised once for all wavelengths.
//!
//! Grid: `nx × ny × nz` voxels spanning the fragment; voxel `(ix, iy, iz)`
//! covers `[ix·dx, (ix+1)·dx) × [iy·dy, (iy+1)·dy) × [z₀ + iz·dz,
//! z₀ + (iz+1)·dz)` with `dz = size_nm[2]/nz`. Arrays are `(nz, ny, nx)`, so
//! every x–y slice is contiguous (the solver FFTs those).
//!
//! Surface relief: light comes from `z < 0` and grains may protrude through
//! the binder surface `z = 0`. A grid may then be taller than the layer:
//! `size_nm[2] = H + k·dz` for a whole number `k` of cells, which lie above
//! the binder (`z₀ = −k·dz`; without relief `k = 0`, `z₀ = 0`).
//! [`Grid::covering_relief`] adds the cells a geometry needs. The binder
//! surface stays flat at `z = 0`: above it, whatever is not grain is vacuum
//! ([`Raster::top_cells`], used by [`Raster::epsilon_into`]). (A binder
//! film wetting the protruding grains would need a model of its meniscus;
//! the flat surface is the simplest choice and keeps the layer's binder
//! volume exact.) The solver needs no change: it sees the whole grid as
//! binder background plus a contrast, which is `1 − ε_binder` in the vacuum
//! voxels; its reference plane `z = 0` then lies `k·dz` above the binder
//! surface, which shifts reflection phases only, not intensities.
//!
//! Volume fraction, not a point sample: for each particle and each voxel of
//! its bounding box (wrapped periodically in x and y) the voxel counts 1 when it
//! lies entirely inside one of the particle's spheres, 0 when it lies entirely
//! outside all of them (box–sphere distance test), and otherwise the share of
//! `s³` midpoint sub-samples inside the union of the particle's spheres. The
//! sub-samples along each x line are counted analytically from the chord of
//! every sphere (same result as testing each point, O(s²) instead of O(s³)).
//! Contributions add up per species; where overlapping particles would make
//! the voxel's total exceed 1, all species are scaled down so the total is 1.
//!
//! Parallel over z-slices: every slice adds its particles' contributions in
//! particle order, so the result is bit-identical for any thread count.
//! Particles are assumed narrower than the lateral period (the packer ensures
//! half of it); parts outside the grid (`z₀ ≤ z ≤ H`) are not rasterised.

pub mod anisotropy;
pub mod structure;
pub mod surface;

pub use anisotropy::{Anisotropy, GrainShare, Normal, SurfaceNormals};

use crate::geometry::{axis_from_uniforms, particle_axis, Geometry, Orientation, Particle, Sphere};
use ndarray::{Array2, Array3, ArrayViewMut2, Axis};
use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_xoshiro::SplitMix64;
use rayon::prelude::*;

/// Largest supported supersampling factor per axis (one x line of sub-samples
/// is a 64-bit mask).
pub const MAX_SUPERSAMPLE: usize = 64;

/// Uniform grid over the fragment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub nx: usize,
    pub ny: usize,
    pub nz: usize,
    /// `[Lx, Ly, Z]`, nm: the geometry's fragment, with `Z = H` or, with
    /// relief cells above the binder, `Z = H + k·Z/nz` (module docs).
    pub size_nm: [f64; 3],
}

/// A grid that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum RasterError {
    #[error("invalid grid: {0}")]
    Invalid(String),
}

impl Grid {
    /// A checked grid: every count ≥ 1, every size finite and > 0.
    pub fn new(nx: usize, ny: usize, nz: usize, size_nm: [f64; 3]) -> Result<Grid, RasterError> {
        let g = Grid {
            nx,
            ny,
            nz,
            size_nm,
        };
        g.check()?;
        Ok(g)
    }

    /// Checks the counts (≥ 1) and sizes (finite, > 0).
    pub fn check(&self) -> Result<(), RasterError> {
        for (name, n) in [("nx", self.nx), ("ny", self.ny), ("nz", self.nz)] {
            if n == 0 {
                return Err(RasterError::Invalid(format!("{name} = 0; must be ≥ 1")));
            }
        }
        if self
            .nx
            .checked_mul(self.ny)
            .and_then(|v| v.checked_mul(self.nz))
            .is_none()
        {
            return Err(RasterError::Invalid("nx·ny·nz overflows".into()));
        }
        for (name, v) in ["Lx", "Ly", "H"].iter().zip(self.size_nm) {
            if !(v.is_finite() && v > 0.0) {
                return Err(RasterError::Invalid(format!(
                    "fragment size {name} = {v} nm; must be finite and > 0"
                )));
            }
        }
        Ok(())
    }

    /// Voxel edge lengths `[dx, dy, dz]`, nm.
    pub fn cell_nm(&self) -> [f64; 3] {
        [
            self.size_nm[0] / self.nx as f64,
            self.size_nm[1] / self.ny as f64,
            self.size_nm[2] / self.nz as f64,
        ]
    }

    /// Number of voxels.
    pub fn voxels(&self) -> usize {
        self.nx * self.ny * self.nz
    }

    /// Volume of one voxel, nm³.
    pub fn voxel_volume_nm3(&self) -> f64 {
        let c = self.cell_nm();
        c[0] * c[1] * c[2]
    }

    /// This grid (over the binder layer `0 ≤ z ≤ H`) extended upwards by
    /// the fewest whole cells of the same `dz` that reach `top_nm` above
    /// `z = 0` (`top_nm ≤ 0` or not finite: the grid as is). A relative
    /// 1e-9 of slack keeps a height that lands on a cell face from adding a
    /// cell.
    pub fn with_top_nm(&self, top_nm: f64) -> Grid {
        let dz = self.size_nm[2] / self.nz as f64;
        let k = if top_nm.is_finite() && top_nm > 0.0 {
            (top_nm / dz * (1.0 - 1e-9)).ceil() as usize
        } else {
            0
        };
        Grid {
            nz: self.nz + k,
            size_nm: [
                self.size_nm[0],
                self.size_nm[1],
                self.size_nm[2] + k as f64 * dz,
            ],
            ..*self
        }
    }

    /// [`Grid::with_top_nm`] for the highest grain point of `geometry`
    /// above `z = 0` (none without relief: the grid as is).
    pub fn covering_relief(&self, geometry: &Geometry) -> Grid {
        let top = geometry
            .particles
            .iter()
            .flat_map(|p| &p.spheres)
            .map(|s| s.radius - s.center[2])
            .filter(|t| t.is_finite())
            .fold(0.0, f64::max);
        self.with_top_nm(top)
    }
}

/// Volume fraction of each species in each voxel, arrays of shape
/// `(nz, ny, nx)`.
#[derive(Debug, Clone)]
pub struct Raster {
    pub grid: Grid,
    pub fractions: Vec<Array3<f64>>,
    /// Top z-slices lying above the plane `z = 0` (0 without relief or a
    /// surface reaching above it).
    pub top_cells: usize,
    /// The binder surface's depth below `z = 0` per column, `(ny, nx)`
    /// ([`surface`]); None: the plane `z = 0`, the top cells vacuum.
    pub surface_nm: Option<Array2<f64>>,
    /// The grain surface's normal in every voxel it cuts ([`anisotropy`]),
    /// one list per z-slice; empty for an explicit structure.
    pub normals: SurfaceNormals,
    /// Per z-slice, each kept species' particles' shares of the voxels with
    /// the particle's crystal axis, sorted by voxel
    /// ([`rasterize_keeping_axes`]); empty otherwise.
    pub crystal: Vec<Vec<GrainShare>>,
}

/// A particle ready for rasterising: its spheres unwrapped next to the first
/// one, and their bounding box.
struct Prepared {
    species: usize,
    first: usize,
    len: usize,
    lo: [f64; 3],
    hi: [f64; 3],
    /// The crystal axis ([`crystal_axis`]).
    axis: [f64; 3],
}

/// A particle's crystal axis: along a cluster's long axis
/// ([`particle_axis`]: first to last sphere; needles and rods grow along
/// their c axis), for a single sphere a direction uniform on the sphere
/// ([`axis_from_uniforms`]) drawn from a seed of the particle's index and
/// centre (fixed by the geometry, the same for any thread count).
fn crystal_axis(geometry: &Geometry, index: usize, p: &Particle) -> [f64; 3] {
    particle_axis(geometry, p).unwrap_or_else(|| {
        let seed = p.spheres.first().map_or(0, |s| {
            s.center
                .iter()
                .fold(index as u64, |h, c| h.rotate_left(21) ^ c.to_bits())
        });
        let mut rng = SplitMix64::seed_from_u64(seed);
        axis_from_uniforms(Orientation::Random, rng.gen(), rng.gen())
    })
}

fn prepare(geometry: &Geometry, size: [f64; 3]) -> (Vec<Prepared>, Vec<Sphere>) {
    let mut preps = Vec::with_capacity(geometry.particles.len());
    let mut spheres = Vec::new();
    for p in &geometry.particles {
        let Some(s0) = p.spheres.first() else {
            continue;
        };
        let finite = p
            .spheres
            .iter()
            .all(|s| s.center.iter().all(|c| c.is_finite()) && s.radius.is_finite());
        if !finite {
            continue;
        }
        let first = spheres.len();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for s in &p.spheres {
            let mut c = s.center;
            for a in 0..2 {
                let d = c[a] - s0.center[a];
                c[a] = s0.center[a] + d - size[a] * (d / size[a]).round();
            }
            let r = s.radius.max(0.0);
            for a in 0..3 {
                lo[a] = lo[a].min(c[a] - r);
                hi[a] = hi[a].max(c[a] + r);
            }
            spheres.push(Sphere {
                center: c,
                radius: r,
            });
        }
        preps.push(Prepared {
            species: p.species,
            first,
            len: p.spheres.len(),
            lo,
            hi,
            axis: crystal_axis(geometry, preps.len(), p),
        });
    }
    (preps, spheres)
}

/// Inclusive voxel range `[floor(lo/d), floor(hi/d)]`, at most `n` long.
fn voxel_range(lo: f64, hi: f64, d: f64, n: usize) -> (i64, i64) {
    let a = (lo / d).floor() as i64;
    let b = ((hi / d).floor() as i64).max(a);
    (a, b.min(a.saturating_add(n as i64 - 1)))
}

/// `floor` without a library call (exact for |x| < 2⁶³; callers clamp).
#[inline]
fn floor_fast(x: f64) -> f64 {
    let t = x as i64 as f64;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

/// `ceil` without a library call (exact for |x| < 2⁶³; callers clamp).
#[inline]
fn ceil_fast(x: f64) -> f64 {
    let t = x as i64 as f64;
    if t < x {
        t + 1.0
    } else {
        t
    }
}

/// Sub-sample indices `k ∈ [0, s)` with `|x0 + (k+½)h − c| < w`, as a bit mask.
#[inline]
fn chord_mask(c: f64, w: f64, x0: f64, h: f64, s: usize) -> u64 {
    let a = floor_fast((c - w - x0) / h - 0.5) + 1.0;
    let b = ceil_fast((c + w - x0) / h - 0.5) - 1.0;
    let kmin = a.clamp(0.0, s as f64) as usize;
    let kmax = b.clamp(-1.0, s as f64 - 1.0);
    if kmax < kmin as f64 {
        return 0;
    }
    let kmax = kmax as usize;
    let width = kmax - kmin + 1;
    let ones = if width >= 64 {
        u64::MAX
    } else {
        (1u64 << width) - 1
    };
    ones << kmin
}

/// Volume fraction of the box `[lo, hi]` inside the union of `spheres`.
/// `active` is scratch space (indices of spheres cutting the box).
fn voxel_fraction(
    spheres: &[Sphere],
    lo: [f64; 3],
    hi: [f64; 3],
    s: usize,
    active: &mut Vec<usize>,
) -> f64 {
    active.clear();
    for (i, sp) in spheres.iter().enumerate() {
        let r2 = sp.radius * sp.radius;
        let (mut near2, mut far2) = (0.0, 0.0);
        for a in 0..3 {
            let c = sp.center[a];
            let near = if c < lo[a] {
                lo[a] - c
            } else if c > hi[a] {
                c - hi[a]
            } else {
                0.0
            };
            let far = (c - lo[a]).abs().max((hi[a] - c).abs());
            near2 += near * near;
            far2 += far * far;
        }
        if far2 <= r2 {
            return 1.0;
        }
        if near2 < r2 {
            active.push(i);
        }
    }
    if active.is_empty() {
        return 0.0;
    }
    let h = [
        (hi[0] - lo[0]) / s as f64,
        (hi[1] - lo[1]) / s as f64,
        (hi[2] - lo[2]) / s as f64,
    ];
    let mut count = 0u32;
    for kz in 0..s {
        let z = lo[2] + (kz as f64 + 0.5) * h[2];
        for ky in 0..s {
            let y = lo[1] + (ky as f64 + 0.5) * h[1];
            let mut mask = 0u64;
            for &i in active.iter() {
                let sp = &spheres[i];
                let (dy, dz) = (y - sp.center[1], z - sp.center[2]);
                let q = sp.radius * sp.radius - dy * dy - dz * dz;
                if q > 0.0 {
                    mask |= chord_mask(sp.center[0], q.sqrt(), lo[0], h[0], s);
                }
            }
            count += mask.count_ones();
        }
    }
    count as f64 / (s * s * s) as f64
}

/// Rasterises the fragment: volume fraction of each species per voxel, with
/// `supersample` midpoint sub-samples per axis in voxels cut by a surface
/// (clamped to `1..=MAX_SUPERSAMPLE`; 4 or 5 is usual).
///
/// The grid may extend above the binder by whole cells (relief, see the
/// module docs); those become [`Raster::top_cells`].
///
/// # Panics
/// If the grid fails [`Grid::check`], its lateral size differs from the
/// geometry's fragment, or its height is not `H` plus a whole number of
/// cells (relative 1e-9): programming errors, not input.
pub fn rasterize(geometry: &Geometry, grid: &Grid, supersample: usize) -> Raster {
    rasterize_keeping_axes(geometry, grid, supersample, &[])
}

/// [`rasterize`], keeping for the species with `keep[s]` each particle's
/// share of every voxel it touches with its crystal axis
/// ([`Raster::crystal`]; for the tensor of uniaxial crystal grains).
pub fn rasterize_keeping_axes(
    geometry: &Geometry,
    grid: &Grid,
    supersample: usize,
    keep: &[bool],
) -> Raster {
    if let Err(e) = grid.check() {
        panic!("rasterize: {e}");
    }
    let close = |g: f64, r: f64| (g - r).abs() <= 1e-9 * g.abs().max(r.abs());
    let dz = grid.size_nm[2] / grid.nz as f64;
    let extra = (grid.size_nm[2] - geometry.size_nm[2]) / dz;
    let top_cells = extra.round().max(0.0) as usize;
    let same = close(geometry.size_nm[0], grid.size_nm[0])
        && close(geometry.size_nm[1], grid.size_nm[1])
        && close(geometry.size_nm[2] + top_cells as f64 * dz, grid.size_nm[2])
        && top_cells < grid.nz;
    assert!(
        same,
        "rasterize: grid size {:?} nm does not cover the fragment {:?} nm \
         (height must be H plus whole cells)",
        grid.size_nm, geometry.size_nm
    );
    let z_origin = -(top_cells as f64) * dz;
    let s = supersample.clamp(1, MAX_SUPERSAMPLE);
    let n_species = geometry
        .particles
        .iter()
        .map(|p| p.species + 1)
        .max()
        .unwrap_or(0)
        .max(geometry.stats.count.len());
    let (nx, ny, nz) = (grid.nx, grid.ny, grid.nz);
    let [dx, dy, _] = grid.cell_nm();
    let h_total = geometry.size_nm[2];
    let (preps, spheres) = prepare(geometry, grid.size_nm);

    // Particles touching each z-slice, in particle order.
    let mut per_slice: Vec<Vec<u32>> = vec![Vec::new(); nz];
    for (i, p) in preps.iter().enumerate() {
        if p.hi[2] <= z_origin || p.lo[2] >= h_total {
            continue;
        }
        let (z0, z1) = voxel_range(p.lo[2] - z_origin, p.hi[2] - z_origin, dz, nz);
        for iz in z0.max(0)..=z1.min(nz as i64 - 1) {
            per_slice[iz as usize].push(i as u32);
        }
    }

    let mut fractions: Vec<Array3<f64>> = (0..n_species)
        .map(|_| Array3::zeros((nz, ny, nx)))
        .collect();
    let mut slices: Vec<Vec<ArrayViewMut2<f64>>> =
        (0..nz).map(|_| Vec::with_capacity(n_species)).collect();
    for f in fractions.iter_mut() {
        for (iz, v) in f.axis_iter_mut(Axis(0)).enumerate() {
            slices[iz].push(v);
        }
    }

    let normals = slices
        .into_par_iter()
        .zip(per_slice.par_iter())
        .enumerate()
        .map(|(iz, (mut views, members))| {
            let mut active = Vec::new();
            let mut normals = Vec::new();
            let mut shares = Vec::new();
            let z_lo = z_origin + iz as f64 * dz;
            let z_hi = z_lo + dz;
            for &pi in members {
                let p = &preps[pi as usize];
                let sph = &spheres[p.first..p.first + p.len];
                let (x0, x1) = voxel_range(p.lo[0], p.hi[0], dx, nx);
                let (y0, y1) = voxel_range(p.lo[1], p.hi[1], dy, ny);
                let view = &mut views[p.species];
                let kept = keep.get(p.species).copied().unwrap_or(false);
                for iy in y0..=y1 {
                    let wy = iy.rem_euclid(ny as i64) as usize;
                    let y_lo = iy as f64 * dy;
                    for ix in x0..=x1 {
                        let wx = ix.rem_euclid(nx as i64) as usize;
                        let x_lo = ix as f64 * dx;
                        let f = voxel_fraction(
                            sph,
                            [x_lo, y_lo, z_lo],
                            [x_lo + dx, y_lo + dy, z_hi],
                            s,
                            &mut active,
                        );
                        if f > 0.0 {
                            view[[wy, wx]] += f;
                            if kept {
                                shares.push(GrainShare {
                                    index: (wx + nx * wy) as u32,
                                    species: p.species as u32,
                                    share: f,
                                    axis: p.axis,
                                });
                            }
                        }
                        if f > 0.0 && f < 1.0 {
                            let centre = [x_lo + 0.5 * dx, y_lo + 0.5 * dy, z_lo + 0.5 * dz];
                            let n = surface_normal(sph, centre);
                            let w = f * (1.0 - f);
                            normals.push(Normal {
                                index: (wx + nx * wy) as u32,
                                n: [w * n[0], w * n[1], w * n[2]],
                            });
                        }
                    }
                }
            }
            // Shares are scaled as the fractions are below, where overlaps
            // pushed a voxel above 1.
            shares.sort_by_key(|g: &GrainShare| g.index);
            for g in &mut shares {
                let i = g.index as usize;
                let total: f64 = views.iter().map(|v| v[[i / nx, i % nx]]).sum();
                if total > 1.0 {
                    g.share /= total;
                }
            }
            for iy in 0..ny {
                for ix in 0..nx {
                    let total: f64 = views.iter().map(|v| v[[iy, ix]]).sum();
                    if total > 1.0 {
                        for v in views.iter_mut() {
                            v[[iy, ix]] /= total;
                        }
                    }
                }
            }
            (SurfaceNormals::merge_slice(normals), shares)
        })
        .collect::<Vec<_>>();
    let (normals, crystal): (Vec<_>, Vec<_>) = normals.into_iter().unzip();
    let crystal = if crystal.iter().all(Vec::is_empty) {
        Vec::new()
    } else {
        crystal
    };

    Raster {
        grid: *grid,
        fractions,
        top_cells,
        surface_nm: None,
        normals: SurfaceNormals { slices: normals },
        crystal,
    }
}

/// The outward normal of a union of spheres near `x`: that of the sphere
/// whose surface is nearest, `(x − c)/|x − c|` for the sphere with the
/// largest `r − |x − c|` (the union's signed depth); zero at a centre.
fn surface_normal(spheres: &[Sphere], x: [f64; 3]) -> [f64; 3] {
    let mut best = (f64::NEG_INFINITY, [0.0; 3]);
    for sp in spheres {
        let d = [
            x[0] - sp.center[0],
            x[1] - sp.center[1],
            x[2] - sp.center[2],
        ];
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let depth = sp.radius - len;
        if depth > best.0 {
            best = if len > 0.0 {
                (depth, [d[0] / len, d[1] / len, d[2] / len])
            } else {
                (depth, [0.0; 3])
            };
        }
    }
    best.1
}

impl Raster {
    /// `ε = (1 − Σ f_s) ε_bg + Σ f_s ε_s` per voxel, written into `out`
    /// (shape `(nz, ny, nx)`); allocates nothing. The background `ε_bg` is
    /// `eps_binder` below the binder surface and vacuum (1) above it (the
    /// [`Raster::top_cells`] slices above the plane `z = 0`, or the surface
    /// map, which mixes the two in the voxel it cuts). Evaluated left to right as `ε_bg·(1 − F) + ε_0·f_0 +
    /// ε_1·f_1 + …` with `F = f_0 + f_1 + …`.
    ///
    /// # Panics
    /// If `eps_species` does not have one entry per species or `out` has the
    /// wrong shape (programming errors).
    pub fn epsilon_into(
        &self,
        eps_binder: Complex64,
        eps_species: &[Complex64],
        out: &mut Array3<Complex64>,
    ) {
        assert_eq!(
            eps_species.len(),
            self.fractions.len(),
            "epsilon_into: one permittivity per species"
        );
        let g = &self.grid;
        assert_eq!(
            out.dim(),
            (g.nz, g.ny, g.nx),
            "epsilon_into: output shape must be (nz, ny, nx)"
        );
        let plane = g.nx * g.ny;
        let contiguous = self.fractions.iter().all(|f| f.is_standard_layout());
        match out.as_slice_mut() {
            Some(o) if contiguous && plane > 0 => {
                o.par_chunks_mut(plane).enumerate().for_each(|(iz, chunk)| {
                    let range = iz * plane..(iz + 1) * plane;
                    // The real part holds F until the binder term replaces it.
                    chunk.fill(Complex64::new(0.0, 0.0));
                    for f in &self.fractions {
                        let Some(fs) = f.as_slice() else { continue };
                        for (e, &v) in chunk.iter_mut().zip(&fs[range.clone()]) {
                            e.re += v;
                        }
                    }
                    match &self.surface_nm {
                        None => {
                            let eps_bg = self.background(eps_binder, iz, 1.0);
                            for e in chunk.iter_mut() {
                                *e = eps_bg * (1.0 - e.re);
                            }
                        }
                        Some(s) => {
                            for (e, &depth) in chunk.iter_mut().zip(s.iter()) {
                                *e = self.background(eps_binder, iz, depth) * (1.0 - e.re);
                            }
                        }
                    }
                    for (f, &es) in self.fractions.iter().zip(eps_species) {
                        let Some(fs) = f.as_slice() else { continue };
                        for (e, &v) in chunk.iter_mut().zip(&fs[range.clone()]) {
                            *e += es * v;
                        }
                    }
                });
            }
            _ => {
                for ((iz, iy, ix), e) in out.indexed_iter_mut() {
                    let total: f64 = self.fractions.iter().map(|f| f[[iz, iy, ix]]).sum();
                    let depth = self.surface_nm.as_ref().map_or(1.0, |s| s[[iy, ix]]);
                    *e = self.background(eps_binder, iz, depth) * (1.0 - total);
                    for (f, &es) in self.fractions.iter().zip(eps_species) {
                        *e += es * f[[iz, iy, ix]];
                    }
                }
            }
        }
    }

    /// The tensor part of the permittivity at `eps_binder`, `eps_species`
    /// ([`anisotropy`]), written into `out`, whose allocation is reused:
    /// - with `surfaces`, for every voxel with a surface normal, the term
    ///   `(ε_n − ε_t) n̂ n̂ᵀ` with `ε_t` the voxel's scalar part and `ε_n` the
    ///   harmonic mean of the same shares;
    /// - for the species with `crystals[s] = Some((ε_o, ε_e))` (whose
    ///   `eps_species` entry is the orientation average `(2ε_o + ε_e)/3`)
    ///   and kept axes ([`rasterize_keeping_axes`]), each grain's term
    ///   `f (ε_e − ε_o) ĉĉᵀ`, and `eps` (the grid of
    ///   [`Raster::epsilon_into`]) moved by `f (ε_o − ε̄)` in its voxels.
    ///
    /// Terms are sorted by voxel within each slice. Returns the number of
    /// surface terms and of crystal terms.
    pub fn anisotropy_into(
        &self,
        eps_binder: Complex64,
        eps_species: &[Complex64],
        crystals: &[Option<(Complex64, Complex64)>],
        surfaces: bool,
        eps: &mut Array3<Complex64>,
        out: &mut Anisotropy,
    ) -> (usize, usize) {
        assert_eq!(
            eps_species.len(),
            self.fractions.len(),
            "anisotropy_into: one permittivity per species"
        );
        let (mut surface_terms, mut crystal_terms) = (0, 0);
        let g = &self.grid;
        assert_eq!(
            eps.dim(),
            (g.nz, g.ny, g.nx),
            "anisotropy_into: ε grid shape"
        );
        out.clear(g.nz, (g.ny, g.nx));
        let crystal = |s: usize| crystals.get(s).copied().flatten();
        // The species' permittivity in the surface means: a crystal's ε_o.
        let eps_mean: Vec<Complex64> = eps_species
            .iter()
            .enumerate()
            .map(|(s, &e)| crystal(s).map_or(e, |(o, _)| o))
            .collect();
        let mut slice_terms = Vec::new();
        for iz in 0..g.nz {
            slice_terms.clear();
            if let Some(shares) = self.crystal.get(iz) {
                for sh in shares {
                    let i = sh.index as usize;
                    let (iy, ix) = (i / g.nx, i % g.nx);
                    let s = sh.species as usize;
                    let Some((o, e)) = crystal(s) else { continue };
                    eps[[iz, iy, ix]] += sh.share * (o - eps_species[s]);
                    slice_terms.push(anisotropy::Term {
                        index: sh.index,
                        axis: sh.axis,
                        delta: sh.share * (e - o),
                    });
                    crystal_terms += 1;
                }
            }
            let normals = match self.normals.slices.get(iz) {
                Some(v) if surfaces => &v[..],
                _ => &[][..],
            };
            for nv in normals {
                let i = nv.index as usize;
                let (iy, ix) = (i / g.nx, i % g.nx);
                let depth = self.surface_nm.as_ref().map_or(1.0, |s| s[[iy, ix]]);
                let eps_bg = self.background(eps_binder, iz, depth);
                let shares = self
                    .fractions
                    .iter()
                    .zip(&eps_mean)
                    .map(|(f, &e)| (f[[iz, iy, ix]], e));
                let Some(eps_n) = anisotropy::harmonic_mean(eps_bg, shares) else {
                    continue;
                };
                let eps_t = eps[[iz, iy, ix]];
                let delta = eps_n - eps_t;
                if delta.norm() > 1e-12 * eps_t.norm() {
                    slice_terms.push(anisotropy::Term {
                        index: nv.index,
                        axis: nv.n,
                        delta,
                    });
                    surface_terms += 1;
                }
            }
            slice_terms.sort_by_key(|t| t.index);
            out.terms.extend_from_slice(&slice_terms);
            out.offsets[iz + 1] = out.terms.len();
        }
        (surface_terms, crystal_terms)
    }

    /// Rasterised grain volume per species over the binder layer's volume
    /// (`Lx·Ly·H`, the cells above the binder excluded from the
    /// denominator, included in the numerator): comparable with the PVC.
    /// Without relief, the mean volume fraction over the grid.
    pub fn mean_fractions(&self) -> Vec<f64> {
        let n = self.grid.voxels() - self.top_cells * self.grid.nx * self.grid.ny;
        self.fractions
            .iter()
            .map(|f| if n == 0 { 0.0 } else { f.sum() / n as f64 })
            .collect()
    }

    /// The non-grain permittivity of slice `iz` in a column whose binder
    /// surface lies at `depth` (nm below `z = 0`; without a surface map the
    /// plane, and `depth` is ignored): binder below the surface, vacuum
    /// above, mixed by volume in the voxel the surface cuts.
    #[inline]
    fn background(&self, eps_binder: Complex64, iz: usize, depth: f64) -> Complex64 {
        let one = Complex64::new(1.0, 0.0);
        match self.surface_nm {
            None if iz < self.top_cells => one,
            None => eps_binder,
            Some(_) => {
                let dz = self.grid.cell_nm()[2];
                let z_lo = (iz as f64 - self.top_cells as f64) * dz;
                let b = surface::binder_share(z_lo, dz, depth);
                one + (eps_binder - one) * b
            }
        }
    }

    /// This raster under `k` more slices of vacuum on top (a grid extended
    /// by [`Grid::with_top_nm`] for a surface above `z = 0`).
    pub fn with_top_cells(self, k: usize) -> Raster {
        if k == 0 {
            return self;
        }
        let g = self.grid;
        let grid = Grid {
            nz: g.nz + k,
            size_nm: [
                g.size_nm[0],
                g.size_nm[1],
                g.size_nm[2] * (g.nz + k) as f64 / g.nz as f64,
            ],
            ..g
        };
        let fractions = self
            .fractions
            .into_iter()
            .map(|f| {
                let mut padded = Array3::zeros((g.nz + k, g.ny, g.nx));
                padded.slice_mut(ndarray::s![k.., .., ..]).assign(&f);
                padded
            })
            .collect();
        Raster {
            grid,
            fractions,
            top_cells: self.top_cells + k,
            surface_nm: self.surface_nm,
            crystal: if self.crystal.is_empty() {
                Vec::new()
            } else {
                (0..k).map(|_| Vec::new()).chain(self.crystal).collect()
            },
            normals: SurfaceNormals {
                slices: (0..k)
                    .map(|_| Vec::new())
                    .chain(self.normals.slices)
                    .collect(),
            },
        }
    }

    /// Mean depth of the binder surface below `z = 0`, nm (0 for the plane).
    pub fn mean_surface_depth_nm(&self) -> f64 {
        self.surface_nm
            .as_ref()
            .map_or(0.0, |s| s.mean().unwrap_or(0.0))
    }

    /// Height of the grid above the binder surface, nm.
    pub fn top_nm(&self) -> f64 {
        self.top_cells as f64 * self.grid.cell_nm()[2]
    }
}
