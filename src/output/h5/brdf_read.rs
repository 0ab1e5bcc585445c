//! What a result file holds for drawing the layer on an object: the data of
//! its RGB BRDF ([`read_brdf_data`]), the spectra its measured colours are
//! integrated from ([`read_measured_spectra`]) and its tile
//! ([`read_tile_png`]).

use std::path::Path;

use super::appearance_read::read_optional;
use super::attrs::read_str_attr;
use super::IoError;
use crate::optics::farfield::table::TableSpec;
use crate::output::merl::BrdfData;

fn hdf(path: &Path) -> impl Fn(hdf5::Error) -> IoError + '_ {
    move |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    }
}

/// The BRDF data of a result file's `/appearance` (ensemble means), `None`
/// where the file has no BRDF tables (no appearance products, or a stack
/// solved layer by layer, whose `/appearance` has its colours only).
pub fn read_brdf_data(path: &Path) -> Result<Option<BrdfData>, IoError> {
    let hdf = hdf(path);
    let file = super::open(path).map_err(&hdf)?;
    if !file.link_exists("appearance") || !file.link_exists("appearance/brdf_table") {
        return Ok(None);
    }
    let g = file.group("appearance").map_err(&hdf)?;
    let vec = |name: &str| -> Result<Vec<f64>, IoError> {
        g.dataset(name).and_then(|d| d.read_raw()).map_err(&hdf)
    };
    let scalar = |name: &str| -> Result<f64, IoError> {
        g.attr(name).and_then(|a| a.read_scalar()).map_err(&hdf)
    };
    let arr2 = |name: &str| -> Result<ndarray::Array2<f64>, IoError> {
        g.dataset(name).and_then(|d| d.read()).map_err(&hdf)
    };
    let density: ndarray::Array4<f64> = g
        .dataset("brdf_table")
        .and_then(|d| d.read())
        .map_err(&hdf)?;
    let n = density.dim().3;
    let paper = match (
        read_optional::<f64, ndarray::Ix1>(&g, "ground_albedo").map_err(&hdf)?,
        read_optional::<f64, ndarray::Ix1>(&g, "r_dd_up").map_err(&hdf)?,
    ) {
        (Some(a), Some(r)) => Some((a.to_vec(), r.to_vec())),
        _ => None,
    };
    Ok(Some(BrdfData {
        wavelengths_nm: vec("wavelengths_nm")?,
        azimuth_deg: scalar("azimuth_deg")?,
        illumination_deg: vec("illumination_deg")?,
        above_deg: vec("above_deg")?,
        table: TableSpec {
            cell: scalar("table_cell")?,
            half: n.saturating_sub(1) / 2,
        },
        density,
        transmittance: arr2("transmittance")?,
        specular: arr2("specular_coherent")? + arr2("specular_incoherent")?,
        paper,
    }))
}

/// One measurement geometry's spectrum as a result file holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSpectrum {
    /// The geometry's name (`45/0`, `d/8 SCI`, `d/8 SCE`).
    pub geometry: String,
    /// Wavelengths of the spectrum the colour is integrated from (nm).
    pub wavelengths_nm: Vec<f64>,
    /// The reflectance factor there (through the spectral proxy where the
    /// result has one).
    pub spectrum: Vec<f64>,
    /// The reflectance factor at the solved wavelengths and those.
    pub solved_nm: Vec<f64>,
    pub solved: Vec<f64>,
}

/// The spectra of `/appearance/measured/<geometry>` (empty when the file
/// has no measured colours).
pub fn read_measured_spectra(path: &Path) -> Result<Vec<MeasuredSpectrum>, IoError> {
    let hdf = hdf(path);
    let file = super::open(path).map_err(&hdf)?;
    if !file.link_exists("appearance/measured") {
        return Ok(vec![]);
    }
    let g = file.group("appearance").map_err(&hdf)?;
    let solved_nm: Vec<f64> = g
        .dataset("wavelengths_nm")
        .and_then(|d| d.read_raw())
        .map_err(&hdf)?;
    let mg = g.group("measured").map_err(&hdf)?;
    let mut out = vec![];
    for name in mg.member_names().map_err(&hdf)? {
        let d = mg.group(&name).map_err(&hdf)?;
        let raw = |n: &str| -> Result<Vec<f64>, IoError> {
            d.dataset(n).and_then(|x| x.read_raw()).map_err(&hdf)
        };
        out.push(MeasuredSpectrum {
            geometry: read_str_attr(&d, "geometry").map_err(&hdf)?,
            wavelengths_nm: raw("spectrum_wavelengths_nm")?,
            spectrum: raw("spectrum")?,
            solved_nm: solved_nm.clone(),
            solved: raw("reflectance_factor")?,
        });
    }
    Ok(out)
}

/// The tile (a PNG file's bytes) a result file holds, if any.
pub fn read_tile_png(path: &Path) -> Result<Option<Vec<u8>>, IoError> {
    let hdf = hdf(path);
    let file = super::open(path).map_err(&hdf)?;
    if !file.link_exists("appearance/tile_png") {
        return Ok(None);
    }
    file.dataset("appearance/tile_png")
        .and_then(|d| d.read_raw::<u8>())
        .map_err(&hdf)
        .map(Some)
}
