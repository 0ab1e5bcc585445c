//! Configuration: the scene file read, checked and turned into a [`Scene`].
//!
//! A scene is read from TOML into raw serde structs (`raw`, with
//! `deny_unknown_fields` and tagged enums, units in key names), then validated
//! into the checked [`Scene`] that every later stage consumes. Validation
//! errors name the file, the key and the allowed range. Pigment optical data
//! (built-in stand-in spectra and user CSV tables) live in [`materials`].
//! The solution methods' names (and whether a scene may use them) are
//! [`Method`]'s; the solver's registry gives each its implementation.

mod check;
pub mod colour;
pub mod ground;
pub mod h5file;
pub mod materials;
mod method;
pub mod paint;
mod raw;
mod raw_paint;
mod stack;
mod wave;

use std::path::{Path, PathBuf};

pub use check::{
    is_paint_text, load_scene, parse_paint, parse_scene, DEFAULT_ENERGY_BALANCE_LIMIT,
};
pub use colour::{Illuminant, Measurement, StandardObserver};
pub use ground::{
    GroundReflectance, ReflectanceSpectrum, SpectrumError, Substrate, DEFAULT_PAPER_ALBEDO,
    DEFAULT_WHITE_ALBEDO,
};
pub use materials::{Material, MaterialError, MaterialSource};
pub use method::Method;
pub use stack::{
    Stack, StackCoupling, StackLayer, DEFAULT_ESCAPE_DIRECTIONS, DEFAULT_TRAPPED_DIRECTIONS,
    MAX_STACK_DIRECTIONS, MAX_STACK_LAYERS, MAX_YULE_NIELSEN_N,
};
pub use wave::{Equation, Linear, NaturalLight, Polarisation};

/// Largest total pigment volume concentration a scene may ask for: what the
/// first-order dynamics packer reaches (spheres to ~55 %, rice grains 50 %).
pub const MAX_PVC: f64 = 0.55;

/// Everything that can go wrong while reading or checking a configuration.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{file}: cannot read: {source}")]
    Read {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{file}: {message}")]
    Parse { file: PathBuf, message: String },
    #[error("{file}: key `{key}`: {message}")]
    Invalid {
        file: PathBuf,
        key: String,
        message: String,
    },
    #[error("{file}: material `{material}`: {message}")]
    Material {
        file: PathBuf,
        material: String,
        message: String,
    },
}

/// The verbatim configuration and where it came from; travels with the results.
#[derive(Debug, Clone)]
pub struct Provenance {
    /// Path the scene was read from.
    pub path: PathBuf,
    /// The exact TOML text.
    pub text: String,
    /// Hex SHA-256 over what decides the results: the config's tables without
    /// `[output]`, canonically written (comments, layout and key order do not
    /// count), and the contents of every data file it references (pigment
    /// tables, structure files), so a changed input changes the hash and a
    /// moved study or another output folder does not.
    pub input_hash: String,
}

/// The layer: a binder slab `0 ≤ z ≤ thickness` holding pigment grains,
/// repeated periodically with period `fragment_x_nm × fragment_y_nm`.
#[derive(Debug, Clone)]
pub struct Layer {
    pub thickness_nm: f64,
    pub fragment_x_nm: f64,
    pub fragment_y_nm: f64,
    /// Real refractive index of the (transparent) binder.
    pub binder_index: f64,
    /// Grains may protrude through the top surface `z = 0` by up to this
    /// fraction of their diameter, `[0, MAX_RELIEF_FRACTION]` (0: flat).
    pub relief_fraction: f64,
    /// Hard-sphere Monte Carlo sweeps run on the packed grains (Brownian
    /// settling in the wet ink: equilibrium structure at the same density),
    /// `[0, MAX_EQUILIBRATE_SWEEPS]`, one sweep = one attempted move per
    /// grain; 0 (default): none.
    pub equilibrate_sweeps: u64,
    /// The binder's top surface.
    pub surface: Surface,
}

/// The binder's top surface (METHOD §3): where the binder ends and air
/// begins above the grains.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Surface {
    /// A plane at `z = 0` (a glossy, levelled binder): the grains stay below
    /// it, leaving a grain-poor binder skin at the same depth everywhere.
    Flat,
    /// The binder drapes over the topmost material at a film thickness
    /// `film_nm` (a binder-starved layer above the critical PVC): the
    /// surface is the grains' upper envelope offset by a ball of radius
    /// `film_nm`, and below it the binder fills every column.
    Conformal { film_nm: f64 },
    /// A random surface around `z = 0`: Gaussian heights of RMS `rms_nm`
    /// with a Gaussian correlation of length `correlation_nm`
    /// (`⟨h(0)h(r)⟩ = σ² e^{−r²/ℓ²}`), drawn anew for each realisation.
    Rough { rms_nm: f64, correlation_nm: f64 },
}

