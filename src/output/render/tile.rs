//! The result tile of METHOD §6: on the left a vertical strip, the layer on
//! its substrate under a uniform white sky; on the right a square, the
//! diffuse BRDF of layer + substrate under parallel light. Both share the
//! vertical axis, the viewing angle θₒ (first value at the top); the square's
//! horizontal axis is the illumination angle θᵢ (first value at the left).
//! Each sampled angle is one patch of [`PATCH_PX`] pixels: patches, not
//! interpolated shading, so what is drawn is what was computed.
//!
//! Every patch carries its CIELAB lightness L*, chroma C*ab and hue angle h°
//! (white of the observer). A colour outside the sRGB gamut is drawn through
//! [`gamut::map_lab`] (chroma reduced at constant L* and h°) and marked by a
//! triangle in its top-right corner; the printed numbers are those computed,
//! not those of the mapped colour. Colours inside are drawn with the 8-bit
//! values given (the result file's).

use super::canvas::{self, text_width_px, Canvas, GLYPH_HEIGHT, SMALL_HEIGHT, TITLE_HEIGHT};
use super::{fmt_num, RenderError};
use crate::optics::colour::{gamut, lab_to_lch, Observer};
use ndarray::Array3;

/// Side of one patch, pixels.
pub const PATCH_PX: usize = 76;
/// Side of the out-of-gamut mark, pixels.
pub const MARK_PX: usize = 14;
const GAP_PX: usize = 12;
const MARGIN: usize = 14;
const BACKGROUND: [u8; 3] = [40, 40, 40];
const TEXT: [u8; 3] = [230, 230, 230];
const DIM_TEXT: [u8; 3] = [190, 190, 190];

/// What the tile shows, for its title.
#[derive(Debug, Clone, Copy)]
pub struct TileCaption<'a> {
    /// The layer's (scene's) name.
    pub name: &'a str,
    /// The observer and illuminant of the colours (named in the title, and
    /// used to map colours into the sRGB gamut).
    pub observer: &'a Observer,
    /// What the layer lies on, as the title says it: `on paper of albedo
    /// 0.9`, `without substrate`, `over the white half of a hiding chart …`
    /// ([`crate::config::Substrate::on_phrase`]).
    pub ground: &'a str,
    /// Over a hiding chart: a line with the contrast ratio and its standard
    /// error (the geometry and conditions named), drawn under the title.
    pub hiding: Option<&'a str>,
    /// Azimuth of the plane of incidence, degrees.
    pub azimuth_deg: f64,
}

impl TileCaption<'_> {
    /// "D65, 2°" for the CIE conditions, else "custom observer".
    pub fn conditions(&self) -> String {
        match self.observer.conditions() {
            Some((ill, obs)) => format!("{ill}, {}°", obs.degrees()),
            None => "custom observer".into(),
        }
    }

    /// The title lines: the name and ground, the conditions, and over a
    /// chart the hiding line.
    pub fn lines(&self) -> Vec<String> {
        let mut lines = vec![
            format!("{} — colour {}", self.name, self.ground),
            format!(
                "{}; plane of incidence φ = {}°, viewing on the specular side",
                self.conditions(),
                fmt_num(self.azimuth_deg)
            ),
        ];
        lines.extend(self.hiding.map(str::to_string));
        lines
    }
}

/// Where the parts of a tile lie (pixels); computed from its size and caption.
#[derive(Debug, Clone)]
pub struct TileLayout {
    pub width: usize,
    pub height: usize,
    /// Left edge of each column of patches (column 0: the sky strip).
    pub columns_x: Vec<usize>,
    /// Top edge of each row of patches.
    pub rows_y: Vec<usize>,
    /// Top of the column headings (θᵢ values) and of the row headings' column
    /// (θₒ values), as rectangles: x, y, w, h.
    pub column_heads: (usize, usize, usize, usize),
    pub row_heads: (usize, usize, usize, usize),
    /// Top of the legend.
    pub legend_top: usize,
}

fn angle(v: f64) -> String {
    format!("{}°", fmt_num(v))
}

fn legend() -> [&'static str; 3] {
    [
        "On each patch: CIELAB lightness L*, chroma C*ab and hue angle h° of the colour computed.",
        "Left strip: under a uniform white sky; square: lit from θᵢ (illumination angle), seen from θₒ (viewing angle), BRDF × π.",
        "◥ outside the sRGB gamut: drawn with C*ab reduced at the same L* and h°.",
    ]
}

