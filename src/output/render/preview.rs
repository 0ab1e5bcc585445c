//! `<name>-preview.png`: a rendered preview of a result, a sphere coated
//! with the layer on its substrate beside a white diffuser sphere (albedo 1)
//! for scale, both under one distant light 45° from the view direction
//! (upper left) and a uniform white sky.
//!
//! The camera is orthographic. At each surface point the radiance (linear
//! sRGB, white balanced as in the MERL export, then matched to the tile's
//! colour as below) is
//! - the diffuse BRDF of layer + paper ([`RgbBrdf::eval`]) times the light's
//!   irradiance times cos θi;
//! - the sky: the directional-hemispherical reflectance of the diffuse BRDF
//!   for the viewing angle (by reciprocity, the radiance under a uniform sky
//!   of radiance 1; integrated once per 2° of θo) times the sky's radiance;
//! - the specular (0,0) order's reflectance at θo times the sky's radiance,
//!   and the light's mirror image: the light drawn as a disc of
//!   [`LIGHT_RADIUS_DEG`] where the mirror direction falls inside it.
//!
//! **Colour.** The RGB BRDF weights the solved wavelengths linearly, so it
//! misses the absorption bands between them that the tile's colour carries
//! through the spectral proxy (a magenta of C*ab ≈ 100 on the tile renders
//! pink from three wavelengths), and its specular order, a thin film's
//! fringes sampled at a few wavelengths, can be strongly coloured where the
//! fine spectrum averages them out. The layer's reflection (diffuse and
//! specular) is therefore scaled per channel so that its colour under the
//! sky alone, at the first viewing angle, is the tile's sky colour there
//! (gamut mapped as the tile draws it): gain = tile / (diffuse + specular),
//! within [[`GAIN_MIN`], [`GAIN_MAX`]]. The caption gives the gains. Without a tile
//! colour (no paper term) the BRDF is drawn as it is and the caption says so.
//!
//! The light and sky are scaled so that the white diffuser facing the light
//! has radiance 1 (0.75 from the light, 0.25 from the sky); values above 1
//! are clipped. Around the spheres is a dark grey backdrop (not the sky,
//! which would hide the spheres' outlines on their sides away from the
//! light, lit by the sky alone). The layer is taken as isotropic
//! in azimuth, its BRDF interpolated between the solved illumination angles
//! and held beyond the largest (the MERL export's approximations).

use std::f64::consts::PI;

use super::canvas::{wrap, Canvas, GLYPH_HEIGHT, SMALL_HEIGHT};
use super::RenderError;
use crate::optics::appearance::Appearance;
use crate::optics::colour::{encode_srgb8, gamut, Observer};
use crate::output::merl::{MerlError, RgbBrdf};

/// Diameter of a sphere, pixels.
pub const SPHERE_PX: usize = 220;
/// Angular radius of the light's disc (for its mirror image), degrees.
pub const LIGHT_RADIUS_DEG: f64 = 3.0;
/// The light's irradiance (normal to it) and the sky's radiance.
const LIGHT_E: f64 = 0.75 * PI;
const SKY_L: f64 = 0.25;
/// Linear value of the backdrop.
const BACKDROP: f64 = 0.045;
const PAD: usize = 16;
const INK: [u8; 3] = [20, 20, 20];
/// Samples per pixel side (anti-aliasing of the outline).
const SUPER: usize = 3;
/// Range of the per-channel colour gains (module docs).
pub const GAIN_MIN: f64 = 0.0;
pub const GAIN_MAX: f64 = 20.0;

