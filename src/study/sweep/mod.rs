//! The sweep file and its expansion into variants.
//!
//! Takes the text of a sweep file; gives the checked [`Study`] (by
//! [`Study::load`] / [`Study::parse`]) and, for one profile, its
//! [`Expansion`]: the named, seeded, validated [`Variant`]s (by
//! [`Study::expand`]). Every error names the sweep file and the key or
//! table at fault, and is found before any work starts.
//!
//! - `raw`: the serde structs of the file as written (unknown keys denied).
//! - `check`: raw → [`Study`] (names, key paths, axes, zips, labels, grids).
//! - `expand`: [`Study`] → [`Expansion`] (product, exclusions, explicit
//!   variants, each scene built and validated).
//! - `keypath`: key-path checks and [`apply_override`], the editing of a
//!   scene table.
//!
//! A sweep file is TOML with a `[study]` table (see docs/STUDY.md):
//!
//! ```toml
//! [study]
//! name = "pigments"          # [A-Za-z0-9_.-]
//! seed = 2024                # study seed (>= 0)
//! profile = "quick"          # default profile (needed when profiles exist)
//! output_dir = "runs/pigments"   # default runs/<name>; relative to the working dir
//!
//! base = "scene.toml"        # relative to this file; or an inline [base] table
//!
//! [profiles.quick]
//! "grid.cell_nm" = 50.0      # quoted dotted key path = TOML value
//!
//! [[axis]]                   # simple form: labels generated
//! name = "pvc"
//! key = "layer.pvc"
//! values = [0.15, 0.3, 0.5]
//!
//! [[axis]]                   # compound form
//! name = "pigment"
//! [[axis.value]]
//! label = "red"
//! set = { "pigment.0.material" = { builtin = "red" } }
//! ```
//!
//! The base is a wave-optics scene (`[layer]`, expanded by
//! [`Study::expand`]) or an effect paint (`[paint]`, by
//! [`Study::expand_paint`]); the scene kind is a [`VariantScene`].
//!
//! Key paths are `.`-separated; an array element is addressed by its index
//! (`pigment.0.diameter_nm`), by `*`, every element (`pigment.*.shape`), or
//! by its `name` (`paint.layer.basecoat.thickness_um`). An
//! `[[axis.value]]` may `remove = ["paint.layer.clearcoat"]` (after every
//! `set`).
//! A missing table on the way is created (`deny_unknown_fields` of the scene
//! schema then rejects a misspelt key, and the error names the axis).
//!
//! Expansion: the cartesian product of the axes, in file order, the last
//! axis varying fastest; `[study] zip = ["a", "b"]` (or a list of such
//! groups) makes axes advance together; `[[exclude]]` tables (`axis = "label"`, all must
//! match) drop combinations, and each must drop at least one; `[[variant]]`
//! tables add explicit variants (`name`, optional `labels = { axis = "label" }`
//! whose axis values are applied, optional `set`). A variant's scene is the
//! base, then the profile's overrides, then each axis value's overrides in
//! axis order, then an explicit variant's `set`; finally `seed`,
//! `output.dir` and `output.name` are set (they are reserved). Its name is
//! the axis labels joined by `_`, sanitised to `[A-Za-z0-9_.-]` (other
//! characters become `-`). Its seed is [`variant_seed`]: SHA-256 of
//! `"<study seed>:<variant name>"`, the first 8 bytes as a big-endian u64,
//! top bit cleared — a function of the name only, never of the position or
//! of the scheduling. Its id is the first 8 hex digits of SHA-256(name).
//!
//! Every variant's text is validated with [`crate::config::parse_scene`] up front;
//! that exact text is what the result file embeds.

mod check;
mod expand;
mod keypath;
mod raw;
mod select;

pub use check::base_table;
pub use keypath::apply_override;
pub use select::Selection;

use super::StudyError;
use crate::config::paint::PaintScene;
use crate::config::{ConfigError, Scene};
use raw::RawSweep;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// One override: a key path and the TOML value it gets.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    pub key: String,
    pub value: Value,
}

/// One value of an axis: its label, what it sets and what it removes.
#[derive(Debug, Clone)]
pub struct AxisValue {
    pub label: String,
    pub set: Vec<Override>,
    /// Key paths removed from the scene (`paint.layer.clearcoat`), after
    /// every `set` of the variant.
    pub remove: Vec<String>,
}

/// An axis of the sweep.
#[derive(Debug, Clone)]
pub struct Axis {
    pub name: String,
    pub values: Vec<AxisValue>,
    /// The steps `from → to` the effects table compares along this axis:
    /// the sweep file's `compare`, else each label to the next.
    pub compare: Vec<(String, String)>,
}

/// A comparison grid declared in the sweep file (or the default ones).
#[derive(Debug, Clone, PartialEq)]
pub struct GridDecl {
    pub name: String,
    pub rows: String,
    pub cols: String,
    /// Axis → label restrictions; axes neither rows, cols nor here split the
    /// grid into one picture per combination of their labels.
    pub where_: BTreeMap<String, String>,
    /// Row / column labels to show, in this order (default: all).
    pub row_labels: Option<Vec<String>>,
    pub col_labels: Option<Vec<String>>,
}

