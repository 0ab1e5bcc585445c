//! The `summary.h5` of an effect study: a link per variant and the table
//! of the variants, every dataset with units, a description and labelled
//! dimensions (docs/FORMAT.md).

use super::row::EffectRow;
use crate::config::paint::PaintScene;
use crate::output::atomic;
use crate::output::h5::{about, dim, Scales, SparkleRecord};
use crate::study::merge::{vlu, write_variants};
use crate::study::sweep::{Expansion, Study, Variant};
use crate::study::StudyError;
use hdf5::types::VarLenUnicode;
use ndarray::{Array2, Array3};
use std::path::Path;

const GEOMETRY: &str = "geometry";
const SPARKLE: &str = "sparkle_illumination_deg";

/// One sparkle figure of a light.
type Get = fn(&SparkleRecord) -> f64;

/// Write the summary of `rows` to `path`.
pub(super) fn write(
    study: &Study,
    exp: &Expansion<PaintScene>,
    rows: &[EffectRow],
    path: &Path,
) -> Result<(), StudyError> {
    // The geometries and sparkle lights of the first variant; another
    // variant's value where it has none is NaN.
    let first = &rows[0].rec;
    let geos: Vec<(f64, f64)> = first
        .colours
        .iter()
        .map(|c| (c.illumination_deg, c.aspecular_deg))
        .collect();
    let lights: Vec<f64> = first
        .sparkle
        .as_ref()
        .map(|s| s.rows.iter().map(|r| r.illumination_deg).collect())
        .unwrap_or_default();
    atomic::write_atomic_with(path, |tmp| -> Result<(), StudyError> {
        let h = |source| StudyError::Hdf5 {
            path: tmp.to_path_buf(),
            source,
        };
        let f = crate::output::h5::create(tmp).map_err(h)?;
        let mut scales = Scales::default();
        let variants: Vec<&Variant<PaintScene>> = rows.iter().map(|r| r.v).collect();
        write_variants(
            &f,
            path,
            study,
            &[
                ("study", study.name.as_str()),
                ("kind", "paint"),
                ("profile", exp.profile.as_deref().unwrap_or("")),
                ("sweep_file", &study.path.display().to_string()),
                ("selection", &exp.selection_text()),
                ("illuminant", &first.illuminant),
            ],
            &variants,
            &mut scales,
        )?;
        f.new_attr::<u32>()
            .shape(())
            .create("observer_deg")
            .and_then(|a| a.write_scalar(&first.observer_deg))
            .map_err(h)?;
        let strings = |xs: Vec<String>| -> Result<Vec<VarLenUnicode>, StudyError> {
            xs.iter().map(|s| vlu(path, s)).collect()
        };
        let n = rows.len();
        let labels: Vec<String> = geos.iter().map(|(i, a)| format!("{i}as{a}")).collect();
        let desc = "multi-angle geometry: illumination (°) `as` aspecular angle (°); geometry";
        scales
            .coordinate(
                &f,
                GEOMETRY,
                &strings(labels)?,
                about("", desc, &[GEOMETRY]),
            )
            .map_err(h)?;
        if !lights.is_empty() {
            let desc = "polar angle of the small light of the sparkle figures, view along \
                        the normal; sparkle_illumination_deg";
            scales
                .coordinate(&f, SPARKLE, &lights, about("deg", desc, &[SPARKLE]))
                .map_err(h)?;
        }
        let flop: Vec<f64> = rows
            .iter()
            .map(|r| r.rec.flop_index.unwrap_or(f64::NAN))
            .collect();
        let desc = "flop index 2.69 (L*15 − L*110)^1.11 / L*45^0.86 at 45° illumination \
                    (NaN: not defined); variant";
        scales
            .write(
                &f,
                "flop_index",
                &flop[..],
                about("1", desc, &[dim::VARIANT]),
            )
            .map_err(h)?;
        for (name, pick, what, lch_dim) in [
            ("lab", 0usize, "CIELAB L*, a*, b*", dim::LAB),
            ("lch", 1, "L*, C*ab, hue angle h (°)", dim::LCH),
        ] {
            let mut a = Array3::from_elem((n, geos.len(), 3), f64::NAN);
            for (i, r) in rows.iter().enumerate() {
                for (g, &(ill, asp)) in geos.iter().enumerate() {
                    if let Some(c) = r
                        .rec
                        .colours
                        .iter()
                        .find(|c| c.illumination_deg == ill && c.aspecular_deg == asp)
                    {
                        let v = if pick == 0 { c.lab } else { c.lch };
                        for k in 0..3 {
                            a[[i, g, k]] = v[k];
                        }
                    }
                }
            }
            let desc = format!(
                "{what} per geometry under {} and the CIE {}° observer; variant × geometry × {lch_dim}",
                first.illuminant, first.observer_deg
            );
            scales
                .write(
                    &f,
                    name,
                    &a,
                    about("1", &desc, &[dim::VARIANT, GEOMETRY, lch_dim]),
                )
                .map_err(h)?;
        }
        let sparkle_col = |get: Get| {
            let mut a = Array2::from_elem((n, lights.len()), f64::NAN);
            for (i, r) in rows.iter().enumerate() {
                for (j, &l) in lights.iter().enumerate() {
                    if let Some(s) = r
                        .rec
                        .sparkle
                        .as_ref()
                        .and_then(|s| s.rows.iter().find(|x| x.illumination_deg == l))
                    {
                        a[[i, j]] = get(s);
                    }
                }
            }
            a
        };
        if !lights.is_empty() {
            let columns: [(&str, &str, Get, &str); 3] = [
                (
                    "glints_per_mm2",
                    "1/mm2",
                    |s| s.glints_per_mm2,
                    "sparkle density: glints per mm²",
                ),
                (
                    "glints_per_cell",
                    "1",
                    |s| s.glints_per_cell,
                    "glints per resolved cell",
                ),
                (
                    "glint_reflectance",
                    "1",
                    |s| s.glint_reflectance,
                    "luminous reflectance Y/100 of a glinting flake (sparkle intensity)",
                ),
            ];
            for (name, units, get, what) in columns {
                let desc = format!("{what}; variant × sparkle_illumination_deg");
                scales
                    .write(
                        &f,
                        name,
                        &sparkle_col(get),
                        about(units, &desc, &[dim::VARIANT, SPARKLE]),
                    )
                    .map_err(h)?;
            }
        }
        let graininess: Vec<f64> = rows
            .iter()
            .map(|r| r.rec.sparkle.as_ref().map_or(f64::NAN, |s| s.graininess))
            .collect();
        let desc = "graininess: relative fluctuation of the flakes per resolved cell under \
                    diffuse light (NaN: no flakes); variant";
        scales
            .write(
                &f,
                "graininess",
                &graininess[..],
                about("1", desc, &[dim::VARIANT]),
            )
            .map_err(h)?;
        drop(scales);
        f.close().map_err(h)?;
        Ok(())
    })
}
