//! The sparkle texture of an effect paint: a patch of the panel as the eye
//! sees it at the viewing distance, one tile per light (a small light at
//! each sparkle illumination angle, then diffuse light), each resolution
//! cell drawn as a square of [`CELL_PX`] pixels in the colour of its
//! tristimulus values ([`crate::optics::flakes::sparkle_texture`]); cells
//! brighter than the white diffuser clip per channel. Under each tile its
//! light, the model's glint density and the glints drawn; a scale bar in
//! millimetres under the row.

use super::canvas::{Canvas, GLYPH_HEIGHT, TITLE_HEIGHT};
use super::{fmt_num, fmt_sig, RenderError};
use crate::optics::colour::{to_srgb8, Observer};
use crate::optics::flakes::sparkle_texture::Texture;

/// Pixels per resolution cell (each side).
pub const CELL_PX: usize = 2;
const MARGIN: usize = 14;
const GAP: usize = 16;
const BACKGROUND: [u8; 3] = [40, 40, 40];
const TEXT: [u8; 3] = [230, 230, 230];
const DIM_TEXT: [u8; 3] = [190, 190, 190];

/// One tile: its light (None: diffuse) and texture.
pub struct SparkleTile<'a> {
    pub illumination_deg: Option<f64>,
    /// The model's glints per cm² (0 under diffuse light).
    pub glints_per_cm2: f64,
    pub texture: &'a Texture,
}

/// What the picture says around the tiles.
pub struct SparkleCaption<'a> {
    pub name: &'a str,
    pub observer: &'a Observer,
    /// "D65, 10°".
    pub conditions: &'a str,
    pub viewing_distance_mm: f64,
    /// A resolution cell's side, mm.
    pub cell_mm: f64,
    pub acceptance_deg: f64,
    pub graininess: f64,
    pub seed: u64,
}

/// The tiles side by side with their captions.
pub fn sparkle_png(
    tiles: &[SparkleTile],
    caption: &SparkleCaption,
) -> Result<Vec<u8>, RenderError> {
    let first = tiles.first().ok_or(RenderError::Empty)?.texture;
    let (tw, th) = (first.width * CELL_PX, first.height * CELL_PX);
    let width = 2 * MARGIN + tiles.len() * tw + (tiles.len() - 1) * GAP;
    let line = GLYPH_HEIGHT + 4;
    let wrap = |l: &str| super::canvas::wrap(l, width - 2 * MARGIN);
    let side_mm = first.width as f64 * caption.cell_mm;
    let subtitle = wrap(&format!(
        "A {} × {} mm patch seen from {} mm along the normal ({} × {} resolution cells of \
         {} mm, the eye's 1′), {}; light at θᵢ from the normal, then diffuse light",
        fmt_num(side_mm),
        fmt_num(first.height as f64 * caption.cell_mm),
        fmt_num(caption.viewing_distance_mm),
        first.width,
        first.height,
        fmt_sig(caption.cell_mm),
        caption.conditions
    ));
    let notes = wrap(&format!(
        "Each cell: the fast model's colour at that geometry plus its glints, Poisson per \
         cell with the sparkle model's mean (acceptance {}°), each a flake of the layer's \
         diameter distribution; colours above the white diffuser clip. Under diffuse light \
         no glints (graininess {}, the relative spread of flakes per cell, not drawn). \
         Seed {}.",
        fmt_num(caption.acceptance_deg),
        fmt_sig(caption.graininess),
        caption.seed
    ));
    let head = MARGIN + TITLE_HEIGHT + 4 + subtitle.len() * line + 6;
    let tiles_bottom = head + th + 6 + 2 * line;
    let bar_h = line + 12;
    let height = tiles_bottom + bar_h + notes.len() * line + MARGIN;
    let mut img = Canvas::new(width, height, BACKGROUND);
    img.text_px(
        MARGIN as f64,
        MARGIN as f64,
        &format!("{} — sparkle", caption.name),
        TEXT,
        TITLE_HEIGHT as f64,
    );
    for (k, l) in subtitle.iter().enumerate() {
        img.text(MARGIN, MARGIN + TITLE_HEIGHT + 4 + k * line, l, DIM_TEXT);
    }
    for (k, tile) in tiles.iter().enumerate() {
        let t = tile.texture;
        let x0 = MARGIN + k * (tw + GAP);
        for cy in 0..t.height {
            for cx in 0..t.width {
                let c = to_srgb8(caption.observer, t.xyz[cy * t.width + cx]);
                img.rect(
                    (x0 + cx * CELL_PX) as i64,
                    (head + cy * CELL_PX) as i64,
                    CELL_PX,
                    CELL_PX,
                    c,
                );
            }
        }
        let (light, figures) = match tile.illumination_deg {
            Some(deg) => (
                format!("light at θᵢ {}°", fmt_num(deg)),
                format!(
                    "{} glints/cm², {} drawn",
                    fmt_sig(tile.glints_per_cm2),
                    t.glints
                ),
            ),
            None => ("diffuse light".to_string(), "no glints".to_string()),
        };
        let cx = (x0 + tw / 2) as f64;
        let y = head + th + 6;
        img.text_centered(cx, y as f64, &light, TEXT, GLYPH_HEIGHT as f64);
        img.text_centered(
            cx,
            (y + line) as f64,
            &figures,
            DIM_TEXT,
            GLYPH_HEIGHT as f64,
        );
    }
    // A scale bar of a round length under the first tile.
    let bar_mm = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0]
        .into_iter()
        .rev()
        .find(|&l| l <= 0.5 * side_mm)
        .unwrap_or(1.0);
    let bar_px = (bar_mm / caption.cell_mm * CELL_PX as f64).round() as usize;
    let by = tiles_bottom + 4;
    img.rect(MARGIN as i64, by as i64, bar_px.max(1), 3, TEXT);
    img.text(
        MARGIN + bar_px + 8,
        by.saturating_sub(GLYPH_HEIGHT / 2),
        &format!("{} mm", fmt_num(bar_mm)),
        TEXT,
    );
    for (k, l) in notes.iter().enumerate() {
        img.text(MARGIN, tiles_bottom + bar_h + k * line, l, DIM_TEXT);
    }
    img.encode_png(&format!("{}: sparkle texture", caption.name))
}
