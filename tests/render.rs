//! The pictures: the diffuse-BRDF picture decodes, has the documented
//! layout, shows the orders where their directions say and a colour bar over
//! the data's range; the tile is large, labelled and marks colours mapped
//! into the sRGB gamut; the geometry picture is labelled; and the gamut
//! mapping keeps lightness and hue.

use inksim::config::Incidence;
use inksim::config::Method;
use inksim::optics::colour::gamut::{self, in_gamut, lab_to_linear_srgb};
use inksim::optics::colour::{self, lab_to_lch, xyz_to_lab, Observer};
use inksim::optics::farfield::{Efficiencies, Order, Side, SolveEntry};
use inksim::output::render::canvas::{self, Canvas};
use inksim::output::render::tile::{self, TileCaption, TileLayout, MARK_PX, PATCH_PX};
use inksim::output::render::{
    brdf_range, diffuse_brdf_png, geometry_png, order_cell, PanelLayout, RenderError,
    DISK_RADIUS_PX, DOT_SIGMA_PX,
};
use inksim::raster::{Grid, Raster};
use inksim::solver::SolveRecord;
use ndarray::{Array3, Axis};
use num_complex::Complex64;

const PERIOD_NM: f64 = 2000.0;

/// Propagating reflected orders of a square lattice (period PERIOD_NM) for
/// incidence in the x–z plane; every diffuse order gets `r_diffuse`, the
/// specular one 0.04; `bright` = ((m, n), R) overrides one order.
fn lattice_entry(
    wl: f64,
    polar: f64,
    r_diffuse: f64,
    bright: Option<((i32, i32), f64)>,
) -> SolveEntry {
    let s_inc = polar.to_radians().sin();
    let step = wl / PERIOD_NM;
    let mut orders = Vec::new();
    for m in -20..=20 {
        for n in -20..=20 {
            let (sx, sy) = (s_inc + m as f64 * step, n as f64 * step);
            let s = (sx * sx + sy * sy).sqrt();
            if s >= 1.0 {
                continue;
            }
            let mut r = if (m, n) == (0, 0) { 0.04 } else { r_diffuse };
            if let Some((mn, rb)) = bright {
                if mn == (m, n) {
                    r = rb;
                }
            }
            orders.push(Order {
                m,
                n,
                theta_deg: s.asin().to_degrees(),
                phi_deg: sy.atan2(sx).to_degrees(),
                reflectance: r,
                transmittance: 0.0,
            });
        }
    }
    entry(wl, polar, orders)
}

fn entry(wl: f64, polar: f64, orders: Vec<Order>) -> SolveEntry {
    SolveEntry {
        wavelength_nm: wl,
        side: Side::Above,
        realisation: 0,
        layer: 0,
        incidence: Incidence {
            polar_deg: polar,
            azimuth_deg: 0.0,
        },
        efficiencies: Efficiencies {
            orders,
            r00: Complex64::new(0.2, 0.0),
            t00: Complex64::new(0.9, 0.0),
            specular_p: None,
            total_reflectance: 0.05,
            total_transmittance: 0.9,
            absorption: 0.05,
            energy_balance: 0.0,
        },
        record: SolveRecord {
            method: Method::Born,
            background: inksim::config::Background::Binder,
            iterations: 3,
            operator_applications: 4,
            residual: 1e-8,
            seconds: 0.0,
            note: String::new(),
        },
        polarised: Vec::new(),
        random_phase_deg: None,
    }
}

struct Image {
    w: usize,
    h: usize,
    px: Vec<u8>,
}

impl Image {
    fn rgb(&self, x: usize, y: usize) -> [u8; 3] {
        let i = (y * self.w + x) * 3;
        [self.px[i], self.px[i + 1], self.px[i + 2]]
    }
    fn lum(&self, x: usize, y: usize) -> u32 {
        self.rgb(x, y).iter().map(|&v| v as u32).sum()
    }
}

