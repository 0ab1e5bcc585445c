//! Hiding power as text: the line the tile draws over a hiding chart and
//! the lines `inksim run` prints (contrast ratio, Kubelka's S and K at Y,
//! and the K/S maximum, each ± its standard error).

use crate::optics::appearance::hiding::{Hiding, Scalar};

/// The geometry the tile and the study tables report: d/8° SCI where the
/// scene measures it (ISO 6504-3's), else the first measured one.
pub fn reported(hiding: &[Hiding]) -> Option<&Hiding> {
    hiding
        .iter()
        .find(|h| h.geometry == crate::config::Measurement::DiffuseEightSci)
        .or_else(|| hiding.first())
}

/// `v` to 4 significant digits (plain notation for ordinary magnitudes).
pub fn sig4(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let digits = (3 - v.abs().log10().floor() as i64).clamp(0, 8) as usize;
    format!("{v:.digits$}")
}

/// `0.9123 ± 0.0041`, or the value alone with `(no s.e.)` where there is
/// none.
pub fn with_se(s: Scalar) -> String {
    match s.se {
        Some(se) if se.is_nan() => format!(
            "{} (no s.e.: in some realisation no Kubelka layer fits the two reflectances)",
            sig4(s.value)
        ),
        Some(se) => format!("{} ± {}", sig4(s.value), sig4_like(se, s.value)),
        None => format!("{} (no s.e.: one realisation)", sig4(s.value)),
    }
}

/// `se` with as many decimals as `value` gets from [`sig4`].
fn sig4_like(se: f64, value: f64) -> String {
    if !value.is_finite() || value == 0.0 || !se.is_finite() {
        return sig4(se);
    }
    let digits = (3 - value.abs().log10().floor() as i64).clamp(0, 8) as usize;
    format!("{se:.digits$}")
}

/// The tile's hiding line: `contrast ratio 0.9123 ± 0.0041 (d/8 SCI, D50,
/// 2°; Y 81.2 over black, 89.0 over white)`.
pub fn tile_line(h: &Hiding, conditions: &str) -> String {
    format!(
        "contrast ratio {} ({}, {conditions}; Y {:.2} over black, {:.2} over white)",
        with_se(h.contrast_ratio),
        h.geometry,
        h.y_black,
        h.y_white
    )
}

/// The lines `inksim run` prints for one geometry.
pub fn lines(h: &Hiding, conditions: &str, thickness_um: f64) -> Vec<String> {
    vec![
        format!(
            "hiding ({}, {conditions}): contrast ratio {}  (Y {:.3} over black, {:.3} over \
             white, white ground Y {:.3})",
            h.geometry,
            with_se(h.contrast_ratio),
            h.y_black,
            h.y_white,
            h.y_ground
        ),
        format!(
            "  Kubelka at Y (X = {} µm, reflectances as measured): S {} /µm, K {} /µm, \
             K/S {}, R∞ {}",
            sig4(thickness_um),
            with_se(h.s_y_per_um),
            with_se(h.k_y_per_um),
            with_se(h.k_over_s_y),
            with_se(h.r_inf_y)
        ),
        format!(
            "  largest K/S over the solved wavelengths: {} at {} nm",
            with_se(h.k_over_s_max),
            h.k_over_s_max_wavelength_nm
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_carry_four_significant_digits_and_their_error_alike() {
        assert_eq!(sig4(0.912345), "0.9123");
        assert_eq!(sig4(12.3456), "12.35");
        assert_eq!(
            with_se(Scalar {
                value: 0.912345,
                se: Some(0.00412)
            }),
            "0.9123 ± 0.0041"
        );
        assert!(with_se(Scalar {
            value: 1.0,
            se: None
        })
        .contains("no s.e."));
        let unfit = with_se(Scalar {
            value: 0.5,
            se: Some(f64::NAN),
        });
        assert!(
            unfit.contains("no Kubelka layer fits") && !unfit.contains("NaN"),
            "{unfit}"
        );
    }
}
