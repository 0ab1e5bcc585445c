//! The spectral proxy of a stack solved layer by layer: every layer its
//! homogeneous slab (the volume-averaged ε, in closed form inside the
//! binder), stacked and printed the same way, on the fine colour grid. It
//! carries the pigments' absorption bands between the solved wavelengths
//! (`optics::appearance::SpectralProxy` for one layer). Beside Maxwell the
//! slabs and surfaces are natural light's (the mean of s and p powers).

use ndarray::{Array2, Array3};
use num_complex::Complex64 as C64;

use crate::config::Scene;
use crate::optics::baseline::adding::Slab;
use crate::optics::baseline::fresnel::Fresnel;
use crate::optics::baseline::matrix::Matrix;
use crate::optics::baseline::ordinates::Ordinates;
use crate::optics::stack::{self, Below, LayerSlab, Views};
use crate::solver::airy;

use super::appearance::fine_grid;
use super::eps::mean_eps;
use super::plan::node_deg;
use super::PipelineError;

/// The spectral proxy of a stack on the fine colour grid: each
/// measurement's reflectance factor, and the tile's BRDF square (1/sr) and
/// sky strip.
pub(super) struct StackProxy {
    pub fine: Vec<f64>,
    /// Per measurement, per fine wavelength.
    pub factors: Vec<Vec<f64>>,
    /// (fine wavelength, illumination, viewing); no illumination angle
    /// when the tile is not asked for.
    pub brdf: Array3<f64>,
    /// (fine wavelength, viewing).
    pub sky: Array2<f64>,
}

/// The spectral proxy of the stack: every layer its homogeneous slab (the
/// volume-averaged ε, in closed form inside the binder), stacked the same
/// way and printed at the same `halftone` (coverages, Yule–Nielsen's n),
/// on the fine colour grid, seen from `views` (the BRDF square only where
/// they ask for it). None for one wavelength, without paper, or where a
/// material has no data on the grid.
pub(super) fn proxy_factors(
    scene: &Scene,
    scenes: &[Scene],
    ords: &Ordinates,
    below: Below,
    views: &Views,
    halftone: (&[f64], f64),
) -> Result<Option<StackProxy>, PipelineError> {
    let wl = &scene.wavelengths_nm;
    if wl.len() < 2 || scene.substrate.ground().is_none() {
        return Ok(None);
    }
    let fine = fine_grid(wl);
    let nb = scene.layer.binder_index;
    let nodes = node_deg(ords);
    // The totals in air are not part of a colour.
    let views = Views {
        above_deg: &[],
        ..*views
    };
    let (coverage, yn) = halftone;
    let ni = views.illumination_deg.map_or(0, |i| i.len());
    let nv = views.viewing_deg.len();
    let mut factors = vec![Vec::with_capacity(fine.len()); views.measurements.len()];
    let mut brdf = Array3::zeros((fine.len(), ni, nv));
    let mut sky = Array2::zeros((fine.len(), nv));
    for (f, &w) in fine.iter().enumerate() {
        let mut slabs = Vec::with_capacity(scenes.len());
        for ls in scenes {
            let Ok(eps) = mean_eps(ls, w) else {
                return Ok(None);
            };
            let eps_rel: C64 = eps / (nb * nb);
            let (mut r, mut t) = (vec![0.0; nodes.len()], vec![0.0; nodes.len()]);
            for (j, &deg) in nodes.iter().enumerate() {
                // Natural light's powers beside Maxwell: the mean of s and p.
                let k0 = 2.0 * std::f64::consts::PI * nb / w;
                let kx = k0 * deg.to_radians().sin();
                let powers = |p: bool| {
                    let s = airy::SlabField::polarised(eps_rel, ls.layer.thickness_nm, k0, kx, p);
                    [s.response.r.norm_sqr(), s.response.t.norm_sqr()]
                };
                [r[j], t[j]] = match views.surfaces {
                    Fresnel::Scalar => powers(false),
                    Fresnel::Unpolarised => {
                        let ([rs, ts], [rp, tp]) = (powers(false), powers(true));
                        [(rs + rp) / 2.0, (ts + tp) / 2.0]
                    }
                };
            }
            let slab = Slab::symmetric(Matrix::diagonal(&r), Matrix::diagonal(&t));
            slabs.push(LayerSlab {
                specular: slab.clone(),
                total: slab,
                // Homogeneous slabs scatter nothing: the mean is all there is.
                azimuthal: Vec::new(),
            });
        }
        let look = stack::halftone(ords, &slabs, coverage, yn, below, &views)?;
        for (g, x) in look.factors.into_iter().enumerate() {
            factors[g].push(x);
        }
        for (v, x) in look.natural.into_iter().enumerate() {
            sky[[f, v]] = x;
        }
        if let Some(plane) = look.plane {
            brdf.index_axis_mut(ndarray::Axis(0), f)
                .assign(&(plane / std::f64::consts::PI));
        }
    }
    Ok(Some(StackProxy {
        fine,
        factors,
        brdf,
        sky,
    }))
}
