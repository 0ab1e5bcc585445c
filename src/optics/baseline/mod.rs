//! Optics — the classical baseline beside the wave solution: Kubelka–Munk
//! with Saunderson's correction (METHOD §6, "Kubelka–Munk baseline").
//!
//! The industry's two-flux picture of the same scene, for showing where
//! radiative transfer and the wave solution part:
//! 1. **Single scatterer** ([`sphere`]): each pigment grain is replaced by
//!    the sphere of equal volume (radius `d/2`, `d` = `diameter_nm`, the
//!    nominal size: the size distribution, the shape and any clusters are
//!    not seen) in the binder (real index `n_b`). Its cross sections and
//!    asymmetry parameter `g` come from the *scalar* partial-wave solution
//!    at the wavelength in the binder `λ/n_b` with relative permittivity
//!    `ε_s/ε_b`, `ε_s = (n + ik)²`: the solver solves the scalar Helmholtz
//!    equation, so the scalar sphere is its consistent single scatterer.
//! 2. **Independent scattering**: number density `N_s = f_s / (π d³/6)`,
//!    absorption coefficient `μa = Σ N_s σ_abs,s` and reduced scattering
//!    coefficient `μs' = Σ N_s σ_sca,s (1 − g_s)`: the grains scatter as if
//!    alone (no near-field coupling, no correlated positions, no dependent
//!    scattering at high PVC). A molecular (dissolved) pigment scatters
//!    nothing and absorbs as its dilute limit `f_s k₀ Im ε_s / n_b` (the
//!    small-sphere `σ_abs = k V Im(ε_s/ε_b)` per volume), so the layer is
//!    Beer's law.
//! 3. **Diffuse light**: `K = 2 μa`, `S = (3/4) μs'` — the common conversion
//!    of the diffusion approximation (light inside fully diffuse, mean path
//!    through a slab twice its thickness; S from matching the diffusion
//!    equation's albedo) — and the KM reflectance of the layer of thickness
//!    `X` on the Lambertian paper `R_g` ([`km::reflectance`]).
//! 4. **Surface** (Saunderson, [`km::saunderson`]): `r_e` the unpolarised
//!    Fresnel reflectance of the flat binder surface from air at the
//!    geometry's directed angle (45° for 45°/0°, 8° for d/8°), `r_i` the
//!    Fresnel reflectance from inside averaged over a Lambertian hemisphere
//!    (computed). 45°/0° and d/8° SCE leave `r_e` itself out (specular
//!    excluded), d/8° SCI includes it.
//! 5. **Colour**: the spectrum on the spectral proxy's fine grid, through
//!    the scene's observer and illuminant, CIELAB per geometry, and
//!    CIEDE2000 to the wave solution's colour in the same geometry.
//!
//! The binder's own absorption and the layer's relief are not in the model.
//! Nor is the wave scene's boundary under the layer: there the binder ends
//! in vacuum above the paper (METHOD §1), here the paper is in optical
//! contact with the binder, as Saunderson's correction assumes — the main
//! reason the two colours differ for a weak layer (METHOD §6).

pub mod km;
pub mod sphere;

use crate::config::Measurement;
use crate::optics::colour::{self, ColourError, Observer};
use num_complex::Complex64 as C64;
use std::f64::consts::PI;

/// One pigment as the baseline sees it.
#[derive(Debug, Clone)]
pub struct BaselineSpecies {
    /// Volume fraction of the layer.
    pub volume_fraction: f64,
    /// Diameter of the equal-volume sphere, nm; 0 for a dissolved pigment.
    pub diameter_nm: f64,
    /// Permittivity `(n + ik)²` at each wavelength of the grid.
    pub eps: Vec<C64>,
}

/// The layer and backing the baseline is computed for.
#[derive(Debug, Clone)]
pub struct BaselineInput {
    /// The fine grid, nm.
    pub wavelengths_nm: Vec<f64>,
    pub binder_index: f64,
    pub thickness_nm: f64,
    pub paper_albedo: f64,
    pub species: Vec<BaselineSpecies>,
}

