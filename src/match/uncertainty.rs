//! A recipe's uncertainty from the target's measurement noise: the target's
//! L*, a*, b* in each geometry carry independent noise of standard
//! deviation σ (`target.noise_lab`), and the recipe's unknowns move with
//! them. To first order the fitted unknowns `x` satisfy
//! `J δx ≈ δLab` with `J = ∂Lab/∂x` at the recipe (the fast model's
//! Jacobian, central differences), so their covariance is the Gauss–Markov
//! `C = (Jᵀ W J)⁻¹`, `W = diag(1/σ²)` — the standard error of each unknown
//! is `√C_jj`, and the correlation `C_ij/√(C_ii C_jj)`.
//!
//! Ingredients the target cannot tell apart are flagged: two unknowns whose
//! correlation exceeds [`MAX_CORRELATION`] in magnitude (the target fixes
//! only a combination of them), one whose standard error exceeds
//! [`MAX_RELATIVE_SE`] of its value, and every unknown when `JᵀWJ` is
//! singular (more unknowns than the target has numbers, or a pigment that
//! does not change the colour). The condition number is that of the
//! correlation matrix (1-norm), free of the unknowns' units. The first-order
//! propagation ignores the bounds: an unknown at a bound is reported as
//! such.
//!
//! **ΔE00's standard error.** The same noise makes the ΔE00 between a
//! recipe's colour and the measured target uncertain. Its standard error
//! per geometry ([`de00_se`]) is the standard deviation of ΔE00 from the
//! recipe's colour to the target drawn with that noise ([`DE00_DRAWS`]
//! normal draws of a fixed seed): for a recipe far from the target about
//! the noise projected on the difference, for one at the target about the
//! noise's own size in ΔE00.

use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::geometry::normal::standard_normal;
use crate::optics::colour::delta_e2000;

use super::problem::Inverse;
use super::solve::{inverse, jacobian, normal_matrix, Bounds};

/// Correlation beyond which two unknowns are not told apart.
pub const MAX_CORRELATION: f64 = 0.95;
/// Relative standard error beyond which an unknown is not pinned down.
pub const MAX_RELATIVE_SE: f64 = 0.5;

/// Draws of the target's noise behind each ΔE00's standard error.
pub const DE00_DRAWS: usize = 512;

/// The standard error of ΔE00 from `lab` to a target `target` measured
/// with noise `sigma` (module docs).
pub fn de00_se(lab: [f64; 3], target: [f64; 3], sigma: [f64; 3]) -> f64 {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x0de0_0e5e);
    let d: Vec<f64> = (0..DE00_DRAWS)
        .map(|_| {
            let t = [0, 1, 2].map(|c| target[c] + sigma[c] * standard_normal(&mut rng));
            delta_e2000(lab, t)
        })
        .collect();
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (d.len() - 1) as f64).sqrt()
}

/// The uncertainty of one recipe's unknowns.
#[derive(Debug, Clone)]
pub struct Uncertainty {
    /// Standard error of each unknown (volume fractions, then the
    /// thickness when free, nm); None when `JᵀWJ` is singular.
    pub se: Option<Vec<f64>>,
    /// Correlation matrix of the unknowns (row-major), when not singular.
    pub correlation: Option<Vec<Vec<f64>>>,
    /// Condition number of the correlation matrix, when not singular.
    pub condition: Option<f64>,
    /// Per unknown: why it is not determined (empty when it is).
    pub flags: Vec<String>,
}

impl Uncertainty {
    /// `name: why` for every unknown (named by `unknowns`, in order) the
    /// target does not determine.
    pub fn not_determined(&self, unknowns: &[String]) -> Vec<String> {
        unknowns
            .iter()
            .zip(&self.flags)
            .filter(|(_, f)| !f.is_empty())
            .map(|(n, f)| format!("{n}: {f}"))
            .collect()
    }
}

/// The uncertainty of `subset`'s unknowns `x`; `names` names them.
pub fn uncertainty<P: Inverse + ?Sized>(
    problem: &P,
    subset: &[usize],
    x: &[f64],
    names: &[String],
) -> Uncertainty {
    let (lo, hi) = problem.bounds(subset);
    let identity = |_: &mut [f64]| {};
    let bounds = Bounds {
        lo: &lo,
        hi: &hi,
        project: &identity,
    };
    let lab = |y: &[f64]| problem.lab_at(subset, y);
    let j = jacobian(&lab, x, &bounds);
    let w: Vec<f64> = (0..j.len())
        .map(|i| 1.0 / problem.noise_lab()[i % 3].powi(2))
        .collect();
    let n = x.len();
    let mut flags = vec![String::new(); n];
    let at_bound = |k: usize| x[k] <= lo[k] || x[k] >= hi[k];
    let Some(cov) = inverse(&normal_matrix(&j, &w)) else {
        let why = if n > j.len() {
            format!("undetermined: {n} unknowns from {} target numbers", j.len())
        } else {
            "undetermined: the colour does not fix the unknowns apart".to_string()
        };
        return Uncertainty {
            se: None,
            correlation: None,
            condition: None,
            flags: vec![why; n],
        };
    };
    let se: Vec<f64> = (0..n).map(|k| cov[(k, k)].max(0.0).sqrt()).collect();
    let corr: Vec<Vec<f64>> = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| cov[(a, b)] / (se[a] * se[b]).max(f64::MIN_POSITIVE))
                .collect()
        })
        .collect();
    for a in 0..n {
        let mut why: Vec<String> = Vec::new();
        for b in 0..n {
            if a != b && corr[a][b].abs() > MAX_CORRELATION {
                why.push(format!(
                    "not told apart from {} (correlation {:+.3})",
                    names[b], corr[a][b]
                ));
            }
        }
        if se[a] > MAX_RELATIVE_SE * x[a].abs() {
            why.push(format!(
                "standard error {:.3e} exceeds half its value",
                se[a]
            ));
        }
        if at_bound(a) {
            why.push("at a bound (the propagation ignores bounds)".into());
        }
        flags[a] = why.join("; ");
    }
    let cm = crate::optics::baseline::matrix::Matrix::from_fn(n, |a, b| corr[a][b]);
    let condition = inverse(&cm).map(|ci| one_norm(&cm, n) * one_norm(&ci, n));
    Uncertainty {
        se: Some(se),
        correlation: Some(corr),
        condition,
        flags,
    }
}

fn one_norm(m: &crate::optics::baseline::matrix::Matrix, n: usize) -> f64 {
    (0..n)
        .map(|c| (0..n).map(|r| m[(r, c)].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without noise ΔE00 is exact; for a lightness difference alone, noise
    /// in L* moves ΔE00 = ΔL*/S_L by σ/S_L (CIEDE2000's S_L at the mean
    /// L* of 55: 1 + 0.015·25/√45), and noise across the difference hardly
    /// at all.
    #[test]
    fn de00_standard_error_follows_the_noise_along_the_difference() {
        let (lab, target) = ([60.0, 0.0, 0.0], [50.0, 0.0, 0.0]);
        assert!(de00_se(lab, target, [0.0; 3]) < 1e-12);
        let s_l = 1.0 + 0.015 * 25.0 / 45f64.sqrt();
        let along = de00_se(lab, target, [0.5, 0.0, 0.0]);
        assert!((along / (0.5 / s_l) - 1.0).abs() < 0.1, "{along}");
        let across = de00_se(lab, target, [0.0, 0.5, 0.5]);
        assert!(across < 0.1 * along, "{across} {along}");
    }
}
