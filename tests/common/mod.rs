//! Set-up shared by the solver tests: a layer of one pigment in the binder.
#![allow(dead_code)]

use inksim::geometry::{pack_rsa, Geometry, PackParams, SpeciesParams};
use inksim::raster::{rasterize, Grid};
use ndarray::Array3;
use num_complex::Complex64 as C64;

/// Binder permittivity of the reference data (n = 1.558).
pub const EPS_B: f64 = 1.558 * 1.558;

/// Spheres of diameter `d` by random sequential addition.
pub fn packed_rsa(size: [f64; 3], d: f64, pvc: f64, seed: u64) -> Geometry {
    let params = PackParams {
        size_nm: size,
        species: vec![SpeciesParams {
            diameter_nm: d,
            volume_fraction: pvc,
        }],
        ..PackParams::default()
    };
    pack_rsa(&params, seed).expect("packing")
}

/// ε on a `[nx, ny, nz]` grid for grains of index `n` in the binder, and the
/// rasterised pigment fraction.
pub fn layer_eps(geom: &Geometry, cells: [usize; 3], n: C64) -> (Array3<C64>, f64) {
    let grid = Grid {
        nx: cells[0],
        ny: cells[1],
        nz: cells[2],
        size_nm: geom.size_nm,
    };
    let raster = rasterize(geom, &grid, 4);
    let mut eps = Array3::zeros((cells[2], cells[1], cells[0]));
    raster.epsilon_into(C64::new(EPS_B, 0.0), &[n * n], &mut eps);
    (eps, raster.mean_fractions()[0])
}
