//! Merging a finished study: one summary HDF5 file, the labelled comparison
//! grids and a summary page.
//!
//! Written into the study folder, each atomically:
//! - `summary.h5`: group `/variants` with one HDF5 *external link* per
//!   variant (`/variants/<name>` → `variants/<name>.h5:/`, a path relative
//!   to the summary file, so the folder can be moved), and a table of the
//!   variants as parallel 1-D datasets in expansion order: `name`, `id`
//!   (UTF-8), `seed` (u64), `mean_reflectance`, `mean_transmittance`,
//!   `mean_absorption` (f64, means over the solves), `natural_srgb8` (n × 3
//!   u8, sRGB under natural light at the first viewing angle; `has_colour`
//!   (u8) says whether the result had an `/appearance` group) and
//!   `labels/<axis>` (UTF-8, empty where a variant has no label on that axis).
//!   Root attributes `study`, `profile`, `sweep_file`.
//! - `grids/<grid>[__<axis>-<label>…].png`: for each declared grid (or the
//!   default: first axis as rows, second as columns), one picture per
//!   combination of the labels of the remaining axes not fixed by `where`;
//!   each cell is the variant's tile, shrunk by an integer factor to at
//!   most [`CELL_PX`] pixels, with row and column labels; an empty cell is
//!   grey with a dash.
//! - `summary.md` and `summary.html`: the grids and a table of the variants
//!   (labels, mean R, T, A, colour as hex and L*a*b*; the HTML page shows
//!   swatches).
//!
//! Merge refuses to run until every variant is finished, and lists what is
//! missing and why.

use super::run::{self, State};
use super::sweep::{sanitise, Expansion, GridDecl, Study, Variant};
use super::StudyError;
use crate::output::atomic;
use crate::output::h5::{self, ResultSummary};
use crate::output::render::canvas::{text_width, Canvas, GLYPH_HEIGHT};
use hdf5::types::VarLenUnicode;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Largest side of a tile in a comparison grid, pixels.
pub const CELL_PX: usize = 200;
const PAD: usize = 8;
const BG: [u8; 3] = [255, 255, 255];
const INK: [u8; 3] = [20, 20, 20];
const EMPTY: [u8; 3] = [215, 215, 215];

/// What merge wrote.
#[derive(Debug, Clone)]
pub struct MergeReport {
    pub summary_h5: PathBuf,
    pub summary_md: PathBuf,
    pub summary_html: PathBuf,
    pub grids: Vec<PathBuf>,
}

/// One row of the summary table.
struct Row<'a> {
    v: &'a Variant,
    s: ResultSummary,
    r: f64,
    t: f64,
    a: f64,
}

/// Merge a finished study (see the module docs).
pub fn merge(study: &Study, exp: &Expansion) -> Result<MergeReport, StudyError> {
    let mut missing = vec![];
    for v in &exp.variants {
        let s = run::state(v);
        if s != State::Done {
            missing.push(format!("{} ({})", v.name, s.reason()));
        }
    }
    if !missing.is_empty() {
        let n = missing.len();
        missing.truncate(20);
        return Err(StudyError::Incomplete(format!(
            "{}: {n} of {} variants are not finished, so there is nothing to merge yet: {}{}; \
             run `inksim run {}{}` first",
            study.path.display(),
            exp.variants.len(),
            missing.join(", "),
            if n > 20 { ", …" } else { "" },
            study.path.display(),
            exp.profile
                .as_deref()
                .map(|p| format!(" --profile {p}"))
                .unwrap_or_default()
        )));
    }
    let mut rows = Vec::with_capacity(exp.variants.len());
    for v in &exp.variants {
        let s = h5::read_summary(&run::paths(v).0)?;
        // Light from above only (solves from below feed the paper term).
        let above: Vec<&h5::EntrySummary> = s
            .entries
            .iter()
            .filter(|e| e.side == crate::optics::farfield::Side::Above)
            .collect();
        let n = above.len().max(1) as f64;
        let mean = |f: fn(&h5::EntrySummary) -> f64| above.iter().map(|e| f(e)).sum::<f64>() / n;
        let (r, t, a) = (
            mean(|e| e.total_reflectance),
            mean(|e| e.total_transmittance),
            mean(|e| e.absorption),
        );
        rows.push(Row { v, s, r, t, a });
    }
    let dir = &exp.study_dir;
    let grids_dir = dir.join("grids");
    let mut grids = vec![];
    for g in &study.grids {
        for (file, title, canvas) in draw_grid(study, exp, g)? {
            let p = grids_dir.join(file);
            atomic::write_atomic(&p, &canvas.encode_png(&title)?)?;
            grids.push(p);
        }
    }
    let summary_h5 = dir.join("summary.h5");
    write_summary_h5(study, exp, &rows, &summary_h5)?;
    let (md, html) = pages(study, exp, &rows, &grids);
    let summary_md = dir.join("summary.md");
    let summary_html = dir.join("summary.html");
    atomic::write_atomic(&summary_md, md.as_bytes())?;
    atomic::write_atomic(&summary_html, html.as_bytes())?;
    Ok(MergeReport {
        summary_h5,
        summary_md,
        summary_html,
        grids,
    })
}

