//! Export of the BRDF of layer + substrate in the MERL binary format
//! (Matusik et al. 2003), which renderers (Mitsuba, PBRT-v3 `merl`, BRDF
//! Explorer, …) load as an isotropic, tabulated RGB BRDF.
//!
//! Format: three little-endian i32 (90, 90, 180), then 90·90·180 f64 per
//! channel (red, green, blue), indexed `φd + 180 (θd + 90 θh)` in the
//! half/difference angles of Rusinkiewicz; θh is sampled as
//! `θh = 90° (i/90)²`, θd and φd ∈ [0, 180°) uniformly. Stored values are
//! the BRDF (1/sr) divided by the MERL channel scales (1, 1.15, 1.66)/1500.
//!
//! **An approximation**, documented as such:
//! - RGB is linear sRGB of the spectral BRDF under D65 (white-balanced so a
//!   Lambertian of albedo 1 is (1/π)(1, 1, 1));
//! - only the diffuse part is tabulated: the specular (0,0) order is a delta
//!   that a 1° table cannot hold;
//! - the layer's BRDF is known at the illumination angles solved; between them
//!   it is interpolated linearly in θi, beyond the largest it is held at the
//!   last solved angle (likewise T(θ) for the paper term); the table in
//!   outgoing directions is the ensemble-mean density table, read as the
//!   BRDF over each node's coverage (bilinear; `optics::farfield::table`),
//!   so it stays bounded at grazing angles;
//! - the layer is taken as isotropic in azimuth (the ensemble is).
//!
//! Bin centres are used for every (θh, θd, φd); directions below the horizon
//! are written as 0.

use crate::optics::appearance::Appearance;
use crate::optics::colour::{self, Observer};
use crate::optics::farfield::table::{self, TableSpec};
use ndarray::{Array2, Array4};
use std::f64::consts::PI;

const N_TH: usize = 90;
const N_TD: usize = 90;
const N_PD: usize = 180;
const SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// Why an export cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum MerlError {
    #[error("needs the BRDF table of at least one illumination angle")]
    NoData,
    #[error("colour: {0}")]
    Colour(#[from] colour::ColourError),
}

/// Linear sRGB weights of each wavelength sample: `rgb = Σ_l w[l] s_l` for a
/// spectrum sampled at the result's wavelengths (the colour pipeline is
/// linear up to the sRGB transfer).
fn channel_weights(obs: &Observer, wl: &[f64]) -> Result<Vec<[f64; 3]>, MerlError> {
    let mut w = Vec::with_capacity(wl.len());
    let mut basis = vec![0.0; wl.len()];
    for l in 0..wl.len() {
        basis.iter_mut().for_each(|b| *b = 0.0);
        basis[l] = 1.0;
        let xyz = colour::xyz_from_reflectance(obs, wl, &basis)?;
        w.push(obs.linear_srgb(xyz));
    }
    Ok(w)
}

/// Piecewise-linear position of `x` in increasing `xs`: (index, fraction),
/// held at the ends.
fn bracket(xs: &[f64], x: f64) -> (usize, f64) {
    if xs.len() == 1 || x <= xs[0] {
        return (0, 0.0);
    }
    let last = xs.len() - 1;
    if x >= xs[last] {
        return (last - 1, 1.0);
    }
    let k = xs.windows(2).position(|w| x < w[1]).unwrap_or(last - 1);
    (k, (x - xs[k]) / (xs[k + 1] - xs[k]))
}

fn rotate_z(v: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

fn rotate_y(v: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]
}

/// Directions (towards light, towards viewer) of a MERL bin centre.
fn directions(ih: usize, id: usize, ip: usize) -> ([f64; 3], [f64; 3]) {
    let th = ((ih as f64 + 0.5) / N_TH as f64).powi(2) * PI / 2.0;
    let td = (id as f64 + 0.5) / N_TD as f64 * PI / 2.0;
    let pd = (ip as f64 + 0.5) / N_PD as f64 * PI;
    let diff = [td.sin() * pd.cos(), td.sin() * pd.sin(), td.cos()];
    // Half vector in the x–z plane (φh = 0: isotropic).
    let wi = rotate_z(rotate_y(diff, th), 0.0);
    let h = [th.sin(), 0.0, th.cos()];
    let d = wi[0] * h[0] + wi[1] * h[1] + wi[2] * h[2];
    let wo = [
        2.0 * d * h[0] - wi[0],
        2.0 * d * h[1] - wi[1],
        2.0 * d * h[2] - wi[2],
    ];
    (wi, wo)
}

