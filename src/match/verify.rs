//! The wave-optics verification of a recipe (`[match.verify]`, METHOD
//! §12): the recipe the fast model found is solved by the full pipeline at
//! the base scene's own fidelity (its grid, fragment, realisations,
//! equation and tolerance), its colour in each target geometry compared
//! with the target, and, while it is outside the tolerance, corrected by
//! the fast–exact difference ([`offset_correction`]): the fast model,
//! shifted by the wave solution's colour minus its own at this recipe, is
//! fitted to the target again, so the fast model supplies only how the
//! colour changes with the recipe and the wave solver the colour itself.
//! Each step's result file is kept (`<output_dir>/verify/`), with its exact
//! scene inside.

use std::path::PathBuf;
use std::time::Instant;

use toml::Value;

use crate::config::Scene;
use crate::optics::colour;
use crate::pipeline::{self, memory::MemoryLimit};

use super::config::{checked_scene, MatchSpec};
use super::correct::{offset_correction, ModelDifference};
use super::forward::Recipe;
use super::problem::Problem;
use super::search::Candidate;
use super::MatchError;

/// One verified recipe of a correction sequence.
#[derive(Debug, Clone)]
pub struct VerifyStep {
    /// Volume fraction of every palette pigment (0: not used).
    pub fractions: Vec<f64>,
    pub thickness_nm: f64,
    /// The wave solution's CIELAB in each target geometry, and its standard
    /// error over the realisations (None for one realisation).
    pub lab: Vec<[f64; 3]>,
    pub lab_se: Vec<Option<[f64; 3]>>,
    /// CIEDE2000 of the wave solution to the target per geometry, and the
    /// standard error of the wave colour in ΔE00.
    pub de00: Vec<f64>,
    pub de00_se: Vec<Option<f64>>,
    /// The fast model's CIELAB of the same recipe per geometry: its
    /// difference from `lab` is the fast model's error here.
    pub fast_lab: Vec<[f64; 3]>,
    /// The wave solution's reflectance factor in the target's first
    /// geometry: wavelengths (nm) and values.
    pub spectrum: (Vec<f64>, Vec<f64>),
    /// The wave result file of this step.
    pub result: PathBuf,
    /// Wall time of the wave run, s.
    pub seconds: f64,
}

impl VerifyStep {
    /// The largest ΔE00 over the geometries.
    pub fn de00_max(&self) -> f64 {
        self.de00.iter().copied().fold(0.0, f64::max)
    }

    /// The wave solution's CIELAB minus the fast model's, stacked (3 per
    /// geometry): the fast–exact difference at this recipe.
    pub fn difference(&self) -> Vec<f64> {
        self.lab
            .iter()
            .zip(&self.fast_lab)
            .flat_map(|(w, f)| [w[0] - f[0], w[1] - f[1], w[2] - f[2]])
            .collect()
    }

    /// ΔE00 between the fast model's and the wave solution's colour of
    /// this recipe, per geometry.
    pub fn model_error(&self) -> Vec<f64> {
        self.lab
            .iter()
            .zip(&self.fast_lab)
            .map(|(w, f)| colour::delta_e2000(*w, *f))
            .collect()
    }
}

/// The outcome of one recipe's verification.
#[derive(Debug, Clone)]
pub struct Verification {
    /// The recipe's rank in the report.
    pub rank: usize,
    /// The first verification, then one per correction step.
    pub steps: Vec<VerifyStep>,
    /// Whether the last step is within the tolerance in every geometry.
    pub verified: bool,
    /// How it ended, in words.
    pub outcome: String,
}

impl Verification {
    pub fn last(&self) -> &VerifyStep {
        self.steps.last().expect("a verification has a step")
    }

    /// The verified recipe: the last step where it reached the tolerance,
    /// else the closest step.
    pub fn answer(&self) -> &VerifyStep {
        if self.verified {
            self.last()
        } else {
            self.best()
        }
    }

