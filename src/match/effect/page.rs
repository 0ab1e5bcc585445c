//! An effect match's page, `<name>.html`: per target geometry (one row
//! each, `45as15` …) a patch of the target's colour beside each recipe's,
//! with CIELAB and ΔE00 ± its standard error, then the flop index of the
//! target and of each recipe. The patches are the scene match's own
//! ([`super::super::page::patch`]: sRGB after gamut mapping at constant L*
//! and hue, a moved patch marked).

use crate::optics::colour::Observer;
use crate::output::html::escape as esc;

use super::super::page::{head, patch, unknowns_html};
use super::config::EffectSpec;
use super::report::EffectReport;

fn flop(v: Option<f64>) -> String {
    v.map_or("not defined".into(), |f| format!("{f:.2}"))
}

/// The page's HTML.
pub fn html(spec: &EffectSpec, r: &EffectReport) -> String {
    let obs = Observer::standard(spec.target.illuminant, spec.target.observer);
    let mut s = head(&spec.name);
    s += &format!(
        "<p>{}. An effect paint's multi-angle colours: per geometry the illumination angle \
         and the aspecular angle of the view (<code>45as15</code>: 45° illumination, 15° from \
         the mirror direction). Colours are CIELAB under {}, {} (the target's conditions); \
         patches in sRGB, a <b>*</b> marks a colour outside the sRGB gamut drawn at its edge \
         with the same L* and hue (a metallic's near-specular L* above 100 is drawn white). \
         ΔE00 ± its standard error from the target's noise. Tolerance {} ΔE00; fast flake \
         model.</p>\n",
        if r.reached() {
            "The best recipe is within the tolerance in every geometry"
        } else {
            "No recipe is within the tolerance: recipe 1 is the closest reachable colour"
        },
        esc(spec.target.illuminant.name()),
        esc(spec.target.observer.name()),
        spec.search.tolerance_de00
    );
    s += "<h2>Target and recipes</h2>\n<table><tr><th>geometry</th><th>target</th>";
    for x in &r.recipes {
        s += &format!(
            "<th>recipe {}<br><small>{}</small></th>",
            x.rank,
            unknowns_html(&x.unknowns, &x.candidate.x)
        );
    }
    s += "</tr>\n";
    for (g, (geometry, target)) in r.target.iter().enumerate() {
        s += &format!(
            "<tr><th>{}</th>{}",
            esc(&geometry.label()),
            patch(&obs, *target, None)
        );
        for x in &r.recipes {
            s += &patch(
                &obs,
                x.candidate.fit.lab[g],
                Some((x.candidate.fit.de00[g], Some(x.de00_se[g]))),
            );
        }
        s += "</tr>\n";
    }
    s += &format!(
        "<tr><th>flop index</th><td>{}</td>",
        flop(r.target_flop_index)
    );
    for x in &r.recipes {
        s += &format!("<td>{}</td>", flop(x.flop_index));
    }
    s += "</tr>\n</table>\n";
    let flagged: Vec<String> = r
        .recipes
        .iter()
        .flat_map(|x| {
            x.not_determined()
                .into_iter()
                .map(move |f| format!("<li>recipe {}: {}</li>", x.rank, esc(&f)))
        })
        .collect();
    if !flagged.is_empty() {
        s += &format!(
            "<h2>Not determined by the target</h2>\n<ul>\n{}\n</ul>\n",
            flagged.join("\n")
        );
    }
    s + "</body></html>\n"
}
