//! Sparkle and graininess of a flake finish (METHOD §10).
//!
//! The surface is seen in **resolution cells**: the eye resolves about one
//! arcminute, so at a viewing distance `d` a cell is `(d · 1′)²` (an
//! instrument's pixel otherwise). Under a small light source a cell
//! **glints** when it holds a flake whose normal lies within the acceptance
//! cone (half-angle `γ`, in the lacquer) about the half vector between the
//! refracted light direction and the view. Flakes lie at independent
//! random places, so the glints per cell are Poisson with mean
//! `N_A · A_cell · P`, `N_A` the flakes per unit area of the paint (every
//! flake of the layer is counted; hiding by the flakes above is left out)
//! and `P = ∫_cone D dω / ∫ D dω` the chance that a normal falls in the
//! cone ([`super::normals`]). Viewed along the normal under light at `θ_i`
//! in air, the half vector leans by half the refracted angle. Under diffuse
//! light every flake is lit from every side: no glints stand out, and what
//! remains is **graininess**, here the relative fluctuation of the number of
//! flakes per cell, `1/√(N_A A_cell)` (Poisson).

use super::normals::Orientation;
use crate::optics::baseline::ordinates::gauss_legendre;
use std::f64::consts::PI;

/// One arcminute, the eye's resolution, rad.
pub const ARCMINUTE_RAD: f64 = PI / (180.0 * 60.0);

/// A resolution cell's area, mm², at `viewing_distance_mm` for an angular
/// resolution `resolution_rad`.
pub fn cell_area_mm2(viewing_distance_mm: f64, resolution_rad: f64) -> f64 {
    (viewing_distance_mm * resolution_rad).powi(2)
}

/// Flakes per mm² of paint: a layer `layer_um` thick holding volume
/// fraction `fraction` of discs `diameter_um` across and `thickness_um`
/// thick.
pub fn flakes_per_mm2(fraction: f64, layer_um: f64, diameter_um: f64, thickness_um: f64) -> f64 {
    let disc_um3 = PI * diameter_um * diameter_um / 4.0 * thickness_um;
    fraction * layer_um / disc_um3 * 1e6
}

/// The half vector's tilt from the normal, in the lacquer of index
/// `lacquer`, for light at `illumination_deg` in air and the view along the
/// normal.
pub fn half_vector_tilt(illumination_deg: f64, lacquer: f64) -> f64 {
    let refracted = (illumination_deg.to_radians().sin() / lacquer).asin();
    0.5 * refracted
}

/// `P`: the chance that a normal of `orientation` lies within
/// `half_angle_rad` of the direction tilted `tilt_rad` from the layer
/// normal (Gauss–Legendre in the cone's polar angle, midpoint in its
/// azimuth, over `∫ D dω` by Gauss–Legendre in tilt).
pub fn cone_probability(orientation: &Orientation, tilt_rad: f64, half_angle_rad: f64) -> f64 {
    let density = orientation.density();
    let (x, w) = gauss_legendre(64);
    let total: f64 = x
        .iter()
        .zip(&w)
        .map(|(x, w)| {
            let t = 0.25 * PI * (x + 1.0);
            0.25 * PI * w * density(t) * t.sin() * 2.0 * PI
        })
        .sum();
    let azimuths = 256;
    let mut cone = 0.0;
    for (x, w) in x.iter().zip(&w) {
        let rho = 0.5 * half_angle_rad * (x + 1.0);
        let radial = 0.5 * half_angle_rad * w * rho.sin();
        for k in 0..azimuths {
            let psi = 2.0 * PI * (k as f64 + 0.5) / azimuths as f64;
            let c = rho.cos() * tilt_rad.cos() + rho.sin() * tilt_rad.sin() * psi.cos();
            // Normals below the horizon are the same flakes turned over.
            cone += radial * (2.0 * PI / azimuths as f64) * density(c.abs().min(1.0).acos());
        }
    }
    cone / total
}

/// Sparkle and graininess of a finish.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sparkle {
    /// Mean glints per resolution cell under directional light.
    pub glints_per_cell: f64,
    /// Glints per mm².
    pub glints_per_mm2: f64,
    /// Relative fluctuation of the flakes per cell under diffuse light.
    pub graininess: f64,
}

/// The sparkle of `flakes_per_mm2` flakes of `orientation` seen in cells of
/// `cell_mm2` under light at `illumination_deg` (None: diffuse light, no
/// glints), acceptance half-angle `acceptance_rad`.
pub fn sparkle(
    flakes_per_mm2: f64,
    orientation: &Orientation,
    lacquer: f64,
    cell_mm2: f64,
    acceptance_rad: f64,
    illumination_deg: Option<f64>,
) -> Sparkle {
    let per_cell = flakes_per_mm2 * cell_mm2;
    let glints_per_mm2 = match illumination_deg {
        Some(deg) => {
            let p = cone_probability(orientation, half_vector_tilt(deg, lacquer), acceptance_rad);
            flakes_per_mm2 * p
        }
        None => 0.0,
    };
    Sparkle {
        glints_per_cell: glints_per_mm2 * cell_mm2,
        glints_per_mm2,
        graininess: if per_cell > 0.0 {
            1.0 / per_cell.sqrt()
        } else {
            0.0
        },
    }
}
