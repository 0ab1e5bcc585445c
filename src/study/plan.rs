//! What a study will cost before it runs: the work of each variant and an
//! estimate of its time and memory.
//!
//! Work: [`pipeline::planned_solves`] solves on an `nx × ny × nz` grid.
//!
//! Memory: the run's own model, [`pipeline::memory`] (the one `check` and
//! `run` hold a run to).
//!
//! Time model (one variant, all threads): per solve
//! `t_setup + applications × t_apply`, where `t_setup` (building the
//! solver's system: shift, Green's tables; and what a BiCGStab run costs
//! beyond its applications) and `t_apply` (one application of the shifted
//! operator `x − G_s V' x` with BiCGStab's vector work, in the fields'
//! precision, [`CALIBRATION_ITERATIONS`]) are **timed at plan
//! time on this machine** — as the process's CPU time over its threads, so
//! the estimate is the machine's when idle, whatever else shares it — for
//! each distinct grid of the plan — on the grid
//! itself when it has at most [`CALIBRATION_VOXELS`] voxels, otherwise on a
//! grid with the same `nz` and fewer lateral cells, scaled by
//! `N log₂(nx ny)` (the FFTs). `applications` is the measured rate of the
//! variant's kind of layer ([`default_applications`]: its solver background
//! and, on the mean background, whether its top is flat — relief, conformal
//! films and rough surfaces need about 1.3× more); once results of this study are
//! finished, every rate is scaled by what they needed against what was
//! assumed for them (the operator applications each solve recorded), the
//! assumption counting as
//! [`PRIOR_RESULTS`] results: a study's axes often run from easy to hard
//! (small grains first), so its first results are a biased sample (100 nm
//! spheres take a third of the applications of 450 nm ones). A pigment
//! with finished results of a kind has its own factor by the same rule
//! ([`pigments_key`]); the others take the kind's, pooled over every
//! pigment's results; closed-form
//! layers (no grid, [`ANALYTIC_SOLVE_S`] per solve) are left out of that
//! ratio and out
//! of the model. A high-contrast layer (white grains: real index more than
//! [`pilot::HIGH_CONTRAST`] from the binder's) is not assumed at the
//! stand-ins' rate: its group is measured by a pilot solve ([`pilot`]),
//! whose factor replaces 1× as the group's prior. A Maxwell variant is timed on the vector operator and
//! pays its setup and applications once per polarisation solved
//! ([`wave_solves`]: natural light one random-phase solve for an ensemble, else two). Geometry packing and output
//! are not modelled (seconds per variant). The estimate is a guide (±2×),
//! not a promise.

use super::cpu::process_cpu_s;
use super::pilot;
use super::run::{self, State};
use super::sweep::Variant;
use crate::config::{Background, Equation, Linear, Precision, Scene, Surface};
use crate::pipeline;
use crate::solver::methods::bicgstab::BiCgStab;
use crate::solver::{Controls, Field, Problem, SolveError, Solver, System, Wave};
use ndarray::Array3;
use num_complex::Complex64 as C64;
use std::collections::BTreeMap;

/// Largest grid timed directly at plan time.
pub const CALIBRATION_VOXELS: usize = 1 << 19;
/// Operator applications per solve assumed when no result of the study
/// exists yet, on the binder background: BiCGStab on the demo layer needed
/// 84–348 (median 232) to 1e-6 (docs/PERFORMANCE.md); 200 is the round middle.
pub const BINDER_APPLICATIONS: f64 = 200.0;
/// The same on the mean background for a layer under a flat binder surface:
/// `auto` (BiCGStab) over the 48 flat granular red variants of the standard
/// profile (60 × 60 × 50 cells, tolerance 1e-4, 0–60° from above and below;
/// 100 nm spheres 12, 450 nm 37; mean 20.8) — docs/PERFORMANCE.md, "The
/// standard study".
pub const MEAN_APPLICATIONS: f64 = 21.0;
/// The same when the top is not a plane (relief, a conformal film or a
/// rough surface): the binder–air interface crosses the grid's cells; the
/// standard profile's 9 red variants of these kinds, with the air at each
/// face on its own mean and loss floor, needed 18–46 per solve (the
/// conformal films and the 15 % rough top the most), 26.7 over their 3344
/// solves — docs/PERFORMANCE.md, "Air at a face".
pub const MEAN_APPLICATIONS_SURFACE: f64 = 27.0;

