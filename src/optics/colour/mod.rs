//! Colour science — from reflectance spectra to what a display shows.
//!
//! This module owns the colorimetric chain of METHOD §6:
//! spectrum → CIE XYZ (observer and illuminant of [`conditions`]: CIE 1931 2°
//! or 1964 10°; D65, D50 or A) → linear sRGB (Bradford-adapted to D65 where
//! the illuminant is another) → sRGB transfer → 8 bit, plus CIELAB and
//! CIEDE2000 for comparing variants. It is a leaf: it imports
//! no other stage, and `render` (and anything after it) uses it.
//!
//! **Tables.** The official CIE tables are shipped as data and embedded with
//! `include_str!`, each file naming its source in a header comment:
//! `data/cie/cie1931_2deg_xyz_1nm.csv` and `cie1964_10deg_xyz_1nm.csv` (x̄ȳz̄,
//! 360–830 nm, 1 nm), `data/cie/cie_d65_1nm.csv` (D65, 300–830 nm, 1 nm) and
//! `cie_d50_5nm.csv` (D50, 300–780 nm, 5 nm); illuminant A is the CIE formula.
//! The [`Observer`] keeps them on the CMF grid, 360–830 nm at 1 nm.
//!
//! **Integration.** Tristimulus values are the sums of CIE 015
//! `X = k Σ R(λ) S(λ) x̄(λ) Δλ` over the 1 nm table grid (Δλ = 1 nm), with
//! `k = 100 / Σ S(λ) ȳ(λ) Δλ`, so a perfect reflecting diffuser has `Y = 100`.
//! This is colour-science's `sd_to_XYZ(method="Integration")` on the same
//! grid. A spectrum given at other wavelengths is linearly interpolated onto
//! the grid and held constant beyond its first and last sample (nearest-value
//! extrapolation, as CIE 015 and colour-science do). Sampling a smooth
//! spectrum every 10 nm instead of 1 nm changes XYZ by < 0.05 (ΔE00 ≈ 0.05);
//! every 50 nm, ΔE00 ≈ 1 (tests/colour.rs), so coarse spectra should be
//! sampled at 10 nm or finer.
//!
//! **White.** `XYZ/100` goes through the IEC 61966-2-1 matrix to linear sRGB.
//! The D65 white of the tables maps to (1, 1, 1) only up to the rounding of
//! that 4-decimal matrix (≈1e-4), so [`Observer::linear_srgb`] divides each
//! channel by the white's linear RGB: reflectance 1 at every wavelength (a
//! Lambertian reflector of albedo 1, `f_r = 1/π`) gives exactly (1, 1, 1), and
//! therefore exactly (255, 255, 255) after the transfer function.
//!
//! **8 bit.** Linear values are clamped to [0, 1] (NaN counts as 0), encoded
//! with the sRGB transfer function and rounded to the nearest of 0…255.

use std::f64::consts::PI;

pub mod conditions;
pub mod gamut;
pub mod metamerism;
pub mod sources;
mod uncertainty;

pub use conditions::{bradford, illuminant_a, Illuminant, StandardObserver, SRGB_WHITE};
use conditions::{interpolate, mat_vec, D50_CSV, D65_CSV};
pub use metamerism::{special_metamerism_index, Metamerism};
pub use sources::TestSource;
pub use uncertainty::{delta_e2000_se, lch_se};

/// Wavelength range (nm) a spectrum's samples must lie in.
pub const WAVELENGTH_RANGE_NM: (f64, f64) = (360.0, 830.0);

/// IEC 61966-2-1 (sRGB) matrix from XYZ (white Y = 1) to linear RGB.
pub const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
];

