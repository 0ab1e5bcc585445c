//! The matching problem: the fast model, the target as the model's colour
//! grid and observer see it, the palette's bounds, and what a subset of the
//! palette's unknowns (its pigments' volume fractions, and the thickness
//! when it is free) mean as a recipe, its colour and its residuals.

use crate::config::Measurement;
use crate::optics::colour::{self, Observer};

use super::config::{MatchSpec, Objective, TargetColour};
use super::forward::{FastModel, Recipe};
use super::solve::Bounds;
use super::MatchError;

/// What one recipe's colour is against the target.
#[derive(Debug, Clone)]
pub struct Fit {
    /// CIELAB per target geometry.
    pub lab: Vec<[f64; 3]>,
    /// CIEDE2000 to the target per target geometry.
    pub de00: Vec<f64>,
    /// Root-mean-square reflectance-factor difference on the grid (a
    /// spectrum target only).
    pub spectral_rms: Option<f64>,
}

impl Fit {
    /// The fit of a stacked CIELAB `lab` (3 per geometry) against the
    /// stacked target `target`, without a spectrum.
    pub fn of_lab(lab: &[f64], target: &[f64]) -> Fit {
        let lab: Vec<[f64; 3]> = lab.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
        let de00 = lab
            .iter()
            .zip(target.chunks(3))
            .map(|(l, t)| colour::delta_e2000(*l, [t[0], t[1], t[2]]))
            .collect();
        Fit {
            lab,
            de00,
            spectral_rms: None,
        }
    }
}

/// What the search ([`super::search`]) and the uncertainty
/// ([`super::uncertainty`]) ask of a matching problem, whatever its forward
/// model: the optional colourants its subsets are drawn from, the bounds of
/// a subset's unknowns, and the stacked CIELAB (3 per target geometry) of
/// a subset's unknowns `x`. [`Problem`] is a scene's layer on the
/// Kubelka–Munk model; `super::effect::EffectProblem` an effect paint on
/// the fast flake model.
pub trait Inverse: Sync {
    /// How many optional colourants the subsets are drawn from.
    fn colourants(&self) -> usize;
    /// Fewest colourants in a subset: 1, or 0 where some unknowns are in
    /// every recipe (an effect paint's flakes).
    fn fewest(&self) -> usize {
        1
    }
    /// Whether `subset`'s least volume fractions fit the total.
    fn feasible(&self, subset: &[usize]) -> bool;
    /// Lower and upper bounds of `subset`'s unknowns.
    fn bounds(&self, subset: &[usize]) -> (Vec<f64>, Vec<f64>);
    /// Carry `subset`'s unknowns `x` (inside the box, lower bounds `lo`)
    /// onto the feasible set.
    fn project(&self, subset: &[usize], lo: &[f64], x: &mut [f64]);
    fn objective(&self) -> Objective;
    /// Whether a `de00` fit is polished by Nelder–Mead on ΔE00 itself.
    fn polish(&self) -> bool {
        self.objective() == Objective::De00
    }
    /// The relative lowering of the cost below which a least-squares fit
    /// stops.
    fn relative_tolerance(&self) -> f64 {
        super::solve::DEFAULT_RELATIVE_TOLERANCE
    }
    /// 1σ noise of L*, a*, b*.
    fn noise_lab(&self) -> [f64; 3];
    /// The target's CIELAB, stacked.
    fn target_stack(&self) -> Vec<f64>;
    /// CIELAB of `subset`'s unknowns `x` in each target geometry, stacked.
    fn lab_at(&self, subset: &[usize], x: &[f64]) -> Vec<f64>;
    /// The residuals the least squares minimise: the CIELAB differences.
    fn residuals_at(&self, subset: &[usize], x: &[f64]) -> Vec<f64> {
        self.lab_at(subset, x)
            .iter()
            .zip(self.target_stack())
            .map(|(a, b)| a - b)
            .collect()
    }
    /// How `subset`'s unknowns `x` stand against the target.
    fn fit_at(&self, subset: &[usize], x: &[f64]) -> Fit {
        Fit::of_lab(&self.lab_at(subset, x), &self.target_stack())
    }
}

/// `f` of the box of `subset`'s unknowns and its projection, as the
/// solvers take them.
pub fn with_bounds<P: Inverse + ?Sized, R>(
    problem: &P,
    subset: &[usize],
    f: impl FnOnce(&Bounds) -> R,
) -> R {
    let (lo, hi) = problem.bounds(subset);
    let project = |y: &mut [f64]| problem.project(subset, &lo, y);
    f(&Bounds {
        lo: &lo,
        hi: &hi,
        project: &project,
    })
}