/// The tolerance the mean background's assumed rates were measured at
/// ([`MEAN_APPLICATIONS`], [`MEAN_APPLICATIONS_SURFACE`]).
pub const MEAN_RATE_TOLERANCE: f64 = 1e-4;
/// The tolerance [`BINDER_APPLICATIONS`] was measured at.
pub const BINDER_RATE_TOLERANCE: f64 = 1e-6;

/// Decades of tolerance a Krylov solve's applications carry beyond the
/// ones it converges: applications grow linearly in the decades
/// `log10(1/tol)` asked, as `(TOLERANCE_OFFSET_DECADES + decades)`.
/// Fitted to BiCGStab on the three ACCURACY layers in Maxwell
/// (iterations + 1 against 1e-4, mean of the three): 0.63 at 1e-2, 0.83 at
/// 1e-3, 1.31 at 1e-6, 1.73 at 1e-9 (docs/ACCURACY.md, "The solver
/// tolerance in Maxwell's equations").
pub const TOLERANCE_OFFSET_DECADES: f64 = 2.5;

/// Applications at tolerance `tol` against those at `reference`
/// ([`TOLERANCE_OFFSET_DECADES`]).
pub fn tolerance_factor(tol: f64, reference: f64) -> f64 {
    let work = |t: f64| TOLERANCE_OFFSET_DECADES + (-t.log10()).max(0.0);
    work(tol) / work(reference)
}

/// Operator applications per solve assumed for `scene` when no result of
/// the study exists yet: by its solver background and, on the mean
/// background, by whether its top is flat; scaled from the tolerance each
/// rate was measured at to the scene's ([`tolerance_factor`]).
pub fn default_applications(scene: &Scene) -> f64 {
    let (rate, measured_at) = match scene.solver.background {
        Background::Binder => (BINDER_APPLICATIONS, BINDER_RATE_TOLERANCE),
        Background::Mean if flat_top(scene) => (MEAN_APPLICATIONS, MEAN_RATE_TOLERANCE),
        Background::Mean => (MEAN_APPLICATIONS_SURFACE, MEAN_RATE_TOLERANCE),
    };
    rate * tolerance_factor(scene.solver.tolerance, measured_at)
}

/// Whether a scene's top is a plane ([`pipeline::flat_top`]): the
/// two kinds of layer whose rates are assumed, and scaled by the finished
/// results, apart.
pub use pipeline::flat_top;

/// Wave solves per incidence: one (Helmholtz, and Maxwell's random-phase
/// natural light), or one per polarisation solved (Maxwell; natural light
/// in two solves is an s and a p solve).
pub fn wave_solves(scene: &Scene) -> usize {
    scene.solver.solves_per_incidence()
}

/// How many finished results the background's measured rate counts as
/// when it is averaged with them ([`calibrate`]).
pub const PRIOR_RESULTS: f64 = 5.0;

/// How many finished results a high-contrast group's pilot counts as: one.
/// It is one solve of one member, and the members differ more than that
/// between each other (rutile in Maxwell's equations: the pilot, d250 at
/// 15 %, 1042 applications per solve; the finished d100 variants at 15 %
/// and 5 %, 2051 and 3432).
pub const PILOT_RESULTS: f64 = 1.0;

/// Seconds per solve of a closed-form (homogeneous) layer: no grid, no
/// iteration. Measured: the standard profile's red_pvc30_mol, 176 solves
/// in 0.3 s with its tile and colours.
pub const ANALYTIC_SOLVE_S: f64 = 2e-3;