/// Errors of the colour stage.
#[derive(Debug, thiserror::Error)]
pub enum ColourError {
    /// Wavelength and value arrays differ in length.
    #[error("spectrum: {wavelengths} wavelengths but {values} values (they must match)")]
    LengthMismatch { wavelengths: usize, values: usize },
    /// No samples.
    #[error("spectrum: no samples (at least one wavelength in 360–830 nm is required)")]
    Empty,
    /// A wavelength outside 360–830 nm or not finite.
    #[error("spectrum: wavelength[{index}] = {value} nm is outside the allowed range 360–830 nm")]
    WavelengthOutOfRange { index: usize, value: f64 },
    /// Wavelengths not strictly increasing.
    #[error(
        "spectrum: wavelengths must be strictly increasing, but wavelength[{index}] = {value} nm \
         follows {previous} nm"
    )]
    NotIncreasing {
        index: usize,
        value: f64,
        previous: f64,
    },
    /// A spectral value that is NaN or infinite.
    #[error("spectrum: value[{index}] = {value} is not finite")]
    NonFinite { index: usize, value: f64 },
    /// A built-in or supplied table could not be read.
    #[error("colour table {table}, line {line}: {reason}")]
    Table {
        table: &'static str,
        line: usize,
        reason: String,
    },
}

/// Observer and illuminant on a common wavelength grid: colour-matching
/// functions weighted by the illuminant and normalised so that a perfect white
/// has `Y = 100`, plus the adaptation that shows its colours on an sRGB display.
#[derive(Debug, Clone)]
pub struct Observer {
    /// Grid wavelengths (nm), increasing, uniform spacing `step_nm`.
    wavelengths_nm: Vec<f64>,
    /// `k S(λ) (x̄, ȳ, z̄)(λ) Δλ` at each grid wavelength.
    weights: Vec<[f64; 3]>,
    /// XYZ of reflectance 1 everywhere (`Y` = 100 up to rounding).
    white_xyz: [f64; 3],
    /// Linear sRGB (IEC matrix, before balancing) of the adapted `white_xyz / 100`.
    white_rgb: [f64; 3],
    /// Bradford transform to the sRGB (D65) white; `None` for D65 itself,
    /// whose small difference from sRGB's white the balance absorbs.
    adapt: Option<[[f64; 3]; 3]>,
    /// The CIE conditions, when built from the shipped tables.
    conditions: Option<(Illuminant, StandardObserver)>,
}

/// Parse `wavelength,v1,v2,…` rows (lines starting with `#` or a letter are
/// comments/headers) into (wavelength, values) with exactly `ncols` values.
fn parse_table(
    text: &str,
    table: &'static str,
    ncols: usize,
) -> Result<Vec<(f64, Vec<f64>)>, ColourError> {
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with(char::is_alphabetic) {
            continue;
        }
        let err = |reason: String| ColourError::Table {
            table,
            line: i + 1,
            reason,
        };
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != ncols + 1 {
            return Err(err(format!(
                "expected {} comma-separated numbers, found {}",
                ncols + 1,
                fields.len()
            )));
        }
        let mut nums = Vec::with_capacity(fields.len());
        for f in &fields {
            let v: f64 = f
                .parse()
                .map_err(|_| err(format!("'{f}' is not a number")))?;
            if !v.is_finite() {
                return Err(err(format!("'{f}' is not finite")));
            }
            nums.push(v);
        }
        rows.push((nums[0], nums[1..].to_vec()));
    }
    Ok(rows)
}

impl Observer {
    /// CIE 1931 2° standard observer under CIE D65, from the embedded official
    /// tables (360–830 nm, 1 nm).
    pub fn cie1931_d65() -> Observer {
        Observer::standard(Illuminant::D65, StandardObserver::TwoDegree)
    }

