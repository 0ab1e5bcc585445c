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

/// A fragment of `size` holding one sphere.
fn one_sphere(size: [f64; 3], center: [f64; 3], radius: f64) -> Geometry {
    Geometry {
        size_nm: size,
        particles: vec![Particle {
            species: 0,
            spheres: vec![Sphere { center, radius }],
        }],
        stats: Default::default(),
    }
}

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
    let geom = one_sphere([l, l, h], centre, r);
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
    let mut eps_grid = ndarray::Array3::zeros((n, n, n));
    raster.epsilon_into(eb, &[es], &mut eps_grid);
    let before = eps_grid.clone();
    let mut t = Anisotropy::default();
    raster.anisotropy_into(eb, &[es], &[], true, &mut eps_grid, &mut t);
    assert_eq!(eps_grid, before, "no crystal: the scalar part is unchanged");
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
    let geom = one_sphere([l, l, h], centre, 120.0);
    let raster = rasterize(&geom, &Grid::new(n, n, n, [l, l, h]).unwrap(), 4);
    let eb = C64::new(EPS_B, 0.0);
    let mut eps = ndarray::Array3::zeros((n, n, n));
    raster.epsilon_into(eb, &[eps_s], &mut eps);
    let mut t = Anisotropy::default();
    raster.anisotropy_into(eb, &[eps_s], &[], true, &mut eps, &mut t);
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

/// A uniaxial crystal filling the layer, its optic axis along z or x: the
/// tensor terms `(ε_e − ε_o) ĉĉᵀ` on every voxel against the exact
/// anisotropic transfer matrix in p (ε_xx, ε_zz) and s (ε_yy = ε_o), at
/// second order in the z cell; the orientation average instead is far off.
#[test]
fn a_uniaxial_crystal_slab_matches_the_anisotropic_transfer_matrix() {
    use inksim::raster::anisotropy::Term;
    // Rutile near 550 nm: n_o 2.65, n_e 2.95, a little loss.
    let (eo, ee) = (C64::new(2.65, 0.01).powi(2), C64::new(2.95, 0.01).powi(2));
    let h = 300.0;
    for axis in [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]] {
        let (exx, ezz) = if axis[2] == 1.0 { (eo, ee) } else { (ee, eo) };
        let (rp, _) = common::airy::tmm_p_uniaxial(&[(exx, ezz, h)], 550.0, 50.0);
        let (rs, _) = tmm(&[(eo, h)], 550.0, 50.0);
        let mut errors = vec![];
        for nz in [60, 120] {
            let eps = ndarray::Array3::from_elem((nz, 2, 2), eo);
            let mut t = Anisotropy::empty(nz, (2, 2));
            for k in 0..nz {
                for index in 0..4 {
                    t.terms.push(Term {
                        index,
                        axis,
                        delta: ee - eo,
                    });
                }
                t.offsets[k + 1] = t.terms.len();
            }
            let lat = Problem::lattice([2, 2, nz], [300.0, 300.0, h], 550.0, 50.0, 0.0);
            let solve = |pol: Linear, tensor: Option<&Anisotropy>, eps| {
                let p = Problem {
                    lattice: lat,
                    eps,
                    tensor,
                    eps_binder: EPS_B,
                    wave: Wave::Vector {
                        polarisation: pol.into(),
                        azimuth_deg: 0.0,
                    },
                };
                let sol = solver::solve(&p, Method::Auto, &tight(Background::Binder)).unwrap();
                let ff = efficiencies(&sol);
                assert!(ff.energy_balance.abs() < 1e-8, "{}", ff.energy_balance);
                ff.total_reflectance
            };
            let p = solve(Linear::P, Some(&t), &eps);
            let s = solve(Linear::S, Some(&t), &eps);
            errors.push(((p - rp).abs(), (s - rs).abs()));
            if nz == 120 {
                let mean = ndarray::Array3::from_elem((nz, 2, 2), (2.0 * eo + ee) / 3.0);
                let avg = solve(Linear::P, None, &mean);
                assert!(
                    (avg - rp).abs() > 20.0 * (p - rp).abs(),
                    "the average {avg} should be off against {p} (exact {rp})"
                );
            }
        }
        eprintln!("axis {axis:?}: p, s errors {errors:?}");
        assert!(errors[1].0 < 1e-3 && errors[1].1 < 1e-3, "{errors:?}");
        assert!(
            errors[0].0 / errors[1].0 > 3.0,
            "p not second order: {errors:?}"
        );
    }
}