/// The parsed sweep file, before a profile is chosen.
#[derive(Debug, Clone)]
pub struct Study {
    /// The sweep file.
    pub path: PathBuf,
    pub name: String,
    pub seed: u64,
    pub default_profile: Option<String>,
    /// `[study] output_dir` (or `runs/<name>`), as written.
    pub output_dir: PathBuf,
    /// Profile name → overrides, sorted by name.
    pub profiles: BTreeMap<String, Vec<Override>>,
    pub axes: Vec<Axis>,
    /// Groups of axis indices that advance together, in axis order; every
    /// axis is in exactly one group.
    pub groups: Vec<Vec<usize>>,
    pub grids: Vec<GridDecl>,
    base: Table,
    /// Path handed to `parse_scene` (CSV tables resolve beside it).
    base_path: PathBuf,
    excludes: Vec<BTreeMap<String, String>>,
    explicit: Vec<ExplicitVariant>,
}

/// A checked `[[variant]]` table.
#[derive(Debug, Clone)]
struct ExplicitVariant {
    name: String,
    labels: BTreeMap<String, String>,
    set: Vec<Override>,
}

/// What a variant's scene may be: a wave-optics [`Scene`] (a `[layer]`
/// base) or an effect paint's [`PaintScene`] (a `[paint]` base).
pub trait VariantScene: Sized {
    /// Whether this kind is an effect paint (its base has a `[paint]` table).
    const PAINT: bool;
    /// Whether the scene takes a `seed` (the fast model of a paint is
    /// deterministic and has none).
    const SEEDED: bool;
    /// Parse and validate a variant's TOML text.
    fn parse(path: &Path, text: &str) -> Result<Self, ConfigError>;
    /// Why this scene cannot be a variant of a study, if it cannot.
    fn study_problem(&self) -> Option<String>;
}

impl VariantScene for Scene {
    const PAINT: bool = false;
    const SEEDED: bool = true;
    fn parse(path: &Path, text: &str) -> Result<Self, ConfigError> {
        crate::config::parse_scene(path, text)
    }
    fn study_problem(&self) -> Option<String> {
        // The merge compares the variants' colours and tiles.
        (!self.appearance.products.tile).then(|| {
            "appearance.outputs must include \"tile\" in a study (the merge compares the \
             variants' colours and tiles)"
                .into()
        })
    }
}

impl VariantScene for PaintScene {
    const PAINT: bool = true;
    const SEEDED: bool = false;
    fn parse(path: &Path, text: &str) -> Result<Self, ConfigError> {
        crate::config::parse_paint(path, text)
    }
    fn study_problem(&self) -> Option<String> {
        None
    }
}

/// One expanded variant: a named, seeded, validated scene (a wave-optics
/// layer's, or an effect paint's with `S = PaintScene`).
#[derive(Debug, Clone)]
pub struct Variant<S = Scene> {
    /// Position in the expansion order (what shards split on).
    pub index: usize,
    /// First 8 hex digits of SHA-256(name).
    pub id: String,
    pub name: String,
    /// (axis, label) for each axis that has a label in this variant, in axis order.
    pub labels: Vec<(String, String)>,
    pub seed: u64,
    /// The exact scene TOML (embedded in the result file).
    pub text: String,
    pub scene: S,
}

impl<S> Variant<S> {
    /// This variant's label on `axis`, if any.
    pub fn label(&self, axis: &str) -> Option<&str> {
        self.labels
            .iter()
            .find(|(a, _)| a == axis)
            .map(|(_, l)| l.as_str())
    }
}

/// The variants of a study for one profile.
#[derive(Debug, Clone)]
pub struct Expansion<S = Scene> {
    /// The profile used (`None` when the study has no profiles).
    pub profile: Option<String>,
    /// `<output_dir>/<profile>` (or `<output_dir>` without profiles).
    pub study_dir: PathBuf,
    pub variants: Vec<Variant<S>>,
    /// The `--only` restrictions that chose these variants (empty: all).
    pub selection: Vec<Selection>,
}

/// Whether TOML `text` is a sweep file (has a `[study]` table).
pub fn is_study_text(text: &str) -> bool {
    text.parse::<Table>()
        .map(|t| t.contains_key("study"))
        .unwrap_or(false)
}

/// The documented seed of a variant: SHA-256 of `"<study_seed>:<name>"`,
/// first 8 bytes big-endian, top bit cleared (scene seeds are ≥ 0 as i64).
pub fn variant_seed(study_seed: u64, name: &str) -> u64 {
    let digest = Sha256::digest(format!("{study_seed}:{name}").as_bytes());
    let mut b = [0u8; 8];
    b.copy_from_slice(&digest[..8]);
    u64::from_be_bytes(b) & 0x7fff_ffff_ffff_ffff
}

