//! The comparison grids: for one grid declaration, one picture per
//! combination of the labels of the axes that are neither rows, columns nor
//! fixed by `where`, each cell the variant's 45°/0° colour as a patch with
//! its L*, C*ab, h° and standard errors (the variant's tile shrunk to at most
//! [`CELL_PX`] pixels where the result has no measured colour).

use crate::config::{Illuminant, StandardObserver};
use crate::optics::colour::{gamut, lab_to_lch, lch_se, Observer};
use crate::output::h5;
use crate::output::render::canvas::{text_width, Canvas, GLYPH_HEIGHT};
use crate::study::run;
use crate::study::sweep::{sanitise, Expansion, GridDecl, Study, Variant};
use crate::study::StudyError;

/// Largest side of a tile in a comparison grid, pixels.
pub const CELL_PX: usize = 200;
const PAD: usize = 8;
const BG: [u8; 3] = [255, 255, 255];
const INK: [u8; 3] = [20, 20, 20];
const EMPTY: [u8; 3] = [215, 215, 215];

/// Labels of `axis` in axis order, restricted to `only` when given.
fn axis_labels(study: &Study, axis: &str, only: &Option<Vec<String>>) -> Vec<String> {
    match only {
        Some(l) => l.clone(),
        None => study
            .axes
            .iter()
            .find(|a| a.name == axis)
            .map(|a| a.values.iter().map(|v| v.label.clone()).collect())
            .unwrap_or_default(),
    }
}

/// One picture of a grid declaration: its name, title, labels and the
/// variant of each cell (the same for the grid and its ΔE00 heat map).
pub(crate) struct GridPicture<'a, S = crate::config::Scene> {
    /// File name without extension: `<grid>[__<axis>-<label>…]`.
    pub stem: String,
    pub title: String,
    /// The axes of the rows and the columns.
    pub rows_axis: String,
    pub cols_axis: String,
    pub rows: Vec<String>,
    pub cols: Vec<String>,
    /// `cells[row][col]`: the variant there, if any.
    pub cells: Vec<Vec<Option<&'a Variant<S>>>>,
}

/// The pictures of one grid declaration, one per combination of the labels
/// of the split axes among the variants that fit it, in expansion order.
pub(crate) fn pictures<'a, S>(
    study: &Study,
    exp: &'a Expansion<S>,
    g: &GridDecl,
) -> Vec<GridPicture<'a, S>> {
    let split: Vec<&str> = study
        .axes
        .iter()
        .map(|a| a.name.as_str())
        .filter(|a| *a != g.rows && *a != g.cols && !g.where_.contains_key(*a))
        .collect();
    let mut rows = axis_labels(study, &g.rows, &g.row_labels);
    let mut cols = axis_labels(study, &g.cols, &g.col_labels);
    // A subset (`--only`) draws only the labels it selected.
    for sel in &exp.selection {
        if sel.axis == g.rows {
            rows.retain(|l| sel.labels.contains(l));
        }
        if sel.axis == g.cols {
            cols.retain(|l| sel.labels.contains(l));
        }
    }
    let fits = |v: &Variant<S>| {
        g.where_.iter().all(|(a, l)| v.label(a) == Some(l))
            && v.label(&g.rows)
                .is_some_and(|l| rows.iter().any(|x| x == l))
            && v.label(&g.cols)
                .is_some_and(|l| cols.iter().any(|x| x == l))
    };
    // Distinct combinations of the split axes among the fitting variants, in
    // expansion order.
    let mut combos: Vec<Vec<Option<String>>> = vec![];
    for v in exp.variants.iter().filter(|v| fits(v)) {
        let c: Vec<Option<String>> = split
            .iter()
            .map(|a| v.label(a).map(str::to_string))
            .collect();
        if !combos.contains(&c) {
            combos.push(c);
        }
    }
    let mut out = vec![];
    for combo in combos {
        let cell = |r: &str, c: &str| {
            exp.variants.iter().find(|v| {
                fits(v)
                    && v.label(&g.rows) == Some(r)
                    && v.label(&g.cols) == Some(c)
                    && split
                        .iter()
                        .zip(&combo)
                        .all(|(a, l)| v.label(a) == l.as_deref())
            })
        };
        let cells = rows
            .iter()
            .map(|r| cols.iter().map(|c| cell(r, c)).collect())
            .collect();
        let mut fixed: Vec<String> = g.where_.iter().map(|(a, l)| format!("{a} {l}")).collect();
        let mut suffix = String::new();
        for (a, l) in split.iter().zip(&combo) {
            let l = l.as_deref().unwrap_or("none");
            fixed.push(format!("{a} {l}"));
            suffix += &format!("__{}-{}", sanitise(a), sanitise(l));
        }
        let title = format!(
            "{} {}: {}{}",
            study.name,
            exp.profile.as_deref().unwrap_or(""),
            g.name,
            if fixed.is_empty() {
                String::new()
            } else {
                format!(" ({})", fixed.join(", "))
            }
        );
        out.push(GridPicture {
            stem: format!("{}{suffix}", g.name),
            title,
            rows_axis: g.rows.clone(),
            cols_axis: g.cols.clone(),
            rows: rows.clone(),
            cols: cols.clone(),
            cells,
        });
    }
    out
}

