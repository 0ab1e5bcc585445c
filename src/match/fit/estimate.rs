//! The fit: the pigment's constants at each wavelength, and its grain
//! diameter shared by all of them when it is free.
//!
//! With `σ` the measurement noise, the residuals of wavelength `λ` are
//! `r_i = (R_i(θ_λ, d) − M_i(λ)) / σ` over every reading `i` (each
//! drawdown over each of its grounds), `θ_λ = k` or `(n, k)`. At a fixed
//! diameter the wavelengths are independent: each `Σ r_i²` is minimised by
//! the match's projected Levenberg–Marquardt ([`levenberg_marquardt`]) from
//! several starting points inside the bounds (`k ≥ 0`, `n` within its
//! range), the best kept. A free diameter is shared: the cost of a
//! diameter is the sum of the wavelengths' minima (variable projection),
//! scanned on a geometric grid over its bounds and then minimised by
//! Nelder–Mead ([`nelder_mead`]) from the best point of the scan.
//!
//! **Standard errors.** To first order the estimates move with the noise
//! by the Gauss–Markov covariance `C = (JᵀJ)⁻¹` of the σ-scaled residuals,
//! `J` their Jacobian in all the unknowns (central differences). `JᵀJ` is
//! block diagonal in the wavelengths, bordered by the diameter's row and
//! column when it is free; its inverse is taken exactly by the Schur
//! complement of the diameter, `S = Σ_λ (c_λ − b_λᵀ A_λ⁻¹ b_λ)` with
//! `A_λ = J_θᵀJ_θ`, `b_λ = J_θᵀJ_d`, `c_λ = J_dᵀJ_d`: `var d = 1/S` and
//! `C_λ = A_λ⁻¹ + A_λ⁻¹ b_λ b_λᵀ A_λ⁻¹ / S`. A constant is flagged as not
//! determined as the match flags an ingredient ([`MAX_CORRELATION`],
//! [`MAX_RELATIVE_SE`]): `JᵀJ` singular, `n` and `k` correlated beyond
//! 0.95, a standard error above half the value, the value at a bound, or
//! another minimum (from a denser set of starting points) within
//! `Δχ² ≤ 4` of the best but more than 3 standard errors away — a dark layer can fit two
//! separate `(n, k)` equally well, which no local standard error shows.

use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use crate::optics::baseline::matrix::Matrix;

use super::super::solve::{
    inverse, jacobian, levenberg_marquardt, nelder_mead, normal_matrix, Bounds,
};
use super::super::uncertainty::{MAX_CORRELATION, MAX_RELATIVE_SE};
use super::config::{FitSpec, Unknowns, MAX_K};
use super::model::DrawdownModel;

/// Starting values of `k` at each wavelength (decades: the fit's cost is
/// not convex in `k` over them).
const K_STARTS: [f64; 4] = [1e-3, 1e-2, 0.1, 1.0];
/// Diameters of the scan of a free size.
const SIZE_SCAN: usize = 9;
/// A rival minimum within this `χ²` of the best fits about as well (2σ
/// of one constant).
const RIVAL_CHI2: f64 = 4.0;
/// … and is a rival when this many standard errors away.
const RIVAL_SE: f64 = 3.0;
/// Levenberg–Marquardt iterations per start.
const LM_ITERATIONS: usize = 200;

/// The fit at one wavelength.
#[derive(Debug, Clone)]
pub struct WavelengthFit {
    pub n: f64,
    pub k: f64,
    /// Standard errors (None: not determined, `JᵀJ` singular); `n`'s is
    /// None where `n` is known.
    pub n_se: Option<f64>,
    pub k_se: Option<f64>,
    /// Correlation of `n` and `k` (an `n-and-k` fit).
    pub correlation_nk: Option<f64>,
    /// Model minus measured reflectance factor of every reading.
    pub residuals: Vec<f64>,
    /// Why `n` / `k` is not determined (empty when it is).
    pub n_flags: String,
    pub k_flags: String,
}

impl WavelengthFit {
    /// Root-mean-square of the residuals.
    pub fn rms(&self) -> f64 {
        rms(&self.residuals)
    }
}

fn rms(r: &[f64]) -> f64 {
    (r.iter().map(|v| v * v).sum::<f64>() / r.len().max(1) as f64).sqrt()
}

