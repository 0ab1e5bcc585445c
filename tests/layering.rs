//! The one-way rule of the library's layout, checked on the source itself.
//!
//! The stages, in pipeline order, are the top-level modules listed in
//! [`STAGES`]. A module may import from its own stage and from earlier
//! stages, never from a later one; and no two modules may import each other,
//! directly or through others (no import cycles). A module's own children are
//! its implementation, so references from a module to its descendants are not
//! edges of the import graph; everything else is (siblings, parents, other
//! stages).
//!
//! References are read from the source text: every `crate::…` path (in `use`
//! trees, braces expanded, and in expressions), and `super::…` paths resolved
//! against the file's module. Code after `#[cfg(test)]` (unit tests at the end
//! of a file) is not part of the library and is skipped. The binary (`main.rs`
//! and its `cli/` modules) sits above every stage and is not checked.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The library's stages, earliest first.
const STAGES: [&str; 10] = [
    "config", "geometry", "raster", "solver", "optics", "output", "pipeline", "study", "match",
    "view",
];

/// A module path such as `["solver", "methods", "gmres"]`.
type ModPath = Vec<String>;

/// Read every library source file under `src/` as (module path, text).
fn library_sources(src: &Path) -> BTreeMap<ModPath, String> {
    fn walk(dir: &Path, prefix: &[String], out: &mut BTreeMap<ModPath, String>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            if p.is_dir() {
                let mut pre = prefix.to_vec();
                pre.push(name);
                walk(&p, &pre, out);
            } else if let Some(stem) = name.strip_suffix(".rs") {
                let mut m = prefix.to_vec();
                if stem != "mod" {
                    m.push(stem.to_string());
                }
                out.insert(m, std::fs::read_to_string(&p).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(src, &[], &mut out);
    // The binary and the crate root are not stages.
    out.retain(|m, _| {
        !m.is_empty() && m[0] != "main" && m[0] != "lib" && m[0] != "cli" && m[0] != "bin"
    });
    out
}

/// The text without comments, string and char literals, and without the
/// unit tests that follow `#[cfg(test)]`.
fn code_only(text: &str) -> String {
    let text = match text.find("#[cfg(test)]") {
        Some(i) => &text[..i],
        None => text,
    };
    let b = text.as_bytes();
    let mut out = String::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            i += 2;
            while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                i += 1;
            }
            i += 2;
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && b.get(i + 2) == Some(&b'\'') {
            // A one-character literal ('a'); lifetimes ('a) are left alone.
            i += 3;
        } else if b[i] == b'\'' && b.get(i + 1) == Some(&b'\\') {
            i += 2;
            while i < b.len() && b[i] != b'\'' {
                i += 1;
            }
            i += 1;
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    out
}

/// Tokens: identifiers, `::`, `{`, `}`, `,`, `*`; everything else is a break.
fn tokens(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let cs: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < cs.len() {
        let c = cs[i];
        // A raw identifier (`r#match`) is the identifier itself.
        if c == 'r'
            && cs.get(i + 1) == Some(&'#')
            && cs
                .get(i + 2)
                .is_some_and(|d| d.is_alphabetic() || *d == '_')
        {
            i += 2;
            continue;
        }
        if c.is_alphanumeric() || c == '_' {
            let s = i;
            while i < cs.len() && (cs[i].is_alphanumeric() || cs[i] == '_') {
                i += 1;
            }
            out.push(cs[s..i].iter().collect());
            continue;
        }
        if c == ':' && cs.get(i + 1) == Some(&':') {
            out.push("::".into());
            i += 2;
            continue;
        }
        if matches!(c, '{' | '}' | ',' | '*') {
            out.push(c.to_string());
        } else if !c.is_whitespace() {
            out.push(";".into());
        }
        i += 1;
    }
    out
}

/// Expand the path (or use tree) starting at token `i` (just after a leading
/// `crate`/`super`/`self` keyword's `::`) into full paths under `prefix`.
fn expand(toks: &[String], mut i: usize, prefix: &[String], out: &mut Vec<ModPath>) -> usize {
    let mut path = prefix.to_vec();
    loop {
        match toks.get(i).map(String::as_str) {
            Some("{") => {
                i += 1;
                while i < toks.len() && toks[i] != "}" {
                    i = expand(toks, i, &path, out);
                    if toks.get(i).map(String::as_str) == Some(",") {
                        i += 1;
                    }
                }
                return i + 1;
            }
            Some("super") if path.len() == prefix.len() && !prefix.is_empty() => {
                path.pop();
                i += 1;
            }
            Some(t) if t.chars().all(|c| c.is_alphanumeric() || c == '_') => {
                if t != "self" {
                    path.push(t.to_string());
                }
                i += 1;
            }
            _ => {
                out.push(path);
                return i;
            }
        }
        if toks.get(i).map(String::as_str) == Some("::") {
            i += 1;
        } else {
            out.push(path);
            return i;
        }
    }
}

/// Every path a module's code refers to through `crate::` or `super::`.
fn references(module: &[String], text: &str) -> Vec<ModPath> {
    let toks = tokens(&code_only(text));
    // The module `super` refers to in this file.
    let mut parent = module.to_vec();
    parent.pop();
    let mut out = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        let t = toks[i].as_str();
        let prev_is_sep = i > 0 && toks[i - 1] == "::";
        if (t == "crate" || t == "super")
            && !prev_is_sep
            && toks.get(i + 1).map(String::as_str) == Some("::")
        {
            let base: Vec<String> = if t == "crate" {
                Vec::new()
            } else {
                parent.clone()
            };
            i = expand(&toks, i + 2, &base, &mut out);
        } else {
            i += 1;
        }
    }
    out
}

/// The longest prefix of `path` that is a module of the tree.
fn resolve(path: &[String], modules: &BTreeSet<ModPath>) -> Option<ModPath> {
    (1..=path.len())
        .rev()
        .map(|n| path[..n].to_vec())
        .find(|p| modules.contains(p))
}

/// Violations of the one-way rule in a source tree given as module → text
/// Empty when the tree keeps it.
fn violations(sources: &BTreeMap<ModPath, String>) -> Vec<String> {
    let modules: BTreeSet<ModPath> = sources.keys().cloned().collect();
    let rank = |m: &ModPath| STAGES.iter().position(|s| *s == m[0]);
    let mut problems = Vec::new();
    let mut edges: BTreeMap<ModPath, BTreeSet<ModPath>> = BTreeMap::new();
    for (m, text) in sources {
        let Some(r) = rank(m) else {
            problems.push(format!(
                "{}: not a stage (stages: {STAGES:?})",
                m.join("::")
            ));
            continue;
        };
        for p in references(m, text) {
            let Some(target) = resolve(&p, &modules) else {
                continue;
            };
            if target == *m || target.starts_with(m) {
                continue; // itself or its own children
            }
            if let Some(rt) = rank(&target) {
                if rt > r {
                    problems.push(format!(
                        "{} imports {} from a later stage",
                        m.join("::"),
                        p.join("::")
                    ));
                }
            }
            edges.entry(m.clone()).or_default().insert(target);
        }
    }
    // Cycles: depth-first search with colours.
    fn dfs(
        n: &ModPath,
        edges: &BTreeMap<ModPath, BTreeSet<ModPath>>,
        state: &mut BTreeMap<ModPath, u8>,
        stack: &mut Vec<ModPath>,
        found: &mut Vec<String>,
    ) {
        state.insert(n.clone(), 1);
        stack.push(n.clone());
        for next in edges.get(n).into_iter().flatten() {
            match state.get(next).copied().unwrap_or(0) {
                0 => dfs(next, edges, state, stack, found),
                1 => {
                    let start = stack.iter().position(|s| s == next).unwrap();
                    let mut cyc: Vec<String> =
                        stack[start..].iter().map(|s| s.join("::")).collect();
                    cyc.push(next.join("::"));
                    found.push(format!("import cycle: {}", cyc.join(" -> ")));
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.clone(), 2);
    }
    let mut state = BTreeMap::new();
    for n in edges.keys() {
        if state.get(n).copied().unwrap_or(0) == 0 {
            dfs(n, &edges, &mut state, &mut Vec::new(), &mut problems);
        }
    }
    problems
}

/// A source tree from (module path, text) pairs.
fn tree(files: &[(&str, &str)]) -> BTreeMap<ModPath, String> {
    let split = |s: &str| s.split("::").map(String::from).collect::<ModPath>();
    files
        .iter()
        .map(|(m, t)| (split(m), t.to_string()))
        .collect()
}

#[test]
fn library_imports_only_point_to_earlier_stages_and_never_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let sources = library_sources(&src);
    assert!(
        sources.len() > 30,
        "too few modules found: {}",
        sources.len()
    );
    for stage in STAGES {
        assert!(
            sources.contains_key(&vec![stage.to_string()]),
            "stage {stage} has no module"
        );
    }
    let problems = violations(&sources);
    assert!(
        problems.is_empty(),
        "layering broken:\n{}",
        problems.join("\n")
    );
}

#[test]
fn a_later_stage_import_is_caught() {
    let s = tree(&[
        ("config", ""),
        ("solver", "pub fn f() {}"),
        ("geometry", "use crate::solver::f;"),
    ]);
    let v = violations(&s);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(v[0].contains("geometry imports solver::f from a later stage"));
}

#[test]
fn grouped_and_relative_imports_are_read() {
    let s = tree(&[
        (
            "config",
            "use crate::{geometry::{self, shapes::Sphere}, raster};",
        ),
        ("geometry", ""),
        ("geometry::shapes", "use super::super::raster::Grid;"),
        (
            "raster",
            "// crate::study is only a comment\nlet s = \"crate::study\";",
        ),
        ("study", ""),
    ]);
    let v = violations(&s);
    assert_eq!(v.len(), 4, "{v:?}");
    assert!(v.iter().any(|x| x.contains("config imports geometry from")));
    assert!(v
        .iter()
        .any(|x| x.contains("config imports geometry::shapes::Sphere from")));
    assert!(v.iter().any(|x| x.contains("config imports raster from")));
    assert!(v
        .iter()
        .any(|x| x.contains("geometry::shapes imports raster::Grid from")));
}

#[test]
fn an_import_cycle_within_a_stage_is_caught() {
    let s = tree(&[
        ("solver", "pub mod a; pub mod b; pub use a::A;"),
        ("solver::a", "use crate::solver::b::B; pub struct A;"),
        ("solver::b", "use super::a::A; pub struct B;"),
    ]);
    let v = violations(&s);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(v[0].starts_with("import cycle: solver::a -> solver::b -> solver::a"));
    // A child using its parent's items is not a cycle.
    let s = tree(&[
        ("solver", "pub mod a; pub struct S; pub fn f() { a::g() }"),
        ("solver::a", "use crate::solver::S; pub fn g() {}"),
    ]);
    assert!(violations(&s).is_empty());
}

#[test]
fn unit_tests_and_comments_do_not_count() {
    let s = tree(&[
        (
            "config",
            "/* crate::study */ pub fn f() {}\n#[cfg(test)]\nmod tests { use crate::study; }",
        ),
        ("study", ""),
    ]);
    assert!(violations(&s).is_empty());
}

#[test]
fn raw_identifiers_name_their_module() {
    // `match` is a keyword: the stage is written `r#match` in paths.
    let s = tree(&[
        ("study", "use crate::r#match::report::run;"),
        ("match", ""),
        ("match::report", ""),
    ]);
    let v = violations(&s);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(
        v.iter()
            .any(|x| x.contains("study imports match::report::run from")),
        "{v:?}"
    );
}
