//! The typed half of `summary.h5`: each axis's settings as numbers, and
//! every variant's measured colours (XYZ, CIELAB, LCh and their standard
//! errors) per geometry, so the study's numbers can be analysed without
//! opening the variant files (layout in the [merge module docs](super)).

use super::Row;
use crate::config::Measurement;
use crate::optics::colour;
use crate::output::h5::{self, MeasuredRecord};
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
pub(super) fn write_axis_values(f: &hdf5::File, study: &Study, rows: &[Row]) -> hdf5::Result<()> {
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
            let d = ag.new_dataset_builder().with_data(&col).create(key)?;
            let text: VarLenUnicode = format!(
                "the value of `{key}` that axis `{}` sets, per variant (NaN: not on this axis)",
                axis.name
            )
            .parse()
            .expect("no NUL");
            d.new_attr::<VarLenUnicode>()
                .shape(())
                .create("description")?
                .write_scalar(&text)?;
        }
    }
    Ok(())
}

/// `colour/<geometry>/{xyz, lab, lch, lab_se, de00_se}` (n × 3, n): each
/// variant's measured colour (NaN where a variant has none, or a standard
/// error where it has one realisation of a random layer; 0 for a layer with
/// nothing random), with the illuminant and observer as
/// attributes of `colour`.
pub(super) fn write_colours(f: &hdf5::File, rows: &[Row]) -> Result<(), StudyError> {
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
        let sets: [(&str, Array2<f64>, &str); 4] = [
            (
                "xyz",
                three(&|x| x.xyz),
                "CIE XYZ, Y of the perfect diffuser = 100",
            ),
            ("lab", three(&|x| x.lab), "CIELAB L*, a*, b*"),
            (
                "lch",
                three(&|x| colour::lab_to_lch(x.lab)),
                "L*, C*ab, hab (degrees)",
            ),
            (
                "lab_se",
                three(&|x| x.lab_se.unwrap_or(nan3)),
                "standard errors of L*, a*, b* over the realisations (0: nothing random in the layer; NaN: one realisation of a random layer)",
            ),
        ];
        for (name, data, description) in sets {
            let d = mg
                .new_dataset_builder()
                .with_data(&data)
                .create(name)
                .map_err(h)?;
            let text: VarLenUnicode = description.parse().expect("no NUL");
            d.new_attr::<VarLenUnicode>()
                .shape(())
                .create("description")
                .and_then(|a| a.write_scalar(&text))
                .map_err(h)?;
        }
        let de: Array1<f64> = found
            .iter()
            .map(|x| x.as_ref().and_then(|x| x.de00_se).unwrap_or(f64::NAN))
            .collect();
        mg.new_dataset_builder()
            .with_data(&de)
            .create("de00_se")
            .map_err(h)?;
    }
    Ok(())
}
