//! A match from file to report: the fast model of the base scene with the
//! palette, the search, and per reported recipe its composition, colour
//! against the target per geometry, metamerism indices and uncertainty.
//!
//! The metamerism indices ([`crate::optics::colour::metamerism`]) compare the
//! recipe's reflectance factor with the target's spectrum in the target's
//! geometry, from the target's illuminant to CIE A, FL11 and LED-B3; a
//! CIELAB target has no spectrum, so they are reported for a spectrum
//! target only.

use std::time::Instant;

use crate::optics::colour::{special_metamerism_index, Metamerism, TestSource};

/// The test sources of the metamerism indices, in report order.
pub const TEST_SOURCES: [TestSource; 3] = TestSource::ALL;
use crate::pipeline::baseline::baseline_input;
use crate::pipeline::fine_grid;
use crate::pipeline::memory::MemoryLimit;

use super::config::MatchSpec;
use super::forward::{FastModel, Recipe};
use super::problem::Problem;
use super::search::{search, Candidate};
use super::uncertainty::{de00_se, uncertainty, Uncertainty};
use super::verify::{self, Verification};
use super::MatchError;

/// One reported recipe.
#[derive(Debug, Clone)]
pub struct RecipeReport {
    /// 1 for the best.
    pub rank: usize,
    pub candidate: Candidate,
    pub recipe: Recipe,
    /// Names of the unknowns: the pigments, then `thickness` when free.
    pub unknowns: Vec<String>,
    /// Whether every geometry is within the tolerance.
    pub reached: bool,
    pub uncertainty: Uncertainty,
    /// Per test source (a spectrum target only).
    pub metamerism: Vec<(TestSource, Metamerism)>,
    /// Reflectance factor in the target's first geometry, on the grid.
    pub factor: Vec<f64>,
    /// Standard error of each geometry's ΔE00 from the target's noise
    /// ([`super::uncertainty::de00_se`]).
    pub de00_se: Vec<f64>,
}

impl RecipeReport {
    /// `name: why` for every unknown the target does not determine.
    pub fn not_determined(&self) -> Vec<String> {
        self.uncertainty.not_determined(&self.unknowns)
    }
}

/// The outcome of a match.
#[derive(Debug, Clone)]
pub struct MatchReport {
    pub recipes: Vec<RecipeReport>,
    /// The model's grid, nm.
    pub wavelengths_nm: Vec<f64>,
    /// The target's geometries and CIELAB.
    pub target_lab: Vec<(crate::config::Measurement, [f64; 3])>,
    /// A spectrum target on the grid.
    pub target_factor: Option<Vec<f64>>,
    /// Palette subsets tried, largest subset size, model evaluations.
    pub subsets: usize,
    pub largest: usize,
    pub evaluations: usize,
    /// The wave-optics verifications of the best recipes (`[match.verify]`;
    /// empty without it), in rank order, and the fidelity they solved at.
    pub verified: Vec<Verification>,
    pub fidelity: Option<String>,
    /// Wall time of the search, the report and the verification, s.
    pub seconds: f64,
}

impl MatchReport {
    /// Whether the best recipe reaches the tolerance (else it is the
    /// closest reachable colour).
    pub fn reached(&self) -> bool {
        self.recipes.first().is_some_and(|r| r.reached)
    }
}

/// The fast model and the problem of a checked match file.
pub fn problem(spec: &MatchSpec) -> Result<Problem, MatchError> {
    let input = baseline_input(&spec.scene)?.ok_or_else(|| MatchError::Config {
        file: spec.path.clone(),
        message: "key `base.substrate`: the fast model needs a ground of one albedo (paper, \
                  white or black)"
            .into(),
    })?;
    if input.wavelengths_nm.len() < fine_grid(&spec.scene.wavelengths_nm).len() {
        return Err(MatchError::Config {
            file: spec.path.clone(),
            message: format!(
                "key `base.illumination.wavelengths_nm`: a palette material has no data over the \
                 whole band {}–{} nm; narrow the band to every material's range (`inksim \
                 materials` lists them)",
                spec.scene.wavelengths_nm[0],
                spec.scene.wavelengths_nm[spec.scene.wavelengths_nm.len() - 1]
            ),
        });
    }
    Problem::new(spec, FastModel::new(spec.model, &input)?)
}

