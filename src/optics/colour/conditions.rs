//! The viewing conditions colour is computed for: CIE illuminant and CIE
//! standard observer, and the chromatic adaptation that shows a colour seen
//! under one illuminant on a D65 (sRGB) display.
//!
//! - **Illuminants.** D65 (the shipped CIE 1 nm table), D50 (the CIE 015
//!   daylight table at 5 nm, linearly interpolated onto the 1 nm grid and held
//!   at its 780 nm value up to 830 nm), A (the CIE formula for a Planckian
//!   radiator of 2856 K, evaluated on the grid). D50 with the 2° observer is
//!   the graphic-arts condition of ISO 13655 and ISO 3664.
//! - **Observers.** CIE 1931 2° and CIE 1964 10° colour-matching functions,
//!   both the official 1 nm tables, 360–830 nm.
//! - **Display.** sRGB's white is D65. A colour computed under another
//!   illuminant is carried to D65 by the linear Bradford transform (as ICC
//!   profiles do for D50), then through the IEC 61966-2-1 matrix; the white is
//!   then balanced to exactly (1, 1, 1) as for D65 (see [`super::Observer`]).

pub use crate::config::{Illuminant, StandardObserver};

/// CIE 1931 2° colour-matching functions, 360–830 nm at 1 nm (source in the file).
pub(super) const CMF_2DEG_CSV: &str = include_str!("../../../data/cie/cie1931_2deg_xyz_1nm.csv");
/// CIE 1964 10° colour-matching functions, 360–830 nm at 1 nm (source in the file).
pub(super) const CMF_10DEG_CSV: &str = include_str!("../../../data/cie/cie1964_10deg_xyz_1nm.csv");
/// CIE D65 relative spectral power, 300–830 nm at 1 nm (source in the file).
pub(super) const D65_CSV: &str = include_str!("../../../data/cie/cie_d65_1nm.csv");
/// CIE D50 relative spectral power, 300–780 nm at 5 nm (source in the file).
pub(super) const D50_CSV: &str = include_str!("../../../data/cie/cie_d50_5nm.csv");

/// The colour-matching functions' table of an observer.
pub(super) fn cmf_csv(observer: StandardObserver) -> &'static str {
    match observer {
        StandardObserver::TwoDegree => CMF_2DEG_CSV,
        StandardObserver::TenDegree => CMF_10DEG_CSV,
    }
}

/// Relative spectral power of CIE illuminant A at `wavelength_nm` (S(560) = 100),
/// by the CIE 015 formula with c₂ = 1.435e7 nm·K and T = 2848 K.
pub fn illuminant_a(wavelength_nm: f64) -> f64 {
    const C2_OVER_T: f64 = 1.435e7 / 2848.0;
    100.0 * (560.0 / wavelength_nm).powi(5) * (C2_OVER_T / 560.0).exp_m1()
        / (C2_OVER_T / wavelength_nm).exp_m1()
}

/// Linear interpolation of a table `(λ, S)` (increasing λ) at `wavelength_nm`,
/// held at its end values outside it.
pub(super) fn interpolate(table: &[(f64, f64)], wavelength_nm: f64) -> f64 {
    let n = table.len();
    if wavelength_nm <= table[0].0 {
        return table[0].1;
    }
    if wavelength_nm >= table[n - 1].0 {
        return table[n - 1].1;
    }
    let j = table.partition_point(|r| r.0 <= wavelength_nm) - 1;
    let ((w0, s0), (w1, s1)) = (table[j], table[j + 1]);
    s0 + (wavelength_nm - w0) / (w1 - w0) * (s1 - s0)
}

/// Bradford cone-response matrix (Lam 1985, as used by ICC and CIECAM97s).
const BRADFORD: [[f64; 3]; 3] = [
    [0.8951, 0.2664, -0.1614],
    [-0.7502, 1.7135, 0.0367],
    [0.0389, -0.0685, 1.0296],
];

/// The sRGB reference white (IEC 61966-2-1: D65 at x = 0.3127, y = 0.3290), Y = 1.
pub const SRGB_WHITE: [f64; 3] = [0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290];

pub(super) fn mat_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

fn mat_mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

fn inverse(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let c = |r0: usize, r1: usize, c0: usize, c1: usize| {
        (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det
    };
    [
        [c(1, 2, 1, 2), -c(0, 2, 1, 2), c(0, 1, 1, 2)],
        [-c(1, 2, 0, 2), c(0, 2, 0, 2), -c(0, 1, 0, 2)],
        [c(1, 2, 0, 1), -c(0, 2, 0, 1), c(0, 1, 0, 1)],
    ]
}

/// The Bradford transform carrying XYZ seen under the white `from` to the
/// corresponding XYZ under the white `to` (whites in any common scale).
pub fn bradford(from: [f64; 3], to: [f64; 3]) -> [[f64; 3]; 3] {
    let (s, d) = (mat_vec(&BRADFORD, from), mat_vec(&BRADFORD, to));
    let gain = [
        [d[0] / s[0], 0.0, 0.0],
        [0.0, d[1] / s[1], 0.0],
        [0.0, 0.0, d[2] / s[2]],
    ];
    mat_mul(&inverse(&BRADFORD), &mat_mul(&gain, &BRADFORD))
}
