//! The result tile of METHOD §6: on the left a vertical strip, the layer on
//! its substrate under a uniform white sky; on the right a square, the
//! diffuse BRDF of layer + substrate under parallel light. Both share the
//! vertical axis, the viewing angle (first value at the top); the square's
//! horizontal axis is the illumination angle (first value at the left).
//! Each sampled angle is one block of [`BLOCK_PX`] pixels: blocks, not
//! interpolated shading, so what is drawn is what was computed.

use super::{text_width, Canvas, RenderError, GLYPH_HEIGHT};
use ndarray::Array3;

/// Side of one angle block, pixels.
pub const BLOCK_PX: usize = 28;
const GAP_PX: usize = 6;
const MARGIN: usize = 10;
const BACKGROUND: [u8; 3] = [40, 40, 40];
const TEXT: [u8; 3] = [230, 230, 230];

/// Draw the tile from `(viewing, 1 + illumination, 3)` sRGB8 colours.
/// `viewing_deg`/`illumination_deg` label the axes; `title` goes on top.
pub fn tile_png(
    srgb8: &Array3<u8>,
    viewing_deg: &[f64],
    illumination_deg: &[f64],
    title: &str,
) -> Result<Vec<u8>, RenderError> {
    let (nv, nc, _) = srgb8.dim();
    if nv == 0 || nc < 2 || nv != viewing_deg.len() || nc != illumination_deg.len() + 1 {
        return Err(RenderError::Empty);
    }
    let ni = nc - 1;
    let range = |v: &[f64]| {
        format!(
            "{}-{}°",
            super::fmt_num(v[0]),
            super::fmt_num(v[v.len() - 1])
        )
    };
    let top_label = format!("ILLUM {} →", range(illumination_deg));
    let side_label = format!("VIEW {} ↓", range(viewing_deg));
    let strip_label = "SKY";
    let strip_w = BLOCK_PX.max(text_width(strip_label) + 4);
    let body_w = strip_w + GAP_PX + ni * BLOCK_PX;
    let line = GLYPH_HEIGHT + 6;
    let w = MARGIN * 2 + body_w.max(text_width(title)).max(text_width(&side_label));
    let x0 = MARGIN;
    let y_title = MARGIN;
    let y_head = y_title + line;
    let y_body = y_head + line;
    let h = y_body + nv * BLOCK_PX + line + MARGIN;
    let w = w.max(x0 + strip_w + GAP_PX + text_width(&top_label) + MARGIN);
    let mut img = Canvas::new(w, h, BACKGROUND);
    img.text(x0, y_title, title, TEXT);
    img.text(x0, y_head, strip_label, TEXT);
    img.text(x0 + strip_w + GAP_PX, y_head, &top_label, TEXT);
    for v in 0..nv {
        for c in 0..nc {
            let x = if c == 0 {
                x0
            } else {
                x0 + BLOCK_PX + GAP_PX + (c - 1) * BLOCK_PX
            };
            let rgb = [srgb8[[v, c, 0]], srgb8[[v, c, 1]], srgb8[[v, c, 2]]];
            img.rect(
                x as i64,
                (y_body + v * BLOCK_PX) as i64,
                BLOCK_PX,
                BLOCK_PX,
                rgb,
            );
        }
    }
    img.text(x0, y_body + nv * BLOCK_PX + 6, &side_label, TEXT);
    img.encode_png(title)
}
