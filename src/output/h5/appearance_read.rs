//! The `/appearance` group read back: its arrays ([`AppearanceArrays`]) and
//! measured colours ([`MeasuredRecord`]).

use std::path::Path;

use super::attrs::read_str_attr;
use super::IoError;

/// The ensemble-mean appearance arrays of a result file (`/appearance`),
/// for comparing runs (docs/ACCURACY.md). Shapes as in docs/FORMAT.md.
#[derive(Debug, Clone, PartialEq)]
pub struct AppearanceArrays {
    pub wavelengths_nm: Vec<f64>,
    pub illumination_deg: Vec<f64>,
    pub viewing_deg: Vec<f64>,
    pub above_deg: Vec<f64>,
    /// (L, A) each.
    pub reflectance: ndarray::Array2<f64>,
    pub transmittance: ndarray::Array2<f64>,
    pub absorption: ndarray::Array2<f64>,
    /// (L, I, V), present with the tile.
    pub brdf_total: Option<ndarray::Array3<f64>>,
    /// (L, V), present with the tile.
    pub natural: Option<ndarray::Array2<f64>>,
    /// CIELAB of the tile's cells (V, 1 + I, 3), present with the tile.
    pub tile_lab: Option<ndarray::Array3<f64>>,
}

/// Read the `/appearance` arrays of a result file (None when absent).
pub fn read_appearance(path: &Path) -> Result<Option<AppearanceArrays>, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = hdf5::File::open(path).map_err(hdf)?;
    if !file.link_exists("appearance") {
        return Ok(None);
    }
    let g = file.group("appearance").map_err(hdf)?;
    let vec = |name: &str| -> Result<Vec<f64>, IoError> {
        g.dataset(name).and_then(|d| d.read_raw()).map_err(hdf)
    };
    let arr2 = |name: &str| -> Result<ndarray::Array2<f64>, IoError> {
        g.dataset(name).and_then(|d| d.read()).map_err(hdf)
    };
    let brdf_total = if g.link_exists("brdf_total") {
        Some(
            g.dataset("brdf_total")
                .and_then(|d| d.read())
                .map_err(hdf)?,
        )
    } else {
        None
    };
    let natural = if g.link_exists("natural") {
        Some(arr2("natural")?)
    } else {
        None
    };
    let tile_lab = if g.link_exists("tile_lab") {
        Some(g.dataset("tile_lab").and_then(|d| d.read()).map_err(hdf)?)
    } else {
        None
    };
    Ok(Some(AppearanceArrays {
        tile_lab,
        wavelengths_nm: vec("wavelengths_nm")?,
        illumination_deg: vec("illumination_deg")?,
        viewing_deg: vec("viewing_deg")?,
        above_deg: vec("above_deg")?,
        reflectance: arr2("reflectance")?,
        transmittance: arr2("transmittance")?,
        absorption: arr2("absorption")?,
        brdf_total,
        natural,
    }))
}

/// One measurement geometry's colour as read back from a result file.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredRecord {
    /// The geometry's name (`45/0`, `d/8 SCI`, `d/8 SCE`).
    pub geometry: String,
    pub lab: [f64; 3],
    /// CIE XYZ (Y of the perfect diffuser = 100).
    pub xyz: [f64; 3],
    /// Standard errors of L*, a*, b* and of ΔE00 (two or more realisations).
    pub lab_se: Option<[f64; 3]>,
    pub de00_se: Option<f64>,
}

/// The measured colours of a result file (`/appearance/measured`) and the
/// illuminant and observer (degrees) they were computed for; `None` when the
/// file has none.
pub fn read_measured(path: &Path) -> Result<Option<(Vec<MeasuredRecord>, String, u32)>, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = hdf5::File::open(path).map_err(hdf)?;
    if !file.link_exists("appearance/measured") {
        return Ok(None);
    }
    let g = file.group("appearance").map_err(hdf)?;
    let illuminant = read_str_attr(&g, "illuminant").map_err(hdf)?;
    let observer: u32 = g
        .attr("observer_deg")
        .and_then(|a| a.read_scalar())
        .map_err(hdf)?;
    let three = |d: &hdf5::Group, name: &str| -> Result<Option<[f64; 3]>, IoError> {
        if !d.link_exists(name) {
            return Ok(None);
        }
        let v: Vec<f64> = d.dataset(name).and_then(|x| x.read_raw()).map_err(hdf)?;
        Ok(Some([v[0], v[1], v[2]]))
    };
    let mg = g.group("measured").map_err(hdf)?;
    let mut out = Vec::new();
    for name in mg.member_names().map_err(hdf)? {
        let d = mg.group(&name).map_err(hdf)?;
        let de00_se = if d.link_exists("de00_se") {
            let v: Vec<f64> = d
                .dataset("de00_se")
                .and_then(|x| x.read_raw())
                .map_err(hdf)?;
            v.first().copied()
        } else {
            None
        };
        out.push(MeasuredRecord {
            geometry: read_str_attr(&d, "geometry").map_err(hdf)?,
            lab: three(&d, "lab")?.unwrap_or([f64::NAN; 3]),
            xyz: three(&d, "xyz")?.unwrap_or([f64::NAN; 3]),
            lab_se: three(&d, "lab_se")?,
            de00_se,
        });
    }
    Ok(Some((out, illuminant, observer)))
}

/// One measurement geometry's Kubelka–Munk colour as read back from a
/// result file (`/appearance/baseline`).
#[derive(Debug, Clone, PartialEq)]
pub struct BaselineRecord {
    /// The baseline's model (`kubelka-munk`).
    pub model: String,
    /// The geometry's name (`45/0`, `d/8 SCI`, `d/8 SCE`).
    pub geometry: String,
    pub lab: [f64; 3],
    /// CIEDE2000 to the wave solution's colour in the same geometry.
    pub de00_to_wave: Option<f64>,
}

/// The baseline colours of a result file; empty when it has none.
pub fn read_baseline(path: &Path) -> Result<Vec<BaselineRecord>, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = hdf5::File::open(path).map_err(hdf)?;
    if !file.link_exists("appearance/baseline") {
        return Ok(Vec::new());
    }
    let g = file.group("appearance/baseline").map_err(hdf)?;
    let model = read_str_attr(&g, "model").map_err(hdf)?;
    let mut out = Vec::new();
    for name in g.member_names().map_err(hdf)? {
        let d = g.group(&name).map_err(hdf)?;
        let lab: Vec<f64> = d.dataset("lab").and_then(|x| x.read_raw()).map_err(hdf)?;
        let de00_to_wave = if d.link_exists("de00_to_wave") {
            let v: Vec<f64> = d
                .dataset("de00_to_wave")
                .and_then(|x| x.read_raw())
                .map_err(hdf)?;
            v.first().copied()
        } else {
            None
        };
        out.push(BaselineRecord {
            model: model.clone(),
            geometry: read_str_attr(&d, "geometry").map_err(hdf)?,
            lab: [lab[0], lab[1], lab[2]],
            de00_to_wave,
        });
    }
    Ok(out)
}