fn decode(png_bytes: &[u8]) -> Image {
    let dec = png::Decoder::new(std::io::Cursor::new(png_bytes));
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    buf.truncate(info.buffer_size());
    Image {
        w: info.width as usize,
        h: info.height as usize,
        px: buf,
    }
}

fn direction(o: &Order) -> (f64, f64) {
    let (t, p) = (o.theta_deg.to_radians(), o.phi_deg.to_radians());
    (t.sin() * p.cos(), t.sin() * p.sin())
}

#[test]
fn picture_decodes_with_one_panel_per_wavelength_and_angle() {
    let mut entries = Vec::new();
    for polar in [60.0, 0.0, 30.0] {
        for wl in [650.0, 450.0] {
            entries.push(lattice_entry(wl, polar, 1e-3, None));
        }
    }
    let png_bytes = diffuse_brdf_png(&entries, "Test: 2 x 3").unwrap();
    let img = decode(&png_bytes);
    let layout = PanelLayout::new(&entries, "Test: 2 x 3").unwrap();
    assert_eq!((img.w, img.h), (layout.width, layout.height));
    assert_eq!(layout.wavelengths_nm, vec![450.0, 650.0]);
    let polars: Vec<f64> = layout.incidences.iter().map(|i| i.polar_deg).collect();
    assert_eq!(polars, vec![0.0, 30.0, 60.0]);

    // Each further column widens the picture by one whole panel (once the
    // grid is wider than the legend).
    let widths: Vec<usize> = [8, 9, 10]
        .iter()
        .map(|&cols| {
            let many: Vec<SolveEntry> = (0..cols)
                .map(|k| lattice_entry(400.0 + 20.0 * k as f64, 0.0, 1e-3, None))
                .collect();
            let l = PanelLayout::new(&many, "").unwrap();
            assert_eq!(l.wavelengths_nm.len(), cols);
            l.width
        })
        .collect();
    let step = widths[1] - widths[0];
    assert_eq!(widths[2] - widths[1], step, "{widths:?}");
    assert!(step as f64 > 2.0 * DISK_RADIUS_PX, "{widths:?}");

    // Column tint: the 650 nm column's dots are red, the 450 nm column's blue.
    for (col, red_wins) in [(0, false), (1, true)] {
        let (cx, cy) = layout.center(0, col);
        let (mut r, mut b) = (0u64, 0u64);
        let rad = DISK_RADIUS_PX as i64 - 2;
        for dy in -rad..=rad {
            for dx in -rad..=rad {
                let p = img.rgb((cx as i64 + dx) as usize, (cy as i64 + dy) as usize);
                r += p[0] as u64;
                b += p[2] as u64;
            }
        }
        assert_eq!(r > b, red_wins, "column {col}: red {r} blue {b}");
    }
}

