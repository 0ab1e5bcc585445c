//! Raster — an explicit layer: the permittivity grid from
//! simple bodies or from an HDF5 file, instead of generated grains.
//!
//! **Primitives** are rasterised into the same [`Raster`] the grains give
//! (one volume-fraction array per body, so ε(λ) per voxel is the
//! volume-fraction average of [`Raster::epsilon_into`]). Slabs and boxes are
//! exact (products of 1-D interval overlaps); spheres and cylinders are exact
//! for voxels wholly inside or outside (corner distances) and sampled on a
//! [`SAMPLES`]³ lattice in voxels their surface cuts. Bodies are periodic in
//! x and y. Where bodies overlap, a later body replaces earlier ones: in a
//! voxel, earlier fractions are scaled by `1 − f` of the later body (exact
//! unless two bodies share a partly filled voxel).
//!
//! **HDF5**: datasets `eps_re` and `eps_im` of shape (nz, ny, nx) — one ε for
//! every wavelength — or (L, nz, ny, nx) with `wavelengths_nm` (L), which
//! must contain every wavelength of the scene (within 1e-9 nm); index 0 of z
//! is the top of the layer (the lit side), as in the grid of the scene.

use crate::config::{Body, Primitive};
use crate::raster::{Grid, Raster};
use ndarray::{Array3, Array4, Axis};
use num_complex::Complex64;
use std::path::{Path, PathBuf};

/// Sub-samples per voxel edge where a curved surface cuts a voxel.
pub const SAMPLES: usize = 12;

/// Why an explicit structure cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum StructureError {
    #[error("{path}: HDF5 error: {source}")]
    Hdf5 { path: PathBuf, source: hdf5::Error },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
}

/// Overlap length of [a0, a1) with [b0, b1).
fn overlap(a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    (a1.min(b1) - a0.max(b0)).max(0.0)
}

/// Overlap of [a0, a1) with a periodic interval [b0, b1) of period `l`.
fn periodic_overlap(a0: f64, a1: f64, b0: f64, b1: f64, l: f64) -> f64 {
    (-2..=2)
        .map(|k| overlap(a0, a1, b0 + k as f64 * l, b1 + k as f64 * l))
        .sum::<f64>()
        .min(a1 - a0)
}

/// Whether point `p` lies in a curved body, periodic in x and y.
fn inside(body: &Body, p: [f64; 3], size: [f64; 3]) -> bool {
    let wrap = |d: f64, l: f64| d - l * (d / l).round();
    // Offset from the body's centre, nearest periodic image in x and y.
    let offset = |c: [f64; 3]| {
        [
            wrap(p[0] - c[0], size[0]),
            wrap(p[1] - c[1], size[1]),
            p[2] - c[2],
        ]
    };
    match *body {
        Body::Sphere {
            center_nm: c,
            radius_nm: r,
        } => {
            let d = offset(c);
            d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= r * r
        }
        Body::Cylinder {
            center_nm: c,
            radius_nm: r,
            length_nm: len,
            axis,
        } => {
            let d = offset(c);
            let radial2: f64 = (0..3).filter(|&a| a != axis).map(|a| d[a] * d[a]).sum();
            d[axis].abs() <= len / 2.0 && radial2 <= r * r
        }
        Body::Slab { .. } | Body::Box { .. } | Body::Boxes { .. } => false,
    }
}

/// Bounding box of a curved body (may extend beyond the fragment in x, y).
fn bounds(body: &Body) -> ([f64; 3], [f64; 3]) {
    match *body {
        Body::Sphere {
            center_nm: c,
            radius_nm: r,
        } => (
            [c[0] - r, c[1] - r, c[2] - r],
            [c[0] + r, c[1] + r, c[2] + r],
        ),
        Body::Cylinder {
            center_nm: c,
            radius_nm: r,
            length_nm: len,
            axis,
        } => {
            let mut h = [r; 3];
            h[axis] = len / 2.0;
            (
                [c[0] - h[0], c[1] - h[1], c[2] - h[2]],
                [c[0] + h[0], c[1] + h[1], c[2] + h[2]],
            )
        }
        Body::Slab { z_nm } => ([f64::MIN, f64::MIN, z_nm[0]], [f64::MAX, f64::MAX, z_nm[1]]),
        Body::Box { min_nm, max_nm } => (min_nm, max_nm),
        // Rasterised box by box (`body_fractions`).
        Body::Boxes { .. } => ([f64::MIN, f64::MIN, 0.0], [f64::MAX, f64::MAX, 0.0]),
    }
}