/// Crystal grains rasterised with their axes: each grain's shares add up
/// to its species' fraction, its terms are `f (ε_e − ε_o) ĉĉᵀ` and the
/// scalar part moves by `f (ε_o − ε̄)`; ε_o = ε_e leaves the grid isotropic
/// and unchanged; the axes of many spheres are isotropic (⟨ĉĉᵀ⟩ = I/3); a
/// two-sphere grain's axis is along it.
#[test]
fn crystal_grains_carry_their_axis_into_the_tensor() {
    use inksim::raster::rasterize_keeping_axes;
    let (l, h) = (1000.0, 1000.0);
    let mut particles = vec![];
    for i in 0..8 {
        for j in 0..8 {
            for k in 0..8 {
                let c = [i, j, k].map(|v| 62.5 + 125.0 * v as f64);
                particles.push(Particle {
                    species: 0,
                    spheres: vec![Sphere {
                        center: c,
                        radius: 40.0,
                    }],
                });
            }
        }
    }
    let geom = Geometry {
        size_nm: [l, l, h],
        particles,
        stats: Default::default(),
    };
    let n = 40;
    let grid = Grid::new(n, n, n, [l, l, h]).unwrap();
    let raster = rasterize_keeping_axes(&geom, &grid, 4, &[true]);
    // Shares add up to the fraction, voxel by voxel.
    for iz in 0..n {
        let mut sum = ndarray::Array2::<f64>::zeros((n, n));
        for g in &raster.crystal[iz] {
            sum[[g.index as usize / n, g.index as usize % n]] += g.share;
        }
        let f = raster.fractions[0].index_axis(ndarray::Axis(0), iz);
        assert!(sum.iter().zip(f.iter()).all(|(a, b)| (a - b).abs() < 1e-12));
    }
    // One axis per grain, isotropic over the 512 grains.
    let mut axes: Vec<[f64; 3]> = raster.crystal.iter().flatten().map(|g| g.axis).collect();
    axes.sort_by(|a, b| a.partial_cmp(b).unwrap());
    axes.dedup();
    assert_eq!(axes.len(), 512);
    for k in 0..3 {
        let m: f64 = axes.iter().map(|a| a[k] * a[k]).sum::<f64>() / 512.0;
        // ⟨c_k²⟩ = 1/3 with s.d. √(4/45/512) = 0.013.
        assert!((m - 1.0 / 3.0).abs() < 0.05, "⟨c{k}²⟩ = {m}");
    }
    let eb = C64::new(EPS_B, 0.0);
    let (eo, ee) = (C64::new(7.0, 0.02), C64::new(8.7, 0.03));
    let mean = (2.0 * eo + ee) / 3.0;
    let mut eps = ndarray::Array3::zeros((n, n, n));
    raster.epsilon_into(eb, &[mean], &mut eps);
    let before = eps.clone();
    let mut t = Anisotropy::default();
    raster.anisotropy_into(eb, &[mean], &[Some((eo, ee))], false, &mut eps, &mut t);
    for iz in 0..n {
        for term in t.slice(iz) {
            let i = term.index as usize;
            let f = raster.fractions[0][[iz, i / n, i % n]];
            assert!((term.delta - f * (ee - eo)).norm() < 1e-12);
            let moved = eps[[iz, i / n, i % n]] - before[[iz, i / n, i % n]];
            assert!((moved - f * (eo - mean)).norm() < 1e-12);
        }
    }
    let grain_voxels = raster.fractions[0].iter().filter(|&&f| f > 0.0).count();
    assert_eq!(t.terms.len(), grain_voxels);
    // No birefringence: an isotropic tensor on the average, unchanged.
    let mut same = before.clone();
    raster.anisotropy_into(eb, &[eo], &[Some((eo, eo))], false, &mut same, &mut t);
    assert!(t.terms.iter().all(|t| t.delta.norm() == 0.0));
    assert!(same
        .iter()
        .zip(&before)
        .all(|(a, b)| (a - b).norm() < 1e-12));
    // A rod's axis is along it.
    let rod = Geometry {
        size_nm: [400.0, 400.0, 400.0],
        particles: vec![Particle {
            species: 0,
            spheres: vec![
                Sphere {
                    center: [150.0, 200.0, 150.0],
                    radius: 40.0,
                },
                Sphere {
                    center: [250.0, 200.0, 250.0],
                    radius: 40.0,
                },
            ],
        }],
        stats: Default::default(),
    };
    let r = rasterize_keeping_axes(
        &rod,
        &Grid::new(20, 20, 20, rod.size_nm).unwrap(),
        4,
        &[true],
    );
    let a = r.crystal.iter().flatten().next().unwrap().axis;
    let s = 0.5f64.sqrt();
    assert!((a[0] - s).abs() < 1e-12 && a[1].abs() < 1e-12 && (a[2] - s).abs() < 1e-12);
}