/// The verification's scene (`[match.verify]`; nothing without it) checked
/// before anything runs: made for a recipe of every palette pigment at the
/// thickest allowed layer, checked by the scene checker and its memory
/// estimate against `memory`.
pub fn check_verification(spec: &MatchSpec, memory: Option<MemoryLimit>) -> Result<(), MatchError> {
    if spec.verify.is_none() {
        return Ok(());
    }
    let every: Vec<f64> = spec
        .palette
        .iter()
        .map(|p| 0.5 * (p.pvc_range[0] + p.pvc_range[1]))
        .collect();
    let total: f64 = every.iter().sum();
    let scale = (spec.search.max_total_pvc / total).min(1.0);
    let fractions: Vec<f64> = every.iter().map(|f| f * scale).collect();
    let thickness = spec
        .search
        .thickness_range_nm
        .map_or(spec.scene.layer.thickness_nm, |[_, hi]| hi);
    let scene = verify::scene(spec, &fractions, thickness, "check")?;
    crate::pipeline::memory::fits(&scene, memory)?;
    Ok(())
}

/// Match the target of `spec`; `progress` hears what is done. A
/// verification's wave runs are held to the machine's available memory.
pub fn run(spec: &MatchSpec, progress: &dyn Fn(&str)) -> Result<MatchReport, MatchError> {
    run_with(spec, MemoryLimit::resolve(None), progress)
}

/// [`run`] with the verification's wave runs held to `memory` (each stops
/// before allocating when its estimate exceeds it).
pub fn run_with(
    spec: &MatchSpec,
    memory: Option<MemoryLimit>,
    progress: &dyn Fn(&str),
) -> Result<MatchReport, MatchError> {
    let start = Instant::now();
    let problem = problem(spec)?;
    check_verification(spec, memory)?;
    progress(&format!(
        "fast model {} on {} wavelengths, {} palette pigment(s), objective {}",
        spec.model.name(),
        problem.model.wavelengths_nm().len(),
        spec.palette.len(),
        spec.search.objective.name()
    ));
    let s = &spec.search;
    let outcome = search(
        &problem,
        s.max_colourants,
        s.starts,
        s.tolerance_de00,
        progress,
    );
    let mut recipes = Vec::new();
    for (i, c) in outcome.ranked.iter().take(s.recipes).enumerate() {
        recipes.push(recipe_report(spec, &problem, i + 1, c)?);
    }
    let mut verified = Vec::new();
    let fidelity = spec.verify.as_ref().map(|_| verify::fidelity(spec));
    if let (Some(v), Some(f)) = (&spec.verify, &fidelity) {
        progress(&format!(
            "verifying the best {} recipe(s) with the wave solver: {f}",
            v.recipes.min(recipes.len())
        ));
        for r in recipes.iter().take(v.recipes) {
            verified.push(verify::verify(
                spec,
                &problem,
                (r.rank, &r.candidate),
                memory,
                progress,
            )?);
        }
    }
    Ok(MatchReport {
        verified,
        fidelity,
        recipes,
        wavelengths_nm: problem.model.wavelengths_nm().to_vec(),
        target_lab: problem.target_lab.clone(),
        target_factor: problem.target_factor.clone(),
        subsets: outcome.subsets,
        largest: outcome.largest,
        evaluations: outcome.evaluations,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The report of one candidate.
fn recipe_report(
    spec: &MatchSpec,
    problem: &Problem,
    rank: usize,
    c: &Candidate,
) -> Result<RecipeReport, MatchError> {
    let recipe = problem.recipe(&c.subset, &c.x);
    let mut unknowns: Vec<String> = c
        .subset
        .iter()
        .map(|&s| spec.palette[s].name.clone())
        .collect();
    if problem.thickness_range_nm.is_some() {
        unknowns.push("thickness".into());
    }
    let geometry = problem.target_lab[0].0;
    let factor = problem.model.factor(&recipe, geometry);
    let metamerism = match &problem.target_factor {
        Some(t) => {
            let grid = problem.model.wavelengths_nm();
            let mut out = Vec::new();
            for source in TEST_SOURCES {
                let test = source.observer(spec.target.observer);
                out.push((
                    source,
                    special_metamerism_index(&problem.observer, &test, grid, t, &factor)?,
                ));
            }
            out
        }
        None => Vec::new(),
    };
    let target = problem.target_stack();
    let de00_se = c
        .fit
        .lab
        .iter()
        .zip(target.chunks(3))
        .map(|(l, t)| de00_se(*l, [t[0], t[1], t[2]], problem.noise_lab))
        .collect();
    Ok(RecipeReport {
        rank,
        de00_se,
        uncertainty: uncertainty(problem, &c.subset, &c.x, &unknowns),
        reached: c.reaches(spec.search.tolerance_de00),
        candidate: c.clone(),
        recipe,
        unknowns,
        metamerism,
        factor,
    })
}
