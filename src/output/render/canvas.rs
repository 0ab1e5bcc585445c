//! An RGB8 canvas with a built-in 5×7 bitmap font, PNG encoding and
//! decoding: what every picture of inksim (result panels, geometry views,
//! tiles, comparison grids) is drawn on.
//!
//! The font covers upper-case letters, digits and common punctuation; lower
//! case is drawn as upper case, other characters as `?`. Glyphs are drawn at
//! [`FONT_SCALE`] times their size.

use super::RenderError;

/// Font scale (5×7 glyphs drawn as 10×14 pixels, advance 12).
pub const FONT_SCALE: usize = 2;
/// Horizontal advance of one character, pixels.
pub const GLYPH_ADVANCE: usize = 6 * FONT_SCALE;
/// Height of a line of text, pixels.
pub const GLYPH_HEIGHT: usize = 7 * FONT_SCALE;

/// Width of `s` in pixels when drawn with [`Canvas::text`].
pub fn text_width(s: &str) -> usize {
    s.chars().count() * GLYPH_ADVANCE
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

    pub fn text(&mut self, x: usize, y: usize, s: &str, c: [u8; 3]) {
        for (k, ch) in s.chars().enumerate() {
            let g = glyph(ch);
            let x0 = x + k * GLYPH_ADVANCE;
            for (row, bits) in g.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0x10 >> col) == 0 {
                        continue;
                    }
                    for dy in 0..FONT_SCALE {
                        for dx in 0..FONT_SCALE {
                            self.set(
                                (x0 + col * FONT_SCALE + dx) as i64,
                                (y + row * FONT_SCALE + dy) as i64,
                                c,
                            );
                        }
                    }
                }
            }
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

/// 5×7 glyph rows, bit 4 = leftmost column.
pub(crate) fn glyph(c: char) -> [u8; 7] {
    match c.to_ascii_uppercase() {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        'A' => [0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11],
        'B' => [0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E],
        'C' => [0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E],
        'D' => [0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C],
        'E' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F],
        'F' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10],
        'G' => [0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F],
        'H' => [0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'I' => [0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E],
        'J' => [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C],
        'K' => [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11],
        'L' => [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F],
        'M' => [0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11],
        'N' => [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11],
        'O' => [0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'P' => [0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10],
        'Q' => [0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D],
        'R' => [0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11],
        'S' => [0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E],
        'T' => [0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
        'U' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'V' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04],
        'W' => [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A],
        'X' => [0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11],
        'Y' => [0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04],
        'Z' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F],
        ' ' => [0; 7],
        '.' => [0, 0, 0, 0, 0, 0x0C, 0x0C],
        ',' => [0, 0, 0, 0, 0x0C, 0x04, 0x08],
        '-' => [0, 0, 0, 0x1F, 0, 0, 0],
        '+' => [0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0],
        '=' => [0, 0, 0x1F, 0, 0x1F, 0, 0],
        ':' => [0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0],
        ';' => [0, 0x0C, 0x0C, 0, 0x0C, 0x04, 0x08],
        '/' => [0, 0x01, 0x02, 0x04, 0x08, 0x10, 0],
        '%' => [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03],
        '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
        ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
        '[' => [0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E],
        ']' => [0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E],
        '<' => [0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02],
        '>' => [0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08],
        '_' => [0, 0, 0, 0, 0, 0, 0x1F],
        '\'' => [0x0C, 0x04, 0x08, 0, 0, 0, 0],
        '°' => [0x0C, 0x12, 0x12, 0x0C, 0, 0, 0],
        '→' => [0, 0x04, 0x02, 0x1F, 0x02, 0x04, 0],
        '↓' => [0x04, 0x04, 0x04, 0x04, 0x15, 0x0E, 0x04],
        _ => [0x0E, 0x11, 0x01, 0x02, 0x04, 0, 0x04], // '?'
    }
}