/// First 8 hex digits of SHA-256(name).
pub fn variant_id(name: &str) -> String {
    Sha256::digest(name.as_bytes())[..4]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// `s` with every character outside `[A-Za-z0-9_.-]` replaced by `-`.
pub fn sanitise(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-') {
                c
            } else {
                '-'
            }
        })
        .collect()
}
impl Study {
    /// Read and check a sweep file (not yet its variants: see [`Study::expand`]).
    pub fn load(path: &Path) -> Result<Study, StudyError> {
        let text = std::fs::read_to_string(path).map_err(|source| StudyError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        Study::parse(path, &text)
    }

    /// Parse sweep `text` read from `path`: the TOML into the raw structs,
    /// then the checks.
    pub fn parse(path: &Path, text: &str) -> Result<Study, StudyError> {
        let raw: RawSweep = toml::from_str(text).map_err(|e| {
            // Where the parser stopped, as a line number.
            let at = e.span().map_or(String::new(), |s| {
                let start = (0..=s.start.min(text.len()))
                    .rev()
                    .find(|&i| text.is_char_boundary(i))
                    .unwrap_or(0);
                format!("line {}: ", text[..start].matches('\n').count() + 1)
            });
            sweep_error(
                path,
                format!(
                    "{at}{} (a sweep file has [study], base, [profiles.*], [[axis]], zip, \
                     [[variant]], [[exclude]], [[grid]])",
                    e.message().trim()
                ),
            )
        })?;
        check::check(path, raw)
    }

    fn err(&self, message: String) -> StudyError {
        sweep_error(&self.path, message)
    }

    /// The profile to use: `requested`, else the study's default; `None`
    /// when the study defines no profiles.
    pub fn resolve_profile(&self, requested: Option<&str>) -> Result<Option<String>, StudyError> {
        match requested.or(self.default_profile.as_deref()) {
            Some(p) if self.profiles.contains_key(p) => Ok(Some(p.to_string())),
            Some(p) => Err(self.err(format!(
                "unknown profile `{p}`; defined: {}",
                list_or_none(self.profiles.keys())
            ))),
            None if self.profiles.is_empty() => Ok(None),
            None => Err(self.err(format!(
                "no profile chosen: give --profile or `study.profile`; defined: {}",
                list_or_none(self.profiles.keys())
            ))),
        }
    }

    /// The study folder of a profile: `<output_dir>/<profile>`.
    pub fn study_dir(&self, profile: Option<&str>) -> PathBuf {
        match profile {
            Some(p) => self.output_dir.join(p),
            None => self.output_dir.clone(),
        }
    }

    /// Whether the base is an effect paint (a `[paint]` table): its variants
    /// are expanded by [`Study::expand_paint`] and run by the fast model.
    pub fn is_paint(&self) -> bool {
        self.base.get("paint").is_some_and(Value::is_table)
    }

    /// Number of combinations of the product (before exclusions).
    pub fn product_size(&self) -> usize {
        self.groups
            .iter()
            .map(|g| self.axes[g[0]].values.len())
            .product::<usize>()
            * usize::from(!self.axes.is_empty())
    }
}

/// A [`StudyError::Sweep`] naming the sweep file `file`.
fn sweep_error(file: &Path, message: String) -> StudyError {
    StudyError::Sweep {
        file: file.to_path_buf(),
        message,
    }
}

/// The names, `, `-joined, or `(none)`.
fn list_or_none<'a>(it: impl Iterator<Item = &'a String>) -> String {
    let v: Vec<&str> = it.map(String::as_str).collect();
    if v.is_empty() {
        "(none)".into()
    } else {
        v.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::check::generated_label;
    use super::*;

    #[test]
    fn seeds_depend_on_the_name_only() {
        // The documented hash, recomputed independently: SHA-256("7:red_pvc30")
        // first 8 bytes, top bit cleared.
        let d = Sha256::digest(b"7:red_pvc30");
        let want = u64::from_be_bytes(d[..8].try_into().unwrap()) & (u64::MAX >> 1);
        assert_eq!(variant_seed(7, "red_pvc30"), want);
        assert_ne!(variant_seed(7, "red_pvc30"), variant_seed(8, "red_pvc30"));
        assert_ne!(variant_seed(7, "red_pvc30"), variant_seed(7, "red_pvc50"));
        assert_eq!(variant_id("x").len(), 8);
    }

    #[test]
    fn labels_and_sanitising() {
        assert_eq!(sanitise("yellow+blue 1/2"), "yellow-blue-1-2");
        assert_eq!(
            generated_label("pvc", &Value::Float(0.15)).unwrap(),
            "pvc0.15"
        );
        assert_eq!(generated_label("d", &Value::Float(200.0)).unwrap(), "d200");
        assert_eq!(generated_label("n", &Value::Integer(3)).unwrap(), "n3");
        assert_eq!(
            generated_label("p", &Value::String("red".into())).unwrap(),
            "red"
        );
        assert!(generated_label("p", &Value::Array(vec![])).is_none());
    }
}
