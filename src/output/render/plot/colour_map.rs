//! The colour scale of the maps (viridis: perceptually uniform, readable in
//! grey and with the common colour-vision deficiencies) and a vertical
//! colour bar for any [`Scale`] and colour ramp.

use super::super::canvas::{text_width_px, Canvas, GLYPH_HEIGHT, SMALL_HEIGHT};
use super::Scale;

/// matplotlib's viridis at t = 0, 1/8, …, 1 (8-bit sRGB); linear in between.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Viridis at `t` (clamped to [0, 1]).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    [0, 1, 2].map(|k| (a[k] as f64 + f * (b[k] as f64 - a[k] as f64)).round() as u8)
}

/// Width of the bar itself and the room its tick labels take, pixels.
pub const BAR_W: usize = 16;
pub const BAR_LABELS_W: usize = 78;

/// A vertical colour bar at `(x, y)`, `h` pixels tall: `ramp(t)` with t = 1
/// at the top; ticks of `scale` on its right, `title` above it, in `ink`.
pub fn colour_bar(
    img: &mut Canvas,
    (x, y, h): (usize, usize, usize),
    scale: &Scale,
    ramp: impl Fn(f64) -> [u8; 3],
    title: &str,
    ink: [u8; 3],
) {
    let small = SMALL_HEIGHT as f64;
    let tw = text_width_px(title, GLYPH_HEIGHT as f64);
    img.text_px(
        (x as f64 + BAR_W as f64 / 2.0 - tw / 2.0).max(0.0),
        (y - GLYPH_HEIGHT - 6) as f64,
        title,
        ink,
        GLYPH_HEIGHT as f64,
    );
    for row in 0..h {
        let t = 1.0 - row as f64 / (h.max(2) - 1) as f64;
        img.rect(x as i64, (y + row) as i64, BAR_W, 1, ramp(t));
    }
    for (v, label) in scale.ticks() {
        let Some(t) = scale.t(v) else { continue };
        let ty = y as f64 + (1.0 - t) * (h.max(2) - 1) as f64;
        img.rect((x + BAR_W) as i64, ty.round() as i64, 5, 1, ink);
        img.text_px((x + BAR_W + 8) as f64, ty - small / 2.0, &label, ink, small);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_runs_dark_to_light_through_its_stops() {
        assert_eq!(viridis(0.0), VIRIDIS[0]);
        assert_eq!(viridis(1.0), VIRIDIS[8]);
        assert_eq!(viridis(0.5), VIRIDIS[4]);
        assert_eq!(viridis(f64::NAN), VIRIDIS[0]);
        let lum = |c: [u8; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
        for k in 0..20 {
            let (a, b) = (k as f64 / 20.0, (k + 1) as f64 / 20.0);
            assert!(lum(viridis(b)) >= lum(viridis(a)) - 0.5, "at {a}");
        }
    }
}
