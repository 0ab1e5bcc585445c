//! One result as the page shows it: its BRDF table, its measured colours
//! (gamut mapped as the tile draws them) with the spectra they come from,
//! and its tile.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::table::PageBrdf;
use super::ViewError;
use crate::config::{Illuminant, StandardObserver};
use crate::optics::colour::{gamut, lab_to_lch, Observer};
use crate::output::h5::{self, MeasuredSpectrum};
use crate::output::merl::{BrdfData, RgbBrdf};

/// A measured colour as the page lists it.
#[derive(Debug, Clone, Serialize)]
pub struct PageColour {
    /// `45/0`, `d/8 SCI`, `d/8 SCE`.
    pub geometry: String,
    pub lab: [f64; 3],
    /// L*, C*ab, h° (deg).
    pub lch: [f64; 3],
    /// Standard errors of L*, a*, b* and of ΔE00 (two or more realisations).
    pub lab_se: Option<[f64; 3]>,
    pub de00_se: Option<f64>,
    /// The colour as sRGB shows it (gamut mapped: L* clamped to [0, 100],
    /// chroma reduced at constant L* and hue), its 8-bit sRGB, and whether
    /// it was moved.
    pub mapped_lab: [f64; 3],
    pub srgb8: [u8; 3],
    pub moved: bool,
    /// The reflectance factor's spectrum the colour is integrated from.
    pub wavelengths_nm: Vec<f64>,
    pub spectrum: Vec<f64>,
    /// The same at the solved wavelengths.
    pub solved_nm: Vec<f64>,
    pub solved: Vec<f64>,
}

/// What the page draws of one result (JSON field names as here).
#[derive(Debug, Clone, Serialize)]
pub struct PageResult {
    pub name: String,
    /// Where it came from and whether it is recomputed live, in words.
    pub model: String,
    /// Illuminant and observer of the colours, e.g. `D50, 2°`.
    pub conditions: String,
    pub colours: Vec<PageColour>,
    pub brdf: PageBrdf,
    /// Axis labels of a study's variant, (axis, label).
    pub labels: Vec<(String, String)>,
    /// XYZ (white Y = 100) of a linear sRGB display value under the colours'
    /// illuminant and observer: the inverse of the display mapping, for the
    /// page's readout of a pixel's CIELAB.
    pub rgb_to_xyz: [[f64; 3]; 3],
    /// XYZ of the perfect white under those conditions.
    pub white_xyz: [f64; 3],
    /// An effect paint's glints; None for other results.
    pub sparkle: Option<PageSparkle>,
}

/// What the page needs to draw an effect paint's glints by the sparkle
/// model of METHOD §10 (`optics::flakes::sparkle`): each canvas pixel is one
/// resolution cell at the viewing distance; a cell glints when one of its
/// flakes has its normal within the acceptance cone (in the lacquer) of the
/// half vector between the refracted lamp and view directions.
#[derive(Debug, Clone, Serialize)]
pub struct PageSparkle {
    /// Flakes per resolution cell (Poisson mean).
    pub flakes_per_cell: f64,
    /// Spread of the flakes' normals (deg).
    pub sigma_deg: f64,
    /// The acceptance cone's half-angle in the lacquer (deg).
    pub acceptance_deg: f64,
    pub lacquer_index: f64,
    /// A flake's share of its cell's area.
    pub coverage: f64,
    /// A flake's reflectance near normal incidence, linear sRGB.
    pub glint_rgb: [f64; 3],
    /// The model's mean glints per cell under a lamp at 45° and a normal
    /// view (`N P`).
    pub mean_glints_45: f64,
    /// The resolution cell's side (mm) and the viewing distance (mm).
    pub cell_mm: f64,
    pub viewing_distance_mm: f64,
}

/// The matrix taking linear sRGB to XYZ under `obs` (the inverse of
/// [`Observer::linear_srgb`], which is linear).
pub fn rgb_to_xyz(obs: &Observer) -> [[f64; 3]; 3] {
    // Columns of the forward map: the images of the unit XYZ vectors.
    let cols: [[f64; 3]; 3] = std::array::from_fn(|k| {
        let mut e = [0.0; 3];
        e[k] = 1.0;
        obs.linear_srgb(e)
    });
    let m = |r: usize, c: usize| cols[c][r];
    let det = m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1))
        - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0))
        + m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
    // Cofactors, transposed, over the determinant.
    std::array::from_fn(|r| {
        std::array::from_fn(|c| {
            let (r1, r2) = ((c + 1) % 3, (c + 2) % 3);
            let (c1, c2) = ((r + 1) % 3, (r + 2) % 3);
            (m(r1, c1) * m(r2, c2) - m(r1, c2) * m(r2, c1)) / det
        })
    })
}