    /// The answer's pigments in use, with their names from `spec`'s
    /// palette, each shown by `show`.
    pub fn composition(&self, spec: &MatchSpec, show: &dyn Fn(&str, f64) -> String) -> String {
        spec.palette
            .iter()
            .zip(&self.answer().fractions)
            .filter(|(_, &f)| f > 0.0)
            .map(|(p, &f)| show(&p.name, f))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The step closest to the target (largest ΔE00 over the geometries
    /// least): the recipe to use when none reached the tolerance.
    pub fn best(&self) -> &VerifyStep {
        &self.steps[best_step(&self.steps)]
    }
}

/// The verification's settings of `spec`; an error without them.
fn settings(spec: &MatchSpec) -> Result<&super::config::VerifySpec, MatchError> {
    spec.verify.as_ref().ok_or_else(|| MatchError::Config {
        file: spec.path.clone(),
        message: "a verification needs [match.verify]".into(),
    })
}

/// The fidelity the verification solves at, in words: the base scene's.
pub fn fidelity(spec: &MatchSpec) -> String {
    let s = &spec.scene;
    let v = spec.verify.as_ref();
    let realisations = match s.realisation_target {
        Some(t) => format!(
            "{}–{} realisations (to a colour s.e. of {} ΔE00)",
            t.min, s.realisations, t.de00
        ),
        None => format!("{} realisation(s)", s.realisations),
    };
    format!(
        "{} equation, {} × {} × {} cells over {} × {} nm, {realisations}, tolerance {:.0e}, \
         wavelengths every {} nm",
        s.solver.equation.name(),
        s.grid.nx,
        s.grid.ny,
        s.grid.nz,
        s.layer.fragment_x_nm,
        s.layer.fragment_y_nm,
        s.solver.tolerance,
        v.map_or(0.0, |v| v.wavelength_step_nm)
    )
}

/// The solved wavelengths: every `step` nm over the colour band, both ends
/// included.
fn wavelengths(spec: &MatchSpec, step: f64) -> Vec<f64> {
    let w = &spec.scene.wavelengths_nm;
    let (a, b) = (w[0], w[w.len() - 1]);
    let n = ((b - a) / step).floor() as usize;
    let mut out: Vec<f64> = (0..=n).map(|i| a + i as f64 * step).collect();
    if b - out[out.len() - 1] > 1e-9 {
        out.push(b);
    }
    out
}

/// The wave scene of a recipe (`fractions` per palette pigment, thickness),
/// made from the base scene with the palette and checked by the scene
/// checker; its results go to `<output_dir>/verify/<name>-<label>.h5`.
pub fn scene(
    spec: &MatchSpec,
    fractions: &[f64],
    thickness_nm: f64,
    label: &str,
) -> Result<Scene, MatchError> {
    let v = settings(spec)?;
    let mut t = spec.base.clone();
    let all = match t.get("pigment") {
        Some(Value::Array(a)) => a.clone(),
        _ => Vec::new(),
    };
    let used: Vec<Value> = all
        .into_iter()
        .zip(fractions)
        .filter(|(_, &f)| f > 0.0)
        .map(|(mut p, &f)| {
            if let Value::Table(p) = &mut p {
                p.insert("pvc".into(), Value::Float(f));
            }
            p
        })
        .collect();
    if used.is_empty() {
        return Err(MatchError::Config {
            file: spec.path.clone(),
            message: "a recipe to verify uses no pigment".into(),
        });
    }
    t.insert("pigment".into(), Value::Array(used));
    let table = |t: &mut toml::Table, k: &str| -> toml::Table {
        match t.remove(k) {
            Some(Value::Table(x)) => x,
            _ => toml::Table::new(),
        }
    };
    let mut layer = table(&mut t, "layer");
    layer.insert("thickness_nm".into(), Value::Float(thickness_nm));
    t.insert("layer".into(), Value::Table(layer));
    let mut ill = table(&mut t, "illumination");
    ill.remove("wavelength_range_nm");
    ill.insert(
        "wavelengths_nm".into(),
        Value::Array(
            wavelengths(spec, v.wavelength_step_nm)
                .into_iter()
                .map(Value::Float)
                .collect(),
        ),
    );
    t.insert("illumination".into(), Value::Table(ill));
    let mut app = table(&mut t, "appearance");
    app.insert(
        "outputs".into(),
        Value::Array(vec![Value::String("tile".into())]),
    );
    app.insert(
        "measurements".into(),
        Value::Array(
            spec.target
                .geometries()
                .iter()
                .map(|m| Value::String(m.name().into()))
                .collect(),
        ),
    );
    app.insert(
        "illuminant".into(),
        Value::String(spec.target.illuminant.name().into()),
    );
    app.insert(
        "observer_deg".into(),
        Value::Integer(spec.target.observer.degrees().into()),
    );
    t.insert("appearance".into(), Value::Table(app));
    let mut out = toml::Table::new();
    out.insert(
        "dir".into(),
        Value::String(spec.output_dir.join("verify").display().to_string()),
    );
    out.insert(
        "name".into(),
        Value::String(format!("{}-{label}", spec.name)),
    );
    t.insert("output".into(), Value::Table(out));
    checked_scene(
        &spec.path,
        &t,
        &spec.base_path,
        "the verification's scene (base scene with the recipe)",
        &|m| m,
    )
}

/// Solve the recipe's scene and read its colours in the target geometries.
fn solve(
    spec: &MatchSpec,
    problem: &Problem,
    recipe: &Recipe,
    label: &str,
    memory: Option<MemoryLimit>,
) -> Result<VerifyStep, MatchError> {
    let scene = scene(spec, &recipe.fractions, recipe.thickness_nm, label)?;
    let start = Instant::now();
    let report = pipeline::run_with(&scene, true, memory)?;
    let seconds = start.elapsed().as_secs_f64();
    let measured = report
        .appearance
        .as_ref()
        .map_or(&[][..], |a| a.measured.as_slice());
    let mut step = VerifyStep {
        fractions: recipe.fractions.clone(),
        thickness_nm: recipe.thickness_nm,
        lab: Vec::new(),
        lab_se: Vec::new(),
        de00: Vec::new(),
        de00_se: Vec::new(),
        fast_lab: Vec::new(),
        spectrum: (Vec::new(), Vec::new()),
        result: report.result_path.clone(),
        seconds,
    };
    let fast = problem.lab_stack(recipe);
    for (g, (m, target)) in problem.target_lab.iter().enumerate() {
        let c = measured
            .iter()
            .find(|c| c.geometry == *m)
            .ok_or_else(|| MatchError::Config {
                file: spec.path.clone(),
                message: format!("the verification's run reported no colour at {}", m.name()),
            })?;
        if g == 0 {
            step.spectrum = (c.spectrum_wavelengths_nm.clone(), c.spectrum.clone());
        }
        step.lab.push(c.lab);
        step.lab_se.push(c.lab_se);
        step.de00.push(colour::delta_e2000(c.lab, *target));
        step.de00_se.push(c.de00_se);
        step.fast_lab
            .push([fast[3 * g], fast[3 * g + 1], fast[3 * g + 2]]);
    }
    Ok(step)
}

/// Verify the recipe of rank `rank`, `candidate`, with the wave solver and
/// correct it (module docs), each wave run held to `memory`; `progress`
/// hears each step.
pub fn verify(
    spec: &MatchSpec,
    problem: &Problem,
    (rank, candidate): (usize, &Candidate),
    memory: Option<MemoryLimit>,
    progress: &dyn Fn(&str),
) -> Result<Verification, MatchError> {
    let v = settings(spec)?;
    let tol = spec.search.tolerance_de00;
    let subset = &candidate.subset;
    let mut x = candidate.x.clone();
    let mut steps = Vec::new();
    let mut difference: Option<ModelDifference> = None;
    // A trust region around the best verified recipe, in units of each
    // unknown's range (max norm): a step that made the colour worse shrinks
    // it to half that step's length; one that improved it widens it 4×.
    let (lo, hi) = problem.bounds(subset);
    let scaled = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .zip(lo.iter().zip(&hi))
            .map(|((p, q), (l, h))| (p - q).abs() / (h - l).max(1e-300))
            .fold(0.0, f64::max)
    };
    let mut radius = 1.0_f64;
    let outcome = loop {
        let k = steps.len();
        let recipe = problem.recipe(subset, &x);
        let step = solve(spec, problem, &recipe, &format!("r{rank}-step{k}"), memory)?;
        progress(&format!(
            "verify recipe {} step {k}: wave ΔE00 {} (fast model's error here {}) in {:.1} s",
            rank,
            geometry_list(problem, &step.de00, &step.de00_se),
            geometry_list(problem, &step.model_error(), &vec![None; step.de00.len()]),
            step.seconds
        ));
        let e = step.difference();
        let worst = step.de00_max();
        steps.push(step);
        if worst <= tol {
            break format!(
                "within {tol} ΔE00 in every geometry after {k} correction step(s) (the wave \
                 solution's colour, its standard error beside it)"
            );
        }
        if k == v.max_steps {
            break format!(
                "not within {tol} ΔE00 after {k} correction step(s) (largest {worst:.3}; the \
                 closest verified recipe is step {}): match.verify.max_steps allows no more",
                best_step(&steps)
            );
        }
        // The trust region follows whether this step improved on the best
        // so far (the difference model's anchor before it learns the step).
        if let Some(d) = &difference {
            radius = if worst >= d.best_score() {
                0.5 * scaled(&x, d.x())
            } else {
                (4.0 * radius).min(1.0)
            };
        }
        let d = match difference.as_mut() {
            None => difference.insert(ModelDifference::new(&x, e, worst)),
            Some(d) => {
                d.update(&x, e, worst);
                d
            }
        };
        if radius < 1e-4 {
            break format!(
                "no correction step improves on step {} any more (the steps that tried made the \
                 colour worse; largest ΔE00 there {:.3})",
                best_step(&steps),
                d.best_score()
            );
        }
        let Some(mut next) = offset_correction(problem, subset, d) else {
            break "the shifted fast model found no corrected recipe; the last verified recipe \
                   is reported"
                .to_string();
        };
        let anchor = d.x();
        let length = scaled(&next, anchor);
        if length > radius {
            // Back along the step to the region's edge: between two
            // recipes within the bounds and the total, so within them too.
            for (y, a) in next.iter_mut().zip(anchor) {
                *y = a + (*y - a) * radius / length;
            }
        }
        if scaled(&next, anchor) < 1e-9 {
            break format!(
                "the correction is stopped at the palette's bounds (largest ΔE00 {worst:.3}): \
                 the wave model reaches this colour only outside them"
            );
        }
        x = next;
    };
    let verified = steps.last().is_some_and(|s| s.de00_max() <= tol);
    Ok(Verification {
        rank,
        steps,
        verified,
        outcome,
    })
}

/// The index of the step closest to the target.
fn best_step(steps: &[VerifyStep]) -> usize {
    (0..steps.len())
        .min_by(|&a, &b| steps[a].de00_max().total_cmp(&steps[b].de00_max()))
        .unwrap_or(0)
}

/// `0.123 ± 0.045 at 45/0, …` over the target's geometries.
fn geometry_list(problem: &Problem, d: &[f64], se: &[Option<f64>]) -> String {
    problem
        .target_lab
        .iter()
        .zip(d.iter().zip(se))
        .map(|((m, _), (d, se))| match se {
            Some(se) => format!("{d:.3} ± {se:.3} at {}", m.name()),
            None => format!("{d:.3} at {}", m.name()),
        })
        .collect::<Vec<_>>()
        .join(", ")
}