/// The outcome of a fit.
#[derive(Debug, Clone)]
pub struct FitOutcome {
    pub wavelengths_nm: Vec<f64>,
    pub per_wavelength: Vec<WavelengthFit>,
    /// The grain diameter (fitted when free), nm, its standard error when
    /// free and determined, and why it is not determined.
    pub diameter_nm: f64,
    pub diameter_se: Option<f64>,
    pub diameter_flags: String,
    /// The free size's scan: (diameter nm, χ² of the best constants).
    pub size_scan: Vec<(f64, f64)>,
    /// `Σ r²/σ²` over everything, and its degrees of freedom.
    pub chi2: f64,
    pub dof: usize,
    /// Forward-model evaluations and wall time, s.
    pub evaluations: usize,
    pub seconds: f64,
}

impl FitOutcome {
    /// RMS of every residual (reflectance factor).
    pub fn rms(&self) -> f64 {
        let all: Vec<f64> = self
            .per_wavelength
            .iter()
            .flat_map(|w| w.residuals.iter().copied())
            .collect();
        rms(&all)
    }

    /// `χ²` per degree of freedom: about 1 when the model explains the
    /// spectra to within the stated noise.
    pub fn chi2_per_dof(&self) -> f64 {
        self.chi2 / self.dof.max(1) as f64
    }

    /// `constant at λ nm: why` for every constant not determined.
    pub fn not_determined(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !self.diameter_flags.is_empty() {
            out.push(format!("diameter: {}", self.diameter_flags));
        }
        for (w, f) in self.wavelengths_nm.iter().zip(&self.per_wavelength) {
            for (c, why) in [("n", &f.n_flags), ("k", &f.k_flags)] {
                if !why.is_empty() {
                    out.push(format!("{c} at {w} nm: {why}"));
                }
            }
        }
        out
    }
}

/// The per-wavelength problem of a fit file.
struct Problem<'a> {
    model: &'a DrawdownModel,
    unknowns: Unknowns,
    noise: f64,
    evaluations: &'a AtomicUsize,
}

impl Problem<'_> {
    /// Bounds of `θ_λ`.
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        match self.unknowns {
            Unknowns::K { .. } => (vec![0.0], vec![MAX_K]),
            Unknowns::NAndK { n_range } => (vec![n_range[0], 0.0], vec![n_range[1], MAX_K]),
        }
    }

    /// `(n, k)` of `θ`.
    fn nk(&self, x: &[f64]) -> (f64, f64) {
        match self.unknowns {
            Unknowns::K { n } => (n, x[0]),
            Unknowns::NAndK { .. } => (x[0], x[1]),
        }
    }

    /// σ-scaled residuals at wavelength `l` of `θ = x` and diameter `d`.
    fn residuals(&self, l: usize, x: &[f64], d: f64) -> Vec<f64> {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let (n, k) = self.nk(x);
        let f = self.model.factors(l, n, k, d);
        f.iter()
            .zip(self.model.measured(l))
            .map(|(a, b)| (a - b) / self.noise)
            .collect()
    }

    /// The starting points of `θ`.
    fn starts(&self) -> Vec<Vec<f64>> {
        match self.unknowns {
            Unknowns::K { .. } => K_STARTS.iter().map(|&k| vec![k]).collect(),
            Unknowns::NAndK { n_range: [lo, hi] } => [0.2, 0.5, 0.8]
                .iter()
                .flat_map(|t| K_STARTS.iter().map(move |&k| vec![lo + t * (hi - lo), k]))
                .collect(),
        }
    }

    /// The starting points of the search for a rival minimum: twice as
    /// dense as [`Self::starts`] in each constant.
    fn rival_starts(&self) -> Vec<Vec<f64>> {
        let ks: Vec<f64> = (0..8)
            .map(|i| 1e-3 * 10f64.powf(i as f64 * 3.5 / 7.0))
            .collect();
        match self.unknowns {
            Unknowns::K { .. } => ks.iter().map(|&k| vec![k]).collect(),
            Unknowns::NAndK { n_range: [lo, hi] } => (0..6)
                .flat_map(|i| {
                    let n = lo + (i as f64 + 0.5) / 6.0 * (hi - lo);
                    ks.iter().map(move |&k| vec![n, k])
                })
                .collect(),
        }
    }

    /// The minimum reached from each of `starts` at wavelength `l` for
    /// diameter `d`, with its cost `Σ r²`.
    fn minima(&self, l: usize, d: f64, starts: &[Vec<f64>]) -> Vec<(Vec<f64>, f64)> {
        let (lo, hi) = self.bounds();
        let identity = |_: &mut [f64]| {};
        let bounds = Bounds {
            lo: &lo,
            hi: &hi,
            project: &identity,
        };
        let f = |x: &[f64]| self.residuals(l, x, d);
        starts
            .iter()
            .map(|s| {
                let m = levenberg_marquardt(&f, s, &bounds, LM_ITERATIONS, 0.0);
                (m.x, m.cost)
            })
            .collect()
    }

    /// The best `θ` at wavelength `l` for diameter `d` from `starts`, and
    /// its cost.
    fn best(&self, l: usize, d: f64, starts: &[Vec<f64>]) -> (Vec<f64>, f64) {
        self.minima(l, d, starts)
            .into_iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((starts[0].clone(), f64::INFINITY))
    }

    /// Every wavelength's best `θ` at diameter `d`, from the starting
    /// points and `warm` (a previous solution, when given); the total cost.
    fn all(&self, d: f64, warm: Option<&[Vec<f64>]>, cold: bool) -> (Vec<Vec<f64>>, f64) {
        let n = self.model.wavelengths_nm().len();
        let found: Vec<(Vec<f64>, f64)> = (0..n)
            .into_par_iter()
            .map(|l| {
                let mut starts = if cold { self.starts() } else { Vec::new() };
                if let Some(w) = warm {
                    starts.push(w[l].clone());
                }
                self.best(l, d, &starts)
            })
            .collect();
        let cost = found.iter().map(|f| f.1).sum();
        (found.into_iter().map(|f| f.0).collect(), cost)
    }
}

