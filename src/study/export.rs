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
//! the perfect diffuser = 100). A variant not finished has no rows; the
//! caller is told how many.

use super::run::{self, State};
use super::sweep::{Expansion, Study};
use super::StudyError;
use crate::optics::colour::lab_to_lch;
use crate::output::export::{num, Csv};
use crate::output::h5;

/// The table's text and the names of the variants not finished.
pub fn colours_csv(study: &Study, exp: &Expansion) -> Result<(String, Vec<String>), StudyError> {
    let mut header: Vec<&str> = vec!["variant"];
    header.extend(study.axes.iter().map(|a| a.name.as_str()));
    header.extend([
        "geometry",
        "illuminant",
        "observer_deg",
        "L_star",
        "a_star",
        "b_star",
        "C_star_ab",
        "h_deg",
        "L_star_se",
        "a_star_se",
        "b_star_se",
        "de00_se",
        "X",
        "Y",
        "Z",
    ]);
    let mut csv = Csv::new(&header);
    let mut missing = Vec::new();
    for v in &exp.variants {
        if run::state(v) != State::Done {
            missing.push(v.name.clone());
            continue;
        }
        let Some((records, illuminant, observer)) = h5::read_measured(&run::paths(v).0)? else {
            continue;
        };
        for r in records {
            let mut f = vec![v.name.clone()];
            f.extend(
                study
                    .axes
                    .iter()
                    .map(|a| v.label(&a.name).unwrap_or("").to_string()),
            );
            let lch = lab_to_lch(r.lab);
            f.extend([r.geometry.clone(), illuminant.clone(), observer.to_string()]);
            f.extend(r.lab.iter().map(|&x| num(x)));
            f.extend([num(lch[1]), num(lch[2])]);
            f.extend((0..3).map(|c| r.lab_se.map_or(String::new(), |s| num(s[c]))));
            f.push(r.de00_se.map_or(String::new(), num));
            f.extend(r.xyz.iter().map(|&x| num(x)));
            csv.row(f);
        }
    }
    Ok((csv.into_text(), missing))
}