/// Labels of `axis` in axis order, restricted to `only` when given.
fn axis_labels(study: &Study, axis: &str, only: &Option<Vec<String>>) -> Vec<String> {
    match only {
        Some(l) => l.clone(),
        None => study
            .axes
            .iter()
            .find(|a| a.name == axis)
            .map(|a| a.values.iter().map(|v| v.label.clone()).collect())
            .unwrap_or_default(),
    }
}

/// The pictures of one grid declaration: (file name, title, canvas).
fn draw_grid(
    study: &Study,
    exp: &Expansion,
    g: &GridDecl,
) -> Result<Vec<(String, String, Canvas)>, StudyError> {
    let split: Vec<&str> = study
        .axes
        .iter()
        .map(|a| a.name.as_str())
        .filter(|a| *a != g.rows && *a != g.cols && !g.where_.contains_key(*a))
        .collect();
    let rows = axis_labels(study, &g.rows, &g.row_labels);
    let cols = axis_labels(study, &g.cols, &g.col_labels);
    let fits = |v: &Variant| {
        g.where_.iter().all(|(a, l)| v.label(a) == Some(l))
            && v.label(&g.rows)
                .is_some_and(|l| rows.iter().any(|x| x == l))
            && v.label(&g.cols)
                .is_some_and(|l| cols.iter().any(|x| x == l))
    };
    // Distinct combinations of the split axes among the fitting variants, in
    // expansion order.
    let mut combos: Vec<Vec<Option<String>>> = vec![];
    for v in exp.variants.iter().filter(|v| fits(v)) {
        let c: Vec<Option<String>> = split
            .iter()
            .map(|a| v.label(a).map(str::to_string))
            .collect();
        if !combos.contains(&c) {
            combos.push(c);
        }
    }
    let mut out = vec![];
    for combo in combos {
        let cell = |r: &str, c: &str| {
            exp.variants.iter().find(|v| {
                fits(v)
                    && v.label(&g.rows) == Some(r)
                    && v.label(&g.cols) == Some(c)
                    && split
                        .iter()
                        .zip(&combo)
                        .all(|(a, l)| v.label(a) == l.as_deref())
            })
        };
        let mut tiles: Vec<Vec<Option<Canvas>>> = vec![];
        for r in &rows {
            let mut line = vec![];
            for c in &cols {
                line.push(match cell(r, c) {
                    Some(v) => {
                        let bytes = std::fs::read(run::paths(v).1).map_err(|source| {
                            StudyError::Io(h5::IoError::File {
                                path: run::paths(v).1,
                                source,
                            })
                        })?;
                        Some(shrink(&Canvas::decode_png(&bytes)?, CELL_PX))
                    }
                    None => None,
                });
            }
            tiles.push(line);
        }
        let mut fixed: Vec<String> = g.where_.iter().map(|(a, l)| format!("{a} {l}")).collect();
        let mut suffix = String::new();
        for (a, l) in split.iter().zip(&combo) {
            let l = l.as_deref().unwrap_or("none");
            fixed.push(format!("{a} {l}"));
            suffix += &format!("__{}-{}", sanitise(a), sanitise(l));
        }
        let title = format!(
            "{} {}: {}{}",
            study.name,
            exp.profile.as_deref().unwrap_or(""),
            g.name,
            if fixed.is_empty() {
                String::new()
            } else {
                format!(" ({})", fixed.join(", "))
            }
        );
        let subtitle = format!("rows: {}, columns: {}", g.rows, g.cols);
        let canvas = compose(&title, &subtitle, &rows, &cols, &tiles);
        out.push((format!("{}{suffix}.png", g.name), title, canvas));
    }
    Ok(out)
}

