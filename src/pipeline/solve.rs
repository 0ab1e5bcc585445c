//! The solves of one layer: every (wavelength, incidence, side) on a
//! permittivity grid through the configured iterative method, or in closed
//! form on the homogeneous slab; each solve logged to the progress bar, and
//! a long one reporting its iterations while it runs (`solver::heartbeat`).

use ndarray::{s, Array3};
use num_complex::Complex64 as C64;

use crate::config::{Incidence, Method, Scene};
use crate::optics::farfield::{self, Efficiencies, Side, SolveEntry};
use crate::output::progress::Progress;
use crate::raster::structure::EpsGrid;
use crate::raster::{Anisotropy, Grid, Raster};
use crate::solver::heartbeat::{self, Beat};
use crate::solver::{self, Controls, Jones, Problem, SolveRecord, Wave};
use rand::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;

use super::eps::{fraction_eps, mean_eps};
use super::plan::{incidences, RunPlan};
use super::PipelineError;

/// One progress step per solve, with its R, T, A, method and balance.
fn log_solve(progress: &Progress, e: &SolveEntry) {
    let eff = &e.efficiencies;
    progress.inc(
        1,
        &format!(
            "{} nm, {}° {}{}: R {:.4} T {:.4} A {:.4} ({} {} it, balance {:.1e})",
            e.wavelength_nm,
            (e.incidence.polar_deg * 100.0).round() / 100.0,
            e.side,
            if e.realisation > 0 {
                format!(" #{}", e.realisation)
            } else {
                String::new()
            },
            eff.total_reflectance,
            eff.total_transmittance,
            eff.absorption,
            e.record.method,
            e.record.iterations,
            eff.energy_balance
        ),
    );
}

/// Solve every (wavelength, incidence, side) of one realisation on a raster.
pub fn solve_realisation(
    scene: &Scene,
    plan: &RunPlan,
    raster: &Raster,
    realisation: usize,
    progress: &Progress,
) -> Result<Vec<SolveEntry>, PipelineError> {
    solve_layer(scene, plan, LayerEps::Raster(raster), realisation, progress)
}