/// Carry the first `k` unknowns of `x` (volume fractions, lower bounds
/// `lo`) down towards their lower bounds, in proportion, until their total
/// is at most `max_total`.
pub fn project_total(max_total: f64, k: usize, lo: &[f64], x: &mut [f64]) {
    let total: f64 = x[..k].iter().sum();
    if total <= max_total {
        return;
    }
    let floor: f64 = lo[..k].iter().sum();
    let t = ((max_total - floor) / (total - floor)).clamp(0.0, 1.0);
    for (v, l) in x[..k].iter_mut().zip(lo) {
        *v = l + (*v - l) * t;
    }
}

/// Root-mean-square of per-geometry ΔE00 values.
pub fn rms(de00: &[f64]) -> f64 {
    (de00.iter().map(|d| d * d).sum::<f64>() / de00.len().max(1) as f64).sqrt()
}

impl Fit {
    /// Root-mean-square of the geometries' ΔE00.
    pub fn de00_rms(&self) -> f64 {
        rms(&self.de00)
    }

    /// The largest ΔE00 over the geometries.
    pub fn de00_max(&self) -> f64 {
        self.de00.iter().copied().fold(0.0, f64::max)
    }
}

/// The problem the search solves (module docs).
pub struct Problem {
    pub model: FastModel,
    /// The target's observer and illuminant.
    pub observer: Observer,
    /// The target's geometries and CIELAB (a spectrum's computed from it).
    pub target_lab: Vec<(Measurement, [f64; 3])>,
    /// A spectrum target on the model's grid.
    pub target_factor: Option<Vec<f64>>,
    pub objective: Objective,
    /// Volume-fraction bounds of each palette pigment.
    pub pvc_range: Vec<[f64; 2]>,
    pub max_total_pvc: f64,
    /// The base layer's thickness (nm) and paper albedo.
    pub thickness_nm: f64,
    pub paper_albedo: f64,
    pub thickness_range_nm: Option<[f64; 2]>,
    /// 1σ noise of L*, a*, b*.
    pub noise_lab: [f64; 3],
}

impl Problem {
    /// The problem of a checked match file on its fast model.
    pub fn new(spec: &MatchSpec, model: FastModel) -> Result<Problem, MatchError> {
        let t = &spec.target;
        let observer = Observer::standard(t.illuminant, t.observer);
        let (target_lab, target_factor) = match &t.colour {
            TargetColour::Lab(c) => (c.clone(), None),
            TargetColour::Spectrum { geometry, spectrum } => {
                let (lo, hi) = spectrum.range_nm();
                let grid = model.wavelengths_nm();
                let (g0, g1) = (grid[0], grid[grid.len() - 1]);
                if lo > g0 || hi < g1 {
                    return Err(MatchError::Config {
                        file: spec.path.clone(),
                        message: format!(
                            "key `target.csv`: the spectrum covers {lo}–{hi} nm, the colour grid \
                             {g0}–{g1} nm: it must cover the grid"
                        ),
                    });
                }
                let f: Vec<f64> = grid.iter().map(|&w| spectrum.at(w)).collect();
                let lab = model.lab_of(&observer, &f)?;
                (vec![(*geometry, lab)], Some(f))
            }
        };
        Ok(Problem {
            observer,
            target_lab,
            target_factor,
            objective: spec.search.objective,
            pvc_range: spec.palette.iter().map(|p| p.pvc_range).collect(),
            max_total_pvc: spec.search.max_total_pvc,
            thickness_nm: spec.scene.layer.thickness_nm,
            paper_albedo: model_albedo(spec),
            thickness_range_nm: spec.search.thickness_range_nm,
            noise_lab: t.noise_lab,
            model,
        })
    }

    /// The unknowns of `subset`: its pigments' volume fractions, then the
    /// thickness when it is free. Lower and upper bounds.
    pub fn bounds(&self, subset: &[usize]) -> (Vec<f64>, Vec<f64>) {
        let mut lo: Vec<f64> = subset.iter().map(|&s| self.pvc_range[s][0]).collect();
        let mut hi: Vec<f64> = subset.iter().map(|&s| self.pvc_range[s][1]).collect();
        if let Some([a, b]) = self.thickness_range_nm {
            lo.push(a);
            hi.push(b);
        }
        (lo, hi)
    }

    /// `f` of the box and the total volume fraction of `subset`'s unknowns,
    /// as the solvers take them.
    pub fn with_bounds<R>(&self, subset: &[usize], f: impl FnOnce(&Bounds) -> R) -> R {
        with_bounds(self, subset, f)
    }