/// The KM coefficients at one wavelength (1/nm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KmCoefficients {
    /// Absorption coefficient μa.
    pub mu_a: f64,
    /// Reduced scattering coefficient μs'.
    pub mu_s_reduced: f64,
    /// `K = 2 μa`.
    pub k: f64,
    /// `S = (3/4) μs'`.
    pub s: f64,
}

/// μa, μs', K and S of the layer at wavelength index `l` of the grid.
pub fn coefficients(input: &BaselineInput, l: usize) -> KmCoefficients {
    let lambda = input.wavelengths_nm[l];
    let nb = input.binder_index;
    let eps_b = nb * nb;
    let k0 = 2.0 * PI / lambda;
    let (mut mu_a, mut mu_s) = (0.0, 0.0);
    for sp in &input.species {
        let eps = sp.eps[l];
        if sp.diameter_nm <= 0.0 {
            mu_a += sp.volume_fraction * k0 * eps.im / nb;
            continue;
        }
        let d = sp.diameter_nm;
        let number = sp.volume_fraction / (PI * d.powi(3) / 6.0);
        let c = sphere::cross_sections(k0 * nb, eps / eps_b, d / 2.0);
        mu_a += number * c.absorption.max(0.0);
        mu_s += number * c.scattering * (1.0 - c.asymmetry);
    }
    KmCoefficients {
        mu_a,
        mu_s_reduced: mu_s,
        k: 2.0 * mu_a,
        s: 0.75 * mu_s,
    }
}

/// The KM body reflectance (inside the surface) on the grid.
pub fn body_reflectance(input: &BaselineInput) -> Vec<f64> {
    (0..input.wavelengths_nm.len())
        .map(|l| {
            let c = coefficients(input, l);
            km::reflectance(c.k, c.s, input.thickness_nm, input.paper_albedo)
        })
        .collect()
}

/// The reflectance factor an instrument in geometry `m` reads from a body
/// reflectance `r` under a binder surface of index `binder_index`.
pub fn measured_factor(m: Measurement, r: f64, binder_index: f64) -> f64 {
    let r_i = km::internal_reflectance(binder_index);
    match m {
        Measurement::FortyFiveZero => {
            km::saunderson_excluded(r, km::external_reflectance(binder_index, 45.0), r_i)
        }
        Measurement::DiffuseEightSce => {
            km::saunderson_excluded(r, km::external_reflectance(binder_index, 8.0), r_i)
        }
        Measurement::DiffuseEightSci => {
            km::saunderson(r, km::external_reflectance(binder_index, 8.0), r_i)
        }
    }
}

/// The baseline's colour in one measurement geometry.
#[derive(Debug, Clone)]
pub struct BaselineColour {
    pub geometry: Measurement,
    /// The fine grid, nm.
    pub spectrum_wavelengths_nm: Vec<f64>,
    /// Reflectance factor on that grid.
    pub reflectance_factor: Vec<f64>,
    /// CIELAB L*, a*, b*.
    pub lab: [f64; 3],
    /// CIEDE2000 to the wave solution's colour in the same geometry, when
    /// that was computed.
    pub de00_to_wave: Option<f64>,
}

/// The KM colours of every geometry in `measurements`; `wave` gives the wave
/// solution's CIELAB in a geometry, when known.
pub fn kubelka_munk(
    input: &BaselineInput,
    measurements: &[Measurement],
    wave: &dyn Fn(Measurement) -> Option<[f64; 3]>,
    observer: &Observer,
) -> Result<Vec<BaselineColour>, ColourError> {
    let body = body_reflectance(input);
    let mut out = Vec::with_capacity(measurements.len());
    for &m in measurements {
        let factor: Vec<f64> = body
            .iter()
            .map(|&r| measured_factor(m, r, input.binder_index))
            .collect();
        let xyz = colour::xyz_from_reflectance(observer, &input.wavelengths_nm, &factor)?;
        let lab = colour::xyz_to_lab(xyz, observer.white_xyz());
        out.push(BaselineColour {
            geometry: m,
            spectrum_wavelengths_nm: input.wavelengths_nm.clone(),
            reflectance_factor: factor,
            lab,
            de00_to_wave: wave(m).map(|w| colour::delta_e2000(lab, w)),
        });
    }
    Ok(out)
}
