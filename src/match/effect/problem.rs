//! The effect paint's matching problem: the multi-angle target, the
//! unknowns' bounds and what a subset of the optional pigments with the
//! flakes' unknowns mean as settings of the base paint
//! ([`super::forward::Setting`]). The unknowns `x` of a subset are its
//! pigments' volume fractions (subset order), then per varied flake layer
//! its concentration and, where free, its coating thickness (nm). It is an
//! [`Inverse`]: the search, the uncertainty and the ranking are the scene
//! match's own.

use crate::optics::colour::Observer;
use crate::optics::flakes::multiangle::{self, AngleColour, Geometry};

use super::super::config::Objective;
use super::super::problem::{project_total, Inverse};
use super::super::MatchError;
use super::config::EffectSpec;
use super::forward::{EffectModel, Setting};

/// The relative lowering of the cost below which the least squares stop.
pub const RELATIVE_TOLERANCE: f64 = 1e-6;

/// The problem the search solves (module docs).
pub struct EffectProblem {
    pub model: EffectModel,
    pub observer: Observer,
    /// The target's geometries and CIELAB.
    pub target: Vec<(Geometry, [f64; 3])>,
    /// Index of each target geometry among [`multiangle::geometries`].
    positions: Vec<usize>,
    pub spec: EffectSpec,
}

impl EffectProblem {
    /// The problem of a checked effect match file; the model is solved
    /// once, in the middle of the bounds, so that a paint the model cannot
    /// compute is refused here rather than in the search.
    pub fn new(spec: &EffectSpec) -> Result<EffectProblem, MatchError> {
        let t = &spec.target;
        let all = multiangle::geometries();
        let positions = t
            .colour
            .iter()
            .map(|(g, _)| all.iter().position(|h| h == g).unwrap_or(0))
            .collect();
        let p = EffectProblem {
            model: EffectModel::new(&spec.paint),
            observer: Observer::standard(t.illuminant, t.observer),
            target: t.colour.clone(),
            positions,
            spec: spec.clone(),
        };
        let (lo, hi) = p.bounds(&[]);
        let mid: Vec<f64> = lo.iter().zip(&hi).map(|(a, b)| 0.5 * (a + b)).collect();
        p.colours(&[], &mid)?;
        Ok(p)
    }

    /// Names of `subset`'s unknowns, as [`EffectProblem::settings`] orders
    /// them.
    pub fn unknowns(&self, subset: &[usize]) -> Vec<String> {
        let mut out: Vec<String> = subset
            .iter()
            .map(|&s| {
                let p = &self.spec.pigments[s];
                format!("{}.{} pvc", p.layer, p.pigment)
            })
            .collect();
        for f in &self.spec.flakes {
            out.push(format!("{}.flakes concentration", f.layer));
            if f.coating_nm_range.is_some() {
                out.push(format!("{}.flakes coating_nm", f.layer));
            }
        }
        out
    }

    /// The settings of the base paint of `subset`'s unknowns `x`: every
    /// optional pigment (0 where not in `subset`), then the flakes'.
    pub fn settings(&self, subset: &[usize], x: &[f64]) -> Vec<Setting> {
        let mut out: Vec<Setting> = self
            .spec
            .pigments
            .iter()
            .enumerate()
            .map(|(s, p)| Setting::Pigment {
                layer: p.layer_index,
                pigment: p.pigment_index,
                fraction: subset.iter().position(|&q| q == s).map_or(0.0, |k| x[k]),
            })
            .collect();
        let mut k = subset.len();
        for f in &self.spec.flakes {
            out.push(Setting::Concentration {
                layer: f.layer_index,
                fraction: x[k],
            });
            k += 1;
            if f.coating_nm_range.is_some() {
                out.push(Setting::Coating {
                    layer: f.layer_index,
                    nm: x[k],
                });
                k += 1;
            }
        }
        out
    }

    /// The multi-angle colours (every geometry) of `subset`'s unknowns `x`.
    pub fn colours(&self, subset: &[usize], x: &[f64]) -> Result<Vec<AngleColour>, MatchError> {
        self.model
            .colours(&self.observer, &self.settings(subset, x))
    }

    /// The target's flop index, when it has 45° illumination at 15°, 45°
    /// and 110° aspecular.
    pub fn target_flop_index(&self) -> Option<f64> {
        let l = |a: f64| {
            self.target
                .iter()
                .find(|(g, _)| g.illumination_deg == 45.0 && g.aspecular_deg == a)
                .map(|(_, lab)| lab[0])
        };
        multiangle::flop_index(l(15.0)?, l(45.0)?, l(110.0)?)
    }
}

impl Inverse for EffectProblem {
    fn colourants(&self) -> usize {
        self.spec.pigments.len()
    }

    /// The flakes are in every recipe: a recipe of no optional pigment is
    /// tried first (when there are flakes to vary).
    fn fewest(&self) -> usize {
        usize::from(self.spec.flakes.is_empty())
    }

    fn feasible(&self, subset: &[usize]) -> bool {
        subset
            .iter()
            .map(|&s| self.spec.pigments[s].pvc_range[0])
            .sum::<f64>()
            <= self.spec.search.max_total_pvc
    }

    fn bounds(&self, subset: &[usize]) -> (Vec<f64>, Vec<f64>) {
        let mut lo: Vec<f64> = subset
            .iter()
            .map(|&s| self.spec.pigments[s].pvc_range[0])
            .collect();
        let mut hi: Vec<f64> = subset
            .iter()
            .map(|&s| self.spec.pigments[s].pvc_range[1])
            .collect();
        for f in &self.spec.flakes {
            lo.push(f.concentration_range[0]);
            hi.push(f.concentration_range[1]);
            if let Some([a, b]) = f.coating_nm_range {
                lo.push(a);
                hi.push(b);
            }
        }
        (lo, hi)
    }

    fn project(&self, subset: &[usize], lo: &[f64], x: &mut [f64]) {
        project_total(self.spec.search.max_total_pvc, subset.len(), lo, x);
    }

    fn objective(&self) -> Objective {
        Objective::De00
    }

    /// No Nelder–Mead polish: each evaluation is a solve of the whole
    /// paint, and the least squares on the CIELAB differences already
    /// leave ΔE00 at the target's noise.
    fn polish(&self) -> bool {
        false
    }

    /// Each evaluation is a solve of the whole paint: the least squares
    /// stop once a step lowers the cost by less than a millionth of it
    /// (the unknowns then move far less than their standard errors).
    fn relative_tolerance(&self) -> f64 {
        RELATIVE_TOLERANCE
    }

    fn noise_lab(&self) -> [f64; 3] {
        self.spec.target.noise_lab
    }

    fn target_stack(&self) -> Vec<f64> {
        self.target.iter().flat_map(|(_, l)| *l).collect()
    }

    /// The target geometries' CIELAB; NaN where the model fails (the
    /// solvers reject such a step; [`EffectProblem::new`] has solved the
    /// paint once already).
    fn lab_at(&self, subset: &[usize], x: &[f64]) -> Vec<f64> {
        match self.colours(subset, x) {
            Ok(c) => self.positions.iter().flat_map(|&p| c[p].lab).collect(),
            Err(_) => vec![f64::NAN; 3 * self.positions.len()],
        }
    }
}