/// BiCGStab iterations of the two calibration runs (each iteration two
/// applications with the vector updates and inner products between them,
/// and a residual at each end): the difference of their times over the
/// difference of their applications is one application's; what the shorter
/// run takes beyond its applications (the Krylov fields' allocation, the
/// shadow vector, the start) is part of a solve's setup.
pub const CALIBRATION_ITERATIONS: [usize; 2] = [2, 6];

/// Timings of one grid.
#[derive(Debug, Clone, Copy)]
pub struct GridTiming {
    /// The grid timed (may be smaller than the one estimated).
    pub timed: [usize; 3],
    pub setup_s: f64,
    /// One operator application with BiCGStab's vector work per
    /// application, in the fields' precision.
    pub apply_s: f64,
}

/// The measured basis of the time model.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// Per distinct [`GridKey`] (grid, equation, field precision, porous
    /// top) → its timing, scaled to that grid.
    pub grids: BTreeMap<GridKey, GridTiming>,
    /// Factor on the assumed applications per solve
    /// ([`default_applications`]) of the variants under a flat top, from the
    /// study's finished results of that kind.
    pub ratio: f64,
    /// Where `ratio` came from.
    pub applications_source: String,
    /// The same for the variants under relief, a conformal film or a rough
    /// surface ([`flat_top`]), from the finished results of that kind.
    pub surface_ratio: f64,
    /// Where `surface_ratio` came from.
    pub surface_source: String,
    /// High-contrast groups ([`pilot::group`]) → their own factor, from a
    /// pilot solve and their finished results, in place of `ratio`.
    pub groups: BTreeMap<String, GroupRate>,
    /// Per pigments ([`pigments_key`]) and kind of top (`true`: flat) with
    /// finished results: their own factor and where it came from, in place
    /// of `ratio` or `surface_ratio` for that pigment's variants. Pigments
    /// differ more than the prior allows (blue needs twice green's
    /// applications per solve in Maxwell's equations), so one pigment's
    /// results scale only its own rates; the others take the pooled factor.
    pub pigments: BTreeMap<(String, bool), (f64, String)>,
}

/// The pigments whose finished results scale a variant's rates: its
/// species' material names in order (`"yellow+blue"`).
pub fn pigments_key(scene: &Scene) -> String {
    scene
        .species
        .iter()
        .map(|s| s.material.name.as_str())
        .collect::<Vec<_>>()
        .join("+")
}

/// The measured factor of one high-contrast group.
#[derive(Debug, Clone)]
pub struct GroupRate {
    /// Factor on the assumed applications of the group's variants.
    pub ratio: f64,
    /// Applications per solve the model assumes for the pilot's variant.
    pub assumed: f64,
    /// Its pilot, or why there is none.
    pub pilot: Result<pilot::Pilot, String>,
    /// Variants in the group.
    pub members: usize,
    /// Where `ratio` came from, in words.
    pub source: String,
}

/// Estimated cost of one variant.
#[derive(Debug, Clone, Copy)]
pub struct Estimate {
    pub solves: usize,
    pub grid: [usize; 3],
    pub voxels: usize,
    pub realisations: usize,
    pub seconds: f64,
    pub bytes: f64,
}

fn grid_of(s: &Scene) -> [usize; 3] {
    [s.grid.nx, s.grid.ny, s.grid.nz]
}

/// What one operator timing stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct GridKey {
    /// `[nx, ny, nz]`.
    pub grid: [usize; 3],
    pub equation: Equation,
    /// The Krylov fields' storage (f32 halves their memory traffic).
    pub precision: Precision,
    /// Whether air reaches deep into the grid from both faces (a conformal
    /// film draped into the gaps between its grains, or an explicit
    /// structure, which may hold air anywhere), so that the mean
    /// background's layered zones (`solver::zone_cells`) reach their cap and
    /// add their sweep tables to every application. A relief's or a rough
    /// surface's air takes a few cells at one face (4–6 of 50 in the
    /// standard study), within the timing's scatter of a flat top.
    pub porous: bool,
}

