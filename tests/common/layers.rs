//! A layer of one pigment in the binder, from packing to ε and to the
//! problem the solver takes, and a brute-force check of particle gaps.

use inksim::config::{Background, Precision};
use inksim::geometry::{pack_rsa, Geometry, PackParams, Particle, SpeciesParams, Sphere};
use inksim::raster::{rasterize, Grid};
use inksim::solver::{Controls, Lattice, Problem};
use ndarray::Array3;
use num_complex::Complex64 as C64;

/// Binder permittivity of the reference data (n = 1.558).
pub const EPS_B: f64 = 1.558 * 1.558;

/// The problem of a layer `eps` in the reference binder.
pub fn in_binder(lattice: Lattice, eps: &Array3<C64>) -> Problem<'_> {
    Problem {
        tensor: None,
        lattice,
        eps,
        eps_binder: EPS_B,
        wave: inksim::solver::Wave::Scalar,
    }
}

/// Controls tight enough to compare against closed forms: residual 1e-11,
/// f64 fields, on `background`.
pub fn tight(background: Background) -> Controls {
    Controls {
        tolerance: 1e-11,
        max_iterations: 20000,
        precision: Precision::F64,
        background,
    }
}

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

/// One sphere of radius `radius` and permittivity `eps_s` per period
/// `l` × `l` × `h` in vacuum, at (0.37 l, 0.61 l, h/2), on `cells` lateral
/// cells and cubic voxels: its ε grid and the lattice of the problem at
/// wavelength `wl` lit at `polar_deg` (azimuth 0).
pub fn one_sphere_lattice(
    l: f64,
    h: f64,
    radius: f64,
    cells: usize,
    eps_s: C64,
    wl: f64,
    polar_deg: f64,
) -> (Array3<C64>, Lattice) {
    let geom = Geometry {
        size_nm: [l, l, h],
        particles: vec![Particle {
            species: 0,
            spheres: vec![Sphere {
                center: [0.37 * l, 0.61 * l, 0.5 * h],
                radius,
            }],
        }],
        stats: Default::default(),
    };
    let nz = (h / (l / cells as f64)).round() as usize;
    let grid = Grid {
        nx: cells,
        ny: cells,
        nz,
        size_nm: [l, l, h],
    };
    let raster = rasterize(&geom, &grid, 4);
    let mut eps = Array3::zeros((nz, cells, cells));
    raster.epsilon_into(C64::new(1.0, 0.0), &[eps_s], &mut eps);
    let lattice = Problem::lattice([cells, cells, nz], [l, l, h], wl, polar_deg, 0.0);
    (eps, lattice)
}

/// A slab of `eps_s` from depth `z1` to `z2` (nm) inside the reference
/// binder of thickness `h`, on `nz` cells of a 2 × 2 lateral grid whose
/// faces need not meet the slab's: the cut cells hold the volume average
/// `ε_t` in the grid and, in the tensor, the term `(ε_n − ε_t) ẑẑᵀ` with
/// `ε_n` the harmonic mean (the exact homogenisation of a laminate for the
/// field across it).
#[allow(dead_code)]
pub fn laminate(
    nz: usize,
    (z1, z2, h): (f64, f64, f64),
    eps_s: C64,
) -> (Array3<C64>, inksim::raster::Anisotropy) {
    use inksim::raster::anisotropy::Term;
    let eps_b = C64::new(EPS_B, 0.0);
    let dz = h / nz as f64;
    let mut eps = Array3::from_elem((nz, 2, 2), eps_b);
    let mut tensor = inksim::raster::Anisotropy::empty(nz, (2, 2));
    for k in 0..nz {
        let (lo, hi) = (k as f64 * dz, (k + 1) as f64 * dz);
        let f = ((hi.min(z2) - lo.max(z1)) / dz).clamp(0.0, 1.0);
        let eps_t = f * eps_s + (1.0 - f) * eps_b;
        eps.slice_mut(ndarray::s![k, .., ..]).fill(eps_t);
        if f > 1e-12 && f < 1.0 - 1e-12 {
            let eps_n = 1.0 / (f / eps_s + (1.0 - f) / eps_b);
            for index in 0..4 {
                tensor.terms.push(Term {
                    index,
                    axis: [0.0, 0.0, 1.0],
                    delta: eps_n - eps_t,
                });
            }
        }
        tensor.offsets[k + 1] = tensor.terms.len();
    }
    (eps, tensor)
}