/// Volume fraction of voxel `[lo, hi)` inside the box `[min_nm, max_nm]`.
fn box_fraction(
    min_nm: [f64; 3],
    max_nm: [f64; 3],
    lo: [f64; 3],
    hi: [f64; 3],
    size: [f64; 3],
) -> f64 {
    let vol = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    periodic_overlap(lo[0], hi[0], min_nm[0], max_nm[0], size[0])
        * periodic_overlap(lo[1], hi[1], min_nm[1], max_nm[1], size[1])
        * overlap(lo[2], hi[2], min_nm[2], max_nm[2])
        / vol
}

/// Volume fraction of voxel `[lo, hi)` inside `body`.
fn fraction(body: &Body, lo: [f64; 3], hi: [f64; 3], size: [f64; 3]) -> f64 {
    match *body {
        Body::Slab { z_nm } => overlap(lo[2], hi[2], z_nm[0], z_nm[1]) / (hi[2] - lo[2]),
        Body::Box { min_nm, max_nm } => box_fraction(min_nm, max_nm, lo, hi, size),
        Body::Boxes { ref boxes } => boxes
            .iter()
            .map(|b| box_fraction(b[0], b[1], lo, hi, size))
            .sum(),
        _ => {
            let corners: Vec<bool> = (0..8)
                .map(|k| {
                    let p = [
                        if k & 1 == 0 { lo[0] } else { hi[0] },
                        if k & 2 == 0 { lo[1] } else { hi[1] },
                        if k & 4 == 0 { lo[2] } else { hi[2] },
                    ];
                    inside(body, p, size)
                })
                .collect();
            // Convex bodies: all corners inside ⇒ the voxel is inside.
            if corners.iter().all(|&c| c) {
                return 1.0;
            }
            let n = SAMPLES;
            let mut hits = 0usize;
            for i in 0..n {
                for j in 0..n {
                    for k in 0..n {
                        let t = |a: usize, q: usize| {
                            lo[a] + (q as f64 + 0.5) / n as f64 * (hi[a] - lo[a])
                        };
                        if inside(body, [t(0, i), t(1, j), t(2, k)], size) {
                            hits += 1;
                        }
                    }
                }
            }
            hits as f64 / (n * n * n) as f64
        }
    }
}