/// What the RGB BRDF is evaluated from: the solved angles, the diffuse
/// density tables, the transmittance and specular reflectance from above and
/// the paper term; taken from an assembled [`Appearance`]
/// ([`BrdfData::of`]) or read back from a result file
/// (`output::h5::read_brdf_data`).
#[derive(Debug, Clone)]
pub struct BrdfData {
    pub wavelengths_nm: Vec<f64>,
    /// Azimuth of the plane of incidence (deg).
    pub azimuth_deg: f64,
    pub illumination_deg: Vec<f64>,
    pub above_deg: Vec<f64>,
    pub table: TableSpec,
    /// Density tables (wavelength, illumination, j, i), ensemble mean.
    pub density: Array4<f64>,
    /// (wavelength, above angle), ensemble means.
    pub transmittance: Array2<f64>,
    /// Specular (0,0) order, coherent plus incoherent (wavelength, above angle).
    pub specular: Array2<f64>,
    /// With a reflecting ground: its albedo and the layer's albedo from
    /// below `R_dd↑`, per wavelength.
    pub paper: Option<(Vec<f64>, Vec<f64>)>,
}

impl BrdfData {
    /// The data of an assembled appearance.
    pub fn of(a: &Appearance) -> BrdfData {
        let sp = &a.spec;
        BrdfData {
            wavelengths_nm: sp.wavelengths_nm.clone(),
            azimuth_deg: sp.azimuth_deg,
            illumination_deg: sp.illumination_deg.clone(),
            above_deg: sp.above_deg.clone(),
            table: sp.table,
            density: a.brdf_table.mean.clone(),
            transmittance: a.transmittance.mean.clone(),
            specular: &a.specular_coherent + &a.specular_incoherent,
            paper: a
                .paper
                .as_ref()
                .map(|p| (p.albedo.to_vec(), p.r_dd_up.mean.to_vec())),
        }
    }
}

/// The diffuse BRDF of layer + substrate in linear sRGB (D65, white
/// balanced), at any pair of directions: what the MERL table samples and
/// the preview renders (the approximations of the module docs).
pub struct RgbBrdf {
    d: BrdfData,
    /// Linear sRGB weights of each wavelength.
    w: Vec<[f64; 3]>,
    /// RGB density tables, (illumination, j, i) flattened.
    rgb_tab: Vec<[f64; 3]>,
    /// Node coverage (share of each node's kernel above the horizon).
    coverage: Vec<f64>,
    /// Paper factor per wavelength, `albedo / (π (1 − albedo r_dd↑))`.
    paper: Option<Vec<f64>>,
}

impl RgbBrdf {
    /// The BRDF of an assembled appearance.
    pub fn new(a: &Appearance) -> Result<Self, MerlError> {
        RgbBrdf::from_data(BrdfData::of(a))
    }

    /// The BRDF of `d`.
    pub fn from_data(d: BrdfData) -> Result<Self, MerlError> {
        if d.wavelengths_nm.is_empty() {
            return Err(MerlError::NoData);
        }
        let obs = Observer::cie1931_d65();
        let w = channel_weights(&obs, &d.wavelengths_nm)?;
        RgbBrdf::with_channels(d, w)
    }

    /// The BRDF of `d` in three channels of any linear weights `w` of its
    /// spectrum (`w[l]`, one per wavelength): `eval` and `specular` then
    /// return `Σ_l w[l] f_l`. A one-hot `w` picks wavelengths, which is how
    /// the spectral exports evaluate the BRDF three wavelengths at a time.
    pub fn with_channels(d: BrdfData, w: Vec<[f64; 3]>) -> Result<Self, MerlError> {
        let (nl, ni) = (d.wavelengths_nm.len(), d.illumination_deg.len());
        if ni == 0 || nl == 0 || d.above_deg.is_empty() || w.len() != nl {
            return Err(MerlError::NoData);
        }
        let nt = d.table.n();
        let tab = &d.density;
        let mut rgb_tab = vec![[0.0f64; 3]; ni * nt * nt];
        for i in 0..ni {
            for k in 0..nt * nt {
                let (j, q) = (k / nt, k % nt);
                let mut c = [0.0; 3];
                for (l, wl) in w.iter().enumerate() {
                    let v = tab[[l, i, j, q]];
                    for ch in 0..3 {
                        c[ch] += wl[ch] * v;
                    }
                }
                rgb_tab[i * nt * nt + k] = c;
            }
        }
        let paper: Option<Vec<f64>> = d.paper.as_ref().map(|(albedo, rdd)| {
            (0..nl)
                .map(|l| albedo[l] / (PI * (1.0 - albedo[l] * rdd[l])))
                .collect()
        });
        let coverage: Vec<f64> = (0..nt * nt)
            .map(|k| table::node_coverage(d.table, k % nt, k / nt))
            .collect();
        Ok(RgbBrdf {
            d,
            w,
            rgb_tab,
            coverage,
            paper,
        })
    }

