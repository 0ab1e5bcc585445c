//! What the appearance stage is given for a scene under its plan: the
//! angles, the table, the substrate, the products, and the spectral proxy
//! (the molecular-mixture slab on a fine wavelength grid) for colour.

use crate::config::{Scene, Substrate};
use crate::optics::appearance::{AppearanceSpec, SpectralProxy};
use crate::optics::substrate::Hemisphere;

use super::eps::mean_eps;
use super::plan::RunPlan;

/// The appearance assembly parameters of a scene under its plan.
pub fn appearance_spec(scene: &Scene, plan: &RunPlan) -> AppearanceSpec {
    AppearanceSpec {
        wavelengths_nm: scene.wavelengths_nm.clone(),
        azimuth_deg: scene.incidence.first().map_or(0.0, |i| i.azimuth_deg),
        illumination_deg: scene.incidence.iter().map(|i| i.polar_deg).collect(),
        viewing_deg: scene.appearance.viewing_deg.clone(),
        above_deg: plan.above_deg.clone(),
        below: plan.below.clone(),
        ground: scene.substrate.ground(),
        chart: scene.substrate.is_chart(),
        thickness_nm: scene.layer.thickness_nm,
        table: plan.table,
        realisations: plan.realisations,
        deterministic: plan.analytic || scene.structure.is_some(),
        btdf: scene.appearance.products.btdf,
        // The preview's colour is matched to the tile's (output::render::preview).
        tile: scene.appearance.products.tile || scene.appearance.products.preview,
        proxy: spectral_proxy(scene),
        measurements: if scene.appearance.products.tile {
            scene.appearance.measurements.clone()
        } else {
            Vec::new()
        },
    }
}

/// Fine grid of the colour proxy, nm.
pub const PROXY_STEP_NM: f64 = 5.0;

/// The molecular-mixture slab on a 5 nm grid (plus every solved wavelength)
/// over the scene's band, for colour with a substrate; None for a single
/// wavelength or when a material lacks data on the grid.
fn spectral_proxy(scene: &Scene) -> Option<SpectralProxy> {
    let wl = &scene.wavelengths_nm;
    // An explicit structure has no pigment mixture to stand in for it.
    if wl.len() < 2 || scene.substrate == Substrate::None || scene.structure.is_some() {
        return None;
    }
    let fine = fine_grid(wl);
    let eps = fine
        .iter()
        .map(|&l| mean_eps(scene, l).ok())
        .collect::<Option<Vec<_>>>()?;
    Some(SpectralProxy {
        wavelengths_nm: fine,
        eps,
        thickness_nm: scene.layer.thickness_nm,
        quadrature: Hemisphere::new(scene.appearance.quadrature_points),
    })
}

/// The colour grid: every `PROXY_STEP_NM` over the band of `wl`, plus every
/// wavelength of `wl`, increasing.
pub fn fine_grid(wl: &[f64]) -> Vec<f64> {
    let mut fine: Vec<f64> = wl.to_vec();
    if wl.is_empty() {
        return fine;
    }
    let (lo, hi) = (wl[0], wl[wl.len() - 1]);
    let mut x = (lo / PROXY_STEP_NM).ceil() * PROXY_STEP_NM;
    while x < hi {
        if !fine.contains(&x) {
            fine.push(x);
        }
        x += PROXY_STEP_NM;
    }
    fine.sort_by(f64::total_cmp);
    fine
}
