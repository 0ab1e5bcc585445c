//! Bounded least squares for a handful of unknowns: a projected
//! Levenberg–Marquardt on a residual vector, a Nelder–Mead polish for a
//! scalar objective that is not a sum of squares (CIEDE2000), and the
//! finite-difference Jacobian both the search and the uncertainty use.
//!
//! The unknowns live in a box `lo ≤ x ≤ hi` with one extra constraint the
//! caller projects onto (`project`, e.g. a total volume fraction); every
//! trial point is projected before it is evaluated, so the model is never
//! asked about a recipe outside its bounds. Small dense systems (at most
//! five unknowns) are solved by the adding–doubling's Gaussian elimination
//! ([`Matrix::solve`]).

use crate::optics::baseline::matrix::Matrix;

/// The box and the extra projection of the unknowns.
pub struct Bounds<'a> {
    pub lo: &'a [f64],
    pub hi: &'a [f64],
    /// Carries a point in the box onto the feasible set (identity if none).
    pub project: &'a dyn Fn(&mut [f64]),
}

impl Bounds<'_> {
    /// `x` clamped into the box, then projected.
    pub fn clamp(&self, x: &mut [f64]) {
        for ((v, lo), hi) in x.iter_mut().zip(self.lo).zip(self.hi) {
            *v = v.clamp(*lo, *hi);
        }
        (self.project)(x);
    }

    /// The difference step of unknown `j`: a millionth of its range.
    fn step(&self, j: usize) -> f64 {
        1e-6 * (self.hi[j] - self.lo[j]).max(1e-9)
    }
}

/// `J[i][j] = ∂r_i/∂x_j` by central differences inside the box (one-sided
/// at a bound), each step a millionth of the unknown's range.
pub fn jacobian(f: &dyn Fn(&[f64]) -> Vec<f64>, x: &[f64], bounds: &Bounds) -> Vec<Vec<f64>> {
    let r0 = f(x);
    let mut cols = Vec::with_capacity(x.len());
    for j in 0..x.len() {
        let h = bounds.step(j);
        let up = (x[j] + h).min(bounds.hi[j]);
        let down = (x[j] - h).max(bounds.lo[j]);
        let at = |v: f64| {
            let mut y = x.to_vec();
            y[j] = v;
            y
        };
        let (ru, rd) = (
            if up > x[j] { f(&at(up)) } else { r0.clone() },
            if down < x[j] {
                f(&at(down))
            } else {
                r0.clone()
            },
        );
        let dx = up - down;
        cols.push(
            ru.iter()
                .zip(&rd)
                .map(|(a, b)| if dx > 0.0 { (a - b) / dx } else { 0.0 })
                .collect::<Vec<f64>>(),
        );
    }
    (0..r0.len())
        .map(|i| cols.iter().map(|c| c[i]).collect())
        .collect()
}

/// `JᵀJ` of a Jacobian (rows residuals), weighted by `w[i]` per residual.
pub fn normal_matrix(j: &[Vec<f64>], w: &[f64]) -> Matrix {
    let n = j.first().map_or(0, Vec::len);
    Matrix::from_fn(n, |a, b| {
        j.iter().zip(w).map(|(row, wi)| wi * row[a] * row[b]).sum()
    })
}

