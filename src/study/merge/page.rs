//! `summary.html`: what was run (inksim version, date, sweep file, profile
//! and its settings, colour conditions), the effects table, the study plots
//! and the comparison grids scaled to the page, each followed by its ΔE00
//! heat map, the table of the variants
//! (labels, R, T, A, L*, C*ab, h° ± s.e., a swatch) and links to every
//! result file. Every link is relative to the study folder and names a file
//! that exists when the page is written. `summary.md` (see [`markdown`])
//! holds the same in Markdown.

use super::effects::{Effect, MeanSe};
use super::Row;
use crate::config::Equation;
use crate::optics::colour::{lab_to_lch, lch_se};
use crate::output::html::escape;
use crate::study::run;
use crate::study::sweep::{Expansion, Study, Variant};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Everything the pages show.
pub(super) struct PageInput<'a> {
    pub study: &'a Study,
    pub exp: &'a Expansion,
    pub rows: &'a [Row<'a>],
    pub effects: &'a [Effect],
    pub grids: &'a [PathBuf],
    /// The ΔE00 heat map of each grid picture, parallel to `grids`.
    pub grid_maps: &'a [Option<PathBuf>],
    pub plots: &'a [PathBuf],
    /// Seconds since 1970-01-01 UTC of the merge.
    pub unix_s: u64,
}

