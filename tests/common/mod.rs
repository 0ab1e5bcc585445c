//! Set-up shared by the tests: a layer of one pigment in the binder, a
//! brute-force check of particle gaps, and the Airy slab reference.
#![allow(dead_code)]

use inksim::geometry::{pack_rsa, Geometry, PackParams, SpeciesParams, Sphere};
use inksim::raster::{rasterize, Grid};
use inksim::solver::green;
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

/// Smallest surface gap over all pairs of particles, brute force, checking
/// the 3×3 periodic images explicitly (not just the nearest one).
pub fn brute_min_gap(g: &Geometry) -> f64 {
    let [lx, ly, _] = g.size_nm;
    let all: Vec<(usize, Sphere)> = g
        .particles
        .iter()
        .enumerate()
        .flat_map(|(i, p)| p.spheres.iter().map(move |s| (i, *s)))
        .collect();
    let mut best = f64::INFINITY;
    for (a, (pa, sa)) in all.iter().enumerate() {
        for (pb, sb) in &all[a + 1..] {
            if pa == pb {
                continue;
            }
            for ix in -1..=1 {
                for iy in -1..=1 {
                    let dx = sa.center[0] - sb.center[0] + ix as f64 * lx;
                    let dy = sa.center[1] - sb.center[1] + iy as f64 * ly;
                    let dz = sa.center[2] - sb.center[2];
                    let gap = (dx * dx + dy * dy + dz * dz).sqrt() - sa.radius - sb.radius;
                    best = best.min(gap);
                }
            }
        }
    }
    best
}

/// Exact Airy amplitudes `(r, t)` of a homogeneous slab of permittivity `eps`
/// and thickness `h` in vacuum, for vacuum wavenumber `k0` and lateral
/// wavenumber `kap` (the one independent slab reference of the tests).
pub fn airy(k0: f64, eps: C64, kap: f64, h: f64) -> (C64, C64) {
    let g = green::sqrt_branch(k0 * k0 * eps - kap * kap);
    let b = green::sqrt_branch(C64::new(k0 * k0 - kap * kap, 0.0));
    let rho = (g - b) / (g + b);
    let e = (2.0 * C64::i() * g * h).exp();
    let a = 2.0 * b / ((g + b) * (1.0 - rho * rho * e));
    (
        a * (1.0 + rho * e) - 1.0,
        a * (C64::i() * g * h).exp() * (1.0 + rho),
    )
}

/// Airy power coefficients `(|r|², |t|²)` of the same slab.
pub fn airy_power(k0: f64, eps: C64, kap: f64, h: f64) -> (f64, f64) {
    let (r, t) = airy(k0, eps, kap, h);
    (r.norm_sqr(), t.norm_sqr())
}

/// `(R, T)` of a slab of real permittivity `eps`, thickness `h` (nm), at
/// wavelength `wl` (nm) and polar angle `polar_deg`.
pub fn airy_rt(eps: f64, h: f64, wl: f64, polar_deg: f64) -> (f64, f64) {
    let k0 = 2.0 * std::f64::consts::PI / wl;
    airy_power(k0, C64::new(eps, 0.0), k0 * polar_deg.to_radians().sin(), h)
}
