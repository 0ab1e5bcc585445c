//! Output — pictures of a result: the orders picture, the tile and the geometry.
//!
//! [`diffuse_brdf_png`] draws the diffuse reflection of every solve as an
//! 8-bit RGB PNG: a grid of panels, one row per distinct direction of
//! incidence θᵢ (sorted by polar, then azimuth angle), one column per distinct
//! wavelength λ (ascending), a colour bar on the right and a legend
//! underneath, wrapped to the width of the grid. Several entries with the same
//! wavelength and incidence (e.g. realisations) share a panel.
//!
//! A panel is the disk of reflected directions in the projected plane
//! `(sx, sy) = (sin θ cos φ, sin θ sin φ)`, `sx` to the right, `sy` up, radius
//! [`DISK_RADIUS_PX`] (faint rings mark θ = 30° and 60°). Each reflected order
//! except (0,0) is a small Gaussian dot (σ = [`DOT_SIGMA_PX`]) whose brightness
//! encodes the order's BRDF estimate `R_mn / Ω_cell` (sr⁻¹), where `Ω_cell` is
//! the projected solid angle `Δsx·Δsy` owned by one order. Orders lie on a
//! regular lattice in `(sx, sy)` (`sx = sx_inc + m λ/Lx`, likewise `sy`), so
//! `Δsx, Δsy` come from a least-squares fit of the order positions against
//! `m` and `n`; if one axis cannot be fitted (a single value of `m` or `n`)
//! the other spacing is used for both, and if neither can, `Ω_cell = π / K`
//! for `K` listed orders (they tile the unit disk). Brightness is
//! `0.2 + 0.8 t` with `t` the position of `log10(R/Ω)` between `lo` and `hi`
//! ([`brdf_range`]), shared by all panels: `hi` is the largest value drawn and
//! `lo = max(smallest positive value, hi / 10^LOG_DECADES)`; values below `lo`
//! are not drawn. The colour bar shows the same ramp in white from `lo`
//! (bottom) to `hi` (top), with ticks at whole decades. Overlapping dots
//! combine by maximum, so a pixel at an order's centre shows exactly that
//! order's brightness. The specular direction (the (0,0) order, or the
//! incidence direction when it is not listed) is marked by a small grey cross.
//!
//! Colour: each column is tinted by an approximate colour of its wavelength,
//! the piecewise-linear map of Dan Bruton ("Color Science", 1996):
//! 380–440 nm (violet→blue), 440–490 (blue→cyan), 490–510 (cyan→green),
//! 510–580 (green→yellow), 580–645 (yellow→red), 645–780 (red), without his
//! intensity fall-off at the ends, mixed with 20 % white so every hue stays
//! visible on black; wavelengths outside 380–780 nm are light grey.
//!
//! [`geometry_png`] draws a layer's raster (top view and an x–z section, with
//! axes in nm or µm, a scale bar and the section's position); [`tile::tile_png`]
//! the colour tile; [`spectra_png`], [`brdf_plane_png`] and [`brdf_polar_png`]
//! the plots of a run (R, T, A against wavelength; the BRDF in the plane of
//! incidence; the BRDF as a polar map), drawn with [`plot`]. Text is set by
//! [`canvas`] in an embedded TrueType font.

use std::cmp::Ordering;

use crate::config::Incidence;
use crate::optics::farfield::{Order, SolveEntry};

mod brdf_plane;
mod brdf_polar;
pub mod canvas;
mod colour_bar;
mod geometry;
pub mod multiangle;
pub mod plot;
pub mod preview;
pub mod sparkle;
mod spectra;
pub mod tile;

pub use brdf_plane::{brdf_plane_png, pick_evenly};
pub use brdf_polar::{brdf_polar_png, map_scale};
pub use canvas::{text_width, Canvas, GLYPH_HEIGHT, SMALL_HEIGHT, TITLE_HEIGHT};
use colour_bar::colour_bar;
pub use colour_bar::superscript;
pub use geometry::geometry_png;
pub use preview::preview_png;
pub use spectra::spectra_png;

