//! `inksim export`: a result file's numbers as CSV tables, for a
//! spreadsheet or any tool without HDF5.
//!
//! From `<name>.h5` (each only when the result has what it holds):
//! - `<name>-solves.csv`: every solve, one row each — `side` (`above`, the
//!   ink side; `below`, the layer flipped for the paper term),
//!   `realisation`, `wavelength_nm`, `polar_deg`, `azimuth_deg`,
//!   `reflectance`, `transmittance`, `absorption` (fractions of the
//!   incident power), `energy_balance`, `method`, `iterations`, `residual`;
//! - `<name>-spectra.csv` (with appearance products): the ensemble means
//!   from above per wavelength and polar angle, `reflectance`,
//!   `transmittance`, `absorption` and their standard errors `*_se`
//!   (empty for one realisation);
//! - `<name>-colours.csv` (with the tile): one row per colour —
//!   `geometry` (`45/0`, `d/8 SCI`, `d/8 SCE` for the measurement
//!   geometries; `sky`, the tile's strip under a uniform white sky, and
//!   `brdf`, its square lit from `illumination_deg`, per `viewing_deg`),
//!   `illuminant`, `observer_deg`, CIELAB `L_star`, `a_star`, `b_star`,
//!   `C_star_ab`, `h_deg`, their standard errors `L_star_se`, `a_star_se`,
//!   `b_star_se` and `de00_se` (empty for one realisation), and CIE `X`,
//!   `Y`, `Z` (Y of the perfect diffuser = 100; measurement geometries only);
//! - `<name>-baseline.csv` (with `appearance.baseline`): per baseline
//!   model (in the scene's order) and measurement geometry the `model`
//!   (`kubelka-munk`, `adding-doubling`, …), `geometry`, `illuminant`,
//!   `observer_deg`, `L_star`, `a_star`, `b_star`, `C_star_ab`, `h_deg` and
//!   `de00_to_wave`, its CIEDE2000 to the wave colour of that geometry.
//! - over a hiding chart (`substrate.kind = "chart"`): `<name>-colours.csv`
//!   also has the colours over the black half (`geometry` `45/0 over
//!   black`, …; the plain rows are over the white half), and
//!   `<name>-hiding.csv` one row per measurement geometry from the
//!   luminance factors (`wavelength_nm` empty) and one per solved
//!   wavelength: `geometry`, `wavelength_nm`, `illuminant`,
//!   `observer_deg`, `contrast_ratio` and `contrast_ratio_se` (Y rows),
//!   `y_black`, `y_white`, `y_ground` (Y rows), Kubelka's `r_inf`,
//!   `s_per_um`, `k_per_um` (1/µm), `k_over_s`, each with its `*_se`
//!   (empty for one realisation of a random layer).
//!
//! - an effect paint's result: `<name>-multiangle.csv` and
//!   `<name>-sparkle.csv` ([`super::export_paint`]).
//!
//! Numbers are written in the shortest form that reads back to the same
//! f64; a text field with a comma or a quote is quoted.

use std::path::Path;

use super::error::IoError;
use super::h5::{
    read_appearance, read_baseline, read_hiding, read_measured, read_measured_black, read_optional,
    read_summary,
};
use crate::optics::farfield::Side;

use super::csv::opt;
pub use super::csv::{colour_fields, num, Csv, COLOUR_COLUMNS};