/// The pictures of one grid declaration: (file name, title, canvas).
pub(super) fn draw_grid(
    study: &Study,
    exp: &Expansion,
    g: &GridDecl,
) -> Result<Vec<(String, String, Canvas)>, StudyError> {
    let mut out = vec![];
    for pic in pictures(study, exp, g) {
        let mut tiles: Vec<Vec<Option<Canvas>>> = vec![];
        for line_cells in &pic.cells {
            let mut line = vec![];
            for cell in line_cells {
                line.push(match cell {
                    Some(v) => Some(match colour_card(v)? {
                        Some(card) => card,
                        None => {
                            let bytes = std::fs::read(run::paths(v).1).map_err(|source| {
                                StudyError::Io(h5::IoError::File {
                                    path: run::paths(v).1,
                                    source,
                                })
                            })?;
                            shrink(&Canvas::decode_png(&bytes)?, CELL_PX)
                        }
                    }),
                    None => None,
                });
            }
            tiles.push(line);
        }
        let subtitle = format!(
            "rows: {}, columns: {}; cells: colour ± s.e. at {CARD_GEOMETRY} (else the \
             geometry each cell names); corner mark: outside sRGB (C*ab reduced for display)",
            pic.rows_axis, pic.cols_axis
        );
        let canvas = compose(&pic.title, &subtitle, &pic.rows, &pic.cols, &tiles);
        out.push((format!("{}.png", pic.stem), pic.title, canvas));
    }
    Ok(out)
}

/// The measurement geometry a grid cell shows where the study measures it
/// (else its first geometry, which the cell names).
const CARD_GEOMETRY: &str = "45/0";
const CARD_W: usize = 190;
const PATCH_H: usize = 80;

/// A grid cell for a variant: a patch of its 45°/0° colour (gamut-mapped for
/// display, marked when moved) above its L*, C*ab, h° and standard errors;
/// `None` when the result has no measured colours (then its tile is shown).
fn colour_card(v: &Variant) -> Result<Option<Canvas>, StudyError> {
    let Some((records, illuminant, observer_deg)) = h5::read_measured(&run::paths(v).0)? else {
        return Ok(None);
    };
    let Some(m) = records
        .iter()
        .find(|m| m.geometry == CARD_GEOMETRY)
        .or(records.first())
    else {
        return Ok(None);
    };
    let (Some(ill), Some(so)) = (
        Illuminant::from_name(&illuminant),
        StandardObserver::from_degrees(observer_deg),
    ) else {
        return Ok(None);
    };
    let obs = Observer::standard(ill, so);
    let mapped = gamut::map_lab(&obs, m.lab);
    let lines = card_lines(m, ill, so);
    let h = PATCH_H + PAD / 2 + lines.len() * (GLYPH_HEIGHT + 3);
    let mut c = Canvas::new(CARD_W, h, BG);
    c.rect(0, 0, CARD_W, PATCH_H, EMPTY);
    c.rect(1, 1, CARD_W - 2, PATCH_H - 2, mapped.srgb8);
    if mapped.moved {
        // A black corner triangle, as on the tiles.
        for y in 0..14usize {
            c.rect((CARD_W - 14 + y) as i64, y as i64, 14 - y, 1, INK);
        }
    }
    for (k, line) in lines.iter().enumerate() {
        c.text(2, PATCH_H + PAD / 2 + k * (GLYPH_HEIGHT + 3), line, INK);
    }
    Ok(Some(c))
}

/// The text under a card's patch.
fn card_lines(m: &h5::MeasuredRecord, ill: Illuminant, so: StandardObserver) -> Vec<String> {
    let [l, c, h] = lab_to_lch(m.lab);
    // A layer with nothing random (a dissolved dye, an explicit structure)
    // stores s.e. 0: the colour is exact, not uncertain.
    let exact = m.lab_se.is_some_and(|se| se.iter().all(|&s| s == 0.0));
    let pm = |se: Option<f64>| se.map_or(String::new(), |s| format!(" ± {s:.2}"));
    let lch_se = m.lab_se.filter(|_| !exact).map(|se| lch_se(m.lab, se));
    let mut lines = vec![
        format!("L* {l:.1}{}", pm(lch_se.map(|s| s[0]))),
        format!("C*ab {c:.1}{}", pm(lch_se.map(|s| s[1]))),
        format!("h° {h:.0}"),
    ];
    lines.push(match m.de00_se {
        _ if exact => "exact (deterministic)".to_string(),
        Some(se) => format!("ΔE00 s.e. {se:.2}"),
        None => "one realisation: no s.e.".to_string(),
    });
    lines.push(format!("{} · {ill}, {}°", m.geometry, so.degrees()));
    lines
}

