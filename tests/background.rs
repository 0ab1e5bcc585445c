//! The mean background (`solver.background = "mean"`) solves the same
//! discrete equation as the binder background: the same order amplitudes
//! and absorption to solver tolerance on random layers, absorbing and
//! lossless (where its loss floor acts), and a homogeneous layer is its own
//! background (solved by the first residual).
use inksim::config::{Background, Method};
use inksim::optics::farfield::efficiencies;
use inksim::solver::{self, Controls, Problem, ShiftParams, Solution, System};
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

/// Applications BiCGStab needs on `p` with the shift parameters `params`,
/// and its solution.
fn applications_with(p: &Problem, params: ShiftParams, tolerance: f64) -> (usize, Solution) {
    use inksim::solver::methods::bicgstab::BiCgStab;
    use inksim::solver::{Field, Solver};
    let mut sys = System::with_params(p, params).unwrap();
    let mut scr = sys.scratch();
    let mut u = Field::F64(Array3::zeros(sys.unknown_dim()));
    sys.set_start_field(&mut u);
    let ctl = Controls {
        tolerance,
        ..tight(Background::Mean)
    };
    let o = BiCgStab::DEFAULT
        .run(&mut sys, &mut scr, &mut u, &ctl)
        .unwrap();
    let record = o.record(sys.background(), 0.0);
    (o.applications, sys.into_solution(scr, u, record))
}

/// Lossless spheres of permittivity `eps_grain`, 200 nm across, in binder on
/// a 20 × 20 × 30 grid of 600 × 600 × 600 nm.
fn four_grains(eps_grain: C64) -> (Array3<C64>, [f64; 3]) {
    let (nx, nz) = (20, 30);
    let size = [600.0, 600.0, 600.0];
    let centres = [
        [150.0, 150.0, 150.0],
        [450.0, 300.0, 300.0],
        [200.0, 450.0, 450.0],
        [480.0, 80.0, 470.0],
    ];
    let eps = Array3::from_shape_fn((nz, nx, nx), |(k, j, i)| {
        let x = [
            (i as f64 + 0.5) * size[0] / nx as f64,
            (j as f64 + 0.5) * size[1] / nx as f64,
            (k as f64 + 0.5) * size[2] / nz as f64,
        ];
        let inside = centres.iter().any(|c| {
            (0..3)
                .map(|a| {
                    let d = (x[a] - c[a]).abs();
                    let d = if a < 2 { d.min(size[a] - d) } else { d };
                    d * d
                })
                .sum::<f64>()
                < 100.0 * 100.0
        });
        if inside {
            eps_grain
        } else {
            C64::new(EPS_B, 0.0)
        }
    });
    (eps, size)
}

/// Maxwell's equations cap the mean background's loss floor at
/// [`solver::MEAN_LOSS_CAP_MAXWELL`] `· max|ε − ⟨ε⟩|`: on lossless grains
/// of rutile's index the cap sets the background, and gives the same answer
/// as the scalar equation's uncapped floor in fewer applications; on grains
/// of low contrast (below 1.5) the floor is the scalar one; the scalar
/// equation keeps its floor.
#[test]
fn maxwell_caps_the_loss_floor_and_it_pays_on_high_index_grains() {
    use inksim::config::Linear;
    use inksim::solver::Wave;
    let vector = Wave::Vector {
        polarisation: Linear::S.into(),
        azimuth_deg: 0.0,
    };
    let mean_and_rad = |eps: &Array3<C64>| {
        let m = eps.iter().sum::<C64>() / eps.len() as f64;
        (m, eps.iter().map(|e| (e - m).norm()).fold(0.0, f64::max))
    };
    let (rutile, size) = four_grains(C64::new(7.3, 0.0));
    let lat = Problem::lattice([20, 20, 30], size, 550.0, 8.0, 0.0);
    let p = Problem {
        wave: vector,
        ..in_binder(lat, &rutile)
    };
    let (m, rad) = mean_and_rad(&rutile);
    assert!(rad > 1.5, "{rad}");
    let sys = System::new(&p, Background::Mean).unwrap();
    let capped = C64::new(m.re, solver::MEAN_LOSS_CAP_MAXWELL * rad);
    assert!((sys.background_eps() - capped).norm() < 1e-12);
    let scalar = System::new(&in_binder(lat, &rutile), Background::Mean).unwrap();
    let uncapped = C64::new(m.re, solver::MEAN_LOSS_FLOOR * rad * rad);
    assert!((scalar.background_eps() - uncapped).norm() < 1e-12);

    let maxwell = ShiftParams::for_wave(Background::Mean, &vector);
    let (n_capped, a) = applications_with(&p, maxwell, 1e-8);
    let (n_uncapped, b) = applications_with(&p, ShiftParams::of(Background::Mean), 1e-8);
    let amp = amplitude_difference(&a, &b);
    eprintln!(
        "lossless ε 7.3 grains: {n_capped} applications with the cap, {n_uncapped} \
         without; amplitudes within {amp:.1e}"
    );
    assert!(amp < 1e-6, "{amp}");
    assert!(
        (n_capped as f64) < 0.8 * n_uncapped as f64,
        "{n_capped} vs {n_uncapped}"
    );

    // Low contrast (lossless grains of ε 3): the cap does not act.
    let (low, _) = four_grains(C64::new(3.0, 0.0));
    let (m, rad) = mean_and_rad(&low);
    assert!(rad < 1.5, "{rad}");
    let p = Problem {
        wave: vector,
        ..in_binder(lat, &low)
    };
    let sys = System::new(&p, Background::Mean).unwrap();
    let want = C64::new(m.re, solver::MEAN_LOSS_FLOOR * rad * rad);
    assert!((sys.background_eps() - want).norm() < 1e-12);
}

