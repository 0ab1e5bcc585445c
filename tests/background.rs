//! The mean background (`solver.background = "mean"`) solves the same
//! discrete equation as the binder background: the same order amplitudes
//! and absorption to solver tolerance on random layers, absorbing and
//! lossless (where its loss floor acts), and a homogeneous layer is its own
//! background (solved by the first residual).
use inksim::config::{Background, Method};
use inksim::optics::farfield::efficiencies;
use inksim::solver::{self, Controls, Problem, Solution, System};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use rand::{Rng, SeedableRng};

mod common;
use common::layers::{in_binder, tight, EPS_B};

/// Voxels of random ε: binder plus Re Δε in [−0.6, 1.6] and Im ε in
/// [0, max_im].
fn random_layer(dim: (usize, usize, usize), max_im: f64, seed: u64) -> Array3<C64> {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    Array3::from_shape_simple_fn(dim, || {
        C64::new(
            EPS_B + rng.gen_range(-0.6..1.6),
            if max_im > 0.0 {
                rng.gen_range(0.0..max_im)
            } else {
                0.0
            },
        )
    })
}

/// Largest difference of the order amplitudes r_mn, t_mn of two solutions.
fn amplitude_difference(a: &Solution, b: &Solution) -> f64 {
    let d = |x: &ndarray::Array2<C64>, y: &ndarray::Array2<C64>| {
        x.iter()
            .zip(y)
            .map(|(p, q)| (p - q).norm())
            .fold(0.0, f64::max)
    };
    d(&a.r, &b.r).max(d(&a.t, &b.t))
}

#[test]
fn mean_background_gives_the_binder_solution_on_random_layers() {
    let size = [600.0, 500.0, 400.0];
    for (max_im, seed) in [(0.8, 1), (0.0, 2)] {
        let eps = random_layer((40, 12, 16), max_im, seed);
        let lat = Problem::lattice([16, 12, 40], size, 500.0, 30.0, 20.0);
        let p = in_binder(lat, &eps);
        let binder = solver::solve(&p, Method::BiCgStab, &tight(Background::Binder)).unwrap();
        let fb = efficiencies(&binder);
        for method in [Method::BiCgStab, Method::Gmres, Method::Auto] {
            let mean = solver::solve(&p, method, &tight(Background::Mean)).unwrap();
            assert!(
                mean.record.note.contains("mean background"),
                "{}",
                mean.record.note
            );
            let fm = efficiencies(&mean);
            let amp = amplitude_difference(&mean, &binder);
            let da = (fm.absorption - fb.absorption).abs();
            eprintln!(
                "Im ε ≤ {max_im}, {method}: |Δr|, |Δt| ≤ {amp:.1e}, |ΔA| {da:.1e}, \
                 applications {} (binder {}), balance {:.1e}",
                mean.record.operator_applications,
                binder.record.operator_applications,
                fm.energy_balance
            );
            assert!(
                amp < 1e-8,
                "{method} Im ε ≤ {max_im}: amplitudes differ by {amp}"
            );
            assert!(
                da < 1e-8,
                "{method} Im ε ≤ {max_im}: absorption differs by {da}"
            );
            assert!(fm.energy_balance.abs() < 1e-8, "{}", fm.energy_balance);
        }
    }
}

#[test]
fn the_mean_background_is_the_layer_mean_with_a_loss_floor() {
    let eps = random_layer((20, 8, 8), 0.5, 3);
    let mean = eps.iter().sum::<C64>() / eps.len() as f64;
    let lat = Problem::lattice([8, 8, 20], [400.0, 400.0, 200.0], 500.0, 0.0, 0.0);
    let p = in_binder(lat, &eps);
    let sys = System::new(&p, Background::Mean).unwrap();
    assert_eq!(sys.background(), Background::Mean);
    // Im ⟨ε⟩ ≈ 0.25 is above the floor 0.1 · max|ε − ⟨ε⟩|² (≈ 0.13 at most).
    let rad = eps.iter().map(|e| (e - mean).norm()).fold(0.0, f64::max);
    assert!(solver::MEAN_LOSS_FLOOR * rad * rad < mean.im);
    assert!((sys.background_eps() - mean).norm() < 1e-14);
    // Lossless: the floor sets the imaginary part.
    let clear = eps.mapv(|e| C64::new(e.re, 0.0));
    let p = Problem { eps: &clear, ..p };
    let sys = System::new(&p, Background::Mean).unwrap();
    let m = clear.iter().sum::<C64>() / clear.len() as f64;
    let rad = clear.iter().map(|e| (e - m).norm()).fold(0.0, f64::max);
    let want = C64::new(m.re, solver::MEAN_LOSS_FLOOR * rad * rad);
    assert!((sys.background_eps() - want).norm() < 1e-12);
}

#[test]
fn a_homogeneous_layer_is_solved_by_its_own_background() {
    let eps_layer = C64::new(2.3, 0.05);
    let eps = Array3::from_elem((100, 4, 4), eps_layer);
    let lat = Problem::lattice([4, 4, 100], [800.0, 800.0, 1000.0], 500.0, 50.0, 0.0);
    let p = in_binder(lat, &eps);
    let binder = solver::solve(&p, Method::BiCgStab, &tight(Background::Binder)).unwrap();
    let mean = solver::solve(&p, Method::BiCgStab, &tight(Background::Mean)).unwrap();
    // V' = 0: the first residual is zero, the answer is u_s itself.
    assert_eq!(mean.record.iterations, 0, "{}", mean.record.note);
    assert_eq!(mean.record.operator_applications, 1);
    assert!(mean.record.residual < 1e-12, "{}", mean.record.residual);
    let amp = amplitude_difference(&mean, &binder);
    assert!(amp < 1e-9, "amplitudes differ by {amp}");
}

#[test]
fn time_marching_keeps_the_cbs_shift_on_the_mean_background() {
    let eps = random_layer((20, 8, 8), 0.5, 4);
    let lat = Problem::lattice([8, 8, 20], [400.0, 400.0, 200.0], 500.0, 0.0, 0.0);
    let p = in_binder(lat, &eps);
    let c = Controls {
        tolerance: 1e-8,
        ..tight(Background::Mean)
    };
    let tm = solver::solve(&p, Method::TimeMarching, &c).unwrap();
    assert!(tm.record.note.contains("ε_r ="), "{}", tm.record.note);
    let bi = solver::solve(&p, Method::BiCgStab, &c).unwrap();
    assert!(
        bi.record.note.contains("mean background"),
        "{}",
        bi.record.note
    );
    let amp = amplitude_difference(&tm, &bi);
    assert!(amp < 1e-6, "amplitudes differ by {amp}");
}
