//! Pilot solves: the operator applications of a high-contrast layer,
//! measured before a study runs instead of assumed.
//!
//! The time model's assumed rates ([`super::plan::default_applications`])
//! were measured on the stand-in pigments, whose real index (1.4) is close
//! to the binder's. A white pigment is another kind of layer: rutile
//! (n ≈ 2.5–2.9, lossless) in binder needs 50–100× the stand-ins'
//! applications per solve (multiple scattering between strong, lossless
//! grains), and no rate measured on the stand-ins predicts it. So a layer
//! whose grains' real index differs from the binder's by more than
//! [`HIGH_CONTRAST`] (relative) is grouped by its pigments' permittivities,
//! equation and background, and each group is measured: one solve of its
//! median variant (by PVC × largest grain) at the middle wavelength, at
//! normal incidence from above, one realisation, nothing else. Its
//! applications against the assumed rate are the group's factor, averaged
//! with the group's finished results (the pilot counted as
//! [`super::plan::PRIOR_RESULTS`] results), as the stand-ins' assumed rate
//! is with theirs. A pilot costs one solve of one variant (seconds to a
//! minute); pilots of one process are kept and reused.

use std::collections::BTreeMap;
use std::sync::Mutex;

use super::sweep::Variant;
use crate::config::Scene;
use crate::output::progress::Progress;
use crate::pipeline::{self, species_eps, RunPlan};

/// Relative real-index contrast `|Re n_p / n_b − 1|` above which a layer's
/// applications are measured by a pilot: the stand-ins (n' = 1.4 in a
/// binder of 1.558) sit at 0.10; CaCO3 (1.6) at 0.04; ZnO (2.0) at 0.28;
/// anatase and rutile (2.5–2.9) at 0.6–0.9.
pub const HIGH_CONTRAST: f64 = 0.25;

/// A pilot solve's measurement.
#[derive(Debug, Clone)]
pub struct Pilot {
    /// The variant solved.
    pub variant: String,
    /// Wavelength solved (nm).
    pub wavelength_nm: f64,
    /// Operator applications per wave solve, measured.
    pub applications: f64,
    /// CPU seconds of the pilot (geometry, raster and the solve).
    pub cpu_s: f64,
}

/// The largest `|Re n_p / n_b − 1|` of the scene's pigments over its
/// wavelengths (0 without pigments).
pub fn contrast(scene: &Scene) -> f64 {
    let nb = scene.layer.binder_index;
    scene
        .wavelengths_nm
        .iter()
        .filter_map(|&l| species_eps(scene, l).ok())
        .flatten()
        .map(|e| (e.sqrt().re / nb - 1.0).abs())
        .fold(0.0, f64::max)
}

/// The pilot group of a scene: `Some(key)` for a single layer of generated
/// grains solved iteratively whose contrast exceeds [`HIGH_CONTRAST`]; the
/// key names its pigments' permittivities at the middle wavelength, its
/// equation and its background.
pub fn group(scene: &Scene) -> Option<String> {
    if scene.structure.is_some()
        || scene.stack.is_some()
        || scene.species.is_empty()
        || contrast(scene) <= HIGH_CONTRAST
        || RunPlan::of(scene).analytic
    {
        return None;
    }
    let wl = middle_wavelength(scene);
    let eps = species_eps(scene, wl).ok()?;
    let eps: Vec<String> = eps
        .iter()
        .map(|e| format!("{:.3}{:+.3}i", e.re, e.im))
        .collect();
    Some(format!(
        "ε {} at {wl} nm, {}, {} background",
        eps.join(", "),
        scene.solver.equation.name(),
        scene.solver.background.name()
    ))
}

fn middle_wavelength(scene: &Scene) -> f64 {
    scene.wavelengths_nm[scene.wavelengths_nm.len() / 2]
}

/// The member a group's pilot solves: the median by PVC × largest grain.
pub fn representative<'a>(members: &[&'a Variant]) -> &'a Variant {
    let mut m = members.to_vec();
    let size = |v: &Variant| v.scene.total_pvc() * pipeline::largest_grain_nm(&v.scene);
    m.sort_by(|a, b| size(a).total_cmp(&size(b)).then(a.name.cmp(&b.name)));
    m[m.len() / 2]
}

/// The pilot of `v`'s group, measured now or earlier in this process.
pub fn measure(key: &str, v: &Variant) -> Result<Pilot, String> {
    static DONE: Mutex<BTreeMap<String, Pilot>> = Mutex::new(BTreeMap::new());
    if let Some(p) = DONE.lock().ok().and_then(|d| d.get(key).cloned()) {
        return Ok(p);
    }
    let p = solve_one(v)?;
    if let Ok(mut d) = DONE.lock() {
        d.insert(key.to_string(), p.clone());
    }
    Ok(p)
}

/// The pilot's scene: the variant at its middle wavelength, at normal
/// incidence from above, one realisation, no appearance products (so no
/// measurement angles and no solves from below).
fn pilot_scene(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    s.wavelengths_nm = vec![middle_wavelength(scene)];
    let azimuth = scene.incidence.first().map_or(0.0, |i| i.azimuth_deg);
    s.incidence = vec![crate::config::Incidence {
        polar_deg: 0.0,
        azimuth_deg: azimuth,
    }];
    s.realisations = 1;
    s.realisation_target = None;
    let p = &mut s.appearance.products;
    (p.brdf, p.btdf, p.tile, p.merl, p.preview) = (false, false, false, false, false);
    s.appearance.baseline.clear();
    s
}

fn solve_one(v: &Variant) -> Result<Pilot, String> {
    let scene = pilot_scene(&v.scene);
    let plan = RunPlan::of(&scene);
    let t0 = super::cpu::process_cpu_s();
    let layer = pipeline::layer::solve(&scene, &plan, &Progress::hidden(1, "pilot"))
        .map_err(|e| e.to_string())?;
    let cpu_s = super::cpu::process_cpu_s() - t0;
    let waves = scene.solver.solves_per_incidence() as f64;
    let entries = &layer.entries;
    if entries.is_empty() {
        return Err("the pilot solved nothing".into());
    }
    // The recorded applications, an `auto` solve's fallbacks included.
    let measured: f64 = entries
        .iter()
        .map(|e| e.record.operator_applications as f64)
        .sum();
    Ok(Pilot {
        variant: v.name.clone(),
        wavelength_nm: scene.wavelengths_nm[0],
        applications: measured / (entries.len() as f64 * waves),
        cpu_s,
    })
}
