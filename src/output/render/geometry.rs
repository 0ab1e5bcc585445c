//! The geometry picture: the layer on its raster, top view and cross-section.

use super::canvas::{self, text_width, Canvas, GLYPH_HEIGHT, SMALL_HEIGHT, TITLE_HEIGHT};
use super::plot::colour_map::{colour_bar, BAR_LABELS_W, BAR_W};
use super::plot::Scale;
use super::{fmt_num, RenderError, MAX_PIXELS};

/// A picture of a layer so a person can see it: the top view (pigment
/// fraction averaged over the thickness) and the x–z cross-section through
/// the middle of the fragment (pigment fraction; z down), both on the raster,
/// with axes in nm or µm, a scale bar, the section's line marked on the top
/// view, a grey-scale bar of the pigment volume fraction (0 binder, 1
/// pigment) and `lines` of statistics underneath.
pub fn geometry_png(
    raster: &crate::raster::Raster,
    title: &str,
    lines: &[String],
) -> Result<Vec<u8>, RenderError> {
    let g = raster.grid;
    let (nx, ny, nz) = (g.nx, g.ny, g.nz);
    let [dx, dy, dz] = g.cell_nm();
    let total = |iz: usize, iy: usize, ix: usize| -> f64 {
        raster
            .fractions
            .iter()
            .map(|f| f[[iz, iy, ix]])
            .sum::<f64>()
            .min(1.0)
    };
    let scale = (320 / nx.max(ny)).max(1);
    let yscale = ((scale as f64 * dy / dx).round() as usize).max(1);
    let zscale = ((scale as f64 * dz / dx).round() as usize).max(1);
    let margin = 20;
    let line = GLYPH_HEIGHT + 6;
    let axis_h = 6 + SMALL_HEIGHT + 4 + GLYPH_HEIGHT + 6;
    let y_axis_w = 2 * SMALL_HEIGHT + 48;
    let top_w = nx * scale;
    let cross_w = nx * scale;
    let (top_h, cross_h) = (ny * yscale, nz * zscale);
    let body_h = top_h.max(cross_h);
    let iy = ny / 2;
    let y_section = (iy as f64 + 0.5) * dy;
    let (unit, div) = length_unit(g.size_nm[0].max(g.size_nm[1]).max(g.size_nm[2]));
    let heading_top = "top view (pigment fraction through the thickness)".to_string();
    let heading_cross = format!(
        "x–z section at y = {} {unit} (dashed on the top view)",
        fmt_num(y_section / div)
    );
    let heading = format!(
        "{title} — the layer on the raster: {nx} × {ny} × {nz} cells of {} × {} × {} nm",
        fmt_num(dx),
        fmt_num(dy),
        fmt_num(dz)
    );
    let x0 = margin + y_axis_w;
    let x1 = x0 + top_w.max(text_width(&heading_top)) + margin + y_axis_w;
    let bar_x = x1 + cross_w.max(text_width(&heading_cross)) + margin;
    let w = (bar_x + BAR_W + BAR_LABELS_W + margin)
        .max(margin * 2 + lines.iter().map(|l| text_width(l)).max().unwrap_or(0))
        .max(margin * 2 + canvas::text_width_px(&heading, TITLE_HEIGHT as f64).ceil() as usize);
    let y_head = margin + TITLE_HEIGHT + 8;
    let y_body = y_head + line;
    let y_text = y_body + body_h + axis_h + line + 8;
    let h = y_text + line * lines.len() + margin;
    if w.saturating_mul(h) > MAX_PIXELS {
        return Err(RenderError::TooLarge {
            width: w,
            height: h,
        });
    }
    let mut img = Canvas::new(w, h, [24, 24, 28]);
    let grey = |f: f64| {
        let v = (40.0 + 215.0 * f.clamp(0.0, 1.0)).round() as u8;
        [v, v, (v as f64 * 0.9) as u8]
    };
    let fg = [230, 230, 230];
    let dim = [200, 200, 200];
    img.text_px(
        margin as f64,
        margin as f64,
        &heading,
        fg,
        TITLE_HEIGHT as f64,
    );
    img.text(x0, y_head, &heading_top, dim);
    for iy in 0..ny {
        for ix in 0..nx {
            let f = (0..nz).map(|iz| total(iz, iy, ix)).sum::<f64>() / nz as f64;
            // y up in the picture.
            img.rect(
                (x0 + ix * scale) as i64,
                (y_body + (ny - 1 - iy) * yscale) as i64,
                scale,
                yscale,
                grey(f),
            );
        }
    }
    // The section's line on the top view, dashed.
    let ys = y_body as f64 + (ny as f64 - iy as f64 - 0.5) * yscale as f64;
    for x in (x0..x0 + top_w).filter(|x| (x - x0) % 8 < 5) {
        img.set(x as i64, ys.round() as i64, [230, 120, 60]);
    }
    img.text(x1, y_head, &heading_cross, dim);
    for iz in 0..nz {
        for ix in 0..nx {
            img.rect(
                (x1 + ix * scale) as i64,
                (y_body + iz * zscale) as i64,
                scale,
                zscale,
                grey(total(iz, iy, ix)),
            );
        }
    }
    let px_per_nm = scale as f64 / dx;
    let axes = [
        // (origin x, origin y, along x?, length nm, px per nm, label, upwards)
        (x0, y_body + top_h, g.size_nm[0], px_per_nm, "x", false),
        (
            x0,
            y_body + top_h,
            g.size_nm[1],
            yscale as f64 / dy,
            "y",
            true,
        ),
        (x1, y_body + cross_h, g.size_nm[0], px_per_nm, "x", false),
        (
            x1,
            y_body,
            g.size_nm[2],
            zscale as f64 / dz,
            "depth z",
            false,
        ),
    ];
    for (k, &(ox, oy, len, ppn, name, up)) in axes.iter().enumerate() {
        let vertical = k % 2 == 1;
        axis(
            &mut img,
            (ox, oy),
            vertical,
            up,
            (len, ppn),
            (unit, div),
            name,
        );
    }
    // Scale bar under the section's x axis.
    let bar_nm = nice_step(g.size_nm[0] / 4.0);
    let bar_px = (bar_nm * px_per_nm).round() as usize;
    let by = y_body + cross_h + axis_h + 8;
    img.rect(x1 as i64, by as i64, bar_px, 4, fg);
    img.text(
        x1 + bar_px + 8,
        by + 2 - GLYPH_HEIGHT / 2,
        &format!("{} {unit}", fmt_num(bar_nm / div)),
        fg,
    );
    // The grey ramp of both views.
    let bar_top = y_body + GLYPH_HEIGHT + 10;
    colour_bar(
        &mut img,
        (
            bar_x,
            bar_top,
            (body_h + axis_h).saturating_sub(GLYPH_HEIGHT + 10).max(60),
        ),
        &Scale::linear(0.0, 1.0),
        grey,
        "pigment fraction",
        fg,
    );
    for (k, l) in lines.iter().enumerate() {
        img.text(margin, y_text + k * line, l, [210, 210, 210]);
    }
    img.encode_png(title)
}