    /// The recipe of `subset`'s unknowns `x`.
    pub fn recipe(&self, subset: &[usize], x: &[f64]) -> Recipe {
        let mut fractions = vec![0.0; self.pvc_range.len()];
        for (&s, &v) in subset.iter().zip(x) {
            fractions[s] = v;
        }
        Recipe {
            fractions,
            thickness_nm: x.get(subset.len()).copied().unwrap_or(self.thickness_nm),
            paper_albedo: self.paper_albedo,
        }
    }

    /// CIELAB of the recipe in each target geometry (stacked, 3 per
    /// geometry).
    pub fn lab_stack(&self, recipe: &Recipe) -> Vec<f64> {
        self.target_lab
            .iter()
            .flat_map(|(m, _)| {
                let f = self.model.factor(recipe, *m);
                // The grid and the factors are the model's own: always valid.
                self.model.lab_of(&self.observer, &f).unwrap_or([0.0; 3])
            })
            .collect()
    }

    /// The target's CIELAB, stacked as [`Problem::lab_stack`] stacks a
    /// recipe's.
    pub fn target_stack(&self) -> Vec<f64> {
        self.target_lab.iter().flat_map(|(_, l)| *l).collect()
    }

    /// CIEDE2000 to the target per geometry of a stacked CIELAB `lab`.
    pub fn de00_each(&self, lab: &[f64]) -> Vec<f64> {
        lab.chunks(3)
            .zip(&self.target_lab)
            .map(|(l, (_, t))| colour::delta_e2000([l[0], l[1], l[2]], *t))
            .collect()
    }

    /// The residuals the search minimises the squares of: CIELAB
    /// differences per geometry (`de00`, polished on ΔE00 itself), or the
    /// reflectance-factor differences on the grid over `√N` (`spectral-rms`).
    pub fn residuals(&self, recipe: &Recipe) -> Vec<f64> {
        match (&self.target_factor, self.objective) {
            (Some(t), super::config::Objective::SpectralRms) => {
                let f = self.model.factor(recipe, self.target_lab[0].0);
                let scale = 1.0 / (t.len() as f64).sqrt();
                f.iter().zip(t).map(|(a, b)| (a - b) * scale).collect()
            }
            _ => {
                let lab = self.lab_stack(recipe);
                lab.iter()
                    .zip(self.target_stack())
                    .map(|(a, b)| a - b)
                    .collect()
            }
        }
    }

    /// How the recipe's colour stands against the target.
    pub fn fit(&self, recipe: &Recipe) -> Fit {
        let stack = self.lab_stack(recipe);
        let de00 = self.de00_each(&stack);
        let lab: Vec<[f64; 3]> = stack.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
        let spectral_rms = self.target_factor.as_ref().map(|t| {
            let f = self.model.factor(recipe, self.target_lab[0].0);
            (f.iter().zip(t).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / t.len() as f64).sqrt()
        });
        Fit {
            lab,
            de00,
            spectral_rms,
        }
    }
}

impl Inverse for Problem {
    fn colourants(&self) -> usize {
        self.pvc_range.len()
    }

    fn feasible(&self, subset: &[usize]) -> bool {
        subset.iter().map(|&s| self.pvc_range[s][0]).sum::<f64>() <= self.max_total_pvc
    }

    fn bounds(&self, subset: &[usize]) -> (Vec<f64>, Vec<f64>) {
        Problem::bounds(self, subset)
    }

    fn project(&self, subset: &[usize], lo: &[f64], x: &mut [f64]) {
        project_total(self.max_total_pvc, subset.len(), lo, x);
    }

    fn objective(&self) -> Objective {
        self.objective
    }

    fn noise_lab(&self) -> [f64; 3] {
        self.noise_lab
    }

    fn target_stack(&self) -> Vec<f64> {
        Problem::target_stack(self)
    }

    fn lab_at(&self, subset: &[usize], x: &[f64]) -> Vec<f64> {
        self.lab_stack(&self.recipe(subset, x))
    }

    fn residuals_at(&self, subset: &[usize], x: &[f64]) -> Vec<f64> {
        self.residuals(&self.recipe(subset, x))
    }

    fn fit_at(&self, subset: &[usize], x: &[f64]) -> Fit {
        self.fit(&self.recipe(subset, x))
    }
}

/// The base scene's paper albedo (the checker made sure it has one).
fn model_albedo(spec: &MatchSpec) -> f64 {
    spec.scene
        .substrate
        .ground()
        .and_then(|g| g.constant())
        .unwrap_or(0.0)
}