#[test]
fn bright_order_is_brightest_at_its_own_position() {
    let bright = (1, 2);
    let entries = vec![
        lattice_entry(500.0, 0.0, 1e-4, None),
        lattice_entry(600.0, 20.0, 1e-4, Some((bright, 0.05))),
        lattice_entry(600.0, 0.0, 1e-4, None),
    ];
    let img = decode(&diffuse_brdf_png(&entries, "bright").unwrap());
    let layout = PanelLayout::new(&entries, "bright").unwrap();
    let e = &entries[1];
    let (row, col) = layout.panel_of(e).unwrap();
    assert_eq!((row, col), (1, 1));
    let o = e
        .efficiencies
        .orders
        .iter()
        .find(|o| (o.m, o.n) == bright)
        .unwrap();
    let (sx, sy) = direction(o);
    assert!(sx > 0.5 && sy > 0.4);
    let (bx, by) = layout.direction_px(row, col, sx, sy);
    let (bx, by) = (bx.round() as i64, by.round() as i64);
    let spec = e
        .efficiencies
        .orders
        .iter()
        .find(|o| (o.m, o.n) == (0, 0))
        .unwrap();
    let (spx, spy) = direction(spec);
    let (spx, spy) = layout.direction_px(row, col, spx, spy);
    let peak = img.lum(bx as usize, by as usize);

    let (cx, cy) = layout.center(row, col);
    // Right of and above the panel centre, as sx > 0, sy > 0 say.
    assert!(bx as f64 > cx && (by as f64) < cy);
    let r = DISK_RADIUS_PX as i64;
    let mut others = 0;
    for dy in -r..=r {
        for dx in -r..=r {
            let (x, y) = (cx as i64 + dx, cy as i64 + dy);
            let near_bright = (x - bx).abs() <= 2 && (y - by).abs() <= 2;
            let near_cross = (x as f64 - spx).abs() <= 5.0 && (y as f64 - spy).abs() <= 5.0;
            if near_bright || near_cross {
                continue;
            }
            let l = img.lum(x as usize, y as usize);
            assert!(l < peak, "pixel ({x},{y}) lum {l} >= peak {peak}");
            others += 1;
        }
    }
    assert!(others > 10_000);

    // The same panel drawn without the bright order differs most at its position.
    let plain = vec![
        entries[0].clone(),
        lattice_entry(600.0, 20.0, 1e-4, None),
        entries[2].clone(),
    ];
    let img0 = decode(&diffuse_brdf_png(&plain, "bright").unwrap());
    assert_eq!((img0.w, img0.h), (img.w, img.h));
    // (Searched over all disks; the legend's numbers change too.)
    let mut best = (0i64, 0usize, 0usize);
    for row in 0..2 {
        for col in 0..2 {
            let (cx, cy) = layout.center(row, col);
            for dy in -r..=r {
                for dx in -r..=r {
                    let (x, y) = ((cx as i64 + dx) as usize, (cy as i64 + dy) as usize);
                    let d = img.lum(x, y) as i64 - img0.lum(x, y) as i64;
                    if d > best.0 {
                        best = (d, x, y);
                    }
                }
            }
        }
    }
    assert!(
        (best.1 as i64 - bx).abs() <= 1 && (best.2 as i64 - by).abs() <= 1,
        "largest change at ({}, {}), order at ({bx}, {by})",
        best.1,
        best.2
    );
}

#[test]
fn brightness_increases_with_reflectance() {
    let mut e = lattice_entry(550.0, 0.0, 0.0, None);
    let mut picked = Vec::new();
    for (mn, r) in [((2, 0), 1e-2), ((-2, 0), 1e-3), ((0, 2), 1e-4)] {
        let o = e
            .efficiencies
            .orders
            .iter_mut()
            .find(|o| (o.m, o.n) == mn)
            .unwrap();
        o.reflectance = r;
        picked.push(*o);
    }
    let entries = vec![e];
    let img = decode(&diffuse_brdf_png(&entries, "").unwrap());
    let layout = PanelLayout::new(&entries, "").unwrap();
    let lum: Vec<u32> = picked
        .iter()
        .map(|o| {
            let (sx, sy) = direction(o);
            let (x, y) = layout.direction_px(0, 0, sx, sy);
            img.lum(x.round() as usize, y.round() as usize)
        })
        .collect();
    assert!(lum[0] > lum[1] && lum[1] > lum[2] && lum[2] > 0, "{lum:?}");
    // Log scale: equal ratios give (nearly) equal brightness steps.
    let (d1, d2) = (lum[0] as i64 - lum[1] as i64, lum[1] as i64 - lum[2] as i64);
    assert!((d1 - d2).abs() <= 6, "{lum:?}");
}

#[test]
fn cell_of_a_lattice_is_the_product_of_its_spacings() {
    let e = lattice_entry(500.0, 30.0, 1e-3, None);
    let want = (500.0 / PERIOD_NM) * (500.0 / PERIOD_NM);
    assert!((order_cell(&e.efficiencies.orders) - want).abs() < 1e-12 * want);
    // Only one order: falls back to the unit disk shared by the orders.
    let one = &e.efficiencies.orders[..1];
    assert!((order_cell(one) - std::f64::consts::PI).abs() < 1e-15);
}

