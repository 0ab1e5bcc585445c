//! Stage 2: volume-fraction rasterisation, checked against analytic volumes.

use inksim::geometry::{
    pack_rsa, sphere_volume, Geometry, GeometryStats, PackParams, Particle, SpeciesParams, Sphere,
};
use inksim::raster::{rasterize, Grid, Raster};
use ndarray::{Array3, ShapeBuilder};
use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

mod common;
use common::threads::on_threads;

const SIZE: [f64; 3] = [1000.0, 1000.0, 500.0];

fn geometry(size_nm: [f64; 3], particles: Vec<Particle>, n_species: usize) -> Geometry {
    Geometry {
        size_nm,
        particles,
        stats: GeometryStats {
            count: vec![0; n_species],
            target_fraction: vec![0.0; n_species],
            achieved_fraction: vec![0.0; n_species],
            min_gap_nm: f64::INFINITY,
            attempts: 0,
            worst_overlap_nm: 0.0,
            order_parameter: None,
            relax_steps: 0,
        },
    }
}

fn ball(species: usize, center: [f64; 3], radius: f64) -> Particle {
    Particle {
        species,
        spheres: vec![Sphere { center, radius }],
    }
}

/// 32 × 32 × 20 voxels of 31.25 × 31.25 × 25 nm.
fn grid() -> Grid {
    Grid::new(32, 32, 20, SIZE).unwrap()
}

/// Rasterised volume of species `s`, nm³.
fn volume(r: &Raster, s: usize) -> f64 {
    r.fractions[s].sum() * r.grid.voxel_volume_nm3()
}

fn single_sphere_error(center: [f64; 3], radius: f64, s: usize) -> f64 {
    let g = geometry(SIZE, vec![ball(0, center, radius)], 1);
    let r = rasterize(&g, &grid(), s);
    volume(&r, 0) / sphere_volume(radius) - 1.0
}

fn random_centers(n: usize, radius: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            [
                rng.gen::<f64>() * SIZE[0],
                rng.gen::<f64>() * SIZE[1],
                radius + rng.gen::<f64>() * (SIZE[2] - 2.0 * radius),
            ]
        })
        .collect()
}

#[test]
fn single_sphere_volume_converges_with_supersampling() {
    let radius = 150.0;
    let centers = random_centers(10, radius, 1);
    for c in &centers {
        let err = single_sphere_error(*c, radius, 5);
        assert!(err.abs() < 2e-3, "centre {c:?}: relative error {err}");
    }
    let mean_err = |s: usize| {
        centers
            .iter()
            .map(|c| single_sphere_error(*c, radius, s).abs())
            .sum::<f64>()
            / centers.len() as f64
    };
    let (e1, e3, e9) = (mean_err(1), mean_err(3), mean_err(9));
    assert!(e1 > e3 && e3 > e9, "errors {e1} {e3} {e9} must decrease");
    assert!(e9 < 3e-4, "s = 9 mean error {e9}");
}

#[test]
fn fractions_are_bounded_and_exact_far_from_the_surface() {
    let c = [500.0, 500.0, 250.0];
    let radius = 150.0;
    let g = geometry(SIZE, vec![ball(0, c, radius)], 1);
    let grid = grid();
    let r = rasterize(&g, &grid, 4);
    let [dx, dy, dz] = grid.cell_nm();
    for ((iz, iy, ix), &f) in r.fractions[0].indexed_iter() {
        assert!((0.0..=1.0).contains(&f));
        // Distances from the centre to the voxel's nearest and farthest points.
        let lo = [ix as f64 * dx, iy as f64 * dy, iz as f64 * dz];
        let (mut near, mut far) = (0.0f64, 0.0f64);
        for a in 0..3 {
            let d = [dx, dy, dz][a];
            let (l, h) = (lo[a] - c[a], lo[a] + d - c[a]);
            near += if l > 0.0 {
                l * l
            } else if h < 0.0 {
                h * h
            } else {
                0.0
            };
            far += l.abs().max(h.abs()).powi(2);
        }
        if far.sqrt() < radius {
            assert_eq!(f, 1.0, "voxel inside the sphere");
        }
        if near.sqrt() > radius {
            assert_eq!(f, 0.0, "voxel outside the sphere");
        }
    }
}

#[test]
fn periodic_boundary_gives_the_same_volume() {
    let radius = 120.0;
    // 16 voxels (500 nm) apart in x and y: same position relative to the grid.
    let inner = [510.3, 507.9, 241.7];
    let straddle = [10.3, 7.9, 241.7];
    let a = rasterize(&geometry(SIZE, vec![ball(0, inner, radius)], 1), &grid(), 5);
    let b = rasterize(
        &geometry(SIZE, vec![ball(0, straddle, radius)], 1),
        &grid(),
        5,
    );
    let (va, vb) = (volume(&a, 0), volume(&b, 0));
    assert!((va / vb - 1.0).abs() < 1e-12, "{va} vs {vb}");
    // Voxel by voxel, up to the shift by 16 voxels.
    for ((iz, iy, ix), &f) in a.fractions[0].indexed_iter() {
        let g = b.fractions[0][[iz, (iy + 16) % 32, (ix + 16) % 32]];
        assert!((f - g).abs() < 1e-12, "voxel {iz} {iy} {ix}: {f} vs {g}");
    }
    // A centre just below L wraps the same way.
    let high = [990.3, 987.9, 241.7];
    let c = rasterize(&geometry(SIZE, vec![ball(0, high, radius)], 1), &grid(), 5);
    assert!((volume(&c, 0) / sphere_volume(radius) - 1.0).abs() < 2e-3);
}

