//! The spectral proxy of a stack solved layer by layer: every layer its
//! homogeneous slab (the volume-averaged ε, in closed form inside the
//! binder), stacked and printed the same way, on the fine colour grid. It
//! carries the pigments' absorption bands between the solved wavelengths
//! (`optics::appearance::SpectralProxy` for one layer).

use ndarray::{Array2, Array3};
use num_complex::Complex64 as C64;

use crate::config::{Scene, Substrate};
use crate::optics::baseline::adding::Slab;
use crate::optics::baseline::matrix::Matrix;
use crate::optics::baseline::ordinates::Ordinates;
use crate::optics::stack::{self, Below, LayerSlab, Views};
use crate::solver::airy;

use super::appearance::fine_grid;
use super::eps::mean_eps;
use super::plan::node_deg;
use super::PipelineError;

/// Each layer's coverage and Yule–Nielsen's n of the stack of `scene`.
pub(super) fn halftone_of(scene: &Scene) -> (Vec<f64>, f64) {
    let st = scene.stack.as_ref().expect("a stack");
    (
        st.layers.iter().map(|l| l.coverage).collect(),
        st.yule_nielsen_n,
    )
}

/// The spectral proxy of a stack on the fine colour grid: each
/// measurement's reflectance factor, and the tile's BRDF square (1/sr) and
/// sky strip.
pub(super) struct StackProxy {
    pub fine: Vec<f64>,
    /// Per measurement, per fine wavelength.
    pub factors: Vec<Vec<f64>>,
    /// (fine wavelength, illumination, viewing).
    pub brdf: Array3<f64>,
    /// (fine wavelength, viewing).
    pub sky: Array2<f64>,
}

/// The spectral proxy of the stack: every layer its homogeneous slab (the
/// volume-averaged ε, in closed form inside the binder), stacked the same
/// way, on the fine colour grid. None for one wavelength, without paper,
/// or where a material has no data on the grid.
pub(super) fn proxy_factors(
    scene: &Scene,
    scenes: &[Scene],
    ords: &Ordinates,
    below: Below,
    illumination: &[f64],
) -> Result<Option<StackProxy>, PipelineError> {
    let wl = &scene.wavelengths_nm;
    if wl.len() < 2 || matches!(scene.substrate, Substrate::None) {
        return Ok(None);
    }
    let fine = fine_grid(wl);
    let nb = scene.layer.binder_index;
    let nodes = node_deg(ords);
    let measurements = &scene.appearance.measurements;
    let viewing = &scene.appearance.viewing_deg;
    let mut factors = vec![Vec::with_capacity(fine.len()); measurements.len()];
    let mut brdf = Array3::zeros((fine.len(), illumination.len(), viewing.len()));
    let mut sky = Array2::zeros((fine.len(), viewing.len()));
    for (f, &w) in fine.iter().enumerate() {
        let mut slabs = Vec::with_capacity(scenes.len());
        for ls in scenes {
            let Ok(eps) = mean_eps(ls, w) else {
                return Ok(None);
            };
            let eps_rel: C64 = eps / (nb * nb);
            let (mut r, mut t) = (vec![0.0; nodes.len()], vec![0.0; nodes.len()]);
            for (j, &deg) in nodes.iter().enumerate() {
                let s = airy::slab(eps_rel, ls.layer.thickness_nm, w / nb, deg);
                r[j] = s.r.norm_sqr();
                t[j] = s.t.norm_sqr();
            }
            let slab = Slab::symmetric(Matrix::diagonal(&r), Matrix::diagonal(&t));
            slabs.push(LayerSlab {
                specular: slab.clone(),
                total: slab,
                // Homogeneous slabs scatter nothing: the mean is all there is.
                azimuthal: Vec::new(),
            });
        }
        let views = Views {
            measurements,
            viewing_deg: viewing,
            illumination_deg: Some(illumination),
            above_deg: &[],
        };
        let (coverage, yn) = halftone_of(scene);
        let look = stack::halftone(ords, &slabs, &coverage, yn, below, &views)?;
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
