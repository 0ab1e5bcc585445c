//! The polar BRDF map of a run: for each angle of incidence (rows) and
//! wavelength (columns, at most [`MAX_WAVELENGTHS`]), the disk of reflected
//! directions seen from above in projected coordinates
//! `(sx, sy) = sin θₒ (cos φₒ, sin φₒ)` (sx right, sy up), each pixel coloured
//! by the layer's diffuse BRDF `f = D / cos θₒ` read from the run's angular
//! table (specular order excluded, no substrate), on one viridis scale
//! shared by every disk with its colour bar. The scale is logarithmic when
//! the values span [`super::plot::scale::LOG_WHEN_DECADES`] decades or more
//! (showing at most [`MAP_DECADES`]; lower values take the darkest colour),
//! else linear from 0. Rings mark θₒ = 30° and 60°, the outer edge 90°;
//! directions beyond [`MAX_VIEW_DEG`] are grey; a white × marks the specular
//! direction.

use super::brdf_plane::{pick_evenly, table_of, MAX_VIEW_DEG, MAX_WAVELENGTHS};
use super::canvas::{self, text_width, GLYPH_HEIGHT, TITLE_HEIGHT};
use super::plot::colour_map::{colour_bar, viridis, BAR_LABELS_W, BAR_W};
use super::plot::{titled_page, Scale, INK, WHITE};
use super::spectra::{incidence_label, realisations_note};
use super::{fmt_num, RenderError};
use crate::optics::appearance::Appearance;

/// Decades shown at most on a log scale.
pub const MAP_DECADES: f64 = 4.0;
/// Radius of a disk, pixels.
const R: usize = 80;
const CELL: usize = 2 * R + 24;
const MARGIN: usize = 16;
const OUTSIDE: [u8; 3] = [200, 200, 200];

/// The colour scale of the maps from the table nodes within
/// [`MAX_VIEW_DEG`] of the normal (see the module docs).
pub fn map_scale(a: &Appearance) -> Option<Scale> {
    let spec = a.spec.table;
    let max_s = MAX_VIEW_DEG.to_radians().sin();
    let mut values = vec![];
    for ((_, _, j, i), &d) in a.brdf_table.mean.indexed_iter() {
        let (sx, sy) = (spec.coord(i), spec.coord(j));
        let s2 = sx * sx + sy * sy;
        if s2 <= max_s * max_s {
            values.push(d / (1.0 - s2).sqrt());
        }
    }
    let hi = values.iter().copied().fold(0.0f64, f64::max);
    if !(hi > 0.0 && hi.is_finite()) {
        return None;
    }
    let positive = values.iter().copied().filter(|v| *v > 0.0);
    let s = Scale::covering(positive.map(|v| (v, 0.0)), true)?;
    if s.log {
        let lo = s.lo.max(s.hi / 10f64.powf(MAP_DECADES));
        return Some(Scale { lo, ..s });
    }
    Scale::covering([(0.0, 0.0), (hi, 0.0)], true)
}

