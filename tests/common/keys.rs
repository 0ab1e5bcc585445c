//! Dotted key paths into a TOML table (`solver.tolerance`, `pigment.0.pvc`:
//! a number indexes an array), and TOML values written as text, for the
//! scene and study builders.

use toml::{Table, Value};

/// The value written `text` in TOML: `value("{ kind = \"rice\" }")`.
pub fn value(text: &str) -> Value {
    let t: Table = format!("v = {text}")
        .parse()
        .unwrap_or_else(|e| panic!("test bug: `{text}` is no TOML value: {e}"));
    t["v"].clone()
}

/// An array of floats.
pub fn floats(v: &[f64]) -> Value {
    Value::Array(v.iter().map(|&x| Value::Float(x)).collect())
}

/// An array of strings.
pub fn strings(v: &[&str]) -> Value {
    Value::Array(v.iter().map(|&s| Value::String(s.into())).collect())
}

/// Set `path` to `new`, creating the tables on the way; an array index may
/// be one past the end (appends).
pub fn set(root: &mut Table, path: &str, new: Value) {
    let keys: Vec<&str> = path.split('.').collect();
    let (first, rest) = keys.split_first().unwrap();
    if rest.is_empty() {
        root.insert(first.to_string(), new);
        return;
    }
    let child = root
        .entry(first.to_string())
        .or_insert_with(|| Value::Table(Table::new()));
    set_in(child, rest, new, path);
}

fn set_in(v: &mut Value, keys: &[&str], new: Value, path: &str) {
    let (k, rest) = keys.split_first().unwrap();
    let child = match v {
        Value::Table(t) if rest.is_empty() => {
            t.insert(k.to_string(), new);
            return;
        }
        Value::Table(t) => t
            .entry(k.to_string())
            .or_insert_with(|| Value::Table(Table::new())),
        Value::Array(a) => {
            let i: usize = k.parse().unwrap_or_else(|_| panic!("test bug: {path}"));
            if i == a.len() {
                a.push(Value::Table(Table::new()));
            }
            if rest.is_empty() {
                a[i] = new;
                return;
            }
            &mut a[i]
        }
        _ => panic!("test bug: {path} goes through a plain value"),
    };
    set_in(child, rest, new, path);
}

/// Remove `path` (a missing one is a test bug); an emptied table goes too.
pub fn remove(root: &mut Table, path: &str) {
    let keys: Vec<&str> = path.split('.').collect();
    let mut v = Value::Table(std::mem::take(root));
    remove_in(&mut v, &keys, path);
    let Value::Table(t) = v else { unreachable!() };
    *root = t;
}

fn remove_in(v: &mut Value, keys: &[&str], path: &str) {
    let (k, rest) = keys.split_first().unwrap();
    match v {
        Value::Table(t) => {
            if rest.is_empty() {
                t.remove(*k)
                    .unwrap_or_else(|| panic!("test bug: no key {path}"));
            } else {
                let child = t
                    .get_mut(*k)
                    .unwrap_or_else(|| panic!("test bug: no key {path}"));
                remove_in(child, rest, path);
                if matches!(child, Value::Table(c) if c.is_empty()) {
                    t.remove(*k);
                }
            }
        }
        Value::Array(a) => {
            let i: usize = k.parse().unwrap_or_else(|_| panic!("test bug: {path}"));
            if rest.is_empty() {
                a.remove(i);
            } else {
                remove_in(&mut a[i], rest, path);
            }
        }
        _ => panic!("test bug: {path} goes through a plain value"),
    }
}

/// The builder methods every file builder shares: `set` and `raw` (any key
/// by its dotted path, a value or its TOML text) and `without` (drop one),
/// for a tuple struct around a [`Table`].
macro_rules! key_setters {
    ($builder:ty) => {
        impl $builder {
            /// Any key by its dotted path.
            pub fn set(mut self, path: &str, v: impl Into<toml::Value>) -> Self {
                $crate::common::keys::set(&mut self.0, path, v.into());
                self
            }

            /// Any key by its dotted path, the value written as TOML text.
            pub fn raw(self, path: &str, text: &str) -> Self {
                self.set(path, $crate::common::keys::value(text))
            }

            /// Drop a key (or a whole table).
            pub fn without(mut self, path: &str) -> Self {
                $crate::common::keys::remove(&mut self.0, path);
                self
            }
        }
    };
}
pub(crate) use key_setters;

/// The table written out as TOML text.
pub fn text(root: &Table) -> String {
    toml::to_string(root).expect("a table is always TOML")
}
