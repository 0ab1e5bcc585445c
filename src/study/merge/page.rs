//! `summary.md` and `summary.html`: the grids and the table of the variants
//! (labels, mean R, T, A, colour as hex and L*a*b*; swatches in HTML).

use super::Row;
use crate::study::sweep::{Expansion, Study};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Colour of a row: (hex, L*a*b* text), when the result has `/appearance`.
fn colour(r: &Row) -> Option<(String, String)> {
    let a = r.s.appearance.as_ref()?;
    let c = a.natural_srgb8.first()?;
    let lab = a
        .natural_lab
        .first()
        .map(|l| format!("L* {:.1} a* {:.1} b* {:.1}", l[0], l[1], l[2]))
        .unwrap_or_default();
    Some((format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]), lab))
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The Markdown and HTML summary pages.
pub(super) fn pages(
    study: &Study,
    exp: &Expansion,
    rows: &[Row],
    grids: &[PathBuf],
) -> (String, String) {
    let rel = |p: &Path| {
        p.strip_prefix(&exp.study_dir)
            .unwrap_or(p)
            .display()
            .to_string()
    };
    let profile = exp.profile.as_deref().unwrap_or("(none)");
    let axes: Vec<&str> = study.axes.iter().map(|a| a.name.as_str()).collect();
    let mut md = String::new();
    let _ = writeln!(md, "# Study `{}` — profile `{profile}`\n", study.name);
    let _ = writeln!(
        md,
        "{} variants from `{}`; results in `variants/`, all linked from `summary.h5`. \
         R, T, A: mean total reflectance, transmittance and absorption over the solves from above; \
         colour: sRGB and CIELAB under natural light at the first viewing angle (\"—\" \
         where the result has no appearance data).\n",
        rows.len(),
        study.path.display()
    );
    let _ = writeln!(md, "## Comparison grids\n");
    for g in grids {
        let _ = writeln!(md, "![{0}]({0})\n", rel(g));
    }
    let _ = writeln!(md, "## Variants\n");
    let mut head = vec!["#", "name"];
    head.extend(&axes);
    head.extend(["R", "T", "A", "colour", "L*a*b*"]);
    let _ = writeln!(md, "| {} |", head.join(" | "));
    let _ = writeln!(md, "|{}", "---|".repeat(head.len()));
    let mut trs = String::new();
    for (i, r) in rows.iter().enumerate() {
        let labels: Vec<&str> = axes.iter().map(|a| r.v.label(a).unwrap_or("—")).collect();
        let (hex, lab) = colour(r).unwrap_or_else(|| ("—".into(), "—".into()));
        let _ = writeln!(
            md,
            "| {} | [{}](variants/{}.png) | {} | {:.4} | {:.4} | {:.4} | {hex} | {lab} |",
            i + 1,
            r.v.name,
            r.v.name,
            labels.join(" | "),
            r.r,
            r.t,
            r.a
        );
        let swatch = match colour(r) {
            Some((hex, _)) => format!(
                "<span style=\"display:inline-block;width:2em;height:1em;background:{hex};\
                 border:1px solid #888\"></span> {hex}"
            ),
            None => "—".into(),
        };
        let _ = writeln!(
            trs,
            "<tr><td>{}</td><td><a href=\"variants/{n}.png\">{n}</a></td>{}<td>{:.4}</td>\
             <td>{:.4}</td><td>{:.4}</td><td>{swatch}</td><td>{}</td></tr>",
            i + 1,
            labels
                .iter()
                .map(|l| format!("<td>{}</td>", html_escape(l)))
                .collect::<String>(),
            r.r,
            r.t,
            r.a,
            html_escape(&lab),
            n = html_escape(&r.v.name)
        );
    }
    let imgs: String = grids
        .iter()
        .map(|g| {
            format!(
                "<p><img src=\"{0}\" alt=\"{0}\"></p>\n",
                html_escape(&rel(g))
            )
        })
        .collect();
    let ths: String = head
        .iter()
        .map(|h| format!("<th>{}</th>", html_escape(h)))
        .collect();
    let html = format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{t}</title>\
         <style>body{{font-family:sans-serif}}table{{border-collapse:collapse}}\
         td,th{{border:1px solid #ccc;padding:2px 6px}}</style></head><body>\n\
         <h1>{t}</h1>\n<p>{n} variants; R, T, A are means over the solves; colour under \
         natural light at the first viewing angle.</p>\n<h2>Comparison grids</h2>\n{imgs}\
         <h2>Variants</h2>\n<table><tr>{ths}</tr>\n{trs}</table>\n</body></html>\n",
        t = html_escape(&format!("Study {} — profile {profile}", study.name)),
        n = rows.len()
    );
    (md, html)
}
