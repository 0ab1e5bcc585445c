//! Checks a [`RawConfig`](super::raw::RawConfig) and builds the [`Scene`].
//!
//! Every value is checked against its documented range; the first violation
//! (in file order) is reported as [`ConfigError::Invalid`] with the dotted key
//! (`pigment[1].pvc`) and the allowed range. Choices made here:
//! - From `grid.cell_nm`, `nx`/`ny` are the smallest 2^a·3^b·5^c ≥
//!   ⌈fragment/cell⌉ (FFT-friendly; the cell in x/y may shrink slightly) and
//!   `nz = max(2, ⌈thickness/z_cell⌉)` (z is not transformed), with
//!   `z_cell = grid.z_cell_nm` or by default `min(cell_nm, 10 nm)`: the
//!   z discretisation error is O(dz²) and cheap to reduce (cost is linear in
//!   nz), and 10 nm keeps it below 1e-3 in R and T for a 1 µm layer
//!   (tests/solver_slab.rs). The ceilings
//!   forgive a relative 1e-9 so that e.g. 1.1/0.1 gives 11, not 12.
//! - Wavelength and polar-angle lists must be strictly increasing (no
//!   duplicate solves, ordered spectra).
//! - A `wavelength_range_nm` includes `stop` when it lies on the step grid
//!   within a relative 1e-9 of a step; the last value is then exactly `stop`.
//! - A pigment's diameter must fit the layer (≤ thickness) and the periodic
//!   fragment (≤ min(fragment x, y)); the total PVC is limited to
//!   [`MAX_PVC`], what the dynamics packer reaches.
//! - Geometry keys: `pigment.size = { kind = "fixed" | "normal" |
//!   "log-normal", sigma }` (normal: relative σ ≤ [`MAX_NORMAL_SIGMA`];
//!   log-normal: σ of ln d ≤ [`MAX_LOG_NORMAL_SIGMA`]); the largest draw
//!   (3 σ) must fit the layer and the fragment like `diameter_nm`.
//!   `pigment.agglomeration = { cluster_size }` in `[1, MAX_CLUSTER_SIZE]`;
//!   `layer.relief_fraction` in `[0, MAX_RELIEF_FRACTION]`;
//!   `layer.equilibrate_sweeps` in `[0, MAX_EQUILIBRATE_SWEEPS]`.
//! - `Provenance::input_hash` is SHA-256 over the config text followed by each
//!   pigment's table text, in pigment order, then each structure primitive's
//!   table text or the bytes of the structure's HDF5 file.
//! - `[structure]` (explicit layer) and `[[pigment]]` exclude each other.

use super::raw::{RawAppearance, RawAxis, RawBody, RawProduct, RawStructure, RawSubstrate};
use super::raw::{
    RawConfig, RawGrid, RawIllumination, RawLayer, RawMaterial, RawMethod, RawPrecision,
};
use super::raw::{RawOrientation, RawOutput, RawPigment, RawShape, RawSize, RawSolver};
use super::MAX_EQUILIBRATE_SWEEPS;
use super::{
    Appearance, Body, ConfigError, GrainOrientation, GrainShape, GrainSize, GridSpec, Incidence,
    Layer, Material, Method, OutputSpec, Precision, Primitive, Products, Provenance, Scene,
    SolverSpec, Species, Structure, Substrate, MAX_CLUSTER_SIZE, MAX_LOG_NORMAL_SIGMA,
    MAX_NORMAL_SIGMA, MAX_PVC, MAX_RELIEF_FRACTION,
};
use crate::config::materials::BUILTIN_NAMES;
use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const MAX_THICKNESS_NM: f64 = 20_000.0;
const MAX_FRAGMENT_NM: f64 = 100_000.0;
const MAX_CELL_NM: f64 = 1_000.0;
const MAX_GRID_DIM: usize = 4096;
const MAX_WAVELENGTHS: usize = 10_000;
const MAX_POLAR_DEG: f64 = 89.0;
/// Default z cell (nm) when the grid is given by `cell_nm`.
pub const DEFAULT_Z_CELL_NM: f64 = 10.0;
const DEFAULT_BINDER_INDEX: f64 = 1.558;
const DEFAULT_SEED: u64 = 1;
const MAX_REALISATIONS: i64 = 10_000;
/// Paper albedo of the reference study (METHOD §8).
pub const DEFAULT_PAPER_ALBEDO: f64 = 0.9;
const DEFAULT_QUADRATURE_POINTS: i64 = 6;
const DEFAULT_TOLERANCE: f64 = 1e-6;
const DEFAULT_MAX_ITERATIONS: usize = 5000;
/// Smallest relative residual f32 field storage reaches reliably.
pub const F32_MIN_TOLERANCE: f64 = 1e-6;
const MAX_ITERATIONS: i64 = 10_000_000;
/// Default accepted error of the effective-medium shortcut: the R/T/A error
/// of the recommended 25 nm grid (docs/ACCURACY.md), so the shortcut costs
/// no more accuracy than the discretisation it replaces.
pub const DEFAULT_EFFECTIVE_MEDIUM_TOLERANCE: f64 = 1e-3;
/// Largest accepted error of the effective-medium shortcut.
pub const MAX_EFFECTIVE_MEDIUM_TOLERANCE: f64 = 0.1;
/// Relative slack for ceilings and for landing on `stop` in a range.
const REL_EPS: f64 = 1e-9;

