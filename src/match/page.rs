//! The match's page, `<name>.html`, and its spectra figure,
//! `<name>-spectra.png`: the target and the recipes side by side. Per
//! geometry a patch of the target's colour beside each recipe's (the fast
//! model's) and each verified recipe's wave colour, with CIELAB and ΔE00;
//! then the reflectance factors in the target's first geometry (the target's
//! spectrum where it has one). Patches are drawn in sRGB after gamut
//! mapping at constant L* and hue ([`map_lab`]); a patch that had to be
//! moved is marked, never clipped silently.

use crate::optics::colour::gamut::map_lab;
use crate::optics::colour::Observer;
use crate::output::html::escape as esc;
use crate::output::render::plot::{self, Panel, PanelSize, Point, Scale, Series};
use crate::output::render::RenderError;

use super::config::MatchSpec;
use super::report::MatchReport;

/// Size of the spectra panel's data area, pixels.
const PANEL: PanelSize = PanelSize { w: 560, h: 320 };

/// A volume fraction as the page prints it: four decimals, or three
/// significant digits below 0.001 (so a trace is not shown as 0.0000).
/// A recipe's unknowns as `name value, …` (HTML-escaped), for its column's
/// heading.
pub(crate) fn unknowns_html(unknowns: &[String], x: &[f64]) -> String {
    let parts: Vec<String> = unknowns
        .iter()
        .zip(x)
        .map(|(n, v)| format!("{} {}", esc(n), frac(*v)))
        .collect();
    parts.join(", ")
}

pub(crate) fn frac(v: f64) -> String {
    if v != 0.0 && v.abs() < 1e-3 {
        format!("{v:.2e}")
    } else {
        format!("{v:.4}")
    }
}

/// One table cell: a patch of `lab` and its numbers (and ΔE00 to the
/// target, when given).
pub(crate) fn patch(obs: &Observer, lab: [f64; 3], de00: Option<(f64, Option<f64>)>) -> String {
    let m = map_lab(obs, lab);
    let [r, g, b] = m.srgb8;
    let de = match de00 {
        Some((d, Some(se))) => format!("<br>ΔE00 {d:.2} ± {se:.2}"),
        Some((d, None)) => format!("<br>ΔE00 {d:.2}"),
        None => String::new(),
    };
    format!(
        "<td><div class=\"patch\" style=\"background:#{r:02x}{g:02x}{b:02x}\">{}</div>\
         L* {:.2} a* {:.2} b* {:.2}{de}</td>",
        if m.moved {
            "<span title=\"outside sRGB: drawn at the gamut's edge, same L* and hue\">*</span>"
        } else {
            ""
        },
        lab[0],
        lab[1],
        lab[2]
    )
}

