//! The anisotropic permittivity of cut voxels (METHOD §3, §9): the tensor
//! part of Maxwell's contrast against exact layered references, and the
//! rasteriser's surface normals.
//!
//! A slab whose faces cut grid cells is the one geometry where the exact
//! answer of a cut cell is known in closed form: a laminate, whose
//! field along the faces sees the volume average of ε and whose field
//! across them the harmonic mean. In p polarisation at oblique incidence
//! E_z crosses the faces; there volume averaging is first order in the
//! cell and the anisotropic cell second order. In s polarisation E has no
//! z component and the tensor term must change nothing.
use inksim::config::{Background, Linear, Method};
use inksim::geometry::{Geometry, Particle, Sphere};
use inksim::optics::farfield::efficiencies;
use inksim::raster::{rasterize, Anisotropy, Grid};
use inksim::solver::{self, Problem, Wave};
use num_complex::Complex64 as C64;

mod common;
use common::airy::{tmm, tmm_p};
use common::layers::{laminate, tight, EPS_B};

const H: f64 = 600.0;
/// Faces at depths that no grid below meets.
const Z1: f64 = 137.0;
const Z2: f64 = 411.0;

/// R and T of the laminate on `nz` cells, with or without its tensor.
fn laminate_rt(nz: usize, eps_s: C64, polar: f64, pol: Linear, tensor: bool) -> (f64, f64) {
    let (eps, t) = laminate(nz, (Z1, Z2, H), eps_s);
    let lat = Problem::lattice([2, 2, nz], [400.0, 400.0, H], 550.0, polar, 20.0);
    let p = Problem {
        lattice: lat,
        eps: &eps,
        tensor: tensor.then_some(&t),
        eps_binder: EPS_B,
        wave: Wave::Vector {
            polarisation: pol.into(),
            azimuth_deg: 20.0,
        },
    };
    let sol = solver::solve(&p, Method::BiCgStab, &tight(Background::Binder)).expect("solve");
    let ff = efficiencies(&sol);
    assert!(
        ff.energy_balance.abs() < 1e-8,
        "balance {}",
        ff.energy_balance
    );
    (ff.total_reflectance, ff.total_transmittance)
}

fn layers(eps_s: C64) -> [(C64, f64); 3] {
    let b = C64::new(EPS_B, 0.0);
    [(b, Z1), (eps_s, Z2 - Z1), (b, H - Z2)]
}

/// p at 60°: the anisotropic cells converge at second order to the
/// transfer matrix and beat volume averaging by far at every grid (by
/// 11–90× here); averaging's error falls at about first order.
#[test]
fn cut_cells_of_a_laminate_converge_at_second_order_in_p() {
    // Low-index layers (a void, an absorbing one): E_z jumps by ε_b/ε_s ≈ 2
    // across the faces. (With a high index the refracted wave is nearly
    // normal, E_z is small inside, and the bulk's second-order z error
    // hides the cut cells.)
    for eps_s in [C64::new(1.2, 0.0), C64::new(1.2, 0.4)] {
        let (r0, t0) = tmm_p(&layers(eps_s), 550.0, 60.0);
        let mut aniso = vec![];
        let mut average = vec![];
        for nz in [20, 40, 80, 160] {
            let err = |(r, t): (f64, f64)| (r - r0).abs().max((t - t0).abs());
            aniso.push(err(laminate_rt(nz, eps_s, 60.0, Linear::P, true)));
            average.push(err(laminate_rt(nz, eps_s, 60.0, Linear::P, false)));
        }
        eprintln!("ε {eps_s}: anisotropic {aniso:?}, average {average:?}");
        let order = |e: &[f64]| (e[0] / e[3]).log2() / 3.0;
        assert!(order(&aniso) > 1.7, "anisotropic order {}", order(&aniso));
        assert!(order(&average) < 1.3, "average order {}", order(&average));
        for (a, v) in aniso.iter().zip(&average) {
            assert!(a * 5.0 < *v, "anisotropic {a:.2e} vs average {v:.2e}");
        }
        assert!(aniso[3] < 3e-5, "{aniso:?}");
    }
}

