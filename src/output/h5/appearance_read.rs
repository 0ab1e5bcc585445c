//! The `/appearance` group read back: its arrays ([`AppearanceArrays`]) and
//! measured colours ([`MeasuredRecord`]).

use std::path::Path;

use super::attrs::read_str_attr;
use super::IoError;

/// Dataset `name` of `g` read whole, `None` where `g` has no such link
/// (the optional datasets of docs/FORMAT.md).
pub fn read_optional<T: hdf5::H5Type, D: ndarray::Dimension>(
    g: &hdf5::Group,
    name: &str,
) -> hdf5::Result<Option<ndarray::Array<T, D>>> {
    if !g.link_exists(name) {
        return Ok(None);
    }
    g.dataset(name)?.read().map(Some)
}

/// The first `N` values of an optional 1-D dataset (a colour's three
/// components, a single value), refused when it holds fewer.
fn optional_values<const N: usize>(g: &hdf5::Group, name: &str) -> hdf5::Result<Option<[f64; N]>> {
    match read_optional::<f64, ndarray::Ix1>(g, name)? {
        None => Ok(None),
        Some(v) if v.len() >= N => Ok(Some(std::array::from_fn(|i| v[i]))),
        Some(v) => Err(hdf5::Error::from(format!(
            "{name}: {} values, expected {N}",
            v.len()
        ))),
    }
}

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

/// Read the `/appearance` arrays of a result file (None when absent, or
/// for a stack solved layer by layer, whose `/appearance` has its colours
/// only).
pub fn read_appearance(path: &Path) -> Result<Option<AppearanceArrays>, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = super::open(path).map_err(hdf)?;
    // A stack solved layer by layer keeps only its colours in /appearance.
    if !file.link_exists("appearance") || !file.link_exists("appearance/wavelengths_nm") {
        return Ok(None);
    }
    let g = file.group("appearance").map_err(hdf)?;
    let vec = |name: &str| -> Result<Vec<f64>, IoError> {
        g.dataset(name).and_then(|d| d.read_raw()).map_err(hdf)
    };
    let arr2 = |name: &str| -> Result<ndarray::Array2<f64>, IoError> {
        g.dataset(name).and_then(|d| d.read()).map_err(hdf)
    };
    Ok(Some(AppearanceArrays {
        tile_lab: read_optional(&g, "tile_lab").map_err(hdf)?,
        wavelengths_nm: vec("wavelengths_nm")?,
        illumination_deg: vec("illumination_deg")?,
        viewing_deg: vec("viewing_deg")?,
        above_deg: vec("above_deg")?,
        reflectance: arr2("reflectance")?,
        transmittance: arr2("transmittance")?,
        absorption: arr2("absorption")?,
        brdf_total: read_optional(&g, "brdf_total").map_err(hdf)?,
        natural: read_optional(&g, "natural").map_err(hdf)?,
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
    read_measured_in(path, "measured")
}

/// Over a hiding chart: the measured colours over its black half
/// (`/appearance/measured_black`), as [`read_measured`] gives those over
/// its white half; `None` when the file has none.
pub fn read_measured_black(
    path: &Path,
) -> Result<Option<(Vec<MeasuredRecord>, String, u32)>, IoError> {
    read_measured_in(path, "measured_black")
}

fn read_measured_in(
    path: &Path,
    group: &str,
) -> Result<Option<(Vec<MeasuredRecord>, String, u32)>, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = super::open(path).map_err(hdf)?;
    if !file.link_exists(&format!("appearance/{group}")) {
        return Ok(None);
    }
    let g = file.group("appearance").map_err(hdf)?;
    let illuminant = read_str_attr(&g, "illuminant").map_err(hdf)?;
    let observer: u32 = g
        .attr("observer_deg")
        .and_then(|a| a.read_scalar())
        .map_err(hdf)?;
    let mg = g.group(group).map_err(hdf)?;
    let mut out = Vec::new();
    for name in mg.member_names().map_err(hdf)? {
        let d = mg.group(&name).map_err(hdf)?;
        let three = |name: &str| optional_values::<3>(&d, name).map_err(hdf);
        out.push(MeasuredRecord {
            geometry: read_str_attr(&d, "geometry").map_err(hdf)?,
            lab: three("lab")?.unwrap_or([f64::NAN; 3]),
            xyz: three("xyz")?.unwrap_or([f64::NAN; 3]),
            lab_se: three("lab_se")?,
            de00_se: optional_values::<1>(&d, "de00_se")
                .map_err(hdf)?
                .map(|[v]| v),
        });
    }
    Ok(Some((out, illuminant, observer)))
}

/// One baseline model's colour in one measurement geometry as read back
/// from a result file (`/appearance/baseline`).
#[derive(Debug, Clone, PartialEq)]
pub struct BaselineRecord {
    /// The baseline's model (`kubelka-munk`, `adding-doubling`, …).
    pub model: String,
    /// The geometry's name (`45/0`, `d/8 SCI`, `d/8 SCE`).
    pub geometry: String,
    pub lab: [f64; 3],
    /// CIEDE2000 to the wave solution's colour in the same geometry.
    pub de00_to_wave: Option<f64>,
}

/// The baseline colours of a result file, model by model; empty when it has
/// none. Reads both layouts: `/appearance/baseline/<model>/<geometry>`
/// (attribute `model` on each model's group) and the earlier single-model
/// `/appearance/baseline/<geometry>` (attribute `model` on the group).
pub fn read_baseline(path: &Path) -> Result<Vec<BaselineRecord>, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = super::open(path).map_err(hdf)?;
    if !file.link_exists("appearance/baseline") {
        return Ok(Vec::new());
    }
    let g = file.group("appearance/baseline").map_err(hdf)?;
    let mut out = Vec::new();
    if g.attr("model").is_ok() {
        let model = read_str_attr(&g, "model").map_err(hdf)?;
        read_geometries(&g, &model, &mut out).map_err(hdf)?;
        return Ok(out);
    }
    // Models in the order written.
    let mut names = g.member_names().map_err(hdf)?;
    if let Ok(order) = read_str_attr(&g, "models") {
        let order: Vec<&str> = order.split(',').collect();
        names.sort_by_key(|n| order.iter().position(|o| o == n).unwrap_or(usize::MAX));
    }
    for name in names {
        let mg = g.group(&name).map_err(hdf)?;
        let model = read_str_attr(&mg, "model").map_err(hdf)?;
        read_geometries(&mg, &model, &mut out).map_err(hdf)?;
    }
    Ok(out)
}

/// The geometry groups of one model's baseline group.
fn read_geometries(
    g: &hdf5::Group,
    model: &str,
    out: &mut Vec<BaselineRecord>,
) -> hdf5::Result<()> {
    for name in g.member_names()? {
        let d = g.group(&name)?;
        let lab = optional_values::<3>(&d, "lab")
            .and_then(|v| v.ok_or_else(|| hdf5::Error::from(format!("{name}: no lab"))))?;
        out.push(BaselineRecord {
            model: model.to_string(),
            geometry: read_str_attr(&d, "geometry")?,
            lab,
            de00_to_wave: optional_values::<1>(&d, "de00_to_wave")?.map(|[v]| v),
        });
    }
    Ok(())
}
