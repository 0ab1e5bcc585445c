//! Export of the BRDF of layer + substrate as a Mitsuba 3 `measured` BSDF:
//! an RGL tensor file (`output::tensor_file`) in the parametrisation of
//! Dupuy & Jakob (2018), spectral, at the result's wavelengths.
//!
//! What the `measured` plugin does with the file, and what is written:
//! - it evaluates `spectra[φi, θi, λ, y, x]` by bilinear interpolation in a
//!   unit square (x, y) and linear interpolation in the parameters
//!   `phi_i`, `theta_i` (radians) and `wavelengths` (nm); the point (x, y) is
//!   the inverse of the `vndf` warp at the half vector's
//!   `(√(2θm/π), (φm − φi + π)/2π)`. `vndf` is written constant, so its
//!   warp is the identity and the grid nodes are the half vectors
//!   `θm = (π/2)(x)²`, `φm − φi = 2π y − π`, `x, y = k/(n − 1)`;
//! - at each node and solved wavelength, `spectra` holds the BRDF times
//!   `cos θo` (what Mitsuba's `eval` returns), with `jacobian = 0`, so no
//!   NDF factor is applied (`ndf`, `sigma` are written constant);
//! - `luminance` (used for importance sampling only) is the luminance of
//!   the same values in linear sRGB (D65), plus a small floor so every
//!   direction can be sampled;
//! - the layer is isotropic in azimuth (the ensemble is): `phi_i` has the
//!   two nodes −π, π holding the same data, so the plugin treats it as
//!   isotropic;
//! - `theta_i` nodes are every 5° to 85°, 89°, and the angles solved (so
//!   the piecewise-linear interpolation between solved angles is kept).
//!
//! **Simplifications**, beside those of the RGB BRDF it reuses
//! ([`RgbBrdf`], see `output::merl`): the specular (0,0) order is a delta
//! and is not in the table; the sample grid is uniform in the half-vector
//! parameters instead of following a fitted visible-normal distribution, so
//! the table's resolution is even over the hemisphere, which suits the
//! diffuse, smooth BRDF of a layer (a sharp lobe would want the RGL warp);
//! outside the solved wavelengths Mitsuba holds the nearest one.

use std::f64::consts::PI;

use super::merl::{BrdfData, MerlError, RgbBrdf};
use super::tensor_file::{self, Field, Values};

/// Nodes of the sample grid in `θm` (x) and `φm − φi` (y); the plugin
/// requires a square grid.
const N_X: usize = 64;
const N_Y: usize = N_X;

/// The BRDF per solved wavelength, evaluated three wavelengths at a time
/// through [`RgbBrdf::with_channels`] with one-hot channel weights.
pub struct SpectralBrdf {
    parts: Vec<RgbBrdf>,
    n: usize,
}

impl SpectralBrdf {
    pub fn new(d: &BrdfData) -> Result<Self, MerlError> {
        let n = d.wavelengths_nm.len();
        let parts = (0..n.div_ceil(3))
            .map(|p| {
                let w = (0..n)
                    .map(|l| std::array::from_fn(|c| f64::from(u8::from(l == 3 * p + c))))
                    .collect();
                RgbBrdf::with_channels(d.clone(), w)
            })
            .collect::<Result<_, _>>()?;
        Ok(SpectralBrdf { parts, n })
    }

    /// The diffuse BRDF (1/sr) per wavelength, directions as
    /// [`RgbBrdf::eval`].
    pub fn eval(&self, wi: [f64; 3], wo: [f64; 3]) -> Vec<f64> {
        let mut out: Vec<f64> = self.parts.iter().flat_map(|b| b.eval(wi, wo)).collect();
        out.truncate(self.n);
        out
    }
}

