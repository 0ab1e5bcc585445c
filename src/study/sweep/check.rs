//! Checks a [`RawSweep`] and builds the validated [`Study`].
//!
//! Every name, key path, axis reference and label is checked here, in file
//! order, and the first problem is reported as [`StudyError::Sweep`] naming
//! the file, the key or table at fault (key `study.zip`, axis `pvc` of
//! `[[axis]]` 2, `[[grid]]` 1) and what is allowed. Choices made here:
//! - `study.seed` defaults to 1, `study.output_dir` to `runs/<name>`.
//! - A `base` file name is relative to the sweep file, and the scene
//!   variants are checked against that path (CSV tables resolve beside it);
//!   an inline `[base]` uses the sweep file's path.
//! - Simple-form axis values without `labels` get [`generated_label`]s.
//! - Zip groups become [`Study::groups`]: every axis in exactly one group,
//!   groups in the order of their first axis.
//! - Without `[[grid]]` tables and with at least two axes, one default grid
//!   `<axis 1>-by-<axis 2>` (first axis as rows, second as columns).
//!
//! What the variants' scenes look like is not checked here: that needs a
//! profile and happens in [`Study::expand`].

use super::keypath::check_key;
use super::raw::{RawAxis, RawGrid, RawSweep, RawVariant};
use super::{
    list_or_none, sanitise, sweep_error, Axis, AxisValue, ExplicitVariant, GridDecl, Override,
    Study,
};
use crate::study::StudyError;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// A generated label for a simple-form axis value: strings as they are,
/// numbers and booleans after the axis name (`pvc0.15`, `d200`).
pub(super) fn generated_label(axis: &str, v: &Value) -> Option<String> {
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

/// Check `raw`, read from the sweep file `path`.
pub(super) fn check(path: &Path, raw: RawSweep) -> Result<Study, StudyError> {
    let c = Checker { path };
    let name = raw.study.name.clone();
    if name.is_empty() || sanitise(&name) != name {
        return Err(c.err(format!(
            "key `study.name`: must be non-empty and use only A-Z a-z 0-9 _ . -, got `{name}`"
        )));
    }
    let seed = match raw.study.seed {
        None => 1,
        Some(s) if s >= 0 => s as u64,
        Some(s) => return Err(c.err(format!("key `study.seed`: must be >= 0, got {s}"))),
    };
    let output_dir = match raw.study.output_dir.as_deref() {
        Some(d) if d.trim().is_empty() => {
            return Err(c.err("key `study.output_dir`: must not be empty".into()))
        }
        Some(d) => PathBuf::from(d),
        None => Path::new("runs").join(&name),
    };
    let (base, base_path) = c.base(raw.base)?;

    let mut profiles = BTreeMap::new();
    for (pname, t) in &raw.profiles {
        profiles.insert(
            pname.clone(),
            c.overrides(t, &format!("[profiles.{pname}]"))?,
        );
    }
    if let Some(p) = &raw.study.profile {
        if !profiles.contains_key(p) {
            return Err(c.err(format!(
                "key `study.profile`: unknown profile `{p}`; defined: {}",
                list_or_none(profiles.keys())
            )));
        }
    }

    let mut axes: Vec<Axis> = Vec::with_capacity(raw.axis.len());
    for (i, a) in raw.axis.iter().enumerate() {
        let axis = c.axis(i, a, &axes)?;
        axes.push(axis);
    }
    let groups = c.groups(raw.study.zip.as_ref(), &axes)?;

    // Exclusions and explicit variants refer to axes by name and label.
    for (i, ex) in raw.exclude.iter().enumerate() {
        let what = format!("[[exclude]] {}", i + 1);
        if ex.is_empty() {
            return Err(c.err(format!("{what}: is empty; it would drop everything")));
        }
        c.labels(&axes, ex, &what)?;
    }
    let mut explicit = vec![];
    for (i, v) in raw.variant.iter().enumerate() {
        explicit.push(c.variant(i, v, &axes)?);
    }

    let mut grids = vec![];
    for (i, g) in raw.grid.iter().enumerate() {
        grids.push(c.grid(i, g, &axes)?);
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

/// The checks of one sweep file; every error names `path`.
struct Checker<'a> {
    path: &'a Path,
}

impl Checker<'_> {
    fn err(&self, message: String) -> StudyError {
        sweep_error(self.path, message)
    }

    /// The base scene as a table, and the path its variants are checked
    /// against.
    fn base(&self, base: Option<Value>) -> Result<(Table, PathBuf), StudyError> {
        base_table(self.path, base).map_err(|m| self.err(m))
    }

    /// The overrides of a `set`-like table, each key path checked; `what`
    /// names the table in errors.
    fn overrides(&self, t: &Table, what: &str) -> Result<Vec<Override>, StudyError> {
        let mut out = Vec::with_capacity(t.len());
        for (k, v) in t {
            check_key(k).map_err(|m| self.err(format!("{what}: key path `{k}`: {m}")))?;
            out.push(Override {
                key: k.clone(),
                value: v.clone(),
            });
        }
        Ok(out)
    }

    /// `[[axis]]` number `i` (0-based), given the axes before it.
    fn axis(&self, i: usize, a: &RawAxis, before: &[Axis]) -> Result<Axis, StudyError> {
        let what = format!("axis `{}` ([[axis]] {})", a.name, i + 1);
        if a.name.is_empty() || sanitise(&a.name) != a.name {
            return Err(self.err(format!(
                "{what}: name must be non-empty and use only A-Z a-z 0-9 _ . -"
            )));
        }
        if before.iter().any(|b| b.name == a.name) {
            return Err(self.err(format!("{what}: two axes are named `{}`", a.name)));
        }
        let values = match (&a.key, &a.values, &a.value) {
            (Some(key), Some(vals), None) => self.simple_values(&what, a, key, vals)?,
            (None, None, Some(vals)) => {
                if a.labels.is_some() {
                    return Err(self.err(format!(
                        "{what}: `labels` goes with the simple form (key + values); \
                         [[axis.value]] entries carry their own label"
                    )));
                }
                let mut out = Vec::with_capacity(vals.len());
                for (j, v) in vals.iter().enumerate() {
                    let at = format!("{what}, value {}", j + 1);
                    for k in &v.remove {
                        check_key(k).map_err(|m| self.err(format!("{at}: remove `{k}`: {m}")))?;
                    }
                    out.push(AxisValue {
                        label: v.label.clone(),
                        set: self.overrides(&v.set, &at)?,
                        remove: v.remove.clone(),
                    });
                }
                out
            }
            _ => {
                return Err(self.err(format!(
                    "{what}: give either `key` and `values` (simple form) or \
                     [[axis.value]] tables with `label` and `set` (compound form)"
                )))
            }
        };
        if values.is_empty() {
            return Err(self.err(format!("{what}: has no values; an axis needs at least one")));
        }
        let mut seen: HashMap<&str, usize> = HashMap::new();
        for (j, v) in values.iter().enumerate() {
            if v.label.is_empty() {
                return Err(self.err(format!("{what}: value {} has an empty label", j + 1)));
            }
            if let Some(k) = seen.insert(v.label.as_str(), j) {
                return Err(self.err(format!(
                    "{what}: label `{}` is used by values {} and {}",
                    v.label,
                    k + 1,
                    j + 1
                )));
            }
        }
        let compare = match &a.compare {
            None => values
                .windows(2)
                .map(|w| (w[0].label.clone(), w[1].label.clone()))
                .collect(),
            Some(pairs) => {
                let labels: Vec<&str> = values.iter().map(|v| v.label.as_str()).collect();
                let mut out = Vec::with_capacity(pairs.len());
                for (j, p) in pairs.iter().enumerate() {
                    let [from, to] = p.as_slice() else {
                        return Err(self.err(format!(
                            "{what}: compare entry {} must be two labels [\"from\", \"to\"], got {} \
                             item(s)",
                            j + 1,
                            p.len()
                        )));
                    };
                    for l in [from, to] {
                        if !labels.contains(&l.as_str()) {
                            return Err(self.err(format!(
                                "{what}: compare entry {} names label `{l}`, which the axis does \
                                 not have; its labels are {}",
                                j + 1,
                                labels.join(", ")
                            )));
                        }
                    }
                    out.push((from.clone(), to.clone()));
                }
                out
            }
        };
        Ok(Axis {
            name: a.name.clone(),
            values,
            compare,
        })
    }

    /// The values of a simple-form axis: one override of `key` each, labelled
    /// by `labels` or generated.
    fn simple_values(
        &self,
        what: &str,
        a: &RawAxis,
        key: &str,
        vals: &[Value],
    ) -> Result<Vec<AxisValue>, StudyError> {
        check_key(key).map_err(|m| self.err(format!("{what}: key path `{key}`: {m}")))?;
        if let Some(labels) = &a.labels {
            if labels.len() != vals.len() {
                return Err(self.err(format!(
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
                    self.err(format!(
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
                    key: key.to_string(),
                    value: v.clone(),
                }],
                remove: vec![],
            });
        }
        Ok(out)
    }

    /// `study.zip` as groups of axis indices (see [`Study::groups`]).
    fn groups(&self, zip: Option<&Value>, axes: &[Axis]) -> Result<Vec<Vec<usize>>, StudyError> {
        let zip_groups = self.zip_names(zip)?;
        let mut group_of: Vec<Option<usize>> = vec![None; axes.len()];
        for (g, names) in zip_groups.iter().enumerate() {
            if names.len() < 2 {
                return Err(self.err(format!(
                    "key `study.zip`: a group needs at least two axes, got {names:?}"
                )));
            }
            let mut len = None;
            for n in names {
                let i = axis_index(axes, n).ok_or_else(|| {
                    self.err(format!(
                        "key `study.zip`: unknown axis `{n}`; axes: {}",
                        axis_names(axes)
                    ))
                })?;
                if group_of[i].is_some() {
                    return Err(self.err(format!("key `study.zip`: axis `{n}` is zipped twice")));
                }
                group_of[i] = Some(g);
                let l = axes[i].values.len();
                match len {
                    None => len = Some((n, l)),
                    Some((first, l0)) if l0 != l => {
                        return Err(self.err(format!(
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
        Ok(groups)
    }

    /// `study.zip` as written: one list of axis names, or a list of them.
    fn zip_names(&self, zip: Option<&Value>) -> Result<Vec<Vec<String>>, StudyError> {
        let shape = || {
            self.err("key `study.zip`: must be a list of axis names or a list of such lists".into())
        };
        let names = |items: &[Value]| -> Vec<String> {
            items
                .iter()
                .filter_map(|v| v.as_str().map(str::to_string))
                .collect()
        };
        match zip {
            None => Ok(vec![]),
            Some(Value::Array(items)) if items.iter().all(|v| v.is_str()) => Ok(vec![names(items)]),
            Some(Value::Array(items)) => {
                let mut gs = vec![];
                for it in items {
                    match it.as_array() {
                        Some(g) if g.iter().all(|v| v.is_str()) => gs.push(names(g)),
                        _ => return Err(shape()),
                    }
                }
                Ok(gs)
            }
            Some(_) => Err(shape()),
        }
    }

    /// Every `axis = "label"` of `m` names an axis and one of its labels.
    fn labels(
        &self,
        axes: &[Axis],
        m: &BTreeMap<String, String>,
        what: &str,
    ) -> Result<(), StudyError> {
        for (a, l) in m {
            let i = axis_index(axes, a).ok_or_else(|| {
                self.err(format!(
                    "{what}: unknown axis `{a}`; axes: {}",
                    axis_names(axes)
                ))
            })?;
            if !axes[i].values.iter().any(|v| &v.label == l) {
                return Err(self.err(format!(
                    "{what}: axis `{a}` has no label `{l}`; labels: {}",
                    list_or_none(axes[i].values.iter().map(|v| &v.label))
                )));
            }
        }
        Ok(())
    }

    /// `[[variant]]` number `i` (0-based).
    fn variant(
        &self,
        i: usize,
        v: &RawVariant,
        axes: &[Axis],
    ) -> Result<ExplicitVariant, StudyError> {
        let what = format!("[[variant]] {} (`{}`)", i + 1, v.name);
        if v.name.is_empty() || sanitise(&v.name) != v.name {
            return Err(self.err(format!(
                "{what}: name must be non-empty and use only A-Z a-z 0-9 _ . -"
            )));
        }
        self.labels(axes, &v.labels, &what)?;
        Ok(ExplicitVariant {
            name: v.name.clone(),
            labels: v.labels.clone(),
            set: self.overrides(&v.set, &what)?,
        })
    }

    /// `[[grid]]` number `i` (0-based).
    fn grid(&self, i: usize, g: &RawGrid, axes: &[Axis]) -> Result<GridDecl, StudyError> {
        let what = format!("[[grid]] {} (`{}`)", i + 1, g.name);
        if g.name.is_empty() || sanitise(&g.name) != g.name {
            return Err(self.err(format!(
                "{what}: name must be non-empty and use only A-Z a-z 0-9 _ . -"
            )));
        }
        for (k, a) in [("rows", &g.rows), ("cols", &g.cols)] {
            if axis_index(axes, a).is_none() {
                return Err(self.err(format!(
                    "{what}: key `{k}`: unknown axis `{a}`; axes: {}",
                    axis_names(axes)
                )));
            }
        }
        if g.rows == g.cols {
            return Err(self.err(format!("{what}: rows and cols are the same axis")));
        }
        self.labels(axes, &g.where_, &format!("{what}: key `where`"))?;
        for (k, axis, labels) in [
            ("row_labels", &g.rows, &g.row_labels),
            ("col_labels", &g.cols, &g.col_labels),
        ] {
            if let Some(ls) = labels {
                let m: BTreeMap<String, String> =
                    ls.iter().map(|l| (axis.clone(), l.clone())).collect();
                self.labels(axes, &m, &format!("{what}: key `{k}`"))?;
            }
        }
        Ok(GridDecl {
            name: g.name.clone(),
            rows: g.rows.clone(),
            cols: g.cols.clone(),
            where_: g.where_.clone(),
            row_labels: g.row_labels.clone(),
            col_labels: g.col_labels.clone(),
        })
    }
}

fn axis_index(axes: &[Axis], name: &str) -> Option<usize> {
    axes.iter().position(|a| a.name == name)
}

fn axis_names(axes: &[Axis]) -> String {
    list_or_none(axes.iter().map(|a| &a.name))
}

/// The base scene of the file `path` as a TOML table (`base = "scene.toml"`,
/// relative to `path`, or an inline `[base]` table), and the path the scene
/// is checked against (its own file, or `path` for an inline one). The
/// message names the key and what is allowed.
pub fn base_table(path: &Path, base: Option<Value>) -> Result<(Table, PathBuf), String> {
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    match base {
        None => Err(
            "missing `base`: give `base = \"scene.toml\"` (relative to this file) or an \
                     inline [base] table holding a complete scene"
                .into(),
        ),
        Some(Value::String(f)) => {
            let p = dir.join(&f);
            let t = std::fs::read_to_string(&p)
                .map_err(|e| format!("key `base`: cannot read scene `{}`: {e}", p.display()))?;
            let table: Table = t.parse().map_err(|e: toml::de::Error| {
                format!("key `base`: {}: {}", p.display(), e.message().trim())
            })?;
            Ok((table, p))
        }
        Some(Value::Table(t)) => Ok((t, path.to_path_buf())),
        Some(other) => Err(format!(
            "key `base`: must be a file name or a table, got a {}",
            other.type_str()
        )),
    }
}
