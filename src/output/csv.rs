//! CSV tables as `inksim export` writes them: a header and rows, numbers
//! in their shortest round-trip form, the colour columns every export
//! shares.

use std::fmt::Write as _;

use crate::optics::colour::lab_to_lch;

/// A CSV table being written: a header, then rows.
pub struct Csv {
    text: String,
    columns: usize,
}

impl Csv {
    pub fn new(header: &[&str]) -> Csv {
        let mut c = Csv {
            text: String::new(),
            columns: header.len(),
        };
        c.row(header.iter().map(|h| h.to_string()).collect());
        c
    }

    /// Append a row of already formatted fields (quoted here if need be).
    pub fn row(&mut self, fields: Vec<String>) {
        debug_assert_eq!(fields.len(), self.columns);
        let line: Vec<String> = fields.into_iter().map(quoted).collect();
        let _ = writeln!(self.text, "{}", line.join(","));
    }

    pub fn into_text(self) -> String {
        self.text
    }
}

/// The columns of a colour, after those that say which colour it is.
pub const COLOUR_COLUMNS: [&str; 14] = [
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
];

/// The fields of [`COLOUR_COLUMNS`]: conditions, CIELAB and LCh, their
/// standard errors and XYZ (empty where absent).
pub fn colour_fields(
    illuminant: &str,
    observer_deg: &str,
    lab: [f64; 3],
    lab_se: Option<[f64; 3]>,
    de00_se: Option<f64>,
    xyz: Option<[f64; 3]>,
) -> Vec<String> {
    let lch = lab_to_lch(lab);
    let mut f = vec![illuminant.to_string(), observer_deg.to_string()];
    f.extend(lab.iter().map(|&v| num(v)));
    f.extend([num(lch[1]), num(lch[2])]);
    f.extend((0..3).map(|c| opt(lab_se.map(|s| s[c]))));
    f.push(opt(de00_se));
    f.extend((0..3).map(|c| opt(xyz.map(|x| x[c]))));
    f
}

/// A number as CSV: its shortest round-trip form (in exponent form when
/// very small or large), empty for NaN.
pub fn num(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else if x != 0.0 && !(1e-4..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

pub(super) fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), num)
}

fn quoted(s: String) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s
    }
}
