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
//! - `Provenance::input_hash` is SHA-256 over the config's tables without
//!   `[output]`, in a canonical form (sorted keys, no comments), followed by each
//!   pigment's table text (a library crystal's: both of its tables), in
//!   pigment order, then each structure primitive's table text or the bytes
//!   of the structure's HDF5 file.
//! - `[structure]` (explicit layer) and `[[pigment]]` exclude each other.
//!
//! One file per part of the scene, each adding its methods to [`Checker`]:
//! `scene` (the whole scene, wavelength coverage, input hash, output names),
//! `layer` (thickness, fragment, binder, grid), `pigments` (species, shapes,
//! sizes, agglomeration), `material` (builtin, library, index, CSV), `structure`
//! (explicit primitives or an ε grid), `illumination` (wavelengths, polar
//! angles), `solver` (method, tolerance, precision) and `appearance`
//! (products, viewing angles, substrate).

mod appearance;
mod illumination;
mod layer;
mod material;
mod paint;
mod pigments;
mod scene;
mod solver;
pub use solver::DEFAULT_ENERGY_BALANCE_LIMIT;
mod stack;
mod structure;

use super::paint::PaintScene;
use super::raw::RawConfig;
use super::raw_paint::RawPaintConfig;
use super::{ConfigError, Scene};
use std::path::Path;

/// Largest polar angle, of illumination and of viewing.
const MAX_POLAR_DEG: f64 = 89.0;
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
    let raw: RawConfig = parse_raw(path, text)?;
    checker(path).scene(path, text, raw)
}

/// The raw tables of TOML `text`; a parse error names `path`, the line and
/// the column.
fn parse_raw<T: serde::de::DeserializeOwned>(path: &Path, text: &str) -> Result<T, ConfigError> {
    toml::from_str(text).map_err(|e| ConfigError::Parse {
        file: path.to_path_buf(),
        message: parse_message(text, &e),
    })
}

/// The checker of the file at `path`.
fn checker(path: &Path) -> Checker<'_> {
    Checker {
        file: path,
        prefix: String::new(),
    }
}

/// Parses and validates an effect paint's TOML `text` (a file with a
/// `[paint]` table, [`is_paint_text`]).
pub fn parse_paint(path: &Path, text: &str) -> Result<PaintScene, ConfigError> {
    let raw: RawPaintConfig = parse_raw(path, text)?;
    checker(path).paint(path, text, raw)
}

/// Whether TOML `text` describes an effect paint (has a top-level `[paint]`
/// table); false for text that is not TOML.
pub fn is_paint_text(text: &str) -> bool {
    text.parse::<toml::Table>()
        .is_ok_and(|t| t.get("paint").is_some_and(|v| v.is_table()))
}

/// The toml error on one line: `line L, column C: message; more`.
fn parse_message(text: &str, e: &toml::de::Error) -> String {
    let msg = in_config_terms(
        &e.message()
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join("; "),
    );
    match e.span() {
        Some(span) => {
            let mut start = span.start.min(text.len());
            while !text.is_char_boundary(start) {
                start -= 1;
            }
            let before = &text[..start];
            let line = before.matches('\n').count() + 1;
            let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            let msg = match msg.as_str() {
                "missing field `kind`" => missing_kind(text.lines().nth(line - 1).unwrap_or("")),
                _ => msg,
            };
            format!("line {line}, column {col}: {msg}")
        }
        None => msg,
    }
}

/// The tables a tagged key takes, by the name of its raw type.
const TAGGED: [(&str, &str); 6] = [
    (
        "RawShape",
        "a grain shape: { kind = \"sphere\" }, { kind = \"molecular\" }, or \
         { kind = \"rice\" | \"cylinder\", aspect, spheres }",
    ),
    (
        "RawSize",
        "a size distribution: { kind = \"fixed\" }, { kind = \"normal\", sigma } or \
         { kind = \"log-normal\", sigma }",
    ),
    (
        "RawBody",
        "a body: { kind = \"slab\", z_nm }, { kind = \"box\", min_nm, max_nm }, \
         { kind = \"sphere\", center_nm, radius_nm } or { kind = \"cylinder\", … }",
    ),
    (
        "RawSurface",
        "a surface: { kind = \"flat\" }, { kind = \"conformal\", film_nm } or \
         { kind = \"rough\", rms_nm, correlation_nm }",
    ),
    (
        "RawSubstrate",
        "a substrate: { kind = \"paper\", albedo }, { kind = \"white\", albedo }, \
         { kind = \"black\" }, { kind = \"csv\", file }, { kind = \"chart\", white_albedo \
         or white_csv } or { kind = \"none\" }",
    ),
    (
        "RawStructure",
        "a structure: kind = \"primitives\" with [[structure.primitive]] tables, \
         kind = \"layers\" with materials and [[structure.layer]] tables, or \
         kind = \"hdf5\" with file",
    ),
];

