//! An effect paint's TOML file as written (`[paint]` instead of `[layer]`):
//! serde structs mirroring the schema one to one, every table denying
//! unknown keys, units in the key names. `check` turns them into the
//! checked [`PaintScene`](super::paint::PaintScene).

use super::raw::{RawMaterial, RawOutput, RawRange, RawSize};
use serde::Deserialize;

/// The whole file of an effect paint.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPaintConfig {
    pub paint: RawPaint,
    pub output: Option<RawOutput>,
}

/// `[paint]`: the layers from the top down on a ground, the spectrum, the
/// colour conditions and the sparkle's viewing conditions.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPaint {
    pub wavelengths_nm: Option<Vec<f64>>,
    pub wavelength_range_nm: Option<RawRange>,
    pub illuminant: Option<String>,
    pub observer_deg: Option<i64>,
    #[serde(default)]
    pub layer: Vec<RawPaintLayer>,
    pub ground: RawPaintGround,
    pub sparkle: Option<RawSparkle>,
    /// Finer or coarser model: the lacquer's nodes and Fourier terms.
    pub model: Option<RawPaintModel>,
}

/// `[[paint.layer]]`: a lacquer of a thickness with ordinary pigments and
/// flakes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPaintLayer {
    pub name: String,
    pub thickness_um: f64,
    pub lacquer: RawMaterial,
    #[serde(default)]
    pub pigment: Vec<RawPaintPigment>,
    pub flakes: Option<RawFlakes>,
}

/// `[[paint.layer.pigment]]`: grains as the radiative-transfer baseline
/// sees them (Mie spheres of equal volume).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPaintPigment {
    pub name: String,
    pub material: RawMaterial,
    pub pvc: f64,
    pub diameter_nm: f64,
    pub size: Option<RawSize>,
}

/// `[paint.layer.flakes]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFlakes {
    pub volume_fraction: f64,
    pub diameter_um: f64,
    pub diameter_sd_um: Option<f64>,
    pub orientation_sd_deg: f64,
    /// Add the diffraction lobe of a disc of the mean diameter (default
    /// true).
    pub diffraction: Option<bool>,
    pub reflector: RawReflector,
}

/// `{ kind = "metal", material, thickness_nm, thickness_sd_nm }`,
/// `{ kind = "spectrum", csv, thickness_nm }` or
/// `{ kind = "coated", substrate = { … }, coating = { … } }`.
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RawReflector {
    Metal {
        material: RawMaterial,
        thickness_nm: f64,
        thickness_sd_nm: Option<f64>,
    },
    Spectrum {
        csv: String,
        thickness_nm: f64,
    },
    Coated {
        substrate: RawFilm,
        coating: RawFilm,
    },
}

/// One film of a coated flake.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFilm {
    pub material: RawMaterial,
    pub thickness_nm: f64,
    pub thickness_sd_nm: Option<f64>,
}

/// `[paint.ground]`: `{ kind = "black" }`, `{ kind = "white", albedo }`,
/// `{ kind = "paper", albedo }`, `{ kind = "csv", file }` or
/// `{ kind = "metal", material }`.
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RawPaintGround {
    Black {},
    White { albedo: Option<f64> },
    Paper { albedo: Option<f64> },
    Csv { file: String },
    Metal { material: RawMaterial },
}

/// `[paint.sparkle]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSparkle {
    pub viewing_distance_mm: Option<f64>,
    pub illumination_deg: Option<Vec<f64>>,
    pub acceptance_deg: Option<f64>,
    pub seed: Option<u64>,
}

/// `[paint.model]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPaintModel {
    pub trapped_nodes: Option<i64>,
    pub escape_nodes: Option<i64>,
    pub max_terms: Option<i64>,
}