/// The polar BRDF map of `a` as a PNG, titled with the run's `name`.
pub fn brdf_polar_png(a: &Appearance, name: &str) -> Result<Vec<u8>, RenderError> {
    let s = &a.spec;
    let picked = pick_evenly(s.wavelengths_nm.len(), MAX_WAVELENGTHS);
    let rows = s.illumination_deg.len();
    if rows == 0 || picked.is_empty() {
        return Err(RenderError::Empty);
    }
    let scale = map_scale(a);
    let title = format!("{name} — diffuse BRDF over the hemisphere, seen from above");
    let left = MARGIN + text_width("θᵢ = 60°") + 12;
    let top = MARGIN + TITLE_HEIGHT + 10 + GLYPH_HEIGHT + 30;
    let bar_x = left + picked.len() * CELL + 20;
    let width = (bar_x + BAR_W + BAR_LABELS_W + MARGIN)
        .max(canvas::text_width_px(&title, TITLE_HEIGHT as f64).ceil() as usize + 2 * MARGIN)
        .max(560);
    let notes: Vec<String> = [
        format!(
            "Each disk: directions of reflection, sx = sin θₒ cos φₒ to the right, \
             sy = sin θₒ sin φₒ up; plane of incidence at φ = {}° (horizontal when 0); \
             rings at θₒ = 30° and 60°, edge 90°; × the specular direction (its order \
             excluded); grey beyond θₒ = {}°. The layer alone, no paper.",
            fmt_num(s.azimuth_deg),
            fmt_num(MAX_VIEW_DEG)
        ),
        match scale {
            Some(sc) if sc.log => format!(
                "Colour: diffuse BRDF on a log scale shared by all disks; values below {} sr⁻¹ \
                 take the darkest colour. {}.",
                super::colour_bar::mantissa_label(sc.lo.log10()),
                realisations_note(s.realisations)
            ),
            Some(_) => format!(
                "Colour: diffuse BRDF on a linear scale from 0 shared by all disks. {}.",
                realisations_note(s.realisations)
            ),
            None => "No diffuse reflection: every disk is empty.".into(),
        },
    ]
    .iter()
    .flat_map(|n| canvas::wrap(n, width - 2 * MARGIN))
    .collect();
    let line = GLYPH_HEIGHT + 4;
    let grid_h = rows * CELL;
    let height = top + grid_h.max(260) + 10 + notes.len() * line + MARGIN;
    let mut img = titled_page(width, height, &title)?;
    for (c, &l) in picked.iter().enumerate() {
        let cx = (left + c * CELL + CELL / 2) as f64;
        let label = format!("λ = {} nm", fmt_num(s.wavelengths_nm[l]));
        img.text_centered(
            cx,
            (top - GLYPH_HEIGHT - 8) as f64,
            &label,
            INK,
            GLYPH_HEIGHT as f64,
        );
    }
    let max_s = MAX_VIEW_DEG.to_radians().sin();
    for (i, &polar) in s.illumination_deg.iter().enumerate() {
        let cy = (top + i * CELL + CELL / 2) as f64;
        img.text(
            MARGIN,
            cy as usize - GLYPH_HEIGHT / 2,
            &incidence_label(polar),
            INK,
        );
        for (c, &l) in picked.iter().enumerate() {
            let cx = (left + c * CELL + CELL / 2) as f64;
            let table = table_of(a, &a.brdf_table.mean, l, i);
            for py in -(R as i64)..=R as i64 {
                for px in -(R as i64)..=R as i64 {
                    let (sx, sy) = (px as f64 / R as f64, -(py as f64) / R as f64);
                    let s2 = sx * sx + sy * sy;
                    if s2 > 1.0 {
                        continue;
                    }
                    let colour = match scale {
                        _ if s2 > max_s * max_s => OUTSIDE,
                        None => viridis(0.0),
                        Some(sc) => {
                            let f = table.density_at(sx, sy) / (1.0 - s2).sqrt();
                            viridis(sc.t(f).unwrap_or(0.0))
                        }
                    };
                    img.set(cx as i64 + px, cy as i64 + py, colour);
                }
            }
            for deg in [30.0f64, 60.0, 90.0] {
                let c = if deg == 90.0 { INK } else { WHITE };
                img.ring(cx, cy, R as f64 * deg.to_radians().sin(), c);
            }
            let st = polar.to_radians().sin();
            let az = s.azimuth_deg.to_radians();
            let (x, y) = (cx + st * az.cos() * R as f64, cy - st * az.sin() * R as f64);
            for d in -4..=4 {
                let d = d as f64;
                img.set((x + d).round() as i64, (y + d).round() as i64, WHITE);
                img.set((x + d).round() as i64, (y - d).round() as i64, WHITE);
            }
        }
    }
    if let Some(sc) = scale {
        colour_bar(
            &mut img,
            (bar_x, top, grid_h.max(260) - 20),
            &sc,
            viridis,
            "BRDF (sr⁻¹)",
            INK,
        );
    }
    let y0 = top + grid_h.max(260) + 10;
    for (k, n) in notes.iter().enumerate() {
        img.text(MARGIN, y0 + k * line, n, INK);
    }
    img.encode_png(&format!("{name}: polar BRDF map"))
}
