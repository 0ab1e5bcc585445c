//! Batched 2-D FFTs over the z-slices of a field.
//!
//! Real-space fields are stored `(nz, ny, nx)`; their spectra `(nz, nx, ny)`
//! (transposed, so both 1-D passes run over contiguous rows). Plans come
//! from one process-wide planner, which caches them by length, so every
//! solve on a grid (all wavelengths, angles, realisations) reuses the same
//! plans; per-slice scratch is owned by the caller's [`FftScratch`].

use ndarray::{Array3, ArrayViewMut2, Axis};
use num_complex::Complex64 as C64;
use rayon::prelude::*;
use rustfft::{Fft, FftPlanner};
use std::sync::{Arc, Mutex, OnceLock};

/// The shared planner (rustfft caches every plan it makes).
fn planner() -> &'static Mutex<FftPlanner<f64>> {
    static PLANNER: OnceLock<Mutex<FftPlanner<f64>>> = OnceLock::new();
    PLANNER.get_or_init(|| Mutex::new(FftPlanner::new()))
}

/// Planned forward and inverse transforms for one slice size.
pub struct Fft2 {
    nx: usize,
    ny: usize,
    fx: Arc<dyn Fft<f64>>,
    fy: Arc<dyn Fft<f64>>,
    ix: Arc<dyn Fft<f64>>,
    iy: Arc<dyn Fft<f64>>,
}

/// Per-slice scratch for the transforms, and per task one real-space
/// plane for the transforms that fill and read slices through closures.
pub struct FftScratch {
    bufs: Vec<Vec<C64>>,
    planes: Vec<Vec<C64>>,
}

impl Fft2 {
    pub fn new(nx: usize, ny: usize) -> Self {
        // A poisoned lock only means another thread panicked while planning;
        // the planner's cache is still valid.
        let mut p = planner().lock().unwrap_or_else(|e| e.into_inner());
        Fft2 {
            nx,
            ny,
            fx: p.plan_fft_forward(nx),
            fy: p.plan_fft_forward(ny),
            ix: p.plan_fft_inverse(nx),
            iy: p.plan_fft_inverse(ny),
        }
    }

    /// Scratch for `nz` slices.
    pub fn scratch(&self, nz: usize) -> FftScratch {
        let len = [&self.fx, &self.fy, &self.ix, &self.iy]
            .iter()
            .map(|f| f.get_inplace_scratch_len())
            .max()
            .unwrap_or(0)
            .max(1);
        let tasks = nz.min(4 * rayon::current_num_threads()).max(1);
        FftScratch {
            bufs: (0..nz).map(|_| vec![C64::new(0.0, 0.0); len]).collect(),
            planes: (0..tasks)
                .map(|_| vec![C64::new(0.0, 0.0); self.nx * self.ny])
                .collect(),
        }
    }

    /// Unnormalised forward transform of every slice: `real (nz,ny,nx)` → `spec (nz,nx,ny)`.
    /// `real` is used as working space and left transformed along x.
    pub fn forward(&self, real: &mut Array3<C64>, spec: &mut Array3<C64>, scr: &mut FftScratch) {
        let (nx, ny) = (self.nx, self.ny);
        let r = real.as_slice_mut().expect("contiguous field");
        let s = spec.as_slice_mut().expect("contiguous spectrum");
        r.par_chunks_mut(nx * ny)
            .zip(s.par_chunks_mut(nx * ny))
            .zip(scr.bufs.par_iter_mut())
            .for_each(|((rs, ss), buf)| {
                self.fx.process_with_scratch(rs, buf);
                transpose(rs, ss, ny, nx);
                self.fy.process_with_scratch(ss, buf);
            });
    }

