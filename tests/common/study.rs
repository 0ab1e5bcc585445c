//! Study (sweep) files built in code: a base scene from
//! [`SceneToml`](super::scene::SceneToml), then the study's own tables.

use super::keys::{self, key_setters, value};
use super::scene::SceneToml;
use toml::{Table, Value};

/// A study file under construction.
#[derive(Clone, Debug)]
pub struct StudyToml(Table);

// `set("axis.1.key", …)`, `raw("axis.1.values", "[…]")`, `without(…)`.
key_setters!(StudyToml);

impl StudyToml {
    /// Study `name` over variants of `base`, results under `output_dir`.
    pub fn new(name: &str, seed: i64, output_dir: &str, base: &SceneToml) -> Self {
        Self(Table::new())
            .set("study.name", name)
            .set("study.seed", seed)
            .set("study.output_dir", output_dir)
            .set("base", base.table().clone())
    }

    /// The profile run when none is named.
    pub fn profile(self, name: &str) -> Self {
        self.set("study.profile", name)
    }

    /// Axes varied together instead of crossed.
    pub fn zip(self, axes: &[&str]) -> Self {
        self.set("study.zip", keys::strings(axes))
    }

    /// In profile `profile`, scene key `key` (a dotted path, kept as one
    /// key) takes `v`.
    pub fn profile_key(mut self, profile: &str, key: &str, v: impl Into<Value>) -> Self {
        let profiles = self
            .0
            .entry("profiles")
            .or_insert_with(|| Value::Table(Table::new()))
            .as_table_mut()
            .unwrap();
        let p = profiles
            .entry(profile)
            .or_insert_with(|| Value::Table(Table::new()))
            .as_table_mut()
            .unwrap();
        p.insert(key.into(), v.into());
        self
    }

    /// An axis setting scene key `key` to each of `values` (TOML text of
    /// an array).
    pub fn axis(self, name: &str, key: &str, values: &str) -> Self {
        let mut t = Table::new();
        t.insert("name".into(), name.into());
        t.insert("key".into(), key.into());
        t.insert("values".into(), value(values));
        self.push("axis", t)
    }

    /// A compound axis: per label, a `set` table written as TOML text.
    pub fn compound_axis(self, name: &str, values: &[(&str, &str)]) -> Self {
        let list = values
            .iter()
            .map(|(label, set)| {
                let mut t = Table::new();
                t.insert("label".into(), (*label).into());
                t.insert("set".into(), value(set));
                Value::Table(t)
            })
            .collect();
        let mut t = Table::new();
        t.insert("name".into(), name.into());
        t.insert("value".into(), Value::Array(list));
        self.push("axis", t)
    }

    /// An `[[exclude]]` of these axis labels.
    pub fn exclude(self, labels: &[(&str, &str)]) -> Self {
        let t = labels
            .iter()
            .map(|(axis, label)| (axis.to_string(), Value::from(*label)))
            .collect();
        self.push("exclude", t)
    }

    /// A `[[variant]]` given explicitly: its name and its other keys as
    /// TOML text of a table (`labels`, `set`), or "" for none.
    pub fn variant(self, name: &str, rest: &str) -> Self {
        let mut t = value(&format!("{{ {rest} }}")).as_table().cloned().unwrap();
        t.insert("name".into(), name.into());
        self.push("variant", t)
    }

    fn push(mut self, key: &str, t: Table) -> Self {
        let list = self
            .0
            .entry(key)
            .or_insert_with(|| Value::Array(vec![]))
            .as_array_mut()
            .unwrap();
        list.push(Value::Table(t));
        self
    }

    /// The study file's text.
    pub fn toml(&self) -> String {
        keys::text(&self.0)
    }
}
