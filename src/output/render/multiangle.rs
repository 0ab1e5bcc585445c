//! The pictures of an effect paint: the **flop plot** (L*, C*ab and h
//! against the aspecular angle, one line per illumination angle) and the
//! **multi-angle patches** (one patch per geometry, a row per illumination
//! angle, each with its L*, C*ab and h°; colours outside sRGB — a metallic
//! near the mirror direction is often lighter than the white diffuser,
//! L* > 100 — drawn through [`gamut::map_lab`] and marked as on the tile),
//! with the flop index and the sparkle figures under them.

use super::canvas::{Canvas, GLYPH_HEIGHT, SMALL_HEIGHT, TITLE_HEIGHT};
use super::plot::{self, Panel, PanelSize, Point, Scale, Series};
use super::tile::{ink_on, mark_moved, patch_numbers, PATCH_PX};
use super::{fmt_num, fmt_sig, RenderError};
use crate::optics::colour::{gamut, Observer};
use crate::output::h5::{AngleRecord, SparkleTable};

const PANEL: PanelSize = PanelSize { w: 300, h: 230 };
const MARGIN: usize = 14;
const GAP: usize = 10;
const BACKGROUND: [u8; 3] = [40, 40, 40];
const TEXT: [u8; 3] = [230, 230, 230];
const DIM_TEXT: [u8; 3] = [190, 190, 190];

/// The illumination angles of `colours`, in their order.
fn illuminations(colours: &[AngleRecord]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for c in colours {
        if !out.contains(&c.illumination_deg) {
            out.push(c.illumination_deg);
        }
    }
    out
}

/// The flop plot of `colours` (`conditions`: "D65, 10°"), titled with the
/// paint's `name`.
pub fn flop_png(
    colours: &[AngleRecord],
    name: &str,
    conditions: &str,
    flop_index: Option<f64>,
) -> Result<Vec<u8>, RenderError> {
    let lights = illuminations(colours);
    let x = Scale::covering_linear(colours.iter().map(|c| (c.aspecular_deg, 0.0)), false)
        .ok_or(RenderError::Empty)?
        .padded(0.05);
    let mut panels = Vec::new();
    for (k, what, label) in [
        (0, "lightness L*", "L*"),
        (1, "chroma C*ab", "C*ab"),
        (2, "hue angle h", "h (°)"),
    ] {
        let series: Vec<Series> = lights
            .iter()
            .enumerate()
            .map(|(n, &light)| Series {
                label: format!("θᵢ = {}°", fmt_num(light)),
                colour: plot::palette(n),
                dashed: false,
                points: colours
                    .iter()
                    .filter(|c| c.illumination_deg == light)
                    .map(|c| Point {
                        x: c.aspecular_deg,
                        y: c.lch[k],
                        se: None,
                    })
                    .collect(),
            })
            .collect();
        let y = Scale::covering_linear(series.iter().flat_map(|s| s.values()), k != 2)
            .ok_or(RenderError::Empty)?;
        panels.push(Panel {
            title: what.into(),
            x_label: "aspecular angle (°)".into(),
            y_label: label.into(),
            x,
            y,
            x_categories: None,
            series,
        });
    }
    let legend = panels[0].legend();
    let notes = [
        format!(
            "Multi-angle colour (ASTM E2194 / E2539, DIN 6175-2), {conditions}: the aspecular \
             angle is measured from the mirror direction towards the normal. Flop index {}.",
            flop_index.map_or("not defined (L*45 = 0)".to_string(), |f| format!("{f:.2}"))
        ),
        "The fast model of the paint (METHOD §9); the mirror reflection itself is in none of \
         these views."
            .to_string(),
    ];
    let img = plot::figure(
        &format!("{name} — flop: lightness, chroma and hue against the aspecular angle"),
        &notes,
        &panels,
        3,
        PANEL,
        &legend,
    )?;
    img.encode_png(&format!("{name}: flop"))
}

/// What the patches' caption says.
pub struct PatchCaption<'a> {
    pub name: &'a str,
    pub observer: &'a Observer,
    /// "D65, 10°".
    pub conditions: &'a str,
    /// What the paint lies on, e.g. "3 layers on a diffuse ground (albedo 0.8)".
    pub paint: &'a str,
    pub flop_index: Option<f64>,
    pub sparkle: Option<&'a SparkleTable>,
}

