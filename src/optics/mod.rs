//! Optics — from the solved field to what a person sees.
//!
//! Takes the solver's field (order amplitudes per solve) and gives:
//! - [`farfield`]: the Kirchhoff far field, order efficiencies, absorption,
//!   the energy balance, and the angular BRDF/BTDF tables;
//! - [`substrate`]: the Lambertian paper and the layer–paper inter-reflections;
//! - [`colour`]: CIE colorimetry (XYZ, CIELAB, CIEDE2000, sRGB);
//! - [`effective_medium`]: the homogeneous slab of the volume-averaged ε
//!   and the estimated error of replacing grains by it;
//! - [`appearance`]: ensemble means with standard errors, natural light and
//!   the colours of a result;
//! - [`flakes`]: effect pigments (metallic and pearlescent flakes) in a
//!   multilayer paint by adding–doubling in azimuthal Fourier terms, and
//!   multi-angle colour;
//! - [`baseline`]: classical colours of the same scene (Kubelka–Munk, and
//!   radiative transfer by adding–doubling) beside the wave solution's.
//!
//! Imports only from `config`, `geometry`, `raster` and `solver`.

pub mod appearance;
pub mod baseline;
pub mod colour;
pub mod effective_medium;
pub mod farfield;
pub mod flakes;
pub mod stack;
pub mod substrate;