/// Unit vector towards the light: 45° from the view direction (+z),
/// from the upper left (x right, y up).
fn light_dir() -> [f64; 3] {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    [-s * s, s * s, s]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    a.map(|v| v / n)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A surface's reflection: the diffuse BRDF in its own frame, its sky
/// reflectance against θo and its specular reflectance against θo.
trait Surface {
    fn brdf(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3];
    fn sky(&self, theta_o_deg: f64) -> [f64; 3];
    fn specular(&self, theta_o_deg: f64) -> [f64; 3];
}

/// The layer on its substrate.
struct Layer {
    brdf: RgbBrdf,
    /// Directional-hemispherical reflectance at θo = 0°, 2°, …, 90°.
    sky: Vec<[f64; 3]>,
    /// Per-channel gain of the reflection, `None` where no tile colour
    /// was there to match (module docs).
    gain: Option<[f64; 3]>,
}

const SKY_STEP_DEG: f64 = 2.0;

impl Layer {
    fn new(a: &Appearance, obs: &Observer) -> Result<Self, MerlError> {
        let brdf = RgbBrdf::new(a)?;
        let n = (90.0 / SKY_STEP_DEG) as usize + 1;
        let sky = (0..n).map(|k| brdf.sky(k as f64 * SKY_STEP_DEG)).collect();
        let mut layer = Layer {
            brdf,
            sky,
            gain: None,
        };
        layer.gain = layer.tile_gain(a, obs);
        Ok(layer)
    }

    /// Gains that give the sky colour at the first viewing angle the tile's
    /// colour (module docs).
    fn tile_gain(&self, a: &Appearance, obs: &Observer) -> Option<[f64; 3]> {
        let lab = *a.colours.as_ref()?.natural_lab.first()?;
        let theta = *a.spec.viewing_deg.first()?;
        let target = gamut::lab_to_linear_srgb(obs, gamut::map_lab(obs, lab).lab);
        let (diffuse, spec) = (self.sky_diffuse(theta), self.brdf.specular(theta));
        Some(std::array::from_fn(|ch| {
            let solved = diffuse[ch] + spec[ch];
            if solved > 1e-9 {
                (target[ch] / solved).clamp(GAIN_MIN, GAIN_MAX)
            } else {
                1.0
            }
        }))
    }

    /// Sky reflectance of the diffuse BRDF as solved (no gain).
    fn sky_diffuse(&self, theta_o_deg: f64) -> [f64; 3] {
        let x = (theta_o_deg / SKY_STEP_DEG).clamp(0.0, (self.sky.len() - 1) as f64);
        let k = (x.floor() as usize).min(self.sky.len() - 2);
        let f = x - k as f64;
        std::array::from_fn(|ch| self.sky[k][ch] * (1.0 - f) + self.sky[k + 1][ch] * f)
    }

    fn gain(&self) -> [f64; 3] {
        self.gain.unwrap_or([1.0; 3])
    }
}

impl Surface for Layer {
    fn brdf(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        let (f, g) = (self.brdf.eval(wi, wo), self.gain());
        std::array::from_fn(|ch| f[ch] * g[ch])
    }
    fn sky(&self, theta_o_deg: f64) -> [f64; 3] {
        let (s, g) = (self.sky_diffuse(theta_o_deg), self.gain());
        std::array::from_fn(|ch| s[ch] * g[ch])
    }
    fn specular(&self, theta_o_deg: f64) -> [f64; 3] {
        let (s, g) = (self.brdf.specular(theta_o_deg), self.gain());
        std::array::from_fn(|ch| s[ch] * g[ch])
    }
}

/// A white Lambertian diffuser of albedo 1.
struct White;

impl Surface for White {
    fn brdf(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            [0.0; 3]
        } else {
            [1.0 / PI; 3]
        }
    }
    fn sky(&self, _: f64) -> [f64; 3] {
        [1.0; 3]
    }
    fn specular(&self, _: f64) -> [f64; 3] {
        [0.0; 3]
    }
}

/// Radiance (linear sRGB) of `s` on a sphere at normal `n` (camera frame,
/// the viewer along +z).
fn shade(s: &dyn Surface, n: [f64; 3]) -> [f64; 3] {
    let v = [0.0, 0.0, 1.0];
    let l = light_dir();
    let cos_o = dot(n, v).clamp(0.0, 1.0);
    let theta_o = cos_o.acos().to_degrees();
    // The surface's frame: z = n, x along the viewer's tangential direction.
    let tv = [
        v[0] - cos_o * n[0],
        v[1] - cos_o * n[1],
        v[2] - cos_o * n[2],
    ];
    let t = if dot(tv, tv) > 1e-12 {
        unit(tv)
    } else {
        unit(cross([0.0, 1.0, 0.0], n))
    };
    let b = cross(n, t);
    let local = |d: [f64; 3]| [dot(d, t), dot(d, b), dot(d, n)];
    let (wi, wo) = (local(l), local(v));
    let f = s.brdf(wi, wo);
    let sky = s.sky(theta_o);
    let spec = s.specular(theta_o);
    // The mirror direction of the view; the light's disc seen in it.
    let r = [
        2.0 * cos_o * n[0] - v[0],
        2.0 * cos_o * n[1] - v[1],
        2.0 * cos_o * n[2] - v[2],
    ];
    let half = LIGHT_RADIUS_DEG.to_radians();
    let disc = if dot(r, l) >= half.cos() && wi[2] > 0.0 {
        LIGHT_E / (2.0 * PI * (1.0 - half.cos()))
    } else {
        0.0
    };
    std::array::from_fn(|ch| {
        f[ch] * LIGHT_E * wi[2].max(0.0) + sky[ch] * SKY_L + spec[ch] * (SKY_L + disc)
    })
}