    /// A CIE standard observer under a CIE illuminant, from the embedded
    /// official tables on the observer's 1 nm grid, 360–830 nm (see
    /// [`Illuminant`] for how each illuminant reaches that grid).
    pub fn standard(illuminant: Illuminant, observer: StandardObserver) -> Observer {
        // The embedded tables are fixed data checked by tests/colour.rs.
        let cmf = parse_table(
            conditions::cmf_csv(observer),
            "colour-matching functions",
            3,
        )
        .expect("embedded CIE tables are valid");
        let mut obs = match illuminant {
            Illuminant::D65 => {
                let ill = parse_table(D65_CSV, "illuminant", 1).expect("embedded table");
                Observer::from_rows(&cmf, &ill)
            }
            Illuminant::D50 => {
                let tab: Vec<(f64, f64)> = parse_table(D50_CSV, "illuminant", 1)
                    .expect("embedded table")
                    .into_iter()
                    .map(|(w, v)| (w, v[0]))
                    .collect();
                Observer::under_table(&cmf, &tab)
            }
            Illuminant::A => {
                let ill: Vec<(f64, Vec<f64>)> = cmf
                    .iter()
                    .map(|(w, _)| (*w, vec![illuminant_a(*w)]))
                    .collect();
                Observer::from_rows(&cmf, &ill)
            }
        }
        .expect("embedded CIE tables are valid");
        if illuminant != Illuminant::D65 {
            obs.set_adaptation(bradford(scale(obs.white_xyz, 0.01), SRGB_WHITE));
        }
        obs.conditions = Some((illuminant, observer));
        obs
    }

    /// Build an observer from CSV text: `cmf_csv` rows `λ,x̄,ȳ,z̄` on a uniform
    /// increasing grid, `illuminant_csv` rows `λ,S` covering every CMF
    /// wavelength (matched to within 1e-9 nm). `#` lines and a header are skipped.
    pub fn from_tables(cmf_csv: &str, illuminant_csv: &str) -> Result<Observer, ColourError> {
        let cmf = parse_table(cmf_csv, "colour-matching functions", 3)?;
        let ill = parse_table(illuminant_csv, "illuminant", 1)?;
        Observer::from_rows(&cmf, &ill)
    }

    /// The observer of `cmf` under the illuminant tabulated in `table`
    /// (`(λ, S)`, increasing λ), put on the CMF grid by linear interpolation
    /// and held at its end values beyond it.
    fn under_table(cmf: &[(f64, Vec<f64>)], table: &[(f64, f64)]) -> Result<Observer, ColourError> {
        let ill: Vec<(f64, Vec<f64>)> = cmf
            .iter()
            .map(|(w, _)| (*w, vec![interpolate(table, *w)]))
            .collect();
        Observer::from_rows(cmf, &ill)
    }

    fn from_rows(
        cmf: &[(f64, Vec<f64>)],
        ill: &[(f64, Vec<f64>)],
    ) -> Result<Observer, ColourError> {
        if cmf.len() < 2 {
            return Err(ColourError::Table {
                table: "colour-matching functions",
                line: 0,
                reason: "fewer than two rows".into(),
            });
        }
        let step = cmf[1].0 - cmf[0].0;
        if step <= 0.0 {
            return Err(ColourError::Table {
                table: "colour-matching functions",
                line: 0,
                reason: format!("wavelengths must increase; the first step is {step} nm"),
            });
        }
        let mut wavelengths_nm = Vec::with_capacity(cmf.len());
        let mut weights = Vec::with_capacity(cmf.len());
        let mut j = 0;
        for (i, (wl, xyz)) in cmf.iter().enumerate() {
            if i > 0 && ((wl - cmf[i - 1].0) - step).abs() > 1e-9 {
                return Err(ColourError::Table {
                    table: "colour-matching functions",
                    line: i + 1,
                    reason: format!("wavelength {wl} nm breaks the uniform {step} nm grid"),
                });
            }
            while j < ill.len() && ill[j].0 < wl - 1e-9 {
                j += 1;
            }
            if j == ill.len() || (ill[j].0 - wl).abs() > 1e-9 {
                return Err(ColourError::Table {
                    table: "illuminant",
                    line: 0,
                    reason: format!("no value at {wl} nm (needed for every CMF wavelength)"),
                });
            }
            let s = ill[j].1[0];
            wavelengths_nm.push(*wl);
            weights.push([s * xyz[0] * step, s * xyz[1] * step, s * xyz[2] * step]);
        }
        let norm: f64 = weights.iter().map(|w| w[1]).sum();
        let k = 100.0 / norm;
        for w in &mut weights {
            for c in w.iter_mut() {
                *c *= k;
            }
        }
        let mut white_xyz = [0.0; 3];
        for w in &weights {
            for c in 0..3 {
                white_xyz[c] += w[c];
            }
        }
        let white_rgb = xyz_to_linear_srgb(scale(white_xyz, 0.01));
        Ok(Observer {
            wavelengths_nm,
            weights,
            white_xyz,
            white_rgb,
            adapt: None,
            conditions: None,
        })
    }