#[test]
fn empty_input_is_an_error() {
    assert!(matches!(
        diffuse_brdf_png(&[], "t"),
        Err(RenderError::Empty)
    ));
}

#[test]
fn non_finite_values_are_errors_not_panics() {
    let mut e = lattice_entry(500.0, 0.0, 1e-3, None);
    e.efficiencies.orders[3].reflectance = f64::NAN;
    let err = diffuse_brdf_png(&[e], "t").unwrap_err();
    assert!(err.to_string().contains("reflectance"), "{err}");
    let mut e = lattice_entry(500.0, 0.0, 1e-3, None);
    e.wavelength_nm = f64::INFINITY;
    assert!(diffuse_brdf_png(&[e], "t").is_err());
}

#[test]
fn entries_without_diffuse_orders_draw_empty_panels() {
    let specular_only = entry(
        500.0,
        0.0,
        vec![Order {
            m: 0,
            n: 0,
            theta_deg: 0.0,
            phi_deg: 0.0,
            reflectance: 0.04,
            transmittance: 0.96,
        }],
    );
    let no_orders = entry(700.0, 45.0, vec![]);
    let entries = vec![specular_only, no_orders];
    let img = decode(&diffuse_brdf_png(&entries, "nothing diffuse ±").unwrap());
    let layout = PanelLayout::new(&entries, "nothing diffuse ±").unwrap();
    assert_eq!((img.w, img.h), (layout.width, layout.height));
    // No tinted pixel inside any disk: only greys (background, guides, cross).
    for row in 0..2 {
        for col in 0..2 {
            let (cx, cy) = layout.center(row, col);
            let r = DISK_RADIUS_PX as i64;
            for dy in -r..=r {
                for dx in -r..=r {
                    let p = img.rgb((cx as i64 + dx) as usize, (cy as i64 + dy) as usize);
                    assert!(p[0] == p[1] && p[1] == p[2], "tinted pixel {p:?}");
                }
            }
        }
    }
}

/// Pixels of `img` in the rectangle (x, y, w, h) that differ from `bg`.
fn inked(img: &Image, (x, y, w, h): (usize, usize, usize, usize), bg: [u8; 3]) -> usize {
    let mut n = 0;
    for yy in y..(y + h).min(img.h) {
        for xx in x..(x + w).min(img.w) {
            if img.rgb(xx, yy) != bg {
                n += 1;
            }
        }
    }
    n
}

const BG: [u8; 3] = [40, 40, 40];

