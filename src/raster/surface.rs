//! The binder's top surface as a height map (METHOD §3).
//!
//! A surface is the depth `s(x, y)` of the binder surface below the plane
//! `z = 0` at the centre of each grid column, shape `(ny, nx)` (negative:
//! above the plane, in the cells a grid adds on top). Below the surface the
//! non-grain part of a voxel is binder, above it vacuum; a voxel the surface
//! cuts is binder in proportion to the part of its height below the surface
//! ([`binder_share`]). Without a map the surface is the plane `z = 0`.
//!
//! - [`conformal`]: the binder drapes over the topmost material at a film
//!   thickness `t`: the upper envelope of the material, `top(x, y)`, offset
//!   by a ball of radius `t` (`s = min over columns within t of
//!   top − √(t² − ρ²)`, a film of thickness `t` measured normal to the
//!   material, not only vertically). A column with no material drapes down
//!   to the layer's bottom (the paper).
//! - [`rough`]: a stationary Gaussian random surface around `z = 0`:
//!   white noise filtered in Fourier space by the square root of the
//!   spectrum of the correlation `σ² e^{−r²/ℓ²}`, then shifted to zero mean
//!   and scaled to RMS `σ` exactly, heights limited to `±ROUGH_LIMIT σ`.

use crate::geometry::normal::standard_normal;
use ndarray::{Array2, Array3};
use num_complex::Complex64;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use rustfft::FftPlanner;

use super::Grid;

/// Rough heights are limited to this many RMS heights either side of the
/// mean (a Gaussian exceeds 4σ with probability 6e-5 per column); the grid
/// adds cells above the layer up to that height.
pub const ROUGH_LIMIT: f64 = 4.0;

/// Fraction of the voxel from `z_lo` to `z_lo + dz` that lies below the
/// surface at depth `s` (binder), in `[0, 1]`.
#[inline]
pub fn binder_share(z_lo: f64, dz: f64, s: f64) -> f64 {
    ((z_lo + dz - s) / dz).clamp(0.0, 1.0)
}

/// Depth of the topmost material in each column of `fractions` (summed over
/// species), `(ny, nx)`: in the first voxel from the top whose total
/// fraction `F` exceeds 1e-9, the material is taken to fill the lower `F` of
/// its height; a column without material gives the grid's bottom.
pub fn material_top(grid: &Grid, z_origin_nm: f64, fractions: &[Array3<f64>]) -> Array2<f64> {
    let dz = grid.cell_nm()[2];
    let bottom = z_origin_nm + grid.nz as f64 * dz;
    Array2::from_shape_fn((grid.ny, grid.nx), |(iy, ix)| {
        for iz in 0..grid.nz {
            let f: f64 = fractions.iter().map(|a| a[[iz, iy, ix]]).sum();
            if f > 1e-9 {
                return z_origin_nm + iz as f64 * dz + (1.0 - f.min(1.0)) * dz;
            }
        }
        bottom
    })
}

/// The conformal surface over `top` (depths, `(ny, nx)`) at film thickness
/// `film_nm`: `s = min over columns within film_nm (periodic) of
/// top − √(film² − ρ²)`, never above `z_origin_nm` (the grid's top).
pub fn conformal(grid: &Grid, z_origin_nm: f64, top: &Array2<f64>, film_nm: f64) -> Array2<f64> {
    let [dx, dy, _] = grid.cell_nm();
    let (nx, ny) = (grid.nx as i64, grid.ny as i64);
    let rx = (film_nm / dx).floor() as i64;
    let ry = (film_nm / dy).floor() as i64;
    // The ball's offsets, shared by every column.
    let mut ball = Vec::new();
    for jy in -ry..=ry {
        for jx in -rx..=rx {
            let rho2 = (jx as f64 * dx).powi(2) + (jy as f64 * dy).powi(2);
            if rho2 <= film_nm * film_nm {
                ball.push((jx, jy, (film_nm * film_nm - rho2).sqrt()));
            }
        }
    }
    Array2::from_shape_fn((grid.ny, grid.nx), |(iy, ix)| {
        let s = ball
            .iter()
            .map(|&(jx, jy, h)| {
                let x = (ix as i64 + jx).rem_euclid(nx) as usize;
                let y = (iy as i64 + jy).rem_euclid(ny) as usize;
                top[[y, x]] - h
            })
            .fold(f64::INFINITY, f64::min);
        s.max(z_origin_nm)
    })
}

