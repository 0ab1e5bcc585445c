//! The search: every subset of the palette of 1, 2, … up to
//! `max_colourants` pigments (0, 1, … where some unknowns are in every
//! recipe, as an effect paint's flakes are) whose least volume fractions fit the total,
//! fewest first; each subset's unknowns fitted from several starting
//! points inside its bounds (the middle of the box, then a Halton sequence
//! over it) by projected Levenberg–Marquardt ([`super::solve`]), a CIEDE2000
//! objective then polished by Nelder–Mead on ΔE00 itself; the best of each
//! subset kept. Once some subset of `k` pigments reaches the tolerance
//! (every geometry's ΔE00 at most `tolerance_de00`), larger subsets are not
//! tried: the fewest colourants that reach it are preferred. Recipes are
//! ranked: those within the tolerance first, fewest colourants, then by
//! the objective; then the others by the objective (the first of them is
//! the closest reachable colour).

use rayon::prelude::*;

use super::config::Objective;
use super::problem::{with_bounds, Fit, Inverse};
use super::solve::fit_and_polish_to;

/// The best recipe found for one subset of the palette.
#[derive(Debug, Clone)]
pub struct Candidate {
    /// Palette indices of its pigments.
    pub subset: Vec<usize>,
    /// Its unknowns (volume fractions, then the thickness when free).
    pub x: Vec<f64>,
    pub fit: Fit,
    /// The objective's value: spectral RMS or RMS ΔE00 over the geometries.
    pub objective: f64,
    /// Model evaluations spent on the subset.
    pub evaluations: usize,
}

impl Candidate {
    /// Whether every geometry is within `tolerance` ΔE00.
    pub fn reaches(&self, tolerance: f64) -> bool {
        self.fit.de00_max() <= tolerance
    }
}

/// The outcome of a search.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Every subset's best recipe, ranked (module docs).
    pub ranked: Vec<Candidate>,
    /// Subsets tried, and the largest subset size tried.
    pub subsets: usize,
    pub largest: usize,
    /// Model evaluations in all.
    pub evaluations: usize,
}

/// Subsets of `0..n` of size `k`, in lexicographic order (one, empty, of
/// size 0).
pub fn subsets(n: usize, k: usize) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut cur: Vec<usize> = (0..k).collect();
    if k == 0 {
        return vec![Vec::new()];
    }
    if k > n {
        return out;
    }
    loop {
        out.push(cur.clone());
        let Some(i) = (0..k).rev().find(|&i| cur[i] < n - k + i) else {
            return out;
        };
        cur[i] += 1;
        for j in i + 1..k {
            cur[j] = cur[j - 1] + 1;
        }
    }
}

/// The `i`-th element of the Halton sequence in base `b`, in (0, 1).
fn halton(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    i += 1;
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

const PRIMES: [usize; 6] = [2, 3, 5, 7, 11, 13];

/// The `s`-th starting point in the box: its middle, then Halton points.
fn start(s: usize, lo: &[f64], hi: &[f64]) -> Vec<f64> {
    (0..lo.len())
        .map(|j| {
            let u = if s == 0 {
                0.5
            } else {
                halton(s - 1, PRIMES[j % PRIMES.len()])
            };
            lo[j] + u * (hi[j] - lo[j])
        })
        .collect()
}

/// Fit one subset from `starts` starting points; its best recipe.
pub fn fit_subset<P: Inverse + ?Sized>(problem: &P, subset: &[usize], starts: usize) -> Candidate {
    with_bounds(problem, subset, |bounds| {
        let residuals = |x: &[f64]| problem.residuals_at(subset, x);
        let de00 = |x: &[f64]| problem.fit_at(subset, x).de00_rms();
        let mut best: Option<Candidate> = None;
        let mut evaluations = 0;
        for s in 0..starts {
            let polish = problem.polish().then_some(&de00 as super::solve::ScalarFn);
            let (x, spent) = fit_and_polish_to(
                &residuals,
                polish,
                &start(s, bounds.lo, bounds.hi),
                bounds,
                problem.relative_tolerance(),
            );
            evaluations += spent;
            let fit = problem.fit_at(subset, &x);
            let objective = match problem.objective() {
                Objective::SpectralRms => fit.spectral_rms.unwrap_or_else(|| fit.de00_rms()),
                Objective::De00 => fit.de00_rms(),
            };
            if best.as_ref().is_none_or(|b| objective < b.objective) {
                best = Some(Candidate {
                    subset: subset.to_vec(),
                    x,
                    fit,
                    objective,
                    evaluations: 0,
                });
            }
        }
        let mut best = best.expect("at least one start");
        best.evaluations = evaluations;
        best
    })
}

/// Search the palette (module docs); `progress` hears one line per subset
/// size.
pub fn search<P: Inverse + ?Sized>(
    problem: &P,
    max_colourants: usize,
    starts: usize,
    tolerance_de00: f64,
    progress: &dyn Fn(&str),
) -> Outcome {
    let n = problem.colourants();
    let mut all: Vec<Candidate> = Vec::new();
    let (mut tried, mut largest) = (0, 0);
    for k in problem.fewest()..=max_colourants.min(n).max(problem.fewest()) {
        let sets: Vec<Vec<usize>> = subsets(n, k)
            .into_iter()
            .filter(|s| problem.feasible(s))
            .collect();
        let found: Vec<Candidate> = sets
            .par_iter()
            .map(|s| fit_subset(problem, s, starts))
            .collect();
        tried += sets.len();
        largest = k;
        let reached = found.iter().filter(|c| c.reaches(tolerance_de00)).count();
        let best = found
            .iter()
            .map(|c| c.fit.de00_max())
            .fold(f64::INFINITY, f64::min);
        progress(&format!(
            "{k} colourant(s): {} subset(s), {reached} within {tolerance_de00} ΔE00, best {}",
            sets.len(),
            if best.is_finite() {
                format!("{best:.3} ΔE00")
            } else {
                "none".into()
            }
        ));
        all.extend(found);
        if reached > 0 {
            break;
        }
    }
    let evaluations = all.iter().map(|c| c.evaluations).sum();
    all.sort_by(|a, b| {
        let (ra, rb) = (a.reaches(tolerance_de00), b.reaches(tolerance_de00));
        rb.cmp(&ra)
            .then_with(|| {
                if ra && rb {
                    a.subset.len().cmp(&b.subset.len())
                } else {
                    std::cmp::Ordering::Equal
                }
            })
            .then_with(|| a.objective.total_cmp(&b.objective))
    });
    Outcome {
        ranked: all,
        subsets: tried,
        largest,
        evaluations,
    }
}