/// s polarisation has no field across the faces: the tensor term along z
/// changes nothing, and both match the transfer matrix at second order.
#[test]
fn a_term_across_the_faces_leaves_s_alone() {
    let eps_s = C64::new(7.3, 0.0);
    let (r0, _) = tmm(&layers(eps_s), 550.0, 60.0);
    for nz in [20, 80] {
        let (ra, ta) = laminate_rt(nz, eps_s, 60.0, Linear::S, true);
        let (rv, tv) = laminate_rt(nz, eps_s, 60.0, Linear::S, false);
        assert!((ra - rv).abs() < 1e-9 && (ta - tv).abs() < 1e-9);
        eprintln!("s, {nz} cells: R {ra:.6} vs {r0:.6}");
    }
}

/// One sphere rasterised: every cut voxel has the radial unit normal at its
/// centre, no other voxel has one, and the tensor term is the harmonic
/// mean minus the average of the voxel's own shares.
#[test]
fn a_sphere_has_radial_normals_and_harmonic_terms() {
    let (l, h, r) = (400.0, 400.0, 130.0);
    let centre = [190.0, 207.0, 203.0];
    let geom = Geometry {
        size_nm: [l, l, h],
        particles: vec![Particle {
            species: 0,
            spheres: vec![Sphere {
                center: centre,
                radius: r,
            }],
        }],
        stats: Default::default(),
    };
    let n = 40;
    let grid = Grid::new(n, n, n, [l, l, h]).unwrap();
    let raster = rasterize(&geom, &grid, 4);
    let d = l / n as f64;
    let mut cut = 0;
    for iz in 0..n {
        let normals = &raster.normals.slices[iz];
        for iy in 0..n {
            for ix in 0..n {
                let f = raster.fractions[0][[iz, iy, ix]];
                let i = (ix + n * iy) as u32;
                let nv = normals.iter().find(|v| v.index == i);
                if f > 0.0 && f < 1.0 {
                    cut += 1;
                    let nv = nv.expect("a cut voxel has a normal");
                    let x = [ix, iy, iz].map(|v| (v as f64 + 0.5) * d);
                    let rel: Vec<f64> = (0..3).map(|a| x[a] - centre[a]).collect();
                    let len = rel.iter().map(|v| v * v).sum::<f64>().sqrt();
                    for (n, r) in nv.n.iter().zip(&rel) {
                        assert!((n - r / len).abs() < 1e-12);
                    }
                } else {
                    assert!(nv.is_none(), "uncut voxel with a normal");
                }
            }
        }
    }
    // A sphere's cut shell: about its area over the cell's area, times 1–2.
    let shell = 4.0 * std::f64::consts::PI * r * r / (d * d);
    assert!(
        cut as f64 > shell && (cut as f64) < 2.5 * shell,
        "{cut} vs {shell}"
    );
    let (eb, es) = (C64::new(EPS_B, 0.0), C64::new(2.0, 0.8).powi(2));
    let mut t = Anisotropy::default();
    raster.anisotropy_into(eb, &[es], &mut t);
    assert_eq!(t.terms.len(), cut);
    for iz in 0..n {
        for term in t.slice(iz) {
            let i = term.index as usize;
            let f = raster.fractions[0][[iz, i / n, i % n]];
            let want = 1.0 / (f / es + (1.0 - f) / eb) - (f * es + (1.0 - f) * eb);
            assert!((term.delta - want).norm() < 1e-12);
            // Passive across the surface too: Im ε_n ≥ 0.
            assert!((f * es + (1.0 - f) * eb + term.delta).im >= 0.0);
        }
    }
}