/// `A⁻¹`, or None when `A` is singular to working precision (the
/// elimination's residual `A A⁻¹ − I` is not small).
pub fn inverse(a: &Matrix) -> Option<Matrix> {
    let n = a.size();
    let inv = a.solve(&Matrix::identity(n)).ok()?;
    let check = a.mul(&inv);
    (check.max_difference(&Matrix::identity(n)) < 1e-8).then_some(inv)
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// The point reached and its cost.
#[derive(Debug, Clone)]
pub struct Minimum {
    pub x: Vec<f64>,
    /// `Σ r²` (Levenberg–Marquardt) or the objective (Nelder–Mead).
    pub cost: f64,
    /// Objective evaluations spent.
    pub evaluations: usize,
}

/// A scalar objective of the unknowns.
pub type ScalarFn<'a> = &'a dyn Fn(&[f64]) -> f64;

/// One start of a fit: Levenberg–Marquardt on `residuals` from `x0`,
/// then, where `polish` is given and exceeds 1e-3 there, Nelder–Mead on
/// it, kept where it does better. The point and the evaluations spent.
pub fn fit_and_polish(
    residuals: &dyn Fn(&[f64]) -> Vec<f64>,
    polish: Option<ScalarFn>,
    x0: &[f64],
    bounds: &Bounds,
) -> (Vec<f64>, usize) {
    fit_and_polish_to(residuals, polish, x0, bounds, DEFAULT_RELATIVE_TOLERANCE)
}

/// The relative lowering of the cost below which Levenberg–Marquardt stops.
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-12;

/// [`fit_and_polish`] with the Levenberg–Marquardt stopping when no step
/// lowers the cost by more than `relative` of it.
pub fn fit_and_polish_to(
    residuals: &dyn Fn(&[f64]) -> Vec<f64>,
    polish: Option<ScalarFn>,
    x0: &[f64],
    bounds: &Bounds,
    relative: f64,
) -> (Vec<f64>, usize) {
    let m = levenberg_marquardt_to(residuals, x0, bounds, 200, 1e-14, relative);
    let (mut x, mut evaluations) = (m.x, m.evaluations);
    if let Some(f) = polish {
        if f(&x) > 1e-3 {
            let p = nelder_mead(f, &x, bounds, 400, 1e-9);
            evaluations += p.evaluations;
            if p.cost < f(&x) {
                x = p.x;
            }
        }
    }
    (x, evaluations)
}

/// Minimise `Σ r(x)²` from `x0` inside `bounds` by projected
/// Levenberg–Marquardt (Marquardt's diagonal scaling; the damping is cut
/// by 3 after a step that lowers the cost and raised by 4 until one does).
/// Stops after `max_iterations`, when the cost is below `cost_floor` or
/// when no step lowers it by more than a relative 1e-12.
pub fn levenberg_marquardt(
    f: &dyn Fn(&[f64]) -> Vec<f64>,
    x0: &[f64],
    bounds: &Bounds,
    max_iterations: usize,
    cost_floor: f64,
) -> Minimum {
    levenberg_marquardt_to(
        f,
        x0,
        bounds,
        max_iterations,
        cost_floor,
        DEFAULT_RELATIVE_TOLERANCE,
    )
}

/// [`levenberg_marquardt`] stopping when no step lowers the cost by more
/// than `relative` of it.
pub fn levenberg_marquardt_to(
    f: &dyn Fn(&[f64]) -> Vec<f64>,
    x0: &[f64],
    bounds: &Bounds,
    max_iterations: usize,
    cost_floor: f64,
    relative: f64,
) -> Minimum {
    let n = x0.len();
    let mut x = x0.to_vec();
    bounds.clamp(&mut x);
    let mut r = f(&x);
    let mut cost = sum_sq(&r);
    let mut evaluations = 1;
    let mut lambda = 1e-3;
    for _ in 0..max_iterations {
        if cost <= cost_floor {
            break;
        }
        let j = jacobian(f, &x, bounds);
        evaluations += 2 * n;
        let a = normal_matrix(&j, &vec![1.0; r.len()]);
        let g: Vec<f64> = (0..n)
            .map(|c| j.iter().zip(&r).map(|(row, ri)| row[c] * ri).sum())
            .collect();
        let mut improved = false;
        for _ in 0..12 {
            let m = Matrix::from_fn(n, |p, q| {
                a[(p, q)]
                    + if p == q {
                        lambda * a[(p, p)].max(1e-12)
                    } else {
                        0.0
                    }
            });
            let rhs = Matrix::from_fn(n, |p, q| if q == 0 { -g[p] } else { 0.0 });
            let Ok(step) = m.solve(&rhs) else {
                lambda *= 4.0;
                continue;
            };
            let mut xn: Vec<f64> = (0..n).map(|p| x[p] + step[(p, 0)]).collect();
            bounds.clamp(&mut xn);
            let rn = f(&xn);
            evaluations += 1;
            let cn = sum_sq(&rn);
            if cn.is_finite() && cn < cost {
                improved = cost - cn > relative * cost;
                (x, r, cost) = (xn, rn, cn);
                lambda = (lambda / 3.0).max(1e-12);
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
    }
    Minimum {
        x,
        cost,
        evaluations,
    }
}

/// Minimise the scalar `f` from `x0` inside `bounds` by Nelder–Mead (the
/// standard coefficients 1, 2, ½, ½; the first simplex steps a tenth of
/// each unknown's range), every vertex projected into the bounds. Stops
/// after `max_evaluations` or when the simplex's values agree to `f_tol`.
pub fn nelder_mead(
    f: &dyn Fn(&[f64]) -> f64,
    x0: &[f64],
    bounds: &Bounds,
    max_evaluations: usize,
    f_tol: f64,
) -> Minimum {
    let n = x0.len();
    let evaluations = std::cell::Cell::new(0);
    let eval = |x: &mut Vec<f64>| {
        bounds.clamp(x);
        evaluations.set(evaluations.get() + 1);
        let v = f(x);
        if v.is_finite() {
            v
        } else {
            f64::MAX
        }
    };
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    let mut start = x0.to_vec();
    let v = eval(&mut start);
    simplex.push((start.clone(), v));
    for j in 0..n {
        let mut y = start.clone();
        let d = 0.1 * (bounds.hi[j] - bounds.lo[j]);
        y[j] = if y[j] + d <= bounds.hi[j] {
            y[j] + d
        } else {
            y[j] - d
        };
        let v = eval(&mut y);
        simplex.push((y, v));
    }
    while evaluations.get() < max_evaluations {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if simplex[n].1 - simplex[0].1 <= f_tol {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|j| simplex[..n].iter().map(|p| p.0[j]).sum::<f64>() / n as f64)
            .collect();
        let along = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|j| centroid[j] + t * (simplex[n].0[j] - centroid[j]))
                .collect()
        };
        let mut xr = along(-1.0);
        let fr = eval(&mut xr);
        if fr < simplex[0].1 {
            let mut xe = along(-2.0);
            let fe = eval(&mut xe);
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let mut xc = along(if fr < simplex[n].1 { -0.5 } else { 0.5 });
            let fc = eval(&mut xc);
            if fc < simplex[n].1.min(fr) {
                simplex[n] = (xc, fc);
            } else {
                let best = simplex[0].0.clone();
                for p in simplex.iter_mut().skip(1) {
                    let mut y: Vec<f64> = best
                        .iter()
                        .zip(&p.0)
                        .map(|(b, v)| b + 0.5 * (v - b))
                        .collect();
                    let v = eval(&mut y);
                    *p = (y, v);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x, cost) = simplex.swap_remove(0);
    Minimum {
        x,
        cost,
        evaluations: evaluations.get(),
    }
}
