//! Gamut mapping: CIELAB colours an sRGB display cannot show, brought inside
//! its gamut without changing their lightness or hue.
//!
//! The colours of a result are CIELAB relative to the observer's white
//! ([`Observer::white_xyz`]). Most lie inside the sRGB gamut; some do not —
//! a saturated pigment seen at a glancing angle, or a radiance factor above 1
//! (L* > 100) near the specular direction. The plain 8-bit path
//! ([`super::encode_srgb8`]) clips each linear channel to [0, 1], which shifts
//! hue and lightness in ways that depend on which channel clips.
//!
//! [`map_lab`] does instead:
//! 1. L* is clamped to [0, 100] (white is the lightest colour a display shows,
//!    black the darkest);
//! 2. if the colour (with the clamped L*) has linear sRGB within [0, 1] in
//!    every channel (tolerance [`GAMUT_TOLERANCE`]), it is kept as it is;
//! 3. otherwise its chroma `C*ab = √(a*² + b*²)` is reduced at constant L* and
//!    hue angle `h° = atan2(b*, a*)` by bisection on [0, C*ab] (the neutral
//!    grey of that L* is always inside) until the interval is narrower than
//!    [`CHROMA_RESOLUTION`]; the inside end is kept.
//!
//! The mapped colour therefore has exactly the clamped L* and the input hue,
//! and the largest chroma of that line the display shows. For sRGB the line of
//! constant L* and h° leaves the gamut once, so the mapping is monotone in
//! chroma: more chroma in never gives less chroma out. Colours inside are
//! encoded exactly as [`super::to_srgb8`] encodes their XYZ.

use super::{encode_srgb8, lab_to_lch, Observer};

/// How far outside [0, 1] a linear channel may lie and still count as
/// inside: rounding of the Lab ↔ XYZ round trip, far below one 8-bit step.
pub const GAMUT_TOLERANCE: f64 = 1e-9;
/// Width of the final chroma interval of the bisection (C*ab units).
pub const CHROMA_RESOLUTION: f64 = 1e-6;

/// A CIELAB colour as an sRGB display shows it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mapped {
    /// 8-bit sRGB of the mapped colour.
    pub srgb8: [u8; 3],
    /// CIELAB of the mapped colour (same white as the input).
    pub lab: [f64; 3],
    /// Whether the colour was outside the gamut (or L* outside [0, 100])
    /// and had to be moved.
    pub moved: bool,
}

/// XYZ (scale of `white`) of CIE 1976 L*a*b*: the inverse of
/// [`super::xyz_to_lab`] with the same ε = 216/24389 and κ = 24389/27.
pub fn lab_to_xyz(lab: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    const EPS: f64 = 216.0 / 24389.0;
    const KAPPA: f64 = 24389.0 / 27.0;
    let [l, a, b] = lab;
    let fy = (l + 16.0) / 116.0;
    let fx = fy + a / 500.0;
    let fz = fy - b / 200.0;
    let finv = |f: f64| {
        let f3 = f * f * f;
        if f3 > EPS {
            f3
        } else {
            (116.0 * f - 16.0) / KAPPA
        }
    };
    let yr = if l > KAPPA * EPS {
        fy * fy * fy
    } else {
        l / KAPPA
    };
    [white[0] * finv(fx), white[1] * yr, white[2] * finv(fz)]
}

/// Linear sRGB (white = (1, 1, 1)) of a CIELAB colour under `obs`.
pub fn lab_to_linear_srgb(obs: &Observer, lab: [f64; 3]) -> [f64; 3] {
    obs.linear_srgb(lab_to_xyz(lab, obs.white_xyz()))
}

/// Whether linear sRGB `rgb` lies in [0, 1]³ (within [`GAMUT_TOLERANCE`]).
pub fn in_gamut(rgb: [f64; 3]) -> bool {
    rgb.iter()
        .all(|&v| (-GAMUT_TOLERANCE..=1.0 + GAMUT_TOLERANCE).contains(&v))
}

/// Map a CIELAB colour (white of `obs`) into the sRGB gamut (module docs).
/// A colour with a non-finite component is drawn black and marked moved.
pub fn map_lab(obs: &Observer, lab: [f64; 3]) -> Mapped {
    if !lab.iter().all(|v| v.is_finite()) {
        return Mapped {
            srgb8: [0, 0, 0],
            lab: [0.0; 3],
            moved: true,
        };
    }
    let l = lab[0].clamp(0.0, 100.0);
    let clamped = [l, lab[1], lab[2]];
    let rgb = lab_to_linear_srgb(obs, clamped);
    if in_gamut(rgb) {
        return Mapped {
            srgb8: encode_srgb8(rgb),
            lab: clamped,
            moved: l != lab[0],
        };
    }
    let [_, c, _] = lab_to_lch(clamped);
    let (ua, ub) = (lab[1] / c, lab[2] / c);
    let at = |chroma: f64| [l, chroma * ua, chroma * ub];
    let (mut lo, mut hi) = (0.0, c);
    while hi - lo > CHROMA_RESOLUTION {
        let mid = 0.5 * (lo + hi);
        if in_gamut(lab_to_linear_srgb(obs, at(mid))) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let mapped = at(lo);
    Mapped {
        srgb8: encode_srgb8(lab_to_linear_srgb(obs, mapped)),
        lab: mapped,
        moved: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::colour::xyz_to_lab;

    #[test]
    fn lab_round_trips_through_xyz() {
        let w = Observer::cie1931_d65().white_xyz();
        for xyz in [[20.0, 30.0, 40.0], [0.1, 0.2, 0.05], [95.0, 100.0, 108.0]] {
            let back = lab_to_xyz(xyz_to_lab(xyz, w), w);
            for k in 0..3 {
                assert!(
                    (back[k] - xyz[k]).abs() < 1e-9 * xyz[k].max(1.0),
                    "{xyz:?} {back:?}"
                );
            }
        }
    }
}
