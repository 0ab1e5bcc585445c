//! Effect pigments: metallic and pearlescent flakes in a multilayer paint
//! (METHOD §10).
//!
//! - [`thin_film`]: a flat multilayer's reflectance and transmittance by the
//!   transfer matrix in s and p;
//! - [`reflector`]: one flake's reflectance and transmittance against the
//!   local angle (metal, measured spectrum, or an interference flake averaged
//!   over its thickness distributions);
//! - [`normals`]: the orientation distribution of the normals `D(m)` and the
//!   quadrature over it.

pub mod kernel;
pub mod multiangle;
pub mod normals;
pub mod paint;
pub mod reflector;
pub mod thin_film;