    /// The angles solved from above (deg).
    pub fn above_deg(&self) -> &[f64] {
        &self.d.above_deg
    }

    /// The illumination angles of the tables (deg).
    pub fn illumination_deg(&self) -> &[f64] {
        &self.d.illumination_deg
    }

    /// Directional-hemispherical reflectance of the diffuse BRDF for the
    /// viewing angle `theta_o_deg` (by reciprocity, the radiance under a
    /// uniform sky of radiance 1), by the midpoint rule in μ = cos θi and φ.
    pub fn sky(&self, theta_o_deg: f64) -> [f64; 3] {
        let (nm, np) = (24, 48);
        let t = theta_o_deg.min(89.5).to_radians();
        let wo = [t.sin(), 0.0, t.cos()];
        let mut acc = [0.0; 3];
        for im in 0..nm {
            let mu = (im as f64 + 0.5) / nm as f64;
            let s = (1.0 - mu * mu).sqrt();
            for ip in 0..np {
                let p = (ip as f64 + 0.5) / np as f64 * 2.0 * PI;
                let f = self.eval([s * p.cos(), s * p.sin(), mu], wo);
                for ch in 0..3 {
                    acc[ch] += f[ch] * mu;
                }
            }
        }
        let w = (1.0 / nm as f64) * (2.0 * PI / np as f64);
        acc.map(|v| v * w)
    }

    /// Transmittance from above at polar angle `theta` (deg), wavelength `l`.
    fn t_of(&self, l: usize, theta: f64) -> f64 {
        let above = &self.d.above_deg;
        let (k, f) = bracket(above, theta);
        let t = &self.d.transmittance;
        if above.len() == 1 {
            t[[l, 0]]
        } else {
            t[[l, k]] * (1.0 - f) + t[[l, k + 1]] * f
        }
    }

    /// RGB density of illumination angle `i` at projected direction (sx, sy).
    fn density(&self, i: usize, sx: f64, sy: f64) -> [f64; 3] {
        let tb = &self.d.table;
        let nt = tb.n();
        let (cell, half) = (tb.cell, tb.half as f64);
        let (x, y) = (sx / cell + half, sy / cell + half);
        let max = (nt - 1) as f64;
        if !(x >= 0.0 && y >= 0.0 && x <= max && y <= max) {
            return [0.0; 3];
        }
        let (q, j) = (
            (x.floor() as usize).min(nt - 2),
            (y.floor() as usize).min(nt - 2),
        );
        let (fx, fy) = (x - q as f64, y - j as f64);
        let w = [
            (j, q, (1.0 - fx) * (1.0 - fy)),
            (j, q + 1, fx * (1.0 - fy)),
            (j + 1, q, (1.0 - fx) * fy),
            (j + 1, q + 1, fx * fy),
        ];
        let cov: f64 = w
            .iter()
            .map(|&(jj, qq, wt)| self.coverage[jj * nt + qq] * wt)
            .sum();
        if cov <= 0.0 {
            return [0.0; 3];
        }
        std::array::from_fn(|ch| {
            w.iter()
                .map(|&(jj, qq, wt)| self.rgb_tab[i * nt * nt + jj * nt + qq][ch] * wt)
                .sum::<f64>()
                / cov
        })
    }