/// The timing key of a scene.
pub fn grid_key(s: &Scene) -> GridKey {
    GridKey {
        grid: grid_of(s),
        equation: s.solver.equation,
        precision: s.solver.precision,
        porous: matches!(s.layer.surface, Surface::Conformal { .. }) || s.structure.is_some(),
    }
}

/// Time setup and one application of `key.equation`'s operator with
/// BiCGStab's vector work on `key.grid` (reduced if large; porous: air at
/// both faces deep enough for the layered zones to reach their cap) and
/// scale.
pub fn time_grid(key: GridKey) -> GridTiming {
    let [nx, ny, nz] = key.grid;
    let (mut tx, mut ty) = (nx, ny);
    while tx * ty * nz > CALIBRATION_VOXELS && (tx > 4 || ty > 4) {
        if tx >= ty {
            tx = tx.div_ceil(2);
        } else {
            ty = ty.div_ceil(2);
        }
    }
    let timed = [tx, ty, nz];
    let (setup, apply) = time_exact(timed, key);
    let work = |x: usize, y: usize| (x * y * nz) as f64 * ((x * y) as f64).log2().max(1.0);
    let scale = work(nx, ny) / work(tx, ty);
    GridTiming {
        timed,
        setup_s: setup * scale,
        apply_s: apply * scale,
    }
}

/// Median of three timings of a solve's setup (the system, and what a
/// BiCGStab run costs beyond its applications) and of one operator
/// application within BiCGStab (two runs of [`CALIBRATION_ITERATIONS`]
/// iterations on fields of `key.precision`) on a
/// layer with grains of index 1.4 + 0.3i in the binder (Maxwell: s
/// polarisation; p costs the same); porous: air in a third of the binder's
/// voxels at every depth (both layered zones at their cap).
fn time_exact([nx, ny, nz]: [usize; 3], key: GridKey) -> (f64, f64) {
    let (equation, zones) = (key.equation, key.porous);
    let eb = 1.558f64.powi(2);
    let ep = C64::new(1.4, 0.3).powi(2);
    let eps = Array3::from_shape_fn((nz, ny, nx), |(k, j, i)| {
        match (i / 3 + j / 3 + k / 3) % 3 {
            0 => ep,
            1 if zones => C64::new(1.0, 0.0),
            _ => C64::new(eb, 0.0),
        }
    });
    let lattice = Problem::lattice(
        [nx, ny, nz],
        [25.0 * nx as f64, 25.0 * ny as f64, 10.0 * nz as f64],
        550.0,
        30.0,
        0.0,
    );
    let wave = match equation {
        Equation::Helmholtz => Wave::Scalar,
        Equation::Maxwell => Wave::Vector {
            polarisation: Linear::S.into(),
            azimuth_deg: 0.0,
        },
    };
    let p = Problem {
        tensor: None,
        lattice,
        eps: &eps,
        eps_binder: eb,
        wave,
    };
    let mut setups = vec![];
    let mut applies = vec![];
    let ctl = |max_iterations| Controls {
        tolerance: 1e-300,
        max_iterations,
        precision: key.precision,
        background: Background::DEFAULT,
    };
    // The process's CPU time over its threads: what the operator costs on
    // this machine idle. Other jobs sharing the cores stretch the wall
    // clock (by 2× and more on a loaded 2-core machine) but not this.
    let threads = rayon::current_num_threads().max(1) as f64;
    let elapsed = |t0: f64| (process_cpu_s() - t0) / threads;
    for _ in 0..3 {
        let t = process_cpu_s();
        let Ok(mut sys) = System::new(&p, Background::DEFAULT) else {
            return (f64::NAN, f64::NAN);
        };
        let mut scr = sys.scratch();
        let setup = elapsed(t);
        let mut runs = [(0.0, 0usize); 2];
        for (run, iterations) in runs.iter_mut().zip(CALIBRATION_ITERATIONS) {
            let mut u = Field::zeros(key.precision, sys.unknown_dim());
            let t = process_cpu_s();
            sys.set_start_field(&mut u);
            // No tolerance is reached: the run stops after its iterations,
            // each two applications, with a residual at each end.
            let applications =
                match BiCgStab::DEFAULT.run(&mut sys, &mut scr, &mut u, &ctl(iterations)) {
                    Err(SolveError::NotConverged { iterations, .. }) => 2 * iterations + 2,
                    Ok(o) => o.applications,
                    Err(_) => return (f64::NAN, f64::NAN),
                };
            *run = (elapsed(t), applications);
        }
        let [(t1, a1), (t2, a2)] = runs;
        let apply = (t2 - t1) / (a2 as f64 - a1 as f64);
        applies.push(apply);
        setups.push(setup + (t1 - a1 as f64 * apply).max(0.0));
    }
    setups.sort_by(f64::total_cmp);
    applies.sort_by(f64::total_cmp);
    (setups[1], applies[1])
}

