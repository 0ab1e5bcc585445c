//! Key paths: checking them and applying an override to a scene table.
//!
//! A key path is `.`-separated; an array element is addressed by its index
//! (`pigment.0.diameter_nm`) or by `*`, every element (`pigment.*.shape`).
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
}
