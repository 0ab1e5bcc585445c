//! The sweep file and its expansion into variants.
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
//! Key paths are `.`-separated; an array element is addressed by its index
//! (`pigment.0.diameter_nm`) or by `*`, every element (`pigment.*.shape`).
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
//! Every variant's text is validated with [`config::parse_scene`] up front;
//! that exact text is what the result file embeds.

use super::StudyError;
use crate::config::{self, Scene};
use serde::Deserialize;
use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// Keys a sweep may not override: the driver sets them per variant.
const RESERVED: [&str; 4] = ["seed", "output", "output.dir", "output.name"];

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSweep {
    study: RawStudy,
    base: Option<Value>,
    #[serde(default)]
    profiles: BTreeMap<String, Table>,
    #[serde(default)]
    axis: Vec<RawAxis>,
    #[serde(default)]
    variant: Vec<RawVariant>,
    #[serde(default)]
    exclude: Vec<BTreeMap<String, String>>,
    #[serde(default)]
    grid: Vec<RawGrid>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStudy {
    name: String,
    seed: Option<i64>,
    profile: Option<String>,
    output_dir: Option<String>,
    zip: Option<Value>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxis {
    name: String,
    key: Option<String>,
    values: Option<Vec<Value>>,
    labels: Option<Vec<String>>,
    value: Option<Vec<RawAxisValue>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxisValue {
    label: String,
    #[serde(default)]
    set: Table,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawVariant {
    name: String,
    #[serde(default)]
    labels: BTreeMap<String, String>,
    #[serde(default)]
    set: Table,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGrid {
    name: String,
    rows: String,
    cols: String,
    #[serde(default, rename = "where")]
    where_: BTreeMap<String, String>,
    row_labels: Option<Vec<String>>,
    col_labels: Option<Vec<String>>,
}

/// One override: a key path and the TOML value it gets.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    pub key: String,
    pub value: Value,
}

/// One value of an axis: its label and what it sets.
#[derive(Debug, Clone)]
pub struct AxisValue {
    pub label: String,
    pub set: Vec<Override>,
}

/// An axis of the sweep.
#[derive(Debug, Clone)]
pub struct Axis {
    pub name: String,
    pub values: Vec<AxisValue>,
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
    explicit: Vec<RawVariantChecked>,
}

#[derive(Debug, Clone)]
struct RawVariantChecked {
    name: String,
    labels: BTreeMap<String, String>,
    set: Vec<Override>,
}

/// One expanded variant: a named, seeded, validated scene.
#[derive(Debug, Clone)]
pub struct Variant {
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
    pub scene: Scene,
}

impl Variant {
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
pub struct Expansion {
    /// The profile used (`None` when the study has no profiles).
    pub profile: Option<String>,
    /// `<output_dir>/<profile>` (or `<output_dir>` without profiles).
    pub study_dir: PathBuf,
    pub variants: Vec<Variant>,
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

/// A generated label for a simple-form axis value: strings as they are,
/// numbers and booleans after the axis name (`pvc0.15`, `d200`).
fn generated_label(axis: &str, v: &Value) -> Option<String> {
    match v {
        Value::String(s) => Some(s.clone()),
        Value::Integer(i) => Some(format!("{axis}{i}")),
        Value::Float(f) if f.fract() == 0.0 && f.abs() < 1e15 => {
            Some(format!("{axis}{}", *f as i64))
        }
        Value::Float(f) => Some(format!("{axis}{f}")),
        Value::Boolean(b) => Some(format!("{axis}-{b}")),
        _ => None,
    }
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

    /// Parse sweep `text` read from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Study, StudyError> {
        let err = |message: String| StudyError::Sweep {
            file: path.to_path_buf(),
            message,
        };
        let raw: RawSweep = toml::from_str(text).map_err(|e| {
            err(format!(
                "{} (a sweep file has [study], base, [profiles.*], [[axis]], zip, \
                 [[variant]], [[exclude]], [[grid]])",
                e.message().trim()
            ))
        })?;
        let name = raw.study.name.clone();
        if name.is_empty() || sanitise(&name) != name {
            return Err(err(format!(
                "key `study.name`: must be non-empty and use only A-Z a-z 0-9 _ . -, got `{name}`"
            )));
        }
        let seed = match raw.study.seed {
            None => 1,
            Some(s) if s >= 0 => s as u64,
            Some(s) => return Err(err(format!("key `study.seed`: must be >= 0, got {s}"))),
        };
        let output_dir = match raw.study.output_dir.as_deref() {
            Some(d) if d.trim().is_empty() => {
                return Err(err("key `study.output_dir`: must not be empty".into()))
            }
            Some(d) => PathBuf::from(d),
            None => Path::new("runs").join(&name),
        };

        let sweep_dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
        let (base, base_path) =
            match raw.base {
                None => return Err(err(
                    "missing `base`: give `base = \"scene.toml\"` (relative to this file) or an \
                     inline [base] table holding a complete scene"
                        .into(),
                )),
                Some(Value::String(f)) => {
                    let p = sweep_dir.join(&f);
                    let t = std::fs::read_to_string(&p).map_err(|e| {
                        err(format!(
                            "key `base`: cannot read scene `{}`: {e}",
                            p.display()
                        ))
                    })?;
                    let table: Table = t.parse().map_err(|e: toml::de::Error| {
                        err(format!(
                            "key `base`: {}: {}",
                            p.display(),
                            e.message().trim()
                        ))
                    })?;
                    (table, p)
                }
                Some(Value::Table(t)) => (t, path.to_path_buf()),
                Some(other) => {
                    return Err(err(format!(
                        "key `base`: must be a file name or a table, got a {}",
                        other.type_str()
                    )))
                }
            };
        let overrides = |t: &Table, what: &str| -> Result<Vec<Override>, StudyError> {
            let mut out = Vec::with_capacity(t.len());
            for (k, v) in t {
                check_key(k).map_err(|m| err(format!("{what}: key path `{k}`: {m}")))?;
                out.push(Override {
                    key: k.clone(),
                    value: v.clone(),
                });
            }
            Ok(out)
        };

        let mut profiles = BTreeMap::new();
        for (pname, t) in &raw.profiles {
            profiles.insert(pname.clone(), overrides(t, &format!("[profiles.{pname}]"))?);
        }
        if let Some(p) = &raw.study.profile {
            if !profiles.contains_key(p) {
                return Err(err(format!(
                    "key `study.profile`: unknown profile `{p}`; defined: {}",
                    list_or_none(profiles.keys())
                )));
            }
        }

        let mut axes: Vec<Axis> = Vec::with_capacity(raw.axis.len());
        for (i, a) in raw.axis.iter().enumerate() {
            let what = format!("axis `{}` ([[axis]] {})", a.name, i + 1);
            if a.name.is_empty() || sanitise(&a.name) != a.name {
                return Err(err(format!(
                    "{what}: name must be non-empty and use only A-Z a-z 0-9 _ . -"
                )));
            }
            if axes.iter().any(|b| b.name == a.name) {
                return Err(err(format!("{what}: two axes are named `{}`", a.name)));
            }
            let values = match (&a.key, &a.values, &a.value) {
                (Some(key), Some(vals), None) => {
                    check_key(key).map_err(|m| err(format!("{what}: key path `{key}`: {m}")))?;
                    if let Some(labels) = &a.labels {
                        if labels.len() != vals.len() {
                            return Err(err(format!(
                                "{what}: {} labels for {} values",
                                labels.len(),
                                vals.len()
                            )));
                        }
                    }
                    let mut out = Vec::with_capacity(vals.len());
                    for (j, v) in vals.iter().enumerate() {
                        let label = match &a.labels {
                            Some(l) => l[j].clone(),
                            None => generated_label(&a.name, v).ok_or_else(|| {
                                err(format!(
                                    "{what}: value {} is a {}; give `labels = [...]` for \
                                     non-scalar values",
                                    j + 1,
                                    v.type_str()
                                ))
                            })?,
                        };
                        out.push(AxisValue {
                            label,
                            set: vec![Override {
                                key: key.clone(),
                                value: v.clone(),
                            }],
                        });
                    }
                    out
                }
                (None, None, Some(vals)) => {
                    if a.labels.is_some() {
                        return Err(err(format!(
                            "{what}: `labels` goes with the simple form (key + values); \
                             [[axis.value]] entries carry their own label"
                        )));
                    }
                    let mut out = Vec::with_capacity(vals.len());
                    for (j, v) in vals.iter().enumerate() {
                        out.push(AxisValue {
                            label: v.label.clone(),
                            set: overrides(&v.set, &format!("{what}, value {}", j + 1))?,
                        });
                    }
                    out
                }
                _ => {
                    return Err(err(format!(
                        "{what}: give either `key` and `values` (simple form) or \
                         [[axis.value]] tables with `label` and `set` (compound form)"
                    )))
                }
            };
            if values.is_empty() {
                return Err(err(format!(
                    "{what}: has no values; an axis needs at least one"
                )));
            }
            let mut seen: HashMap<&str, usize> = HashMap::new();
            for (j, v) in values.iter().enumerate() {
                if v.label.is_empty() {
                    return Err(err(format!("{what}: value {} has an empty label", j + 1)));
                }
                if let Some(k) = seen.insert(v.label.as_str(), j) {
                    return Err(err(format!(
                        "{what}: label `{}` is used by values {} and {}",
                        v.label,
                        k + 1,
                        j + 1
                    )));
                }
            }
            axes.push(Axis {
                name: a.name.clone(),
                values,
            });
        }

        let axis_index = |n: &str| axes.iter().position(|a| a.name == n);
        let axis_names = || list_or_none(axes.iter().map(|a| &a.name));

        // Zip groups.
        let zip_groups: Vec<Vec<String>> = match &raw.study.zip {
            None => vec![],
            Some(Value::Array(items)) if items.iter().all(|v| v.is_str()) => {
                vec![items
                    .iter()
                    .filter_map(|v| v.as_str().map(str::to_string))
                    .collect()]
            }
            Some(Value::Array(items)) => {
                let mut gs = vec![];
                for it in items {
                    match it.as_array() {
                        Some(g) if g.iter().all(|v| v.is_str()) => gs.push(
                            g.iter()
                                .filter_map(|v| v.as_str().map(str::to_string))
                                .collect(),
                        ),
                        _ => return Err(err(
                            "key `study.zip`: must be a list of axis names or a list of such lists"
                                .into(),
                        )),
                    }
                }
                gs
            }
            Some(_) => {
                return Err(err(
                    "key `study.zip`: must be a list of axis names or a list of such lists".into(),
                ))
            }
        };
        let mut group_of: Vec<Option<usize>> = vec![None; axes.len()];
        for (g, names) in zip_groups.iter().enumerate() {
            if names.len() < 2 {
                return Err(err(format!(
                    "key `study.zip`: a group needs at least two axes, got {names:?}"
                )));
            }
            let mut len = None;
            for n in names {
                let i = axis_index(n).ok_or_else(|| {
                    err(format!(
                        "key `study.zip`: unknown axis `{n}`; axes: {}",
                        axis_names()
                    ))
                })?;
                if group_of[i].is_some() {
                    return Err(err(format!("key `study.zip`: axis `{n}` is zipped twice")));
                }
                group_of[i] = Some(g);
                let l = axes[i].values.len();
                match len {
                    None => len = Some((n, l)),
                    Some((first, l0)) if l0 != l => {
                        return Err(err(format!(
                            "key `study.zip`: zipped axes advance together and need equal lengths; \
                             `{first}` has {l0} values, `{n}` has {l}"
                        )))
                    }
                    _ => {}
                }
            }
        }
        let mut groups: Vec<Vec<usize>> = vec![];
        let mut placed: Vec<Option<usize>> = vec![None; zip_groups.len()];
        for (i, g) in group_of.iter().enumerate() {
            match *g {
                None => groups.push(vec![i]),
                Some(g) => match placed[g] {
                    Some(k) => groups[k].push(i),
                    None => {
                        placed[g] = Some(groups.len());
                        groups.push(vec![i]);
                    }
                },
            }
        }

        // Exclusions and explicit variants refer to axes by name and label.
        let check_labels = |m: &BTreeMap<String, String>, what: &str| -> Result<(), StudyError> {
            for (a, l) in m {
                let i = axis_index(a).ok_or_else(|| {
                    err(format!(
                        "{what}: unknown axis `{a}`; axes: {}",
                        axis_names()
                    ))
                })?;
                if !axes[i].values.iter().any(|v| &v.label == l) {
                    return Err(err(format!(
                        "{what}: axis `{a}` has no label `{l}`; labels: {}",
                        list_or_none(axes[i].values.iter().map(|v| &v.label))
                    )));
                }
            }
            Ok(())
        };
        for (i, ex) in raw.exclude.iter().enumerate() {
            let what = format!("[[exclude]] {}", i + 1);
            if ex.is_empty() {
                return Err(err(format!("{what}: is empty; it would drop everything")));
            }
            check_labels(ex, &what)?;
        }
        let mut explicit = vec![];
        for (i, v) in raw.variant.iter().enumerate() {
            let what = format!("[[variant]] {} (`{}`)", i + 1, v.name);
            if v.name.is_empty() || sanitise(&v.name) != v.name {
                return Err(err(format!(
                    "{what}: name must be non-empty and use only A-Z a-z 0-9 _ . -"
                )));
            }
            check_labels(&v.labels, &what)?;
            explicit.push(RawVariantChecked {
                name: v.name.clone(),
                labels: v.labels.clone(),
                set: overrides(&v.set, &what)?,
            });
        }

        let mut grids = vec![];
        for (i, g) in raw.grid.iter().enumerate() {
            let what = format!("[[grid]] {} (`{}`)", i + 1, g.name);
            if g.name.is_empty() || sanitise(&g.name) != g.name {
                return Err(err(format!(
                    "{what}: name must be non-empty and use only A-Z a-z 0-9 _ . -"
                )));
            }
            for (k, a) in [("rows", &g.rows), ("cols", &g.cols)] {
                if axis_index(a).is_none() {
                    return Err(err(format!(
                        "{what}: key `{k}`: unknown axis `{a}`; axes: {}",
                        axis_names()
                    )));
                }
            }
            if g.rows == g.cols {
                return Err(err(format!("{what}: rows and cols are the same axis")));
            }
            check_labels(&g.where_, &format!("{what}: key `where`"))?;
            for (k, axis, labels) in [
                ("row_labels", &g.rows, &g.row_labels),
                ("col_labels", &g.cols, &g.col_labels),
            ] {
                if let Some(ls) = labels {
                    let m: BTreeMap<String, String> =
                        ls.iter().map(|l| (axis.clone(), l.clone())).collect();
                    check_labels(&m, &format!("{what}: key `{k}`"))?;
                }
            }
            grids.push(GridDecl {
                name: g.name.clone(),
                rows: g.rows.clone(),
                cols: g.cols.clone(),
                where_: g.where_.clone(),
                row_labels: g.row_labels.clone(),
                col_labels: g.col_labels.clone(),
            });
        }
        if grids.is_empty() && axes.len() >= 2 {
            grids.push(GridDecl {
                name: format!("{}-by-{}", axes[0].name, axes[1].name),
                rows: axes[0].name.clone(),
                cols: axes[1].name.clone(),
                where_: BTreeMap::new(),
                row_labels: None,
                col_labels: None,
            });
        }

        Ok(Study {
            path: path.to_path_buf(),
            name,
            seed,
            default_profile: raw.study.profile,
            output_dir,
            profiles,
            axes,
            groups,
            grids,
            base,
            base_path,
            excludes: raw.exclude,
            explicit,
        })
    }

    fn err(&self, message: String) -> StudyError {
        StudyError::Sweep {
            file: self.path.clone(),
            message,
        }
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

    /// Number of combinations of the product (before exclusions).
    pub fn product_size(&self) -> usize {
        self.groups
            .iter()
            .map(|g| self.axes[g[0]].values.len())
            .product::<usize>()
            * usize::from(!self.axes.is_empty())
    }

    /// Expand the sweep for a profile into validated variants. Every error
    /// (bad key in an axis, exclusion matching nothing, duplicate names,
    /// invalid scene) is reported here, before any work.
    pub fn expand(&self, profile: Option<&str>) -> Result<Expansion, StudyError> {
        let profile = self.resolve_profile(profile)?;
        let study_dir = self.study_dir(profile.as_deref());
        let variants_dir = study_dir.join("variants");
        let prof: &[Override] = profile
            .as_deref()
            .and_then(|p| self.profiles.get(p))
            .map_or(&[], Vec::as_slice);

        // Choices: for each variant, the value index per axis (None = no label).
        let mut choices: Vec<Vec<Option<usize>>> = vec![];
        if !self.axes.is_empty() {
            let mut counter = vec![0usize; self.groups.len()];
            let n_total = self.product_size();
            for _ in 0..n_total {
                let mut c = vec![None; self.axes.len()];
                for (g, members) in self.groups.iter().enumerate() {
                    for &a in members {
                        c[a] = Some(counter[g]);
                    }
                }
                choices.push(c);
                for g in (0..self.groups.len()).rev() {
                    counter[g] += 1;
                    if counter[g] < self.axes[self.groups[g][0]].values.len() {
                        break;
                    }
                    counter[g] = 0;
                }
            }
        }
        let label_of = |c: &[Option<usize>], a: usize| c[a].map(|j| &self.axes[a].values[j].label);
        let mut hits = vec![0usize; self.excludes.len()];
        choices.retain(|c| {
            let mut keep = true;
            for (k, ex) in self.excludes.iter().enumerate() {
                let m = ex.iter().all(|(a, l)| {
                    let i = self.axes.iter().position(|x| &x.name == a);
                    i.and_then(|i| label_of(c, i)) == Some(l)
                });
                if m {
                    hits[k] += 1;
                    keep = false;
                }
            }
            keep
        });
        for (k, h) in hits.iter().enumerate() {
            if *h == 0 {
                let desc: Vec<String> = self.excludes[k]
                    .iter()
                    .map(|(a, l)| format!("{a} = \"{l}\""))
                    .collect();
                return Err(self.err(format!(
                    "[[exclude]] {} ({}) matches no combination of the axes; remove it or fix it \
                     (zipped axes only combine label by label)",
                    k + 1,
                    desc.join(", ")
                )));
            }
        }

        struct Pending {
            name: String,
            labels: Vec<(String, String)>,
            sets: Vec<(String, Override)>,
            origin: String,
        }
        let mut pending: Vec<Pending> = vec![];
        for c in &choices {
            let mut labels = vec![];
            let mut sets = vec![];
            for (a, axis) in self.axes.iter().enumerate() {
                if let Some(j) = c[a] {
                    let v = &axis.values[j];
                    labels.push((axis.name.clone(), v.label.clone()));
                    for o in &v.set {
                        sets.push((
                            format!("axis `{}` value `{}`", axis.name, v.label),
                            o.clone(),
                        ));
                    }
                }
            }
            let name = labels
                .iter()
                .map(|(_, l)| sanitise(l))
                .collect::<Vec<_>>()
                .join("_");
            let origin = labels
                .iter()
                .map(|(a, l)| format!("{a} = {l}"))
                .collect::<Vec<_>>()
                .join(", ");
            pending.push(Pending {
                name,
                labels,
                sets,
                origin,
            });
        }
        for (i, ev) in self.explicit.iter().enumerate() {
            let mut labels = vec![];
            let mut sets = vec![];
            for axis in &self.axes {
                if let Some(l) = ev.labels.get(&axis.name) {
                    if let Some(v) = axis.values.iter().find(|v| &v.label == l) {
                        labels.push((axis.name.clone(), l.clone()));
                        for o in &v.set {
                            sets.push((format!("axis `{}` value `{l}`", axis.name), o.clone()));
                        }
                    }
                }
            }
            for o in &ev.set {
                sets.push((format!("[[variant]] `{}`", ev.name), o.clone()));
            }
            pending.push(Pending {
                name: ev.name.clone(),
                labels,
                sets,
                origin: format!("[[variant]] {}", i + 1),
            });
        }
        if pending.is_empty() {
            return Err(
                self.err("the study has no variants: add [[axis]] or [[variant]] tables".into())
            );
        }
        let mut seen: HashMap<String, usize> = HashMap::new();
        for (i, p) in pending.iter().enumerate() {
            if let Some(j) = seen.insert(p.name.clone(), i) {
                return Err(self.err(format!(
                    "two variants are named `{}`: ({}) and ({}); names must be unique — \
                     make the labels distinct (after sanitising to A-Z a-z 0-9 _ . -)",
                    p.name, pending[j].origin, p.origin
                )));
            }
        }

        let mut variants = Vec::with_capacity(pending.len());
        for (index, p) in pending.into_iter().enumerate() {
            let mut table = self.base.clone();
            for o in prof {
                apply_override(&mut table, o).map_err(|m| {
                    self.err(format!(
                        "[profiles.{}]: key path `{}`: {m}",
                        profile.as_deref().unwrap_or(""),
                        o.key
                    ))
                })?;
            }
            for (src, o) in &p.sets {
                apply_override(&mut table, o).map_err(|m| {
                    self.err(format!(
                        "{src}: key path `{}`: {m} (variant `{}`)",
                        o.key, p.name
                    ))
                })?;
            }
            let seed = variant_seed(self.seed, &p.name);
            table.insert("seed".into(), Value::Integer(seed as i64));
            let mut out = Table::new();
            out.insert(
                "dir".into(),
                Value::String(variants_dir.to_string_lossy().into_owned()),
            );
            out.insert("name".into(), Value::String(p.name.clone()));
            table.insert("output".into(), Value::Table(out));
            let text = toml::to_string(&table).map_err(|e| {
                self.err(format!("variant `{}`: cannot write its scene: {e}", p.name))
            })?;
            let scene_path = PathBuf::from(format!("{}#{}", self.base_path.display(), p.name));
            let scene = config::parse_scene(&scene_path, &text).map_err(|e| {
                let blame = blame(&e, prof, &p.sets, profile.as_deref());
                self.err(format!(
                    "variant `{}` ({}) is not a valid scene: {e}{blame}",
                    p.name, p.origin
                ))
            })?;
            variants.push(Variant {
                index,
                id: variant_id(&p.name),
                name: p.name,
                labels: p.labels,
                seed,
                text,
                scene,
            });
        }
        Ok(Expansion {
            profile,
            study_dir,
            variants,
        })
    }
}

/// Which override is likely behind a scene error: the one whose key path
/// contains the offending key or the unknown field.
fn blame(
    e: &config::ConfigError,
    prof: &[Override],
    sets: &[(String, Override)],
    profile: Option<&str>,
) -> String {
    let needle: Option<String> = match e {
        config::ConfigError::Invalid { key, .. } => Some(
            key.split(['.', '['])
                .next_back()
                .unwrap_or("")
                .trim_end_matches(']')
                .to_string(),
        ),
        config::ConfigError::Parse { message, .. } => message
            .split("unknown field `")
            .nth(1)
            .and_then(|s| s.split('`').next())
            .map(str::to_string)
            .or_else(|| {
                message
                    .split("unknown variant `")
                    .nth(1)
                    .and_then(|s| s.split('`').next())
                    .map(str::to_string)
            }),
        _ => None,
    };
    let Some(n) = needle.filter(|n| !n.is_empty()) else {
        return String::new();
    };
    let hit = |o: &Override| {
        o.key.split('.').any(|s| s == n) || o.value.to_string().contains(&format!("\"{n}\""))
    };
    if let Some((src, o)) = sets.iter().rev().find(|(_, o)| hit(o)) {
        return format!(" — set by {src} (key path `{}`)", o.key);
    }
    if let Some(o) = prof.iter().find(|o| hit(o)) {
        return format!(
            " — set by [profiles.{}] (key path `{}`)",
            profile.unwrap_or(""),
            o.key
        );
    }
    String::new()
}

fn list_or_none<'a>(it: impl Iterator<Item = &'a String>) -> String {
    let v: Vec<&str> = it.map(String::as_str).collect();
    if v.is_empty() {
        "(none)".into()
    } else {
        v.join(", ")
    }
}

/// A key path is `.`-separated non-empty segments and not reserved.
fn check_key(k: &str) -> Result<(), String> {
    if k.is_empty() || k.split('.').any(str::is_empty) {
        return Err(
            "segments must be non-empty (e.g. `layer.pvc`, `pigment.0.diameter_nm`)".into(),
        );
    }
    if RESERVED.contains(&k) || k.starts_with("output.") {
        return Err(
            "is set by the study for each variant (seed from the study seed, output under the \
             study folder) and cannot be overridden"
                .into(),
        );
    }
    Ok(())
}

/// Apply one override to a scene table; returns how many places were set.
pub fn apply_override(root: &mut Table, o: &Override) -> Result<usize, String> {
    let segs: Vec<&str> = o.key.split('.').collect();
    let (head, rest) = segs.split_first().ok_or("empty key path")?;
    if *head == "*" || head.parse::<usize>().is_ok() {
        return Err("the scene is a table: start with a key name".into());
    }
    if rest.is_empty() {
        root.insert(head.to_string(), o.value.clone());
        return Ok(1);
    }
    let child = root
        .entry(head.to_string())
        .or_insert_with(|| Value::Table(Table::new()));
    set_path(child, rest, &o.value, head)
}

fn set_path(v: &mut Value, segs: &[&str], val: &Value, done: &str) -> Result<usize, String> {
    let Some((head, rest)) = segs.split_first() else {
        *v = val.clone();
        return Ok(1);
    };
    match v {
        Value::Table(t) => {
            if *head == "*" || head.parse::<usize>().is_ok() {
                return Err(format!(
                    "`{done}` is a table, not an array: `{head}` addresses array elements"
                ));
            }
            if rest.is_empty() {
                t.insert(head.to_string(), val.clone());
                return Ok(1);
            }
            let child = t
                .entry(head.to_string())
                .or_insert_with(|| Value::Table(Table::new()));
            set_path(child, rest, val, &format!("{done}.{head}"))
        }
        Value::Array(a) => {
            if *head == "*" {
                if a.is_empty() {
                    return Err(format!("`{done}` is empty: `*` matches nothing"));
                }
                let mut n = 0;
                for (i, el) in a.iter_mut().enumerate() {
                    n += set_path(el, rest, val, &format!("{done}.{i}"))?;
                }
                Ok(n)
            } else if let Ok(i) = head.parse::<usize>() {
                let len = a.len();
                let el = a.get_mut(i).ok_or_else(|| {
                    format!(
                        "index {i} is out of range: `{done}` has {len} element(s) (0..{})",
                        len.saturating_sub(1)
                    )
                })?;
                set_path(el, rest, val, &format!("{done}.{i}"))
            } else {
                Err(format!(
                    "`{done}` is an array: address its elements by index (`{done}.0`) or all \
                     of them by `*`, got `{head}`"
                ))
            }
        }
        other => Err(format!(
            "`{done}` is a {}, not a table or an array",
            other.type_str()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(s: &str) -> Table {
        s.parse().unwrap()
    }

    #[test]
    fn overrides_address_tables_indices_and_wildcards() {
        let mut t = table("[[p]]\nd = 1.0\n[[p]]\nd = 2.0\n[g]\nc = 3\n");
        let o = |k: &str, v: Value| Override {
            key: k.into(),
            value: v,
        };
        assert_eq!(
            apply_override(&mut t, &o("p.*.d", Value::Float(5.0))),
            Ok(2)
        );
        assert_eq!(
            apply_override(&mut t, &o("p.1.e", Value::Integer(1))),
            Ok(1)
        );
        assert_eq!(apply_override(&mut t, &o("g.c", Value::Integer(4))), Ok(1));
        assert_eq!(
            apply_override(&mut t, &o("new.x", Value::Integer(4))),
            Ok(1)
        );
        assert_eq!(
            t,
            table("[[p]]\nd = 5.0\n[[p]]\nd = 5.0\ne = 1\n[g]\nc = 4\n[new]\nx = 4\n")
        );
        let e = apply_override(&mut t, &o("p.2.d", Value::Float(1.0))).unwrap_err();
        assert!(e.contains("index 2 is out of range: `p` has 2"), "{e}");
        let e = apply_override(&mut t, &o("p.d", Value::Float(1.0))).unwrap_err();
        assert!(e.contains("`p` is an array"), "{e}");
        let e = apply_override(&mut t, &o("g.c.x", Value::Float(1.0))).unwrap_err();
        assert!(e.contains("`g.c` is a integer"), "{e}");
    }

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