/// The measured colours of a result and the observer they are under, from
/// its records and spectra.
pub fn page_colours(
    records: &[h5::MeasuredRecord],
    spectra: &[MeasuredSpectrum],
    obs: &Observer,
) -> Vec<PageColour> {
    records
        .iter()
        .map(|m| {
            let mapped = gamut::map_lab(obs, m.lab);
            let s = spectra.iter().find(|s| s.geometry == m.geometry);
            let take =
                |f: fn(&MeasuredSpectrum) -> &Vec<f64>| s.map(f).cloned().unwrap_or_default();
            PageColour {
                geometry: m.geometry.clone(),
                lab: m.lab,
                lch: lab_to_lch(m.lab),
                lab_se: m.lab_se,
                de00_se: m.de00_se,
                mapped_lab: mapped.lab,
                srgb8: mapped.srgb8,
                moved: mapped.moved,
                wavelengths_nm: take(|s| &s.wavelengths_nm),
                spectrum: take(|s| &s.spectrum),
                solved_nm: take(|s| &s.solved_nm),
                solved: take(|s| &s.solved),
            }
        })
        .collect()
}

/// The page's data of a result from its BRDF data and measured colours.
pub fn page_result(
    name: &str,
    model: &str,
    data: BrdfData,
    colours: Vec<PageColour>,
    obs: &Observer,
) -> Result<PageResult, ViewError> {
    let rgb = RgbBrdf::from_data(data)?;
    let anchor = colours
        .iter()
        .find(|c| c.geometry == "45/0")
        .map(|c| (c.lab, obs));
    let conditions = match obs.conditions() {
        Some((ill, o)) => format!("{ill}, {}°", o.degrees()),
        None => "custom observer".into(),
    };
    Ok(PageResult {
        name: name.to_string(),
        model: model.to_string(),
        conditions,
        colours,
        brdf: PageBrdf::new(&rgb, anchor),
        labels: vec![],
        rgb_to_xyz: rgb_to_xyz(obs),
        white_xyz: obs.white_xyz(),
        sparkle: None,
    })
}

/// A result file loaded for the page.
#[derive(Debug, Clone)]
pub struct LoadedResult {
    pub path: PathBuf,
    pub page: PageResult,
    /// The tile (PNG), where the file holds one.
    pub tile_png: Option<Vec<u8>>,
}

/// Load a result file; a file that is missing, is not a result, or has no
/// BRDF tables is refused with a one-line reason naming it.
pub fn load(path: &Path) -> Result<LoadedResult, ViewError> {
    if !path.is_file() {
        return Err(ViewError::Missing(path.to_path_buf()));
    }
    let data = h5::read_brdf_data(path)?.ok_or_else(|| ViewError::NoBrdf(path.to_path_buf()))?;
    let (records, obs) = match h5::read_measured(path)? {
        Some((records, ill, deg)) => {
            let obs = match (
                Illuminant::from_name(&ill),
                StandardObserver::from_degrees(deg),
            ) {
                (Some(i), Some(o)) => Observer::standard(i, o),
                _ => Observer::cie1931_d65(),
            };
            (records, obs)
        }
        None => (vec![], Observer::cie1931_d65()),
    };
    let spectra = h5::read_measured_spectra(path)?;
    let colours = page_colours(&records, &spectra, &obs);
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let page = page_result(
        &name,
        "wave optics (a result file; not recomputed live)",
        data,
        colours,
        &obs,
    )?;
    Ok(LoadedResult {
        path: path.to_path_buf(),
        page,
        tile_png: h5::read_tile_png(path)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb_to_xyz_inverts_the_display_mapping() {
        let obs = Observer::standard(Illuminant::D50, StandardObserver::TwoDegree);
        let m = rgb_to_xyz(&obs);
        for xyz in [[20.0, 30.0, 40.0], [96.4, 100.0, 82.5], [1.0, 0.5, 3.0]] {
            let rgb = obs.linear_srgb(xyz);
            for (r, row) in m.iter().enumerate() {
                let back: f64 = (0..3).map(|k| row[k] * rgb[k]).sum();
                assert!((back - xyz[r]).abs() < 1e-9 * xyz[r].max(1.0), "{xyz:?}");
            }
        }
    }
}