/// Largest `surface.film_nm`, as a fraction of the layer thickness.
pub const MAX_FILM_FRACTION: f64 = 0.5;
/// Largest `surface.rms_nm`, as a fraction of the layer thickness.
pub const MAX_ROUGH_RMS_FRACTION: f64 = 0.25;

/// Largest `layer.equilibrate_sweeps`.
pub const MAX_EQUILIBRATE_SWEEPS: u64 = 100_000;
/// Largest `layer.relief_fraction`.
pub const MAX_RELIEF_FRACTION: f64 = 0.5;
/// Largest relative `sigma` of a normal grain-size distribution.
pub const MAX_NORMAL_SIGMA: f64 = 0.3;
/// Largest `sigma` (of ln d) of a log-normal grain-size distribution.
pub const MAX_LOG_NORMAL_SIGMA: f64 = 0.5;
/// Largest `agglomeration.cluster_size`.
pub const MAX_CLUSTER_SIZE: usize = 10_000;
/// Most grains of one species a layer may hold (PVC × layer volume over the
/// grain volume): random addition places 450 000 in 6 s and 200 MB on two
/// cores, so this bounds the packing at a minute and a few GB; smaller
/// grains than this allows are far below the grid cell, where a dissolved
/// (molecular) pigment describes them.
pub const MAX_GRAINS: usize = 2_000_000;

/// Distribution of a pigment's effective diameter `d` (`diameter_nm`),
/// truncated at 3 standard deviations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GrainSize {
    Fixed,
    /// Mean `d`, relative standard deviation `sigma` (range `d (1 ± 3σ)`).
    Normal {
        sigma: f64,
    },
    /// Median `d`, standard deviation `sigma` of `ln d` (range `d e^{±3σ}`).
    LogNormal {
        sigma: f64,
    },
}

impl GrainSize {
    /// Largest diameter a grain of nominal diameter `d` can get.
    pub fn max_diameter(&self, d: f64) -> f64 {
        match *self {
            GrainSize::Fixed => d,
            GrainSize::Normal { sigma } => d * (1.0 + 3.0 * sigma),
            GrainSize::LogNormal { sigma } => d * (3.0 * sigma).exp(),
        }
    }
}

/// One pigment species in the layer.
#[derive(Debug, Clone)]
pub struct Species {
    pub name: String,
    pub material: Material,
    /// Target volume fraction of the layer (PVC share of this species), 0..1.
    pub volume_fraction: f64,
    /// Effective diameter in nm: the diameter of the sphere of equal volume
    /// (0 for [`GrainShape::Molecular`]).
    pub diameter_nm: f64,
    pub shape: GrainShape,
    pub orientation: GrainOrientation,
    /// Strength of the "magnetic" aligning torque (0: none).
    pub alignment_field: f64,
    /// Grain-size distribution around `diameter_nm`.
    pub size: GrainSize,
    /// Grains per seeded cluster (1: no agglomeration).
    pub cluster_size: usize,
}

/// Grain shape: a rigid cluster of spheres (METHOD §2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GrainShape {
    Sphere,
    /// Dissolved to molecular size: the layer is the homogeneous slab with
    /// the volume-averaged ε (METHOD §7's molecular-mixture limit).
    Molecular,
    /// Equal spheres on the axis; `aspect` = length / diameter.
    Cylinder {
        aspect: f64,
        spheres: usize,
    },
    /// Spheres on the axis whose radii shrink towards both ends.
    Rice {
        aspect: f64,
        spheres: usize,
    },
}

/// How grain axes are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GrainOrientation {
    Random,
    InPlane,
    Perpendicular,
}

/// Grid of the refractive-index raster and of the solver.
#[derive(Debug, Clone, Copy)]
pub struct GridSpec {
    pub nx: usize,
    pub ny: usize,
    pub nz: usize,
    /// The permittivity of voxels a grain surface cuts.
    pub voxel_permittivity: VoxelPermittivity,
}

/// How a voxel cut by a grain surface sees its two media (METHOD §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VoxelPermittivity {
    /// Anisotropic in Maxwell's equations, the average in the scalar one
    /// (the default).
    #[default]
    Auto,
    /// The volume average `Σ f_i ε_i` for every field direction.
    Average,
    /// The average along the surface and the harmonic mean `1/Σ f_i/ε_i`
    /// along its normal (Maxwell only).
    Anisotropic,
}

