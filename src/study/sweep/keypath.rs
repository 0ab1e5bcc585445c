//! Key paths: checking them and applying an override to a scene table.
//!
//! A key path is `.`-separated; an array element is addressed by its index
//! (`pigment.0.diameter_nm`), by `*`, every element (`pigment.*.shape`), or
//! by the value of its `name` key (`paint.layer.basecoat.thickness_um`).
//! [`remove_path`] removes what a path addresses (a layer of a paint).
//! A missing table on the way is created (the scene schema's
//! `deny_unknown_fields` then rejects a misspelt key). The keys the study
//! sets per variant ([`RESERVED`]) cannot be overridden.

use super::Override;
use toml::{Table, Value};

/// Keys a sweep may not override: the driver sets them per variant.
pub(super) const RESERVED: [&str; 4] = ["seed", "output", "output.dir", "output.name"];

/// A key path is `.`-separated non-empty segments and not reserved.
pub(super) fn check_key(k: &str) -> Result<(), String> {
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
            } else if let Some(el) = a.iter_mut().find(|el| named(el, head)) {
                set_path(el, rest, val, &format!("{done}.{head}"))
            } else {
                Err(no_element(done, head, a))
            }
        }
        other => Err(format!(
            "`{done}` is a {}, not a table or an array",
            other.type_str()
        )),
    }
}

/// Whether `el` is a table whose `name` is `name`.
fn named(el: &Value, name: &str) -> bool {
    el.get("name").and_then(Value::as_str) == Some(name)
}

/// An array `done` has no element `head`: the ways it can be addressed.
fn no_element(done: &str, head: &str, a: &[Value]) -> String {
    let names: Vec<&str> = a
        .iter()
        .filter_map(|el| el.get("name").and_then(Value::as_str))
        .collect();
    let by_name = if names.is_empty() {
        String::new()
    } else {
        format!(", or by name ({})", names.join(", "))
    };
    format!(
        "`{done}` is an array with no element named `{head}`: address its elements by index \
         (`{done}.0`), all of them by `*`{by_name}"
    )
}

/// Remove what key path `key` addresses: a table's key, or an array's
/// element by its index or its `name`. It must exist.
pub fn remove_path(root: &mut Table, key: &str) -> Result<(), String> {
    let segs: Vec<&str> = key.split('.').collect();
    let (last, parents) = segs.split_last().ok_or("empty key path")?;
    let mut here = Value::Table(std::mem::take(root));
    let r = remove_in(&mut here, parents, last, "");
    if let Value::Table(t) = here {
        *root = t;
    }
    r
}

fn remove_in(v: &mut Value, parents: &[&str], last: &str, done: &str) -> Result<(), String> {
    let at = |s: &str| {
        if done.is_empty() {
            s.to_string()
        } else {
            format!("{done}.{s}")
        }
    };
    if let Some((head, rest)) = parents.split_first() {
        let child = match v {
            Value::Table(t) => t.get_mut(*head),
            Value::Array(a) => match head.parse::<usize>() {
                Ok(i) => a.get_mut(i),
                Err(_) => a.iter_mut().find(|el| named(el, head)),
            },
            _ => None,
        };
        let child = child.ok_or_else(|| format!("`{}` is not in the scene", at(head)))?;
        return remove_in(child, rest, last, &at(head));
    }
    let gone = match v {
        Value::Table(t) => t.remove(last).is_some(),
        Value::Array(a) => match last.parse::<usize>() {
            Ok(i) if i < a.len() => {
                a.remove(i);
                true
            }
            Ok(_) => false,
            Err(_) => {
                let before = a.len();
                a.retain(|el| !named(el, last));
                a.len() < before
            }
        },
        _ => false,
    };
    if gone {
        Ok(())
    } else {
        Err(format!("`{}` is not in the scene", at(last)))
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
        assert!(
            e.contains("`p` is an array with no element named `d`"),
            "{e}"
        );
        let e = apply_override(&mut t, &o("g.c.x", Value::Float(1.0))).unwrap_err();
        assert!(e.contains("`g.c` is a integer"), "{e}");
    }

    #[test]
    fn elements_are_addressed_and_removed_by_name() {
        let mut t =
            table("[[layer]]\nname = \"clear\"\nt = 1.0\n[[layer]]\nname = \"base\"\nt = 2.0\n");
        let o = Override {
            key: "layer.base.t".into(),
            value: Value::Float(5.0),
        };
        assert_eq!(apply_override(&mut t, &o), Ok(1));
        remove_path(&mut t, "layer.clear").unwrap();
        assert_eq!(t, table("[[layer]]\nname = \"base\"\nt = 5.0\n"));
        let e = remove_path(&mut t, "layer.clear").unwrap_err();
        assert_eq!(e, "`layer.clear` is not in the scene");
        let bad = Override {
            key: "layer.top.t".into(),
            value: Value::Float(1.0),
        };
        let e = apply_override(&mut t, &bad).unwrap_err();
        assert!(
            e.contains("no element named `top`") && e.contains("by name (base)"),
            "{e}"
        );
    }
}
