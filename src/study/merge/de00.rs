//! The ΔE00 heat map beside each comparison grid picture
//! (`grids/<picture>-de00.png`): the grid's cells, rows and columns, each
//! cell coloured by the CIEDE2000 difference of its variant's measured
//! colour (45°/0°, as on the grid cards) to the colour of the grid's
//! reference cell, and labelled with that ΔE00 ± its standard error.
//!
//! The reference is the first cell, row by row, that has a measured colour:
//! the top-left cell (first row label, first column label) unless that one
//! is empty. The axes declare no reference label, and the grid's first row
//! and column are where a reader looks for one; the picture names it and
//! frames it.
//!
//! The standard error of ΔE00 comes from both colours' standard errors of
//! L*, a*, b* by linear propagation ([`delta_e2000_se`], as for the effects
//! table); it is present only when both variants have one. A cell whose
//! ΔE00 is within two standard errors of 0 is hatched and its number marked
//! "≈": the difference is not resolved by the realisations run. The colour
//! bar runs from 0 to a tick at or above the largest ΔE00 of the picture.

use super::grid::{pictures, GridPicture};
use super::measured;
use crate::optics::colour::{delta_e2000, delta_e2000_se};
use crate::output::render::canvas::{text_width, wrap, Canvas, GLYPH_HEIGHT, SMALL_HEIGHT};
use crate::output::render::plot::colour_map::{colour_bar, viridis, BAR_LABELS_W, BAR_W};
use crate::output::render::plot::Scale;
use crate::study::run;
use crate::study::sweep::{Expansion, Study};
use crate::study::StudyError;

const PAD: usize = 8;
const CELL_W: usize = 150;
const CELL_H: usize = 58;
const BG: [u8; 3] = [255, 255, 255];
const INK: [u8; 3] = [20, 20, 20];
const EMPTY: [u8; 3] = [215, 215, 215];

/// One cell of a heat map: a variant with a measured colour.
#[derive(Debug, Clone, PartialEq)]
pub struct De00Cell {
    pub variant: String,
    pub lab: [f64; 3],
    pub lab_se: Option<[f64; 3]>,
    /// CIEDE2000 difference of this colour to the reference cell's.
    pub de00: f64,
    /// Its standard error (`None` unless both colours have one).
    pub se: Option<f64>,
}

impl De00Cell {
    /// Whether ΔE00 is within two standard errors of 0.
    pub fn near_zero(&self) -> bool {
        self.se.is_some_and(|s| self.de00 <= 2.0 * s)
    }
}

/// The heat map of one comparison grid picture.
#[derive(Debug, Clone)]
pub struct De00Map {
    /// The grid declaration's name.
    pub grid: String,
    /// The grid picture's file name (`<picture>.png`) and the heat map's
    /// (`<picture>-de00.png`), both in `grids/`.
    pub grid_file: String,
    pub file: String,
    pub title: String,
    pub rows_axis: String,
    pub cols_axis: String,
    pub rows: Vec<String>,
    pub cols: Vec<String>,
    /// `cells[row][col]`; `None` where the grid has no variant or the
    /// variant no measured colour.
    pub cells: Vec<Vec<Option<De00Cell>>>,
    /// (row, column) of the reference cell.
    pub reference: (usize, usize),
    /// The colour bar's scale (from 0).
    pub scale: Scale,
    /// "45/0, D50, 2°": the geometry and conditions of the colours.
    pub conditions: String,
}

/// The heat maps of every grid picture of the study that has at least one
/// measured colour, in the order of the grids.
pub fn de00_maps(study: &Study, exp: &Expansion) -> Result<Vec<De00Map>, StudyError> {
    let mut out = vec![];
    for g in &study.grids {
        for pic in pictures(study, exp, g) {
            if let Some(m) = map_of(&g.name, &pic)? {
                out.push(m);
            }
        }
    }
    Ok(out)
}

