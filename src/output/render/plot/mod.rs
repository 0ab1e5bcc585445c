//! Line plots on the canvas: panels with framed axes, ticks, tick labels and
//! axis titles (units in brackets), series as lines with markers and
//! standard-error bars (a shaded band where points are dense), a legend, and
//! figures that lay several panels out under one title.
//!
//! Drawing is black on white. Series colours are the Okabe–Ito palette
//! (distinguishable with the common colour-vision deficiencies); a series
//! may also be dashed. A point's error bar is ± one standard error; a value
//! outside the axis range is clipped at the frame. [`colour_map`] holds the
//! colour scale of the maps and its bar.

pub mod colour_map;
pub mod scale;

pub use scale::Scale;

use super::canvas::{self, text_width_px, Canvas, GLYPH_HEIGHT, SMALL_HEIGHT, TITLE_HEIGHT};
use super::{RenderError, MAX_PIXELS};

pub const WHITE: [u8; 3] = [255, 255, 255];
pub const INK: [u8; 3] = [25, 25, 25];
const GRID: [u8; 3] = [228, 228, 228];
const MARGIN: usize = 16;
/// Points per series above which error bars become a band.
const BAND_ABOVE: usize = 24;

/// Okabe–Ito colours, in the order series get them.
pub const PALETTE: [[u8; 3]; 8] = [
    [0, 114, 178],
    [213, 94, 0],
    [0, 158, 115],
    [204, 121, 167],
    [230, 159, 0],
    [86, 180, 233],
    [0, 0, 0],
    [170, 150, 20],
];

/// The `k`-th palette colour (cycling).
pub fn palette(k: usize) -> [u8; 3] {
    PALETTE[k % PALETTE.len()]
}

/// One data point: position and the standard error of `y` (if known).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub se: Option<f64>,
}

/// A named line of points.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub colour: [u8; 3],
    pub dashed: bool,
    pub points: Vec<Point>,
}

impl Series {
    /// `(y, se)` of every point, for [`Scale::covering`].
    pub fn values(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.points.iter().map(|p| (p.y, p.se.unwrap_or(0.0)))
    }
}

/// One framed plot.
#[derive(Debug, Clone)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x: Scale,
    pub y: Scale,
    /// Names of the x positions 0, 1, … (a categorical axis) instead of
    /// numeric ticks; drawn reading upwards.
    pub x_categories: Option<Vec<String>>,
    pub series: Vec<Series>,
}

impl Panel {
    /// The legend entries of its series: (label, colour, dashed).
    pub fn legend(&self) -> Vec<(String, [u8; 3], bool)> {
        self.series
            .iter()
            .map(|s| (s.label.clone(), s.colour, s.dashed))
            .collect()
    }
}

/// Size of every panel's frame (the data area), pixels.
#[derive(Debug, Clone, Copy)]
pub struct PanelSize {
    pub w: usize,
    pub h: usize,
}

/// Room around a frame for tick labels and titles.
const LEFT: usize = 2 * GLYPH_HEIGHT + 56;
const TOP: usize = GLYPH_HEIGHT + 10;

/// Height below a panel's frame: tick labels (or upright category names)
/// and the axis title.
fn bottom_room(p: &Panel) -> usize {
    let ticks = match &p.x_categories {
        Some(c) => c
            .iter()
            .map(|s| text_width_px(s, SMALL_HEIGHT as f64).ceil() as usize)
            .max()
            .unwrap_or(0),
        None => SMALL_HEIGHT,
    };
    8 + ticks + 6 + GLYPH_HEIGHT + 8
}