impl PageInput<'_> {
    /// `p` relative to the study folder, with `/` separators.
    pub fn rel(&self, p: &Path) -> String {
        let r = p.strip_prefix(&self.exp.study_dir).unwrap_or(p);
        r.components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/")
    }

    pub fn profile(&self) -> &str {
        self.exp.profile.as_deref().unwrap_or("(none)")
    }

    /// The facts at the top of the page: (what, value).
    pub fn facts(&self) -> Vec<(String, String)> {
        let settings = match self.exp.profile.as_ref() {
            Some(p) => self.study.profiles.get(p).map_or(String::new(), |o| {
                o.iter()
                    .map(|o| format!("{} = {}", o.key, o.value))
                    .collect::<Vec<_>>()
                    .join("; ")
            }),
            None => "no profiles".into(),
        };
        // The realisations each variant's result holds (a target stops
        // early), and the most the profile allowed.
        let used: Vec<usize> = self
            .rows
            .iter()
            .map(|r| {
                r.s.entries
                    .iter()
                    .map(|e| e.realisation + 1)
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let (lo, hi) = (
            used.iter().copied().min().unwrap_or(0),
            used.iter().copied().max().unwrap_or(0),
        );
        let target = self.rows.iter().find_map(|r| {
            r.v.scene
                .realisation_target
                .map(|t| (t, r.v.scene.realisations))
        });
        let realisations = match (lo == hi, target) {
            (true, None) => lo.to_string(),
            (false, None) => format!("{lo}–{hi}"),
            (_, Some((t, most))) => format!(
                "{lo}–{hi} (added until the colour's s.e. is {} ΔE00, at most {most}; a \
                 layer the same in every realisation runs one)",
                fmt_target(t.de00)
            ),
        };
        let colour = self.rows.iter().find_map(|r| r.measured.as_ref()).map_or(
            "no measured colours".into(),
            |m| {
                format!(
                    "{} geometry; {} (illuminant, observer)",
                    m.record.geometry, m.conditions
                )
            },
        );
        vec![
            ("study".into(), self.study.name.clone()),
            ("wave equation".into(), self.equations()),
            ("sweep file".into(), self.study.path.display().to_string()),
            ("profile".into(), self.profile().to_string()),
            ("profile settings".into(), settings),
            (
                "variants".into(),
                if self.exp.selection.is_empty() {
                    self.rows.len().to_string()
                } else {
                    format!(
                        "{}, only {} (a subset of the study)",
                        self.rows.len(),
                        self.exp.selection_text()
                    )
                },
            ),
            ("realisations per variant".into(), realisations),
            ("colour".into(), colour),
            ("inksim version".into(), crate::VERSION.to_string()),
            ("merged".into(), utc_date(self.unix_s)),
        ]
    }

    /// Which wave equation the colours came from: one for every variant,
    /// or how many variants took each (the variants table then names each
    /// variant's).
    pub fn equations(&self) -> String {
        let maxwell = self
            .rows
            .iter()
            .filter(|r| r.v.scene.solver.equation == Equation::Maxwell)
            .count();
        let helmholtz = self.rows.len() - maxwell;
        match (helmholtz, maxwell) {
            (_, 0) => "helmholtz for every variant (the scalar approximation: its model \
                       error against Maxwell's equations is in docs/ACCURACY.md and in `inksim \
                       plan`'s expected error)"
                .into(),
            (0, _) => "maxwell for every variant (the vector field; natural light as s and p \
                       or one random-phase solve per incidence, see each result's solves)"
                .into(),
            (h, m) => format!("helmholtz for {h} variants, maxwell for {m} (column \"equation\")"),
        }
    }

    /// Whether the variants differ in their wave equation.
    pub fn mixed_equations(&self) -> bool {
        let mut e = self.rows.iter().map(|r| r.v.scene.solver.equation);
        e.next().is_some_and(|first| e.any(|x| x != first))
    }

    /// The variants table's descriptive columns: the axes, and the
    /// equation when the variants differ in it.
    pub fn columns(&self) -> Vec<String> {
        let mut c: Vec<String> = self.study.axes.iter().map(|a| a.name.clone()).collect();
        if self.mixed_equations() {
            c.push("equation".into());
        }
        c
    }

    /// A variant's cells under [`PageInput::columns`].
    pub fn column_cells(&self, r: &Row) -> Vec<String> {
        let mut c: Vec<String> = self
            .study
            .axes
            .iter()
            .map(|a| r.v.label(&a.name).unwrap_or("—").to_string())
            .collect();
        if self.mixed_equations() {
            c.push(r.v.scene.solver.equation.name().into());
        }
        c
    }

    /// Links to a variant's files that exist: (text, relative path).
    pub fn variant_files(&self, v: &Variant) -> Vec<(String, String)> {
        let (h5, tile) = run::paths(v);
        let dir = h5.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut files = vec![("h5".to_string(), h5), ("tile".to_string(), tile)];
        for what in ["orders", "spectra", "brdf-plane", "brdf-polar", "preview"] {
            files.push((what.into(), dir.join(format!("{}-{what}.png", v.name))));
        }
        files
            .into_iter()
            .filter(|(_, p)| p.is_file())
            .map(|(t, p)| (t, self.rel(&p)))
            .collect()
    }
}

/// `YYYY-MM-DD HH:MM UTC` of a Unix time.
pub fn utc_date(unix_s: u64) -> String {
    let [y, m, d, hh, mm, _] = crate::output::progress::utc_civil(unix_s);
    format!("{y:04}-{m:02}-{d:02} {hh:02}:{mm:02} UTC")
}

/// `+1.23 ± 0.04` (signed) or `1.23 ± 0.04`; no "±" without an s.e.
pub fn fmt_mean_se(m: &MeanSe, signed: bool) -> String {
    let v = if signed {
        format!("{:+.2}", m.mean)
    } else {
        format!("{:.2}", m.mean)
    };
    match m.se {
        Some(s) => format!("{v} ± {s:.2}"),
        None => v,
    }
}

/// A variant's colour cells: L*, C*ab, h° (each ± s.e.) and the sRGB hex
/// of the result's natural-light colour; `None` without measured colour.
pub fn colour_cells(r: &Row) -> Option<([String; 3], Option<String>)> {
    let m = r.measured.as_ref()?;
    let lch = lab_to_lch(m.record.lab);
    let se = m.record.lab_se.map(|s| lch_se(m.record.lab, s));
    let cell = |k: usize, digits: usize| match se {
        Some(s) => format!("{:.*} ± {:.*}", digits, lch[k], digits, s[k]),
        None => format!("{:.*}", digits, lch[k]),
    };
    let hex =
        r.s.appearance
            .as_ref()
            .and_then(|a| a.natural_srgb8.first())
            .map(|c| format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]));
    Some(([cell(0, 1), cell(1, 1), cell(2, 0)], hex))
}

/// A value ± its standard error with `digits` decimals (`—` when not finite).
fn value_se(value: f64, se: Option<f64>, digits: usize) -> String {
    if !value.is_finite() {
        return if value.is_nan() {
            "—".into()
        } else {
            "∞".into()
        };
    }
    match se.filter(|s| s.is_finite()) {
        Some(se) => format!("{value:.digits$} ± {se:.digits$}"),
        None => format!("{value:.digits$}"),
    }
}