impl TileLayout {
    /// Layout for `nv` = `viewing_deg.len()` rows and `ni` illumination angles.
    pub fn new(nv: usize, ni: usize, viewing_deg: &[f64], caption: &TileCaption) -> TileLayout {
        let g = GLYPH_HEIGHT as f64;
        let row_head_w = viewing_deg
            .iter()
            .map(|&v| text_width_px(&angle(v), g).ceil() as usize)
            .max()
            .unwrap_or(0);
        // Vertical axis title, then the row headings.
        let x_rows = MARGIN + GLYPH_HEIGHT + 8;
        let x_patches = x_rows + row_head_w + 8;
        let columns_x: Vec<usize> = (0..=ni)
            .map(|c| match c {
                0 => x_patches,
                _ => x_patches + PATCH_PX + GAP_PX + (c - 1) * PATCH_PX,
            })
            .collect();
        let body_right = x_patches + PATCH_PX + GAP_PX + ni * PATCH_PX;
        let y_title = MARGIN;
        let y_axis = y_title + caption.lines().len() * TITLE_HEIGHT + 10;
        let y_heads = y_axis + GLYPH_HEIGHT + 4;
        let y_body = y_heads + GLYPH_HEIGHT + 6;
        let rows_y: Vec<usize> = (0..nv).map(|r| y_body + r * PATCH_PX).collect();
        let legend_top = y_body + nv * PATCH_PX + 10;
        let text_w = caption
            .lines()
            .iter()
            .map(|l| text_width_px(l, TITLE_HEIGHT as f64))
            .chain(legend().iter().map(|l| text_width_px(l, g)))
            .fold(0.0f64, f64::max)
            .ceil() as usize;
        let width = (body_right + MARGIN).max(MARGIN * 2 + text_w);
        let height = legend_top + legend().len() * (GLYPH_HEIGHT + 4) + MARGIN;
        TileLayout {
            width,
            height,
            column_heads: (x_patches, y_heads, body_right - x_patches, GLYPH_HEIGHT),
            row_heads: (x_rows, y_body, row_head_w, nv * PATCH_PX),
            columns_x,
            rows_y,
            legend_top,
        }
    }
}

/// Draw the tile. `srgb8` and `lab` are `(viewing, 1 + illumination, 3)`:
/// column 0 the sky strip, then the BRDF square; `lab` is CIELAB relative to
/// `caption.observer`'s white. `viewing_deg`/`illumination_deg` label the
/// rows and columns.
pub fn tile_png(
    srgb8: &Array3<u8>,
    lab: &Array3<f64>,
    viewing_deg: &[f64],
    illumination_deg: &[f64],
    caption: &TileCaption,
) -> Result<Vec<u8>, RenderError> {
    let (nv, nc, _) = srgb8.dim();
    if nv == 0
        || nc < 2
        || nv != viewing_deg.len()
        || nc != illumination_deg.len() + 1
        || lab.dim() != srgb8.dim()
    {
        return Err(RenderError::Empty);
    }
    let ni = nc - 1;
    let l = TileLayout::new(nv, ni, viewing_deg, caption);
    let mut img = Canvas::new(l.width, l.height, BACKGROUND);
    let (g, s, t) = (
        GLYPH_HEIGHT as f64,
        SMALL_HEIGHT as f64,
        TITLE_HEIGHT as f64,
    );
    let lines = caption.lines();
    img.text_px(MARGIN as f64, MARGIN as f64, &lines[0], TEXT, t);
    img.text_px(
        MARGIN as f64,
        (MARGIN + TITLE_HEIGHT + 2) as f64,
        &lines[1],
        DIM_TEXT,
        g,
    );
    if let Some(line) = lines.get(2) {
        img.text_px(
            MARGIN as f64,
            (MARGIN + 2 * TITLE_HEIGHT + 2) as f64,
            line,
            TEXT,
            g,
        );
    }

    // Column axis: the sky strip, then θᵢ over the square.
    let y_axis = (l.column_heads.1 - GLYPH_HEIGHT - 4) as f64;
    let sq_x = l.columns_x[1] as f64;
    let sq_w = (ni * PATCH_PX) as f64;
    img.text_centered(
        l.columns_x[0] as f64 + PATCH_PX as f64 / 2.0,
        y_axis,
        "sky",
        TEXT,
        g,
    );
    let title = fitting("illumination angle θᵢ", "θᵢ", sq_w, g);
    img.text_centered(sq_x + sq_w / 2.0, y_axis, title, TEXT, g);
    let y_heads = l.column_heads.1 as f64;
    img.text_centered(
        l.columns_x[0] as f64 + PATCH_PX as f64 / 2.0,
        y_heads,
        "white",
        DIM_TEXT,
        g,
    );
    for (i, &a) in illumination_deg.iter().enumerate() {
        let cx = l.columns_x[1 + i] as f64 + PATCH_PX as f64 / 2.0;
        img.text_centered(cx, y_heads, &angle(a), TEXT, g);
    }
    // Row axis: θₒ, written upwards, then one heading per row.
    let (rx, ry, rw, rh) = l.row_heads;
    let title = fitting("viewing angle θₒ", "θₒ", rh as f64, g);
    img.text_up(
        MARGIN as f64,
        ry as f64 + rh as f64 / 2.0 + text_width_px(title, g) / 2.0,
        title,
        TEXT,
        g,
    );
    for (r, &v) in viewing_deg.iter().enumerate() {
        let label = angle(v);
        let x = (rx + rw) as f64 - text_width_px(&label, g);
        let y = l.rows_y[r] as f64 + (PATCH_PX as f64 - g) / 2.0;
        img.text_px(x, y, &label, TEXT, g);
    }

    for r in 0..nv {
        for c in 0..nc {
            let lab_rc = [lab[[r, c, 0]], lab[[r, c, 1]], lab[[r, c, 2]]];
            let given = [srgb8[[r, c, 0]], srgb8[[r, c, 1]], srgb8[[r, c, 2]]];
            let mapped = gamut::map_lab(caption.observer, lab_rc);
            let rgb = if mapped.moved { mapped.srgb8 } else { given };
            let (x, y) = (l.columns_x[c], l.rows_y[r]);
            img.rect(x as i64, y as i64, PATCH_PX, PATCH_PX, rgb);
            let ink = ink_on(mapped.lab[0]);
            if mapped.moved {
                mark_moved(&mut img, (x, y), ink);
            }
            patch_numbers(&mut img, (x, y), lab_rc, ink, s);
        }
    }
    for (k, line) in legend().iter().enumerate() {
        img.text(
            MARGIN,
            l.legend_top + k * (GLYPH_HEIGHT + 4),
            line,
            DIM_TEXT,
        );
    }
    img.encode_png(&lines.join(" — "))
}