impl VoxelPermittivity {
    /// Whether cut voxels are anisotropic in a solve of `equation`.
    pub fn anisotropic(self, equation: Equation) -> bool {
        match self {
            VoxelPermittivity::Auto => equation == Equation::Maxwell,
            VoxelPermittivity::Average => false,
            VoxelPermittivity::Anisotropic => true,
        }
    }

    /// The name of what a solve of `equation` uses, for plans and notes.
    pub fn describe(self, equation: Equation) -> &'static str {
        if self.anisotropic(equation) {
            "anisotropic (average along the grain surface, harmonic mean across it)"
        } else {
            "volume average"
        }
    }
}

/// How the solver stores its fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Precision {
    /// Complex f64 everywhere (default).
    #[default]
    F64,
    /// Fields stored as complex f32 (half the memory); every operator
    /// application, inner product and norm runs in f64.
    F32,
}

impl Precision {
    /// `if_f64` or `if_f32`, by storage.
    pub fn select<T>(self, if_f64: T, if_f32: T) -> T {
        match self {
            Precision::F64 => if_f64,
            Precision::F32 => if_f32,
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        })
    }
}

/// The background medium of the iterative solvers' Green's operator
/// (METHOD §4). Both give the same discrete solution; they differ in how
/// many operator applications reach it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Background {
    /// The binder slab shifted to `ε_r + iε_s` with the convergent-Born-series
    /// preconditioner (Osnabrugge et al. 2016).
    Binder,
    /// The layer's mean permittivity ⟨ε⟩ (over every voxel), unpreconditioned;
    /// time-marching, which needs the CBS shift to converge, keeps `Binder`.
    Mean,
}

impl Background {
    /// What a scene without `solver.background` gets.
    pub const DEFAULT: Background = Background::Mean;

    /// The name scenes use.
    pub fn name(self) -> &'static str {
        match self {
            Background::Binder => "binder",
            Background::Mean => "mean",
        }
    }
}

impl Default for Background {
    fn default() -> Self {
        Background::DEFAULT
    }
}

impl std::fmt::Display for Background {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Solver settings.
#[derive(Debug, Clone, Copy)]
pub struct SolverSpec {
    /// The wave equation: scalar Helmholtz (the fast approximation) or
    /// Maxwell's.
    pub equation: Equation,
    /// The incident light's polarisation (Maxwell only; the scalar wave is
    /// always `Unpolarised`, which it treats as s).
    pub polarisation: Polarisation,
    /// How natural light is solved for (Maxwell, unpolarised).
    pub natural_light: NaturalLight,
    pub method: Method,
    /// Target relative residual.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Field storage.
    pub precision: Precision,
    /// Background medium of the Krylov methods' Green's operator.
    pub background: Background,
    /// Largest absolute error in R, T or A accepted from replacing a grain
    /// layer by the homogeneous slab of the volume-averaged ε (closed form,
    /// no solve) when the measured estimate allows it; 0 never does.
    pub effective_medium_tolerance: f64,
    /// Largest |ΣR + ΣT + A − 1| a solve may leave: one whose balance is
    /// worse at `tolerance` is solved again to a tenth of it.
    pub energy_balance_limit: f64,
}

impl SolverSpec {
    /// The linear polarisations solved per incidence: `None` for the scalar
    /// wave (one solve), else Maxwell's (natural light: s and p).
    pub fn polarisations(&self) -> Option<&'static [Linear]> {
        match self.equation {
            Equation::Helmholtz => None,
            Equation::Maxwell => Some(self.polarisation.components()),
        }
    }

    /// Whether natural light is solved once per incidence at a random
    /// relative phase of s and p (Maxwell, unpolarised, `random-phase`).
    pub fn random_phase(&self) -> bool {
        self.equation == Equation::Maxwell
            && self.polarisation == Polarisation::Unpolarised
            && self.natural_light == NaturalLight::RandomPhase
    }

    /// Wave solves per incidence of a grid layer: 1 for the scalar wave and
    /// random-phase natural light, else one per linear polarisation.
    pub fn solves_per_incidence(&self) -> usize {
        if self.random_phase() {
            1
        } else {
            self.polarisations().map_or(1, <[Linear]>::len)
        }
    }
}

/// One direction of incidence (from above, in vacuum).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Incidence {
    pub polar_deg: f64,
    pub azimuth_deg: f64,
}