/// Operator applications of the finished results among `variants` against
/// what [`default_applications`] assumed for them, per solve: (measured /
/// assumed, results counted), if any.
pub fn measured_ratio(variants: &[Variant]) -> Option<(f64, usize)> {
    let (mut measured, mut assumed, mut files) = (0.0, 0.0, 0usize);
    for v in variants {
        // Closed-form layers have no applications: they would drag the mean down.
        if run::state(v) != State::Done || pipeline::RunPlan::of(&v.scene).analytic {
            continue;
        }
        let Ok(s) = crate::output::h5::read_summary(&run::paths(v).0) else {
            continue;
        };
        files += 1;
        for e in &s.entries {
            // The recorded applications count an `auto` solve's fallbacks;
            // its iterations are the answering method's alone.
            measured += e.operator_applications.map_or_else(
                || (e.iterations as f64 + 1.0) * e.method.solver().applications_per_iteration(),
                |a| a as f64,
            );
            assumed += default_applications(&v.scene) * wave_solves(&v.scene) as f64;
        }
    }
    (assumed > 0.0).then(|| (measured / assumed, files))
}

/// Calibrate the time model for the grids of `variants`: time each grid's
/// operator, measure every high-contrast group by a pilot solve
/// ([`pilot`]), and scale the assumed rates by the finished results.
pub fn calibrate(variants: &[Variant], finished: &[Variant]) -> Calibration {
    let mut grids = BTreeMap::new();
    for v in variants {
        let key = grid_key(&v.scene);
        grids.entry(key).or_insert_with(|| time_grid(key));
    }
    // Each variant's group, found once: None for the ordinary layers.
    let mut members: BTreeMap<String, Vec<&Variant>> = BTreeMap::new();
    for v in variants {
        if let Some(key) = pilot::group(&v.scene) {
            members.entry(key).or_default().push(v);
        }
    }
    let mut done: BTreeMap<Option<String>, Vec<Variant>> = BTreeMap::new();
    for v in finished {
        done.entry(pilot::group(&v.scene))
            .or_default()
            .push(v.clone());
    }
    let measured = |key: Option<String>| done.get(&key).and_then(|f| measured_ratio(f));
    let groups = members
        .iter()
        .map(|(key, m)| {
            let rep = pilot::representative(m);
            let assumed = default_applications(&rep.scene);
            let p = pilot::measure(key, rep);
            let prior = p.as_ref().map_or(1.0, |p| p.applications / assumed);
            let (ratio, source) = blend(
                (prior, PILOT_RESULTS),
                measured(Some(key.clone())),
                "the pilot's factor",
                "group",
            );
            let rate = GroupRate {
                ratio,
                assumed,
                pilot: p,
                members: m.len(),
                source,
            };
            (key.clone(), rate)
        })
        .collect();
    // The ordinary layers' factor, per kind of top.
    let kind = |flat: bool| {
        let of_kind: Vec<Variant> = done
            .get(&None)
            .map(|f| {
                f.iter()
                    .filter(|v| flat_top(&v.scene) == flat)
                    .cloned()
                    .collect()
            })
            .unwrap_or_default();
        match measured_ratio(&of_kind) {
            None => (
                1.0,
                "no finished result of this kind yet: the measured rates as assumed \
                 (docs/PERFORMANCE.md, \"The standard study\")"
                    .to_string(),
            ),
            done => blend((1.0, PRIOR_RESULTS), done, "1×", "kind"),
        }
    };
    let (ratio, applications_source) = kind(true);
    let (surface_ratio, surface_source) = kind(false);
    // Per pigment and kind, the same rule on that pigment's results alone.
    let mut by: BTreeMap<(String, bool), Vec<Variant>> = BTreeMap::new();
    for v in done.get(&None).into_iter().flatten() {
        by.entry((pigments_key(&v.scene), flat_top(&v.scene)))
            .or_default()
            .push(v.clone());
    }
    let pigments = by
        .into_iter()
        .filter_map(|(key, vs)| {
            let done = measured_ratio(&vs)?;
            Some((
                key,
                blend((1.0, PRIOR_RESULTS), Some(done), "1×", "pigment"),
            ))
        })
        .collect();
    Calibration {
        grids,
        ratio,
        applications_source,
        surface_ratio,
        surface_source,
        groups,
        pigments,
    }
}