/// The CSV tables of the result file `path`: (file suffix, text), in the
/// order of the module docs.
pub fn result_tables(path: &Path) -> Result<Vec<(&'static str, String)>, IoError> {
    if path.is_file() && super::h5::is_paint_result(path)? {
        return super::export_paint::paint_tables(path);
    }
    let summary = read_summary(path)?;
    let mut solves = Csv::new(&[
        "side",
        "realisation",
        "wavelength_nm",
        "polar_deg",
        "azimuth_deg",
        "reflectance",
        "transmittance",
        "absorption",
        "energy_balance",
        "method",
        "iterations",
        "residual",
    ]);
    for e in &summary.entries {
        solves.row(vec![
            match e.side {
                Side::Above => "above",
                Side::Below => "below",
            }
            .into(),
            e.realisation.to_string(),
            num(e.wavelength_nm),
            num(e.polar_deg),
            num(e.azimuth_deg),
            num(e.total_reflectance),
            num(e.total_transmittance),
            num(e.absorption),
            num(e.energy_balance),
            e.method.to_string(),
            e.iterations.to_string(),
            num(e.residual),
        ]);
    }
    let mut tables = vec![("solves", solves.into_text())];
    let Some(a) = read_appearance(path)? else {
        // A stack solved layer by layer: its measured colours alone.
        if let Some((records, ill, obs)) = read_measured(path)? {
            let mut header = vec!["geometry", "viewing_deg", "illumination_deg"];
            header.extend(COLOUR_COLUMNS);
            let mut colours = Csv::new(&header);
            for r in records {
                let mut f = vec![r.geometry.clone(), String::new(), String::new()];
                f.extend(colour_fields(
                    &ill,
                    &obs.to_string(),
                    r.lab,
                    r.lab_se,
                    r.de00_se,
                    Some(r.xyz),
                ));
                colours.row(f);
            }
            tables.push(("colours", colours.into_text()));
        }
        return Ok(tables);
    };
    let extra = Extra::read(path)?;
    let mut spectra = Csv::new(&[
        "wavelength_nm",
        "polar_deg",
        "reflectance",
        "reflectance_se",
        "transmittance",
        "transmittance_se",
        "absorption",
        "absorption_se",
    ]);
    let se =
        |s: &Option<ndarray::Array2<f64>>, l: usize, k: usize| opt(s.as_ref().map(|s| s[[l, k]]));
    for (l, &wl) in a.wavelengths_nm.iter().enumerate() {
        for (k, &polar) in a.above_deg.iter().enumerate() {
            spectra.row(vec![
                num(wl),
                num(polar),
                num(a.reflectance[[l, k]]),
                se(&extra.reflectance_se, l, k),
                num(a.transmittance[[l, k]]),
                se(&extra.transmittance_se, l, k),
                num(a.absorption[[l, k]]),
                se(&extra.absorption_se, l, k),
            ]);
        }
    }
    tables.push(("spectra", spectra.into_text()));
    let Some(tile) = &a.tile_lab else {
        return Ok(tables);
    };
    let mut header = vec!["geometry", "viewing_deg", "illumination_deg"];
    header.extend(COLOUR_COLUMNS);
    let mut colours = Csv::new(&header);
    let (ill, obs) = extra.conditions.clone().unwrap_or_default();
    let lab_row = |geometry: &str,
                   view: String,
                   illum: String,
                   lab: [f64; 3],
                   lab_se: Option<[f64; 3]>,
                   de00_se: Option<f64>,
                   xyz: Option<[f64; 3]>| {
        let mut f = vec![geometry.to_string(), view, illum];
        f.extend(colour_fields(&ill, &obs, lab, lab_se, de00_se, xyz));
        f
    };
    if let Some((records, _, _)) = read_measured(path)? {
        for r in records {
            colours.row(lab_row(
                &r.geometry,
                String::new(),
                String::new(),
                r.lab,
                r.lab_se,
                r.de00_se,
                Some(r.xyz),
            ));
        }
    }
    if let Some((records, _, _)) = read_measured_black(path)? {
        for r in records {
            colours.row(lab_row(
                &format!("{} over black", r.geometry),
                String::new(),
                String::new(),
                r.lab,
                r.lab_se,
                r.de00_se,
                Some(r.xyz),
            ));
        }
    }
    for (o, &view) in a.viewing_deg.iter().enumerate() {
        for c in 0..tile.dim().1 {
            let at = |t: &ndarray::Array3<f64>| [t[[o, c, 0]], t[[o, c, 1]], t[[o, c, 2]]];
            let (geometry, illum) = match c {
                0 => ("sky", String::new()),
                _ => ("brdf", num(a.illumination_deg[c - 1])),
            };
            colours.row(lab_row(
                geometry,
                num(view),
                illum,
                at(tile),
                extra.tile_lab_se.as_ref().map(at),
                extra.tile_de00_se.as_ref().map(|s| s[[o, c]]),
                None,
            ));
        }
    }
    tables.push(("colours", colours.into_text()));
    let hiding = read_hiding(path)?;
    if !hiding.is_empty() {
        let mut t = Csv::new(&[
            "geometry",
            "wavelength_nm",
            "illuminant",
            "observer_deg",
            "contrast_ratio",
            "contrast_ratio_se",
            "y_black",
            "y_white",
            "y_ground",
            "r_inf",
            "r_inf_se",
            "s_per_um",
            "s_per_um_se",
            "k_per_um",
            "k_per_um_se",
            "k_over_s",
            "k_over_s_se",
        ]);
        for h in &hiding {
            let mut f = vec![
                h.geometry.clone(),
                String::new(),
                ill.clone(),
                obs.clone(),
                num(h.contrast_ratio),
                opt(h.contrast_ratio_se),
                num(h.y_black),
                num(h.y_white),
                num(h.y_ground),
            ];
            for (v, se) in h.at_y {
                f.push(num(v));
                f.push(opt(se));
            }
            t.row(f);
            for (l, &wl) in a.wavelengths_nm.iter().enumerate() {
                let mut f = vec![h.geometry.clone(), num(wl), ill.clone(), obs.clone()];
                f.extend(std::iter::repeat_n(String::new(), 5));
                for (v, se) in &h.spectral {
                    f.push(v.get(l).map_or_else(String::new, |x| num(*x)));
                    f.push(opt(se.as_ref().and_then(|s| s.get(l).copied())));
                }
                t.row(f);
            }
        }
        tables.push(("hiding", t.into_text()));
    }
    let baseline = read_baseline(path)?;
    if !baseline.is_empty() {
        let mut header = vec!["model", "geometry"];
        header.extend(&COLOUR_COLUMNS[..7]);
        header.push("de00_to_wave");
        let mut km = Csv::new(&header);
        for b in baseline {
            let mut f = vec![b.model.clone(), b.geometry.clone()];
            f.extend(
                colour_fields(&ill, &obs, b.lab, None, None, None)
                    .into_iter()
                    .take(7),
            );
            f.push(opt(b.de00_to_wave));
            km.row(f);
        }
        tables.push(("baseline", km.into_text()));
    }
    Ok(tables)
}