    /// Show colours through the chromatic adaptation `m` (XYZ → XYZ under the
    /// sRGB white) and balance the adapted white to (1, 1, 1).
    fn set_adaptation(&mut self, m: [[f64; 3]; 3]) {
        self.white_rgb = xyz_to_linear_srgb(scale(mat_vec(&m, self.white_xyz), 0.01));
        self.adapt = Some(m);
    }

    /// The CIE illuminant and observer, for an observer built by [`Observer::standard`].
    pub fn conditions(&self) -> Option<(Illuminant, StandardObserver)> {
        self.conditions
    }

    /// Grid wavelengths (nm).
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelengths_nm
    }

    /// XYZ of a perfect white (reflectance 1 at every wavelength), `Y` = 100.
    pub fn white_xyz(&self) -> [f64; 3] {
        self.white_xyz
    }

    /// Linear sRGB of XYZ (white `Y` = 100), each channel divided by the
    /// white's so that the perfect white is exactly (1, 1, 1).
    /// Under an illuminant other than D65 the colour is first carried to the
    /// sRGB white by the Bradford transform.
    pub fn linear_srgb(&self, xyz: [f64; 3]) -> [f64; 3] {
        let xyz = match &self.adapt {
            Some(m) => mat_vec(m, xyz),
            None => xyz,
        };
        let rgb = xyz_to_linear_srgb(scale(xyz, 0.01));
        [
            rgb[0] / self.white_rgb[0],
            rgb[1] / self.white_rgb[1],
            rgb[2] / self.white_rgb[2],
        ]
    }
}

fn scale(v: [f64; 3], s: f64) -> [f64; 3] {
    [v[0] * s, v[1] * s, v[2] * s]
}

/// Tristimulus values (white `Y` = 100) of a reflectance spectrum under D65.
///
/// `wavelengths_nm` strictly increasing, each within 360–830 nm, any spacing;
/// `reflectance` finite (values above 1, e.g. a radiance factor, are allowed).
/// The spectrum is linearly interpolated onto the observer's 1 nm grid and
/// held at its end values outside its sampled range; a single sample is a flat
/// spectrum. Does not allocate.
pub fn xyz_from_reflectance(
    obs: &Observer,
    wavelengths_nm: &[f64],
    reflectance: &[f64],
) -> Result<[f64; 3], ColourError> {
    if wavelengths_nm.len() != reflectance.len() {
        return Err(ColourError::LengthMismatch {
            wavelengths: wavelengths_nm.len(),
            values: reflectance.len(),
        });
    }
    if wavelengths_nm.is_empty() {
        return Err(ColourError::Empty);
    }
    let (lo, hi) = WAVELENGTH_RANGE_NM;
    for (i, (&w, &r)) in wavelengths_nm.iter().zip(reflectance).enumerate() {
        // `!(lo..=hi).contains` also rejects NaN.
        if !(lo..=hi).contains(&w) {
            return Err(ColourError::WavelengthOutOfRange { index: i, value: w });
        }
        if i > 0 && w <= wavelengths_nm[i - 1] {
            return Err(ColourError::NotIncreasing {
                index: i,
                value: w,
                previous: wavelengths_nm[i - 1],
            });
        }
        if !r.is_finite() {
            return Err(ColourError::NonFinite { index: i, value: r });
        }
    }
    let n = wavelengths_nm.len();
    let mut xyz = [0.0; 3];
    let mut j = 0; // segment [j, j+1] of the input containing the grid wavelength
    for (&wl, w) in obs.wavelengths_nm.iter().zip(&obs.weights) {
        let r = if wl <= wavelengths_nm[0] {
            reflectance[0]
        } else if wl >= wavelengths_nm[n - 1] {
            reflectance[n - 1]
        } else {
            while wavelengths_nm[j + 1] < wl {
                j += 1;
            }
            let (w0, w1) = (wavelengths_nm[j], wavelengths_nm[j + 1]);
            let t = (wl - w0) / (w1 - w0);
            reflectance[j] + t * (reflectance[j + 1] - reflectance[j])
        };
        xyz[0] += r * w[0];
        xyz[1] += r * w[1];
        xyz[2] += r * w[2];
    }
    Ok(xyz)
}