#[test]
fn colour_bar_spans_the_data_range_and_is_labelled() {
    let mut e = lattice_entry(550.0, 0.0, 1e-4, None);
    for o in e.efficiencies.orders.iter_mut() {
        if (o.m, o.n) == (1, 1) {
            o.reflectance = 3e-2;
        }
    }
    let entries = vec![e, lattice_entry(450.0, 30.0, 2e-4, None)];
    let (lo, hi) = brdf_range(&entries).unwrap();
    let cell = order_cell(&entries[0].efficiencies.orders);
    assert!((hi - (3e-2 / cell).log10()).abs() < 1e-12);
    assert!((lo - (1e-4 / cell).log10()).abs() < 1e-12);
    let img = decode(&diffuse_brdf_png(&entries, "bar").unwrap());
    let layout = PanelLayout::new(&entries, "bar").unwrap();
    let (bx, by, bw, bh) = layout.bar;
    assert!(bh >= 100 && bw >= 8, "{:?}", layout.bar);
    // Top row: the brightest value (full white); bottom row: the dimmest (20 %).
    let mid = bx + bw / 2;
    assert_eq!(img.rgb(mid, by), [255, 255, 255]);
    assert_eq!(img.rgb(mid, by + bh - 1), [51, 51, 51]);
    // Monotone from bottom to top.
    for y in by + 1..by + bh {
        assert!(img.lum(mid, y) <= img.lum(mid, y - 1));
    }
    // The brightest order's dot centre shows the bar's top colour in its tint,
    // and the dimmest the bottom's: the bar spans exactly what is drawn.
    let o = entries[0]
        .efficiencies
        .orders
        .iter()
        .find(|o| (o.m, o.n) == (1, 1))
        .unwrap();
    let (sx, sy) = direction(o);
    let (x, y) = layout.direction_px(0, 1, sx, sy);
    // Green is full in the 550 nm tint; the dot's Gaussian falls off by the
    // pixel centre's distance from the order's exact position.
    let (px, py) = (x.round(), y.round());
    let g = (-((px - x).powi(2) + (py - y).powi(2)) / (2.0 * DOT_SIGMA_PX * DOT_SIGMA_PX)).exp();
    let peak = img.rgb(px as usize, py as usize);
    assert!((peak[1] as f64 - 255.0 * g).abs() <= 1.0, "{peak:?} vs {g}");
    // Tick labels right of the bar, the unit above it.
    assert!(inked(&img, (bx + bw + 6, by, 50, bh), BG) > 100);
    assert!(inked(&img, (bx, by - 20, 60, 18), BG) > 60);
    // The legend underneath is drawn and the canvas is not much wider than
    // the panels and the bar.
    assert!(inked(&img, (10, layout.legend_top, layout.width - 20, 40), BG) > 500);
    assert!(
        layout.width - (bx + bw) < 100,
        "width {} bar {:?}",
        layout.width,
        layout.bar
    );
}

#[test]
fn panel_labels_are_drawn() {
    let entries = vec![lattice_entry(500.0, 20.0, 1e-3, None)];
    let img = decode(&diffuse_brdf_png(&entries, "labels").unwrap());
    let layout = PanelLayout::new(&entries, "labels").unwrap();
    let (cx, cy) = layout.center(0, 0);
    let r = DISK_RADIUS_PX as usize;
    // Left of the disk: the row's θᵢ; above it: the column's λ; the title.
    assert!(inked(&img, (0, cy as usize - 10, cx as usize - r - 4, 20), BG) > 40);
    assert!(inked(&img, (cx as usize - r, cy as usize - r - 30, 2 * r, 20), BG) > 40);
    assert!(inked(&img, (0, 0, layout.width, 30), BG) > 40);
}

fn caption(obs: &Observer) -> TileCaption<'_> {
    TileCaption {
        name: "magenta",
        observer: obs,
        ground: "on paper of albedo 0.8",
        hiding: None,
        azimuth_deg: 0.0,
    }
}

/// A 3 × (1 + 4) tile: in-gamut greyish colours, one out-of-gamut cyan.
fn tile_input(obs: &Observer) -> (Array3<u8>, Array3<f64>) {
    let (nv, nc) = (3, 5);
    let mut lab = Array3::zeros((nv, nc, 3));
    let mut rgb = Array3::zeros((nv, nc, 3));
    for v in 0..nv {
        for c in 0..nc {
            let l = [
                30.0 + 15.0 * v as f64,
                5.0 * c as f64 - 10.0,
                10.0 - 3.0 * c as f64,
            ];
            let s = colour::encode_srgb8(lab_to_linear_srgb(obs, l));
            for k in 0..3 {
                lab[[v, c, k]] = l[k];
                rgb[[v, c, k]] = s[k];
            }
        }
    }
    // Cell (1, 2): a cyan beyond sRGB, stored clipped as today.
    let cyan = [60.0, -90.0, -40.0];
    let clipped = colour::encode_srgb8(lab_to_linear_srgb(obs, cyan));
    for k in 0..3 {
        lab[[1, 2, k]] = cyan[k];
        rgb[[1, 2, k]] = clipped[k];
    }
    (rgb, lab)
}