/// The header cells of a variant's hiding power (with [`hiding_cells`]).
pub const HIDING_HEAD: [&str; 4] = ["CR", "S (1/µm)", "K (1/µm)", "K/S max"];

/// A variant's hiding power over a chart: the contrast ratio, Kubelka's S
/// and K at Y, and the largest K/S over the solved wavelengths with where it
/// is, each ± its standard error; `—` without a chart.
pub fn hiding_cells(r: &Row) -> [String; 4] {
    match &r.hiding {
        Some(h) => [
            value_se(h.contrast_ratio, h.contrast_ratio_se, 4),
            value_se(h.at_y[1].0, h.at_y[1].1, 3),
            value_se(h.at_y[2].0, h.at_y[2].1, 4),
            format!(
                "{} at {:.0} nm",
                value_se(h.k_over_s_max, h.k_over_s_max_se, 3),
                h.k_over_s_max_wavelength_nm
            ),
        ],
        None => std::array::from_fn(|_| "—".into()),
    }
}

/// Whether any variant has a contrast ratio (then the variants table has
/// the [`HIDING_HEAD`] columns).
pub fn any_hiding(p: &PageInput) -> bool {
    p.rows.iter().any(|r| r.hiding.is_some())
}

/// The sentence the variants table adds for its hiding columns.
pub const CR_TEXT: &str = " CR: contrast ratio Y(over black)/Y(over white) over a hiding chart; \
                           S, K: Kubelka's scattering and absorption coefficients per µm of \
                           layer from the luminance factors over black and white (exact \
                           hyperbolic solution); K/S max: the largest K/S over the solved \
                           wavelengths (a colour pigment's absorption maximum); each ± s.e., in \
                           d/8 SCI where measured.";

/// The sentence the effects table adds for its tinting strength column.
pub const TINT_TEXT: &str = " Tinting strength: 100 % × K/S of the step's second variant over \
                             K/S of its first, at the wavelength where the first's K/S is \
                             largest (its absorption maximum; d/8 SCI over the chart), ± s.e.";

/// Whether any effect has a tinting strength.
pub fn any_tint(effects: &[Effect]) -> bool {
    effects.iter().any(|e| e.tinting_strength.is_some())
}

/// The header cells of the effects table and each effect's cells.
pub fn effect_table(effects: &[Effect]) -> (Vec<&'static str>, Vec<Vec<String>>) {
    let tint = any_tint(effects);
    let mut head = vec![
        "axis",
        "step",
        "pairs",
        "direction",
        "ΔL*",
        "ΔC*ab",
        "Δh°",
        "ΔE00",
        "ΔE00 range",
    ];
    if tint {
        head.push("tinting strength (%)");
    }
    let rows = effects
        .iter()
        .map(|e| {
            let mut cells = vec![
                e.axis.clone(),
                format!("{} → {}", e.from, e.to),
                e.pairs.to_string(),
                e.direction(),
                fmt_mean_se(&e.delta_lch[0], true),
                fmt_mean_se(&e.delta_lch[1], true),
                fmt_mean_se(&e.delta_lch[2], true),
                fmt_mean_se(&e.delta_e00, false),
                format!("{:.2} – {:.2}", e.delta_e00_range.0, e.delta_e00_range.1),
            ];
            if tint {
                cells.push(match e.tinting_strength {
                    Some(t) => value_se(t.mean, t.se, 1),
                    None => "—".into(),
                });
            }
            cells
        })
        .collect();
    (head, rows)
}

fn tr(cells: &[String], tag: &str) -> String {
    let mut s = String::from("<tr>");
    for c in cells {
        let _ = write!(s, "<{tag}>{c}</{tag}>");
    }
    s + "</tr>\n"
}