/// Add the volume fractions of `body` to `f` over the voxels its bounds
/// touch (cells `d`).
fn body_fractions(body: &Body, grid: &Grid, d: [f64; 3], f: &mut Array3<f64>) {
    let (nx, ny, nz) = (grid.nx, grid.ny, grid.nz);
    let size = grid.size_nm;
    let (blo, bhi) = bounds(body);
    let range = |a: usize, n: usize| -> Vec<usize> {
        let l = size[a];
        if a < 2 && (bhi[a] - blo[a] >= l || blo[a] <= f64::MIN / 2.0) {
            return (0..n).collect();
        }
        let i0 = (blo[a] / d[a]).floor() as i64;
        let i1 = (bhi[a] / d[a]).ceil() as i64;
        let mut v: Vec<usize> = (i0..i1)
            .filter_map(|i| {
                if a < 2 {
                    Some(i.rem_euclid(n as i64) as usize)
                } else if i >= 0 && (i as usize) < n {
                    Some(i as usize)
                } else {
                    None
                }
            })
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    let (xs, ys, zs) = (range(0, nx), range(1, ny), range(2, nz));
    for &iz in &zs {
        for &iy in &ys {
            for &ix in &xs {
                let lo = [ix as f64 * d[0], iy as f64 * d[1], iz as f64 * d[2]];
                let hi = [lo[0] + d[0], lo[1] + d[1], lo[2] + d[2]];
                f[[iz, iy, ix]] += fraction(body, lo, hi, size);
            }
        }
    }
}

/// Rasterise primitives on `grid`: one fraction array per primitive.
pub fn rasterize_primitives(primitives: &[Primitive], grid: &Grid) -> Raster {
    let (nx, ny, nz) = (grid.nx, grid.ny, grid.nz);
    let size = grid.size_nm;
    let d = [
        size[0] / nx as f64,
        size[1] / ny as f64,
        size[2] / nz as f64,
    ];
    let mut fractions: Vec<Array3<f64>> = Vec::with_capacity(primitives.len());
    for p in primitives {
        let f = match &p.body {
            // Each box over its own voxels: the boxes are disjoint, so
            // their fractions add.
            Body::Boxes { boxes } => {
                let mut f = Array3::zeros((nz, ny, nx));
                for b in boxes {
                    let one = Body::Box {
                        min_nm: b[0],
                        max_nm: b[1],
                    };
                    body_fractions(&one, grid, d, &mut f);
                }
                f
            }
            body => {
                let mut f = Array3::zeros((nz, ny, nx));
                body_fractions(body, grid, d, &mut f);
                f
            }
        };
        // A later body replaces earlier ones where it lies.
        for ((iz, iy, ix), &v) in f.indexed_iter() {
            if v > 0.0 {
                for prev in fractions.iter_mut() {
                    prev[[iz, iy, ix]] *= 1.0 - v.min(1.0);
                }
            }
        }
        fractions.push(f);
    }
    Raster {
        grid: *grid,
        fractions,
        top_cells: 0,
        surface_nm: None,
        normals: Default::default(),
        crystal: Vec::new(),
    }
}

/// A permittivity grid read from HDF5.
#[derive(Debug, Clone)]
pub struct EpsGrid {
    pub path: PathBuf,
    /// None: one grid for every wavelength.
    pub wavelengths_nm: Option<Vec<f64>>,
    /// (L or 1, nz, ny, nx).
    pub eps: Array4<Complex64>,
}

impl EpsGrid {
    /// Read `eps_re`, `eps_im` (and `wavelengths_nm`) and check the shape
    /// against `grid` and the wavelengths against `wavelengths_nm`.
    pub fn read(
        path: &Path,
        grid: &Grid,
        wavelengths_nm: &[f64],
    ) -> Result<EpsGrid, StructureError> {
        let hdf = |source| StructureError::Hdf5 {
            path: path.to_path_buf(),
            source,
        };
        let invalid = |message: String| StructureError::Invalid {
            path: path.to_path_buf(),
            message,
        };
        let file = crate::config::h5file::open(path).map_err(hdf)?;
        let re: ndarray::ArrayD<f64> = file
            .dataset("eps_re")
            .and_then(|d| d.read_dyn())
            .map_err(hdf)?;
        let im: ndarray::ArrayD<f64> = file
            .dataset("eps_im")
            .and_then(|d| d.read_dyn())
            .map_err(hdf)?;
        if re.shape() != im.shape() {
            return Err(invalid(format!(
                "eps_re {:?} and eps_im {:?} differ in shape",
                re.shape(),
                im.shape()
            )));
        }
        let want = [grid.nz, grid.ny, grid.nx];
        let (lists, re4, im4) = match re.ndim() {
            3 => (None, re.insert_axis(Axis(0)), im.insert_axis(Axis(0))),
            4 => {
                let w: Vec<f64> = file
                    .dataset("wavelengths_nm")
                    .and_then(|d| d.read_raw())
                    .map_err(hdf)?;
                if w.len() != re.shape()[0] {
                    return Err(invalid(format!(
                        "wavelengths_nm has {} values for {} ε grids",
                        w.len(),
                        re.shape()[0]
                    )));
                }
                (Some(w), re, im)
            }
            n => {
                return Err(invalid(format!(
                    "eps_re has {n} dimensions; need 3 (nz, ny, nx) or 4 (L, nz, ny, nx)"
                )))
            }
        };
        if re4.shape()[1..] != want {
            return Err(invalid(format!(
                "ε grid is {:?} (nz, ny, nx) but the scene's grid is {want:?}; set grid.nx/ny/nz to match",
                &re4.shape()[1..]
            )));
        }
        if let Some(w) = &lists {
            for &wl in wavelengths_nm {
                if !w.iter().any(|x| (x - wl).abs() <= 1e-9) {
                    return Err(invalid(format!(
                        "no ε grid for the scene's wavelength {wl} nm"
                    )));
                }
            }
        }
        let mut eps = Array4::zeros((re4.shape()[0], want[0], want[1], want[2]));
        for (e, (r, i)) in eps.iter_mut().zip(re4.iter().zip(im4.iter())) {
            if !r.is_finite() || !i.is_finite() || *i < 0.0 {
                return Err(invalid(format!(
                    "ε = {r} + {i}i: every value must be finite with Im ε ≥ 0 (no gain)"
                )));
            }
            *e = Complex64::new(*r, *i);
        }
        Ok(EpsGrid {
            path: path.to_path_buf(),
            wavelengths_nm: lists,
            eps,
        })
    }

    /// Copy the grid of `wavelength_nm` into `out` (nz, ny, nx).
    pub fn epsilon_into(&self, wavelength_nm: f64, out: &mut Array3<Complex64>) {
        let k = match &self.wavelengths_nm {
            None => 0,
            Some(w) => w
                .iter()
                .position(|x| (x - wavelength_nm).abs() <= 1e-9)
                .unwrap_or(0),
        };
        out.assign(&self.eps.index_axis(Axis(0), k));
    }
}