/// The page's head, style and title for the match `name`.
pub(crate) fn head(name: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>match {0}</title>\n\
         <style>body{{font-family:sans-serif;margin:2em;max-width:110em}}\
         table{{border-collapse:collapse;font-size:90%}}td,th{{border:1px solid #bbb;\
         padding:4px 8px;vertical-align:top}}.patch{{width:7em;height:4em;margin-bottom:4px;\
         color:#fff;font-weight:bold}}img{{max-width:100%}}</style></head><body>\n\
         <h1>Match <code>{0}</code></h1>\n",
        esc(name)
    )
}

/// The page's HTML; `spectra` is the figure's file name beside it.
pub fn html(spec: &MatchSpec, r: &MatchReport, spectra: Option<&str>) -> String {
    let obs = Observer::standard(spec.target.illuminant, spec.target.observer);
    let conditions = format!(
        "{}, {}",
        spec.target.illuminant.name(),
        spec.target.observer.name()
    );
    let mut s = head(&spec.name);
    s += &format!(
        "<p>{}. Colours are CIELAB under {} (the target's \
         conditions); patches in sRGB, a <b>*</b> marks a colour outside the sRGB gamut drawn \
         at its edge with the same L* and hue. ΔE00 ± its standard error from the target's noise (the fast recipes) or from the realisations (the wave colours). Tolerance {} ΔE00; fast model {}; objective {}.</p>\n",
        if r.reached() {
            "The best recipe is within the tolerance on the fast model".to_string()
        } else {
            "No recipe is within the tolerance on the fast model: recipe 1 is the closest \
             reachable colour"
                .to_string()
        },
        esc(&conditions),
        spec.search.tolerance_de00,
        spec.model.name(),
        spec.search.objective.name()
    );
    s += "<h2>Target and recipes</h2>\n<table><tr><th>geometry</th><th>target</th>";
    for x in &r.recipes {
        s += &format!(
            "<th>recipe {} (fast model)<br><small>{}</small></th>",
            x.rank,
            unknowns_html(&x.unknowns, &x.candidate.x)
        );
    }
    for v in &r.verified {
        s += &format!(
            "<th>recipe {} verified (wave)<br><small>{}</small></th>",
            v.rank,
            v.composition(spec, &|n, f| format!("{} {}", esc(n), frac(f)))
        );
    }
    s += "</tr>\n";
    for (g, (m, target)) in r.target_lab.iter().enumerate() {
        s += &format!(
            "<tr><th>{}</th>{}",
            esc(m.name()),
            patch(&obs, *target, None)
        );
        for x in &r.recipes {
            s += &patch(
                &obs,
                x.candidate.fit.lab[g],
                Some((x.candidate.fit.de00[g], Some(x.de00_se[g]))),
            );
        }
        for v in &r.verified {
            let last = v.answer();
            s += &patch(&obs, last.lab[g], Some((last.de00[g], last.de00_se[g])));
        }
        s += "</tr>\n";
    }
    s += "</table>\n";
    if let Some(f) = &r.fidelity {
        s += &format!(
            "<h2>Verification by wave optics</h2>\n<p>Solved at the base scene's fidelity: {}.</p>\n<ul>\n",
            esc(f)
        );
        for v in &r.verified {
            s += &format!(
                "<li>recipe {}: {} steps; {}</li>\n",
                v.rank,
                v.steps.len(),
                esc(&v.outcome)
            );
        }
        s += "</ul>\n";
    }
    if let Some(f) = spectra {
        s += &format!(
            "<h2>Spectra</h2>\n<img src=\"{0}\" alt=\"reflectance factor of the target and the \
             recipes against wavelength\">\n",
            esc(f)
        );
    }
    s + "</body></html>\n"
}

/// The spectra figure: each recipe's reflectance factor on the fast model
/// and each verified recipe's wave spectrum in the target's first geometry,
/// beside the target's spectrum when it has one.
pub fn spectra_png(spec: &MatchSpec, r: &MatchReport) -> Result<Vec<u8>, RenderError> {
    let geometry = r.target_lab[0].0.name();
    let mut series = Vec::new();
    let line = |label: String, k: usize, dashed: bool, x: &[f64], y: &[f64]| Series {
        label,
        colour: plot::palette(k),
        dashed,
        points: x
            .iter()
            .zip(y)
            .map(|(&x, &y)| Point { x, y, se: None })
            .collect(),
    };
    if let Some(t) = &r.target_factor {
        series.push(line("target".into(), 6, false, &r.wavelengths_nm, t));
    }
    for (k, x) in r.recipes.iter().enumerate() {
        series.push(line(
            format!("recipe {} (fast model)", x.rank),
            k,
            true,
            &r.wavelengths_nm,
            &x.factor,
        ));
    }
    for (k, v) in r.verified.iter().enumerate() {
        let last = v.answer();
        series.push(line(
            format!("recipe {} verified (wave)", v.rank),
            k,
            false,
            &last.spectrum.0,
            &last.spectrum.1,
        ));
    }
    let x = Scale::covering_linear(r.wavelengths_nm.iter().map(|&w| (w, 0.0)), false)
        .ok_or(RenderError::Empty)?
        .padded(0.03);
    let y = Scale::covering_linear(series.iter().flat_map(|s| s.values()), true)
        .ok_or(RenderError::Empty)?;
    let panel = Panel {
        title: format!("reflectance factor, {geometry}"),
        x_label: "wavelength λ (nm)".into(),
        y_label: "reflectance factor (1)".into(),
        x,
        y,
        x_categories: None,
        series,
    };
    let legend = panel.legend();
    let notes = [format!(
        "Dashed: the fast model ({}){}{}.",
        spec.model.name(),
        if r.verified.is_empty() {
            ""
        } else {
            "; solid: the wave solution of a verified recipe (mean over its realisations)"
        },
        if r.target_factor.is_some() {
            "; black: the target's spectrum"
        } else {
            "; the target is CIELAB only (no spectrum)"
        }
    )];
    let img = plot::figure(
        &format!("{} — target and recipes", spec.name),
        &notes,
        &[panel],
        1,
        PANEL,
        &legend,
    )?;
    img.encode_png(&format!("{}: spectra", spec.name))
}