/// Draw a sphere of `s` with its top-left corner at (x0, y0).
fn sphere(img: &mut Canvas, s: &dyn Surface, x0: usize, y0: usize) {
    let d = SPHERE_PX as f64;
    for py in 0..SPHERE_PX {
        for px in 0..SPHERE_PX {
            let mut acc = [0.0; 3];
            for sy in 0..SUPER {
                for sx in 0..SUPER {
                    let x = ((px * SUPER + sx) as f64 + 0.5) / (SUPER as f64 * d) * 2.0 - 1.0;
                    let y = 1.0 - ((py * SUPER + sy) as f64 + 0.5) / (SUPER as f64 * d) * 2.0;
                    let rr = x * x + y * y;
                    let c = if rr < 1.0 {
                        shade(s, [x, y, (1.0 - rr).sqrt()])
                    } else {
                        [BACKDROP; 3]
                    };
                    // Average displayed values (clipped), as a camera would.
                    for ch in 0..3 {
                        acc[ch] += c[ch].clamp(0.0, 1.0);
                    }
                }
            }
            let n = (SUPER * SUPER) as f64;
            img.set(
                (x0 + px) as i64,
                (y0 + py) as i64,
                encode_srgb8(acc.map(|v| v / n)),
            );
        }
    }
}

/// The preview picture of an appearance result (module docs); `obs` is the
/// observer and illuminant of its colours (the tile's).
pub fn preview_png(a: &Appearance, obs: &Observer, name: &str) -> Result<Vec<u8>, RenderError> {
    let layer = Layer::new(a, obs).map_err(|e| RenderError::Preview(e.to_string()))?;
    let w = 2 * SPHERE_PX + 3 * PAD;
    let paper = match &a.spec.ground {
        Some(g) => format!("on a ground of {g}"),
        None => "alone".to_string(),
    };
    let caption = [
        format!("{name}: layer {paper} (left), white diffuser (right)"),
        format!(
            "One light 45° from the view (upper left, its mirror image a {LIGHT_RADIUS_DEG}° \
             disc) and a uniform white sky; sRGB ({}), white facing the light = 1, clipped.",
            match obs.conditions() {
                Some((ill, o)) => format!("{ill}, {}°", o.degrees()),
                None => "custom observer".into(),
            }
        ),
        format!(
            "Layer BRDF solved at θi = {}°; interpolated between, held beyond.",
            a.spec
                .illumination_deg
                .iter()
                .map(|d| format!("{d}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        match layer.gain {
            Some(g) => format!(
                "Colour matched to the tile's sky colour at θo = {}°: RGB gains \
                 {:.2}, {:.2}, {:.2} (the solved wavelengths alone miss the bands between).",
                a.spec.viewing_deg[0], g[0], g[1], g[2]
            ),
            None => "Colour from the solved wavelengths alone (no tile colour to match: \
                     the layer has no paper term)."
                .to_string(),
        },
    ];
    let lines: Vec<(String, f64)> = caption
        .iter()
        .enumerate()
        .flat_map(|(k, c)| {
            let size = if k == 0 { GLYPH_HEIGHT } else { SMALL_HEIGHT } as f64;
            let max = if k == 0 {
                w - 2 * PAD
            } else {
                (w - 2 * PAD) * 17 / 14
            };
            wrap(c, max).into_iter().map(move |l| (l, size))
        })
        .collect();
    let text_h: f64 = lines.iter().map(|(_, s)| s + 3.0).sum();
    let h = SPHERE_PX + 2 * PAD + text_h.ceil() as usize + PAD;
    let bg = encode_srgb8([BACKDROP; 3]);
    let mut img = Canvas::new(w, h, [255, 255, 255]);
    img.rect(0, 0, w, SPHERE_PX + 2 * PAD, bg);
    sphere(&mut img, &layer, PAD, PAD);
    sphere(&mut img, &White, 2 * PAD + SPHERE_PX, PAD);
    let mut y = (SPHERE_PX + 2 * PAD + PAD / 2) as f64;
    for (l, size) in &lines {
        img.text_px(PAD as f64, y, l, INK, *size);
        y += size + 3.0;
    }
    img.encode_png(&format!("{name} preview"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_white_diffuser_facing_the_light_is_one() {
        // The normal towards the light: cos θi = 1, θo = 45°.
        let c = shade(&White, light_dir());
        for v in c {
            assert!((v - 1.0).abs() < 1e-12, "{c:?}");
        }
        // Facing the viewer: cos θi = cos 45°, plus the sky.
        let c = shade(&White, [0.0, 0.0, 1.0]);
        assert!((c[0] - (0.75 * std::f64::consts::FRAC_1_SQRT_2 + 0.25)).abs() < 1e-12);
        let l = light_dir();
        assert!((dot(l, l) - 1.0).abs() < 1e-12 && (l[2] - 45f64.to_radians().cos()).abs() < 1e-12);
    }
}