/// serde's wording for the config's enums put in the config's terms: a
/// tagged key given as a bare string or without `kind`, a material with
/// none or several of its kinds.
fn in_config_terms(msg: &str) -> String {
    const MATERIAL: &str = "a material is a table with exactly one of `builtin`, `library`, \
                            `csv`, `index`, `epsilon` (e.g. material = { library = \"rutile\" })";
    if msg.contains("wanted exactly 1 element, more than 1 element") {
        return format!("{MATERIAL}; this one gives more than one");
    }
    if msg.contains("wanted exactly 1 element, found 0 elements") {
        return format!("{MATERIAL}; this one gives none");
    }
    for (raw, wanted) in TAGGED {
        if msg.contains(&format!("expected internally tagged enum {raw}")) {
            let got = msg
                .strip_prefix("invalid type: ")
                .and_then(|m| m.split(", expected").next())
                .map(|g| format!(", got {g}"))
                .unwrap_or_default();
            return format!("expected {wanted}{got}");
        }
    }
    msg.to_string()
}

/// A tagged table without `kind`, on the line `key = { … }`: name the key
/// and the kinds it takes.
fn missing_kind(line: &str) -> String {
    // `shape = { … }` or a table header `[pigment.shape]`.
    let line = line.trim();
    let key = match line.strip_prefix('[') {
        Some(h) => h.trim_matches(|c| c == '[' || c == ']').rsplit('.').next(),
        None => line.split('=').next(),
    }
    .unwrap_or("")
    .trim();
    let raw: &[&str] = match key {
        "shape" => &["RawShape", "RawBody"],
        "size" => &["RawSize"],
        "surface" => &["RawSurface"],
        "substrate" => &["RawSubstrate"],
        _ => &[],
    };
    let kinds: Vec<&str> = TAGGED
        .iter()
        .filter(|(r, _)| raw.contains(r))
        .map(|(_, w)| *w)
        .collect();
    match kinds.is_empty() {
        true => "missing `kind`, the key that says which form this table takes".into(),
        false => format!(
            "`{key}` is missing `kind`: expected {}",
            kinds.join("; or ")
        ),
    }
}

/// A number as a message shows it: as written for ordinary magnitudes, in
/// exponent form (`1e300`, `1e-9`) for very large or small ones.
pub(crate) fn num(v: f64) -> String {
    let a = v.abs();
    if v.is_finite() && v != 0.0 && !(1e-4..1e7).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Checks the parts of one file's raw scene; every error names `file`.
struct Checker<'a> {
    file: &'a Path,
    /// Put before every key an error names (`stack[1].` inside a stack).
    prefix: String,
}

impl Checker<'_> {
    fn invalid(&self, key: impl Into<String>, message: impl Into<String>) -> ConfigError {
        ConfigError::Invalid {
            file: self.file.to_path_buf(),
            key: format!("{}{}", self.prefix, key.into()),
            message: message.into(),
        }
    }

    /// `Ok(v)` when `ok`, else "must be in {range}, got {v}".
    fn range(&self, key: &str, v: f64, ok: bool, range: &str) -> Result<f64, ConfigError> {
        if ok {
            Ok(v)
        } else {
            Err(self.invalid(key, format!("must be in {range}, got {}", num(v))))
        }
    }

    /// Every value of `list` in range (`ok`, message as [`Self::range`]) and
    /// strictly increasing, checked in order; errors name `key[i]`.
    fn increasing(
        &self,
        key: &str,
        list: &[f64],
        ok: impl Fn(f64) -> bool,
        range: &str,
    ) -> Result<(), ConfigError> {
        for (i, &v) in list.iter().enumerate() {
            let k = format!("{key}[{i}]");
            self.range(&k, v, ok(v), range)?;
            if i > 0 && v <= list[i - 1] {
                return Err(self.invalid(
                    k,
                    format!(
                        "values must be strictly increasing, got {} after {}",
                        num(v),
                        num(list[i - 1])
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Polar angles in `[0, MAX_POLAR_DEG]`, strictly increasing.
    fn polar_angles(&self, key: &str, list: &[f64]) -> Result<(), ConfigError> {
        self.increasing(
            key,
            list,
            |p| (0.0..=MAX_POLAR_DEG).contains(&p),
            &format!("[0, {MAX_POLAR_DEG}] deg"),
        )
    }
}