    /// The diffuse BRDF (1/sr, linear sRGB) for light arriving from unit
    /// direction `wi` (towards the light) seen from `wo` (towards the
    /// viewer), both in the layer's frame (z the normal); 0 below the
    /// horizon.
    pub fn eval(&self, wi: [f64; 3], wo: [f64; 3]) -> [f64; 3] {
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            return [0.0; 3];
        }
        let ni = self.d.illumination_deg.len();
        let az = self.d.azimuth_deg.to_radians();
        let theta_i = wi[2].min(1.0).acos().to_degrees();
        let theta_o = wo[2].min(1.0).acos().to_degrees();
        // Light travels along −wi; rotate so it travels along the solved
        // azimuth `az`; the viewer's lateral direction follows.
        let phi_travel = (-wi[1]).atan2(-wi[0]);
        let rot = az - phi_travel;
        let (s, c) = rot.sin_cos();
        let (sx, sy) = (c * wo[0] - s * wo[1], s * wo[0] + c * wo[1]);
        let (k, f) = bracket(&self.d.illumination_deg, theta_i);
        let d0 = self.density(k, sx, sy);
        let d1 = if ni > 1 {
            self.density(k + 1, sx, sy)
        } else {
            d0
        };
        let mut rgb = [0.0; 3];
        for ch in 0..3 {
            rgb[ch] = d0[ch] * (1.0 - f) + d1[ch] * f;
        }
        if let Some(pk) = &self.paper {
            for (l, wl) in self.w.iter().enumerate() {
                let v = pk[l] * self.t_of(l, theta_i) * self.t_of(l, theta_o);
                for ch in 0..3 {
                    rgb[ch] += wl[ch] * v;
                }
            }
        }
        rgb
    }

    /// The specular (0,0) order's reflectance at polar angle `theta` (deg),
    /// coherent plus incoherent, linear sRGB; interpolated between the
    /// angles solved from above, held beyond them.
    pub fn specular(&self, theta: f64) -> [f64; 3] {
        let above = &self.d.above_deg;
        let (k, f) = bracket(above, theta);
        let r = |l: usize, a: usize| self.d.specular[[l, a]];
        let mut rgb = [0.0; 3];
        for (l, wl) in self.w.iter().enumerate() {
            let v = if above.len() == 1 {
                r(l, 0)
            } else {
                r(l, k) * (1.0 - f) + r(l, k + 1) * f
            };
            for ch in 0..3 {
                rgb[ch] += wl[ch] * v;
            }
        }
        rgb
    }
}

/// The MERL binary file of an appearance result.
pub fn encode(a: &Appearance) -> Result<Vec<u8>, MerlError> {
    let brdf = RgbBrdf::new(a)?;
    let n = N_TH * N_TD * N_PD;
    let mut out = vec![0.0f64; 3 * n];
    for ih in 0..N_TH {
        for id in 0..N_TD {
            for ip in 0..N_PD {
                let (wi, wo) = directions(ih, id, ip);
                if wi[2] <= 0.0 || wo[2] <= 0.0 {
                    continue;
                }
                let rgb = brdf.eval(wi, wo);
                let idx = ip + N_PD * (id + N_TD * ih);
                for ch in 0..3 {
                    out[ch * n + idx] = rgb[ch].max(0.0) / SCALE[ch];
                }
            }
        }
    }
    let mut bytes = Vec::with_capacity(12 + 8 * out.len());
    for d in [N_TH as i32, N_TD as i32, N_PD as i32] {
        bytes.extend_from_slice(&d.to_le_bytes());
    }
    for v in out {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    Ok(bytes)
}

/// Read back one value of a MERL file (as the MERL reference reader does):
/// the BRDF (1/sr) in RGB at bin (ih, id, ip).
pub fn lookup(bytes: &[u8], ih: usize, id: usize, ip: usize) -> Option<[f64; 3]> {
    let n = N_TH * N_TD * N_PD;
    if bytes.len() != 12 + 24 * n {
        return None;
    }
    let idx = ip + N_PD * (id + N_TD * ih);
    let mut c = [0.0; 3];
    for (ch, v) in c.iter_mut().enumerate() {
        let o = 12 + 8 * (ch * n + idx);
        *v = f64::from_le_bytes(bytes[o..o + 8].try_into().ok()?) * SCALE[ch];
    }
    Some(c)
}

/// The (θi, θo, Δφ) in degrees of a MERL bin centre (for tests and users).
pub fn bin_angles(ih: usize, id: usize, ip: usize) -> (f64, f64, f64) {
    let (wi, wo) = directions(ih, id, ip);
    let ti = wi[2].clamp(-1.0, 1.0).acos().to_degrees();
    let to = wo[2].clamp(-1.0, 1.0).acos().to_degrees();
    let dphi = (wo[1].atan2(wo[0]) - wi[1].atan2(wi[0])).to_degrees();
    (ti, to, dphi)
}
