//! The summary page of an effect study, as blocks written out once as
//! Markdown and once as HTML: the facts, the findings, the table per label,
//! the grids, the table of the variants, and per variant its flop curve,
//! patches and sparkle figures.

use super::findings::{self, hue_name, LabelMeans, Step, DE00_FLOOR, FACE, FLOP_FLOOR};
use super::row::EffectRow;
use crate::config::paint::PaintScene;
use crate::optics::flakes::multiangle::ASPECULAR_45_DEG;
use crate::output::html::escape as esc;
use crate::study::sweep::{Expansion, Study};
use std::path::{Path, PathBuf};

/// One block of the page.
pub enum Block {
    /// A heading of level 1–3.
    Heading(usize, String),
    Paragraph(String),
    List(Vec<String>),
    Table(Vec<String>, Vec<Vec<String>>),
    /// A picture: path relative to the page, caption.
    Image(String, String),
}

/// `path` relative to the study folder `dir` (as the page links it).
fn relative(dir: &Path, path: &Path) -> String {
    path.strip_prefix(dir)
        .unwrap_or(path)
        .to_string_lossy()
        .into_owned()
}

fn num(x: Option<f64>, digits: usize) -> String {
    x.filter(|x| x.is_finite())
        .map_or("–".into(), |x| format!("{x:.digits$}"))
}

/// The page's blocks.
pub fn blocks(
    study: &Study,
    exp: &Expansion<PaintScene>,
    rows: &[EffectRow],
    steps: &[Step],
    means: &[LabelMeans],
    grids: &[PathBuf],
) -> Vec<Block> {
    let first = &rows[0].rec;
    let mut b = vec![Block::Heading(
        1,
        format!(
            "Effect study `{}`{}",
            study.name,
            exp.profile
                .as_deref()
                .map(|p| format!(", profile {p}"))
                .unwrap_or_default()
        ),
    )];
    b.push(Block::Paragraph(format!(
        "{} variants of an effect paint, each computed by the fast model (METHOD §9) from the \
         sweep file {}. Colours are CIELAB under {} and the CIE {}° observer, at 45° \
         illumination and aspecular angles −15°, 15°, 25°, 45°, 75°, 110° and at 15° \
         illumination; the flop index is 2.69 (L*15 − L*110)^1.11 / L*45^0.86. The fast \
         model is deterministic: its figures have no sampling uncertainty, so a change \
         below {FLOP_FLOOR} in the flop index or {DE00_FLOOR} in ΔE00 (numerical noise) is \
         counted as none. Sparkle: glints of single flakes under a small light at each \
         illumination angle, viewed along the normal; graininess under diffuse light.",
        rows.len(),
        study.path.display(),
        first.illuminant,
        first.observer_deg
    )));
    let first_axis = study.axes.first().map(|a| a.name.as_str());
    b.push(Block::Heading(2, "What the study finds".into()));
    let mut found: Vec<String> = steps.iter().map(Step::sentence).collect();
    for m in means.iter().filter(|m| m.face_lch.is_some()) {
        if let Some([_, c, h]) = m.face_lch {
            if first_axis == Some(m.axis.as_str()) {
                found.push(format!(
                    "`{}` = {}: at {}as{} C*ab {c:.1}, h {h:.0}° — {} (mean of {} variant(s)).",
                    m.axis,
                    m.label,
                    FACE.0,
                    FACE.1,
                    hue_name(c, h),
                    m.variants
                ));
            }
        }
    }
    b.push(Block::List(found));
    b.push(Block::Heading(2, "Per label".into()));
    b.push(Block::Paragraph(format!(
        "Means over the variants with each label; the colour at {}as{} (h: the \
         chroma-weighted circular mean). A hue is named for the first axis only: the other \
         axes' means mix its finishes.",
        FACE.0, FACE.1
    )));
    b.push(Block::Table(
        [
            "axis",
            "label",
            "variants",
            "flop index",
            "L*",
            "C*ab",
            "h (°)",
            "hue",
        ]
        .map(String::from)
        .to_vec(),
        means
            .iter()
            .map(|m| {
                let lch = m.face_lch;
                vec![
                    m.axis.clone(),
                    m.label.clone(),
                    m.variants.to_string(),
                    num(m.flop, 2),
                    num(lch.map(|c| c[0]), 1),
                    num(lch.map(|c| c[1]), 1),
                    num(lch.map(|c| c[2]), 0),
                    match lch {
                        Some(c) if Some(m.axis.as_str()) == first_axis => {
                            hue_name(c[1], c[2]).to_string()
                        }
                        _ => "–".into(),
                    },
                ]
            })
            .collect(),
    ));
    if !grids.is_empty() {
        b.push(Block::Heading(2, "Grids".into()));
        for g in grids {
            let rel = relative(&exp.study_dir, g);
            b.push(Block::Image(rel.clone(), rel));
        }
    }
    b.push(Block::Heading(2, "Variants".into()));
    b.push(Block::Paragraph(
        "L*/C*ab/h at 45° illumination per aspecular angle; sparkle: glints per mm² (per \
         resolved cell) under a small light at each angle; Y: the glinting flake's luminous \
         reflectance (sparkle intensity)."
            .into(),
    ));
    let lights: Vec<f64> = first
        .sparkle
        .as_ref()
        .map(|s| s.rows.iter().map(|r| r.illumination_deg).collect())
        .unwrap_or_default();
    let mut head = vec!["variant".to_string(), "flop".into()];
    head.extend(ASPECULAR_45_DEG.iter().map(|a| format!("45as{a} L*/C*/h")));
    head.extend(lights.iter().map(|l| format!("sparkle {l}° /mm² (cell) Y")));
    head.push("graininess".into());
    let table = rows
        .iter()
        .map(|r| {
            let mut line = vec![r.v.name.clone(), num(r.rec.flop_index, 2)];
            for a in ASPECULAR_45_DEG {
                line.push(
                    findings::colour_at(r, (45.0, a)).map_or("–".into(), |(_, c)| {
                        format!("{:.1}/{:.1}/{:.0}", c[0], c[1], c[2])
                    }),
                );
            }
            for l in &lights {
                let s = r
                    .rec
                    .sparkle
                    .as_ref()
                    .and_then(|s| s.rows.iter().find(|x| x.illumination_deg == *l));
                line.push(s.map_or("–".into(), |s| {
                    format!(
                        "{:.2} ({:.3}) {:.2}",
                        s.glints_per_mm2, s.glints_per_cell, s.glint_reflectance
                    )
                }));
            }
            line.push(num(r.rec.sparkle.as_ref().map(|s| s.graininess), 3));
            line
        })
        .collect();
    b.push(Block::Table(head, table));
    b.push(Block::Heading(
        2,
        "Flop curves and patches per variant".into(),
    ));
    for r in rows {
        let labels: Vec<String> = r.v.labels.iter().map(|(a, l)| format!("{a} {l}")).collect();
        b.push(Block::Heading(3, r.v.name.clone()));
        b.push(Block::Paragraph(format!(
            "{}; flop index {}; result variants/{}.h5",
            labels.join(", "),
            num(r.rec.flop_index, 2),
            r.v.name
        )));
        for (file, what) in [("-flop", "flop curve"), ("", "patches")] {
            let rel = format!("variants/{}{file}.png", r.v.name);
            b.push(Block::Image(rel, format!("{} {what}", r.v.name)));
        }
    }
    b
}