#[test]
fn tile_is_large_labelled_and_marks_mapped_colours() {
    let obs = Observer::cie1931_d65();
    let cap = caption(&obs);
    assert!(
        tile::glyphs_missing(&cap).is_empty(),
        "{:?}",
        tile::glyphs_missing(&cap)
    );
    assert_eq!(cap.conditions(), "D65, 2°");
    assert!(cap.lines()[0].contains("magenta") && cap.lines()[0].contains("0.8"));
    let (rgb, lab) = tile_input(&obs);
    let viewing = [0.0, 30.0, 60.0];
    let illum = [0.0, 15.0, 45.0, 60.0];
    let img = decode(&tile::tile_png(&rgb, &lab, &viewing, &illum, &cap).unwrap());
    let l = TileLayout::new(3, 4, &viewing, &cap);
    assert_eq!((img.w, img.h), (l.width, l.height));
    assert!(l.columns_x[2] - l.columns_x[1] >= 64 && l.rows_y[1] - l.rows_y[0] >= 64);
    assert!(img.w >= 5 * PATCH_PX && img.h >= 3 * PATCH_PX);
    // Headings: every column's θᵢ and every row's θₒ put ink in its place.
    let (hx, hy, _, hh) = l.column_heads;
    for c in 0..5 {
        let x = l.columns_x[c];
        assert!(inked(&img, (x, hy, PATCH_PX, hh), BG) > 20, "column {c}");
        assert!(x >= hx);
    }
    let (rx, _, rw, _) = l.row_heads;
    for r in 0..3 {
        let y = l.rows_y[r];
        assert!(inked(&img, (rx, y, rw, PATCH_PX), BG) > 20, "row {r}");
    }
    // Title and legend.
    assert!(inked(&img, (0, 0, img.w, hy - 25), BG) > 300);
    assert!(inked(&img, (0, l.legend_top, img.w, img.h - l.legend_top), BG) > 300);
    for r in 0..3 {
        for c in 0..5 {
            let (x, y) = (l.columns_x[c], l.rows_y[r]);
            // Top-left corner: the patch's own colour; numbers at the bottom.
            let corner = img.rgb(x + 3, y + 3);
            let mark = img.rgb(x + PATCH_PX - 2, y + 1);
            let own = |p: [u8; 3]| p == corner;
            let numbers = (y + PATCH_PX / 2..y + PATCH_PX)
                .flat_map(|yy| (x..x + PATCH_PX).map(move |xx| (xx, yy)))
                .filter(|&(xx, yy)| !own(img.rgb(xx, yy)))
                .count();
            assert!(numbers > 60, "patch ({r}, {c}): {numbers} text pixels");
            if (r, c) == (1, 2) {
                let m = gamut::map_lab(&obs, [lab[[1, 2, 0]], lab[[1, 2, 1]], lab[[1, 2, 2]]]);
                assert!(m.moved);
                assert_eq!(corner, m.srgb8);
                assert_ne!(corner, [rgb[[1, 2, 0]], rgb[[1, 2, 1]], rgb[[1, 2, 2]]]);
                assert!(!own(mark), "no mark on the mapped patch");
                // The mark's inside: a filled triangle of MARK_PX.
                assert_eq!(img.rgb(x + PATCH_PX - MARK_PX / 2, y + 2), mark);
            } else {
                assert_eq!(corner, [rgb[[r, c, 0]], rgb[[r, c, 1]], rgb[[r, c, 2]]]);
                assert!(own(mark), "mark on in-gamut patch ({r}, {c})");
            }
        }
    }
    // Mismatched inputs are errors.
    let short = lab.select(Axis(0), &[0, 1]);
    assert!(tile::tile_png(&rgb, &short, &viewing, &illum, &cap).is_err());
}