#[test]
fn multi_sphere_particle_counts_the_union_once() {
    // Two spheres of one particle overlapping in a lens: volume of the union.
    let (r, d) = (100.0f64, 80.0f64);
    let lens = std::f64::consts::PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
    let union = 2.0 * sphere_volume(r) - lens;
    let p = Particle {
        species: 0,
        spheres: vec![
            Sphere {
                center: [30.0, 500.0, 250.0],
                radius: r,
            },
            // Stored wrapped, as the packer does: 80 nm to the left through x = 0.
            Sphere {
                center: [950.0, 500.0, 250.0],
                radius: r,
            },
        ],
    };
    let rast = rasterize(&geometry(SIZE, vec![p], 1), &grid(), 8);
    let v = volume(&rast, 0);
    assert!((v / union - 1.0).abs() < 2e-3, "{v} vs union {union}");
    assert!(rast.fractions[0].iter().all(|&f| (0.0..=1.0).contains(&f)));
}

#[test]
fn epsilon_is_the_exact_linear_mix() {
    // Supersample 4: every fraction is k/64, so with dyadic permittivities all
    // arithmetic below is exact whatever the evaluation order.
    let g = geometry(
        SIZE,
        vec![
            ball(0, [410.0, 500.0, 250.0], 100.0),
            ball(1, [610.0, 500.0, 250.0], 100.0),
        ],
        2,
    );
    let r = rasterize(&g, &grid(), 4);
    let eb = Complex64::new(2.25, 0.0);
    let es = [Complex64::new(1.5, 0.75), Complex64::new(3.0, 0.125)];
    let mut out = Array3::zeros((20, 32, 32));
    r.epsilon_into(eb, &es, &mut out);
    let mut mixed = 0;
    for ((iz, iy, ix), &e) in out.indexed_iter() {
        let f0 = r.fractions[0][[iz, iy, ix]];
        let f1 = r.fractions[1][[iz, iy, ix]];
        assert_eq!(f0 * 64.0, (f0 * 64.0).round(), "fraction not k/64");
        let expect = eb * (1.0 - f0 - f1) + es[0] * f0 + es[1] * f1;
        assert_eq!(e, expect, "voxel {iz} {iy} {ix}");
        if f0 > 0.0 && f1 > 0.0 {
            mixed += 1;
        }
        if f0 == 0.0 && f1 == 0.0 {
            assert_eq!(e, eb);
        }
        if f1 == 1.0 {
            assert_eq!(e, es[1]);
        }
    }
    // The spheres touch at x = 510, inside a voxel, so some voxels hold both species.
    assert!(mixed > 0);
    assert!(r.fractions[1].iter().any(|&f| f == 1.0));
    // A column-major output takes the general path and agrees.
    let mut f_order = Array3::zeros((20, 32, 32).f());
    r.epsilon_into(eb, &es, &mut f_order);
    assert!(!f_order.is_standard_layout());
    assert_eq!(f_order, out);
}

#[test]
fn packed_fragment_mean_fraction_matches_geometry() {
    let params = PackParams::new(
        [2000.0, 2000.0, 500.0],
        vec![
            SpeciesParams {
                diameter_nm: 160.0,
                volume_fraction: 0.12,
            },
            SpeciesParams {
                diameter_nm: 100.0,
                volume_fraction: 0.10,
            },
        ],
    );
    let g = pack_rsa(&params, 9).unwrap();
    let r = rasterize(&g, &Grid::new(64, 64, 20, g.size_nm).unwrap(), 5);
    let mean = r.mean_fractions();
    for (s, (&got, &want)) in mean.iter().zip(&g.stats.achieved_fraction).enumerate() {
        assert!(
            (got / want - 1.0).abs() < 2e-3,
            "species {s}: raster {got} vs geometry {want}"
        );
    }
    for iz in 0..20 {
        for iy in 0..64 {
            for ix in 0..64 {
                let t = r.fractions[0][[iz, iy, ix]] + r.fractions[1][[iz, iy, ix]];
                assert!(t <= 1.0 + 1e-15);
            }
        }
    }
}

#[test]
fn overlapping_particles_never_exceed_one() {
    let g = geometry(
        SIZE,
        vec![
            ball(0, [500.0, 500.0, 250.0], 120.0),
            ball(0, [520.0, 500.0, 250.0], 120.0),
            ball(1, [500.0, 520.0, 250.0], 120.0),
        ],
        2,
    );
    let r = rasterize(&g, &grid(), 4);
    for (a, b) in r.fractions[0].iter().zip(r.fractions[1].iter()) {
        assert!(a + b <= 1.0 + 1e-15, "{a} + {b}");
    }
    // Where all three cover the voxel, species 0 counts twice: scaled to 2/3.
    assert_eq!(r.fractions[0][[10, 16, 16]], 2.0 / 3.0);
    assert_eq!(r.fractions[1][[10, 16, 16]], 1.0 / 3.0);
}