/// The blocks as Markdown.
pub fn markdown(blocks: &[Block]) -> String {
    let mut s = String::new();
    for b in blocks {
        match b {
            Block::Heading(l, t) => s += &format!("{} {t}\n\n", "#".repeat(*l)),
            Block::Paragraph(t) => s += &format!("{t}\n\n"),
            Block::List(items) => {
                for i in items {
                    s += &format!("- {i}\n");
                }
                s += "\n";
            }
            Block::Table(head, rows) => {
                s += &format!("| {} |\n", head.join(" | "));
                s += &format!("|{}\n", "---|".repeat(head.len()));
                for r in rows {
                    s += &format!("| {} |\n", r.join(" | "));
                }
                s += "\n";
            }
            Block::Image(src, alt) => s += &format!("![{alt}]({src})\n\n"),
        }
    }
    s
}

/// Inline `code` spans of Markdown as HTML.
fn inline(t: &str) -> String {
    esc(t)
        .split('`')
        .enumerate()
        .map(|(i, p)| {
            if i % 2 == 1 {
                format!("<code>{p}</code>")
            } else {
                p.to_string()
            }
        })
        .collect()
}

/// The blocks as a self-contained HTML page (pictures linked).
pub fn html(title: &str, blocks: &[Block]) -> String {
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n\
         <style>body{{font-family:sans-serif;margin:2em;max-width:110em}}\
         table{{border-collapse:collapse;font-size:90%}}td,th{{border:1px solid #bbb;\
         padding:2px 6px;text-align:right}}td:first-child,th:first-child{{text-align:left}}\
         img{{max-width:100%;margin:4px}}figure{{display:inline-block;margin:0}}</style>\
         </head><body>\n",
        esc(title)
    );
    for b in blocks {
        match b {
            Block::Heading(l, t) => s += &format!("<h{l}>{}</h{l}>\n", inline(t)),
            Block::Paragraph(t) => s += &format!("<p>{}</p>\n", inline(t)),
            Block::List(items) => {
                s += "<ul>\n";
                for i in items {
                    s += &format!("<li>{}</li>\n", inline(i));
                }
                s += "</ul>\n";
            }
            Block::Table(head, rows) => {
                s += "<table><tr>";
                for h in head {
                    s += &format!("<th>{}</th>", esc(h));
                }
                s += "</tr>\n";
                for r in rows {
                    s += "<tr>";
                    for c in r {
                        s += &format!("<td>{}</td>", esc(c));
                    }
                    s += "</tr>\n";
                }
                s += "</table>\n";
            }
            Block::Image(src, alt) => {
                s += &format!(
                    "<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\" loading=\"lazy\"></a>\
                     </figure>\n",
                    esc(src),
                    esc(alt)
                )
            }
        }
    }
    s + "</body></html>\n"
}
