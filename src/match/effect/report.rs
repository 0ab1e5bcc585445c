//! An effect match from file to report: the problem, the search (the scene
//! match's own, [`super::super::search`]) and per reported recipe its
//! unknowns with their uncertainty, its colour against the target per
//! geometry with the standard error of each ΔE00, and its multi-angle
//! colours and flop index.
//!
//! Each ΔE00's standard error is the scene match's
//! ([`super::super::uncertainty::de00_se`]).

use std::time::Instant;

use crate::optics::flakes::multiangle::{self, AngleColour, Geometry};

use super::super::problem::Inverse;
use super::super::search::{search, Candidate};
use super::super::uncertainty::{de00_se, uncertainty, Uncertainty};
use super::super::MatchError;
use super::config::EffectSpec;
use super::problem::EffectProblem;

/// One reported recipe of an effect match.
#[derive(Debug, Clone)]
pub struct EffectRecipe {
    /// 1 for the best.
    pub rank: usize,
    pub candidate: Candidate,
    /// Names of the unknowns ([`EffectProblem::unknowns`]).
    pub unknowns: Vec<String>,
    /// Whether every geometry is within the tolerance.
    pub reached: bool,
    pub uncertainty: Uncertainty,
    /// Standard error of each target geometry's ΔE00 from the target's
    /// noise (module docs).
    pub de00_se: Vec<f64>,
    /// Volume fraction of each optional pigment (0: not used), in file
    /// order.
    pub pvc: Vec<f64>,
    /// Per varied flake layer, in file order: concentration and coating
    /// thickness (nm; the base's where it is not varied, NaN for a flake
    /// without a coating).
    pub concentration: Vec<f64>,
    pub coating_nm: Vec<f64>,
    /// The recipe's colours in every multi-angle geometry.
    pub colours: Vec<AngleColour>,
    pub flop_index: Option<f64>,
}

impl EffectRecipe {
    /// `name: why` for every unknown the target does not determine.
    pub fn not_determined(&self) -> Vec<String> {
        self.uncertainty.not_determined(&self.unknowns)
    }
}

/// The outcome of an effect match.
#[derive(Debug, Clone)]
pub struct EffectReport {
    pub recipes: Vec<EffectRecipe>,
    pub wavelengths_nm: Vec<f64>,
    /// The target's geometries and CIELAB, and its flop index (when it has
    /// the three geometries of the index).
    pub target: Vec<(Geometry, [f64; 3])>,
    pub target_flop_index: Option<f64>,
    /// Subsets tried, largest subset size, model evaluations.
    pub subsets: usize,
    pub largest: usize,
    pub evaluations: usize,
    /// Wall time of the search and the report, s.
    pub seconds: f64,
}

impl EffectReport {
    /// Whether the best recipe reaches the tolerance (else it is the
    /// closest reachable colour).
    pub fn reached(&self) -> bool {
        self.recipes.first().is_some_and(|r| r.reached)
    }
}

/// Match the effect target of `spec`; `progress` hears what is done.
pub fn run(spec: &EffectSpec, progress: &dyn Fn(&str)) -> Result<EffectReport, MatchError> {
    let start = Instant::now();
    let problem = EffectProblem::new(spec)?;
    progress(&format!(
        "fast flake model of the base paint on {} wavelengths, {} geometries in the target, \
         {} flake layer(s) and {} optional pigment(s) varied",
        problem.model.wavelengths_nm().len(),
        problem.target.len(),
        spec.flakes.len(),
        spec.pigments.len()
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
        recipes.push(recipe_report(&problem, i + 1, c)?);
    }
    Ok(EffectReport {
        recipes,
        wavelengths_nm: problem.model.wavelengths_nm().to_vec(),
        target: problem.target.clone(),
        target_flop_index: problem.target_flop_index(),
        subsets: outcome.subsets,
        largest: outcome.largest,
        evaluations: outcome.evaluations,
        seconds: start.elapsed().as_secs_f64(),
    })
}

fn recipe_report(
    problem: &EffectProblem,
    rank: usize,
    c: &Candidate,
) -> Result<EffectRecipe, MatchError> {
    let spec = &problem.spec;
    let unknowns = problem.unknowns(&c.subset);
    let colours = problem.colours(&c.subset, &c.x)?;
    let sigma = problem.noise_lab();
    let de00_se = c
        .fit
        .lab
        .iter()
        .zip(&problem.target)
        .map(|(l, (_, t))| de00_se(*l, *t, sigma))
        .collect();
    let pvc = (0..spec.pigments.len())
        .map(|s| {
            c.subset
                .iter()
                .position(|&q| q == s)
                .map_or(0.0, |k| c.x[k])
        })
        .collect();
    let paint = problem.model.paint(&problem.settings(&c.subset, &c.x));
    let (mut concentration, mut coating_nm) = (Vec::new(), Vec::new());
    for f in &spec.flakes {
        let flakes = paint.layers[f.layer_index].flakes.as_ref();
        concentration.push(flakes.map_or(f64::NAN, |f| f.volume_fraction));
        coating_nm.push(flakes.map_or(f64::NAN, |f| match &f.reflector {
            crate::config::paint::ReflectorSpec::Coated { coating, .. } => coating.thickness_nm,
            _ => f64::NAN,
        }));
    }
    Ok(EffectRecipe {
        rank,
        uncertainty: uncertainty(problem, &c.subset, &c.x, &unknowns),
        reached: c.reaches(spec.search.tolerance_de00),
        candidate: c.clone(),
        unknowns,
        de00_se,
        pvc,
        concentration,
        coating_nm,
        flop_index: multiangle::flop_index_of(&colours),
        colours,
    })
}
