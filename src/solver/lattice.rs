//! The Bloch–Fourier lattice of one problem: grid, period, wavenumber and
//! the lateral wave vector of the incident wave, and what follows from them
//! per harmonic (diffraction order, κ, β). Everything in the solver that
//! works per harmonic takes its numbers from here.

use super::green::{self, Slab};
use num_complex::Complex64 as C64;

/// The Bloch–Fourier lattice of one problem.
#[derive(Debug, Clone, Copy)]
pub struct Lattice {
    pub nx: usize,
    pub ny: usize,
    pub nz: usize,
    /// Period Lx, Ly and thickness H (nm).
    pub size_nm: [f64; 3],
    /// Free-space wavenumber (rad/nm).
    pub k0: f64,
    /// Lateral wave vector of the incident wave (rad/nm).
    pub q: [f64; 2],
}

impl Lattice {
    /// Diffraction order of FFT index `i` on an axis of `n` points.
    pub fn order(i: usize, n: usize) -> i32 {
        if i < n.div_ceil(2) {
            i as i32
        } else {
            i as i32 - n as i32
        }
    }

    /// κ of the harmonic at FFT indices (ix, iy).
    pub fn kappa(&self, ix: usize, iy: usize) -> [f64; 2] {
        let tau = 2.0 * std::f64::consts::PI;
        [
            self.q[0] + tau * Self::order(ix, self.nx) as f64 / self.size_nm[0],
            self.q[1] + tau * Self::order(iy, self.ny) as f64 / self.size_nm[1],
        ]
    }

    /// β = sqrt(k0² − |κ|²) in vacuum (Im ≥ 0).
    pub fn beta(&self, ix: usize, iy: usize) -> C64 {
        let [kx, ky] = self.kappa(ix, iy);
        green::sqrt_branch(C64::new(self.k0 * self.k0 - kx * kx - ky * ky, 0.0))
    }

    pub fn slab(&self) -> Slab {
        Slab {
            k0: self.k0,
            thickness: self.size_nm[2],
            nz: self.nz,
        }
    }

    pub fn harmonics(&self) -> usize {
        self.nx * self.ny
    }
}
