//! `/appearance/hiding/<geometry>` (over a hiding chart): the contrast ratio
//! and Kubelka's S and K with their standard errors, written from a
//! [`Hiding`] and read back as a [`HidingRecord`] (docs/FORMAT.md).

use std::path::Path;

use super::super::appearance_read::read_optional;
use super::super::attrs::{read_str_attr, write_scalar_attr, write_str_attr};
use super::super::described::{about, dim, standard_error, Scales};
use super::super::IoError;
use super::write_estimate;
use crate::optics::appearance::hiding::{Hiding, Scalar};

/// Write every geometry's hiding power under `/appearance/hiding`.
pub(super) fn write_hiding(
    s: &mut Scales,
    g: &hdf5::Group,
    hiding: &[Hiding],
    thickness_nm: f64,
) -> hdf5::Result<()> {
    if hiding.is_empty() {
        return Ok(());
    }
    let hg = g.create_group("hiding")?;
    write_scalar_attr(&hg, "thickness_nm", thickness_nm)?;
    write_str_attr(
        &hg,
        "method",
        "Kubelka 1948 exact hyperbolic solution from the reflectance factors over the \
         chart's black and white halves as measured (surface reflection included, no \
         Saunderson correction); standard errors from each realisation's own pair",
    )?;
    for h in hiding {
        write_one(s, &hg, h)?;
    }
    Ok(())
}

fn write_one(s: &mut Scales, parent: &hdf5::Group, h: &Hiding) -> hdf5::Result<()> {
    let g = parent.create_group(h.geometry.slug())?;
    write_str_attr(&g, "geometry", h.geometry.name())?;
    let value = |name: &str, v: Scalar, units: &str, description: &str| -> hdf5::Result<()> {
        s.write(
            &g,
            name,
            &[v.value][..],
            about(units, description, &[dim::VALUE]),
        )?;
        if let Some(se) = v.se {
            let d = standard_error(description);
            s.write(
                &g,
                &format!("{name}_se"),
                &[se][..],
                about(units, &d, &[dim::VALUE]),
            )?;
        }
        Ok(())
    };
    value(
        "contrast_ratio",
        h.contrast_ratio,
        "1",
        "contrast ratio Y(over black) / Y(over white) in this geometry under the scene's \
         illuminant and observer (ISO 6504-3, ASTM D2805); one value",
    )?;
    for (name, v, description) in [
        (
            "y_black",
            h.y_black,
            "luminance factor Y over the black half (white Y = 100); one value",
        ),
        (
            "y_white",
            h.y_white,
            "luminance factor Y over the white half (white Y = 100); one value",
        ),
        (
            "y_ground",
            h.y_ground,
            "luminance factor Y of the white half itself (white Y = 100); one value",
        ),
    ] {
        value(name, Scalar { value: v, se: None }, "1", description)?;
    }
    s.write(
        &g,
        "ground_reflectance",
        h.ground_reflectance.view(),
        about(
            "1",
            "reflectance R_g of the white half at the solved wavelengths; wavelength",
            &[dim::WAVELENGTH],
        ),
    )?;
    for (name, e, units, description) in [
        (
            "r_inf",
            &h.r_inf,
            "1",
            "Kubelka's R∞, the reflectance at complete hiding, at the solved wavelengths; \
             wavelength",
        ),
        (
            "s_per_um",
            &h.s_per_um,
            "um-1",
            "Kubelka's scattering coefficient S at the solved wavelengths; wavelength",
        ),
        (
            "k_per_um",
            &h.k_per_um,
            "um-1",
            "Kubelka's absorption coefficient K at the solved wavelengths (0 where the readings \
             admit no absorbing layer, a < 1 with R_w ≥ R_b: S is then the non-absorbing \
             layer's, from R_b); wavelength",
        ),
        (
            "k_over_s",
            &h.k_over_s,
            "1",
            "K/S = (1 − R∞)²/(2 R∞) at the solved wavelengths; wavelength",
        ),
    ] {
        write_estimate(
            s,
            &g,
            name,
            e,
            about(units, description, &[dim::WAVELENGTH]),
        )?;
    }
    for (name, v, units, description) in [
        (
            "r_inf_y",
            h.r_inf_y,
            "1",
            "Kubelka's R∞ from the luminance factors Y/100; one value",
        ),
        (
            "s_y_per_um",
            h.s_y_per_um,
            "um-1",
            "Kubelka's S from the luminance factors Y/100; one value",
        ),
        (
            "k_y_per_um",
            h.k_y_per_um,
            "um-1",
            "Kubelka's K from the luminance factors Y/100; one value",
        ),
        (
            "k_over_s_y",
            h.k_over_s_y,
            "1",
            "K/S from the luminance factors Y/100; one value",
        ),
        (
            "k_over_s_max",
            h.k_over_s_max,
            "1",
            "the largest K/S over the solved wavelengths (the colour pigment's absorption \
             maximum, for tinting strength); one value",
        ),
    ] {
        value(name, v, units, description)?;
    }
    value(
        "k_over_s_max_wavelength_nm",
        Scalar {
            value: h.k_over_s_max_wavelength_nm,
            se: None,
        },
        "nm",
        "the solved wavelength of the largest K/S; one value",
    )?;
    Ok(())
}

