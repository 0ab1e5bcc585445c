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

use crate::config::{Equation, GrainShape, Scene};

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
}