/// A prior factor averaged with the finished results' (`done`: factor and
/// results counted), the prior (`factor`, `weight`) counting as `weight`
/// results.
fn blend(
    (prior, weight): (f64, f64),
    done: Option<(f64, usize)>,
    prior_name: &str,
    whose: &str,
) -> (f64, String) {
    match done {
        Some((r, files)) => (
            (weight * prior + files as f64 * r) / (weight + files as f64),
            format!(
                "the {files} finished result(s) of this {whose} needed {r:.2}× the assumed \
                 rates, averaged with {prior_name} counted as {weight} result(s)"
            ),
        ),
        None => (prior, format!("{prior_name}, no finished result yet")),
    }
}

/// The estimate of one variant.
pub fn estimate(scene: &Scene, cal: &Calibration) -> Estimate {
    let grid = grid_of(scene);
    let voxels = grid.iter().product();
    // With a realisation target, the realisations the fragment's
    // statistics call for (the run stops there), not the most allowed.
    let realisations = pipeline::accuracy::expected_realisations(scene);
    let solves = pipeline::planned_solves(scene) / scene.realisations.max(1) * realisations;
    let seconds = if pipeline::RunPlan::of(scene).analytic {
        solves as f64 * ANALYTIC_SOLVE_S
    } else {
        cal.grids.get(&grid_key(scene)).map_or(f64::NAN, |t| {
            let flat = flat_top(scene);
            let pooled = cal
                .pigments
                .get(&(pigments_key(scene), flat))
                .map_or(if flat { cal.ratio } else { cal.surface_ratio }, |p| p.0);
            let ratio = pilot::group(scene)
                .and_then(|k| cal.groups.get(&k))
                .map_or(pooled, |g| g.ratio);
            let applications = default_applications(scene) * ratio;
            let waves = wave_solves(scene) as f64;
            solves as f64 * waves * (t.setup_s + applications * t.apply_s)
        })
    };
    let bytes = pipeline::memory::estimate_bytes(scene);
    Estimate {
        solves,
        grid,
        voxels,
        realisations,
        seconds,
        bytes,
    }
}

