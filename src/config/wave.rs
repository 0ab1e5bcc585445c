//! Which wave equation a scene is solved with, and the incident light's
//! polarisation: what `[solver] equation` and `[illumination] polarisation`
//! may name (METHOD §9). The solver stage gives them their meaning; this
//! stage only knows the names, so that an unknown one is refused as the
//! scene is read.

/// The wave equation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Equation {
    /// The scalar Helmholtz equation: every flat surface reflects like
    /// s-polarised light; the fast approximation.
    #[default]
    Helmholtz,
    /// Maxwell's equations (the vector field, s and p polarisations).
    Maxwell,
}

impl Equation {
    pub fn name(self) -> &'static str {
        match self {
            Equation::Helmholtz => "helmholtz",
            Equation::Maxwell => "maxwell",
        }
    }
}

/// One linear polarisation of the incident plane wave, relative to its
/// plane of incidence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Linear {
    /// E perpendicular to the plane of incidence (TE).
    S,
    /// E in the plane of incidence (TM).
    P,
}

impl Linear {
    pub fn name(self) -> &'static str {
        match self {
            Linear::S => "s",
            Linear::P => "p",
        }
    }
}

/// The incident light's polarisation as a scene asks for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Polarisation {
    /// Natural light: the incoherent mean of s and p (powers, not
    /// amplitudes); two solves per incidence.
    #[default]
    Unpolarised,
    S,
    P,
}

impl Polarisation {
    pub fn name(self) -> &'static str {
        match self {
            Polarisation::Unpolarised => "unpolarised",
            Polarisation::S => "s",
            Polarisation::P => "p",
        }
    }

    /// The linear polarisations to solve for.
    pub fn components(self) -> &'static [Linear] {
        match self {
            Polarisation::Unpolarised => &[Linear::S, Linear::P],
            Polarisation::S => &[Linear::S],
            Polarisation::P => &[Linear::P],
        }
    }
}

/// How natural light is solved for in Maxwell's equations. The scene's
/// `"auto"` (the default) is random-phase for an ensemble of random
/// layers (generated grains, two realisations or more, or a target
/// uncertainty) and two solves otherwise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NaturalLight {
    /// s and p solved apart and their powers averaged: exact for every
    /// realisation, two solves per incidence.
    #[default]
    TwoSolves,
    /// One solve per incidence, lit by `(ŝ + e^{iφ} p̂)/√2` with a phase φ
    /// drawn per realisation and solve: its powers are natural light's plus
    /// a cross term between s and p that averages out over the ensemble
    /// like the grains' own randomness (and is counted in the colours'
    /// standard errors). For random layers only.
    RandomPhase,
}

impl NaturalLight {
    pub fn name(self) -> &'static str {
        match self {
            NaturalLight::TwoSolves => "two-solves",
            NaturalLight::RandomPhase => "random-phase",
        }
    }
}
