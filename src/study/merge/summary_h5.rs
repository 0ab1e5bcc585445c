//! `summary.h5`: external links to every variant file and the table of
//! the variants (layout in the [merge module docs](super)).

use super::Row;
use crate::output::atomic;
use crate::study::sweep::{Expansion, Study};
use crate::study::StudyError;
use hdf5::types::VarLenUnicode;
use std::path::Path;

fn vlu(path: &Path, s: &str) -> Result<VarLenUnicode, StudyError> {
    s.parse().map_err(|_| StudyError::Sweep {
        file: path.to_path_buf(),
        message: format!("text `{s}` cannot be stored (contains NUL)"),
    })
}

pub(super) fn write_summary_h5(
    study: &Study,
    exp: &Expansion,
    rows: &[Row],
    path: &Path,
) -> Result<(), StudyError> {
    atomic::write_atomic_with(path, |tmp| -> Result<(), StudyError> {
        let h = |source| StudyError::Hdf5 {
            path: tmp.to_path_buf(),
            source,
        };
        let f = hdf5::File::create(tmp).map_err(h)?;
        for (name, v) in [
            ("study", study.name.as_str()),
            ("profile", exp.profile.as_deref().unwrap_or("")),
            ("sweep_file", &study.path.display().to_string()),
            ("selection", &exp.selection_text()),
        ] {
            let val = vlu(path, v)?;
            f.new_attr::<VarLenUnicode>()
                .shape(())
                .create(name)
                .and_then(|a| a.write_scalar(&val))
                .map_err(h)?;
        }
        let links = f.create_group("variants").map_err(h)?;
        for r in rows {
            let target = format!("variants/{}.h5", r.v.name);
            links.link_external(&target, "/", &r.v.name).map_err(h)?;
        }
        let strings = |xs: Vec<String>| -> Result<Vec<VarLenUnicode>, StudyError> {
            xs.iter().map(|s| vlu(path, s)).collect()
        };
        let names = strings(rows.iter().map(|r| r.v.name.clone()).collect())?;
        f.new_dataset_builder()
            .with_data(&names)
            .create("name")
            .map_err(h)?;
        let ids = strings(rows.iter().map(|r| r.v.id.clone()).collect())?;
        f.new_dataset_builder()
            .with_data(&ids)
            .create("id")
            .map_err(h)?;
        let seeds: Vec<u64> = rows.iter().map(|r| r.v.seed).collect();
        f.new_dataset_builder()
            .with_data(&seeds)
            .create("seed")
            .map_err(h)?;
        for (n, xs) in [
            (
                "mean_reflectance",
                rows.iter().map(|r| r.r).collect::<Vec<f64>>(),
            ),
            ("mean_transmittance", rows.iter().map(|r| r.t).collect()),
            ("mean_absorption", rows.iter().map(|r| r.a).collect()),
        ] {
            f.new_dataset_builder()
                .with_data(&xs)
                .create(n)
                .map_err(h)?;
        }
        let mut rgb = ndarray::Array2::<u8>::zeros((rows.len(), 3));
        let mut has = vec![0u8; rows.len()];
        for (i, r) in rows.iter().enumerate() {
            if let Some(c) =
                r.s.appearance
                    .as_ref()
                    .and_then(|a| a.natural_srgb8.first())
            {
                rgb.row_mut(i).assign(&ndarray::arr1(c));
                has[i] = 1;
            }
        }
        f.new_dataset_builder()
            .with_data(&rgb)
            .create("natural_srgb8")
            .map_err(h)?;
        f.new_dataset_builder()
            .with_data(&has)
            .create("has_colour")
            .map_err(h)?;
        let lg = f.create_group("labels").map_err(h)?;
        for a in &study.axes {
            let ls = strings(
                rows.iter()
                    .map(|r| r.v.label(&a.name).unwrap_or("").to_string())
                    .collect(),
            )?;
            lg.new_dataset_builder()
                .with_data(&ls)
                .create(a.name.as_str())
                .map_err(h)?;
        }
        super::summary_values::write_axis_values(&f, study, rows).map_err(h)?;
        super::summary_values::write_colours(&f, rows)?;
        f.close().map_err(h)?;
        Ok(())
    })
}