/// What [`read_appearance`] does not read: standard errors and the colour
/// conditions.
struct Extra {
    reflectance_se: Option<ndarray::Array2<f64>>,
    transmittance_se: Option<ndarray::Array2<f64>>,
    absorption_se: Option<ndarray::Array2<f64>>,
    tile_lab_se: Option<ndarray::Array3<f64>>,
    tile_de00_se: Option<ndarray::Array2<f64>>,
    /// (illuminant, observer degrees) as written.
    conditions: Option<(String, String)>,
}

impl Extra {
    fn read(path: &Path) -> Result<Extra, IoError> {
        let hdf = |source| IoError::Hdf5 {
            path: path.to_path_buf(),
            source,
        };
        let g = crate::output::h5::open(path)
            .and_then(|f| f.group("appearance"))
            .map_err(hdf)?;
        let two = |name: &str| read_optional::<f64, ndarray::Ix2>(&g, name).map_err(hdf);
        let conditions = match (g.attr("illuminant"), g.attr("observer_deg")) {
            (Ok(i), Ok(o)) => {
                let ill: hdf5::types::VarLenUnicode = i.read_scalar().map_err(hdf)?;
                let obs: u32 = o.read_scalar().map_err(hdf)?;
                Some((ill.to_string(), obs.to_string()))
            }
            _ => None,
        };
        Ok(Extra {
            reflectance_se: two("reflectance_se")?,
            transmittance_se: two("transmittance_se")?,
            absorption_se: two("absorption_se")?,
            tile_lab_se: read_optional(&g, "tile_lab_se").map_err(hdf)?,
            tile_de00_se: two("tile_de00_se")?,
            conditions,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_quoted_only_when_they_must_be_and_numbers_read_back() {
        let mut c = Csv::new(&["a", "b"]);
        c.row(vec!["d/8 SCI".into(), "x,y".into()]);
        c.row(vec!["say \"hi\"".into(), num(0.1 + 0.2)]);
        c.row(vec![num(f64::NAN), opt(None)]);
        c.row(vec![num(2.4e-9), num(-0.0)]);
        let t = c.into_text();
        assert_eq!(
            t,
            "a,b\nd/8 SCI,\"x,y\"\n\"say \"\"hi\"\"\",0.30000000000000004\n,\n2.4e-9,-0\n"
        );
        assert_eq!("0.30000000000000004".parse::<f64>().unwrap(), 0.1 + 0.2);
        for x in [2.4e-9, 1.0 / 3.0, 1e300, -7.25e-12, 123456.0] {
            assert_eq!(num(x).parse::<f64>().unwrap(), x);
        }
    }
}