/// One geometry's hiding power as read back.
#[derive(Debug, Clone, PartialEq)]
pub struct HidingRecord {
    /// `45/0`, `d/8 SCI`, `d/8 SCE`.
    pub geometry: String,
    pub contrast_ratio: f64,
    pub contrast_ratio_se: Option<f64>,
    pub y_black: f64,
    pub y_white: f64,
    pub y_ground: f64,
    /// From the luminance factors: `[R∞, S (1/µm), K (1/µm), K/S]`, each
    /// with its standard error.
    pub at_y: [(f64, Option<f64>); 4],
    pub k_over_s_max: f64,
    pub k_over_s_max_se: Option<f64>,
    pub k_over_s_max_wavelength_nm: f64,
    /// The solved wavelengths (`/appearance/wavelengths_nm`), nm.
    pub wavelengths_nm: Vec<f64>,
    /// At [`Self::wavelengths_nm`]: R∞, S, K and K/S, each with its
    /// standard errors.
    pub spectral: [(Vec<f64>, Option<Vec<f64>>); 4],
}

/// Names of [`HidingRecord::at_y`]'s and [`HidingRecord::spectral`]'s
/// datasets, in order.
pub const AT_Y: [&str; 4] = ["r_inf_y", "s_y_per_um", "k_y_per_um", "k_over_s_y"];
pub const SPECTRAL: [&str; 4] = ["r_inf", "s_per_um", "k_per_um", "k_over_s"];

/// The hiding power of a result file, one record per geometry in the order
/// of `/appearance/measured`'s names; empty when the file has none (no
/// chart).
pub fn read_hiding(path: &Path) -> Result<Vec<HidingRecord>, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = super::super::open(path).map_err(hdf)?;
    if !file.link_exists("appearance/hiding") {
        return Ok(Vec::new());
    }
    let hg = file.group("appearance/hiding").map_err(hdf)?;
    let wavelengths_nm = read_optional::<f64, ndarray::Ix1>(&file, "appearance/wavelengths_nm")
        .map_err(hdf)?
        .map(|v| v.to_vec())
        .unwrap_or_default();
    let mut out = Vec::new();
    for name in hg.member_names().map_err(hdf)? {
        let g = hg.group(&name).map_err(hdf)?;
        let one = |n: &str| -> Result<Option<f64>, IoError> {
            Ok(read_optional::<f64, ndarray::Ix1>(&g, n)
                .map_err(hdf)?
                .and_then(|v| v.first().copied()))
        };
        let must = |n: &str| -> Result<f64, IoError> { Ok(one(n)?.unwrap_or(f64::NAN)) };
        let with_se = |n: &str| -> Result<(f64, Option<f64>), IoError> {
            Ok((must(n)?, one(&format!("{n}_se"))?))
        };
        let vector = |n: &str| -> Result<Option<Vec<f64>>, IoError> {
            Ok(read_optional::<f64, ndarray::Ix1>(&g, n)
                .map_err(hdf)?
                .map(|v| v.to_vec()))
        };
        let spectral = |n: &str| -> Result<(Vec<f64>, Option<Vec<f64>>), IoError> {
            Ok((vector(n)?.unwrap_or_default(), vector(&format!("{n}_se"))?))
        };
        out.push(HidingRecord {
            geometry: read_str_attr(&g, "geometry").map_err(hdf)?,
            contrast_ratio: must("contrast_ratio")?,
            contrast_ratio_se: one("contrast_ratio_se")?,
            y_black: must("y_black")?,
            y_white: must("y_white")?,
            y_ground: must("y_ground")?,
            at_y: [
                with_se(AT_Y[0])?,
                with_se(AT_Y[1])?,
                with_se(AT_Y[2])?,
                with_se(AT_Y[3])?,
            ],
            k_over_s_max: must("k_over_s_max")?,
            k_over_s_max_se: one("k_over_s_max_se")?,
            k_over_s_max_wavelength_nm: must("k_over_s_max_wavelength_nm")?,
            wavelengths_nm: wavelengths_nm.clone(),
            spectral: [
                spectral(SPECTRAL[0])?,
                spectral(SPECTRAL[1])?,
                spectral(SPECTRAL[2])?,
                spectral(SPECTRAL[3])?,
            ],
        });
    }
    Ok(out)
}