/// The HTML page (the Markdown one is `markdown::page`, from the same
/// input).
/// The classical baselines' CIEDE2000 to the wave solution's colour, one
/// row per variant that carries any, one column per model, beside the wave
/// colour's own ΔE00 standard error: (head, rows), both empty when no
/// variant has a baseline.
pub(super) fn baseline_table(p: &PageInput) -> (Vec<String>, Vec<Vec<String>>) {
    let mut models: Vec<&str> = Vec::new();
    for r in p.rows {
        for b in &r.baseline {
            if !models.contains(&b.model.as_str()) {
                models.push(&b.model);
            }
        }
    }
    if models.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let axes: Vec<&str> = p.study.axes.iter().map(|a| a.name.as_str()).collect();
    let mut head: Vec<String> = vec!["variant".into()];
    head.extend(axes.iter().map(|a| a.to_string()));
    head.push("s.e. of the wave colour (ΔE00)".into());
    head.extend(models.iter().map(|m| format!("{m}: ΔE00 to wave")));
    let rows = p
        .rows
        .iter()
        .filter(|r| !r.baseline.is_empty())
        .map(|r| {
            let mut cells = vec![r.v.name.clone()];
            cells.extend(axes.iter().map(|a| r.v.label(a).unwrap_or("—").to_string()));
            let se = r.measured.as_ref().and_then(|m| m.record.de00_se);
            cells.push(se.map_or("—".into(), |x| format!("{x:.2}")));
            for m in &models {
                let de = r
                    .baseline
                    .iter()
                    .find(|b| b.model == *m)
                    .and_then(|b| b.de00_to_wave);
                cells.push(de.map_or("—".into(), |x| format!("{x:.2}")));
            }
            cells
        })
        .collect();
    (head, rows)
}

/// What the baseline table shows, in words (both pages).
pub(super) const BASELINE_TEXT: &str = "CIEDE2000 between each classical baseline's colour \
    (appearance.baseline: Kubelka–Munk, radiative transfer by adding–doubling; METHOD §6) and \
    the wave solution's, in the geometry of the effects table, per variant; beside it the wave \
    colour's own ΔE00 standard error, below which a disagreement is not resolved. Where a \
    baseline stays below 1, independent scattering suffices; where it does not, the grains' \
    coupling, the binder skin or the boundary matter (docs/VALIDATION.md).";

pub(super) fn html_page(p: &PageInput) -> String {
    let e = escape;
    let title = format!("Study {} — profile {}", p.study.name, p.profile());
    let mut body = format!("<h1>{}</h1>\n<table class=\"facts\">\n", e(&title));
    for (k, v) in p.facts() {
        body += &tr(&[e(&k), e(&v)], "td");
    }
    body += "</table>\n<p>Files: <a href=\"summary.h5\">summary.h5</a> (every variant \
             linked), <a href=\"summary.md\">summary.md</a>.</p>\n";
    body += &format!(
        "<h2>Effects</h2>\n<p>Each step an axis compares (its <code>compare</code> pairs, else each \
             label to the next): the \
             mean change of the measured colour over the pairs of variants that differ in that \
             axis only, ± the standard error of the mean from the variants' own standard \
             errors; the ΔE00 range over the pairs shows how much the effect depends on the \
             other axes.{}</p>\n",
        if any_tint(p.effects) { TINT_TEXT } else { "" }
    );
    let (head, rows) = effect_table(p.effects);
    if rows.is_empty() {
        body += "<p>No pairs of variants with measured colours.</p>\n";
    } else {
        body += "<table>\n";
        body += &tr(&head.iter().map(|h| e(h)).collect::<Vec<_>>(), "th");
        for r in rows {
            body += &tr(&r.iter().map(|c| e(c)).collect::<Vec<_>>(), "td");
        }
        body += "</table>\n";
    }
    let (bhead, brows) = baseline_table(p);
    if !brows.is_empty() {
        body += &format!(
            "<h2>Classical baselines</h2>\n<p>{}</p>\n<table>\n",
            e(BASELINE_TEXT)
        );
        body += &tr(&bhead.iter().map(|h| e(h)).collect::<Vec<_>>(), "th");
        for r in brows {
            body += &tr(&r.iter().map(|c| e(c)).collect::<Vec<_>>(), "td");
        }
        body += "</table>\n";
    }
    let figure = |f: &Path, caption: &str| {
        let r = e(&p.rel(f));
        format!(
            "<figure><a href=\"{r}\"><img src=\"{r}\" alt=\"{r}\"></a>\
             <figcaption>{caption}<a href=\"{r}\">{r}</a></figcaption></figure>\n"
        )
    };
    body += "<h2>Plots</h2>\n<div class=\"pics\">\n";
    for f in p.plots {
        body += &figure(f, "");
    }
    body += "</div>\n<h2>Comparison grids</h2>\n<p>Each grid of colours is followed by its \
             ΔE00 heat map: the CIEDE2000 difference of every cell to the grid's reference \
             cell ± its standard error, hatched and marked ≈ where it is within two standard \
             errors of 0 — differences an sRGB patch cannot show.</p>\n\
             <div class=\"pics wide\">\n";
    for (k, f) in p.grids.iter().enumerate() {
        body += &figure(f, "");
        if let Some(Some(m)) = p.grid_maps.get(k) {
            body += &figure(m, "ΔE00 to the reference cell: ");
        }
    }
    body += "</div>\n";
    body += &variants_html(p);
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width\"><title>{t}</title>\n<style>\
         body{{font-family:'DejaVu Sans',sans-serif;margin:1.5em;color:#222}}\
         table{{border-collapse:collapse;margin:0.5em 0}}\
         td,th{{border:1px solid #ccc;padding:2px 6px;text-align:left}}\
         .pics{{display:flex;flex-wrap:wrap;gap:12px}}\
         figure{{margin:0;flex:0 1 calc(50% - 8px);max-width:100%}}\
         .wide figure{{flex:0 1 auto}}\
         figure img{{max-width:100%;height:auto;border:1px solid #ddd}}\
         figcaption{{font-size:small;color:#555}}\
         .swatch{{display:inline-block;width:2em;height:1em;border:1px solid #888}}\
         </style></head><body>\n{body}</body></html>\n",
        t = e(&title)
    )
}