#[test]
fn in_gamut_colours_are_unchanged() {
    let obs = Observer::cie1931_d65();
    let wl: Vec<f64> = (0..=40).map(|k| 380.0 + 10.0 * k as f64).collect();
    let mut n = 0;
    for k in 0..60 {
        // Smooth spectra between 0.03 and 0.9: greys, pinks, greens, blues.
        let (c, w, a) = (
            400.0 + 5.0 * k as f64,
            30.0 + k as f64,
            0.03 + 0.014 * k as f64,
        );
        let r: Vec<f64> = wl
            .iter()
            .map(|&l| a + (0.9 - a) * (-((l - c) / w).powi(2)).exp())
            .collect();
        let xyz = colour::xyz_from_reflectance(&obs, &wl, &r).unwrap();
        if !in_gamut(obs.linear_srgb(xyz)) {
            continue;
        }
        n += 1;
        let m = gamut::map_lab(&obs, xyz_to_lab(xyz, obs.white_xyz()));
        assert!(!m.moved, "{xyz:?}");
        assert_eq!(m.srgb8, colour::to_srgb8(&obs, xyz), "{xyz:?}");
    }
    assert!(n > 30, "only {n} in-gamut samples");
    // The white and the black.
    let white = gamut::map_lab(&obs, [100.0, 0.0, 0.0]);
    assert_eq!((white.srgb8, white.moved), ([255; 3], false));
    assert_eq!(gamut::map_lab(&obs, [0.0, 0.0, 0.0]).srgb8, [0; 3]);
}

#[test]
fn out_of_gamut_colours_keep_lightness_and_hue() {
    for obs in [
        Observer::cie1931_d65(),
        Observer::standard(colour::Illuminant::A, colour::StandardObserver::TenDegree),
    ] {
        for lab in [
            [60.0, -90.0, -40.0],
            [50.0, 80.0, -90.0],
            [88.0, -10.0, 120.0],
            [30.0, 70.0, 70.0],
            [45.0, -100.0, 80.0],
            [75.0, 0.0, -90.0],
            [112.0, 20.0, 5.0],
        ] {
            let m = gamut::map_lab(&obs, lab);
            assert!(m.moved, "{lab:?}");
            assert!(
                in_gamut(lab_to_linear_srgb(&obs, m.lab)),
                "{lab:?} -> {:?}",
                m.lab
            );
            let want_l = lab[0].clamp(0.0, 100.0);
            assert!((m.lab[0] - want_l).abs() <= 0.5, "{lab:?} -> {:?}", m.lab);
            let [_, c0, h0] = lab_to_lch(lab);
            let [_, c1, h1] = lab_to_lch(m.lab);
            assert!(c1 <= c0);
            if c1 > 1.0 {
                let dh = (h1 - h0 + 540.0) % 360.0 - 180.0;
                assert!(dh.abs() <= 0.5, "{lab:?}: hue {h0} -> {h1}");
            }
            // On the boundary: a little more chroma leaves the gamut.
            if lab[0] < 100.0 {
                let more = [m.lab[0], m.lab[1] * 1.01, m.lab[2] * 1.01];
                assert!(!in_gamut(lab_to_linear_srgb(&obs, more)), "{lab:?}");
            }
            // The drawn 8 bits are the mapped colour's.
            assert_eq!(
                m.srgb8,
                colour::encode_srgb8(lab_to_linear_srgb(&obs, m.lab))
            );
        }
    }
    // Not finite: drawn black, marked.
    let obs = Observer::cie1931_d65();
    assert!(gamut::map_lab(&obs, [f64::NAN, 0.0, 0.0]).moved);
}

#[test]
fn mapping_is_monotone_in_chroma() {
    let obs = Observer::cie1931_d65();
    for l in [20.0, 50.0, 80.0, 95.0] {
        for h in (0..360).step_by(15) {
            let (ca, sa) = ((h as f64).to_radians().cos(), (h as f64).to_radians().sin());
            let mut last = 0.0;
            let mut moved_seen = false;
            for k in 0..=100 {
                let c = 2.0 * k as f64;
                let m = gamut::map_lab(&obs, [l, c * ca, c * sa]);
                let [_, cm, _] = lab_to_lch(m.lab);
                assert!(cm + 1e-6 >= last, "L {l} h {h}: C {c} -> {cm} < {last}");
                assert!(cm <= c + 1e-9);
                // Once moved, every larger chroma is moved too.
                assert!(!moved_seen || m.moved, "L {l} h {h} C {c}");
                moved_seen |= m.moved;
                last = cm;
            }
            assert!(moved_seen, "L {l} h {h}: C 200 inside sRGB?");
        }
    }
}