/// Fit the pigment of `spec` on `model` (module docs).
pub fn fit(spec: &FitSpec, model: &DrawdownModel) -> FitOutcome {
    let start = Instant::now();
    let evaluations = AtomicUsize::new(0);
    let p = Problem {
        model,
        unknowns: spec.pigment.unknowns,
        noise: spec.noise,
        evaluations: &evaluations,
    };
    let d0 = spec.pigment.diameter_nm;
    let (theta, d, size_scan) = match spec.pigment.diameter_range_nm {
        None => {
            let (theta, _) = p.all(d0, None, true);
            (theta, d0, Vec::new())
        }
        Some([lo, hi]) => free_size(&p, d0, [lo, hi]),
    };
    let wl = model.wavelengths_nm().to_vec();
    let (per_wavelength, diameter_se, diameter_flags) =
        uncertainty(&p, &theta, d, spec.pigment.diameter_range_nm);
    let chi2: f64 = per_wavelength
        .iter()
        .flat_map(|w| w.residuals.iter().map(|r| (r / spec.noise).powi(2)))
        .sum();
    let unknowns = wl.len() * spec.pigment.unknowns.per_wavelength()
        + usize::from(spec.pigment.diameter_range_nm.is_some());
    FitOutcome {
        wavelengths_nm: wl.clone(),
        per_wavelength,
        diameter_nm: d,
        diameter_se,
        diameter_flags,
        size_scan,
        chi2,
        dof: (wl.len() * model.readings()).saturating_sub(unknowns),
        evaluations: evaluations.load(Ordering::Relaxed),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// The free diameter: the scan, then Nelder–Mead on the profile cost from
/// its best point; every wavelength's `θ` at the diameter found.
#[allow(clippy::type_complexity)]
fn free_size(p: &Problem, d0: f64, [lo, hi]: [f64; 2]) -> (Vec<Vec<f64>>, f64, Vec<(f64, f64)>) {
    let mut scan: Vec<(f64, f64)> = Vec::with_capacity(SIZE_SCAN + 1);
    let mut best: Option<(f64, Vec<Vec<f64>>, f64)> = None;
    let mut grid: Vec<f64> = (0..SIZE_SCAN)
        .map(|i| lo * (hi / lo).powf(i as f64 / (SIZE_SCAN - 1) as f64))
        .collect();
    grid.push(d0);
    for d in grid {
        let (theta, cost) = p.all(d, best.as_ref().map(|b| b.1.as_slice()), true);
        scan.push((d, cost));
        if best.as_ref().is_none_or(|b| cost < b.2) {
            best = Some((d, theta, cost));
        }
    }
    scan.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (d_best, theta_best, _) = best.unwrap_or((d0, Vec::new(), f64::INFINITY));
    let warm = Mutex::new(theta_best);
    let profile = |x: &[f64]| {
        let w = warm.lock().map(|w| w.clone()).unwrap_or_default();
        let (theta, cost) = p.all(x[0], Some(&w), false);
        if let Ok(mut w) = warm.lock() {
            *w = theta;
        }
        cost
    };
    let identity = |_: &mut [f64]| {};
    let bounds = Bounds {
        lo: &[lo],
        hi: &[hi],
        project: &identity,
    };
    let m = nelder_mead(&profile, &[d_best], &bounds, 60, 1e-6);
    let d = m.x[0];
    let w = warm.into_inner().unwrap_or_default();
    let (theta, _) = p.all(d, Some(&w), true);
    (theta, d, scan)
}

/// Another minimum at wavelength `l` (from [`Problem::rival_starts`]) that
/// fits about as well as `x` — `χ²` within [`RIVAL_CHI2`] — but lies more than
/// [`RIVAL_SE`] standard errors `se` away: the local standard errors do
/// not cover it, so the constants are ambiguous there. Said as a flag.
fn rival(p: &Problem, l: usize, d: f64, x: &[f64], se: &[f64]) -> Option<String> {
    let cost = p.residuals(l, x, d).iter().map(|r| r * r).sum::<f64>();
    p.minima(l, d, &p.rival_starts())
        .into_iter()
        .filter(|(y, c)| {
            *c <= cost + RIVAL_CHI2
                && y.iter()
                    .zip(x)
                    .zip(se)
                    .any(|((a, b), s)| (a - b).abs() > RIVAL_SE * s)
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(y, c)| {
            let (n, k) = p.nk(&y);
            format!(
                "another solution fits about as well (n {n:.4}, k {k:.4e}, chi2 {:+.2})",
                c - cost
            )
        })
}

/// `N⁻¹` through its unit-diagonal scaling (a correlation-like matrix, so
/// the check of the inverse does not depend on the unknowns' units); None
/// when singular.
fn inverse_scaled(nm: &Matrix) -> Option<Matrix> {
    let n = nm.size();
    let s: Vec<f64> = (0..n).map(|i| nm[(i, i)]).collect();
    if s.iter().any(|v| !(*v > 0.0 && v.is_finite())) {
        return None;
    }
    let scaled = Matrix::from_fn(n, |a, b| nm[(a, b)] / (s[a] * s[b]).sqrt());
    let inv = inverse(&scaled)?;
    Some(Matrix::from_fn(n, |a, b| {
        inv[(a, b)] / (s[a] * s[b]).sqrt()
    }))
}

/// The per-wavelength results with their standard errors and flags, and
/// the diameter's (module docs).
fn uncertainty(
    p: &Problem,
    theta: &[Vec<f64>],
    d: f64,
    size: Option<[f64; 2]>,
) -> (Vec<WavelengthFit>, Option<f64>, String) {
    let (lo, hi) = p.bounds();
    let q = lo.len();
    let free = size.is_some();
    let (mut ylo, mut yhi) = (lo.clone(), hi.clone());
    if let Some([a, b]) = size {
        ylo.push(a);
        yhi.push(b);
    }
    // Per wavelength: the normal matrix in (θ, d), A⁻¹ and A⁻¹b.
    let blocks: Vec<(Matrix, Option<Matrix>, Vec<f64>)> = (0..theta.len())
        .into_par_iter()
        .map(|l| {
            let f = |y: &[f64]| p.residuals(l, &y[..q], if free { y[q] } else { d });
            let mut y = theta[l].clone();
            if free {
                y.push(d);
            }
            let identity = |_: &mut [f64]| {};
            let bounds = Bounds {
                lo: &ylo,
                hi: &yhi,
                project: &identity,
            };
            let j = jacobian(&f, &y, &bounds);
            let nm = normal_matrix(&j, &vec![1.0; j.len()]);
            let a = Matrix::from_fn(q, |r, c| nm[(r, c)]);
            let a_inv = inverse_scaled(&a);
            let a_inv_b = match (&a_inv, free) {
                (Some(ai), true) => (0..q)
                    .map(|r| (0..q).map(|c| ai[(r, c)] * nm[(c, q)]).sum())
                    .collect(),
                _ => vec![0.0; q],
            };
            (nm, a_inv, a_inv_b)
        })
        .collect();
    // The Schur complement of the diameter.
    let schur = free.then(|| {
        blocks
            .iter()
            .filter(|b| b.1.is_some())
            .map(|(nm, _, aib)| nm[(q, q)] - (0..q).map(|r| nm[(r, q)] * aib[r]).sum::<f64>())
            .sum::<f64>()
    });
    let d_var = schur.filter(|s| *s > 1e-12 * blocks.iter().map(|b| b.0[(q, q)]).sum::<f64>());
    let (diameter_se, diameter_flags) = match (size, d_var) {
        (None, _) => (None, String::new()),
        (Some(_), None) => (
            None,
            "not determined: the drawdowns do not change with it apart from the constants".into(),
        ),
        (Some([a, b]), Some(s)) => {
            let se = (1.0 / s).sqrt();
            let mut why = Vec::new();
            if se > MAX_RELATIVE_SE * d {
                why.push(format!("standard error {se:.3e} nm exceeds half its value"));
            }
            if d <= a || d >= b {
                why.push("at a bound of pigment.diameter_range_nm".into());
            }
            (Some(se), why.join("; "))
        }
    };
    let fits = theta
        .iter()
        .zip(blocks)
        .enumerate()
        .map(|(l, (x, (_, a_inv, aib)))| {
            let cov = a_inv.map(|ai| match d_var {
                Some(s) => Matrix::from_fn(q, |r, c| ai[(r, c)] + aib[r] * aib[c] / s),
                None => ai,
            });
            let (n, k) = p.nk(x);
            let residuals: Vec<f64> = p.residuals(l, x, d).iter().map(|r| r * p.noise).collect();
            let se: Option<Vec<f64>> = cov
                .as_ref()
                .map(|c| (0..q).map(|i| c[(i, i)].max(0.0).sqrt()).collect());
            let corr = match (&cov, &se) {
                (Some(c), Some(s)) if q == 2 => {
                    Some(c[(0, 1)] / (s[0] * s[1]).max(f64::MIN_POSITIVE))
                }
                _ => None,
            };
            let other = se.as_ref().and_then(|s| rival(p, l, d, x, s));
            let flags: Vec<String> = (0..q)
                .map(|i| {
                    let Some(s) = &se else {
                        return "not determined: JᵀJ is singular at this wavelength (the \
                                drawdowns fix only a combination of the constants, or none)"
                            .to_string();
                    };
                    let mut why = Vec::new();
                    if let Some(c) = corr.filter(|c| c.abs() > MAX_CORRELATION) {
                        let other = if i == 0 { "k" } else { "n" };
                        why.push(format!("not told apart from {other} (correlation {c:+.3})"));
                    }
                    if s[i] > MAX_RELATIVE_SE * x[i].abs() {
                        why.push(format!(
                            "standard error {:.3e} exceeds half its value",
                            s[i]
                        ));
                    }
                    if x[i] <= lo[i] || x[i] >= hi[i] {
                        why.push("at a bound".into());
                    }
                    if let Some(a) = &other {
                        why.push(a.clone());
                    }
                    why.join("; ")
                })
                .collect();
            let (n_se, k_se, n_flags, k_flags) = match (q, se) {
                (1, s) => (None, s.map(|s| s[0]), String::new(), flags[0].clone()),
                (_, s) => (
                    s.as_ref().map(|s| s[0]),
                    s.as_ref().map(|s| s[1]),
                    flags[0].clone(),
                    flags[1].clone(),
                ),
            };
            WavelengthFit {
                n,
                k,
                n_se,
                k_se,
                correlation_nk: corr,
                residuals,
                n_flags,
                k_flags,
            }
        })
        .collect();
    (fits, diameter_se, diameter_flags)
}