/// A relief's air: the grains of [`four_grains`] under a binder surface
/// that undulates 10–90 nm below the top face, the grains' caps standing
/// in the air above it (as `layer.relief_fraction` makes them).
fn relief(eps_grain: C64) -> (Array3<C64>, [f64; 3]) {
    air_above(eps_grain, |wave| 50.0 + 40.0 * wave)
}

/// The grains of [`four_grains`] with air for binder above the depth
/// `depth(sin 2πx cos 2πy)` (nm below the top face; x, y in periods).
fn air_above(eps_grain: C64, depth: impl Fn(f64) -> f64) -> (Array3<C64>, [f64; 3]) {
    let (mut eps, size) = four_grains(eps_grain);
    let (nz, ny, nx) = eps.dim();
    let tau = 2.0 * std::f64::consts::PI;
    for ((k, j, i), e) in eps.indexed_iter_mut() {
        let (x, y) = ((i as f64 + 0.5) / nx as f64, (j as f64 + 0.5) / ny as f64);
        let z = (k as f64 + 0.5) * size[2] / nz as f64;
        if z < depth((tau * x).sin() * (tau * y).cos()) && *e == C64::new(EPS_B, 0.0) {
            *e = C64::new(1.0, 0.0);
        }
    }
    (eps, size)
}

/// BiCGStab to 1e-10 on the mean background with the shift parameters
/// `better` and `worse`: both give the binder background's solution
/// `binder` (amplitudes and absorption to 1e-8, energy balanced), and
/// `better` takes fewer than 0.8× the applications of `worse`.
fn pays_against(
    p: &Problem,
    better: ShiftParams,
    worse: ShiftParams,
    binder: &Solution,
    what: &str,
) {
    let (n_better, a) = applications_with(p, better, 1e-10);
    let (n_worse, b) = applications_with(p, worse, 1e-10);
    let amp = amplitude_difference(&a, binder).max(amplitude_difference(&b, binder));
    let (fa, fb) = (efficiencies(&a), efficiencies(binder));
    eprintln!(
        "{what}: {n_better} applications against {n_worse}; amplitudes within {amp:.1e} of the \
         binder background's, |ΔA| {:.1e}",
        (fa.absorption - fb.absorption).abs()
    );
    assert!(amp < 1e-8, "{what}: {amp}");
    assert!((fa.absorption - fb.absorption).abs() < 1e-8, "{what}");
    assert!(
        fa.energy_balance.abs() < 1e-8,
        "{what}: {}",
        fa.energy_balance
    );
    assert!(
        (n_better as f64) < 0.8 * n_worse as f64,
        "{what}: {n_better} vs {n_worse}"
    );
}

/// [`pays_against`] for the layered zones of `params` against one mean for
/// every cell.
fn layering_pays(p: &Problem, params: ShiftParams, binder: &Solution, what: &str) {
    let one = ShiftParams {
        layered_air: false,
        ..params
    };
    pays_against(
        p,
        params,
        one,
        binder,
        &format!("{what}, layered vs one mean"),
    );
}

