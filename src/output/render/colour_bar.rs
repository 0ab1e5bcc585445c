//! The colour bar of the orders picture and its decade labels.

use super::canvas::{Canvas, GLYPH_HEIGHT, SMALL_HEIGHT};
use super::{brightness, to_rgb8, PanelLayout, DIM_TEXT, TEXT};

/// The colour bar of the orders picture: the brightness ramp of the dots in
/// white, `hi` at the top, `lo` at the bottom, a tick and a label at every
/// whole decade in between (and at the ends when they are far from one).
pub(super) fn colour_bar(img: &mut Canvas, layout: &PanelLayout, scale: Option<(f64, f64)>) {
    let (x, y, w, h) = layout.bar;
    let small = SMALL_HEIGHT as f64;
    img.text_px(
        x as f64 - 4.0,
        (y - GLYPH_HEIGHT - 4) as f64,
        "BRDF (sr⁻¹)",
        TEXT,
        GLYPH_HEIGHT as f64,
    );
    let Some((lo, hi)) = scale else {
        img.text_up(
            (x + 1) as f64,
            (y + h) as f64,
            "no diffuse order",
            DIM_TEXT,
            small,
        );
        return;
    };
    for row in 0..h {
        // Top row = hi, bottom row = lo.
        let t = if h > 1 {
            1.0 - row as f64 / (h - 1) as f64
        } else {
            1.0
        };
        let b = brightness(lo + t * (hi - lo), (lo, hi));
        let c = to_rgb8([1.0; 3], b);
        img.rect(x as i64, (y + row) as i64, w, 1, c);
    }
    let y_of = |lv: f64| {
        let t = if hi > lo { (lv - lo) / (hi - lo) } else { 1.0 };
        y as f64 + (1.0 - t) * (h - 1) as f64
    };
    let mut ticks: Vec<(f64, String)> = (lo.ceil() as i64..=hi.floor() as i64)
        .map(|d| (d as f64, decade_label(d)))
        .collect();
    // Label the ends too when no decade is close to them.
    let spacing = small + 2.0;
    for end in [hi, lo] {
        if ticks
            .iter()
            .all(|(v, _)| (y_of(*v) - y_of(end)).abs() > spacing)
        {
            ticks.push((end, mantissa_label(end)));
        }
    }
    for (lv, label) in ticks {
        let ty = y_of(lv);
        img.rect((x + w) as i64, ty.round() as i64, 4, 1, TEXT);
        img.text_px((x + w + 6) as f64, ty - small / 2.0, &label, TEXT, small);
    }
}

/// `10ⁿ` with a superscript exponent.
pub(super) fn decade_label(d: i64) -> String {
    format!("10{}", superscript(&d.to_string()))
}

/// A value given by its log10, as `a.b×10ⁿ`.
pub(super) fn mantissa_label(lv: f64) -> String {
    let d = lv.floor();
    let m = 10f64.powf(lv - d);
    if (m - 10.0).abs() < 0.05 {
        return decade_label(d as i64 + 1);
    }
    format!("{:.1}×10{}", m, superscript(&(d as i64).to_string()))
}

/// Digits and minus sign as Unicode superscripts.
pub fn superscript(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            '9' => '⁹',
            '-' => '⁻',
            other => other,
        })
        .collect()
}
