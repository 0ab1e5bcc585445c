//! `inksim export STUDY`: every finished variant's measured colours in one
//! CSV table, `<study dir>/colours.csv`, for a spreadsheet or a statistics
//! package.
//!
//! One row per variant and measurement geometry, in expansion order:
//! `variant`, one column per axis (the variant's label on it, empty when it
//! has none), `geometry` (`45/0`, `d/8 SCI`, `d/8 SCE`), `illuminant`,
//! `observer_deg`, CIELAB `L_star`, `a_star`, `b_star`, `C_star_ab`,
//! `h_deg`, their standard errors `L_star_se`, `a_star_se`, `b_star_se`
//! and `de00_se` (empty for one realisation), and CIE `X`, `Y`, `Z` (Y of
//! the perfect diffuser = 100). For each baseline model that any variant
//! carries (`appearance.baseline`), four more columns give its colour in
//! the same geometry, `<p>_L_star`, `<p>_a_star`, `<p>_b_star`, and
//! `<p>_de00_to_wave`, its CIEDE2000 to the wave colour (empty for a
//! variant without it). The prefix `<p>` is `km` (kubelka-munk),
//! `km_scene` (kubelka-munk-scene), `ad` (adding-doubling) or `ad_contact`
//! (adding-doubling-contact); the models come in the order of
//! `Baseline::ALL`. A variant not finished has no rows; the caller is told
//! how many.

use super::run::{self, State};
use super::sweep::{Expansion, Study};
use super::StudyError;
use crate::config::Baseline;
use crate::output::export::{colour_fields, num, Csv, COLOUR_COLUMNS};
use crate::output::h5;

/// A model's columns after its prefix.
const BASELINE_COLUMNS: [&str; 4] = ["L_star", "a_star", "b_star", "de00_to_wave"];

/// Column prefix of a model's name as stored (the name itself, with `_`
/// for `-`, for a model this build does not know).
fn prefix(model: &str) -> String {
    Baseline::from_name(model)
        .map(|b| b.column_prefix().to_string())
        .unwrap_or_else(|| model.replace('-', "_"))
}

/// The table's text and the names of the variants not finished.
pub fn colours_csv(study: &Study, exp: &Expansion) -> Result<(String, Vec<String>), StudyError> {
    let mut rows: Vec<(Vec<String>, Vec<h5::BaselineRecord>)> = Vec::new();
    let mut missing = Vec::new();
    for v in &exp.variants {
        if run::state(v) != State::Done {
            missing.push(v.name.clone());
            continue;
        }
        let path = run::paths(v).0;
        let Some((records, illuminant, observer)) = h5::read_measured(&path)? else {
            continue;
        };
        let baseline = h5::read_baseline(&path)?;
        for r in records {
            let mut f = vec![v.name.clone()];
            f.extend(
                study
                    .axes
                    .iter()
                    .map(|a| v.label(&a.name).unwrap_or("").to_string()),
            );
            f.push(r.geometry.clone());
            f.extend(colour_fields(
                &illuminant,
                &observer.to_string(),
                r.lab,
                r.lab_se,
                r.de00_se,
                Some(r.xyz),
            ));
            let here = baseline
                .iter()
                .filter(|b| b.geometry == r.geometry)
                .cloned()
                .collect();
            rows.push((f, here));
        }
    }
    // The models present, known ones in their documented order.
    let mut models: Vec<String> = Vec::new();
    for (_, records) in &rows {
        for b in records {
            if !models.contains(&b.model) {
                models.push(b.model.clone());
            }
        }
    }
    let rank = |m: &String| {
        Baseline::from_name(m)
            .and_then(|b| Baseline::ALL.iter().position(|a| *a == b))
            .unwrap_or(usize::MAX)
    };
    models.sort_by_key(rank);
    let names: Vec<String> = models
        .iter()
        .flat_map(|m| {
            let p = prefix(m);
            BASELINE_COLUMNS.iter().map(move |c| format!("{p}_{c}"))
        })
        .collect();
    let mut header: Vec<&str> = vec!["variant"];
    header.extend(study.axes.iter().map(|a| a.name.as_str()));
    header.push("geometry");
    header.extend(COLOUR_COLUMNS);
    header.extend(names.iter().map(String::as_str));
    let mut csv = Csv::new(&header);
    for (mut f, records) in rows {
        for m in &models {
            match records.iter().find(|b| &b.model == m) {
                Some(b) => {
                    f.extend(b.lab.iter().map(|&x| num(x)));
                    f.push(b.de00_to_wave.map_or(String::new(), num));
                }
                None => f.extend(std::iter::repeat_n(String::new(), BASELINE_COLUMNS.len())),
            }
        }
        csv.row(f);
    }
    Ok((csv.into_text(), missing))
}