/// A run of library rutile grains: in Maxwell the plan says each grain is a
/// tensor and every solve's record counts its anisotropic cut voxels and
/// crystal-grain voxels (energy balance held); in Helmholtz the plan says
/// orientation average and no solve has a tensor.
#[test]
fn a_rutile_run_takes_a_tensor_per_grain_in_maxwell_only() {
    use common::scene::{PigmentToml, SceneToml};
    let dir = tempfile::tempdir().unwrap();
    let base = SceneToml::grains()
        .seed(5)
        .thickness_nm(300.0)
        .fragment_nm(400.0)
        .pigment(PigmentToml::library("rutile").pvc(0.1).diameter_nm(120.0))
        .grid_n([16, 16, 12])
        .wavelengths_nm(&[550.0])
        .polar_deg(&[0.0])
        .tolerance(1e-6)
        .outputs(&["tile"])
        .output(dir.path(), "r");
    for (equation, tensor) in [("maxwell", true), ("helmholtz", false)] {
        let scene = base.clone().equation(equation).scene(dir.path());
        let plan = inksim::pipeline::RunPlan::of(&scene).lines.join("\n");
        let want = if tensor {
            "as a tensor per grain"
        } else {
            "orientation average"
        };
        assert!(plan.contains(want), "{equation}: {plan}");
        // The memory model counts the cut voxels' normals and terms, and
        // the crystal grains' shares and terms, in Maxwell only.
        use inksim::pipeline::memory;
        let crystal = memory::crystal_share(&scene);
        assert_eq!(crystal > 0.1, tensor, "crystal share {crystal}");
        let averaged = base
            .clone()
            .equation(equation)
            .set("grid.voxel_permittivity", "average")
            .scene(dir.path());
        let cut = if tensor {
            memory::CUT_VOXEL_BYTES * memory::cut_share(&scene)
        } else {
            0.0
        };
        let voxels = (16 * 16 * 12) as f64;
        let diff = memory::estimate_bytes(&scene) - memory::estimate_bytes(&averaged);
        assert!(
            (diff - voxels * cut).abs() < 1e-6,
            "{diff} vs {}",
            voxels * cut
        );
        let rep = inksim::pipeline::run(&scene).unwrap();
        for e in &rep.entries {
            assert!(e.efficiencies.energy_balance.abs() < 1e-4);
            let note = &e.record.note;
            if tensor {
                let count = |what: &str| -> usize {
                    let before = note.split(what).next().unwrap();
                    before.rsplit(' ').next().unwrap().parse().unwrap()
                };
                assert!(count(" cut voxels") > 0, "{note}");
                assert!(count(" crystal-grain voxels") > 100, "{note}");
            } else {
                assert!(!note.contains("tensor"), "{note}");
            }
        }
    }
}