fn map_of(grid: &str, pic: &GridPicture) -> Result<Option<De00Map>, StudyError> {
    let mut colours = vec![];
    let mut conditions = String::new();
    for line in &pic.cells {
        let mut row = vec![];
        for v in line {
            let m = match v {
                Some(v) => measured(&run::paths(v).0)?.map(|m| (v.name.clone(), m)),
                None => None,
            };
            if let (Some((_, m)), true) = (&m, conditions.is_empty()) {
                conditions = format!("{}, {}", m.record.geometry, m.conditions);
            }
            row.push(m);
        }
        colours.push(row);
    }
    let Some(reference) = colours
        .iter()
        .enumerate()
        .find_map(|(i, r)| r.iter().position(Option::is_some).map(|j| (i, j)))
    else {
        return Ok(None);
    };
    let r = colours[reference.0][reference.1]
        .as_ref()
        .map(|(_, m)| m.record.clone())
        .expect("the reference cell has a colour");
    let cells: Vec<Vec<Option<De00Cell>>> = colours
        .iter()
        .enumerate()
        .map(|(i, line)| {
            line.iter()
                .enumerate()
                .map(|(j, c)| {
                    c.as_ref().map(|(name, m)| {
                        let (lab, lab_se) = (m.record.lab, m.record.lab_se);
                        let is_ref = (i, j) == reference;
                        De00Cell {
                            variant: name.clone(),
                            lab,
                            lab_se,
                            de00: if is_ref { 0.0 } else { delta_e2000(r.lab, lab) },
                            se: match (is_ref, r.lab_se, lab_se) {
                                (true, _, _) => None,
                                (false, Some(sr), Some(s)) => {
                                    Some(delta_e2000_se(r.lab, sr, lab, s))
                                }
                                _ => None,
                            },
                        }
                    })
                })
                .collect()
        })
        .collect();
    let max = cells
        .iter()
        .flatten()
        .flatten()
        .map(|c| c.de00)
        .fold(0.0, f64::max);
    let scale = if max > 0.0 {
        Scale::covering_linear([(0.0, 0.0), (max, 0.0)], true).unwrap_or(Scale::linear(0.0, max))
    } else {
        Scale {
            step: Some(0.2),
            ..Scale::linear(0.0, 1.0)
        }
    };
    Ok(Some(De00Map {
        grid: grid.to_string(),
        grid_file: format!("{}.png", pic.stem),
        file: format!("{}-de00.png", pic.stem),
        title: format!("{}: ΔE00 to the reference cell", pic.title),
        rows_axis: pic.rows_axis.clone(),
        cols_axis: pic.cols_axis.clone(),
        rows: pic.rows.clone(),
        cols: pic.cols.clone(),
        cells,
        reference,
        scale,
        conditions,
    }))
}

/// Relative luminance of an sRGB8 colour, roughly (for the text colour).
fn light(c: [u8; 3]) -> bool {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64 > 140.0
}

/// The text of a cell: the number line and the note under it.
pub(super) fn cell_text(c: &De00Cell, is_ref: bool) -> (String, String) {
    if is_ref {
        return ("0".into(), "reference".into());
    }
    let v = format!("{:.2}", c.de00);
    match c.se {
        Some(0.0) => (v, "exact (s.e. 0)".into()),
        Some(s) if c.near_zero() => (format!("≈ {v} ± {s:.2}"), "within 2 s.e. of 0".into()),
        Some(s) => (format!("{v} ± {s:.2}"), String::new()),
        None => (v, "no s.e.".into()),
    }
}

/// Diagonal hatching over a cell (lines rising to the right, every 9
/// pixels), `c` mixed in at 55 %.
fn hatch(img: &mut Canvas, (x, y, w, h): (usize, usize, usize, usize), c: [u8; 3]) {
    for py in 0..h {
        for px in 0..w {
            if (px + py) % 9 == 0 {
                img.blend((x + px) as i64, (y + py) as i64, c, 0.55);
            }
        }
    }
}

