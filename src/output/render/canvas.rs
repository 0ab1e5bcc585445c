//! An RGB8 canvas with anti-aliased TrueType text, PNG encoding and
//! decoding: what every picture of inksim (result panels, geometry views,
//! tiles, comparison grids) is drawn on.
//!
//! Text is set in DejaVu Sans (`data/fonts/DejaVuSans.ttf`, Bitstream Vera
//! licence beside it), embedded in the binary and rasterised by `ab_glyph`
//! with kerning. It covers Latin, Greek (λ, θ, µ), degree and superscript or
//! subscript signs (sr⁻¹, nm², θᵢ, θₒ); a character the font lacks is drawn
//! as the font's empty-box glyph. Sizes are line heights (ascent − descent)
//! in pixels; [`GLYPH_HEIGHT`] is the default.

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, GlyphId, PxScale, ScaleFont};

use super::RenderError;

/// Line height of the default text size, pixels (an em of about 14.6 px).
pub const GLYPH_HEIGHT: usize = 17;
/// Line height of small text (numbers on patches, tick labels), pixels.
pub const SMALL_HEIGHT: usize = 14;
/// Line height of titles, pixels.
pub const TITLE_HEIGHT: usize = 21;

static FONT_BYTES: &[u8] = include_bytes!("../../../data/fonts/DejaVuSans.ttf");

/// The embedded font.
pub fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_BYTES).expect("embedded DejaVu Sans parses"))
}

/// Whether the font has a glyph for `ch` (else it draws an empty box).
pub fn has_glyph(ch: char) -> bool {
    font().glyph_id(ch) != GlyphId(0)
}

/// Distance from the top of the line box to the baseline, for line height `size`.
pub fn ascent(size: f64) -> f64 {
    font().as_scaled(PxScale::from(size as f32)).ascent() as f64
}

/// Width of `s` in pixels when drawn with [`Canvas::text`].
pub fn text_width(s: &str) -> usize {
    text_width_px(s, GLYPH_HEIGHT as f64).ceil() as usize
}

/// Advance width of `s` (kerning included) at line height `size`, pixels.
pub fn text_width_px(s: &str, size: f64) -> f64 {
    let f = font().as_scaled(PxScale::from(size as f32));
    let mut w = 0.0f32;
    let mut prev: Option<GlyphId> = None;
    for ch in s.chars() {
        let id = f.glyph_id(ch);
        if let Some(p) = prev {
            w += f.kern(p, id);
        }
        w += f.h_advance(id);
        prev = Some(id);
    }
    w as f64
}