/// The cells holding air at a face take their own lateral mean as the
/// background (`ShiftParams::layered_air`): the same solution as the binder
/// background to solver tolerance in both equations, with the air on top
/// and (a layer lit from below, solved upside down) at the bottom, in fewer
/// applications than one mean for every cell.
#[test]
fn a_reliefs_air_takes_its_own_mean_and_it_pays() {
    use inksim::config::Linear;
    use inksim::solver::{air_cells, Wave};
    let (top, size) = relief(C64::new(1.96, 1.2));
    let mut bottom = top.clone();
    bottom.invert_axis(ndarray::Axis(0));
    let bottom = bottom.as_standard_layout().to_owned();
    assert_eq!(air_cells(&top), (4, 0));
    assert_eq!(air_cells(&bottom), (0, 4));
    let vector = Wave::Vector {
        polarisation: Linear::P.into(),
        azimuth_deg: 0.0,
    };
    let lat = Problem::lattice([20, 20, 30], size, 450.0, 30.0, 0.0);
    for (eps, face) in [(&top, "top"), (&bottom, "bottom")] {
        for wave in [Wave::Scalar, vector] {
            let p = Problem {
                wave,
                ..in_binder(lat, eps)
            };
            let binder = solver::solve(&p, Method::BiCgStab, &tight(Background::Binder)).unwrap();
            let params = ShiftParams::for_wave(Background::Mean, &wave);
            let sys = System::with_params(&p, params).unwrap();
            assert!(
                sys.describe_background()
                    .contains(&format!("layered at the {face} over 4 cells holding air")),
                "{}",
                sys.describe_background()
            );
            layering_pays(&p, params, &binder, &format!("air at the {face}, {wave:?}"));
        }
    }
}

/// A porous layer: the grains of [`four_grains`] under a binder surface
/// draped 40–620 nm deep, so that the air's share falls from the top face
/// through the whole depth and reaches the bottom face in one column (as a
/// conformal film over a binder-starved layer leaves it).
fn porous(eps_grain: C64) -> (Array3<C64>, [f64; 3]) {
    air_above(eps_grain, |wave| 40.0 + 290.0 * (1.0 + wave))
}

/// Where air reaches through the whole layer, each face layers its outer
/// quarter of the cells (`solver::zone_cells`, whose tables the memory
/// model counts) and the cells between share one mean: the same solution as
/// the binder background's in both equations, in fewer applications than
/// one mean for every cell.
#[test]
fn a_porous_layers_faces_take_their_own_means_up_to_a_quarter_of_the_cells() {
    use inksim::config::Linear;
    use inksim::solver::{air_cells, zone_cells, Wave};
    let (eps, size) = porous(C64::new(1.96, 1.2));
    assert_eq!(air_cells(&eps), (15, 15));
    assert_eq!(zone_cells(&eps), (7, 7));
    let vector = Wave::Vector {
        polarisation: Linear::P.into(),
        azimuth_deg: 0.0,
    };
    let lat = Problem::lattice([20, 20, 30], size, 450.0, 30.0, 0.0);
    for wave in [Wave::Scalar, vector] {
        let p = Problem {
            wave,
            ..in_binder(lat, &eps)
        };
        let binder = solver::solve(&p, Method::BiCgStab, &tight(Background::Binder)).unwrap();
        let params = ShiftParams::for_wave(Background::Mean, &wave);
        let note = System::with_params(&p, params)
            .unwrap()
            .describe_background();
        for face in ["top", "bottom"] {
            assert!(
                note.contains(&format!(
                    "layered at the {face} over 7 of the 15 cells holding air"
                )),
                "{note}"
            );
        }
        layering_pays(&p, params, &binder, &format!("porous, {wave:?}"));
    }
}

/// Each layered cell takes the loss floor of the contrast left in it, and
/// the cells between the zones that of theirs (`ShiftParams::floor_per_zone`):
/// under a relief of weakly absorbing grains (the stand-ins at the edge of
/// their bands) the air's contrast, about 1.4, no longer sets the bulk's
/// loss. The same solution as the binder background's in both equations,
/// a smaller loss in the bulk, and fewer applications than one floor from
/// the largest contrast for every cell.
#[test]
fn a_reliefs_bulk_takes_the_loss_floor_of_its_own_contrast() {
    use inksim::config::Linear;
    use inksim::solver::Wave;
    let (eps, size) = relief(C64::new(1.96, 0.02));
    let vector = Wave::Vector {
        polarisation: Linear::S.into(),
        azimuth_deg: 0.0,
    };
    let lat = Problem::lattice([20, 20, 30], size, 400.0, 30.0, 0.0);
    for wave in [Wave::Scalar, vector] {
        let p = Problem {
            wave,
            ..in_binder(lat, &eps)
        };
        let binder = solver::solve(&p, Method::BiCgStab, &tight(Background::Binder)).unwrap();
        let own = ShiftParams::for_wave(Background::Mean, &wave);
        assert!(own.floor_per_zone, "the default");
        let largest = ShiftParams {
            floor_per_zone: false,
            ..own
        };
        let bulk_loss = |params| System::with_params(&p, params).unwrap().background_eps().im;
        let (own_loss, largest_loss) = (bulk_loss(own), bulk_loss(largest));
        eprintln!("{wave:?}: bulk loss {own_loss:.4} against {largest_loss:.4}");
        assert!(
            own_loss < 0.5 * largest_loss,
            "{own_loss} vs {largest_loss}"
        );
        pays_against(
            &p,
            own,
            largest,
            &binder,
            &format!("{wave:?}, a floor per zone vs the largest"),
        );
    }
}

