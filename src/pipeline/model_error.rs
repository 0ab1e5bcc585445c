//! The scalar approximation's model error: how far a Helmholtz colour is
//! from the Maxwell colour of the same layer, as measured (docs/ACCURACY.md,
//! "The scalar approximation").
//!
//! - Dissolved inks (homogeneous layers, closed form in both equations):
//!   `scripts/model_error_surfaces.py`, exact.
//! - Grains: `scripts/model_error_grains.py`, the same fragments (same
//!   seeds) in both equations, 1 µm layers on paper of albedo 0.9.
//!
//! The term a Helmholtz scene's expected error carries is the largest
//! ΔE00 over the measured stand-in pigments (red, blue, yellow) and over
//! the geometries 45°/0°, d/8° SCI and SCE, at the scene's total PVC
//! (linear between the measured PVCs) and each granular species' diameter
//! (linear in log d between the measured diameters), held beyond the
//! measured range. Measurements on stand-ins, not bounds.
//!
//! The stand-ins' grains differ from the binder by |n/n_b − 1| ≤ 0.1, and
//! one such grain scatters at most ~2× more in the scalar equation than in
//! Maxwell's. High-index grains go far beyond: a 100 nm rutile sphere
//! (n 2.75 in 1.5) scatters 4.5–8× more in the scalar equation at
//! 450–650 nm (the scalar sphere against vector Mie; docs/ACCURACY.md,
//! "High-index grains"). [`grain_ratio`] computes that ratio for the
//! scene's own grains, and the plan says when the stand-ins' term does not
//! speak for the layer.

use crate::config::{Equation, GrainShape, Scene};
use crate::optics::baseline::{mie, sphere};

/// Total PVCs the error was measured at.
const PVC: [f64; 3] = [0.15, 0.30, 0.50];
/// Dissolved inks: the largest ΔE00 per PVC.
const DISSOLVED: [f64; 3] = [2.19, 1.35, 1.51];
/// Grain diameters (equal-volume spheres) the error was measured at, nm.
const DIAMETER_NM: [f64; 3] = [100.0, 200.0, 300.0];
/// Grains: the largest ΔE00 per PVC (rows) and diameter (columns).
const GRAINS: [[f64; 3]; 3] = [[2.72, 3.11, 2.66], [1.26, 1.30, 1.22], [1.31, 2.01, 2.10]];

/// Linear interpolation in `xs` (increasing), held beyond its ends.
fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    if x <= xs[0] {
        return ys[0];
    }
    for i in 1..xs.len() {
        if x <= xs[i] {
            let t = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
            return ys[i - 1] + t * (ys[i] - ys[i - 1]);
        }
    }
    ys[ys.len() - 1]
}

/// The grains' error at total PVC `pvc` and diameter `d_nm`.
fn grains(pvc: f64, d_nm: f64) -> f64 {
    let logs = DIAMETER_NM.map(f64::ln);
    let by_pvc: Vec<f64> = GRAINS
        .iter()
        .map(|row| interpolate(&logs, row, d_nm.max(1.0).ln()))
        .collect();
    interpolate(&PVC, &by_pvc, pvc)
}

/// The expected ΔE00 of solving `scene` in the scalar equation rather than
/// Maxwell's: `None` when it is solved in Maxwell's, or when it has no
/// pigment the measurements speak for (an explicit structure, a stack).
pub fn scalar_de00(scene: &Scene) -> Option<f64> {
    if scene.solver.equation == Equation::Maxwell
        || scene.structure.is_some()
        || scene.species.is_empty()
    {
        return None;
    }
    let pvc = scene.total_pvc();
    let terms = scene.species.iter().map(|s| match s.shape {
        GrainShape::Molecular => interpolate(&PVC, &DISSOLVED, pvc),
        _ => grains(pvc, s.diameter_nm),
    });
    terms.reduce(f64::max)
}

/// Beyond this ratio, either way, of one grain's transport scattering in
/// the scalar equation to Maxwell's, the stand-ins' measured term does not
/// speak for the layer (theirs stay within it).
pub const GRAIN_RATIO_LIMIT: f64 = 2.0;

/// One grain's scattering, the scalar equation's over Maxwell's, where it
/// is furthest from 1.
#[derive(Debug, Clone, PartialEq)]
pub struct GrainRatio {
    /// `σ_sca (1 − g)` of the scalar sphere over vector Mie's.
    pub ratio: f64,
    pub species: String,
    pub wavelength_nm: f64,
}