fn variants_html(p: &PageInput) -> String {
    let e = escape;
    let mut head: Vec<String> = vec!["#".into(), "name".into()];
    head.extend(p.columns().iter().map(|a| e(a)));
    let cr = any_hiding(p);
    for h in ["R", "T", "A", "L*", "C*ab", "h°", "colour"] {
        head.push(h.into());
    }
    if cr {
        head.extend(HIDING_HEAD.map(String::from));
    }
    head.push("files".into());
    let mut s = format!(
        "<h2>Variants</h2>\n<p>R, T, A: mean total reflectance, transmittance and absorption \
         over the solves from above (for a stack combined by adding, of the whole stack in air over its angles). L*, C*ab, h°: the measured colour ± s.e.; swatch: sRGB \
         under natural light at the first viewing angle.{}</p>\n<table>\n",
        if cr { CR_TEXT } else { "" }
    );
    s += &tr(&head, "th");
    for (i, r) in p.rows.iter().enumerate() {
        let mut cells = vec![(i + 1).to_string(), e(&r.v.name)];
        cells.extend(p.column_cells(r).iter().map(|c| e(c)));
        cells.extend([r.r, r.t, r.a].map(|x| format!("{x:.4}")));
        match colour_cells(r) {
            Some((lch, hex)) => {
                cells.extend(lch);
                cells.push(hex.map_or("—".into(), |h| {
                    format!("<span class=\"swatch\" style=\"background:{h}\"></span> {h}")
                }));
            }
            None => cells.extend(["—", "—", "—", "—"].map(String::from)),
        }
        if cr {
            cells.extend(hiding_cells(r));
        }
        cells.push(
            p.variant_files(r.v)
                .iter()
                .map(|(t, f)| format!("<a href=\"{}\">{}</a>", e(f), e(t)))
                .collect::<Vec<_>>()
                .join(" "),
        );
        s += &tr(&cells, "td");
    }
    s + "</table>\n"
}

/// A target uncertainty as written: 0.7, 1.7, 1.
fn fmt_target(v: f64) -> String {
    let t = format!("{v:.3}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_are_utc_civil_dates() {
        assert_eq!(utc_date(0), "1970-01-01 00:00 UTC");
        assert_eq!(utc_date(951_782_400), "2000-02-29 00:00 UTC");
        assert_eq!(utc_date(1_700_000_000), "2023-11-14 22:13 UTC");
    }

    #[test]
    fn means_with_and_without_errors() {
        let m = MeanSe {
            mean: 1.234,
            se: Some(0.056),
        };
        assert_eq!(fmt_mean_se(&m, true), "+1.23 ± 0.06");
        assert_eq!(
            fmt_mean_se(
                &MeanSe {
                    mean: 2.0,
                    se: None
                },
                false
            ),
            "2.00"
        );
    }
}
