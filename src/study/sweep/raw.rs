//! The sweep file as written: serde structs mirroring its tables one to one.
//!
//! Every table denies unknown keys, so a misspelt key is an error rather than
//! a silently ignored setting. Nothing is checked here beyond the TOML types;
//! [`check`](super::check) turns a [`RawSweep`] into the validated
//! [`Study`](super::Study).

use serde::Deserialize;
use std::collections::BTreeMap;
use toml::{Table, Value};

/// The whole sweep file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSweep {
    pub study: RawStudy,
    /// A file name (relative to the sweep file) or an inline table.
    pub base: Option<Value>,
    #[serde(default)]
    pub profiles: BTreeMap<String, Table>,
    #[serde(default)]
    pub axis: Vec<RawAxis>,
    #[serde(default)]
    pub variant: Vec<RawVariant>,
    /// Axis → label; a combination matching all of them is dropped.
    #[serde(default)]
    pub exclude: Vec<BTreeMap<String, String>>,
    #[serde(default)]
    pub grid: Vec<RawGrid>,
}

/// `[study]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawStudy {
    pub name: String,
    pub seed: Option<i64>,
    pub profile: Option<String>,
    pub output_dir: Option<String>,
    /// A list of axis names or a list of such lists.
    pub zip: Option<Value>,
}

/// `[[axis]]`: the simple form (`key`, `values`, optional `labels`) or the
/// compound form (`[[axis.value]]` tables).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawAxis {
    pub name: String,
    pub key: Option<String>,
    pub values: Option<Vec<Value>>,
    pub labels: Option<Vec<String>>,
    pub value: Option<Vec<RawAxisValue>>,
    /// The effects table's steps, `[["s100", "s200"], …]` (default: each
    /// label to the next).
    pub compare: Option<Vec<Vec<String>>>,
}

/// `[[axis.value]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawAxisValue {
    pub label: String,
    #[serde(default)]
    pub set: Table,
    /// Key paths to remove (`paint.layer.clearcoat`: a layer by its name).
    #[serde(default)]
    pub remove: Vec<String>,
}

/// `[[variant]]`: an explicit variant.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawVariant {
    pub name: String,
    #[serde(default)]
    pub labels: BTreeMap<String, String>,
    #[serde(default)]
    pub set: Table,
}

/// `[[grid]]`: a comparison grid.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawGrid {
    pub name: String,
    pub rows: String,
    pub cols: String,
    #[serde(default, rename = "where")]
    pub where_: BTreeMap<String, String>,
    pub row_labels: Option<Vec<String>>,
    pub col_labels: Option<Vec<String>>,
}
