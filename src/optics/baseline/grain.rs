//! The single scatterer of the baselines, after the wave equation they
//! stand beside (METHOD §6): the scalar sphere for the Helmholtz equation,
//! Mie theory for Maxwell's equations.

use super::sphere::CrossSections;
use super::{mie, sphere};
use crate::config::Equation;
use num_complex::Complex64 as C64;

/// Which sphere solution gives a grain's cross sections and phase function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GrainModel {
    /// The scalar partial-wave sphere ([`sphere`]): `u` and `∂u/∂r`
    /// continuous, the single scatterer of the scalar Helmholtz equation.
    ScalarSphere,
    /// Mie theory ([`mie`]): the electromagnetic sphere, phase function of
    /// natural light `(|S_1|² + |S_2|²)/2`.
    VectorMie,
}

impl GrainModel {
    /// The grain of the baselines beside a solve of `equation`.
    pub fn of(equation: Equation) -> GrainModel {
        match equation {
            Equation::Helmholtz => GrainModel::ScalarSphere,
            Equation::Maxwell => GrainModel::VectorMie,
        }
    }

    /// The name in a result file.
    pub fn name(self) -> &'static str {
        match self {
            GrainModel::ScalarSphere => "scalar-sphere",
            GrainModel::VectorMie => "vector-mie",
        }
    }

    /// One line on what it is.
    pub fn description(self) -> &'static str {
        match self {
            GrainModel::ScalarSphere => {
                "each grain's equal-volume sphere by the scalar partial-wave series (u and du/dr \
                 continuous), the single scatterer of the scalar Helmholtz equation"
            }
            GrainModel::VectorMie => {
                "each grain's equal-volume sphere by Mie theory (Bohren & Huffman 1983), the \
                 single scatterer of Maxwell's equations; phase function of natural light \
                 (|S1|^2 + |S2|^2)/2"
            }
        }
    }

    /// σ_ext, σ_sca, σ_abs and g of a sphere of radius `a` and relative
    /// permittivity `eps_rel` in a host of wavenumber `k`.
    pub fn cross_sections(self, k: f64, eps_rel: C64, a: f64) -> CrossSections {
        match self {
            GrainModel::ScalarSphere => sphere::cross_sections(k, eps_rel, a),
            GrainModel::VectorMie => mie::cross_sections(k, eps_rel, a),
        }
    }

    /// The Legendre moments of its scattered intensity (`m_0 = σ_sca`).
    pub fn phase_moments(self, k: f64, eps_rel: C64, a: f64) -> Vec<f64> {
        match self {
            GrainModel::ScalarSphere => sphere::phase_moments(k, eps_rel, a),
            GrainModel::VectorMie => mie::phase_moments(k, eps_rel, a),
        }
    }
}
