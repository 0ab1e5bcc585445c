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
//! the perfect diffuser = 100). Where any variant carries the
//! Kubelka–Munk baseline (`appearance.baseline`), four more columns give
//! its colour in the same geometry, `km_L_star`, `km_a_star`, `km_b_star`,
//! and `km_de00_to_wave`, its CIEDE2000 to the wave colour (empty for a
//! variant without it). A variant not finished has no rows; the caller is
//! told how many.

use super::run::{self, State};
use super::sweep::{Expansion, Study};
use super::StudyError;
use crate::output::export::{colour_fields, num, Csv, COLOUR_COLUMNS};
use crate::output::h5;

/// The baseline's columns, when a variant has it.
const BASELINE_COLUMNS: [&str; 4] = ["km_L_star", "km_a_star", "km_b_star", "km_de00_to_wave"];

/// The table's text and the names of the variants not finished.
pub fn colours_csv(study: &Study, exp: &Expansion) -> Result<(String, Vec<String>), StudyError> {
    let mut rows: Vec<(Vec<String>, Option<h5::BaselineRecord>)> = Vec::new();
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
            let km = baseline.iter().find(|b| b.geometry == r.geometry).cloned();
            rows.push((f, km));
        }
    }
    let with_baseline = rows.iter().any(|(_, km)| km.is_some());
    let mut header: Vec<&str> = vec!["variant"];
    header.extend(study.axes.iter().map(|a| a.name.as_str()));
    header.push("geometry");
    header.extend(COLOUR_COLUMNS);
    if with_baseline {
        header.extend(BASELINE_COLUMNS);
    }
    let mut csv = Csv::new(&header);
    for (mut f, km) in rows {
        if with_baseline {
            match km {
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
