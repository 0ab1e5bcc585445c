//! Multi-angle colour of an effect finish, as the trade measures it (ASTM
//! E2194 and E2539, DIN 6175-2), and the flop index.
//!
//! **Geometries.** Light in the plane of incidence at the illumination angle
//! `θ_i`; the view in the same plane at the **aspecular angle** `α`,
//! measured from the mirror direction towards the normal (and on towards
//! the light): the view leaves at the signed polar angle `θ_i − α`, on the
//! mirror's side of the normal when positive (azimuth 0 from the mirror
//! direction's side), on the light's side when negative (azimuth 180°). The
//! set: 45° illumination at `α` = −15°, 15°, 25°, 45°, 75°, 110°, and 15°
//! illumination at −15°, 15°, 25°, 45°, 75° (those of the 45° set whose view
//! stays above 85° from the normal).
//!
//! **Colour** per geometry: the reflectance factor `π f` of the scattered
//! light (the mirror reflection never reaches these views) across the
//! spectrum, through the chosen illuminant and observer, CIELAB and LCh.
//!
//! **Flop index** (X-Rite's, from the 45° set):
//! `FI = 2.69 (L*₁₅ − L*₁₁₀)^1.11 / (L*₄₅)^0.86`: 0 for a solid colour
//! (whose lightness does not change with angle), about 15–17 for a strong
//! metallic. When `L*₁₁₀ > L*₁₅` (a reverse flop) the power is taken of the
//! magnitude and the sign kept, so the index is negative rather than
//! undefined; without lightness at 45° it is not defined.

use crate::optics::colour::{self, ColourError, Observer};

/// One measuring geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    pub illumination_deg: f64,
    pub aspecular_deg: f64,
}

impl Geometry {
    /// The view: polar angle from the normal (°) and azimuth from the
    /// mirror direction's side (0° or 180°).
    pub fn view(&self) -> (f64, f64) {
        let signed = self.illumination_deg - self.aspecular_deg;
        if signed >= 0.0 {
            (signed, 0.0)
        } else {
            (-signed, 180.0)
        }
    }

    /// A short label, e.g. `45as15`.
    pub fn label(&self) -> String {
        format!("{}as{}", self.illumination_deg, self.aspecular_deg)
    }
}

/// The aspecular angles at 45° illumination.
pub const ASPECULAR_45_DEG: [f64; 6] = [-15.0, 15.0, 25.0, 45.0, 75.0, 110.0];
/// The aspecular angles at 15° illumination.
pub const ASPECULAR_15_DEG: [f64; 5] = [-15.0, 15.0, 25.0, 45.0, 75.0];

/// Every geometry of the multi-angle set, the 45° illumination first.
pub fn geometries() -> Vec<Geometry> {
    let at = |illumination_deg: f64, set: &[f64]| {
        set.iter()
            .map(|&aspecular_deg| Geometry {
                illumination_deg,
                aspecular_deg,
            })
            .collect::<Vec<_>>()
    };
    let mut out = at(45.0, &ASPECULAR_45_DEG);
    out.extend(at(15.0, &ASPECULAR_15_DEG));
    out
}

/// The air directions (polar, °) the geometries need among the nodes.
pub fn air_directions() -> Vec<f64> {
    let mut d: Vec<f64> = geometries()
        .iter()
        .flat_map(|g| [g.illumination_deg, g.view().0])
        .collect();
    d.sort_by(f64::total_cmp);
    d.dedup();
    d
}

/// The colour of one geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleColour {
    pub geometry: Geometry,
    pub xyz: [f64; 3],
    pub lab: [f64; 3],
    /// L*, C*ab, h (°).
    pub lch: [f64; 3],
}

/// The colours of every geometry from its reflectance-factor spectrum
/// (`factors[g][l]` at `wavelengths_nm[l]`, geometries as [`geometries`]).
pub fn colours(
    obs: &Observer,
    wavelengths_nm: &[f64],
    factors: &[Vec<f64>],
) -> Result<Vec<AngleColour>, ColourError> {
    geometries()
        .into_iter()
        .zip(factors)
        .map(|(geometry, f)| {
            let xyz = colour::xyz_from_reflectance(obs, wavelengths_nm, f)?;
            let lab = colour::xyz_to_lab(xyz, obs.white_xyz());
            Ok(AngleColour {
                geometry,
                xyz,
                lab,
                lch: colour::lab_to_lch(lab),
            })
        })
        .collect()
}

/// `FI = 2.69 (L*₁₅ − L*₁₁₀)^1.11 / (L*₄₅)^0.86` (sign kept for a reverse
/// flop); None when `L*₄₅ ≤ 0`.
pub fn flop_index(l15: f64, l45: f64, l110: f64) -> Option<f64> {
    if !(l45 > 0.0 && l15.is_finite() && l110.is_finite()) {
        return None;
    }
    let d = l15 - l110;
    Some(d.signum() * 2.69 * d.abs().powf(1.11) / l45.powf(0.86))
}

/// The flop index of a multi-angle set (its 45° illumination at 15°, 45°
/// and 110° aspecular).
pub fn flop_index_of(colours: &[AngleColour]) -> Option<f64> {
    let l = |a: f64| {
        colours
            .iter()
            .find(|c| c.geometry.illumination_deg == 45.0 && c.geometry.aspecular_deg == a)
            .map(|c| c.lab[0])
    };
    flop_index(l(15.0)?, l(45.0)?, l(110.0)?)
}