/// A figure: `title`, then `notes` (wrapped), the panels in rows of `cols`,
/// and a legend of `legend` (label, colour, dashed) under them.
pub fn figure(
    title: &str,
    notes: &[String],
    panels: &[Panel],
    cols: usize,
    size: PanelSize,
    legend: &[(String, [u8; 3], bool)],
) -> Result<Canvas, RenderError> {
    if panels.is_empty() {
        return Err(RenderError::Empty);
    }
    let cols = cols.clamp(1, panels.len());
    let rows = panels.len().div_ceil(cols);
    let bottom = panels.iter().map(bottom_room).max().unwrap_or(0);
    let cell_w = LEFT + size.w + MARGIN;
    let cell_h = TOP + size.h + bottom;
    let title_w = text_width_px(title, TITLE_HEIGHT as f64).ceil() as usize;
    let width = (MARGIN + cols * cell_w).max(title_w + 2 * MARGIN);
    let notes: Vec<String> = notes
        .iter()
        .flat_map(|n| canvas::wrap(n, width - 2 * MARGIN))
        .collect();
    let line = GLYPH_HEIGHT + 4;
    let head = MARGIN + TITLE_HEIGHT + 6 + notes.len() * line + 6;
    let legend_rows = legend_layout(legend, width - 2 * MARGIN);
    let height = head + rows * cell_h + legend_rows.len() * line + MARGIN;
    let mut img = titled_page(width, height, title)?;
    for (k, n) in notes.iter().enumerate() {
        img.text(MARGIN, MARGIN + TITLE_HEIGHT + 6 + k * line, n, INK);
    }
    for (k, p) in panels.iter().enumerate() {
        let (r, c) = (k / cols, k % cols);
        let frame = Frame {
            x: MARGIN + c * cell_w + LEFT,
            y: head + r * cell_h + TOP,
            w: size.w,
            h: size.h,
        };
        draw_panel(&mut img, frame, p);
    }
    let y0 = head + rows * cell_h;
    for (k, items) in legend_rows.iter().enumerate() {
        for &(x, i) in items {
            let (label, colour, dashed) = &legend[i];
            let y = (y0 + k * line) as f64;
            let ym = y + GLYPH_HEIGHT as f64 / 2.0;
            let x = (MARGIN + x) as f64;
            stroke(&mut img, None, (x, ym), (x + 26.0, ym), *colour, *dashed);
            marker(&mut img, None, x + 13.0, ym, *colour);
            img.text_px(x + 32.0, y, label, INK, GLYPH_HEIGHT as f64);
        }
    }
    Ok(img)
}

/// A white `width × height` canvas with `title` at its top left, refused
/// when larger than the picture limit.
pub fn titled_page(width: usize, height: usize, title: &str) -> Result<Canvas, RenderError> {
    if width.saturating_mul(height) > MAX_PIXELS {
        return Err(RenderError::TooLarge { width, height });
    }
    let mut img = Canvas::new(width, height, WHITE);
    img.text_px(
        MARGIN as f64,
        MARGIN as f64,
        title,
        INK,
        TITLE_HEIGHT as f64,
    );
    Ok(img)
}

/// Legend entries packed into rows no wider than `max`: per row, the
/// (x offset, entry index) of each item.
fn legend_layout(legend: &[(String, [u8; 3], bool)], max: usize) -> Vec<Vec<(usize, usize)>> {
    let mut rows: Vec<Vec<(usize, usize)>> = vec![];
    let mut x = 0;
    for (i, (label, _, _)) in legend.iter().enumerate() {
        let w = 32 + canvas::text_width(label) + 24;
        if rows.is_empty() || (x + w > max && x > 0) {
            rows.push(vec![]);
            x = 0;
        }
        rows.last_mut().expect("a row").push((x, i));
        x += w;
    }
    rows
}

/// The data area of a panel on the canvas, pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub x: usize,
    pub y: usize,
    pub w: usize,
    pub h: usize,
}

impl Frame {
    /// Pixel position of data `(x, y)` (None where a scale cannot show it).
    pub fn at(&self, p: &Panel, x: f64, y: f64) -> Option<(f64, f64)> {
        Some((
            self.x as f64 + p.x.t(x)? * self.w as f64,
            (self.y + self.h) as f64 - p.y.t(y)? * self.h as f64,
        ))
    }

    fn contains(&self, x: i64, y: i64) -> bool {
        x >= self.x as i64
            && y >= self.y as i64
            && x <= (self.x + self.w) as i64
            && y <= (self.y + self.h) as i64
    }
}

