//! Effect pigments: metallic and pearlescent flakes in a multilayer paint
//! (METHOD §10).
//!
//! - [`thin_film`]: a flat multilayer's reflectance and transmittance by the
//!   transfer matrix in s and p;
//! - [`reflector`]: one flake's reflectance and transmittance against the
//!   local angle (metal, measured spectrum, or an interference flake averaged
//!   over its thickness distributions);
//! - [`normals`]: the orientation distribution of the normals `D(m)`, the
//!   quadrature over it and the diffraction lobe of small flakes;
//! - [`kernel`]: a layer's scattering per azimuthal Fourier term on the
//!   adding–doubling directions (flakes and ordinary pigments);
//! - [`paint`]: the fast model, layers added on a ground under the paint's
//!   surface, and its BRDF;
//! - [`air`]: the fast model's reflection at any air angles, linear between
//!   the nodes (for renderers and regular tables);
//! - [`montecarlo`]: the full model that checks it, ray tracing with
//!   explicit disc flakes;
//! - [`multiangle`]: the multi-angle geometries, their colours and the flop
//!   index;
//! - [`sparkle`]: Poisson glints per resolution cell and graininess;
//! - [`sparkle_texture`]: a patch of resolution cells with its glints drawn.

pub mod air;
pub mod kernel;
pub mod montecarlo;
pub mod multiangle;
pub mod normals;
pub mod paint;
pub mod reflector;
pub mod sparkle;
pub mod sparkle_texture;
pub mod thin_film;
