//! Correcting a recipe from a measurement: a batch made to the recipe `x`
//! measures `Lab_meas` where the model predicts `Lab(x)`; the fast model's
//! Jacobian `J = ∂Lab/∂x` at `x` turns the remaining difference to the
//! target into a step, the weighted least-squares (Gauss–Newton) solution
//! of `J δx = Lab_target − Lab_meas`, projected into the bounds. The model's
//! own error (or the batch's, such as a pigment of different strength) is
//! in the measurement, so repeating the step converges on the target as
//! long as the model's *change* of colour is right. The same step corrects
//! a fast recipe by a slower, exact model's colour.

use super::problem::Problem;
use super::solve::{jacobian, normal_matrix, Bounds};

/// The corrected unknowns of `subset` after one step from `x`, given the
/// CIELAB measured in each target geometry (stacked, 3 per geometry).
/// None when the Jacobian does not fix a step.
pub fn correction_step(
    problem: &Problem,
    subset: &[usize],
    x: &[f64],
    measured_lab: &[f64],
) -> Option<Vec<f64>> {
    let (lo, hi) = problem.bounds(subset);
    let k = subset.len();
    let project = |y: &mut [f64]| problem.project_total(k, &lo, y);
    let bounds = Bounds {
        lo: &lo,
        hi: &hi,
        project: &project,
    };
    let lab = |y: &[f64]| problem.lab_stack(&problem.recipe(subset, y));
    let j = jacobian(&lab, x, &bounds);
    let target: Vec<f64> = problem.target_lab.iter().flat_map(|(_, l)| *l).collect();
    let d: Vec<f64> = target
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
}