/// Radius of a panel's disk of directions, in pixels.
pub const DISK_RADIUS_PX: f64 = 60.0;
/// Standard deviation of an order's dot, in pixels.
pub const DOT_SIGMA_PX: f64 = 1.2;
/// Decades of BRDF shown below the brightest order.
pub const LOG_DECADES: f64 = 4.0;

/// Side of the square cell that holds one panel.
const CELL_PX: usize = 140;
const MARGIN: usize = 12;
/// Width of the colour bar, and the room right of it for its ticks.
const BAR_W: usize = 16;
const BAR_LABELS_W: usize = 64;
/// Largest image produced (pixels), to refuse absurd grids instead of
/// allocating gigabytes.
const MAX_PIXELS: usize = 100_000_000;

const BACKGROUND: [u8; 3] = [40, 40, 40];
const TEXT: [u8; 3] = [230, 230, 230];
const DIM_TEXT: [u8; 3] = [190, 190, 190];
const DISK_EDGE: [u8; 3] = [110, 110, 110];
const GUIDE: [u8; 3] = [45, 45, 45];
const CROSS: [u8; 3] = [150, 150, 150];

/// Why a picture cannot be drawn.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("render: no solve entries to draw")]
    Empty,
    #[error("render: entry {index}: {what} is not finite or out of range ({value})")]
    BadValue {
        index: usize,
        what: String,
        value: f64,
    },
    #[error(
        "render: picture of {width} × {height} pixels exceeds the limit of {MAX_PIXELS} pixels"
    )]
    TooLarge { width: usize, height: usize },
    #[error("render: PNG encoding failed: {0}")]
    Encode(#[from] png::EncodingError),
    #[error("render: PNG decoding failed: {0}")]
    Decode(#[from] png::DecodingError),
    #[error("render: unsupported PNG ({0}); need 8-bit RGB or RGBA")]
    Format(String),
    #[error("render: preview: {0}")]
    Preview(String),
}

/// Where the panels of a picture lie; computed from the entries alone.
#[derive(Debug, Clone)]
pub struct PanelLayout {
    pub width: usize,
    pub height: usize,
    /// Column values, ascending.
    pub wavelengths_nm: Vec<f64>,
    /// Row values, sorted by polar then azimuth angle.
    pub incidences: Vec<Incidence>,
    /// The colour bar: left, top, width, height (pixels); its top row shows
    /// the largest BRDF drawn, its bottom row the smallest.
    pub bar: (usize, usize, usize, usize),
    /// Top of the legend, which is wrapped into these lines.
    pub legend_top: usize,
    pub legend: Vec<String>,
    left: usize,
    top: usize,
}

impl PanelLayout {
    /// Lay out the panels for `entries`.
    pub fn new(entries: &[SolveEntry], title: &str) -> Result<Self, RenderError> {
        if entries.is_empty() {
            return Err(RenderError::Empty);
        }
        check_entries(entries)?;
        let mut wavelengths: Vec<f64> = entries.iter().map(|e| e.wavelength_nm).collect();
        wavelengths.sort_by(f64::total_cmp);
        wavelengths.dedup_by(|a, b| close(*a, *b));
        let mut incidences: Vec<Incidence> = entries.iter().map(|e| e.incidence).collect();
        incidences.sort_by(incidence_cmp);
        incidences.dedup_by(|a, b| same_incidence(a, b));

        let left = incidences
            .iter()
            .flat_map(row_label)
            .map(|l| text_width(&l))
            .max()
            .unwrap_or(0)
            + 2 * MARGIN;
        let top = MARGIN + TITLE_HEIGHT + MARGIN + GLYPH_HEIGHT + 8;
        let grid_h = incidences.len() * CELL_PX;
        let bar_x = left + wavelengths.len() * CELL_PX + MARGIN;
        let width = (bar_x + BAR_W + BAR_LABELS_W + MARGIN)
            .max(canvas::text_width_px(title, TITLE_HEIGHT as f64).ceil() as usize + 2 * MARGIN);
        // The bar's unit is written above it, its decades beside it.
        let bar = (
            bar_x,
            top + GLYPH_HEIGHT + 4,
            BAR_W,
            grid_h - GLYPH_HEIGHT - 14,
        );
        let legend = legend_text()
            .iter()
            .flat_map(|p| canvas::wrap(p, width - 2 * MARGIN))
            .collect::<Vec<_>>();
        let legend_top = top + grid_h + 6;
        let height = legend_top + legend.len() * (GLYPH_HEIGHT + 4) + MARGIN;
        if width.saturating_mul(height) > MAX_PIXELS {
            return Err(RenderError::TooLarge { width, height });
        }
        Ok(PanelLayout {
            width,
            height,
            wavelengths_nm: wavelengths,
            incidences,
            bar,
            legend_top,
            legend,
            left,
            top,
        })
    }

    /// Pixel position (x right, y down) of the centre of panel (`row`, `col`).
    pub fn center(&self, row: usize, col: usize) -> (f64, f64) {
        let half = (CELL_PX / 2) as f64;
        (
            (self.left + col * CELL_PX) as f64 + half,
            (self.top + row * CELL_PX) as f64 + half,
        )
    }

    /// Pixel position of direction `(sx, sy)` in panel (`row`, `col`).
    pub fn direction_px(&self, row: usize, col: usize, sx: f64, sy: f64) -> (f64, f64) {
        let (cx, cy) = self.center(row, col);
        (cx + sx * DISK_RADIUS_PX, cy - sy * DISK_RADIUS_PX)
    }

    /// Row and column of the panel that shows `entry`.
    pub fn panel_of(&self, entry: &SolveEntry) -> Option<(usize, usize)> {
        let row = self
            .incidences
            .iter()
            .position(|i| same_incidence(i, &entry.incidence))?;
        let col = self
            .wavelengths_nm
            .iter()
            .position(|w| close(*w, entry.wavelength_nm))?;
        Some((row, col))
    }
}

/// Projected direction `(sin θ cos φ, sin θ sin φ)` of an order.
pub fn order_direction(o: &Order) -> (f64, f64) {
    let (t, p) = (o.theta_deg.to_radians(), o.phi_deg.to_radians());
    (t.sin() * p.cos(), t.sin() * p.sin())
}

/// Projected solid angle owned by one order of `orders` (see module docs).
pub fn order_cell(orders: &[Order]) -> f64 {
    let dx = lattice_spacing(orders, |o| (o.m, order_direction(o).0));
    let dy = lattice_spacing(orders, |o| (o.n, order_direction(o).1));
    match (dx, dy) {
        (Some(a), Some(b)) => a * b,
        (Some(a), None) | (None, Some(a)) => a * a,
        (None, None) => std::f64::consts::PI / orders.len().max(1) as f64,
    }
}

/// BRDF estimate `R / Ω_cell` of every drawable diffuse order of an entry.
fn diffuse_values(e: &SolveEntry) -> impl Iterator<Item = (&Order, f64)> {
    let cell = order_cell(&e.efficiencies.orders);
    e.efficiencies
        .orders
        .iter()
        .filter(|o| !(o.m == 0 && o.n == 0) && o.reflectance > 0.0)
        .map(move |o| (o, o.reflectance / cell))
}

/// `(log10 lo, log10 hi)` of the BRDF (sr⁻¹) the orders picture shows, shared
/// by all panels and spanned by its colour bar (module docs); `None` when no
/// diffuse order has R > 0.
pub fn brdf_range(entries: &[SolveEntry]) -> Option<(f64, f64)> {
    let mut hi = f64::NEG_INFINITY;
    let mut min_pos = f64::INFINITY;
    for e in entries {
        for (_, v) in diffuse_values(e) {
            hi = hi.max(v);
            min_pos = min_pos.min(v);
        }
    }
    (hi > 0.0 && hi.is_finite()).then(|| {
        let lo = min_pos.max(hi / 10f64.powf(LOG_DECADES));
        (lo.log10(), hi.log10())
    })
}

/// Dot brightness (0.2 … 1) of log10 BRDF `lv` on the scale `(lo, hi)`.
fn brightness(lv: f64, (lo, hi): (f64, f64)) -> f64 {
    let t = if hi > lo { (lv - lo) / (hi - lo) } else { 1.0 };
    0.2 + 0.8 * t.clamp(0.0, 1.0)
}

/// Render the diffuse reflection of `entries` as an 8-bit RGB PNG.
pub fn diffuse_brdf_png(entries: &[SolveEntry], title: &str) -> Result<Vec<u8>, RenderError> {
    let layout = PanelLayout::new(entries, title)?;
    let mut img = Canvas::new(layout.width, layout.height, BACKGROUND);
    let scale = brdf_range(entries);

    // Text.
    img.text_px(
        MARGIN as f64,
        MARGIN as f64,
        title,
        TEXT,
        TITLE_HEIGHT as f64,
    );
    let header_y = (MARGIN + TITLE_HEIGHT + MARGIN) as f64;
    for (col, &wl) in layout.wavelengths_nm.iter().enumerate() {
        let (cx, _) = layout.center(0, col);
        let label = format!("λ = {} nm", fmt_num(wl));
        img.text_centered(cx, header_y, &label, TEXT, GLYPH_HEIGHT as f64);
    }
    for (row, inc) in layout.incidences.iter().enumerate() {
        let (_, cy) = layout.center(row, 0);
        let lines = row_label(inc);
        let y0 = cy - (lines.len() * GLYPH_HEIGHT) as f64 / 2.0;
        for (k, l) in lines.iter().enumerate() {
            let x = layout.left - MARGIN - text_width(l);
            img.text_px(
                x as f64,
                y0 + (k * GLYPH_HEIGHT) as f64,
                l,
                TEXT,
                GLYPH_HEIGHT as f64,
            );
        }
    }
    for (k, line) in layout.legend.iter().enumerate() {
        img.text(
            MARGIN,
            layout.legend_top + k * (GLYPH_HEIGHT + 4),
            line,
            DIM_TEXT,
        );
    }
    colour_bar(&mut img, &layout, scale);

    // Empty disks with guides.
    for row in 0..layout.incidences.len() {
        for (col, &wl) in layout.wavelengths_nm.iter().enumerate() {
            let (cx, cy) = layout.center(row, col);
            img.disk(cx, cy, DISK_RADIUS_PX, [0, 0, 0]);
            for s in [0.5, 0.75f64.sqrt()] {
                img.ring(cx, cy, s * DISK_RADIUS_PX, GUIDE);
            }
            img.ring(cx, cy, DISK_RADIUS_PX, DISK_EDGE);
            // Colour swatch under the column header, once per column.
            if row == 0 {
                let tint = to_rgb8(wavelength_tint(wl), 1.0);
                let y0 = layout.top - 5;
                for x in (cx - DISK_RADIUS_PX) as usize..=(cx + DISK_RADIUS_PX) as usize {
                    for y in y0..y0 + 3 {
                        img.set(x as i64, y as i64, tint);
                    }
                }
            }
        }
    }

    // Dots, then specular markers on top.
    for e in entries {
        let Some((row, col)) = layout.panel_of(e) else {
            continue;
        };
        if let Some((lo, hi)) = scale {
            let tint = wavelength_tint(e.wavelength_nm);
            for (o, v) in diffuse_values(e) {
                let lv = v.log10();
                if lv < lo {
                    continue;
                }
                let b = brightness(lv, (lo, hi));
                let (sx, sy) = order_direction(o);
                let (x, y) = layout.direction_px(row, col, sx, sy);
                splat(&mut img, x, y, tint, b);
            }
        }
    }
    for e in entries {
        let Some((row, col)) = layout.panel_of(e) else {
            continue;
        };
        let (sx, sy) = specular_direction(e);
        let (x, y) = layout.direction_px(row, col, sx, sy);
        let (xi, yi) = (x.round() as i64, y.round() as i64);
        for d in -4..=4 {
            img.set(xi + d, yi, CROSS);
            img.set(xi, yi + d, CROSS);
        }
    }

    img.encode_png(title)
}

fn check_entries(entries: &[SolveEntry]) -> Result<(), RenderError> {
    let bad = |index: usize, what: &str, value: f64| RenderError::BadValue {
        index,
        what: what.to_string(),
        value,
    };
    for (i, e) in entries.iter().enumerate() {
        if !(e.wavelength_nm.is_finite() && e.wavelength_nm > 0.0) {
            return Err(bad(i, "wavelength_nm", e.wavelength_nm));
        }
        if !(e.incidence.polar_deg.is_finite() && e.incidence.polar_deg.abs() <= 90.0) {
            return Err(bad(i, "incidence polar_deg", e.incidence.polar_deg));
        }
        if !e.incidence.azimuth_deg.is_finite() {
            return Err(bad(i, "incidence azimuth_deg", e.incidence.azimuth_deg));
        }
        for o in &e.efficiencies.orders {
            let what = |f: &str| format!("order ({}, {}) {f}", o.m, o.n);
            if !o.theta_deg.is_finite() {
                return Err(bad(i, &what("theta_deg"), o.theta_deg));
            }
            if !o.phi_deg.is_finite() {
                return Err(bad(i, &what("phi_deg"), o.phi_deg));
            }
            if !o.reflectance.is_finite() {
                return Err(bad(i, &what("reflectance"), o.reflectance));
            }
        }
    }
    Ok(())
}

/// Least-squares slope of position against order index; `None` when the
/// indices do not vary or the slope vanishes.
fn lattice_spacing(orders: &[Order], key: impl Fn(&Order) -> (i32, f64)) -> Option<f64> {
    let n = orders.len() as f64;
    if orders.len() < 2 {
        return None;
    }
    let (mut sm, mut ss) = (0.0, 0.0);
    for o in orders {
        let (m, s) = key(o);
        sm += m as f64;
        ss += s;
    }
    let (mm, ms) = (sm / n, ss / n);
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for o in orders {
        let (m, s) = key(o);
        let d = m as f64 - mm;
        sxx += d * d;
        sxy += d * (s - ms);
    }
    let slope = (sxy / sxx).abs();
    (sxx > 0.0 && slope.is_finite() && slope > 0.0).then_some(slope)
}

fn specular_direction(e: &SolveEntry) -> (f64, f64) {
    match e.efficiencies.orders.iter().find(|o| o.m == 0 && o.n == 0) {
        Some(o) => order_direction(o),
        None => {
            let (t, p) = (
                e.incidence.polar_deg.to_radians(),
                e.incidence.azimuth_deg.to_radians(),
            );
            (t.sin() * p.cos(), t.sin() * p.sin())
        }
    }
}

/// Bruton's piecewise-linear wavelength → RGB (see module docs), in 0..=1.
pub fn wavelength_tint(nm: f64) -> [f64; 3] {
    let c = if (380.0..440.0).contains(&nm) {
        [(440.0 - nm) / 60.0, 0.0, 1.0]
    } else if (440.0..490.0).contains(&nm) {
        [0.0, (nm - 440.0) / 50.0, 1.0]
    } else if (490.0..510.0).contains(&nm) {
        [0.0, 1.0, (510.0 - nm) / 20.0]
    } else if (510.0..580.0).contains(&nm) {
        [(nm - 510.0) / 70.0, 1.0, 0.0]
    } else if (580.0..645.0).contains(&nm) {
        [1.0, (645.0 - nm) / 65.0, 0.0]
    } else if (645.0..=780.0).contains(&nm) {
        [1.0, 0.0, 0.0]
    } else {
        return [0.8, 0.8, 0.8];
    };
    c.map(|v| 0.2 + 0.8 * v)
}

fn to_rgb8(c: [f64; 3], b: f64) -> [u8; 3] {
    c.map(|v| (v * b * 255.0).round().clamp(0.0, 255.0) as u8)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

fn same_incidence(a: &Incidence, b: &Incidence) -> bool {
    close(a.polar_deg, b.polar_deg) && close(a.azimuth_deg, b.azimuth_deg)
}

fn incidence_cmp(a: &Incidence, b: &Incidence) -> Ordering {
    a.polar_deg
        .total_cmp(&b.polar_deg)
        .then(a.azimuth_deg.total_cmp(&b.azimuth_deg))
}

/// Three significant digits (at least the units).
pub(crate) fn fmt_sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return fmt_num(v);
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// A number with at most two decimals, trailing zeros dropped.
pub(crate) fn fmt_num(x: f64) -> String {
    let s = format!("{x:.2}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

fn row_label(i: &Incidence) -> Vec<String> {
    let polar = format!("θᵢ = {}°", fmt_num(i.polar_deg));
    if i.azimuth_deg == 0.0 {
        vec![polar]
    } else {
        vec![polar, format!("φᵢ = {}°", fmt_num(i.azimuth_deg))]
    }
}

/// Legend paragraphs (wrapped to the picture's width when drawn).
fn legend_text() -> [&'static str; 3] {
    [
        "Rows: angle of incidence θᵢ from above; columns: wavelength λ, tinted by its approximate colour.",
        "Each disk: the directions of reflection seen from above, sx = sin θ cos φ to the right, \
         sy = sin θ sin φ up; rings at θ = 30° and 60°; + the specular direction (order (0,0), not drawn).",
        "Each dot: one diffracted order, its brightness the BRDF R/Ω (sr⁻¹) on the log scale of the bar, \
         shared by all panels; orders below its lowest value are not drawn.",
    ]
}

/// Gaussian dot of peak brightness `b`, combined by per-channel maximum.
fn splat(img: &mut Canvas, x: f64, y: f64, tint: [f64; 3], b: f64) {
    let reach = (3.0 * DOT_SIGMA_PX).ceil() as i64;
    let (xc, yc) = (x.round() as i64, y.round() as i64);
    for py in yc - reach..=yc + reach {
        for px in xc - reach..=xc + reach {
            let Some(i) = img.index(px, py) else {
                continue;
            };
            let (dx, dy) = (px as f64 - x, py as f64 - y);
            let g = (-(dx * dx + dy * dy) / (2.0 * DOT_SIGMA_PX * DOT_SIGMA_PX)).exp();
            let c = to_rgb8(tint, b * g);
            for (p, v) in img.px[i..i + 3].iter_mut().zip(c) {
                *p = (*p).max(v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tint_follows_the_documented_map() {
        let t = |nm: f64| wavelength_tint(nm).map(|v| (v - 0.2) / 0.8);
        assert_eq!(t(440.0), [0.0, 0.0, 1.0]);
        assert_eq!(t(510.0), [0.0, 1.0, 0.0]);
        assert_eq!(t(580.0), [1.0, 1.0, 0.0]);
        assert_eq!(t(700.0), [1.0, 0.0, 0.0]);
        let g = t(465.0);
        assert!((g[1] - 0.5).abs() < 1e-12 && g[2] == 1.0);
        assert_eq!(wavelength_tint(900.0), [0.8, 0.8, 0.8]);
    }

    #[test]
    fn numbers_are_formatted_compactly() {
        assert_eq!(fmt_num(450.0), "450");
        assert_eq!(fmt_num(632.8), "632.8");
        assert_eq!(fmt_num(12.345), "12.35");
        assert_eq!(fmt_num(-0.001), "0");
    }

    #[test]
    fn every_label_character_has_a_glyph() {
        let mut text: String = legend_text().concat();
        text.push_str("BRDF (sr⁻¹) λ = 450 nm θᵢ = 30° φᵢ x (µm) z (down) ×10⁻¹²³⁴⁵⁶⁷⁸⁹⁰");
        for ch in text.chars() {
            assert!(canvas::has_glyph(ch), "missing glyph {ch:?}");
        }
    }

    #[test]
    fn labels_are_compact() {
        assert_eq!(colour_bar::decade_label(-3), "10⁻³");
        assert_eq!(colour_bar::mantissa_label(2.0f64.log10() - 2.0), "2.0×10⁻²");
        assert_eq!(geometry::nice_step(2600.0), 2000.0);
        assert_eq!(geometry::nice_step(0.7), 0.5);
    }
}