/// Draw a heat map (see the module docs).
pub fn draw(m: &De00Map) -> Canvas {
    let cw = CELL_W.max(m.cols.iter().map(|c| text_width(c)).max().unwrap_or(0) + PAD);
    let lw = m.rows.iter().map(|r| text_width(r)).max().unwrap_or(0) + 2 * PAD;
    let (ri, rj) = m.reference;
    let subtitle = format!(
        "rows: {}, columns: {}; reference: {} {}, {} {} (framed, {})",
        m.rows_axis,
        m.cols_axis,
        m.rows_axis,
        m.rows[ri],
        m.cols_axis,
        m.cols[rj],
        if m.reference == (0, 0) {
            "the first row and column"
        } else {
            "the first cell with a colour"
        }
    );
    let grid_w = lw + m.cols.len() * cw;
    let bar_x = grid_w + 3 * PAD;
    let body_w = bar_x + BAR_W + BAR_LABELS_W;
    let w = body_w
        .max(text_width(&m.title) + 2 * PAD)
        .max(text_width(&subtitle) + 2 * PAD)
        .max(560);
    let legend: Vec<String> = [
        format!(
            "Colour and number: CIEDE2000 ΔE00 of the cell's {} colour to the reference's, \
             ± its standard error (propagated from the L*, a*, b* standard errors of both).",
            m.conditions
        ),
        format!(
            "Hatched, ≈: ΔE00 within 2 standard errors of 0, not told apart from the \
             reference by the realisations run.{}",
            if m.cells
                .iter()
                .flatten()
                .flatten()
                .any(|c| c.lab_se.is_none())
            {
                " No s.e.: a variant with one realisation."
            } else {
                ""
            }
        ),
    ]
    .iter()
    .flat_map(|l| wrap(l, w - 2 * PAD))
    .collect();
    let head = 3 * (GLYPH_HEIGHT + PAD) + PAD;
    let grid_h = m.rows.len() * CELL_H;
    let bar_h = grid_h.max(160);
    let legend_y = head + bar_h + 2 * PAD;
    let h = legend_y + legend.len() * (GLYPH_HEIGHT + 4) + PAD;
    let mut img = Canvas::new(w, h, BG);
    img.text(PAD, PAD, &m.title, INK);
    img.text(PAD, 2 * PAD + GLYPH_HEIGHT, &subtitle, INK);
    for (j, col) in m.cols.iter().enumerate() {
        let x = lw + j * cw + (cw - text_width(col)) / 2;
        img.text(x, head - GLYPH_HEIGHT - PAD / 2, col, INK);
    }
    for (i, row) in m.rows.iter().enumerate() {
        let y = head + i * CELL_H;
        img.text(PAD, y + (CELL_H - GLYPH_HEIGHT) / 2, row, INK);
        for (j, cell) in m.cells[i].iter().enumerate() {
            let (x, y0, cw_in, ch_in) = (lw + j * cw + 1, y + 1, cw - 2, CELL_H - 2);
            let Some(c) = cell else {
                img.rect(x as i64, y0 as i64, cw_in, ch_in, EMPTY);
                img.text(
                    x + (cw_in - text_width("-")) / 2,
                    y0 + (ch_in - GLYPH_HEIGHT) / 2,
                    "-",
                    INK,
                );
                continue;
            };
            let fill = viridis(m.scale.t(c.de00).unwrap_or(0.0));
            let ink = if light(fill) { INK } else { BG };
            img.rect(x as i64, y0 as i64, cw_in, ch_in, fill);
            let is_ref = (i, j) == m.reference;
            if c.near_zero() && !is_ref {
                hatch(&mut img, (x, y0, cw_in, ch_in), ink);
            }
            if is_ref {
                // Black outside, white inside: seen on any fill.
                for k in 0..5 {
                    let c = if k < 2 { INK } else { BG };
                    let (a, b) = (x + k, y0 + k);
                    let (ww, hh) = (cw_in - 2 * k, ch_in - 2 * k);
                    img.rect(a as i64, b as i64, ww, 1, c);
                    img.rect(a as i64, (b + hh - 1) as i64, ww, 1, c);
                    img.rect(a as i64, b as i64, 1, hh, c);
                    img.rect((a + ww - 1) as i64, b as i64, 1, hh, c);
                }
            }
            let (num, note) = cell_text(c, is_ref);
            let cx = (x + cw_in / 2) as f64;
            let ty = y0 + (ch_in - GLYPH_HEIGHT - SMALL_HEIGHT - 2) / 2;
            img.text_centered(cx, ty as f64, &num, ink, GLYPH_HEIGHT as f64);
            img.text_centered(
                cx,
                (ty + GLYPH_HEIGHT + 2) as f64,
                &note,
                ink,
                SMALL_HEIGHT as f64,
            );
        }
    }
    colour_bar(
        &mut img,
        (bar_x, head, bar_h),
        &m.scale,
        viridis,
        "ΔE00",
        INK,
    );
    for (k, line) in legend.iter().enumerate() {
        img.text(PAD, legend_y + k * (GLYPH_HEIGHT + 4), line, INK);
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::render::canvas::has_glyph;

    fn cell(de00: f64, se: Option<f64>) -> De00Cell {
        De00Cell {
            variant: "v".into(),
            lab: [50.0, 0.0, 0.0],
            lab_se: None,
            de00,
            se,
        }
    }

    #[test]
    fn cells_within_two_standard_errors_are_marked() {
        assert!(cell(0.3, Some(0.2)).near_zero());
        assert!(!cell(0.5, Some(0.2)).near_zero());
        assert!(!cell(0.1, None).near_zero());
        assert_eq!(cell_text(&cell(0.3, Some(0.2)), false).0, "≈ 0.30 ± 0.20");
        assert_eq!(cell_text(&cell(1.234, Some(0.1)), false).0, "1.23 ± 0.10");
        assert_eq!(cell_text(&cell(1.0, None), false).1, "no s.e.");
        assert_eq!(cell_text(&cell(0.0, None), true).1, "reference");
        assert!(has_glyph('≈') && has_glyph('±'));
    }
}