/// Where results go.
#[derive(Debug, Clone)]
pub struct OutputSpec {
    pub dir: PathBuf,
    /// Base name of the result files (`<name>.h5`, `<name>.png`).
    pub name: String,
}

/// A body of an explicit structure (nm; z = 0 is the top of the layer,
/// periodic in x and y).
#[derive(Debug, Clone, PartialEq)]
pub enum Body {
    /// Disjoint axis-aligned boxes `[min_nm, max_nm]`, one body: the cells
    /// of one material in a layered structure (`kind = "layers"`).
    Boxes {
        boxes: Vec<[[f64; 3]; 2]>,
    },
    /// The full fragment between two depths.
    Slab {
        z_nm: [f64; 2],
    },
    /// An axis-aligned box.
    Box {
        min_nm: [f64; 3],
        max_nm: [f64; 3],
    },
    Sphere {
        center_nm: [f64; 3],
        radius_nm: f64,
    },
    /// A circular cylinder along a coordinate axis (0 = x, 1 = y, 2 = z).
    Cylinder {
        center_nm: [f64; 3],
        radius_nm: f64,
        length_nm: f64,
        axis: usize,
    },
}

/// One body of an explicit structure and its material.
#[derive(Debug, Clone)]
pub struct Primitive {
    pub body: Body,
    pub material: Material,
}

/// The layer given explicitly: for users with measured structures,
/// and validation.
#[derive(Debug, Clone)]
pub enum Structure {
    /// Bodies in the binder; a later body replaces earlier ones where they
    /// overlap.
    Primitives(Vec<Primitive>),
    /// A permittivity grid from an HDF5 file (resolved path): datasets
    /// `eps_re`, `eps_im` of shape (nz, ny, nx) for every wavelength, or
    /// (L, nz, ny, nx) with `wavelengths_nm` (L) covering the scene's.
    Hdf5(PathBuf),
}

/// Which appearance products a scene asks for; each one decides which solves
/// and stages run (see `pipeline::plan`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Products {
    /// Binned diffuse BRDF table and the specular split.
    pub brdf: bool,
    /// Binned BTDF table.
    pub btdf: bool,
    /// The colour tile of METHOD §6 (natural-light strip + BRDF square).
    pub tile: bool,
    /// The BRDF exported in MERL's binary format (RGB, isotropic).
    pub merl: bool,
    /// A rendered preview: a sphere of layer + substrate under one light
    /// and a white sky (`<name>-preview.png`).
    pub preview: bool,
}

/// How the far field becomes appearance.
#[derive(Debug, Clone)]
pub struct Appearance {
    /// Polar viewing angles (deg, increasing): the tile's rows.
    pub viewing_deg: Vec<f64>,
    pub products: Products,
    /// Cell of the angular BRDF/BTDF table in projected direction
    /// coordinates `sin θ (cos φ, sin φ)`; `None`: 2 λ_max / min(Lx, Ly).
    pub brdf_cell: Option<f64>,
    /// Gauss–Legendre nodes in cos θ for hemispherical integrals.
    pub quadrature_points: usize,
    /// CIE illuminant and standard observer of every colour (default D50,
    /// 2°: ISO 13655, the graphic-arts condition).
    pub illuminant: Illuminant,
    pub observer: StandardObserver,
    /// Measurement geometries reported with the tile (default all three:
    /// 45°/0°, d/8° SCI and SCE); each adds its angles to the solves from above.
    pub measurements: Vec<Measurement>,
    /// Classical models whose colours are reported beside the wave
    /// solution's (`baseline = "kubelka-munk"` or a list of names), in the
    /// order given; empty: none.
    pub baseline: Vec<Baseline>,
}

/// A classical colour model computed from the same scene (METHOD §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Baseline {
    /// Kubelka–Munk two-flux reflectance on the paper with Saunderson's
    /// surface correction, from the grains' cross sections (the scalar
    /// sphere's beside the Helmholtz equation, Mie's beside Maxwell's).
    KubelkaMunk,
    /// The same two-flux body on the wave scene's boundary: the binder's
    /// lower surface and an air gap before the paper, Fresnel surfaces of
    /// the solver's equation.
    KubelkaMunkScene,
    /// Radiative transfer by adding–doubling with the wave scene's boundary.
    AddingDoubling,
    /// Radiative transfer by adding–doubling with the paper in optical
    /// contact with the binder (Saunderson's assumption).
    AddingDoublingContact,
}

impl Baseline {
    /// Every model, in the order of the documentation.
    pub const ALL: [Baseline; 4] = [
        Baseline::KubelkaMunk,
        Baseline::KubelkaMunkScene,
        Baseline::AddingDoubling,
        Baseline::AddingDoublingContact,
    ];

