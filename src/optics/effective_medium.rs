//! The effective medium of a pigment layer: the homogeneous slab of the
//! volume-averaged permittivity `⟨ε⟩ = Σ f ε_s + (1 − Σ f) ε_b`, and the
//! estimated error of replacing grains by it.
//!
//! Takes plain numbers (volume fractions, largest grain diameters, the
//! permittivities per wavelength), never a scene; gives `⟨ε⟩` and the worst
//! estimated absolute error in R, T or A over a band of wavelengths and
//! incidence angles ([`airy::effective_medium_error`] at each), and whether
//! the grains lie beyond the size range where that estimate was measured.

use crate::solver::airy;
use num_complex::Complex64 as C64;

/// The volume-averaged permittivity `Σ f ε_s + (1 − Σ f) ε_b` of grains of
/// volume fractions `fractions` and permittivities `eps` in a binder of
/// permittivity `eps_binder` (the molecular-mixture slab).
pub fn volume_average(eps_binder: C64, fractions: &[f64], eps: &[C64]) -> C64 {
    let total: f64 = fractions.iter().sum();
    fractions
        .iter()
        .zip(eps)
        .fold(eps_binder * (1.0 - total), |acc, (f, e)| acc + e * *f)
}

/// One grain species as the error estimate sees it.
#[derive(Debug, Clone, Copy)]
pub struct GrainClass {
    /// Volume fraction of the species in the layer.
    pub volume_fraction: f64,
    /// Largest diameter a grain of the species can have, nm.
    pub max_diameter_nm: f64,
}

/// Size parameter `k0 d` of a grain of diameter `d` at wavelength `λ`.
pub fn size_parameter(diameter_nm: f64, wavelength_nm: f64) -> f64 {
    2.0 * std::f64::consts::PI / wavelength_nm * diameter_nm
}

/// Whether a size parameter lies beyond where the error estimate was
/// measured to hold (`k0 d >` [`airy::EFFECTIVE_MAX_SIZE_PARAMETER`]): single
/// grains scatter strongly there, so the estimate does not apply.
pub fn beyond_measured_size(size_parameter: f64) -> bool {
    size_parameter > airy::EFFECTIVE_MAX_SIZE_PARAMETER
}

/// The largest estimated error and where it occurs.
#[derive(Debug, Clone, Copy)]
pub struct WorstError {
    /// Estimated largest absolute error in R, T or A.
    pub error: f64,
    pub wavelength_nm: f64,
    pub polar_deg: f64,
}

/// The worst [`airy::effective_medium_error`] of a layer of `grains` in a
/// binder of permittivity `eps_binder`, `thickness_nm` thick, over every
/// wavelength and polar angle; `eps_at(λ)` gives the grains' permittivities
/// at a wavelength (in the order of `grains`). Ties go to the later
/// wavelength and angle.
pub fn worst_error<E>(
    grains: &[GrainClass],
    eps_binder: f64,
    thickness_nm: f64,
    wavelengths_nm: &[f64],
    polar_deg: &[f64],
    mut eps_at: impl FnMut(f64) -> Result<Vec<C64>, E>,
) -> Result<WorstError, E> {
    let mut worst = WorstError {
        error: 0.0,
        wavelength_nm: 0.0,
        polar_deg: 0.0,
    };
    for &lambda in wavelengths_nm {
        let eps = eps_at(lambda)?;
        let terms: Vec<airy::GrainTerm> = grains
            .iter()
            .zip(&eps)
            .map(|(g, e)| airy::GrainTerm {
                volume_fraction: g.volume_fraction,
                diameter_nm: g.max_diameter_nm,
                delta_eps: e - eps_binder,
            })
            .collect();
        for &p in polar_deg {
            let est = airy::effective_medium_error(&terms, eps_binder, thickness_nm, lambda, p);
            if est >= worst.error {
                worst = WorstError {
                    error: est,
                    wavelength_nm: lambda,
                    polar_deg: p,
                };
            }
        }
    }
    Ok(worst)
}