/// Shrink by the smallest integer factor that brings both sides to ≤ `max`
/// (box average).
pub fn shrink(src: &Canvas, max: usize) -> Canvas {
    let f = src.w.div_ceil(max).max(src.h.div_ceil(max)).max(1);
    if f == 1 {
        return Canvas {
            w: src.w,
            h: src.h,
            px: src.px.clone(),
        };
    }
    let (w, h) = (src.w / f, src.h / f);
    let mut out = Canvas::new(w.max(1), h.max(1), BG);
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0usize; 3];
            for dy in 0..f {
                for dx in 0..f {
                    let i = ((y * f + dy) * src.w + x * f + dx) * 3;
                    for (a, &p) in acc.iter_mut().zip(&src.px[i..i + 3]) {
                        *a += p as usize;
                    }
                }
            }
            let n = f * f;
            let o = (y * w + x) * 3;
            for (p, a) in out.px[o..o + 3].iter_mut().zip(acc) {
                *p = ((a + n / 2) / n) as u8;
            }
        }
    }
    out
}

/// Lay out a labelled grid of tiles.
pub(crate) fn compose(
    title: &str,
    subtitle: &str,
    rows: &[String],
    cols: &[String],
    tiles: &[Vec<Option<Canvas>>],
) -> Canvas {
    let all = tiles.iter().flatten().flatten();
    let tw = all.clone().map(|c| c.w).max().unwrap_or(CELL_PX / 2);
    let th = all.map(|c| c.h).max().unwrap_or(CELL_PX / 2);
    let cw = tw.max(cols.iter().map(|c| text_width(c)).max().unwrap_or(0)) + PAD;
    let ch = th + PAD;
    let lw = rows.iter().map(|r| text_width(r)).max().unwrap_or(0) + 2 * PAD;
    let head = 3 * (GLYPH_HEIGHT + PAD) + PAD;
    let w = (lw + cols.len() * cw + PAD).max(text_width(title).max(text_width(subtitle)) + 2 * PAD);
    let h = head + rows.len() * ch + PAD;
    let mut c = Canvas::new(w, h, BG);
    c.text(PAD, PAD, title, INK);
    c.text(PAD, 2 * PAD + GLYPH_HEIGHT, subtitle, INK);
    let y0 = head;
    for (j, col) in cols.iter().enumerate() {
        let x = lw + j * cw + (cw - text_width(col)) / 2;
        c.text(x, y0 - GLYPH_HEIGHT - PAD / 2, col, INK);
    }
    for (i, row) in rows.iter().enumerate() {
        let y = y0 + i * ch;
        c.text(PAD, y + (ch - GLYPH_HEIGHT) / 2, row, INK);
        for (j, tile) in tiles[i].iter().enumerate().take(cols.len()) {
            let x = lw + j * cw;
            match tile {
                Some(t) => c.blit(t, (x + (cw - t.w) / 2) as i64, (y + (ch - t.h) / 2) as i64),
                None => {
                    c.rect(
                        (x + PAD / 2) as i64,
                        (y + PAD / 2) as i64,
                        cw - PAD,
                        th,
                        EMPTY,
                    );
                    c.text(
                        x + (cw - text_width("-")) / 2,
                        y + (ch - GLYPH_HEIGHT) / 2,
                        "-",
                        INK,
                    );
                }
            }
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(lab_se: Option<[f64; 3]>, de00_se: Option<f64>) -> h5::MeasuredRecord {
        h5::MeasuredRecord {
            geometry: "45/0".to_string(),
            lab: [50.0, 10.0, -10.0],
            xyz: [20.0, 18.0, 25.0],
            lab_se,
            de00_se,
        }
    }

    fn se_line(m: &h5::MeasuredRecord) -> String {
        card_lines(m, Illuminant::D50, StandardObserver::TwoDegree)[3].clone()
    }

    #[test]
    fn card_lines_say_exact_for_identical_realisations() {
        let exact = se_line(&record(Some([0.0; 3]), Some(0.0)));
        assert!(exact.starts_with("exact"), "{exact}");
        let noisy = se_line(&record(Some([0.1, 0.0, 0.0]), Some(0.12)));
        assert_eq!(noisy, "ΔE00 s.e. 0.12");
        let single = se_line(&record(None, None));
        assert_eq!(single, "one realisation: no s.e.");
    }
}