    /// Unnormalised inverse transform: `spec (nz,nx,ny)` → `real (nz,ny,nx)`.
    /// `spec` is used as working space.
    pub fn inverse(&self, spec: &mut Array3<C64>, real: &mut Array3<C64>, scr: &mut FftScratch) {
        let (nx, ny) = (self.nx, self.ny);
        let r = real.as_slice_mut().expect("contiguous field");
        let s = spec.as_slice_mut().expect("contiguous spectrum");
        s.par_chunks_mut(nx * ny)
            .zip(r.par_chunks_mut(nx * ny))
            .zip(scr.bufs.par_iter_mut())
            .for_each(|((ss, rs), buf)| {
                self.iy.process_with_scratch(ss, buf);
                transpose(ss, rs, nx, ny);
                self.ix.process_with_scratch(rs, buf);
            });
    }
}

impl Fft2 {
    /// [`Fft2::forward`] of the slices `load(k, plane)` writes (plane `k`
    /// of the field, (ny, nx)) into `spec (nslices, nx, ny)`: the field is
    /// never stored whole, so a source made per voxel (the contrast times
    /// the unknowns) costs no pass over memory of its own.
    pub fn forward_from(
        &self,
        spec: &mut Array3<C64>,
        scr: &mut FftScratch,
        load: impl Fn(usize, &mut [C64]) + Sync,
    ) {
        let (nx, ny) = (self.nx, self.ny);
        let slices = spec.dim().0;
        let per = slices.div_ceil(scr.planes.len());
        let s = spec.as_slice_mut().expect("contiguous spectrum");
        s.par_chunks_mut(per * nx * ny)
            .zip(scr.planes.par_iter_mut())
            .zip(scr.bufs.par_iter_mut())
            .enumerate()
            .for_each(|(task, ((chunk, plane), buf))| {
                for (i, ss) in chunk.chunks_mut(nx * ny).enumerate() {
                    load(task * per + i, plane);
                    self.fx.process_with_scratch(plane, buf);
                    transpose(plane, ss, ny, nx);
                    self.fy.process_with_scratch(ss, buf);
                }
            });
    }

    /// [`Fft2::inverse`] of `spec` (used as working space), handing each
    /// real-space plane `k` (ny, nx) to `store(k, plane, out's slice k)`;
    /// returns what `store` returns, in slice order.
    pub fn inverse_into<S: Send + Sync, R: Send>(
        &self,
        spec: &mut Array3<C64>,
        scr: &mut FftScratch,
        out: &mut Array3<S>,
        store: impl Fn(usize, &[C64], ArrayViewMut2<S>) -> R + Sync,
    ) -> Vec<R> {
        let (nx, ny) = (self.nx, self.ny);
        let slices = spec.dim().0;
        assert_eq!(out.dim().0, slices, "one output slice per spectral slice");
        let per = slices.div_ceil(scr.planes.len());
        let s = spec.as_slice_mut().expect("contiguous spectrum");
        let parts: Vec<Vec<R>> = s
            .par_chunks_mut(per * nx * ny)
            .zip(out.axis_chunks_iter_mut(Axis(0), per).into_par_iter())
            .zip(scr.planes.par_iter_mut())
            .zip(scr.bufs.par_iter_mut())
            .enumerate()
            .map(|(task, (((chunk, mut outs), plane), buf))| {
                chunk
                    .chunks_mut(nx * ny)
                    .zip(outs.outer_iter_mut())
                    .enumerate()
                    .map(|(i, (ss, o))| {
                        self.iy.process_with_scratch(ss, buf);
                        transpose(ss, plane, nx, ny);
                        self.ix.process_with_scratch(plane, buf);
                        store(task * per + i, plane, o)
                    })
                    .collect()
            })
            .collect();
        parts.into_iter().flatten().collect()
    }
}

/// `dst (cols × rows) = srcᵀ` for `src (rows × cols)`: the `transpose`
/// crate's recursive kernel, 2.2× (60² slices) to 3.7× (256²) faster than a
/// plain 16 × 16 tiled loop (`cargo bench --bench transpose`).
fn transpose(src: &[C64], dst: &mut [C64], rows: usize, cols: usize) {
    transpose::transpose(src, dst, cols, rows);
}