/// Draw panel `p` into `f`: grid, frame, ticks, labels, error bars, lines
/// and markers.
pub fn draw_panel(img: &mut Canvas, f: Frame, p: &Panel) {
    let small = SMALL_HEIGHT as f64;
    let (fx, fy, fw, fh) = (f.x as f64, f.y as f64, f.w as f64, f.h as f64);
    img.text_centered(
        fx + fw / 2.0,
        fy - TOP as f64 + 2.0,
        &p.title,
        INK,
        GLYPH_HEIGHT as f64,
    );
    let x_ticks: Vec<(f64, String)> = match &p.x_categories {
        Some(c) => c
            .iter()
            .enumerate()
            .map(|(i, s)| (i as f64, s.clone()))
            .collect(),
        None => p.x.ticks(),
    };
    for (v, label) in &x_ticks {
        let Some(t) = p.x.t(*v) else { continue };
        let x = fx + t * fw;
        img.line((x, fy), (x, fy + fh), GRID);
        img.line((x, fy + fh), (x, fy + fh + 5.0), INK);
        if p.x_categories.is_some() {
            let tw = text_width_px(label, small);
            img.text_up(x - small / 2.0, fy + fh + 8.0 + tw, label, INK, small);
        } else {
            img.text_centered(x, fy + fh + 7.0, label, INK, small);
        }
    }
    let mut max_label = 0.0f64;
    for (v, label) in p.y.ticks() {
        let Some(t) = p.y.t(v) else { continue };
        let y = fy + fh - t * fh;
        img.line((fx, y), (fx + fw, y), GRID);
        img.line((fx - 5.0, y), (fx, y), INK);
        let tw = text_width_px(&label, small);
        max_label = max_label.max(tw);
        img.text_px(fx - 8.0 - tw, y - small / 2.0, &label, INK, small);
    }
    for (a, b) in [
        ((fx, fy), (fx + fw, fy)),
        ((fx, fy + fh), (fx + fw, fy + fh)),
        ((fx, fy), (fx, fy + fh)),
        ((fx + fw, fy), (fx + fw, fy + fh)),
    ] {
        img.line(a, b, INK);
    }
    let x_title_y = fy + fh + bottom_room(p) as f64 - GLYPH_HEIGHT as f64 - 8.0;
    img.text_centered(
        fx + fw / 2.0,
        x_title_y,
        &p.x_label,
        INK,
        GLYPH_HEIGHT as f64,
    );
    let tw = text_width_px(&p.y_label, GLYPH_HEIGHT as f64);
    img.text_up(
        fx - 14.0 - max_label - GLYPH_HEIGHT as f64,
        fy + fh / 2.0 + tw / 2.0,
        &p.y_label,
        INK,
        GLYPH_HEIGHT as f64,
    );
    // Uncertainty under every line, lines under every marker.
    for s in &p.series {
        draw_errors(img, f, p, s);
    }
    for s in &p.series {
        draw_line(img, f, p, s);
    }
}

/// Error bars of a series, or its band where the points are dense.
fn draw_errors(img: &mut Canvas, f: Frame, p: &Panel, s: &Series) {
    let band = s.points.len() > BAND_ABOVE;
    let light = s.colour.map(|v| (v as f64 * 0.3 + 255.0 * 0.7) as u8);
    let mut prev_band: Option<(f64, f64, f64)> = None;
    for pt in &s.points {
        let Some(se) = pt.se.filter(|e| e.is_finite() && *e > 0.0) else {
            prev_band = None;
            continue;
        };
        let (Some((x, lo)), Some((_, hi))) = (
            f.at(
                p,
                pt.x,
                (pt.y - se).max(if p.y.log { p.y.lo } else { f64::MIN }),
            ),
            f.at(p, pt.x, pt.y + se),
        ) else {
            continue;
        };
        if band {
            if let Some((x0, lo0, hi0)) = prev_band {
                // Fill the trapezoid between the two columns.
                let n = (x - x0).abs().ceil().max(1.0) as usize;
                for k in 0..=n {
                    let t = k as f64 / n as f64;
                    let xx = x0 + t * (x - x0);
                    let (a, b) = (lo0 + t * (lo - lo0), hi0 + t * (hi - hi0));
                    for y in b.round() as i64..=a.round() as i64 {
                        if f.contains(xx.round() as i64, y) {
                            img.set(xx.round() as i64, y, light);
                        }
                    }
                }
            }
            prev_band = Some((x, lo, hi));
        } else {
            stroke(img, Some(f), (x, lo), (x, hi), s.colour, false);
            stroke(img, Some(f), (x - 4.0, lo), (x + 4.0, lo), s.colour, false);
            stroke(img, Some(f), (x - 4.0, hi), (x + 4.0, hi), s.colour, false);
        }
    }
}