/// An axis title: `long` where it fits in `room` pixels at size `g`, else
/// `short` (a tile of one or two patches; the legend names the angles).
fn fitting<'a>(long: &'a str, short: &'a str, room: f64, g: f64) -> &'a str {
    if text_width_px(long, g) <= room {
        long
    } else {
        short
    }
}

/// The out-of-gamut mark: a filled triangle in the top-right corner of the
/// patch at `(x, y)`.
pub(super) fn mark_moved(img: &mut Canvas, (x, y): (usize, usize), ink: [u8; 3]) {
    for k in 0..MARK_PX {
        img.rect(
            (x + PATCH_PX - MARK_PX + k) as i64,
            (y + k) as i64,
            MARK_PX - k,
            1,
            ink,
        );
    }
}

/// Black on light patches, white on dark ones.
pub(super) fn ink_on(lightness: f64) -> [u8; 3] {
    if lightness > 55.0 {
        [0, 0, 0]
    } else {
        [255, 255, 255]
    }
}

/// L*, C*ab and h° of `lab` in three lines at the bottom left of a patch.
pub(super) fn patch_numbers(
    img: &mut Canvas,
    (x, y): (usize, usize),
    lab: [f64; 3],
    ink: [u8; 3],
    s: f64,
) {
    let [_, c, h] = lab_to_lch(lab);
    let lines = [
        format!("L* {:.1}", lab[0]),
        format!("C* {c:.1}"),
        if c < 0.5 {
            "h° –".to_string()
        } else {
            format!("h° {h:.0}")
        },
    ];
    let y0 = (y + PATCH_PX) as f64 - 4.0 - 3.0 * s;
    for (k, line) in lines.iter().enumerate() {
        img.text_px((x + 4) as f64, y0 + k as f64 * s, line, ink, s);
    }
}

/// Every character the tile writes besides names and numbers has a glyph.
pub fn glyphs_missing(caption: &TileCaption) -> Vec<char> {
    let mut text: String = legend().concat();
    text.push_str(&caption.lines().concat());
    text.push_str("sky white illumination angle θᵢ viewing angle θₒ L* C* h° – 0123456789.");
    text.chars().filter(|&c| !canvas::has_glyph(c)).collect()
}
