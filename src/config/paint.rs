//! An effect paint, checked (METHOD §9): layers of lacquer from the top
//! down, each with ordinary pigments and flakes, on a ground; the spectrum,
//! the colour conditions and the sparkle's viewing conditions. A file with
//! a `[paint]` table describes a paint instead of a wave-optics layer; the
//! fast model of `optics::flakes` computes it.

use super::colour::{Illuminant, StandardObserver};
use super::ground::GroundReflectance;
use super::{GrainSize, Material, OutputSpec, Provenance, ReflectanceSpectrum};
use std::sync::Arc;

/// Default distance at which the sparkle is seen, mm (a panel at arm's
/// length).
pub const DEFAULT_VIEWING_DISTANCE_MM: f64 = 500.0;
/// Default illumination angles of the sparkle figures, degrees from the
/// normal (the view along the normal).
pub const DEFAULT_SPARKLE_ILLUMINATION_DEG: [f64; 3] = [15.0, 45.0, 75.0];
/// Default acceptance half-angle of a glint about the half vector, degrees
/// in the lacquer: about the half-angle a lamp of a few centimetres
/// subtends at the viewing distance, refracted.
pub const DEFAULT_ACCEPTANCE_DEG: f64 = 1.0;
/// Most layers of a paint.
pub const MAX_PAINT_LAYERS: usize = 8;
/// Largest flake volume fraction of a layer (flakes lie flat; beyond this
/// they overlap and the independent-flake model does not hold).
pub const MAX_FLAKE_FRACTION: f64 = 0.3;
/// Largest lacquer index difference between layers: the fast model takes
/// one lacquer index for the whole paint (its layers' boundaries do not
/// reflect).
pub const MAX_LACQUER_MISMATCH: f64 = 0.02;

/// A checked effect-paint file.
#[derive(Debug, Clone)]
pub struct PaintScene {
    pub provenance: Provenance,
    pub wavelengths_nm: Vec<f64>,
    pub illuminant: Illuminant,
    pub observer: StandardObserver,
    /// From the top down.
    pub layers: Vec<PaintLayerSpec>,
    pub ground: PaintGround,
    pub sparkle: SparkleSpec,
    pub model: PaintModel,
    pub output: OutputSpec,
}

/// One layer of the paint.
#[derive(Debug, Clone)]
pub struct PaintLayerSpec {
    pub name: String,
    pub thickness_um: f64,
    /// The lacquer: its real index is the paint's (within
    /// [`MAX_LACQUER_MISMATCH`] of the top layer's), its `k` absorbs.
    pub lacquer: Material,
    pub pigments: Vec<PaintPigment>,
    pub flakes: Option<FlakeSpec>,
}

/// Ordinary grains in a layer.
#[derive(Debug, Clone)]
pub struct PaintPigment {
    pub name: String,
    pub material: Material,
    pub volume_fraction: f64,
    pub diameter_nm: f64,
    pub size: GrainSize,
}

/// The flakes of a layer.
#[derive(Debug, Clone)]
pub struct FlakeSpec {
    pub volume_fraction: f64,
    pub diameter_um: f64,
    pub diameter_sd_um: f64,
    /// Standard deviation of the normals' tilt (Gaussian in angle).
    pub orientation_sd_deg: f64,
    pub diffraction: bool,
    pub reflector: ReflectorSpec,
}

impl FlakeSpec {
    /// The mean thickness of a flake, nm.
    pub fn thickness_nm(&self) -> f64 {
        match &self.reflector {
            ReflectorSpec::Metal { film, .. } => film.thickness_nm,
            ReflectorSpec::Spectrum { thickness_nm, .. } => *thickness_nm,
            ReflectorSpec::Coated { substrate, coating } => {
                substrate.thickness_nm + 2.0 * coating.thickness_nm
            }
        }
    }

    /// The mean of the squared diameter, µm² (the discs' mean area is
    /// `π ⟨D²⟩/4`).
    pub fn mean_square_diameter_um2(&self) -> f64 {
        self.diameter_um * self.diameter_um + self.diameter_sd_um * self.diameter_sd_um
    }

    /// The projected flake area per unit volume of lacquer when lying flat,
    /// 1/nm: volume fraction over the mean thickness.
    pub fn area_per_nm(&self) -> f64 {
        self.volume_fraction / self.thickness_nm()
    }
}

/// A film of a flake with a normal thickness distribution.
#[derive(Debug, Clone)]
pub struct FilmSpec {
    pub material: Material,
    pub thickness_nm: f64,
    pub thickness_sd_nm: f64,
}

/// What a flake is made of.
#[derive(Debug, Clone)]
pub enum ReflectorSpec {
    /// A metal film (aluminium) of a complex index.
    Metal { film: Box<FilmSpec> },
    /// An opaque flake of a measured reflectance spectrum.
    Spectrum {
        reflectance: Arc<ReflectanceSpectrum>,
        thickness_nm: f64,
    },
    /// An interference flake: coating / substrate / coating.
    Coated {
        substrate: Box<FilmSpec>,
        coating: Box<FilmSpec>,
    },
}

impl ReflectorSpec {
    /// `metal`, `spectrum` or `coated`.
    pub fn kind(&self) -> &'static str {
        match self {
            ReflectorSpec::Metal { .. } => "metal",
            ReflectorSpec::Spectrum { .. } => "spectrum",
            ReflectorSpec::Coated { .. } => "coated",
        }
    }
}

/// What the paint lies on.
#[derive(Debug, Clone)]
pub enum PaintGround {
    Black,
    /// A diffuse ground in optical contact with the lowest layer.
    Lambertian(GroundReflectance),
    /// A flat metal (or any medium) of a complex index.
    Metal(Box<Material>),
}

impl PaintGround {
    /// How a caption names it.
    pub fn describe(&self) -> String {
        match self {
            PaintGround::Black => "a black ground".into(),
            PaintGround::Lambertian(g) => format!("a diffuse ground ({g})"),
            PaintGround::Metal(m) => format!("a metal ground ({m})"),
        }
    }
}

/// The sparkle's viewing conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct SparkleSpec {
    pub viewing_distance_mm: f64,
    pub illumination_deg: Vec<f64>,
    pub acceptance_deg: f64,
    /// Seed of the sparkle texture's glints.
    pub seed: u64,
}

/// Resolution of the fast model; None: the model's default.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PaintModel {
    pub trapped_nodes: Option<usize>,
    pub escape_nodes: Option<usize>,
    pub max_terms: Option<usize>,
}