/// XYZ (white `Y` = 1) to linear sRGB by the IEC 61966-2-1 matrix [`XYZ_TO_SRGB`].
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    let m = &XYZ_TO_SRGB;
    [
        m[0][0] * xyz[0] + m[0][1] * xyz[1] + m[0][2] * xyz[2],
        m[1][0] * xyz[0] + m[1][1] * xyz[1] + m[1][2] * xyz[2],
        m[2][0] * xyz[0] + m[2][1] * xyz[1] + m[2][2] * xyz[2],
    ]
}

/// sRGB transfer function (IEC 61966-2-1): linear light → encoded value.
pub fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.0031308 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`srgb_encode`]: encoded value → linear light.
pub fn srgb_decode(encoded: f64) -> f64 {
    if encoded <= 0.04045 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear sRGB → 8-bit sRGB: clamp to [0, 1] (NaN → 0), encode, round.
pub fn encode_srgb8(linear: [f64; 3]) -> [u8; 3] {
    linear.map(|v| {
        let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        // In [0, 255] by construction; the cast cannot wrap.
        (srgb_encode(v) * 255.0).round().clamp(0.0, 255.0) as u8
    })
}

/// XYZ (white `Y` = 100, from [`xyz_from_reflectance`]) → 8-bit sRGB, with the
/// per-channel white balance of [`Observer::linear_srgb`]: a perfect white is
/// exactly (255, 255, 255).
pub fn to_srgb8(obs: &Observer, xyz: [f64; 3]) -> [u8; 3] {
    encode_srgb8(obs.linear_srgb(xyz))
}

/// CIE 1976 L*a*b* of `xyz` relative to the reference `white` (same scale).
pub fn xyz_to_lab(xyz: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    const EPS: f64 = 216.0 / 24389.0;
    const KAPPA: f64 = 24389.0 / 27.0;
    let f = |t: f64| {
        if t > EPS {
            t.cbrt()
        } else {
            (KAPPA * t + 16.0) / 116.0
        }
    };
    let fx = f(xyz[0] / white[0]);
    let fy = f(xyz[1] / white[1]);
    let fz = f(xyz[2] / white[2]);
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// Hue angle in degrees in [0, 360); 0 for a = b = 0 (Sharma et al. 2005).
fn hue_deg(b: f64, a: f64) -> f64 {
    if a == 0.0 && b == 0.0 {
        return 0.0;
    }
    let h = b.atan2(a).to_degrees();
    if h < 0.0 {
        h + 360.0
    } else {
        h
    }
}

/// Hue differences this close to ±180° are treated as exactly 180°, the
/// |Δh'| ≤ 180° branch of Sharma et al.: two hues that are exactly opposite
/// must not flip branch because of the last bit of `atan2`.
const HUE_TIE_DEG: f64 = 1e-9;

/// CIEDE2000 colour difference (k_L = k_C = k_H = 1), following
/// Sharma, Wu & Dalal, Color Res. Appl. 30, 21–30 (2005), eqs. (1)–(22).
pub fn delta_e2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let pow7 = |x: f64| x.powi(7);
    let c1 = a1.hypot(b1);
    let c2 = a2.hypot(b2);
    let cbar = 0.5 * (c1 + c2);
    let g = 0.5 * (1.0 - (pow7(cbar) / (pow7(cbar) + pow7(25.0))).sqrt());
    let a1p = (1.0 + g) * a1;
    let a2p = (1.0 + g) * a2;
    let c1p = a1p.hypot(b1);
    let c2p = a2p.hypot(b2);
    let h1p = hue_deg(b1, a1p);
    let h2p = hue_deg(b2, a2p);

    let dlp = l2 - l1;
    let dcp = c2p - c1p;
    let diff = h2p - h1p;
    let chroma_zero = c1p * c2p == 0.0;
    let dhp = if chroma_zero {
        0.0
    } else if diff.abs() <= 180.0 + HUE_TIE_DEG {
        diff
    } else if diff > 180.0 {
        diff - 360.0
    } else {
        diff + 360.0
    };
    let dhp_big = 2.0 * (c1p * c2p).sqrt() * (0.5 * dhp).to_radians().sin();

    let lbarp = 0.5 * (l1 + l2);
    let cbarp = 0.5 * (c1p + c2p);
    let sum = h1p + h2p;
    let hbarp = if chroma_zero {
        sum
    } else if diff.abs() <= 180.0 + HUE_TIE_DEG {
        0.5 * sum
    } else if sum < 360.0 {
        0.5 * (sum + 360.0)
    } else {
        0.5 * (sum - 360.0)
    };
    let t = 1.0 - 0.17 * (hbarp - 30.0).to_radians().cos()
        + 0.24 * (2.0 * hbarp).to_radians().cos()
        + 0.32 * (3.0 * hbarp + 6.0).to_radians().cos()
        - 0.20 * (4.0 * hbarp - 63.0).to_radians().cos();
    let dtheta = 30.0 * (-((hbarp - 275.0) / 25.0).powi(2)).exp();
    let rc = 2.0 * (pow7(cbarp) / (pow7(cbarp) + pow7(25.0))).sqrt();
    let lb50 = (lbarp - 50.0).powi(2);
    let sl = 1.0 + 0.015 * lb50 / (20.0 + lb50).sqrt();
    let sc = 1.0 + 0.045 * cbarp;
    let sh = 1.0 + 0.015 * cbarp * t;
    let rt = -(2.0 * dtheta).to_radians().sin() * rc;
    let (tl, tc, th) = (dlp / sl, dcp / sc, dhp_big / sh);
    (tl * tl + tc * tc + th * th + rt * tc * th).sqrt()
}

/// Convenience: reflectance spectrum → 8-bit sRGB under D65.
pub fn reflectance_to_srgb8(
    obs: &Observer,
    wavelengths_nm: &[f64],
    reflectance: &[f64],
) -> Result<[u8; 3], ColourError> {
    Ok(to_srgb8(
        obs,
        xyz_from_reflectance(obs, wavelengths_nm, reflectance)?,
    ))
}

/// CIELAB → CIE LCh(ab): lightness, chroma `C*ab = √(a*² + b*²)` and hue
/// angle `h_ab` in degrees, in [0, 360).
pub fn lab_to_lch(lab: [f64; 3]) -> [f64; 3] {
    let h = lab[2].atan2(lab[1]).to_degrees();
    [
        lab[0],
        lab[1].hypot(lab[2]),
        if h < 0.0 { h + 360.0 } else { h },
    ]
}

/// Reflectance of a Lambertian surface with BRDF `f_r` (sr⁻¹): `π f_r`.
/// A perfect Lambertian reflector of albedo 1 (`f_r = 1/π`) gives 1.
pub fn lambertian_reflectance(f_r: f64) -> f64 {
    PI * f_r
}
