//! A sparkle texture's numbers (METHOD §10): a patch of the panel seen in
//! resolution cells, each cell the paint's base colour plus the glints it
//! holds.
//!
//! Under a small light the glints per cell are Poisson with the mean of
//! [`super::sparkle`] (each flake layer its own population, independent);
//! each glint is one flake whose diameter is drawn from the layer's
//! distribution (normal, mean and spread as configured, cut at zero). A
//! glinting flake adds to its cell the luminance factor of
//! [`glint_factor`] times its reflectance's tristimulus values; the cell is
//! its average over the cell's area (the eye does not resolve the flake).
//! Under diffuse light no glint stands out (every cell holds the base
//! colour). Draws come from one seeded generator per tile, cell by cell in
//! row order: the same seed gives the same texture.

use super::montecarlo::poisson;
use crate::geometry::normal::standard_normal as normal;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::PI;

/// The glints of one flake layer in one tile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlintPopulation {
    /// Mean glints per resolution cell.
    pub per_cell: f64,
    /// Mean flake diameter, µm.
    pub diameter_um: f64,
    /// Spread (standard deviation) of the diameter, µm.
    pub diameter_sd_um: f64,
    /// Tristimulus values a glint adds to its cell per µm² of flake area
    /// (white `Y` = 100).
    pub xyz_per_um2: [f64; 3],
}

/// A tile of `width × height` resolution cells.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    pub width: usize,
    pub height: usize,
    /// Tristimulus values per cell, row by row (white `Y` = 100).
    pub xyz: Vec<[f64; 3]>,
    /// Glints drawn in the tile.
    pub glints: usize,
}

/// The luminance factor (`π L / E`, a white diffuser's is 1) a cell of
/// `cell_mm2` gains from one glinting flake of `flake_um2` and reflectance
/// 1, seen along the normal under light at `illumination_deg` in air,
/// through a surface of index `lacquer` that passes `transmission` of the
/// light each way (the product of both passes). The flake reflects the
/// light it intercepts into the cone about the view that the acceptance
/// half-angle `acceptance_rad` of its normal spans, `2γ` in the lacquer
/// (solid angle `π (2γ)²`, `n²` times larger in air): the flux
/// `E A_f cos(θ_t/2)/cos θ_t` (the refracted beam at `θ_t` meets a flake
/// tilted by `θ_t/2`) spread over that cone and the cell.
pub fn glint_factor(
    flake_um2: f64,
    cell_mm2: f64,
    acceptance_rad: f64,
    lacquer: f64,
    illumination_deg: f64,
    transmission: f64,
) -> f64 {
    let theta_t = (illumination_deg.to_radians().sin() / lacquer).asin();
    let flux = flake_um2 * 1e-6 * (0.5 * theta_t).cos() / theta_t.cos();
    let cone = lacquer * lacquer * PI * (2.0 * acceptance_rad).powi(2);
    PI * transmission * flux / (cone * cell_mm2)
}

/// A diameter of the population, redrawn until positive.
fn diameter(p: &GlintPopulation, rng: &mut impl Rng) -> f64 {
    for _ in 0..64 {
        let d = p.diameter_um + p.diameter_sd_um * normal(rng);
        if d > 0.0 {
            return d;
        }
    }
    p.diameter_um
}

/// The tile of `width × height` cells of `base_xyz` with the glints of
/// `populations` (none: diffuse light), drawn from `seed`.
pub fn texture(
    width: usize,
    height: usize,
    base_xyz: [f64; 3],
    populations: &[GlintPopulation],
    seed: u64,
) -> Texture {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut xyz = vec![base_xyz; width * height];
    let mut glints = 0;
    for cell in &mut xyz {
        for p in populations {
            if p.per_cell <= 0.0 {
                continue;
            }
            for _ in 0..poisson(p.per_cell, &mut rng) {
                let d = diameter(p, &mut rng);
                let area = 0.25 * PI * d * d;
                for (c, k) in cell.iter_mut().zip(&p.xyz_per_um2) {
                    *c += k * area;
                }
                glints += 1;
            }
        }
    }
    Texture {
        width,
        height,
        xyz,
        glints,
    }
}
