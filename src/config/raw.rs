//! The TOML file as written: serde structs mirroring the schema one to one.
//!
//! Every table denies unknown keys, so a typo is an error rather than a
//! silently ignored setting. Units are part of the key names. Values are not
//! checked here (integers are read as `i64` so that out-of-range values reach
//! `check` and get a message with the allowed range); `check` turns this
//! into the checked [`Scene`](super::Scene).

use super::Method;
use serde::de::{self, Deserializer, EnumAccess, VariantAccess, Visitor};
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawConfig {
    pub seed: Option<i64>,
    pub realisations: Option<RawRealisations>,
    /// The layer; absent when `[[stack]]` gives the layers instead.
    pub layer: Option<RawLayer>,
    #[serde(default)]
    pub pigment: Vec<RawPigment>,
    /// Layers from the top down, each with its pigments, instead of
    /// `[layer]` and `[[pigment]]`.
    #[serde(default)]
    pub stack: Vec<RawStackLayer>,
    /// How the layers of a stack are combined.
    pub stacking: Option<RawStacking>,
    pub grid: RawGrid,
    pub illumination: RawIllumination,
    pub solver: Option<RawSolver>,
    pub output: Option<RawOutput>,
    pub appearance: Option<RawAppearance>,
    pub substrate: Option<RawSubstrate>,
    pub structure: Option<RawStructure>,
}

/// `realisations = 4`, or `realisations = { target_de00 = 0.5, max = 16 }`:
/// a count, or a target uncertainty of the colour with the most
/// realisations it may take.
#[derive(Debug)]
pub enum RawRealisations {
    Count(i64),
    Target(RawRealisationTarget),
}

/// `{ target_de00, max, min }`: realisations are added until the standard
/// error of every measured colour's ΔE00 to the mean is at most
/// `target_de00`, from `min` (default 3) up to `max`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRealisationTarget {
    pub target_de00: f64,
    pub max: i64,
    pub min: Option<i64>,
}

impl<'de> Deserialize<'de> for RawRealisations {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawRealisations;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a count, or a table { target_de00 = …, max = … }")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawRealisations, E> {
                Ok(RawRealisations::Count(v))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<RawRealisations, E> {
                Ok(RawRealisations::Count(i64::try_from(v).unwrap_or(i64::MAX)))
            }
            fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<RawRealisations, A::Error> {
                RawRealisationTarget::deserialize(de::value::MapAccessDeserializer::new(map))
                    .map(RawRealisations::Target)
            }
        }
        d.deserialize_any(V)
    }
}

/// One `[[stack]]` element: a layer as `[layer]` gives it, and its
/// pigments as `[[pigment]]` does.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawStackLayer {
    pub layer: RawLayer,
    #[serde(default)]
    pub pigment: Vec<RawPigment>,
    /// Share of the area the layer is printed on (halftone), (0, 1].
    pub coverage: Option<f64>,
}

/// `[stacking]`: `coupling = "incoherent" | "coherent"` and the directions
/// of the adding method.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawStacking {
    pub coupling: Option<String>,
    pub trapped_directions: Option<i64>,
    pub escape_directions: Option<i64>,
    /// Yule–Nielsen's n of a halftone's area mixture, [1, 10].
    pub yule_nielsen_n: Option<f64>,
}

/// `[structure]`: the layer given explicitly instead of generated grains.
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RawStructure {
    /// Simple bodies in the binder, rasterised by volume fraction.
    Primitives {
        #[serde(default)]
        primitive: Vec<RawPrimitive>,
    },
    /// A complex ε grid from an HDF5 file.
    Hdf5 { file: String },
    /// Slices in z, each a map of material codes over the fragment.
    Layers {
        materials: Vec<RawMaterial>,
        #[serde(default)]
        layer: Vec<RawSlice>,
    },
}