/// A dilute layer: one lossless grain of ε 7.3 (200 nm across, about 2 % of
/// the 600 nm cube). The bulk's loss floor is scaled by its mean square
/// contrast against [`solver::MEAN_LOSS_DILUTE`] times the largest
/// contrast squared (closed form here: a grid of two values), and the
/// smaller floor gives the same answer as the binder background in fewer
/// applications than the whole floor, in both equations.
#[test]
fn a_dilute_layer_takes_the_share_of_the_loss_floor_its_grains_call_for() {
    use inksim::config::Linear;
    use inksim::solver::Wave;
    let (four, size) = four_grains(C64::new(7.3, 0.0));
    // Keep the first grain (centred at 150, 150, 150 nm) alone.
    let eps = Array3::from_shape_fn(four.dim(), |(k, j, i)| {
        if k < 15 && j < 10 && i < 10 {
            four[[k, j, i]]
        } else {
            C64::new(EPS_B, 0.0)
        }
    });
    let grain = eps.iter().filter(|e| e.re > 7.0).count();
    assert!(grain > 100, "{grain} grain voxels");
    let n = eps.len() as f64;
    let m = eps.iter().sum::<C64>() / n;
    let rad = eps.iter().map(|e| (e - m).norm()).fold(0.0, f64::max);
    let square = eps.iter().map(|e| (e - m).norm_sqr()).sum::<f64>() / n;
    let share = square / (solver::MEAN_LOSS_DILUTE * rad * rad);
    eprintln!("grain fraction {:.4}, share {share:.3}", grain as f64 / n);
    assert!(share < 0.5, "{share}");
    let vector = Wave::Vector {
        polarisation: Linear::S.into(),
        azimuth_deg: 0.0,
    };
    let lat = Problem::lattice([20, 20, 30], size, 550.0, 8.0, 0.0);
    for wave in [Wave::Scalar, vector] {
        let p = Problem {
            wave,
            ..in_binder(lat, &eps)
        };
        let own = ShiftParams::for_wave(Background::Mean, &wave);
        assert_eq!(own.mean_loss_dilute, solver::MEAN_LOSS_DILUTE);
        let whole = ShiftParams {
            mean_loss_dilute: 0.0,
            ..own
        };
        let floor = (own.mean_loss_floor * rad * rad).min(own.mean_loss_cap * rad);
        let loss = |params| System::with_params(&p, params).unwrap().background_eps();
        assert!((loss(whole) - C64::new(m.re, floor)).norm() < 1e-12);
        assert!((loss(own) - C64::new(m.re, share * floor)).norm() < 1e-12);
        let binder = solver::solve(&p, Method::BiCgStab, &tight(Background::Binder)).unwrap();
        let (n_own, a) = applications_with(&p, own, 1e-8);
        let (n_whole, b) = applications_with(&p, whole, 1e-8);
        let (da, db) = (
            amplitude_difference(&a, &binder),
            amplitude_difference(&b, &binder),
        );
        eprintln!(
            "{wave:?}: {n_own} applications with the share, {n_whole} with the whole \
             floor; amplitudes within {da:.1e} and {db:.1e} of the binder background's"
        );
        assert!(da < 1e-6 && db < 1e-6, "{da} {db}");
        assert!(
            (n_own as f64) < 0.7 * n_whole as f64,
            "{n_own} vs {n_whole}"
        );
    }
    // The same grain in bluer light is larger inside: at 300 nm (k0 n a ≈ 6,
    // above 5) it keeps the whole floor, at 380 nm (4.7) part of it.
    for wavelength in [300.0, 380.0] {
        let lat = Problem::lattice([20, 20, 30], size, wavelength, 8.0, 0.0);
        let p = in_binder(lat, &eps);
        let own = ShiftParams::of(Background::Mean);
        let whole = ShiftParams {
            mean_loss_dilute: 0.0,
            ..own
        };
        let loss = |params| System::with_params(&p, params).unwrap().background_eps().im;
        let (got, full) = (loss(own), loss(whole));
        eprintln!("{wavelength} nm: floor {got:.4} of the whole {full:.4}");
        if wavelength < 350.0 {
            assert!((got - full).abs() < 1e-12 * full, "{got} vs {full}");
        } else {
            assert!(
                got > 1.2 * share * full && got < 0.9 * full,
                "{got} vs {full}, share {share}"
            );
        }
    }
}
