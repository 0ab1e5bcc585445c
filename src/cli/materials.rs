//! `inksim materials`: every material a scene may name, with its kind,
//! wavelength range, source and licence.

use anyhow::Result;
use inksim::config::materials::library::{library_names, TableInfo};
use inksim::config::materials::BUILTIN_NAMES;
use inksim::config::Material;
use std::fmt::Write;

/// The listing: the stand-ins, then the library.
pub fn materials() -> Result<()> {
    print!("{}", listing()?);
    Ok(())
}

/// `lo-hi nm` of a material.
fn range(m: &Material) -> String {
    let (lo, hi) = m.range_nm();
    format!("{lo}-{hi} nm")
}

fn listing() -> Result<String> {
    let mut out = String::new();
    let row = |out: &mut String, name: &str, kind: &str, range: &str, licence: &str| {
        let _ = writeln!(out, "{name:<18}{kind:<14}{range:<18}{licence}");
    };
    let _ = writeln!(
        out,
        "Stand-ins: material = {{ builtin = \"<name>\" }} (made by scripts/make_pigments.py)\n"
    );
    row(&mut out, "NAME", "KIND", "RANGE", "LICENCE");
    let own = format!("{} (inksim's own)", env!("CARGO_PKG_LICENSE"));
    for name in BUILTIN_NAMES {
        // Embedded and checked by the tests; a missing one is skipped.
        let Some(m) = Material::builtin(name) else {
            continue;
        };
        row(&mut out, name, "stand-in", &range(&m), &own);
        let what = String::from_utf8_lossy(m.table_bytes())
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# "))
            .unwrap_or("")
            .trim_end_matches('.')
            .to_string();
        let _ = writeln!(out, "    {what}");
    }
    let _ = writeln!(
        out,
        "\nLibrary: material = {{ library = \"<name>\" }} (published optical constants; \
         data/materials/SOURCE.md)\n"
    );
    row(&mut out, "NAME", "KIND", "RANGE", "LICENCE");
    for name in library_names() {
        let m = Material::library(name)?;
        let tables: Vec<(&str, &TableInfo)> = match m.axes() {
            Some((o, e)) => [("o: ", o), ("e: ", e)]
                .into_iter()
                .filter_map(|(ray, t)| t.info().map(|i| (ray, i)))
                .collect(),
            None => m.info().map(|i| vec![("", i)]).unwrap_or_default(),
        };
        let kind = if m.axes().is_some() {
            "crystal o+e"
        } else {
            "library"
        };
        let licence = tables.first().map_or("", |(_, i)| i.licence.as_str());
        row(&mut out, name, kind, &range(&m), licence);
        let page = |i: &TableInfo| i.page.split(' ').next().unwrap_or("").to_string();
        let pages: Vec<String> = tables
            .iter()
            .map(|(ray, i)| format!("{ray}{}", page(i)))
            .collect();
        if let Some((_, first)) = tables.first() {
            let what = first.material.split(", ordinary ray").next().unwrap_or("");
            let _ = writeln!(out, "    {what} [{}]", pages.join(", "));
        }
        let same = tables
            .windows(2)
            .all(|w| w[0].1.reference == w[1].1.reference);
        for (ray, info) in &tables {
            let ray = if same { "" } else { ray };
            let _ = writeln!(out, "      {ray}{}", info.reference);
            if same {
                break;
            }
        }
    }
    let _ = writeln!(
        out,
        "\nA crystal (o+e) enters the scalar wave equation as the orientation average \
         ε = (2 ε_o + ε_e)/3 (docs/METHOD.md).\nA wavelength outside a material's range \
         is refused when the scene is checked."
    );
    Ok(out)
}
