//! The typed half of `summary.h5`: each axis's settings as numbers, and
//! every variant's measured colours (XYZ, CIELAB, LCh and their standard
//! errors) per geometry, so the study's numbers can be analysed without
//! opening the variant files (layout: docs/FORMAT.md).

use super::Row;
use crate::config::Measurement;
use crate::optics::colour;
use crate::output::h5::{self, about, dim, MeasuredRecord, Scales};
use crate::study::run;
use crate::study::sweep::Study;
use crate::study::StudyError;
use hdf5::types::VarLenUnicode;
use ndarray::{Array1, Array2};
use std::collections::BTreeMap;
use toml::Value;

/// `values/<axis>/<key>`: for every key an axis sets to a number (integer
/// or float) in all of its values, that number per variant (NaN for a
/// variant without a label on the axis). Keys set to anything else (tables,
/// strings) are described by the axis's labels (`labels/<axis>`).
pub(super) fn write_axis_values(
    f: &hdf5::File,
    study: &Study,
    rows: &[Row],
    scales: &Scales,
) -> hdf5::Result<()> {
    let g = f.create_group("values")?;
    for axis in &study.axes {
        // key → label → number, kept only when every value sets it to one.
        let mut keys: BTreeMap<&str, BTreeMap<&str, f64>> = BTreeMap::new();
        for v in &axis.values {
            for o in &v.set {
                let x = match &o.value {
                    Value::Integer(i) => Some(*i as f64),
                    Value::Float(x) => Some(*x),
                    _ => None,
                };
                if let Some(x) = x {
                    keys.entry(o.key.as_str())
                        .or_default()
                        .insert(v.label.as_str(), x);
                }
            }
        }
        keys.retain(|_, by_label| by_label.len() == axis.values.len());
        if keys.is_empty() {
            continue;
        }
        let ag = g.create_group(&axis.name)?;
        for (key, by_label) in keys {
            let col: Array1<f64> = rows
                .iter()
                .map(|r| {
                    r.v.label(&axis.name)
                        .and_then(|l| by_label.get(l).copied())
                        .unwrap_or(f64::NAN)
                })
                .collect();
            let description = format!(
                "the value of `{key}` that axis `{}` sets, per variant (NaN: not on this \
                 axis); variant",
                axis.name
            );
            let a = about(units_of_key(key), &description, &[dim::VARIANT]);
            scales.write(&ag, key, &col, a)?;
        }
    }
    Ok(())
}

/// Units of a scene key's number: scene keys name them by suffix (`_nm`,
/// `_nm3`, `_deg`); a key without one is a plain number.
fn units_of_key(key: &str) -> &'static str {
    let last = key.rsplit('.').next().unwrap_or(key);
    [("_nm", "nm"), ("_nm3", "nm3"), ("_deg", "deg")]
        .into_iter()
        .find(|(suffix, _)| last.ends_with(suffix))
        .map_or("1", |(_, units)| units)
}