/// `[[structure.layer]]`: the slice `z_nm = [z0, z1]` and its map, rows
/// along y (the first at y = 0), one character per column along x: `0` the
/// binder, `k` (1–9) the k-th of `structure.materials`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSlice {
    pub z_nm: Vec<f64>,
    pub map: Vec<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPrimitive {
    pub shape: RawBody,
    pub material: RawMaterial,
}

/// `{ kind = "slab", z_nm = [z0, z1] }`, `{ kind = "box", min_nm, max_nm }`,
/// `{ kind = "sphere", center_nm, radius_nm }`,
/// `{ kind = "cylinder", center_nm, radius_nm, length_nm, axis }`.
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RawBody {
    Slab {
        z_nm: Vec<f64>,
    },
    Box {
        min_nm: Vec<f64>,
        max_nm: Vec<f64>,
    },
    Sphere {
        center_nm: Vec<f64>,
        radius_nm: f64,
    },
    Cylinder {
        center_nm: Vec<f64>,
        radius_nm: f64,
        length_nm: f64,
        axis: RawAxis,
    },
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RawAxis {
    X,
    Y,
    Z,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLayer {
    pub thickness_nm: f64,
    pub fragment_nm: Vec<f64>,
    pub binder_index: Option<f64>,
    /// Total PVC, shared among the pigments by their `share`.
    pub pvc: Option<f64>,
    /// Grains may protrude through the top surface by this fraction of
    /// their diameter.
    pub relief_fraction: Option<f64>,
    /// Hard-sphere Monte Carlo sweeps after packing (Brownian settling of
    /// the grains in the wet ink; one sweep = one attempted move per grain).
    pub equilibrate_sweeps: Option<i64>,
    /// The binder's top surface.
    pub surface: Option<RawSurface>,
}

/// `surface = { kind = "flat" }`, `{ kind = "conformal", film_nm }` or
/// `{ kind = "rough", rms_nm, correlation_nm }`.
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RawSurface {
    Flat,
    Conformal { film_nm: f64 },
    Rough { rms_nm: f64, correlation_nm: f64 },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPigment {
    pub name: String,
    pub material: RawMaterial,
    pub pvc: Option<f64>,
    pub share: Option<f64>,
    pub diameter_nm: Option<f64>,
    pub shape: Option<RawShape>,
    pub orientation: Option<RawOrientation>,
    pub alignment_field: Option<f64>,
    pub size: Option<RawSize>,
    pub agglomeration: Option<RawAgglomeration>,
}

/// `{ kind = "fixed" }`, `{ kind = "normal", sigma = 0.1 }` (relative),
/// `{ kind = "log-normal", sigma = 0.2 }` (of ln d).
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RawSize {
    Fixed,
    Normal { sigma: f64 },
    LogNormal { sigma: f64 },
}

/// `{ cluster_size = 8 }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAgglomeration {
    pub cluster_size: i64,
}

/// `{ kind = "sphere" }`, `{ kind = "cylinder", aspect = 3, spheres = 5 }`,
/// `{ kind = "rice", aspect = 3, spheres = 7 }`.
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RawShape {
    Sphere,
    Molecular,
    Cylinder {
        aspect: Option<f64>,
        spheres: Option<i64>,
    },
    Rice {
        aspect: Option<f64>,
        spheres: Option<i64>,
    },
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawOrientation {
    Random,
    InPlane,
    Perpendicular,
}

/// `{ builtin = "red" }`, `{ library = "rutile" }`, `{ csv = "path.csv" }`,
/// `{ index = [n, k] }` or
/// `{ epsilon = [re, im] }`.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RawMaterial {
    Builtin(String),
    /// A material of the library (`inksim materials` lists them).
    Library(String),
    Csv(String),
    /// Constant `[n, k]` at every wavelength.
    Index(Vec<f64>),
    /// Constant complex permittivity `[Re ε, Im ε]` at every wavelength.
    Epsilon(Vec<f64>),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGrid {
    pub cell_nm: Option<f64>,
    /// z cell (with `cell_nm`); default min(cell_nm, DEFAULT_Z_CELL_NM).
    pub z_cell_nm: Option<f64>,
    pub nx: Option<i64>,
    pub ny: Option<i64>,
    pub nz: Option<i64>,
    /// `"auto"`, `"average"` or `"anisotropic"`: the permittivity of voxels
    /// a grain surface cuts.
    pub voxel_permittivity: Option<RawVoxelPermittivity>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawVoxelPermittivity {
    Auto,
    Average,
    Anisotropic,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawIllumination {
    pub wavelengths_nm: Option<Vec<f64>>,
    pub wavelength_range_nm: Option<RawRange>,
    pub polar_deg: Vec<f64>,
    pub azimuth_deg: Option<f64>,
    pub polarisation: Option<RawPolarisation>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawPolarisation {
    Unpolarised,
    S,
    P,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawEquation {
    Helmholtz,
    Maxwell,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRange {
    pub start: f64,
    pub stop: f64,
    pub step: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSolver {
    pub equation: Option<RawEquation>,
    pub method: Option<RawMethod>,
    pub tolerance: Option<f64>,
    pub max_iterations: Option<i64>,
    pub precision: Option<RawPrecision>,
    pub background: Option<RawBackground>,
    pub effective_medium_tolerance: Option<f64>,
    /// Largest |ΣR + ΣT + A − 1| accepted before a solve is solved again,
    /// tighter.
    pub energy_balance_limit: Option<f64>,
    /// `"auto"`, `"two-solves"` or `"random-phase"` (Maxwell's natural
    /// light).
    pub natural_light: Option<RawNaturalLight>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawNaturalLight {
    Auto,
    TwoSolves,
    RandomPhase,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawBackground {
    Binder,
    Mean,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawPrecision {
    F64,
    F32,
}

/// A method name, looked up in the solver's registry as it is read (an
/// unknown name is a parse error listing the allowed ones, as for the enums
/// here).
#[derive(Debug, Clone, Copy)]
pub struct RawMethod(pub Method);

impl<'de> Deserialize<'de> for RawMethod {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Name;
        impl<'de> Visitor<'de> for Name {
            type Value = RawMethod;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a method name")
            }
            fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<RawMethod, A::Error> {
                let (name, variant): (String, _) = data.variant()?;
                let method = Method::from_config_name(&name)
                    .ok_or_else(|| de::Error::unknown_variant(&name, Method::config_names()))?;
                variant.unit_variant()?;
                Ok(RawMethod(method))
            }
        }
        d.deserialize_enum("RawMethod", Method::config_names(), Name)
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawOutput {
    pub dir: Option<String>,
    pub name: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAppearance {
    pub viewing_deg: Option<Vec<f64>>,
    pub outputs: Option<Vec<RawProduct>>,
    pub brdf_cell: Option<f64>,
    pub quadrature_points: Option<i64>,
    pub illuminant: Option<String>,
    pub observer_deg: Option<i64>,
    pub measurements: Option<Vec<String>>,
    pub baseline: Option<RawBaseline>,
}

/// `appearance.baseline`: one model's name or a list of names.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged, expecting = "a baseline model's name or a list of names")]
pub enum RawBaseline {
    One(String),
    Many(Vec<String>),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RawProduct {
    Brdf,
    Btdf,
    Tile,
    Merl,
    Preview,
}

/// `{ kind = "paper", albedo = 0.9 }`, `{ kind = "none" }`,
/// `{ kind = "black" }`, `{ kind = "white", albedo = 0.8 }`,
/// `{ kind = "csv", file = "ground.csv" }` or
/// `{ kind = "chart", white_albedo = 0.8 }` / `{ kind = "chart", white_csv = "white.csv" }`.
#[derive(Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RawSubstrate {
    Paper {
        albedo: Option<f64>,
    },
    // Tables without fields (not unit variants), so that a stray key is
    // refused as for the others.
    None {},
    Black {},
    White {
        albedo: Option<f64>,
    },
    Csv {
        file: String,
    },
    Chart {
        white_albedo: Option<f64>,
        white_csv: Option<String>,
    },
}
