//! `inksim export` of an effect paint's result: `<name>-multiangle.csv`,
//! one row per geometry — `geometry` (`45as15`: illumination 45°,
//! aspecular 15°), `illumination_deg`, `aspecular_deg`, the colour columns
//! of every export ([`COLOUR_COLUMNS`]: illuminant, observer, CIELAB, LCh,
//! empty standard errors — the fast model is deterministic — and XYZ) and
//! `flop_index` (the paint's, on every row); and with flakes
//! `<name>-sparkle.csv`, one row per illumination angle —
//! `illumination_deg`, `glints_per_mm2`, `glints_per_cell`,
//! `glint_reflectance`, `viewing_distance_mm`, `cell_area_mm2`,
//! `flakes_per_mm2`, `graininess`.

use std::path::Path;

use super::csv::{colour_fields, num, Csv, COLOUR_COLUMNS};
use super::error::IoError;
use super::h5::read_paint;

/// The CSV tables of a paint result: (file suffix, text).
pub fn paint_tables(path: &Path) -> Result<Vec<(&'static str, String)>, IoError> {
    let p = read_paint(path)?;
    let mut header = vec!["geometry", "illumination_deg", "aspecular_deg"];
    header.extend(COLOUR_COLUMNS);
    header.push("flop_index");
    let mut multiangle = Csv::new(&header);
    let flop = p.flop_index.map_or(String::new(), num);
    for c in &p.colours {
        let mut f = vec![c.label(), num(c.illumination_deg), num(c.aspecular_deg)];
        f.extend(colour_fields(
            &p.illuminant,
            &p.observer_deg.to_string(),
            c.lab,
            None,
            None,
            Some(c.xyz),
        ));
        f.push(flop.clone());
        multiangle.row(f);
    }
    let mut tables = vec![("multiangle", multiangle.into_text())];
    if let Some(s) = &p.sparkle {
        let mut sparkle = Csv::new(&[
            "illumination_deg",
            "glints_per_mm2",
            "glints_per_cell",
            "glint_reflectance",
            "viewing_distance_mm",
            "cell_area_mm2",
            "flakes_per_mm2",
            "graininess",
        ]);
        for r in &s.rows {
            sparkle.row(vec![
                num(r.illumination_deg),
                num(r.glints_per_mm2),
                num(r.glints_per_cell),
                num(r.glint_reflectance),
                num(s.viewing_distance_mm),
                num(s.cell_area_mm2),
                num(s.flakes_per_mm2),
                num(s.graininess),
            ]);
        }
        tables.push(("sparkle", sparkle.into_text()));
    }
    Ok(tables)
}