/// The transport cross-section `σ_sca (1 − g)` of each granular species'
/// equal-volume sphere in the binder, the scalar sphere's over vector
/// Mie's, at every solved wavelength: the one furthest from 1 (in log).
/// `None` in Maxwell's equations or without granular species.
pub fn grain_ratio(scene: &Scene) -> Option<GrainRatio> {
    if scene.solver.equation == Equation::Maxwell || scene.structure.is_some() {
        return None;
    }
    let nb = scene.layer.binder_index;
    let mut worst: Option<GrainRatio> = None;
    for sp in &scene.species {
        if sp.shape == GrainShape::Molecular || sp.diameter_nm <= 0.0 {
            continue;
        }
        for &w in &scene.wavelengths_nm {
            let Some(n) = sp.material.index_at(w) else {
                continue;
            };
            let (k, a) = (2.0 * std::f64::consts::PI * nb / w, sp.diameter_nm / 2.0);
            let eps_rel = (n / nb) * (n / nb);
            let transport = |c: sphere::CrossSections| c.scattering * (1.0 - c.asymmetry);
            let vector = transport(mie::cross_sections(k, eps_rel, a));
            if vector <= 0.0 {
                continue;
            }
            let ratio = transport(sphere::cross_sections(k, eps_rel, a)) / vector;
            if worst
                .as_ref()
                .is_none_or(|g| ratio.ln().abs() > g.ratio.ln().abs())
            {
                worst = Some(GrainRatio {
                    ratio,
                    species: sp.name.clone(),
                    wavelength_nm: w,
                });
            }
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measured_points_are_returned_and_held_beyond() {
        assert_eq!(grains(0.15, 100.0), GRAINS[0][0]);
        assert_eq!(grains(0.30, 300.0), GRAINS[1][2]);
        assert_eq!(grains(0.05, 50.0), GRAINS[0][0]);
        assert_eq!(grains(0.6, 450.0), GRAINS[2][2]);
        let mid = grains(0.15, 150.0);
        assert!(mid > GRAINS[0][0] && mid < GRAINS[0][1], "{mid}");
        assert_eq!(interpolate(&PVC, &DISSOLVED, 0.3), 1.35);
    }

    /// A Helmholtz scene's expected error carries the term (grains and
    /// dissolved inks apart); the same scene in Maxwell's equations does
    /// not.
    #[test]
    fn the_plan_counts_it_for_the_scalar_equation_only() {
        let scene = |shape: &str, equation: &str| {
            let text = format!(
                "[layer]\nthickness_nm = 1000.0\nfragment_nm = [1000.0, 1000.0]\npvc = 0.3\n\
                 [[pigment]]\nname = \"red\"\nmaterial = {{ builtin = \"red\" }}\n\
                 diameter_nm = 200.0\n{shape}\n[illumination]\nwavelengths_nm = [550.0]\n\
                 polar_deg = [0.0]\n[solver]\nequation = \"{equation}\"\n[grid]\ncell_nm = 25.0\n"
            );
            crate::config::parse_scene(std::path::Path::new("t.toml"), &text).unwrap()
        };
        let term = |s: &Scene| {
            crate::pipeline::accuracy::expected_rows(s)
                .into_iter()
                .find(|(what, _)| what.starts_with("scalar approximation"))
                .map(|(_, v)| v)
        };
        assert_eq!(term(&scene("", "helmholtz")), Some(GRAINS[1][1]));
        let dissolved = "shape = { kind = \"molecular\" }";
        assert_eq!(term(&scene(dissolved, "helmholtz")), Some(DISSOLVED[1]));
        assert_eq!(term(&scene("", "maxwell")), None);
        assert_eq!(scalar_de00(&scene(dissolved, "maxwell")), None);
    }

    /// Rutile of 100 nm scatters far more in the scalar equation (the
    /// scalar sphere against vector Mie, as scripts-independent closed
    /// forms; miepython gives Q_sca 0.315 against the scalar 2.35 at
    /// 550 nm), and the plan says the stand-ins' term does not speak for
    /// it; the red stand-in of 200 nm stays within the limit.
    #[test]
    fn high_index_grains_are_beyond_the_measured_term() {
        let scene = |material: &str, d: f64| {
            let text = format!(
                "[layer]\nthickness_nm = 1000.0\nfragment_nm = [1000.0, 1000.0]\npvc = 0.1\n\
                 [[pigment]]\nname = \"p\"\nmaterial = {material}\ndiameter_nm = {d}\n\
                 [illumination]\nwavelengths_nm = [450.0, 550.0, 650.0]\npolar_deg = [0.0]\n\
                 [grid]\ncell_nm = 25.0\n"
            );
            crate::config::parse_scene(std::path::Path::new("t.toml"), &text).unwrap()
        };
        let rutile = scene("{ library = \"rutile\" }", 100.0);
        let g = grain_ratio(&rutile).unwrap();
        assert!(g.ratio > 4.0, "{g:?}");
        let row = crate::pipeline::accuracy::expected_rows(&rutile)
            .into_iter()
            .find(|(what, _)| what.starts_with("scalar approximation"))
            .unwrap();
        assert!(row.0.contains("not bounded"), "{}", row.0);
        let red = scene("{ builtin = \"red\" }", 200.0);
        let g = grain_ratio(&red).unwrap();
        assert!(
            g.ratio < GRAIN_RATIO_LIMIT && g.ratio > 1.0 / GRAIN_RATIO_LIMIT,
            "{g:?}"
        );
        let row = crate::pipeline::accuracy::expected_rows(&red)
            .into_iter()
            .find(|(what, _)| what.starts_with("scalar approximation"))
            .unwrap();
        assert!(!row.0.contains("not bounded"), "{}", row.0);
    }
}
