//! The Krylov methods' fused operator application against its parts.
//!
//! `System::apply_pa_sums` makes the source slice by slice inside the
//! forward transform and subtracts and sums slice by slice inside the
//! inverse one. It must give what the separate steps give: `P A x` by
//! `apply_a_shifted` and `precondition`, then `‖·‖²` and `⟨·, w⟩` by the
//! storage's reductions, for both equations (Maxwell with the tensor of a
//! sphere's cut voxels), both backgrounds and both field precisions.

use inksim::config::{Background, Linear};
use inksim::geometry::{Geometry, Particle, Sphere};
use inksim::raster::{rasterize, Anisotropy, Grid};
use inksim::solver::storage::{dot, norm_sqr, Storage};
use inksim::solver::{Problem, System, Wave};
use ndarray::Array3;
use num_complex::{Complex32 as C32, Complex64 as C64};

mod common;
use common::layers::EPS_B;

/// One sphere of a red-like pigment in a 400 nm cube, its ε grid and the
/// tensor of its cut voxels.
fn sphere(n: usize) -> (Array3<C64>, Anisotropy) {
    let l = 400.0;
    let geom = Geometry {
        size_nm: [l, l, l],
        particles: vec![Particle {
            species: 0,
            spheres: vec![Sphere {
                center: [190.0, 215.0, 205.0],
                radius: 120.0,
            }],
        }],
        stats: Default::default(),
    };
    let raster = rasterize(&geom, &Grid::new(n, n, n, [l, l, l]).unwrap(), 4);
    let (eb, es) = (C64::new(EPS_B, 0.0), C64::new(1.4, 0.6).powi(2));
    let mut eps = Array3::zeros((n, n, n));
    raster.epsilon_into(eb, &[es], &mut eps);
    let mut t = Anisotropy::default();
    raster.anisotropy_into(eb, &[es], &[], true, &mut eps, &mut t);
    assert!(!t.terms.is_empty(), "the sphere has cut voxels");
    (eps, t)
}

fn check<S: Storage + Send + Sync>(p: &Problem, background: Background) {
    let sys = System::new(p, background).expect("system");
    let mut scr = sys.scratch();
    let dim = sys.unknown_dim();
    let field = |a: f64, b: f64| {
        Array3::from_shape_fn(dim, |(k, j, i)| {
            S::store(C64::new(
                (a * (i + 2 * j) as f64 + 0.3 * k as f64).sin(),
                (b * (k + j) as f64 - 0.1 * i as f64).cos(),
            ))
        })
    };
    let (x, w) = (field(0.37, 0.21), field(0.11, 0.53));
    let mut want = Array3::<S>::default(dim);
    sys.apply_a_shifted(&mut scr, &x, &mut want);
    sys.precondition(&mut want);
    let mut got = Array3::<S>::default(dim);
    let (nn, d) = sys.apply_pa_sums(&mut scr, &x, &mut got, &w);
    let scale = norm_sqr(&want).sqrt();
    let diff = want
        .iter()
        .zip(&got)
        .map(|(a, b)| (a.load() - b.load()).norm_sqr())
        .sum::<f64>()
        .sqrt();
    // Equal to rounding (one rounding of the stored value in f32).
    let tol = if std::mem::size_of::<S>() == 16 {
        1e-12
    } else {
        1e-7
    };
    assert!(
        diff <= tol * scale,
        "{background:?}: |fused − parts| {diff:e} of {scale:e}"
    );
    assert!((nn - norm_sqr(&got)).abs() <= 1e-12 * nn);
    let dw = dot(&got, &w);
    assert!((d - dw).norm() <= 1e-12 * nn.sqrt() * norm_sqr(&w).sqrt());
    // And the sum `⟨out, x⟩` with w the input itself (BiCGStab's ⟨t, s⟩).
    let mut again = Array3::<S>::default(dim);
    let (_, dx) = sys.apply_pa_sums(&mut scr, &x, &mut again, &x);
    assert!((dx - dot(&again, &x)).norm() <= 1e-12 * nn.sqrt() * norm_sqr(&x).sqrt());
}

#[test]
fn the_fused_application_equals_its_parts() {
    let n = 12;
    let (eps, tensor) = sphere(n);
    let lattice = Problem::lattice([n, n, n], [400.0, 400.0, 400.0], 480.0, 35.0, 20.0);
    let waves = [
        (Wave::Scalar, None),
        (
            Wave::Vector {
                polarisation: Linear::P.into(),
                azimuth_deg: 20.0,
            },
            Some(&tensor),
        ),
    ];
    for (wave, tensor) in waves {
        let p = Problem {
            lattice,
            eps: &eps,
            tensor,
            eps_binder: EPS_B,
            wave,
        };
        for background in [Background::Mean, Background::Binder] {
            check::<C64>(&p, background);
            check::<C32>(&p, background);
        }
    }
}