/// Unit for lengths up to `max_nm`: (name, nm per unit).
fn length_unit(max_nm: f64) -> (&'static str, f64) {
    if max_nm >= 2000.0 {
        ("µm", 1000.0)
    } else {
        ("nm", 1.0)
    }
}

/// The largest of 1, 2, 5 × 10ⁿ not above `x` (x > 0).
pub(super) fn nice_step(x: f64) -> f64 {
    let d = 10f64.powf(x.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * d)
        .find(|&s| s <= x)
        .unwrap_or(d)
}

/// Ticks and a title along one edge of a view. Horizontal axes run right
/// from `origin` below the view; vertical ones run along its left edge, up
/// from `origin` when `up` (y) or down (z).
fn axis(
    img: &mut Canvas,
    origin: (usize, usize),
    vertical: bool,
    up: bool,
    (len_nm, px_per_nm): (f64, f64),
    (unit, div): (&str, f64),
    name: &str,
) {
    let fg = [200, 200, 200];
    let small = SMALL_HEIGHT as f64;
    let step = nice_step(len_nm / 3.0);
    let (ox, oy) = (origin.0 as f64, origin.1 as f64);
    let n = (len_nm / step).floor() as usize;
    let length_px = len_nm * px_per_nm;
    if vertical {
        img.line(
            (ox - 2.0, oy),
            (ox - 2.0, oy + if up { -length_px } else { length_px }),
            fg,
        );
    } else {
        img.line((ox, oy + 2.0), (ox + length_px, oy + 2.0), fg);
    }
    let mut max_label = 0.0f64;
    for k in 0..=n {
        let v = k as f64 * step;
        let p = v * px_per_nm;
        let label = fmt_num(v / div);
        if vertical {
            let y = if up { oy - p } else { oy + p };
            img.line((ox - 6.0, y), (ox - 2.0, y), fg);
            let tw = canvas::text_width_px(&label, small);
            max_label = max_label.max(tw);
            img.text_px(ox - 9.0 - tw, y - small / 2.0, &label, fg, small);
        } else {
            img.line((ox + p, oy + 2.0), (ox + p, oy + 6.0), fg);
            img.text_centered(ox + p, oy + 7.0, &label, fg, small);
        }
    }
    let title = format!("{name} ({unit})");
    if vertical {
        let mid = oy
            + if up {
                -length_px / 2.0
            } else {
                length_px / 2.0
            };
        let tw = canvas::text_width_px(&title, GLYPH_HEIGHT as f64);
        img.text_up(
            ox - 14.0 - max_label - GLYPH_HEIGHT as f64,
            mid + tw / 2.0,
            &title,
            fg,
            GLYPH_HEIGHT as f64,
        );
    } else {
        img.text_centered(
            ox + length_px / 2.0,
            oy + 8.0 + small,
            &title,
            fg,
            GLYPH_HEIGHT as f64,
        );
    }
}