/// The line through a series' points and, unless dense, its markers.
fn draw_line(img: &mut Canvas, f: Frame, p: &Panel, s: &Series) {
    let band = s.points.len() > BAND_ABOVE;
    let mut prev: Option<(f64, f64)> = None;
    for pt in &s.points {
        let q = f.at(p, pt.x, pt.y);
        if let (Some(a), Some(b)) = (prev, q) {
            stroke(img, Some(f), a, b, s.colour, s.dashed);
        }
        prev = q;
    }
    if !band {
        for pt in &s.points {
            if let Some((x, y)) = f.at(p, pt.x, pt.y) {
                marker(img, Some(f), x, y, s.colour);
            }
        }
    }
}

/// A two-pixel line, dashed (8 on, 5 off) when asked, clipped to `clip`.
fn stroke(
    img: &mut Canvas,
    clip: Option<Frame>,
    a: (f64, f64),
    b: (f64, f64),
    c: [u8; 3],
    dashed: bool,
) {
    let len = (b.0 - a.0).hypot(b.1 - a.1);
    let n = len.ceil().max(1.0) as usize;
    for k in 0..=n {
        if dashed && (k % 13) >= 8 {
            continue;
        }
        let t = k as f64 / n as f64;
        let (x, y) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        for (dx, dy) in [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5)] {
            let (px, py) = ((x + dx).round() as i64, (y + dy).round() as i64);
            if clip.is_none_or(|f| f.contains(px, py)) {
                img.set(px, py, c);
            }
        }
    }
}

/// A filled disk of radius 3 with a white rim, clipped to `clip`.
fn marker(img: &mut Canvas, clip: Option<Frame>, x: f64, y: f64, c: [u8; 3]) {
    if clip.is_some_and(|f| !f.contains(x.round() as i64, y.round() as i64)) {
        return;
    }
    img.disk(x, y, 4.0, WHITE);
    img.disk(x, y, 3.0, c);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panel(categories: Option<Vec<String>>) -> Panel {
        let s = Series {
            label: "a".into(),
            colour: palette(0),
            dashed: false,
            points: vec![
                Point {
                    x: 0.0,
                    y: 1.0,
                    se: Some(0.5),
                },
                Point {
                    x: 1.0,
                    y: 3.0,
                    se: None,
                },
            ],
        };
        Panel {
            title: "t".into(),
            x_label: "x (nm)".into(),
            y_label: "y".into(),
            x: Scale::categories(2),
            y: Scale::covering(s.values(), true).unwrap(),
            x_categories: categories,
            series: vec![s],
        }
    }

    #[test]
    fn figure_draws_frames_points_and_legend() {
        let size = PanelSize { w: 200, h: 120 };
        let legend = [("a".to_string(), palette(0), false)];
        let p = panel(Some(vec!["one".into(), "two".into()]));
        let img = figure(
            "title",
            &["note".into()],
            &[p.clone(), p.clone()],
            2,
            size,
            &legend,
        )
        .unwrap();
        assert!(img.w >= 2 * 200 && img.h >= 120);
        // The second point's marker is drawn in the series colour where the
        // frame maps it.
        let frame = Frame {
            x: MARGIN + LEFT,
            y: MARGIN + TITLE_HEIGHT + 6 + (GLYPH_HEIGHT + 4) + 6 + TOP,
            w: 200,
            h: 120,
        };
        let (x, y) = frame.at(&p, 1.0, 3.0).unwrap();
        assert_eq!(
            img.get(x.round() as i64, y.round() as i64),
            Some(palette(0))
        );
        assert!(figure("t", &[], &[], 1, size, &legend).is_err());
    }

    #[test]
    fn legend_wraps_to_the_width() {
        let items: Vec<_> = (0..6)
            .map(|k| (format!("series number {k}"), palette(k), false))
            .collect();
        let rows = legend_layout(&items, 400);
        assert!(rows.len() >= 2);
        assert_eq!(rows.iter().map(Vec::len).sum::<usize>(), 6);
    }
}