/// A rough surface of RMS height `rms_nm` and correlation length
/// `correlation_nm` on the grid's columns, from `seed`: depths (the
/// negated heights) of zero mean and RMS `rms_nm` exactly, then limited to
/// `±ROUGH_LIMIT · rms_nm`.
pub fn rough(grid: &Grid, rms_nm: f64, correlation_nm: f64, seed: u64) -> Array2<f64> {
    let (nx, ny) = (grid.nx, grid.ny);
    let [lx, ly, _] = grid.size_nm;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    // White noise.
    let mut field: Vec<Complex64> = (0..nx * ny)
        .map(|_| Complex64::new(standard_normal(&mut rng), 0.0))
        .collect();
    let mut planner = FftPlanner::new();
    let (fx, fy) = (planner.plan_fft_forward(nx), planner.plan_fft_forward(ny));
    let (bx, by) = (planner.plan_fft_inverse(nx), planner.plan_fft_inverse(ny));
    transform_2d(&mut field, nx, ny, &*fx, &*fy);
    // Amplitude filter √S(k), S(k) ∝ exp(−k²ℓ²/4) for ⟨h h⟩ = σ² e^{−r²/ℓ²}.
    let freq = |i: usize, n: usize, l: f64| {
        let m = if i <= n / 2 {
            i as f64
        } else {
            i as f64 - n as f64
        };
        2.0 * std::f64::consts::PI * m / l
    };
    for iy in 0..ny {
        let ky = freq(iy, ny, ly);
        for ix in 0..nx {
            let kx = freq(ix, nx, lx);
            let k2 = kx * kx + ky * ky;
            field[iy * nx + ix] *= (-k2 * correlation_nm * correlation_nm / 8.0).exp();
        }
    }
    transform_2d(&mut field, nx, ny, &*bx, &*by);
    let n = (nx * ny) as f64;
    let mean = field.iter().map(|c| c.re).sum::<f64>() / n;
    let var = field.iter().map(|c| (c.re - mean).powi(2)).sum::<f64>() / n;
    let scale = if var > 0.0 { rms_nm / var.sqrt() } else { 0.0 };
    let limit = ROUGH_LIMIT * rms_nm;
    Array2::from_shape_fn((ny, nx), |(iy, ix)| {
        let h = (field[iy * nx + ix].re - mean) * scale;
        -h.clamp(-limit, limit)
    })
}