/// Where the permittivity of each wavelength comes from.
#[derive(Clone, Copy)]
pub enum LayerEps<'a> {
    /// Volume fractions (grains or primitives) and the materials' n(λ).
    Raster(&'a Raster),
    /// A permittivity grid read from a file.
    Grid(&'a EpsGrid, Grid),
}

/// Solve every (wavelength, incidence, side) on one layer.
pub fn solve_layer(
    scene: &Scene,
    plan: &RunPlan,
    layer: LayerEps,
    realisation: usize,
    progress: &Progress,
) -> Result<Vec<SolveEntry>, PipelineError> {
    let g = match layer {
        LayerEps::Raster(r) => r.grid,
        LayerEps::Grid(_, g) => g,
    };
    let eps_b = scene.layer.binder_index.powi(2);
    let outside = plan.outside_eps(scene);
    let ctl = controls(scene);
    let incs = incidences(scene, plan);
    let mut eps = Array3::from_elem((g.nz, g.ny, g.nx), C64::new(0.0, 0.0));
    let mut flipped = plan
        .below
        .as_ref()
        .map(|_| Array3::from_elem((g.nz, g.ny, g.nx), C64::new(0.0, 0.0)));
    // The tensor part (Maxwell: anisotropic cut voxels, crystal grains),
    // and its mirror image for light from below.
    let surfaces = scene
        .grid
        .voxel_permittivity
        .anisotropic(scene.solver.equation);
    let mut tensor = Anisotropy::empty(g.nz, (g.ny, g.nx));
    let mut tensor_below = Anisotropy::empty(g.nz, (g.ny, g.nx));
    // (surface terms, crystal terms) of the wavelength's tensor.
    let mut tensor_counts = (0, 0);
    let mut entries = Vec::new();
    for &lambda in &scene.wavelengths_nm {
        match layer {
            LayerEps::Raster(raster) => {
                let eps_species = fraction_eps(scene, lambda)?;
                raster.epsilon_into(C64::new(eps_b, 0.0), &eps_species, &mut eps);
                let crystals = crystal_eps(scene, lambda);
                if surfaces || crystals.iter().any(Option::is_some) {
                    tensor_counts = raster.anisotropy_into(
                        C64::new(eps_b, 0.0),
                        &eps_species,
                        &crystals,
                        surfaces,
                        &mut eps,
                        &mut tensor,
                    );
                    if plan.embedded {
                        tensor.scale(C64::new(outside, 0.0));
                    }
                    if flipped.is_some() {
                        tensor_below = tensor.flipped();
                    }
                }
            }
            LayerEps::Grid(grid_eps, _) => grid_eps.epsilon_into(lambda, &mut eps),
        }
        if plan.embedded {
            eps.mapv_inplace(|e| e / outside);
        }
        let lambda_solved = lambda / outside.sqrt();
        if let Some(f) = flipped.as_mut() {
            f.assign(&eps.slice(s![..;-1, .., ..]));
        }
        for (side, inc) in &incs {
            let lattice = Problem::lattice(
                [g.nx, g.ny, g.nz],
                g.size_nm,
                lambda_solved,
                inc.polar_deg,
                inc.azimuth_deg,
            );
            let (grid_eps, grid_tensor) = match (side, flipped.as_ref()) {
                (Side::Below, Some(f)) => (f, &tensor_below),
                _ => (&eps, &tensor),
            };
            let phase = plan
                .seeds
                .get(realisation)
                .map(|&seed| random_phase(seed, lambda, inc, *side));
            let waves = waves(scene, inc, phase);
            // A long solve reports where it stands (solver::heartbeat).
            let beat = |b: Beat| {
                progress.log(&format!(
                    "[inksim] still solving {lambda} nm, {}° {side}{}: {} iteration {}, \
                     residual {}{:.1e} (tolerance {:.0e}), {:.0} s",
                    (inc.polar_deg * 100.0).round() / 100.0,
                    if realisation > 0 {
                        format!(" #{realisation}")
                    } else {
                        String::new()
                    },
                    b.method,
                    b.iterations,
                    if b.estimated { "≈ " } else { "" },
                    b.residual,
                    ctl.tolerance,
                    b.elapsed_s
                ))
            };
            let mut parts = Vec::with_capacity(waves.len());
            for &wave in &waves {
                let p = Problem {
                    tensor: Some(grid_tensor).filter(|t| !t.is_empty()),
                    lattice,
                    eps: grid_eps,
                    eps_binder: eps_b / outside,
                    wave,
                };
                let label = format!(
                    "{lambda} nm, {}° {side}",
                    (inc.polar_deg * 100.0).round() / 100.0
                );
                let (efficiencies, mut record) = solve_balanced(
                    &p,
                    scene.solver.method,
                    ctl,
                    scene.solver.energy_balance_limit,
                    &beat,
                    progress,
                    &label,
                )
                .map_err(|source| PipelineError::Solve {
                    wavelength_nm: lambda,
                    polar_deg: inc.polar_deg,
                    source,
                })?;
                if p.tensor.is_some() {
                    record.note.push_str(&format!(
                        "; tensor ε: {} cut voxels anisotropic, {} crystal-grain voxels",
                        tensor_counts.0, tensor_counts.1
                    ));
                }
                parts.push((wave, efficiencies, record));
            }
            let entry = combine(parts, lambda, inc, *side, realisation);
            log_solve(progress, &entry);
            entries.push(entry);
        }
    }
    Ok(entries)
}

/// Each species' `(ε_o, ε_e)` where its grains are a tensor each
/// ([`Scene::crystal_tensors`]), else None (its orientation average).
fn crystal_eps(scene: &Scene, lambda: f64) -> Vec<Option<(C64, C64)>> {
    scene
        .species
        .iter()
        .zip(scene.crystal_tensors())
        .map(|(s, tensor)| tensor.then(|| s.material.epsilon_axes_at(lambda)).flatten())
        .collect()
}

/// How often a long solve reports: `INKSIM_HEARTBEAT_S` seconds when set
/// to a number ≥ 0, else [`heartbeat::INTERVAL`].
pub fn heartbeat_interval() -> std::time::Duration {
    std::env::var("INKSIM_HEARTBEAT_S")
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0 && *s < 1e9)
        .map_or(heartbeat::INTERVAL, std::time::Duration::from_secs_f64)
}

