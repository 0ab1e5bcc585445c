//! `summary.h5`: external links to every variant file and the table of
//! the variants (layout: docs/FORMAT.md).

use super::Row;
use crate::output::atomic;
use crate::output::h5::{about, dim, Scales};
use crate::study::sweep::{Expansion, Study, Variant};
use crate::study::StudyError;
use hdf5::types::VarLenUnicode;
use std::path::Path;

pub(crate) fn vlu(path: &Path, s: &str) -> Result<VarLenUnicode, StudyError> {
    s.parse().map_err(|_| StudyError::Sweep {
        file: path.to_path_buf(),
        message: format!("text `{s}` cannot be stored (contains NUL)"),
    })
}

/// What every study's summary file starts with: the root's text
/// attributes `attrs`, a `/variants/<name>` external link per variant, the
/// `name` coordinate and each axis's labels in `/labels` (`path`: the final
/// file, for messages).
pub(crate) fn write_variants<S>(
    f: &hdf5::File,
    path: &Path,
    study: &Study,
    attrs: &[(&str, &str)],
    variants: &[&Variant<S>],
    scales: &mut Scales,
) -> Result<(), StudyError> {
    let h = |source| StudyError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    for (name, v) in attrs {
        let val = vlu(path, v)?;
        f.new_attr::<VarLenUnicode>()
            .shape(())
            .create(*name)
            .and_then(|a| a.write_scalar(&val))
            .map_err(h)?;
    }
    let links = f.create_group("variants").map_err(h)?;
    for v in variants {
        let target = format!("variants/{}.h5", v.name);
        links.link_external(&target, "/", &v.name).map_err(h)?;
    }
    let strings = |xs: Vec<String>| -> Result<Vec<VarLenUnicode>, StudyError> {
        xs.iter().map(|s| vlu(path, s)).collect()
    };
    let variant = &[dim::VARIANT][..];
    let names = strings(variants.iter().map(|v| v.name.clone()).collect())?;
    let description = "variant names (labels, no units), in expansion order; variant";
    scales
        .coordinate(f, "name", &names, about("", description, variant))
        .map_err(h)?;
    let lg = f.create_group("labels").map_err(h)?;
    for a in &study.axes {
        let ls = strings(
            variants
                .iter()
                .map(|v| v.label(&a.name).unwrap_or("").to_string())
                .collect(),
        )?;
        let description = format!(
            "label of each variant on axis `{}` (\"\": not on this axis; labels, no units); variant",
            a.name
        );
        scales
            .write(&lg, &a.name, &ls[..], about("", &description, variant))
            .map_err(h)?;
    }
    Ok(())
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
        let f = crate::output::h5::create(tmp).map_err(h)?;
        let mut scales = Scales::default();
        let variants: Vec<&Variant> = rows.iter().map(|r| r.v).collect();
        write_variants(
            &f,
            path,
            study,
            &[
                ("study", study.name.as_str()),
                ("profile", exp.profile.as_deref().unwrap_or("")),
                ("sweep_file", &study.path.display().to_string()),
                ("selection", &exp.selection_text()),
            ],
            &variants,
            &mut scales,
        )?;
        let strings = |xs: Vec<String>| -> Result<Vec<VarLenUnicode>, StudyError> {
            xs.iter().map(|s| vlu(path, s)).collect()
        };
        let variant = &[dim::VARIANT][..];
        let ids = strings(rows.iter().map(|r| r.v.id.clone()).collect())?;
        let description = "variant ids: the first 8 hex digits of the SHA-256 of the name \
                           (labels, no units); variant";
        scales
            .write(&f, "id", &ids[..], about("", description, variant))
            .map_err(h)?;
        let seeds: Vec<u64> = rows.iter().map(|r| r.v.seed).collect();
        let description = "seed of each variant's scene; variant";
        scales
            .write(&f, "seed", &seeds[..], about("1", description, variant))
            .map_err(h)?;
        for (n, xs, what) in [
            (
                "mean_reflectance",
                rows.iter().map(|r| r.r).collect::<Vec<f64>>(),
                "total reflectance",
            ),
            (
                "mean_transmittance",
                rows.iter().map(|r| r.t).collect(),
                "total transmittance",
            ),
            (
                "mean_absorption",
                rows.iter().map(|r| r.a).collect(),
                "absorbed fraction",
            ),
        ] {
            let description = format!("{what}, mean over the variant's solves from above; variant");
            scales
                .write(&f, n, &xs[..], about("1", &description, variant))
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
        let description = "sRGB 8-bit code values under a uniform white sky at the first \
                           viewing angle (0 where has_colour is 0); variant × R, G, B";
        scales
            .write(
                &f,
                "natural_srgb8",
                &rgb,
                about("1", description, &[dim::VARIANT, dim::RGB]),
            )
            .map_err(h)?;
        let description = "1 where the variant's result has colours (an /appearance group \
                           with the tile), else 0; variant";
        scales
            .write(&f, "has_colour", &has[..], about("1", description, variant))
            .map_err(h)?;
        super::summary_values::write_axis_values(&f, study, rows, &scales).map_err(h)?;
        super::summary_values::write_hiding(&f, rows, &scales).map_err(h)?;
        super::summary_values::write_colours(&f, rows, &scales)?;
        // The scales hold datasets open; the file closes with the last handle.
        drop(scales);
        f.close().map_err(h)?;
        Ok(())
    })
}