/// In-place 2-D transform of a row-major `ny × nx` array: rows, then
/// columns.
fn transform_2d(
    a: &mut [Complex64],
    nx: usize,
    ny: usize,
    fx: &dyn rustfft::Fft<f64>,
    fy: &dyn rustfft::Fft<f64>,
) {
    for row in a.chunks_mut(nx) {
        fx.process(row);
    }
    let mut col = vec![Complex64::new(0.0, 0.0); ny];
    for ix in 0..nx {
        for (iy, c) in col.iter_mut().enumerate() {
            *c = a[iy * nx + ix];
        }
        fy.process(&mut col);
        for (iy, c) in col.iter().enumerate() {
            a[iy * nx + ix] = *c;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, cell: f64) -> Grid {
        Grid::new(n, n, 10, [n as f64 * cell, n as f64 * cell, 100.0]).unwrap()
    }

    #[test]
    fn binder_share_is_the_part_below_the_surface() {
        assert_eq!(binder_share(0.0, 10.0, 0.0), 1.0);
        assert_eq!(binder_share(0.0, 10.0, 10.0), 0.0);
        assert!((binder_share(0.0, 10.0, 2.5) - 0.75).abs() < 1e-15);
        assert_eq!(binder_share(-10.0, 10.0, 3.0), 0.0);
        assert_eq!(binder_share(20.0, 10.0, 3.0), 1.0);
    }

    #[test]
    fn rough_surface_has_the_asked_rms_zero_mean_and_correlation() {
        // 128² columns of 5 nm, ℓ = 40 nm = 8 cells: the correlation at lag
        // ℓ along x, averaged over seeds, is σ² e^{-1} (0.368) within its
        // statistical error (≈ 0.02 for 8 fields of (640/40)² ≈ 256
        // correlation areas).
        let g = grid(128, 5.0);
        let (sigma, ell) = (3.0, 40.0);
        let mut c_ell = 0.0;
        let mut c_2ell = 0.0;
        let seeds = 8;
        for seed in 0..seeds {
            let s = rough(&g, sigma, ell, seed);
            let n = s.len() as f64;
            let mean = s.sum() / n;
            let rms = (s.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
            // Exact before the ±4σ limit, which moves a few columns.
            assert!(
                mean.abs() < 1e-2 * sigma && (rms - sigma).abs() < 1e-2 * sigma,
                "{mean} {rms}"
            );
            let lag = |l: usize| {
                let mut c = 0.0;
                for iy in 0..128 {
                    for ix in 0..128 {
                        c += s[[iy, ix]] * s[[iy, (ix + l) % 128]];
                    }
                }
                c / n / (sigma * sigma)
            };
            c_ell += lag(8) / seeds as f64;
            c_2ell += lag(16) / seeds as f64;
        }
        let e = (-1.0f64).exp();
        assert!((c_ell - e).abs() < 0.06, "C(ℓ)/σ² = {c_ell}, expected {e}");
        assert!((c_2ell - e.powi(4)).abs() < 0.06, "C(2ℓ)/σ² = {c_2ell}");
        // Different seeds, different surfaces; same seed, same surface.
        assert_ne!(rough(&g, sigma, ell, 1), rough(&g, sigma, ell, 2));
        assert_eq!(rough(&g, sigma, ell, 1), rough(&g, sigma, ell, 1));
    }

    #[test]
    fn conformal_surface_is_the_envelope_offset_by_a_ball() {
        // A single column of material reaching depth 50 nm on a 1 nm grid:
        // the surface is a hemisphere of radius t around that column's top,
        // elsewhere the bottom (100 nm) offset by t.
        let g = grid(41, 1.0);
        let mut top = Array2::from_elem((41, 41), 100.0);
        top[[20, 20]] = 50.0;
        let t = 10.0;
        let s = conformal(&g, 0.0, &top, t);
        assert_eq!(s[[20, 20]], 40.0);
        assert!((s[[20, 26]] - (50.0 - (100.0f64 - 36.0).sqrt())).abs() < 1e-12);
        assert_eq!(s[[20, 31]], 90.0, "beyond the ball: the bottom offset by t");
        assert_eq!(s[[0, 0]], 90.0);
        // Never above the grid's top.
        let s = conformal(&g, 45.0, &top, t);
        assert_eq!(s[[20, 20]], 45.0);
    }

    #[test]
    fn material_top_reads_partial_voxels() {
        let g = Grid::new(2, 1, 4, [2.0, 1.0, 40.0]).unwrap();
        let mut f = Array3::zeros((4, 1, 2));
        f[[1, 0, 0]] = 0.25; // material in the lower quarter of voxel 1
        f[[2, 0, 0]] = 1.0;
        let top = material_top(&g, -10.0, &[f]);
        assert!((top[[0, 0]] - (-10.0 + 10.0 + 7.5)).abs() < 1e-12);
        assert_eq!(top[[0, 1]], 30.0, "no material: the bottom");
    }
}