#[test]
fn thread_count_does_not_change_the_raster() {
    let params = PackParams::new(
        [2000.0, 2000.0, 600.0],
        vec![
            SpeciesParams {
                diameter_nm: 200.0,
                volume_fraction: 0.15,
            },
            SpeciesParams {
                diameter_nm: 90.0,
                volume_fraction: 0.1,
            },
        ],
    );
    let g = pack_rsa(&params, 4).unwrap();
    let grid = Grid::new(50, 48, 24, g.size_nm).unwrap();
    let run = |threads| {
        on_threads(threads, || {
            let r = rasterize(&g, &grid, 5);
            let mut eps = Array3::zeros((24, 48, 50));
            r.epsilon_into(
                Complex64::new(2.4, 0.0),
                &[Complex64::new(1.9, 0.7), Complex64::new(2.1, 0.3)],
                &mut eps,
            );
            (r, eps)
        })
    };
    let (a, ea) = run(1);
    let (b, eb) = run(2);
    let (c, ec) = run(3);
    for s in 0..2 {
        let bits = |r: &Raster| {
            r.fractions[s]
                .iter()
                .map(|f| f.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&a), bits(&b));
        assert_eq!(bits(&a), bits(&c));
    }
    assert_eq!(ea, eb);
    assert_eq!(ea, ec);
}

#[test]
fn grid_checks() {
    assert!(Grid::new(0, 4, 4, SIZE).is_err());
    assert!(Grid::new(4, 4, 4, [1.0, -1.0, 1.0]).is_err());
    assert!(Grid::new(4, 4, 4, [1.0, 1.0, f64::NAN]).is_err());
    let g = Grid::new(40, 20, 10, [1000.0, 500.0, 250.0]).unwrap();
    assert_eq!(g.cell_nm(), [25.0, 25.0, 25.0]);
    assert_eq!(g.voxels(), 8000);
}

/// Surface relief: a sphere protruding through z = 0 by 18 nm. The grid
/// grows by whole cells above the binder; the whole sphere is rasterised;
/// above z = 0 the background is vacuum, below it binder.
#[test]
fn relief_cells_hold_protruding_grains_over_vacuum() {
    let r = 60.0;
    let c = [500.0, 500.0, r - 18.0];
    let g = geometry(SIZE, vec![ball(0, c, r)], 1);
    let base = grid(); // dz = 25 nm
    let grid = base.covering_relief(&g);
    assert_eq!(grid.nz, base.nz + 1);
    assert_eq!(grid.size_nm[2], SIZE[2] + 25.0);
    // No protrusion: the grid is unchanged.
    let flat = geometry(SIZE, vec![ball(0, [500.0, 500.0, r], r)], 1);
    assert_eq!(base.covering_relief(&flat), base);
    let ras = rasterize(&g, &grid, 8);
    assert_eq!(ras.top_cells, 1);
    assert_eq!(ras.top_nm(), 25.0);
    let v = volume(&ras, 0);
    assert!((v / sphere_volume(r) - 1.0).abs() < 5e-3, "{v}");
    // The cap above z = 0 sits in the top slice.
    let cap = std::f64::consts::PI * 18.0 * 18.0 * (3.0 * r - 18.0) / 3.0;
    let top: f64 =
        ras.fractions[0].index_axis(ndarray::Axis(0), 0).sum() * ras.grid.voxel_volume_nm3();
    assert!((top / cap - 1.0).abs() < 0.02, "{top} vs {cap}");
    // Mean fraction is per binder volume.
    assert!((ras.mean_fractions()[0] - v / SIZE.iter().product::<f64>()).abs() < 1e-12);
    let eb = Complex64::new(2.4, 0.0);
    let es = Complex64::new(5.0, 1.0);
    let mut eps = Array3::zeros((grid.nz, grid.ny, grid.nx));
    ras.epsilon_into(eb, &[es], &mut eps);
    assert_eq!(eps[[0, 0, 0]], Complex64::new(1.0, 0.0));
    assert_eq!(eps[[1, 0, 0]], eb);
    let f = ras.fractions[0][[0, 16, 16]];
    assert!(f > 0.0);
    let want = Complex64::new(1.0, 0.0) * (1.0 - f) + es * f;
    assert!((eps[[0, 16, 16]] - want).norm() < 1e-12);
}

#[test]
#[should_panic(expected = "whole cells")]
fn grid_taller_by_a_fraction_of_a_cell_is_refused() {
    let g = geometry(SIZE, vec![], 1);
    let grid = Grid::new(32, 32, 21, [SIZE[0], SIZE[1], SIZE[2] + 10.0]).unwrap();
    rasterize(&g, &grid, 2);
}