/// The multi-angle patches of `colours`: a row per illumination angle, a
/// patch per aspecular angle.
pub fn patches_png(
    colours: &[AngleRecord],
    caption: &PatchCaption,
) -> Result<Vec<u8>, RenderError> {
    if colours.is_empty() {
        return Err(RenderError::Empty);
    }
    let lights = illuminations(colours);
    let per_row = lights
        .iter()
        .map(|&l| colours.iter().filter(|c| c.illumination_deg == l).count())
        .max()
        .unwrap_or(1);
    let (g, s, t) = (
        GLYPH_HEIGHT as f64,
        SMALL_HEIGHT as f64,
        TITLE_HEIGHT as f64,
    );
    let row_head = 70;
    let mut lines = vec![
        format!(
            "Flop index {}",
            caption
                .flop_index
                .map_or("not defined (L*45 = 0)".to_string(), |f| format!("{f:.2}"))
        ),
        "Patches: aspecular angle above each; a triangle marks a colour outside sRGB (drawn \
         at its L*, h with less chroma; L* above 100 drawn at 100); printed numbers are those \
         computed."
            .to_string(),
    ];
    if let Some(sp) = caption.sparkle {
        let per: Vec<String> = sp
            .rows
            .iter()
            .map(|r| {
                format!(
                    "{}°: {} glints/mm² ({} per cell)",
                    fmt_num(r.illumination_deg),
                    fmt_sig(r.glints_per_mm2),
                    fmt_sig(r.glints_per_cell)
                )
            })
            .collect();
        lines.push(format!(
            "Sparkle at {} mm (cell {} mm²): {}; graininess {} under diffuse light",
            fmt_num(sp.viewing_distance_mm),
            fmt_sig(sp.cell_area_mm2),
            per.join(", "),
            fmt_sig(sp.graininess)
        ));
    }
    let width = MARGIN * 2 + row_head + per_row * (PATCH_PX + GAP);
    let wrap = |l: &str| super::canvas::wrap(l, width - 2 * MARGIN);
    let subtitle = wrap(&format!("{} — {}", caption.paint, caption.conditions));
    let head = MARGIN + TITLE_HEIGHT + 4 + subtitle.len() * (GLYPH_HEIGHT + 4) + 8;
    let row_h = GLYPH_HEIGHT + 6 + PATCH_PX + GAP;
    let wrapped: Vec<String> = lines.iter().flat_map(|l| wrap(l)).collect();
    let height = head + lights.len() * row_h + wrapped.len() * (GLYPH_HEIGHT + 4) + MARGIN;
    let mut img = Canvas::new(width, height, BACKGROUND);
    img.text_px(MARGIN as f64, MARGIN as f64, caption.name, TEXT, t);
    for (k, l) in subtitle.iter().enumerate() {
        let y = MARGIN + TITLE_HEIGHT + 4 + k * (GLYPH_HEIGHT + 4);
        img.text(MARGIN, y, l, DIM_TEXT);
    }
    for (r, &light) in lights.iter().enumerate() {
        let y = head + r * row_h;
        img.text_px(
            MARGIN as f64,
            (y + GLYPH_HEIGHT + 6 + PATCH_PX / 2) as f64 - g / 2.0,
            &format!("θᵢ {}°", fmt_num(light)),
            TEXT,
            g,
        );
        for (k, c) in colours
            .iter()
            .filter(|c| c.illumination_deg == light)
            .enumerate()
        {
            let x = MARGIN + row_head + k * (PATCH_PX + GAP);
            img.text_centered(
                (x + PATCH_PX / 2) as f64,
                y as f64,
                &format!("{}°", fmt_num(c.aspecular_deg)),
                TEXT,
                g,
            );
            let py = y + GLYPH_HEIGHT + 6;
            let mapped = gamut::map_lab(caption.observer, c.lab);
            img.rect(x as i64, py as i64, PATCH_PX, PATCH_PX, mapped.srgb8);
            let ink = ink_on(mapped.lab[0]);
            if mapped.moved {
                mark_moved(&mut img, (x, py), ink);
            }
            patch_numbers(&mut img, (x, py), c.lab, ink, s);
        }
    }
    let y0 = head + lights.len() * row_h;
    for (k, l) in wrapped.iter().enumerate() {
        img.text(MARGIN, y0 + k * (GLYPH_HEIGHT + 4), l, DIM_TEXT);
    }
    img.encode_png(&format!("{}: multi-angle colour", caption.name))
}