    /// The name in a scene file.
    pub fn name(self) -> &'static str {
        match self {
            Baseline::KubelkaMunk => "kubelka-munk",
            Baseline::KubelkaMunkScene => "kubelka-munk-scene",
            Baseline::AddingDoubling => "adding-doubling",
            Baseline::AddingDoublingContact => "adding-doubling-contact",
        }
    }

    /// The model of a scene-file name.
    pub fn from_name(name: &str) -> Option<Baseline> {
        Baseline::ALL.into_iter().find(|b| b.name() == name)
    }

    /// Prefix of the model's columns in a study's colours.csv
    /// (`km_L_star`, `ad_L_star`, …).
    pub fn column_prefix(self) -> &'static str {
        match self {
            Baseline::KubelkaMunk => "km",
            Baseline::KubelkaMunkScene => "km_scene",
            Baseline::AddingDoubling => "ad",
            Baseline::AddingDoublingContact => "ad_contact",
        }
    }

    /// One line on what the model assumes (for the plan).
    pub fn summary(self) -> &'static str {
        match self {
            Baseline::KubelkaMunk => {
                "two-flux, K = 2 μa, S = 3/4 μs'; Saunderson's surface, paper in optical contact"
            }
            Baseline::KubelkaMunkScene => {
                "two-flux, K = 2 μa, S = 3/4 μs'; the equation's Fresnel surfaces, air gap over the paper"
            }
            Baseline::AddingDoubling => {
                "radiative transfer (adding–doubling, phase function, δ-M); the equation's \
                 Fresnel surfaces with total internal reflection, air gap over the paper"
            }
            Baseline::AddingDoublingContact => {
                "radiative transfer (adding–doubling, phase function, δ-M); the equation's \
                 Fresnel top surface, paper in optical contact"
            }
        }
    }
}

/// `realisations = { target_de00, max, min }`: realisations are added (at
/// least `min`, at most the scene's `realisations`) until the standard error
/// of ΔE00 to the mean colour is at most `de00` for every measured colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RealisationTarget {
    /// Target standard error of ΔE00 to the mean colour.
    pub de00: f64,
    /// Fewest realisations (≥ 2, for a standard error to exist).
    pub min: usize,
}

/// A validated scene: every value is in range and every material covers every
/// requested wavelength.
#[derive(Debug, Clone)]
pub struct Scene {
    pub provenance: Provenance,
    pub seed: u64,
    /// Independent random fragments averaged (seed of realisation k derived
    /// from `seed` and k); with a target, the most a run may make.
    pub realisations: usize,
    /// Stop adding realisations once the colour is this certain.
    pub realisation_target: Option<RealisationTarget>,
    pub layer: Layer,
    pub species: Vec<Species>,
    pub grid: GridSpec,
    pub wavelengths_nm: Vec<f64>,
    pub incidence: Vec<Incidence>,
    pub solver: SolverSpec,
    pub output: OutputSpec,
    pub appearance: Appearance,
    pub substrate: Substrate,
    /// An explicit structure instead of generated grains (then `species` is
    /// empty).
    pub structure: Option<Structure>,
    /// Layers from the top down instead of one (`[[stack]]`). Then `layer`
    /// is the whole stack (thicknesses summed, the top layer's fragment),
    /// `species` every layer's pigments in stack order with their volume
    /// fractions of the whole, and `grid` the whole stack's.
    pub stack: Option<Stack>,
}

impl Scene {
    /// Per species, whether its grains are solved as a tensor each: a
    /// uniaxial crystal (ordinary and extraordinary tables) in Maxwell's
    /// equations; otherwise its orientation average (METHOD §8).
    pub fn crystal_tensors(&self) -> Vec<bool> {
        let maxwell = self.solver.equation == Equation::Maxwell;
        self.species
            .iter()
            .map(|s| maxwell && s.material.axes().is_some())
            .collect()
    }

    /// Total pigment volume concentration requested.
    pub fn total_pvc(&self) -> f64 {
        self.species.iter().map(|s| s.volume_fraction).sum()
    }

    /// Whether the pigments are dissolved (homogeneous layer, no grains).
    pub fn is_molecular(&self) -> bool {
        !self.species.is_empty()
            && self
                .species
                .iter()
                .all(|s| s.shape == GrainShape::Molecular)
    }

    /// File the scene was read from.
    pub fn path(&self) -> &Path {
        &self.provenance.path
    }
}