/// Reads `path` and parses it with [`parse_scene`].
pub fn load_scene(path: &Path) -> Result<Scene, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        file: path.to_path_buf(),
        source,
    })?;
    parse_scene(path, &text)
}

/// Parses and validates scene TOML `text`; `path` is where it came from (used
/// in messages, for resolving CSV paths and for default output names).
pub fn parse_scene(path: &Path, text: &str) -> Result<Scene, ConfigError> {
    let raw: RawConfig = toml::from_str(text).map_err(|e| ConfigError::Parse {
        file: path.to_path_buf(),
        message: parse_message(text, &e),
    })?;
    Checker { file: path }.scene(path, text, raw)
}

/// The toml error on one line: `line L, column C: message; more`.
fn parse_message(text: &str, e: &toml::de::Error) -> String {
    let msg = e
        .message()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ");
    match e.span() {
        Some(span) => {
            let mut start = span.start.min(text.len());
            while !text.is_char_boundary(start) {
                start -= 1;
            }
            let before = &text[..start];
            let line = before.matches('\n').count() + 1;
            let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            format!("line {line}, column {col}: {msg}")
        }
        None => msg,
    }
}

struct Checker<'a> {
    file: &'a Path,
}

impl Checker<'_> {
    fn invalid(&self, key: impl Into<String>, message: impl Into<String>) -> ConfigError {
        ConfigError::Invalid {
            file: self.file.to_path_buf(),
            key: key.into(),
            message: message.into(),
        }
    }

    /// `Ok(v)` when `ok`, else "must be in {range}, got {v}".
    fn range(&self, key: &str, v: f64, ok: bool, range: &str) -> Result<f64, ConfigError> {
        if ok {
            Ok(v)
        } else {
            Err(self.invalid(key, format!("must be in {range}, got {v}")))
        }
    }

    fn scene(&self, path: &Path, text: &str, raw: RawConfig) -> Result<Scene, ConfigError> {
        let seed = match raw.seed {
            None => DEFAULT_SEED,
            Some(s) if s >= 0 => s as u64,
            Some(s) => return Err(self.invalid("seed", format!("must be >= 0, got {s}"))),
        };
        let realisations = match raw.realisations {
            None => 1,
            Some(r) if (1..=MAX_REALISATIONS).contains(&r) => r as usize,
            Some(r) => {
                return Err(self.invalid(
                    "realisations",
                    format!("must be in [1, {MAX_REALISATIONS}], got {r}"),
                ))
            }
        };
        let layer = self.layer(&raw.layer)?;
        let structure = match &raw.structure {
            None => None,
            Some(st) => Some(self.structure(st, &layer)?),
        };
        let species = if structure.is_some() {
            if !raw.pigment.is_empty() || raw.layer.pvc.is_some() {
                return Err(self.invalid(
                    "structure",
                    "an explicit structure replaces the generated grains: remove [[pigment]] and layer.pvc",
                ));
            }
            Vec::new()
        } else {
            self.pigments(&raw.pigment, &layer, raw.layer.pvc)?
        };
        let grid = self.grid(&raw.grid, &layer)?;
        let (wavelengths_nm, wl_key) = self.wavelengths(&raw.illumination)?;
        let incidence = self.incidence(&raw.illumination)?;
        let solver = self.solver(raw.solver.as_ref())?;
        let output = self.output(path, raw.output.as_ref())?;
        let appearance = self.appearance(raw.appearance.as_ref(), &incidence)?;
        let substrate = self.substrate(raw.substrate.as_ref())?;

        for &wl in &wavelengths_nm {
            for s in &species {
                if s.material.index_at(wl).is_none() {
                    let (lo, hi) = s.material.range_nm();
                    return Err(self.invalid(
                        wl_key,
                        format!(
                            "wavelength {wl} nm is outside the data range [{lo}, {hi}] nm of \
                             material {} (pigment `{}`)",
                            s.material, s.name
                        ),
                    ));
                }
            }
        }

        if let Some(Structure::Primitives(ps)) = &structure {
            for &wl in &wavelengths_nm {
                for (i, p) in ps.iter().enumerate() {
                    if p.material.index_at(wl).is_none() {
                        let (lo, hi) = p.material.range_nm();
                        return Err(self.invalid(
                            wl_key,
                            format!(
                                "wavelength {wl} nm is outside the data range [{lo}, {hi}] nm of \
                                 material {} (structure.primitive[{i}])",
                                p.material
                            ),
                        ));
                    }
                }
            }
        }

        let mut hasher = Sha256::new();
        hasher.update(text.as_bytes());
        for s in &species {
            hasher.update(s.material.table_bytes());
        }
        match &structure {
            Some(Structure::Primitives(ps)) => {
                for p in ps {
                    hasher.update(p.material.table_bytes());
                }
            }
            Some(Structure::Hdf5(path)) => {
                let bytes = std::fs::read(path).map_err(|source| ConfigError::Read {
                    file: path.clone(),
                    source,
                })?;
                hasher.update(&bytes);
            }
            None => {}
        }
        let mut input_hash = String::with_capacity(64);
        for b in hasher.finalize() {
            let _ = write!(input_hash, "{b:02x}");
        }

        Ok(Scene {
            provenance: Provenance {
                path: path.to_path_buf(),
                text: text.to_string(),
                input_hash,
            },
            seed,
            realisations,
            layer,
            species,
            grid,
            wavelengths_nm,
            incidence,
            solver,
            output,
            appearance,
            substrate,
            structure,
        })
    }

    fn structure(&self, raw: &RawStructure, layer: &Layer) -> Result<Structure, ConfigError> {
        match raw {
            RawStructure::Hdf5 { file } => {
                if file.trim().is_empty() {
                    return Err(self.invalid("structure.file", "must not be empty"));
                }
                let path = self.file.parent().unwrap_or(Path::new("")).join(file);
                if !path.is_file() {
                    return Err(self.invalid(
                        "structure.file",
                        format!("{} is not a readable file", path.display()),
                    ));
                }
                Ok(Structure::Hdf5(path))
            }
            RawStructure::Primitives { primitive } => {
                if primitive.is_empty() {
                    return Err(self.invalid(
                        "structure.primitive",
                        "at least one [[structure.primitive]] is required",
                    ));
                }
                let h = layer.thickness_nm;
                let mut out = Vec::with_capacity(primitive.len());
                for (i, p) in primitive.iter().enumerate() {
                    let key = format!("structure.primitive[{i}]");
                    let material = self.material(&p.material, &format!("{key}.material"))?;
                    let three = |k: &str, v: &[f64]| -> Result<[f64; 3], ConfigError> {
                        if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
                            return Err(self.invalid(
                                format!("{key}.shape.{k}"),
                                format!("must be 3 finite values [x, y, z] in nm, got {v:?}"),
                            ));
                        }
                        Ok([v[0], v[1], v[2]])
                    };
                    let positive = |k: &str, v: f64| {
                        self.range(
                            &format!("{key}.shape.{k}"),
                            v,
                            v > 0.0 && v.is_finite(),
                            "(0, inf) nm",
                        )
                    };
                    let in_layer = |k: &str, z: f64| {
                        self.range(
                            &format!("{key}.shape.{k}"),
                            z,
                            (0.0..=h).contains(&z),
                            &format!("z in [0, {h}] nm (inside the layer)"),
                        )
                    };
                    let body = match &p.shape {
                        RawBody::Slab { z_nm } => {
                            if z_nm.len() != 2 || z_nm[0] >= z_nm[1] {
                                return Err(self.invalid(
                                    format!("{key}.shape.z_nm"),
                                    format!("must be [z0, z1] with z0 < z1, got {z_nm:?}"),
                                ));
                            }
                            in_layer("z_nm", z_nm[0])?;
                            in_layer("z_nm", z_nm[1])?;
                            Body::Slab {
                                z_nm: [z_nm[0], z_nm[1]],
                            }
                        }
                        RawBody::Box { min_nm, max_nm } => {
                            let (lo, hi) = (three("min_nm", min_nm)?, three("max_nm", max_nm)?);
                            if (0..3).any(|a| lo[a] >= hi[a]) {
                                return Err(self.invalid(
                                    format!("{key}.shape"),
                                    "min_nm must be below max_nm on every axis",
                                ));
                            }
                            in_layer("min_nm", lo[2])?;
                            in_layer("max_nm", hi[2])?;
                            Body::Box {
                                min_nm: lo,
                                max_nm: hi,
                            }
                        }
                        RawBody::Sphere {
                            center_nm,
                            radius_nm,
                        } => {
                            let c = three("center_nm", center_nm)?;
                            let r = positive("radius_nm", *radius_nm)?;
                            in_layer("center_nm", c[2] - r)?;
                            in_layer("center_nm", c[2] + r)?;
                            Body::Sphere {
                                center_nm: c,
                                radius_nm: r,
                            }
                        }
                        RawBody::Cylinder {
                            center_nm,
                            radius_nm,
                            length_nm,
                            axis,
                        } => {
                            let c = three("center_nm", center_nm)?;
                            let r = positive("radius_nm", *radius_nm)?;
                            let l = positive("length_nm", *length_nm)?;
                            let axis = match axis {
                                RawAxis::X => 0,
                                RawAxis::Y => 1,
                                RawAxis::Z => 2,
                            };
                            let half_z = if axis == 2 { l / 2.0 } else { r };
                            in_layer("center_nm", c[2] - half_z)?;
                            in_layer("center_nm", c[2] + half_z)?;
                            Body::Cylinder {
                                center_nm: c,
                                radius_nm: r,
                                length_nm: l,
                                axis,
                            }
                        }
                    };
                    out.push(Primitive { body, material });
                }
                Ok(Structure::Primitives(out))
            }
        }
    }

    fn appearance(
        &self,
        raw: Option<&RawAppearance>,
        incidence: &[Incidence],
    ) -> Result<Appearance, ConfigError> {
        let viewing_deg = match raw.and_then(|a| a.viewing_deg.as_ref()) {
            None => incidence.iter().map(|i| i.polar_deg).collect(),
            Some(list) => {
                let key = "appearance.viewing_deg";
                if list.is_empty() {
                    return Err(self.invalid(key, "must not be empty"));
                }
                for (i, &v) in list.iter().enumerate() {
                    let k = format!("{key}[{i}]");
                    self.range(
                        &k,
                        v,
                        (0.0..=MAX_POLAR_DEG).contains(&v),
                        &format!("[0, {MAX_POLAR_DEG}] deg"),
                    )?;
                    if i > 0 && v <= list[i - 1] {
                        return Err(self.invalid(
                            k,
                            format!(
                                "values must be strictly increasing, got {v} after {}",
                                list[i - 1]
                            ),
                        ));
                    }
                }
                list.clone()
            }
        };
        let mut products = Products::default();
        let list = raw
            .and_then(|a| a.outputs.clone())
            .unwrap_or_else(|| vec![RawProduct::Brdf, RawProduct::Tile]);
        for p in list {
            match p {
                RawProduct::Brdf => products.brdf = true,
                RawProduct::Btdf => products.btdf = true,
                RawProduct::Tile => products.tile = true,
                RawProduct::Merl => products.merl = true,
            }
        }
        let brdf_cell = match raw.and_then(|a| a.brdf_cell) {
            None => None,
            Some(c) => Some(self.range(
                "appearance.brdf_cell",
                c,
                c > 0.0 && c <= 1.0,
                "(0, 1] (in units of sin θ)",
            )?),
        };
        let q = raw
            .and_then(|a| a.quadrature_points)
            .unwrap_or(DEFAULT_QUADRATURE_POINTS);
        if !(2..=32).contains(&q) {
            return Err(self.invalid(
                "appearance.quadrature_points",
                format!("must be in [2, 32], got {q}"),
            ));
        }
        Ok(Appearance {
            viewing_deg,
            products,
            brdf_cell,
            quadrature_points: q as usize,
        })
    }

    fn substrate(&self, raw: Option<&RawSubstrate>) -> Result<Substrate, ConfigError> {
        Ok(match raw {
            Some(RawSubstrate::None) => Substrate::None,
            None => Substrate::Paper {
                albedo: DEFAULT_PAPER_ALBEDO,
            },
            Some(RawSubstrate::Paper { albedo }) => {
                let a = albedo.unwrap_or(DEFAULT_PAPER_ALBEDO);
                Substrate::Paper {
                    albedo: self.range(
                        "substrate.albedo",
                        a,
                        (0.0..=1.0).contains(&a),
                        "[0, 1]",
                    )?,
                }
            }
        })
    }

    fn layer(&self, raw: &RawLayer) -> Result<Layer, ConfigError> {
        let t = raw.thickness_nm;
        let thickness_nm = self.range(
            "layer.thickness_nm",
            t,
            t > 0.0 && t <= MAX_THICKNESS_NM,
            &format!("(0, {MAX_THICKNESS_NM}] nm"),
        )?;
        if raw.fragment_nm.len() != 2 {
            return Err(self.invalid(
                "layer.fragment_nm",
                format!(
                    "must be 2 values [x, y] in nm, got {}",
                    raw.fragment_nm.len()
                ),
            ));
        }
        let mut frag = [0.0; 2];
        for (i, &f) in raw.fragment_nm.iter().enumerate() {
            frag[i] = self.range(
                &format!("layer.fragment_nm[{i}]"),
                f,
                f > 0.0 && f <= MAX_FRAGMENT_NM,
                &format!("(0, {MAX_FRAGMENT_NM}] nm"),
            )?;
        }
        let b = raw.binder_index.unwrap_or(DEFAULT_BINDER_INDEX);
        let binder_index =
            self.range("layer.binder_index", b, (1.0..=3.0).contains(&b), "[1, 3]")?;
        let r = raw.relief_fraction.unwrap_or(0.0);
        let relief_fraction = self.range(
            "layer.relief_fraction",
            r,
            (0.0..=MAX_RELIEF_FRACTION).contains(&r),
            &format!("[0, {MAX_RELIEF_FRACTION}] (fraction of a grain's diameter)"),
        )?;
        let sweeps = raw.equilibrate_sweeps.unwrap_or(0);
        if !(0..=MAX_EQUILIBRATE_SWEEPS as i64).contains(&sweeps) {
            return Err(self.invalid(
                "layer.equilibrate_sweeps",
                format!(
                    "must be in [0, {MAX_EQUILIBRATE_SWEEPS}] (Monte Carlo sweeps, one attempted \
                     move per grain each; 0 = off), got {sweeps}"
                ),
            ));
        }
        Ok(Layer {
            thickness_nm,
            fragment_x_nm: frag[0],
            fragment_y_nm: frag[1],
            binder_index,
            relief_fraction,
            equilibrate_sweeps: sweeps as u64,
        })
    }

    fn pigments(
        &self,
        raw: &[RawPigment],
        layer: &Layer,
        total_pvc: Option<f64>,
    ) -> Result<Vec<Species>, ConfigError> {
        if raw.is_empty() {
            return Err(self.invalid("pigment", "at least one [[pigment]] table is required"));
        }
        if let Some(t) = total_pvc {
            self.range(
                "layer.pvc",
                t,
                t > 0.0 && t <= MAX_PVC,
                &format!("(0, {MAX_PVC}] (the most the packer reaches)"),
            )?;
        }
        let mut shares = Vec::with_capacity(raw.len());
        for (i, p) in raw.iter().enumerate() {
            let key = |field: &str| format!("pigment[{i}].{field}");
            match (total_pvc, p.pvc, p.share) {
                (Some(_), Some(_), _) => {
                    return Err(self.invalid(
                        key("pvc"),
                        "layer.pvc is given: set this pigment's `share` of it instead",
                    ))
                }
                (None, _, Some(_)) => {
                    return Err(self.invalid(
                        key("share"),
                        "a share needs the total layer.pvc; or give this pigment's pvc",
                    ))
                }
                (None, None, None) => {
                    return Err(self.invalid(
                        key("pvc"),
                        "missing; give each pigment's pvc, or layer.pvc with shares",
                    ))
                }
                (None, Some(v), None) => shares.push(v),
                (Some(_), None, sh) => {
                    let sh = sh.unwrap_or(1.0);
                    shares.push(self.range(
                        &key("share"),
                        sh,
                        sh > 0.0 && sh.is_finite(),
                        "(0, inf)",
                    )?);
                }
            }
        }
        let fractions: Vec<f64> = match total_pvc {
            None => shares,
            Some(t) => {
                let sum: f64 = shares.iter().sum();
                shares.iter().map(|s| t * s / sum).collect()
            }
        };
        let molecular: Vec<bool> = raw
            .iter()
            .map(|p| matches!(p.shape, Some(RawShape::Molecular)))
            .collect();
        if molecular.iter().any(|&m| m) && !molecular.iter().all(|&m| m) {
            let i = molecular.iter().position(|&m| !m).unwrap_or(0);
            return Err(self.invalid(
                format!("pigment[{i}].shape"),
                "another pigment is molecular; dissolved and particulate pigments cannot be mixed",
            ));
        }
        let mut seen: HashMap<&str, usize> = HashMap::new();
        let mut species = Vec::with_capacity(raw.len());
        let max_d = layer
            .thickness_nm
            .min(layer.fragment_x_nm)
            .min(layer.fragment_y_nm);
        for (i, p) in raw.iter().enumerate() {
            let key = |field: &str| format!("pigment[{i}].{field}");
            let name = p.name.trim();
            if name.is_empty() {
                return Err(self.invalid(key("name"), "must not be empty"));
            }
            if let Some(j) = seen.insert(name, i) {
                return Err(self.invalid(
                    key("name"),
                    format!("duplicate pigment name `{name}` (also pigment[{j}].name)"),
                ));
            }
            let material = self.material(&p.material, &key("material"))?;
            let vf = fractions[i];
            let vf_key = if total_pvc.is_some() {
                "layer.pvc".to_string()
            } else {
                key("pvc")
            };
            let volume_fraction = self.range(&vf_key, vf, vf > 0.0 && vf < 1.0, "(0, 1)")?;
            let shape = self.shape(p.shape.as_ref(), &key("shape"))?;
            // A molecular pigment's diameter is not used (documented).
            let diameter_nm = match (shape, p.diameter_nm) {
                (GrainShape::Molecular, _) => 0.0,
                (_, None) => return Err(self.invalid(key("diameter_nm"), "missing")),
                (_, Some(d)) => self.range(
                    &key("diameter_nm"),
                    d,
                    d > 0.0 && d <= max_d,
                    &format!("(0, {max_d}] nm (at most the layer thickness and the fragment size)"),
                )?,
            };
            let orientation = match p.orientation {
                None | Some(RawOrientation::Random) => GrainOrientation::Random,
                Some(RawOrientation::InPlane) => GrainOrientation::InPlane,
                Some(RawOrientation::Perpendicular) => GrainOrientation::Perpendicular,
            };
            let f = p.alignment_field.unwrap_or(0.0);
            let alignment_field = self.range(
                &key("alignment_field"),
                f,
                (0.0..=100.0).contains(&f),
                "[0, 100]",
            )?;
            if alignment_field > 0.0 && orientation == GrainOrientation::Random {
                return Err(self.invalid(
                    key("alignment_field"),
                    "needs orientation \"in-plane\" or \"perpendicular\" (the direction it aligns towards)",
                ));
            }
            if alignment_field > 0.0 && matches!(shape, GrainShape::Sphere | GrainShape::Molecular)
            {
                return Err(self.invalid(
                    key("alignment_field"),
                    "spheres and dissolved pigments have no axis to align",
                ));
            }
            let size = match &p.size {
                None | Some(RawSize::Fixed) => GrainSize::Fixed,
                Some(RawSize::Normal { sigma }) => GrainSize::Normal {
                    sigma: self.range(
                        &key("size.sigma"),
                        *sigma,
                        (0.0..=MAX_NORMAL_SIGMA).contains(sigma),
                        &format!("[0, {MAX_NORMAL_SIGMA}] (relative to diameter_nm)"),
                    )?,
                },
                Some(RawSize::LogNormal { sigma }) => GrainSize::LogNormal {
                    sigma: self.range(
                        &key("size.sigma"),
                        *sigma,
                        (0.0..=MAX_LOG_NORMAL_SIGMA).contains(sigma),
                        &format!("[0, {MAX_LOG_NORMAL_SIGMA}] (standard deviation of ln d)"),
                    )?,
                },
            };
            if shape != GrainShape::Molecular {
                let largest = size.max_diameter(diameter_nm);
                if largest > max_d * (1.0 + REL_EPS) {
                    return Err(self.invalid(
                        key("size"),
                        format!(
                            "the largest grain (3 sigma) is {largest} nm; it must be at most \
                             {max_d} nm (the layer thickness and the fragment size)"
                        ),
                    ));
                }
            }
            let cluster_size = match &p.agglomeration {
                None => 1,
                Some(a) => {
                    let c = a.cluster_size;
                    if !(1..=MAX_CLUSTER_SIZE as i64).contains(&c) {
                        return Err(self.invalid(
                            key("agglomeration.cluster_size"),
                            format!(
                                "must be in [1, {MAX_CLUSTER_SIZE}] (grains per cluster), got {c}"
                            ),
                        ));
                    }
                    c as usize
                }
            };
            if shape == GrainShape::Molecular && (p.size.is_some() || cluster_size > 1) {
                return Err(self.invalid(
                    key(if p.size.is_some() {
                        "size"
                    } else {
                        "agglomeration"
                    }),
                    "a dissolved (molecular) pigment has no grains to size or cluster",
                ));
            }
            species.push(Species {
                name: name.to_string(),
                material,
                volume_fraction,
                diameter_nm,
                shape,
                orientation,
                alignment_field,
                size,
                cluster_size,
            });
        }
        let total: f64 = species.iter().map(|s| s.volume_fraction).sum();
        if total > MAX_PVC * (1.0 + REL_EPS) {
            return Err(self.invalid(
                "pigment[*].pvc",
                format!("total pvc {total} exceeds {MAX_PVC}, the most the packer reaches"),
            ));
        }
        Ok(species)
    }

    fn shape(&self, raw: Option<&RawShape>, key: &str) -> Result<GrainShape, ConfigError> {
        let parts = |aspect: Option<f64>, spheres: Option<i64>, def_a: f64, def_n: i64| {
            let a = aspect.unwrap_or(def_a);
            let a = self.range(
                &format!("{key}.aspect"),
                a,
                (1.0..=20.0).contains(&a),
                "[1, 20]",
            )?;
            let n = spheres.unwrap_or(def_n);
            if !(2..=64).contains(&n) {
                return Err(self.invalid(
                    format!("{key}.spheres"),
                    format!("must be in [2, 64], got {n}"),
                ));
            }
            Ok((a, n as usize))
        };
        Ok(match raw {
            None | Some(RawShape::Sphere) => GrainShape::Sphere,
            Some(RawShape::Molecular) => GrainShape::Molecular,
            Some(RawShape::Cylinder { aspect, spheres }) => {
                let (aspect, spheres) = parts(*aspect, *spheres, 3.0, 5)?;
                if (spheres as f64) <= aspect - 1.0 {
                    return Err(self.invalid(
                        format!("{key}.spheres"),
                        format!("a cylinder of aspect {aspect} needs more than {} spheres so neighbours overlap", aspect - 1.0),
                    ));
                }
                GrainShape::Cylinder { aspect, spheres }
            }
            Some(RawShape::Rice { aspect, spheres }) => {
                let (aspect, spheres) = parts(*aspect, *spheres, 3.0, 7)?;
                GrainShape::Rice { aspect, spheres }
            }
        })
    }

    fn material(&self, raw: &RawMaterial, key: &str) -> Result<Material, ConfigError> {
        match raw {
            RawMaterial::Builtin(name) => Material::builtin(name).ok_or_else(|| {
                self.invalid(
                    format!("{key}.builtin"),
                    format!(
                        "unknown builtin material `{name}`; available: {}",
                        BUILTIN_NAMES.join(", ")
                    ),
                )
            }),
            RawMaterial::Index(nk) => {
                let k = format!("{key}.index");
                if nk.len() != 2 {
                    return Err(self.invalid(k, format!("must be [n, k], got {} values", nk.len())));
                }
                self.range(&k, nk[0], (1.0..=10.0).contains(&nk[0]), "n in [1, 10]")?;
                self.range(&k, nk[1], (0.0..=10.0).contains(&nk[1]), "k in [0, 10]")?;
                let text = format!(
                    "wavelength_nm,n,k\n1,{n},{kk}\n1000000,{n},{kk}\n",
                    n = nk[0],
                    kk = nk[1]
                );
                let name = format!("n{}+{}i", nk[0], nk[1]);
                Material::from_csv_text(&name, &text).map_err(|e| self.invalid(k, e.to_string()))
            }
            RawMaterial::Csv(rel) => {
                if rel.trim().is_empty() {
                    return Err(self.invalid(format!("{key}.csv"), "must not be empty"));
                }
                let base = self.file.parent().unwrap_or(Path::new(""));
                let resolved = base.join(rel);
                Material::from_csv(&resolved).map_err(|e| ConfigError::Material {
                    file: self.file.to_path_buf(),
                    material: rel.clone(),
                    message: e.to_string(),
                })
            }
        }
    }

    fn grid(&self, raw: &RawGrid, layer: &Layer) -> Result<GridSpec, ConfigError> {
        let explicit = [("nx", raw.nx), ("ny", raw.ny), ("nz", raw.nz)];
        let any_count = explicit.iter().any(|(_, v)| v.is_some());
        match raw.cell_nm {
            Some(_) if any_count => {
                Err(self.invalid("grid", "give either cell_nm or all of nx, ny, nz, not both"))
            }
            None if raw.z_cell_nm.is_some() => Err(self.invalid(
                "grid.z_cell_nm",
                "goes with cell_nm; with explicit counts set nz instead",
            )),
            None if !any_count => {
                Err(self.invalid("grid", "give either cell_nm or all of nx, ny, nz"))
            }
            Some(cell) => {
                let cell = self.range(
                    "grid.cell_nm",
                    cell,
                    cell > 0.0 && cell <= MAX_CELL_NM,
                    &format!("(0, {MAX_CELL_NM}] nm"),
                )?;
                let count = |axis: &str, len: f64, min: usize| {
                    let q = len / cell;
                    if q > MAX_GRID_DIM as f64 {
                        return Err(self.invalid(
                            "grid.cell_nm",
                            format!(
                                "cell {cell} nm needs {} cells along {axis}, more than \
                                 {MAX_GRID_DIM}; use a larger cell",
                                q.ceil()
                            ),
                        ));
                    }
                    Ok(((q * (1.0 - REL_EPS)).ceil() as usize).max(min))
                };
                let nx = next_fft_size(count("x", layer.fragment_x_nm, 1)?);
                let ny = next_fft_size(count("y", layer.fragment_y_nm, 1)?);
                let z_cell = match raw.z_cell_nm {
                    Some(z) => self.range(
                        "grid.z_cell_nm",
                        z,
                        z > 0.0 && z <= MAX_CELL_NM,
                        &format!("(0, {MAX_CELL_NM}] nm"),
                    )?,
                    None => cell.min(DEFAULT_Z_CELL_NM),
                };
                let nz = ((layer.thickness_nm / z_cell * (1.0 - REL_EPS)).ceil() as usize).max(2);
                if nz > MAX_GRID_DIM {
                    return Err(self.invalid(
                        "grid.z_cell_nm",
                        format!("needs {nz} cells along z, more than {MAX_GRID_DIM}"),
                    ));
                }
                Ok(GridSpec { nx, ny, nz })
            }
            None => {
                let mut n = [0usize; 3];
                for (i, (axis, v)) in explicit.iter().enumerate() {
                    let key = format!("grid.{axis}");
                    let min = if i == 2 { 2 } else { 1 };
                    let v = v.ok_or_else(|| {
                        self.invalid(
                            key.as_str(),
                            "missing; give all of nx, ny, nz (or cell_nm alone)",
                        )
                    })?;
                    if v < min || v > MAX_GRID_DIM as i64 {
                        return Err(self
                            .invalid(key, format!("must be in [{min}, {MAX_GRID_DIM}], got {v}")));
                    }
                    let v = v as usize;
                    if i < 2 && !is_fft_size(v) {
                        return Err(self.invalid(
                            key,
                            format!(
                                "must be of the form 2^a 3^b 5^c (FFT-friendly), got {v}; \
                                 nearest larger is {}",
                                next_fft_size(v)
                            ),
                        ));
                    }
                    n[i] = v;
                }
                Ok(GridSpec {
                    nx: n[0],
                    ny: n[1],
                    nz: n[2],
                })
            }
        }
    }

    /// The wavelength list and the key it came from.
    fn wavelengths(&self, raw: &RawIllumination) -> Result<(Vec<f64>, &'static str), ConfigError> {
        match (&raw.wavelengths_nm, &raw.wavelength_range_nm) {
            (Some(_), Some(_)) => Err(self.invalid(
                "illumination",
                "give either wavelengths_nm or wavelength_range_nm, not both",
            )),
            (None, None) => Err(self.invalid(
                "illumination",
                "give either wavelengths_nm or wavelength_range_nm",
            )),
            (Some(list), None) => {
                let key = "illumination.wavelengths_nm";
                if list.is_empty() {
                    return Err(self.invalid(key, "must not be empty"));
                }
                if list.len() > MAX_WAVELENGTHS {
                    return Err(self.invalid(
                        key,
                        format!("at most {MAX_WAVELENGTHS} values, got {}", list.len()),
                    ));
                }
                for (i, &w) in list.iter().enumerate() {
                    let k = format!("{key}[{i}]");
                    self.range(&k, w, w > 0.0 && w.is_finite(), "(0, inf) nm")?;
                    if i > 0 && w <= list[i - 1] {
                        return Err(self.invalid(
                            k,
                            format!(
                                "values must be strictly increasing, got {w} after {}",
                                list[i - 1]
                            ),
                        ));
                    }
                }
                Ok((list.clone(), key))
            }
            (None, Some(r)) => {
                let key = "illumination.wavelength_range_nm";
                self.range(
                    &format!("{key}.start"),
                    r.start,
                    r.start > 0.0 && r.start.is_finite(),
                    "(0, inf) nm",
                )?;
                self.range(
                    &format!("{key}.stop"),
                    r.stop,
                    r.stop >= r.start && r.stop.is_finite(),
                    &format!("[start, inf) = [{}, inf) nm", r.start),
                )?;
                self.range(
                    &format!("{key}.step"),
                    r.step,
                    r.step > 0.0 && r.step.is_finite(),
                    "(0, inf) nm",
                )?;
                let q = (r.stop - r.start) / r.step;
                if q + 1.0 > MAX_WAVELENGTHS as f64 {
                    return Err(self.invalid(
                        key,
                        format!(
                            "gives {} wavelengths, more than {MAX_WAVELENGTHS}; use a larger step",
                            q.floor() + 1.0
                        ),
                    ));
                }
                let steps = (q * (1.0 + REL_EPS)).floor() as usize;
                let mut list: Vec<f64> = (0..=steps).map(|i| r.start + i as f64 * r.step).collect();
                let last = list.len() - 1;
                if (list[last] - r.stop).abs() <= REL_EPS * r.step {
                    list[last] = r.stop;
                }
                Ok((list, key))
            }
        }
    }

    fn incidence(&self, raw: &RawIllumination) -> Result<Vec<Incidence>, ConfigError> {
        let key = "illumination.polar_deg";
        if raw.polar_deg.is_empty() {
            return Err(self.invalid(key, "must not be empty"));
        }
        let a = raw.azimuth_deg.unwrap_or(0.0);
        let azimuth_deg = self.range(
            "illumination.azimuth_deg",
            a,
            (-360.0..=360.0).contains(&a),
            "[-360, 360] deg",
        )?;
        let mut out = Vec::with_capacity(raw.polar_deg.len());
        for (i, &p) in raw.polar_deg.iter().enumerate() {
            let k = format!("{key}[{i}]");
            self.range(
                &k,
                p,
                (0.0..=MAX_POLAR_DEG).contains(&p),
                &format!("[0, {MAX_POLAR_DEG}] deg"),
            )?;
            if i > 0 && p <= raw.polar_deg[i - 1] {
                return Err(self.invalid(
                    k,
                    format!(
                        "values must be strictly increasing, got {p} after {}",
                        raw.polar_deg[i - 1]
                    ),
                ));
            }
            out.push(Incidence {
                polar_deg: p,
                azimuth_deg,
            });
        }
        Ok(out)
    }

    fn solver(&self, raw: Option<&RawSolver>) -> Result<SolverSpec, ConfigError> {
        let method = raw
            .and_then(|s| s.method)
            .map_or(Method::Auto, |RawMethod(m)| m);
        let t = raw.and_then(|s| s.tolerance).unwrap_or(DEFAULT_TOLERANCE);
        let tolerance = self.range(
            "solver.tolerance",
            t,
            (1e-12..=1e-1).contains(&t),
            "[1e-12, 1e-1]",
        )?;
        let max_iterations = match raw.and_then(|s| s.max_iterations) {
            None => DEFAULT_MAX_ITERATIONS,
            Some(m) if (1..=MAX_ITERATIONS).contains(&m) => m as usize,
            Some(m) => {
                return Err(self.invalid(
                    "solver.max_iterations",
                    format!("must be in [1, {MAX_ITERATIONS}], got {m}"),
                ))
            }
        };
        let precision = match raw.and_then(|s| s.precision) {
            Some(RawPrecision::F32) => Precision::F32,
            Some(RawPrecision::F64) | None => Precision::F64,
        };
        if precision == Precision::F32 && tolerance < F32_MIN_TOLERANCE {
            return Err(self.invalid(
                "solver.tolerance",
                format!(
                    "must be in [{F32_MIN_TOLERANCE:e}, 1e-1] with precision = \"f32\" \
                     (f32 fields cannot hold a smaller residual), got {tolerance:e}"
                ),
            ));
        }
        let e = raw
            .and_then(|s| s.effective_medium_tolerance)
            .unwrap_or(DEFAULT_EFFECTIVE_MEDIUM_TOLERANCE);
        let effective_medium_tolerance = self.range(
            "solver.effective_medium_tolerance",
            e,
            (0.0..=MAX_EFFECTIVE_MEDIUM_TOLERANCE).contains(&e),
            "[0, 0.1] (absolute error in R, T, A; 0 never takes the shortcut)",
        )?;
        Ok(SolverSpec {
            method,
            tolerance,
            max_iterations,
            precision,
            effective_medium_tolerance,
        })
    }

    fn output(&self, path: &Path, raw: Option<&RawOutput>) -> Result<OutputSpec, ConfigError> {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "scene".to_string());
        let dir = match raw.and_then(|o| o.dir.as_deref()) {
            Some(d) if d.trim().is_empty() => {
                return Err(self.invalid("output.dir", "must not be empty"))
            }
            Some(d) => PathBuf::from(d),
            None => Path::new("runs").join(&stem),
        };
        let (name, from_stem) = match raw.and_then(|o| o.name.clone()) {
            Some(n) => (n, false),
            None => (stem, true),
        };
        let valid = !name.is_empty()
            && name != "."
            && name != ".."
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-'));
        if !valid {
            let origin = if from_stem {
                " (defaulted from the config file name; set output.name)"
            } else {
                ""
            };
            return Err(self.invalid(
                "output.name",
                format!("must be non-empty and use only A-Z a-z 0-9 _ . -, got `{name}`{origin}"),
            ));
        }
        Ok(OutputSpec { dir, name })
    }
}

/// Whether `n ≥ 1` has no prime factor other than 2, 3, 5.
fn is_fft_size(mut n: usize) -> bool {
    if n == 0 {
        return false;
    }
    for p in [2, 3, 5] {
        while n.is_multiple_of(p) {
            n /= p;
        }
    }
    n == 1
}

/// Smallest 2^a·3^b·5^c ≥ `n` (`n ≥ 1`).
fn next_fft_size(n: usize) -> usize {
    let mut m = n.max(1);
    while !is_fft_size(m) {
        m += 1;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_sizes() {
        let smooth: Vec<usize> = (1..=30).filter(|&n| is_fft_size(n)).collect();
        assert_eq!(
            smooth,
            [1, 2, 3, 4, 5, 6, 8, 9, 10, 12, 15, 16, 18, 20, 24, 25, 27, 30]
        );
        assert!(!is_fft_size(0));
        assert_eq!(next_fft_size(7), 8);
        assert_eq!(next_fft_size(81), 81);
        assert_eq!(next_fft_size(97), 100);
        assert_eq!(next_fft_size(4096), 4096);
        assert_eq!(next_fft_size(4001), 4050);
    }
}