/// Shrink by the smallest integer factor that brings both sides to ≤ `max`
/// (box average).
pub fn shrink(src: &Canvas, max: usize) -> Canvas {
    let f = src.w.div_ceil(max).max(src.h.div_ceil(max)).max(1);
    if f == 1 {
        return Canvas {
            w: src.w,
            h: src.h,
            px: src.px.clone(),
        };
    }
    let (w, h) = (src.w / f, src.h / f);
    let mut out = Canvas::new(w.max(1), h.max(1), BG);
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0usize; 3];
            for dy in 0..f {
                for dx in 0..f {
                    let i = ((y * f + dy) * src.w + x * f + dx) * 3;
                    for (a, &p) in acc.iter_mut().zip(&src.px[i..i + 3]) {
                        *a += p as usize;
                    }
                }
            }
            let n = f * f;
            let o = (y * w + x) * 3;
            for (p, a) in out.px[o..o + 3].iter_mut().zip(acc) {
                *p = ((a + n / 2) / n) as u8;
            }
        }
    }
    out
}

/// Lay out a labelled grid of tiles.
fn compose(
    title: &str,
    subtitle: &str,
    rows: &[String],
    cols: &[String],
    tiles: &[Vec<Option<Canvas>>],
) -> Canvas {
    let all = tiles.iter().flatten().flatten();
    let tw = all.clone().map(|c| c.w).max().unwrap_or(CELL_PX / 2);
    let th = all.map(|c| c.h).max().unwrap_or(CELL_PX / 2);
    let cw = tw.max(cols.iter().map(|c| text_width(c)).max().unwrap_or(0)) + PAD;
    let ch = th + PAD;
    let lw = rows.iter().map(|r| text_width(r)).max().unwrap_or(0) + 2 * PAD;
    let head = 3 * (GLYPH_HEIGHT + PAD) + PAD;
    let w = (lw + cols.len() * cw + PAD).max(text_width(title).max(text_width(subtitle)) + 2 * PAD);
    let h = head + rows.len() * ch + PAD;
    let mut c = Canvas::new(w, h, BG);
    c.text(PAD, PAD, title, INK);
    c.text(PAD, 2 * PAD + GLYPH_HEIGHT, subtitle, INK);
    let y0 = head;
    for (j, col) in cols.iter().enumerate() {
        let x = lw + j * cw + (cw - text_width(col)) / 2;
        c.text(x, y0 - GLYPH_HEIGHT - PAD / 2, col, INK);
    }
    for (i, row) in rows.iter().enumerate() {
        let y = y0 + i * ch;
        c.text(PAD, y + (ch - GLYPH_HEIGHT) / 2, row, INK);
        for (j, tile) in tiles[i].iter().enumerate().take(cols.len()) {
            let x = lw + j * cw;
            match tile {
                Some(t) => c.blit(t, (x + (cw - t.w) / 2) as i64, (y + (ch - t.h) / 2) as i64),
                None => {
                    c.rect(
                        (x + PAD / 2) as i64,
                        (y + PAD / 2) as i64,
                        cw - PAD,
                        th,
                        EMPTY,
                    );
                    c.text(
                        x + (cw - text_width("-")) / 2,
                        y + (ch - GLYPH_HEIGHT) / 2,
                        "-",
                        INK,
                    );
                }
            }
        }
    }
    c
}

