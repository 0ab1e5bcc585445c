//! The tensor part of Maxwell's contrast: per voxel, uniaxial terms
//! `δ â âᵀ` beside the scalar permittivity ([`Anisotropy`]; METHOD §9,
//! "Surface voxels").
//!
//! Every operation of [`System`](super::System) that multiplies by the
//! permittivity has a tensor counterpart here: the contrast source
//! `k0² δ â (â·E)`, the CBS preconditioner's `i δ â (â·x)/ε_s`, the
//! absorption `Im δ |â·E|²` and the bounds of the spectrum that choose the
//! shift. The three components of voxel `(iz, iy, ix)` are rows `iz`,
//! `nz + iz` and `2 nz + iz` of the stacked unknowns. Work is parallel
//! over z-slices, each slice's terms in their stored order, so the result is
//! the same for any thread count; nothing is allocated.

use super::storage::Storage;
use crate::raster::Anisotropy;
use ndarray::{s, Array3, ArrayView3, ArrayViewMut2, Axis};
use num_complex::Complex64 as C64;
use rayon::prelude::*;

/// The three component views `(nz, ny, nx)` of stacked unknowns.
fn split_mut<S>(
    x: &mut Array3<S>,
    nz: usize,
) -> (
    ndarray::ArrayViewMut3<'_, S>,
    ndarray::ArrayViewMut3<'_, S>,
    ndarray::ArrayViewMut3<'_, S>,
) {
    x.multi_slice_mut((
        s![0..nz, .., ..],
        s![nz..2 * nz, .., ..],
        s![2 * nz..3 * nz, .., ..],
    ))
}

/// Run `f(slice, [x, y, z] views of that slice)` over every z-slice in
/// parallel.
fn per_slice<S: Send + Sync>(
    x: &mut Array3<S>,
    nz: usize,
    f: impl Fn(usize, [&mut ArrayViewMut2<S>; 3]) + Sync,
) {
    let (mut a, mut b, mut c) = split_mut(x, nz);
    a.axis_iter_mut(Axis(0))
        .into_par_iter()
        .zip(b.axis_iter_mut(Axis(0)).into_par_iter())
        .zip(c.axis_iter_mut(Axis(0)).into_par_iter())
        .enumerate()
        .for_each(|(iz, ((mut ex, mut ey), mut ez))| f(iz, [&mut ex, &mut ey, &mut ez]));
}

#[inline]
fn at(nx: usize, index: u32) -> [usize; 2] {
    let i = index as usize;
    [i / nx, i % nx]
}

#[inline]
fn project(axis: [f64; 3], v: [C64; 3]) -> C64 {
    v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2]
}

/// `field_v += k2 Σ δ â (â·x_v)` over the terms.
pub fn add_contrast<S: Storage + Sync>(
    a: &Anisotropy,
    k2: f64,
    x: &Array3<S>,
    field: &mut Array3<C64>,
) {
    // The system's arrays are in standard layout (made by `zeros` or
    // `default`): borrowed as they are, rows as contiguous slices.
    let x = x.as_standard_layout();
    let xs = x.as_slice().expect("standard layout");
    per_slice(field, a.nz(), |iz, f| {
        for (c, row) in f.into_iter().enumerate() {
            let row = row.as_slice_mut().expect("contiguous row");
            add_contrast_plane(a, k2, xs, c, iz, row);
        }
    });
}

/// [`add_contrast`] of one row of the stacked unknowns: component `c` of
/// z-slice `iz` (`plane` (ny, nx), flat), from `xs`, the unknowns in
/// standard layout, flat.
pub fn add_contrast_plane<S: Storage>(
    a: &Anisotropy,
    k2: f64,
    xs: &[S],
    c: usize,
    iz: usize,
    plane: &mut [C64],
) {
    let nz = a.nz();
    let (ny, nx) = a.plane;
    let size = ny * nx;
    let row = |c: usize| &xs[(c * nz + iz) * size..(c * nz + iz + 1) * size];
    let (rx, ry, rz) = (row(0), row(1), row(2));
    for t in a.slice(iz) {
        let i = t.index as usize;
        let v = [rx[i].load(), ry[i].load(), rz[i].load()];
        plane[i] += k2 * t.delta * project(t.axis, v) * t.axis[c];
    }
}