/// One problem solved and held to the energy balance, not only to the
/// residual: while `|ΣR + ΣT + A − 1|` exceeds `limit` (`[solver]
/// energy_balance_limit`) it is solved again to a tenth of the tolerance (down to 1e-10, or 1e-6 with
/// f32 storage), saying so in the log (`label` names the solve) and in the
/// record, whose cost includes the attempts it replaced. Where the tighter
/// solve fails, the answer at the looser tolerance is kept and the log and
/// the note say so. A solve `auto` finished on another background than the
/// one asked for is solved again on the background that answered. A
/// tighter solve starts from the looser answer's field (the memory model
/// counts that copy, [`super::memory::WARM_START_BYTES`]).
fn solve_balanced(
    p: &Problem,
    method: Method,
    mut ctl: Controls,
    limit: f64,
    beat: &dyn Fn(Beat),
    progress: &Progress,
    label: &str,
) -> Result<(Efficiencies, SolveRecord), solver::SolveError> {
    // Attempts a tighter solve replaced, and why.
    let (mut replaced, mut again) = (Vec::<SolveRecord>::new(), String::new());
    // The looser answer a tighter solve is to replace: kept if that solve
    // fails, and the field it starts from.
    let mut looser: Option<(Efficiencies, solver::Solution)> = None;
    let (efficiencies, mut record) = loop {
        let solved = heartbeat::scope(heartbeat_interval(), beat, || match &looser {
            Some((_, s)) => solver::solve_from(p, method, &ctl, &s.field),
            None => solver::solve(p, method, &ctl),
        });
        let sol = match (solved, looser.take()) {
            (Ok(sol), previous) => {
                replaced.extend(previous.map(|(_, s)| s.record));
                sol
            }
            (Err(e), None) => return Err(e),
            // A tighter solve that fails keeps the answer at the looser
            // tolerance, which met its own residual: said in the log and
            // the note, its energy balance recorded as it is.
            (Err(e), Some((eff, previous))) => {
                progress.log(&format!(
                    "[inksim] {label}: the solve to {:.0e} failed ({e}); keeping the answer at \
                     {:.0e} (energy balance {:.1e})",
                    ctl.tolerance,
                    ctl.tolerance * 10.0,
                    eff.energy_balance
                ));
                again.push_str(&format!(
                    "; the solve to {:.0e} failed ({e}), this answer kept",
                    ctl.tolerance
                ));
                let mut kept = previous.record;
                kept.operator_applications += e.applications();
                break (eff, kept);
            }
        };
        let eff = farfield::efficiencies(&sol);
        let tighter = ctl.tolerance / 10.0;
        if eff.energy_balance.abs() <= limit || tighter < ctl.precision.select(1e-10, 1e-6) {
            break (eff, sol.record);
        }
        progress.log(&format!(
            "[inksim] {label}: energy balance {:.1e} above {:.0e} at tolerance {:.0e}; \
             solving again to {tighter:.0e}",
            eff.energy_balance, limit, ctl.tolerance
        ));
        again.push_str(&format!(
            "; solved again to {tighter:.0e} (energy balance {:.1e} at {:.0e})",
            eff.energy_balance, ctl.tolerance
        ));
        ctl.tolerance = tighter;
        if method == Method::Auto && sol.record.background != ctl.background {
            // Where `auto` had to leave the mean background (a stall), the
            // tighter solve starts on the background that answered: the
            // same problem would stall the same way again.
            ctl.background = sol.record.background;
        }
        looser = Some((eff, sol));
    };
    for r in &replaced {
        record.add(r);
    }
    record.note.push_str(&again);
    Ok((efficiencies, record))
}

/// The problems one incidence is solved as: the scalar wave, or Maxwell's
/// for each linear polarisation the scene asks for (unpolarised: s and p),
/// or, for random-phase natural light on a grid layer (`phase` given), one
/// mixed state `(ŝ + e^{iφ} p̂)/√2`.
fn waves(scene: &Scene, inc: &Incidence, phase: Option<f64>) -> Vec<Wave> {
    let vector = |polarisation: Jones| Wave::Vector {
        polarisation,
        azimuth_deg: inc.azimuth_deg,
    };
    match (scene.solver.polarisations(), phase) {
        (None, _) => vec![Wave::Scalar],
        (Some(_), Some(phi)) if scene.solver.random_phase() => vec![vector(Jones::phased(phi))],
        (Some(linear), _) => linear.iter().map(|&l| vector(l.into())).collect(),
    }
}