/// A 400 nm cell of one sphere (radius 120 nm) at `centre` on `n³` cells,
/// rasterised: its ε grid and its tensor.
fn sphere_layer(centre: [f64; 3], n: usize, eps_s: C64) -> (ndarray::Array3<C64>, Anisotropy) {
    let (l, h) = (400.0, 400.0);
    let geom = Geometry {
        size_nm: [l, l, h],
        particles: vec![Particle {
            species: 0,
            spheres: vec![Sphere {
                center: centre,
                radius: 120.0,
            }],
        }],
        stats: Default::default(),
    };
    let raster = rasterize(&geom, &Grid::new(n, n, n, [l, l, h]).unwrap(), 4);
    let eb = C64::new(EPS_B, 0.0);
    let mut eps = ndarray::Array3::zeros((n, n, n));
    raster.epsilon_into(eb, &[eps_s], &mut eps);
    let mut t = Anisotropy::default();
    raster.anisotropy_into(eb, &[eps_s], &mut t);
    (eps, t)
}

fn solve_sphere(
    (eps, t): &(ndarray::Array3<C64>, Anisotropy),
    pol: Linear,
    azimuth: f64,
    method: Method,
) -> solver::Solution {
    let n = eps.dim().0;
    let lat = Problem::lattice([n, n, n], [400.0, 400.0, 400.0], 550.0, 35.0, azimuth);
    let p = Problem {
        lattice: lat,
        eps,
        tensor: Some(t),
        eps_binder: EPS_B,
        wave: Wave::Vector {
            polarisation: pol.into(),
            azimuth_deg: azimuth,
        },
    };
    solver::solve(&p, method, &tight(Background::Binder)).expect("solve")
}

/// With the tensor: energy balance to solver tolerance in s and p, every
/// method agreeing; the cell with x and y exchanged and lit at azimuth 90°
/// gives the same totals (the normals turn with the cell); the tensor of
/// the cell mirrored in z is the original's [`Anisotropy::flipped`] (the
/// grid lit from below); the same bits on 1 and 2 threads.
#[test]
fn a_sphere_lattice_with_its_tensor_balances_rotates_and_mirrors() {
    let n = 16;
    let eps_s = C64::new(2.9, 0.6);
    let centre = [190.0, 215.0, 205.0];
    let layer = sphere_layer(centre, n, eps_s);
    assert!(layer.1.terms.len() > 100);
    let swapped = sphere_layer([centre[1], centre[0], centre[2]], n, eps_s);
    for pol in [Linear::S, Linear::P] {
        let mut totals = vec![];
        for method in [Method::BiCgStab, Method::Gmres, Method::TimeMarching] {
            let ff = efficiencies(&solve_sphere(&layer, pol, 0.0, method));
            assert!(ff.energy_balance.abs() < 1e-7, "{pol:?} {method}");
            totals.push((ff.total_reflectance, ff.absorption));
        }
        for t in &totals[1..] {
            assert!((t.0 - totals[0].0).abs() < 1e-7 && (t.1 - totals[0].1).abs() < 1e-7);
        }
        // x ↔ y mirrors the cell: lit at azimuth 90° it is the same
        // problem, powers unchanged.
        let ff = efficiencies(&solve_sphere(&swapped, pol, 90.0, Method::BiCgStab));
        assert!(
            (ff.total_reflectance - totals[0].0).abs() < 1e-8,
            "{pol:?} R"
        );
        assert!((ff.absorption - totals[0].1).abs() < 1e-8, "{pol:?} A");
    }
    let mirrored = sphere_layer([centre[0], centre[1], 400.0 - centre[2]], n, eps_s);
    let flipped = layer.1.flipped();
    assert_eq!(mirrored.1.offsets, flipped.offsets);
    for (a, b) in mirrored.1.terms.iter().zip(&flipped.terms) {
        assert_eq!(a.index, b.index);
        assert!((a.delta - b.delta).norm() < 1e-12);
        assert!((0..3).all(|k| (a.axis[k] - b.axis[k]).abs() < 1e-12));
    }
    let run = || {
        let s = solve_sphere(&layer, Linear::P, 10.0, Method::BiCgStab);
        (s.field, s.absorption)
    };
    let one = common::threads::on_threads(1, run);
    let two = common::threads::on_threads(2, run);
    assert_eq!(one.1.to_bits(), two.1.to_bits());
    assert!(one.0.iter().zip(two.0.iter()).all(|(a, b)| a == b));
}