/// After the isotropic CBS scaling `x ← γ x` (γ = 1 + i(ε − ε_r)/ε_s per
/// voxel), add the tensor part: `x_v += (i/ε_s) Σ δ â (â·x_v⁰)` with
/// `x_v⁰ = x_v/γ_v` the voxel's value before the scaling (γ never vanishes:
/// `Re γ ≥ 1 − 1/margin`).
pub fn add_precondition<S: Storage + Send + Sync>(
    a: &Anisotropy,
    eps: ArrayView3<C64>,
    er: f64,
    es: f64,
    x: &mut Array3<S>,
) {
    let nz = a.nz();
    let nx = a.plane.1;
    let i_es = C64::i() / es;
    per_slice(x, nz, |iz, f| {
        for terms in a.voxel_terms(iz) {
            // One voxel's terms, all from its values before the update.
            let [iy, ix] = at(nx, terms[0].index);
            let gamma = 1.0 + i_es * (eps[[iz, iy, ix]] - er);
            let v0 = [0, 1, 2].map(|c| f[c][[iy, ix]].load() / gamma);
            let mut add = [C64::new(0.0, 0.0); 3];
            for t in terms {
                let w = i_es * t.delta * project(t.axis, v0);
                for (ac, a) in add.iter_mut().zip(t.axis) {
                    *ac += w * a;
                }
            }
            for c in 0..3 {
                let cur = f[c][[iy, ix]].load();
                f[c][[iy, ix]] = S::store(cur + add[c]);
            }
        }
    });
}

/// `Σ Im δ |â·u_v|²` over the terms (the tensor part of `Σ Im(u* ε u)`),
/// summed per slice in a fixed order.
pub fn absorption<S: Storage>(a: &Anisotropy, u: &Array3<S>) -> f64 {
    let nz = a.nz();
    let nx = a.plane.1;
    let parts: Vec<f64> = (0..nz)
        .into_par_iter()
        .map(|iz| {
            a.slice(iz)
                .iter()
                .map(|t| {
                    let [iy, ix] = at(nx, t.index);
                    let v = [0, 1, 2].map(|c| u[[c * nz + iz, iy, ix]].load());
                    t.delta.im * project(t.axis, v).norm_sqr()
                })
                .sum()
        })
        .collect();
    parts.iter().sum()
}

/// Per voxel with terms, `(ε_v, Σ δ, Σ |δ|)`: its scalar part, the sum of
/// its terms (`ε_v + Σδ` is the largest eigenvalue's sum for one axis) and
/// a bound of the tensor part's norm, in slice order.
pub fn voxels<'a>(
    a: &'a Anisotropy,
    eps: &'a Array3<C64>,
) -> impl Iterator<Item = (C64, C64, f64)> + 'a {
    (0..a.nz()).flat_map(move |iz| slice_voxels(a, eps, iz))
}

/// [`voxels`] of slice `iz` alone.
pub fn slice_voxels<'a>(
    a: &'a Anisotropy,
    eps: &'a Array3<C64>,
    iz: usize,
) -> impl Iterator<Item = (C64, C64, f64)> + 'a {
    let nx = a.plane.1;
    a.voxel_terms(iz).map(move |terms| {
        let [iy, ix] = at(nx, terms[0].index);
        let sum = terms.iter().map(|t| t.delta).sum::<C64>();
        let bound = terms.iter().map(|t| t.delta.norm()).sum::<f64>();
        (eps[[iz, iy, ix]], sum, bound)
    })
}