/// Split `text` at spaces into lines no wider than `max_px` at the default
/// size (a single word wider than that gets a line of its own).
pub fn wrap(text: &str, max_px: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut cur = String::new();
    for word in text.split_whitespace() {
        let candidate = if cur.is_empty() {
            word.to_string()
        } else {
            format!("{cur} {word}")
        };
        if text_width(&candidate) <= max_px || cur.is_empty() {
            cur = candidate;
        } else {
            lines.push(std::mem::replace(&mut cur, word.to_string()));
        }
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
}

/// Call `o(x, y, coverage)` for every covered pixel of `s` laid out from the
/// origin on the baseline (y negative above it), at line height `size`.
fn for_each_coverage(s: &str, size: f64, mut o: impl FnMut(i32, i32, f32)) {
    let scale = PxScale::from(size as f32);
    let f = font().as_scaled(scale);
    let mut pen = 0.0f32;
    let mut prev: Option<GlyphId> = None;
    for ch in s.chars() {
        let id = f.glyph_id(ch);
        if let Some(p) = prev {
            pen += f.kern(p, id);
        }
        let glyph = id.with_scale_and_position(scale, ab_glyph::point(pen.round(), 0.0));
        if let Some(outlined) = font().outline_glyph(glyph) {
            let b = outlined.px_bounds();
            outlined.draw(|gx, gy, a| {
                if a > 0.0 {
                    o(b.min.x as i32 + gx as i32, b.min.y as i32 + gy as i32, a)
                }
            });
        }
        pen += f.h_advance(id);
        prev = Some(id);
    }
}

/// An RGB8 image; all drawing clips at the border.
pub struct Canvas {
    pub w: usize,
    pub h: usize,
    /// Row-major RGB8 pixels, `3 w h` bytes.
    pub px: Vec<u8>,
}

impl Canvas {
    /// A `w × h` canvas filled with `bg`.
    pub fn new(w: usize, h: usize, bg: [u8; 3]) -> Canvas {
        let mut c = Canvas {
            w,
            h,
            px: vec![0; w * h * 3],
        };
        c.fill(bg);
        c
    }

    /// Colour of pixel (x, y), if inside.
    pub fn get(&self, x: i64, y: i64) -> Option<[u8; 3]> {
        self.index(x, y)
            .map(|i| [self.px[i], self.px[i + 1], self.px[i + 2]])
    }

    /// Fill the rectangle `[x, x + w) × [y, y + h)` (clipped).
    pub fn rect(&mut self, x: i64, y: i64, w: usize, h: usize, c: [u8; 3]) {
        for yy in y..y + h as i64 {
            for xx in x..x + w as i64 {
                self.set(xx, yy, c);
            }
        }
    }

    /// Copy `src` with its top-left corner at (x, y) (clipped).
    pub fn blit(&mut self, src: &Canvas, x: i64, y: i64) {
        for sy in 0..src.h {
            for sx in 0..src.w {
                let i = (sy * src.w + sx) * 3;
                self.set(
                    x + sx as i64,
                    y + sy as i64,
                    [src.px[i], src.px[i + 1], src.px[i + 2]],
                );
            }
        }
    }

    pub fn fill(&mut self, c: [u8; 3]) {
        for p in self.px.chunks_exact_mut(3) {
            p.copy_from_slice(&c);
        }
    }

    pub fn index(&self, x: i64, y: i64) -> Option<usize> {
        (x >= 0 && y >= 0 && (x as usize) < self.w && (y as usize) < self.h)
            .then(|| (y as usize * self.w + x as usize) * 3)
    }

    pub fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if let Some(i) = self.index(x, y) {
            self.px[i..i + 3].copy_from_slice(&c);
        }
    }

    pub fn disk(&mut self, cx: f64, cy: f64, r: f64, c: [u8; 3]) {
        let (x0, x1) = ((cx - r).floor() as i64, (cx + r).ceil() as i64);
        let (y0, y1) = ((cy - r).floor() as i64, (cy + r).ceil() as i64);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (dx, dy) = (x as f64 - cx, y as f64 - cy);
                if dx * dx + dy * dy <= r * r {
                    self.set(x, y, c);
                }
            }
        }
    }

    pub fn ring(&mut self, cx: f64, cy: f64, r: f64, c: [u8; 3]) {
        let steps = (2.0 * std::f64::consts::PI * r * 2.0).ceil().max(8.0) as usize;
        for k in 0..steps {
            let a = 2.0 * std::f64::consts::PI * k as f64 / steps as f64;
            self.set(
                (cx + r * a.cos()).round() as i64,
                (cy + r * a.sin()).round() as i64,
                c,
            );
        }
    }

    /// Draw `s` in the default size with the top of its line box at
    /// `(x, y)` (the baseline lies [`ascent`]`(GLYPH_HEIGHT)` lower).
    pub fn text(&mut self, x: usize, y: usize, s: &str, c: [u8; 3]) {
        self.text_px(x as f64, y as f64, s, c, GLYPH_HEIGHT as f64);
    }

    /// Draw `s` with line height `size` pixels, top of the line box at `(x, y)`.
    pub fn text_px(&mut self, x: f64, y: f64, s: &str, c: [u8; 3], size: f64) {
        let base = y + ascent(size);
        for_each_coverage(s, size, |px, py, a| {
            self.blend(
                (x + px as f64).floor() as i64,
                (base + py as f64).floor() as i64,
                c,
                a,
            )
        });
    }

    /// Draw `s` with line height `size` centred horizontally on `cx`.
    pub fn text_centered(&mut self, cx: f64, y: f64, s: &str, c: [u8; 3], size: f64) {
        self.text_px(cx - text_width_px(s, size) / 2.0, y, s, c, size);
    }

    /// Draw `s` turned a quarter turn anticlockwise (reading upwards), line
    /// height `size`; `(x, y)` is the left end of the line box's top edge
    /// before turning, i.e. the turned text occupies `[x, x + size) ×
    /// (y − width, y]`.
    pub fn text_up(&mut self, x: f64, y: f64, s: &str, c: [u8; 3], size: f64) {
        let asc = ascent(size);
        for_each_coverage(s, size, |px, py, a| {
            // Unturned (u, v) = (px, asc + py) → turned (v, −u).
            let (u, v) = (px as f64, asc + py as f64);
            self.blend((x + v).floor() as i64, (y - u).floor() as i64, c, a)
        });
    }

    /// Mix `c` into pixel (x, y) with weight `a` in [0, 1].
    pub fn blend(&mut self, x: i64, y: i64, c: [u8; 3], a: f32) {
        if let Some(i) = self.index(x, y) {
            let a = a.clamp(0.0, 1.0);
            for (p, v) in self.px[i..i + 3].iter_mut().zip(c) {
                *p = (*p as f32 * (1.0 - a) + v as f32 * a).round() as u8;
            }
        }
    }

    /// Straight line from `a` to `b`, one pixel wide.
    pub fn line(&mut self, a: (f64, f64), b: (f64, f64), c: [u8; 3]) {
        let n = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            self.set(
                (a.0 + t * (b.0 - a.0)).round() as i64,
                (a.1 + t * (b.1 - a.1)).round() as i64,
                c,
            );
        }
    }

    /// PNG bytes (RGB8), with `title` as an iTXt "Title" chunk when non-empty.
    pub fn encode_png(&self, title: &str) -> Result<Vec<u8>, RenderError> {
        let img = self;
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, img.w as u32, img.h as u32);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let keyword_ok = title.chars().all(|c| c != '\0');
            if keyword_ok && !title.is_empty() {
                enc.add_itxt_chunk("Title".into(), title.into())?;
            }
            let mut writer = enc.write_header()?;
            writer.write_image_data(&img.px)?;
            writer.finish()?;
        }
        Ok(out)
    }

    /// Decode an 8-bit RGB or RGBA PNG (alpha dropped).
    pub fn decode_png(bytes: &[u8]) -> Result<Canvas, RenderError> {
        let dec = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = dec.read_info()?;
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf)?;
        if info.bit_depth != png::BitDepth::Eight {
            return Err(RenderError::Format(format!(
                "bit depth {:?}",
                info.bit_depth
            )));
        }
        let (w, h) = (info.width as usize, info.height as usize);
        let ch = match info.color_type {
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            other => return Err(RenderError::Format(format!("colour type {other:?}"))),
        };
        let mut px = Vec::with_capacity(w * h * 3);
        for row in buf[..info.buffer_size()].chunks_exact(info.line_size) {
            for p in row[..w * ch].chunks_exact(ch) {
                px.extend_from_slice(&p[..3]);
            }
        }
        Ok(Canvas { w, h, px })
    }
}