#[test]
fn geometry_picture_has_axes_scale_bar_and_section() {
    let (nx, ny, nz) = (40, 40, 20);
    let grid = Grid::new(nx, ny, nz, [2000.0, 2000.0, 1000.0]).unwrap();
    let mut f = Array3::zeros((nz, ny, nx));
    for iz in 0..nz {
        for iy in 0..ny {
            for ix in 0..nx {
                let d = ((ix as f64 - 20.0).powi(2) + (iy as f64 - 20.0).powi(2)).sqrt();
                if d < 8.0 && iz > 4 && iz < 15 {
                    f[[iz, iy, ix]] = 1.0;
                }
            }
        }
    }
    let raster = Raster {
        grid,
        fractions: vec![f],
        top_cells: 0,
        surface_nm: None,
        normals: Default::default(),
        crystal: Vec::new(),
    };
    let lines = vec!["pigment volume fraction 0.2 (µm³ per µm³)".to_string()];
    let png = geometry_png(&raster, "demo layer", &lines).unwrap();
    let c = Canvas::decode_png(&png).unwrap();
    let img = Image {
        w: c.w,
        h: c.h,
        px: c.px,
    };
    assert!(img.w >= 2 * 320 && img.h >= 320, "{} × {}", img.w, img.h);
    let bg = [24, 24, 28];
    // Every quarter of the picture's height carries drawing or text.
    for q in 0..4 {
        let band = (0, q * img.h / 4, img.w, img.h / 4);
        assert!(inked(&img, band, bg) > 200, "quarter {q}");
    }
    // The section's dashed line on the top view (orange).
    let orange = (0..img.h)
        .flat_map(|y| (0..img.w).map(move |x| (x, y)))
        .filter(|&(x, y)| img.rgb(x, y) == [230, 120, 60])
        .count();
    assert!(orange > 100, "{orange}");
    assert!(canvas::text_width("x (µm)") > 20);
}

#[test]
fn a_tile_of_one_patch_keeps_its_axis_titles_inside() {
    // One illumination and one viewing angle: the axis titles must not run
    // over the sky heading or down into the legend.
    let obs = Observer::cie1931_d65();
    let cap = caption(&obs);
    let (rgb, lab) = tile_input(&obs);
    let (rgb, lab) = (
        rgb.slice(ndarray::s![0..1, 0..2, ..]).to_owned(),
        lab.slice(ndarray::s![0..1, 0..2, ..]).to_owned(),
    );
    let img = decode(&tile::tile_png(&rgb, &lab, &[0.0], &[0.0], &cap).unwrap());
    let l = TileLayout::new(1, 1, &[0.0], &cap);
    let rows_end = l.rows_y[0] + PATCH_PX;
    // Left of the row headings, between the patches and the legend: empty.
    let (rx, _, _, _) = l.row_heads;
    assert_eq!(
        inked(&img, (0, rows_end, rx, l.legend_top - rows_end), BG),
        0,
        "the viewing-angle title runs into the legend"
    );
    // Above the sky column, the square's title stays right of it.
    let (_, hy, _, _) = l.column_heads;
    let axis_y = hy - canvas::GLYPH_HEIGHT - 4;
    assert_eq!(
        inked(
            &img,
            (l.columns_x[0] + PATCH_PX, axis_y, 6, canvas::GLYPH_HEIGHT),
            BG
        ),
        0,
        "the illumination-angle title runs over the sky heading"
    );
}