/// Checks that a tensor part fits a permittivity grid `(nz, ny, nx)` and
/// is passive (`Im δ ≥ −Im ε_v` for each term: `Im(ε_v + δ) ≥ 0`, the
/// tensor's smallest loss for one axis); the error text, or None.
pub fn check(a: &Anisotropy, eps: &Array3<C64>) -> Option<String> {
    let (nz, ny, nx) = eps.dim();
    if a.nz() != nz || a.plane != (ny, nx) || a.offsets.last() != Some(&a.terms.len()) {
        return Some(format!(
            "tensor permittivity of {} slices of {:?} does not match the grid {:?}",
            a.nz(),
            a.plane,
            eps.dim()
        ));
    }
    for iz in 0..nz {
        for t in a.slice(iz) {
            let i = t.index as usize;
            let len2: f64 = t.axis.iter().map(|v| v * v).sum();
            if i >= ny * nx {
                return Some(format!("tensor term at voxel {i} outside the slice"));
            }
            if !(t.delta.re.is_finite() && t.delta.im.is_finite()) || (len2 - 1.0).abs() > 1e-9 {
                return Some("tensor terms must be finite with unit axes".into());
            }
            if (eps[[iz, i / nx, i % nx]] + t.delta).im < -1e-12 {
                return Some("tensor permittivity must be passive".into());
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::anisotropy::Term;

    /// One voxel with two terms; the dense 3 × 3 products by hand.
    #[test]
    fn tensor_operations_match_dense_matrices() {
        let (nz, ny, nx) = (2, 2, 3);
        let eps = Array3::from_shape_fn((nz, ny, nx), |(z, y, x)| {
            C64::new(2.0 + z as f64 + 0.1 * y as f64, 0.05 * x as f64)
        });
        let s = 0.5f64.sqrt();
        let terms = [
            Term {
                index: 4,
                axis: [s, 0.0, s],
                delta: C64::new(-0.7, 0.02),
            },
            Term {
                index: 4,
                axis: [0.0, 1.0, 0.0],
                delta: C64::new(0.3, 0.01),
            },
        ];
        let a = Anisotropy {
            plane: (ny, nx),
            offsets: vec![0, 0, 2],
            terms: terms.to_vec(),
        };
        assert!(check(&a, &eps).is_none());
        let x = Array3::from_shape_fn((3 * nz, ny, nx), |(r, y, xx)| {
            C64::new(r as f64 + 0.5, y as f64 - xx as f64)
        });
        let (iz, iy, ix) = (1, 1, 1);
        let v: Vec<C64> = (0..3).map(|c| x[[c * nz + iz, iy, ix]]).collect();
        let dense = |c: usize, d: usize| -> C64 {
            terms.iter().map(|t| t.delta * t.axis[c] * t.axis[d]).sum()
        };
        let mv: Vec<C64> = (0..3)
            .map(|c| (0..3).map(|d| dense(c, d) * v[d]).sum())
            .collect();
        let mut field = Array3::zeros((3 * nz, ny, nx));
        add_contrast(&a, 2.0, &x, &mut field);
        for c in 0..3 {
            assert!((field[[c * nz + iz, iy, ix]] - 2.0 * mv[c]).norm() < 1e-13);
        }
        let touched = field.iter().filter(|v| v.norm() > 0.0).count();
        assert_eq!(touched, 3);
        // Row by row (the fused application's source): the same values.
        let xs = x.as_slice().unwrap();
        for c in 0..3 {
            for z in 0..nz {
                let mut plane = vec![C64::new(0.0, 0.0); ny * nx];
                add_contrast_plane(&a, 2.0, xs, c, z, &mut plane);
                let row = field.slice(s![c * nz + z, .., ..]);
                assert!(plane.iter().zip(row.iter()).all(|(p, f)| p == f));
            }
        }
        // The preconditioner: γ x + (i/ε_s) Δ x.
        let (er, es) = (3.0, 4.0);
        let mut y = x.clone();
        y.zip_mut_with(
            &Array3::from_shape_fn((3 * nz, ny, nx), |(r, yy, xx)| eps[[r % nz, yy, xx]]),
            |y, e| *y *= 1.0 + C64::i() * (e - er) / es,
        );
        add_precondition(&a, eps.view(), er, es, &mut y);
        let gamma = 1.0 + C64::i() * (eps[[iz, iy, ix]] - er) / es;
        for c in 0..3 {
            let want = gamma * v[c] + C64::i() / es * mv[c];
            assert!((y[[c * nz + iz, iy, ix]] - want).norm() < 1e-13);
        }
        // Absorption: Im(v* Δ v).
        let want: C64 = (0..3).map(|c| v[c].conj() * mv[c]).sum();
        assert!((absorption(&a, &x) - want.im).abs() < 1e-12);
        let vox: Vec<_> = voxels(&a, &eps).collect();
        assert_eq!(vox.len(), 1);
        assert!((vox[0].1 - C64::new(-0.4, 0.03)).norm() < 1e-15);
    }
}