fn vlu(path: &Path, s: &str) -> Result<VarLenUnicode, StudyError> {
    s.parse().map_err(|_| StudyError::Sweep {
        file: path.to_path_buf(),
        message: format!("text `{s}` cannot be stored (contains NUL)"),
    })
}

fn write_summary_h5(
    study: &Study,
    exp: &Expansion,
    rows: &[Row],
    path: &Path,
) -> Result<(), StudyError> {
    atomic::write_atomic_with(path, |tmp| -> Result<(), StudyError> {
        let h = |source| StudyError::Hdf5 {
            path: tmp.to_path_buf(),
            source,
        };
        let f = hdf5::File::create(tmp).map_err(h)?;
        for (name, v) in [
            ("study", study.name.as_str()),
            ("profile", exp.profile.as_deref().unwrap_or("")),
            ("sweep_file", &study.path.display().to_string()),
        ] {
            let val = vlu(path, v)?;
            f.new_attr::<VarLenUnicode>()
                .shape(())
                .create(name)
                .and_then(|a| a.write_scalar(&val))
                .map_err(h)?;
        }
        let links = f.create_group("variants").map_err(h)?;
        for r in rows {
            let target = format!("variants/{}.h5", r.v.name);
            links.link_external(&target, "/", &r.v.name).map_err(h)?;
        }
        let strings = |xs: Vec<String>| -> Result<Vec<VarLenUnicode>, StudyError> {
            xs.iter().map(|s| vlu(path, s)).collect()
        };
        let names = strings(rows.iter().map(|r| r.v.name.clone()).collect())?;
        f.new_dataset_builder()
            .with_data(&names)
            .create("name")
            .map_err(h)?;
        let ids = strings(rows.iter().map(|r| r.v.id.clone()).collect())?;
        f.new_dataset_builder()
            .with_data(&ids)
            .create("id")
            .map_err(h)?;
        let seeds: Vec<u64> = rows.iter().map(|r| r.v.seed).collect();
        f.new_dataset_builder()
            .with_data(&seeds)
            .create("seed")
            .map_err(h)?;
        for (n, xs) in [
            (
                "mean_reflectance",
                rows.iter().map(|r| r.r).collect::<Vec<f64>>(),
            ),
            ("mean_transmittance", rows.iter().map(|r| r.t).collect()),
            ("mean_absorption", rows.iter().map(|r| r.a).collect()),
        ] {
            f.new_dataset_builder()
                .with_data(&xs)
                .create(n)
                .map_err(h)?;
        }
        let mut rgb = ndarray::Array2::<u8>::zeros((rows.len(), 3));
        let mut has = vec![0u8; rows.len()];
        for (i, r) in rows.iter().enumerate() {
            if let Some(c) =
                r.s.appearance
                    .as_ref()
                    .and_then(|a| a.natural_srgb8.first())
            {
                rgb.row_mut(i).assign(&ndarray::arr1(c));
                has[i] = 1;
            }
        }
        f.new_dataset_builder()
            .with_data(&rgb)
            .create("natural_srgb8")
            .map_err(h)?;
        f.new_dataset_builder()
            .with_data(&has)
            .create("has_colour")
            .map_err(h)?;
        let lg = f.create_group("labels").map_err(h)?;
        for a in &study.axes {
            let ls = strings(
                rows.iter()
                    .map(|r| r.v.label(&a.name).unwrap_or("").to_string())
                    .collect(),
            )?;
            lg.new_dataset_builder()
                .with_data(&ls)
                .create(a.name.as_str())
                .map_err(h)?;
        }
        f.close().map_err(h)?;
        Ok(())
    })
}

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
fn pages(study: &Study, exp: &Expansion, rows: &[Row], grids: &[PathBuf]) -> (String, String) {
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