/// `colour/<geometry>/{xyz, lab, lch, lab_se, de00_se}` (n × 3, n): each
/// variant's measured colour (NaN where a variant has none, or a standard
/// error where it has one realisation of a random layer; 0 for a layer with
/// nothing random), with the illuminant and observer as
/// attributes of `colour`.
pub(super) fn write_colours(
    f: &hdf5::File,
    rows: &[Row],
    scales: &Scales,
) -> Result<(), StudyError> {
    let n = rows.len();
    let mut per_variant: Vec<Vec<MeasuredRecord>> = Vec::with_capacity(n);
    let mut conditions: Option<(String, u32)> = None;
    for r in rows {
        let path = run::paths(r.v).0;
        match h5::read_measured(&path)? {
            Some((records, illuminant, observer)) => {
                conditions.get_or_insert((illuminant, observer));
                per_variant.push(records);
            }
            None => per_variant.push(Vec::new()),
        }
    }
    let h = |source| StudyError::Hdf5 {
        path: f.filename().into(),
        source,
    };
    let g = f.create_group("colour").map_err(h)?;
    if let Some((illuminant, observer)) = &conditions {
        let ill: VarLenUnicode = illuminant.parse().expect("no NUL");
        g.new_attr::<VarLenUnicode>()
            .shape(())
            .create("illuminant")
            .and_then(|a| a.write_scalar(&ill))
            .map_err(h)?;
        g.new_attr::<u32>()
            .shape(())
            .create("observer_deg")
            .and_then(|a| a.write_scalar(observer))
            .map_err(h)?;
    }
    for m in Measurement::ALL {
        let find = |rs: &[MeasuredRecord]| rs.iter().find(|x| x.geometry == m.name()).cloned();
        let found: Vec<Option<MeasuredRecord>> = per_variant.iter().map(|rs| find(rs)).collect();
        if found.iter().all(Option::is_none) {
            continue;
        }
        let nan3 = [f64::NAN; 3];
        let three = |pick: &dyn Fn(&MeasuredRecord) -> [f64; 3]| {
            Array2::from_shape_fn((n, 3), |(i, c)| found[i].as_ref().map_or(nan3, pick)[c])
        };
        let mg = g.create_group(m.slug()).map_err(h)?;
        let sets: [(&str, Array2<f64>, &str, &str, &str); 4] = [
            (
                "xyz",
                three(&|x| x.xyz),
                "1",
                "CIE XYZ, Y of the perfect diffuser = 100; variant × X, Y, Z",
                dim::TRISTIMULUS,
            ),
            (
                "lab",
                three(&|x| x.lab),
                "1",
                "CIELAB L*, a*, b*; variant × L*, a*, b*",
                dim::LAB,
            ),
            (
                "lch",
                three(&|x| colour::lab_to_lch(x.lab)),
                "1, 1, deg",
                "L*, C*ab, hab (degrees); variant × L*, C*ab, hab",
                dim::LCH,
            ),
            (
                "lab_se",
                three(&|x| x.lab_se.unwrap_or(nan3)),
                "1",
                "standard errors of L*, a*, b* over the realisations (0: nothing random in the \
                 layer; NaN: one realisation of a random layer); variant × L*, a*, b*",
                dim::LAB,
            ),
        ];
        for (name, data, units, description, d) in sets {
            let dims = [dim::VARIANT, d];
            let a = about(units, description, &dims);
            scales.write(&mg, name, &data, a).map_err(h)?;
        }
        let de: Array1<f64> = found
            .iter()
            .map(|x| x.as_ref().and_then(|x| x.de00_se).unwrap_or(f64::NAN))
            .collect();
        let description = "standard error of each variant's colour in ΔE00 over the \
                           realisations (NaN: none); variant";
        let a = about("1", description, &[dim::VARIANT]);
        scales.write(&mg, "de00_se", &de, a).map_err(h)?;
    }
    Ok(())
}

/// `hiding/{contrast_ratio, s_y_per_um, k_y_per_um}` and their `_se` (n):
/// each variant's contrast ratio and Kubelka's S and K at Y over a hiding
/// chart (NaN for a variant without a chart, or a standard error with one
/// realisation of a random layer), in the geometry named by the attribute
/// `geometry` of each variant (`geometry`, labels); nothing when no variant
/// has a chart.
pub(super) fn write_hiding(f: &hdf5::File, rows: &[Row], scales: &Scales) -> hdf5::Result<()> {
    if rows.iter().all(|r| r.hiding.is_none()) {
        return Ok(());
    }
    let g = f.create_group("hiding")?;
    let col = |pick: &dyn Fn(&h5::HidingRecord) -> Option<f64>| -> Array1<f64> {
        rows.iter()
            .map(|r| r.hiding.as_ref().and_then(pick).unwrap_or(f64::NAN))
            .collect()
    };
    let sets: [(&str, Array1<f64>, &str, &str); 6] = [
        (
            "contrast_ratio",
            col(&|h| Some(h.contrast_ratio)),
            "1",
            "contrast ratio Y(over black)/Y(over white) over the hiding chart; variant",
        ),
        (
            "contrast_ratio_se",
            col(&|h| h.contrast_ratio_se),
            "1",
            "standard error of the contrast ratio over the realisations; variant",
        ),
        (
            "s_y_per_um",
            col(&|h| Some(h.at_y[1].0)),
            "um-1",
            "Kubelka's scattering coefficient S from the luminance factors; variant",
        ),
        (
            "s_y_per_um_se",
            col(&|h| h.at_y[1].1),
            "um-1",
            "standard error of S over the realisations; variant",
        ),
        (
            "k_y_per_um",
            col(&|h| Some(h.at_y[2].0)),
            "um-1",
            "Kubelka's absorption coefficient K from the luminance factors; variant",
        ),
        (
            "k_y_per_um_se",
            col(&|h| h.at_y[2].1),
            "um-1",
            "standard error of K over the realisations; variant",
        ),
    ];
    for (name, data, units, description) in sets {
        scales.write(&g, name, &data, about(units, description, &[dim::VARIANT]))?;
    }
    let geometry: Vec<VarLenUnicode> = rows
        .iter()
        .map(|r| {
            r.hiding
                .as_ref()
                .map_or("", |h| h.geometry.as_str())
                .parse()
                .expect("no NUL")
        })
        .collect();
    let description = "the measurement geometry of each variant's hiding values (\"\": no \
                       chart; labels, no units); variant";
    scales.write(
        &g,
        "geometry",
        &geometry[..],
        about("", description, &[dim::VARIANT]),
    )?;
    Ok(())
}