fn unit(theta: f64, phi: f64) -> [f64; 3] {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

/// The outgoing direction mirrored from `wi` about the half vector of a
/// grid node (x, y) (φi = 0).
fn node_wo(wi: [f64; 3], x: usize, y: usize) -> [f64; 3] {
    let u = x as f64 / (N_X - 1) as f64;
    let tm = u * u * PI / 2.0;
    let pm = 2.0 * PI * (y as f64 / (N_Y - 1) as f64) - PI;
    let m = unit(tm, pm);
    let d = 2.0 * (m[0] * wi[0] + m[1] * wi[1] + m[2] * wi[2]);
    std::array::from_fn(|k| d * m[k] - wi[k])
}

/// The illumination angles of the file (deg).
fn theta_i_nodes(d: &BrdfData) -> Vec<f64> {
    let mut t: Vec<f64> = (0..=17).map(|k| 5.0 * k as f64).collect();
    t.push(89.0);
    t.extend(d.illumination_deg.iter().chain(&d.above_deg).copied());
    t.retain(|v| (0.0..=89.0).contains(v));
    t.sort_by(f64::total_cmp);
    t.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    t
}

/// The tensor file of the BRDF `d`, with `description` (e.g. the scene's
/// name) stored in it.
pub fn encode(d: &BrdfData, description: &str) -> Result<Vec<u8>, MerlError> {
    let nl = d.wavelengths_nm.len();
    if nl < 2 {
        return Err(MerlError::NoData);
    }
    let spectral = SpectralBrdf::new(d)?;
    let rgb = RgbBrdf::from_data(d.clone())?;
    let ti = theta_i_nodes(d);
    let (nt, cell) = (ti.len(), N_X * N_Y);
    let mut spectra = vec![0f32; nt * nl * cell];
    let mut lum = vec![0f32; nt * cell];
    for (it, &t) in ti.iter().enumerate() {
        let wi = unit(t.to_radians(), 0.0);
        let mut y_of = vec![0.0; cell];
        for y in 0..N_Y {
            for x in 0..N_X {
                let wo = node_wo(wi, x, y);
                if wo[2] <= 0.0 {
                    continue;
                }
                let k = y * N_X + x;
                for (l, f) in spectral.eval(wi, wo).into_iter().enumerate() {
                    spectra[(it * nl + l) * cell + k] = (f * wo[2]) as f32;
                }
                let c = rgb.eval(wi, wo);
                y_of[k] = (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]).max(0.0) * wo[2];
            }
        }
        let floor = 1e-3 * y_of.iter().sum::<f64>() / cell as f64 + 1e-9;
        for (k, v) in y_of.iter().enumerate() {
            lum[it * cell + k] = (v + floor) as f32;
        }
    }
    let twice = |v: Vec<f32>| [v.clone(), v].concat();
    let ones = |n: usize| Values::F32(vec![1.0; n]);
    let f32s = |v: Vec<f64>| Values::F32(v.into_iter().map(|x| x as f32).collect());
    let fields = [
        (
            "description",
            vec![description.len()],
            Values::U8(description.as_bytes().to_vec()),
        ),
        ("jacobian", vec![1], Values::U8(vec![0])),
        ("phi_i", vec![2], f32s(vec![-PI, PI])),
        (
            "theta_i",
            vec![nt],
            f32s(ti.iter().map(|t| t.to_radians()).collect()),
        ),
        ("wavelengths", vec![nl], f32s(d.wavelengths_nm.clone())),
        ("ndf", vec![2, 2], ones(4)),
        ("sigma", vec![2, 2], ones(4)),
        ("vndf", vec![2, nt, 2, 2], ones(2 * nt * 4)),
        ("luminance", vec![2, nt, N_Y, N_X], Values::F32(twice(lum))),
        (
            "spectra",
            vec![2, nt, nl, N_Y, N_X],
            Values::F32(twice(spectra)),
        ),
    ];
    let fields: Vec<Field> = fields
        .into_iter()
        .map(|(name, shape, v)| Field::new(name, &shape, v).ok_or(MerlError::NoData))
        .collect::<Result<_, _>>()?;
    Ok(tensor_file::encode(&fields))
}

/// Reference evaluations of the same BRDF at directions between the grid
/// nodes, for checking a renderer's reading of the file: CSV with
/// `theta_i_deg`, `phi_i_deg`, `theta_o_deg`, `phi_o_deg`, `wavelength_nm`,
/// `brdf_per_sr` (the diffuse BRDF) and `brdf_cos` (times cos θo, what
/// Mitsuba's `eval` returns).
pub fn reference_samples(d: &BrdfData) -> Result<String, MerlError> {
    let spectral = SpectralBrdf::new(d)?;
    let mut csv = super::export::Csv::new(&[
        "theta_i_deg",
        "phi_i_deg",
        "theta_o_deg",
        "phi_o_deg",
        "wavelength_nm",
        "brdf_per_sr",
        "brdf_cos",
    ]);
    for ti in [12.0, 33.0, 47.0, 61.0] {
        for pi in [0.0, 70.0] {
            for to in [8.0, 24.0, 41.0, 58.0, 72.0] {
                for dp in [20.0, 95.0, 160.0, 200.0] {
                    let po: f64 = pi + dp;
                    let wi = unit(f64::to_radians(ti), f64::to_radians(pi));
                    let wo = unit(f64::to_radians(to), po.to_radians());
                    for (l, f) in spectral.eval(wi, wo).into_iter().enumerate() {
                        csv.row(
                            [ti, pi, to, po, d.wavelengths_nm[l], f, f * wo[2]]
                                .iter()
                                .map(|v| v.to_string())
                                .collect(),
                        );
                    }
                }
            }
        }
    }
    Ok(csv.into_text())
}