/// `1.5 s`, `12 min`, `3.4 h`.
pub fn human_time(s: f64) -> String {
    if !s.is_finite() {
        "?".into()
    } else if s < 90.0 {
        format!("{s:.1} s")
    } else if s < 5400.0 {
        format!("{:.0} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_print_in_their_unit() {
        assert_eq!(human_time(30.0), "30.0 s");
        assert_eq!(human_time(600.0), "10 min");
        assert_eq!(human_time(7200.0), "2.0 h");
    }

    #[test]
    fn a_layer_whose_top_is_not_flat_is_assumed_to_need_more_applications() {
        let scene = |extra: &str| {
            let text = format!(
                "[layer]\nthickness_nm = 500.0\nfragment_nm = [400.0, 400.0]\npvc = 0.3\n{extra}\n\
                 [[pigment]]\nname = \"red\"\nmaterial = {{ builtin = \"red\" }}\n\
                 diameter_nm = 100.0\n[illumination]\nwavelengths_nm = [550.0]\npolar_deg = [0.0]\n[grid]\ncell_nm = 25.0\n\
                 [solver]\ntolerance = 1e-4\n"
            );
            crate::config::parse_scene(std::path::Path::new("t.toml"), &text).unwrap()
        };
        assert_eq!(default_applications(&scene("")), MEAN_APPLICATIONS);
        for top in [
            "relief_fraction = 0.3",
            "surface = { kind = \"conformal\", film_nm = 20.0 }",
            "surface = { kind = \"rough\", rms_nm = 20.0, correlation_nm = 100.0 }",
        ] {
            assert_eq!(
                default_applications(&scene(top)),
                MEAN_APPLICATIONS_SURFACE,
                "{top}"
            );
        }
        let mut binder = scene("");
        binder.solver.background = Background::Binder;
        binder.solver.tolerance = BINDER_RATE_TOLERANCE;
        assert_eq!(default_applications(&binder), BINDER_APPLICATIONS);
    }

    /// The rates hold at the tolerance they were measured at; a looser one
    /// needs fewer applications, a tighter one more, by the decades asked.
    #[test]
    fn the_assumed_rate_follows_the_tolerance() {
        assert_eq!(tolerance_factor(1e-4, 1e-4), 1.0);
        let f = |t: f64| tolerance_factor(t, MEAN_RATE_TOLERANCE);
        assert!(f(1e-2) < f(1e-3) && f(1e-3) < 1.0 && f(1e-6) > 1.0 && f(1e-9) > f(1e-6));
        // Ten times looser never costs more than a decade's share of the work.
        assert!(
            (f(1e-3) - (TOLERANCE_OFFSET_DECADES + 3.0) / (TOLERANCE_OFFSET_DECADES + 4.0)).abs()
                < 1e-12
        );
        // A tolerance of 1 or more asks for no decade at all.
        assert_eq!(f(1.0), f(10.0));
    }

    /// Natural light in Maxwell is two wave solves per incidence (one as a
    /// random-phase state), one polarisation one, Helmholtz one.
    #[test]
    fn maxwell_pays_per_polarisation() {
        let scene = |polarisation: &str, equation: &str| {
            let text = format!(
                "[layer]\nthickness_nm = 500.0\nfragment_nm = [400.0, 400.0]\npvc = 0.3\n\
                 [[pigment]]\nname = \"red\"\nmaterial = {{ builtin = \"red\" }}\n\
                 diameter_nm = 100.0\n[illumination]\nwavelengths_nm = [550.0]\npolar_deg = [0.0]\n\
                 polarisation = \"{polarisation}\"\n[solver]\nequation = \"{equation}\"\n\
                 [grid]\ncell_nm = 25.0\n"
            );
            crate::config::parse_scene(std::path::Path::new("t.toml"), &text).unwrap()
        };
        assert_eq!(wave_solves(&scene("unpolarised", "helmholtz")), 1);
        assert_eq!(wave_solves(&scene("unpolarised", "maxwell")), 2);
        assert_eq!(wave_solves(&scene("p", "maxwell")), 1);
        // An ensemble takes natural light as one random-phase solve.
        let mut ensemble = scene("unpolarised", "maxwell");
        ensemble.solver.natural_light = crate::config::NaturalLight::RandomPhase;
        assert_eq!(wave_solves(&ensemble), 1);
    }

    #[test]
    fn large_grids_are_timed_reduced_and_scaled() {
        let t = time_grid(GridKey {
            grid: [64, 64, 200],
            equation: Equation::Helmholtz,
            precision: Precision::F64,
            porous: false,
        });
        assert!(t.timed[0] * t.timed[1] * t.timed[2] <= CALIBRATION_VOXELS);
        assert_eq!(t.timed[2], 200);
        assert!(t.apply_s > 0.0 && t.setup_s > 0.0);
    }
}
