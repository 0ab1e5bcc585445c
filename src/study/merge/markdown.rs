//! `summary.md`: the summary page's facts, effects table, plots, grids and
//! variants in Markdown (see [`super::page`]).

use super::page::{
    any_hiding, any_tint, baseline_table, colour_cells, effect_table, hiding_cells, PageInput,
    BASELINE_TEXT, CR_TEXT, HIDING_HEAD, TINT_TEXT,
};
use std::fmt::Write as _;

fn row(cells: &[String]) -> String {
    format!("| {} |\n", cells.join(" | "))
}

fn table(head: &[String], rows: &[Vec<String>]) -> String {
    let mut s = row(head);
    s += &format!("|{}\n", "---|".repeat(head.len()));
    for r in rows {
        s += &row(r);
    }
    s
}

pub(super) fn page(p: &PageInput) -> String {
    let mut md = format!("# Study `{}` — profile `{}`\n\n", p.study.name, p.profile());
    for (k, v) in p.facts() {
        let _ = writeln!(md, "- {k}: {v}");
    }
    md += "- files: [summary.h5](summary.h5) (every variant linked), \
           [summary.html](summary.html)\n\n## Effects\n\n\
           For each step an axis compares (its `compare` pairs, else each label to the next): \
           mean change of the measured colour over the pairs of variants that differ in that \
           axis only, ± the standard error of the mean; ΔE00 range over the pairs.";
    if any_tint(p.effects) {
        md += TINT_TEXT;
    }
    md += "\n\n";
    let (head, rows) = effect_table(p.effects);
    if rows.is_empty() {
        md += "No pairs of variants with measured colours.\n\n";
    } else {
        let head: Vec<String> = head.iter().map(|h| h.to_string()).collect();
        md += &table(&head, &rows);
        md += "\n";
    }
    let (bhead, brows) = baseline_table(p);
    if !brows.is_empty() {
        md += &format!("## Classical baselines\n\n{BASELINE_TEXT}\n\n");
        md += &table(&bhead, &brows);
        md += "\n";
    }
    md += "## Plots\n\n";
    for f in p.plots {
        let _ = writeln!(md, "![{0}]({0})\n", p.rel(f));
    }
    md += "## Comparison grids\n\nEach grid of colours is followed by its ΔE00 heat map: \
           the CIEDE2000 difference of every cell to the grid's reference cell ± its standard \
           error, hatched and marked ≈ where it is within two standard errors of 0.\n\n";
    for (k, f) in p.grids.iter().enumerate() {
        let _ = writeln!(md, "![{0}]({0})\n", p.rel(f));
        if let Some(Some(m)) = p.grid_maps.get(k) {
            let _ = writeln!(md, "ΔE00 to the reference cell: ![{0}]({0})\n", p.rel(m));
        }
    }
    let cr = any_hiding(p);
    md += "## Variants\n\nR, T, A: mean total reflectance, transmittance and absorption over \
           the solves from above (for a stack combined by adding, of the whole stack in air over its angles); L*, C*ab, h°: the measured colour ± s.e.";
    if cr {
        md += CR_TEXT;
    }
    md += "\n\n";
    let mut head: Vec<String> = vec!["#".into(), "name".into()];
    head.extend(p.columns());
    for h in ["R", "T", "A", "L*", "C*ab", "h°", "colour"] {
        head.push(h.into());
    }
    if cr {
        head.extend(HIDING_HEAD.map(String::from));
    }
    head.push("files".into());
    let rows: Vec<Vec<String>> = p
        .rows
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let name = match p.variant_files(r.v).iter().find(|(t, _)| t == "tile") {
                Some((_, f)) => format!("[{}]({f})", r.v.name),
                None => r.v.name.clone(),
            };
            let mut cells = vec![(i + 1).to_string(), name];
            cells.extend(p.column_cells(r));
            cells.extend([r.r, r.t, r.a].map(|x| format!("{x:.4}")));
            match colour_cells(r) {
                Some((lch, hex)) => {
                    cells.extend(lch);
                    cells.push(hex.unwrap_or_else(|| "—".into()));
                }
                None => cells.extend(["—", "—", "—", "—"].map(String::from)),
            }
            if cr {
                cells.extend(hiding_cells(r));
            }
            cells.push(
                p.variant_files(r.v)
                    .iter()
                    .map(|(t, f)| format!("[{t}]({f})"))
                    .collect::<Vec<_>>()
                    .join(" "),
            );
            cells
        })
        .collect();
    md + &table(&head, &rows)
}
