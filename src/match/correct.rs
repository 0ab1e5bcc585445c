//! Correcting a recipe from a measurement: a batch made to the recipe `x`
//! measures `Lab_meas` where the model predicts `Lab(x)`; the fast model's
//! Jacobian `J = ∂Lab/∂x` at `x` turns the remaining difference to the
//! target into a step, the weighted least-squares (Gauss–Newton) solution
//! of `J δx = Lab_target − Lab_meas`, projected into the bounds. The model's
//! own error (or the batch's, such as a pigment of different strength) is
//! in the measurement, so repeating the step converges on the target as
//! long as the model's *change* of colour is right. The same step corrects
//! a fast recipe by a slower, exact model's colour.

use super::problem::{rms, Problem};
use super::solve::{fit_and_polish, jacobian, normal_matrix};

/// The corrected unknowns of `subset` after one step from `x`, given the
/// CIELAB measured in each target geometry (stacked, 3 per geometry).
/// None when the Jacobian does not fix a step.
pub fn correction_step(
    problem: &Problem,
    subset: &[usize],
    x: &[f64],
    measured_lab: &[f64],
) -> Option<Vec<f64>> {
    problem.with_bounds(subset, |bounds| {
        let lab = |y: &[f64]| problem.lab_stack(&problem.recipe(subset, y));
        let j = jacobian(&lab, x, bounds);
        let d: Vec<f64> = problem
            .target_stack()
            .iter()
            .zip(measured_lab)
            .map(|(t, m)| t - m)
            .collect();
        let n = x.len();
        let a = normal_matrix(&j, &vec![1.0; j.len()]);
        let rhs = crate::optics::baseline::matrix::Matrix::from_fn(n, |p, q| {
            if q == 0 {
                j.iter().zip(&d).map(|(row, di)| row[p] * di).sum()
            } else {
                0.0
            }
        });
        let step = super::solve::inverse(&a)?.mul(&rhs);
        let mut y: Vec<f64> = (0..n).map(|p| x[p] + step[(p, 0)]).collect();
        bounds.clamp(&mut y);
        Some(y)
    })
}

/// What the verification knows of the exact model's difference from the
/// fast one, `e(y) = exact(y) − fast(y)` (CIELAB stacked, 3 per
/// geometry): `e(y) ≈ e(a) + B (y − a)`, anchored at the verified recipe
/// `a` closest to the target so far (exact there), its slope `B` learnt
/// from each verified step by Broyden's rank-one update (zero at first: a
/// constant offset). Anchoring at the best recipe rather than the last
/// keeps a step that made the colour worse from leading the next one; what
/// that step taught the slope is kept.
#[derive(Debug, Clone)]
pub struct ModelDifference {
    /// The last verified recipe and its difference.
    last: (Vec<f64>, Vec<f64>),
    /// The anchor (recipe, difference) and its distance to the target.
    anchor: (Vec<f64>, Vec<f64>),
    anchor_score: f64,
    /// Rows: the stacked CIELAB coordinates; columns: the unknowns.
    slope: Vec<Vec<f64>>,
}

impl ModelDifference {
    /// The difference `e` (exact minus fast CIELAB, stacked) at the first
    /// verified recipe `x`, whose `score` is its largest ΔE00 to the target.
    pub fn new(x: &[f64], e: Vec<f64>, score: f64) -> Self {
        ModelDifference {
            slope: vec![vec![0.0; x.len()]; e.len()],
            last: (x.to_vec(), e.clone()),
            anchor: (x.to_vec(), e),
            anchor_score: score,
        }
    }

    /// Learn from the next verified recipe `y`, its difference `e` and its
    /// score.
    pub fn update(&mut self, y: &[f64], e: Vec<f64>, score: f64) {
        let (x, e0) = &self.last;
        let dx: Vec<f64> = y.iter().zip(x).map(|(a, b)| a - b).collect();
        let norm: f64 = dx.iter().map(|d| d * d).sum();
        if norm > 0.0 {
            for (r, row) in self.slope.iter_mut().enumerate() {
                let predicted: f64 = row.iter().zip(&dx).map(|(b, d)| b * d).sum();
                let miss = e[r] - e0[r] - predicted;
                for (b, d) in row.iter_mut().zip(&dx) {
                    *b += miss * d / norm;
                }
            }
        }
        self.last = (y.to_vec(), e.clone());
        if score < self.anchor_score {
            self.anchor = (y.to_vec(), e);
            self.anchor_score = score;
        }
    }

    /// The anchor, from which the next correction starts.
    pub fn x(&self) -> &[f64] {
        &self.anchor.0
    }

    /// The anchor's score: the least largest ΔE00 verified so far.
    pub fn best_score(&self) -> f64 {
        self.anchor_score
    }

    /// The modelled difference at `y`.
    pub fn at(&self, y: &[f64]) -> Vec<f64> {
        let (a, e) = &self.anchor;
        e.iter()
            .zip(&self.slope)
            .map(|(o, row)| {
                o + row
                    .iter()
                    .zip(y.iter().zip(a))
                    .map(|(b, (p, q))| b * (p - q))
                    .sum::<f64>()
            })
            .collect()
    }
}

/// The recipe of `subset` that the fast model plus the modelled fast–exact
/// difference `d` puts on the target: the bounded Levenberg–Marquardt fit
/// of `fast(y) + d(y) = target` from the last verified recipe, polished on
/// the RMS ΔE00 of `fast(y) + d(y)` to the target. Where the difference
/// changes slowly with the recipe, repeating it (with `d` updated from
/// each verified step) converges on the exact model's recipe; unlike one
/// Gauss–Newton step ([`correction_step`]) it keeps the bounds and the
/// total volume fraction inside the fit, not clamped after it. None when
/// the fit gives no finite recipe.
pub fn offset_correction(
    problem: &Problem,
    subset: &[usize],
    d: &ModelDifference,
) -> Option<Vec<f64>> {
    problem.with_bounds(subset, |bounds| {
        let target = problem.target_stack();
        let shifted = |y: &[f64]| -> Vec<f64> {
            let lab = problem.lab_stack(&problem.recipe(subset, y));
            lab.iter().zip(d.at(y)).map(|(l, o)| l + o).collect()
        };
        let residuals = |y: &[f64]| -> Vec<f64> {
            shifted(y).iter().zip(&target).map(|(a, t)| a - t).collect()
        };
        let de00 = |y: &[f64]| rms(&problem.de00_each(&shifted(y)));
        let (y, _) = fit_and_polish(&residuals, Some(&de00), d.x(), bounds);
        y.iter().all(|v| v.is_finite()).then_some(y)
    })
}