/// The relative phase of s and p for one random-phase solve, uniform in
/// [0, 2π): a hash of the realisation's seed, the wavelength, the
/// incidence and the side, so that it is the same for any thread count and
/// independent between solves.
fn random_phase(seed: u64, lambda: f64, inc: &Incidence, side: Side) -> f64 {
    let mut h = seed;
    for v in [
        lambda.to_bits(),
        inc.polar_deg.to_bits(),
        inc.azimuth_deg.to_bits(),
        side as u64,
    ] {
        h = SplitMix64::seed_from_u64(h ^ v).next_u64();
    }
    (h >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU
}

/// One incidence's entry from its solves: the scalar solve as it is; for
/// Maxwell the incoherent mean over the linear polarisations solved
/// (powers, not amplitudes), the records added up, and each polarisation's
/// own efficiencies kept; a mixed (random-phase) state's solve as it is,
/// with no per-polarisation efficiencies.
fn combine(
    parts: Vec<(Wave, Efficiencies, SolveRecord)>,
    wavelength_nm: f64,
    inc: &Incidence,
    side: Side,
    realisation: usize,
) -> SolveEntry {
    let mut record: Option<SolveRecord> = None;
    let mut polarised = Vec::new();
    let mut notes = Vec::new();
    let (mut single, mut random_phase_deg) = (None, None);
    for (wave, eff, rec) in parts {
        match wave {
            Wave::Scalar => single = Some(eff),
            Wave::Vector { polarisation, .. } => {
                notes.push(format!("{}: {}", polarisation.name(), rec.note));
                match polarisation.as_linear() {
                    Some(l) => polarised.push((l, eff)),
                    None => {
                        single = Some(eff);
                        random_phase_deg =
                            Some((polarisation.p / polarisation.s).arg().to_degrees());
                    }
                }
            }
        }
        match record.as_mut() {
            None => record = Some(rec),
            Some(r) => {
                r.add(&rec);
                r.residual = r.residual.max(rec.residual);
            }
        }
    }
    let mut record = record.expect("at least one solve per incidence");
    if !notes.is_empty() {
        let how = if single.is_some() {
            "natural light as one random-phase state"
        } else {
            "natural light as s and p"
        };
        record.note = if polarised.len() == 1 {
            format!("Maxwell, {}", notes.join("; "))
        } else {
            format!("Maxwell, {how}, {}", notes.join("; "))
        };
    }
    let efficiencies = match single {
        Some(eff) => eff,
        None => farfield::polarisation_mean(&polarised),
    };
    SolveEntry {
        wavelength_nm,
        incidence: *inc,
        side,
        realisation,
        layer: 0,
        efficiencies,
        record,
        polarised,
        random_phase_deg,
    }
}

/// The solver's iteration controls of a scene.
fn controls(scene: &Scene) -> Controls {
    Controls {
        tolerance: scene.solver.tolerance,
        max_iterations: scene.solver.max_iterations,
        precision: scene.solver.precision,
        background: scene.solver.background,
    }
}

/// The homogeneous slab of a molecular mixture (or of grains fine enough for
/// the effective-medium shortcut), `⟨ε⟩ = Σ f ε_s + (1 − Σ f) ε_b`, in closed
/// form (the `airy` method) for every (wavelength, incidence, side).
pub fn solve_analytic(
    scene: &Scene,
    plan: &RunPlan,
    progress: &Progress,
) -> Result<Vec<SolveEntry>, PipelineError> {
    let incs = incidences(scene, plan);
    let ctl = controls(scene);
    let eps_b = scene.layer.binder_index.powi(2);
    let outside = plan.outside_eps(scene);
    let why = if scene.is_molecular() {
        "molecular mixture"
    } else {
        "effective-medium shortcut (grains fine against λ)"
    };
    let mut entries = Vec::new();
    for &lambda in &scene.wavelengths_nm {
        let mean = Array3::from_elem((1, 1, 1), mean_eps(scene, lambda)? / outside);
        for (side, inc) in &incs {
            // A homogeneous slab is symmetric (from below = from above) and
            // the same at every azimuth: one cell, lit at azimuth 0.
            let size = [1.0, 1.0, scene.layer.thickness_nm];
            let lattice =
                Problem::lattice([1, 1, 1], size, lambda / outside.sqrt(), inc.polar_deg, 0.0);
            let mut parts = Vec::new();
            for wave in waves(scene, inc, None) {
                let p = Problem {
                    tensor: None,
                    lattice,
                    eps: &mean,
                    eps_binder: eps_b / outside,
                    wave,
                };
                let mut sol = solver::solve(&p, Method::Airy, &ctl).map_err(|source| {
                    PipelineError::Solve {
                        wavelength_nm: lambda,
                        polar_deg: inc.polar_deg,
                        source,
                    }
                })?;
                sol.record.note = format!("{why}: {}", sol.record.note);
                let eff = farfield::slab_efficiencies(&sol.slab_response(), inc);
                parts.push((wave, eff, sol.record));
            }
            let entry = combine(parts, lambda, inc, *side, 0);
            log_solve(progress, &entry);
            entries.push(entry);
        }
    }
    Ok(entries)
}
