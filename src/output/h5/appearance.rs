//! The `/appearance` group: written from an [`Appearance`] (ensemble means
//! with their standard errors) and read back as [`AppearanceArrays`].

use std::path::Path;

use ndarray::Array2;

use super::attrs::{read_str_attr, write_scalar_attr, write_str_attr};
use super::IoError;
use crate::optics::appearance::{Appearance, Estimate, MeasuredColour};

/// The ensemble-mean appearance arrays of a result file (`/appearance`),
/// for comparing runs (docs/ACCURACY.md). Shapes as in the module docs.
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

fn write_estimate<D: ndarray::Dimension>(
    g: &hdf5::Group,
    name: &str,
    e: &Estimate<D>,
) -> hdf5::Result<()> {
    g.new_dataset_builder()
        .with_data(e.mean.view())
        .create(name)?;
    if let Some(se) = &e.se {
        g.new_dataset_builder()
            .with_data(se.view())
            .create(format!("{name}_se").as_str())?;
    }
    Ok(())
}

pub(super) fn write_appearance(
    file: &hdf5::File,
    a: &Appearance,
    tile_png: Option<&[u8]>,
) -> hdf5::Result<()> {
    let g = file.create_group("appearance")?;
    let sp = &a.spec;
    let below = sp.below.as_ref().map(|h| h.polar_deg()).unwrap_or_default();
    for (name, v) in [
        ("wavelengths_nm", &sp.wavelengths_nm),
        ("above_deg", &sp.above_deg),
        ("illumination_deg", &sp.illumination_deg),
        ("viewing_deg", &sp.viewing_deg),
        ("below_deg", &below),
    ] {
        g.new_dataset_builder().with_data(&v[..]).create(name)?;
    }
    write_scalar_attr(&g, "azimuth_deg", sp.azimuth_deg)?;
    write_scalar_attr(&g, "table_cell", sp.table.cell)?;
    write_scalar_attr(&g, "realisations", sp.realisations as u64)?;
    write_estimate(&g, "reflectance", &a.reflectance)?;
    write_estimate(&g, "transmittance", &a.transmittance)?;
    write_estimate(&g, "absorption", &a.absorption)?;
    for (name, v) in [
        ("specular_coherent", &a.specular_coherent),
        ("specular_incoherent", &a.specular_incoherent),
        ("direct_coherent", &a.direct_coherent),
        ("direct_incoherent", &a.direct_incoherent),
    ] {
        g.new_dataset_builder().with_data(v.view()).create(name)?;
    }
    write_estimate(&g, "brdf_table", &a.brdf_table)?;
    let nt = sp.table.n();
    let coverage = ndarray::Array2::from_shape_fn((nt, nt), |(j, i)| {
        crate::optics::farfield::table::node_coverage(sp.table, i, j)
    });
    described(
        &g,
        "table_coverage",
        coverage.view(),
        "1",
        "share of each table node's bilinear kernel above the horizon; the BRDF/BTDF is \
         bilinear(table) / bilinear(table_coverage)",
    )?;
    write_estimate(&g, "brdf_diffuse", &a.brdf_diffuse)?;
    if let Some(t) = &a.btdf_table {
        write_estimate(&g, "btdf_table", t)?;
    }
    if let Some(t) = &a.btdf_diffuse {
        write_estimate(&g, "btdf_diffuse", t)?;
    }
    if let Some(p) = &a.paper {
        write_scalar_attr(&g, "paper_albedo", p.albedo)?;
        write_estimate(&g, "r_dd_up", &p.r_dd_up)?;
        write_estimate(&g, "t_d", &p.t_d)?;
    }
    if let Some(t) = &a.brdf_total {
        g.new_dataset_builder()
            .with_data(t.view())
            .create("brdf_total")?;
    }
    if let Some(n) = &a.natural {
        g.new_dataset_builder()
            .with_data(n.view())
            .create("natural")?;
    }
    if let Some(c) = &a.colours {
        g.new_dataset_builder()
            .with_data(c.tile_srgb8.view())
            .create("tile_srgb8")?;
        g.new_dataset_builder()
            .with_data(c.tile_lab.view())
            .create("tile_lab")?;
        let rgb = Array2::from_shape_fn((c.natural_srgb8.len(), 3), |(i, j)| c.natural_srgb8[i][j]);
        g.new_dataset_builder()
            .with_data(&rgb)
            .create("natural_srgb8")?;
        let lab = Array2::from_shape_fn((c.natural_lab.len(), 3), |(i, j)| c.natural_lab[i][j]);
        g.new_dataset_builder()
            .with_data(&lab)
            .create("natural_lab")?;
    }
    if let Some((ill, obs)) = a.colour_conditions {
        write_str_attr(&g, "illuminant", ill.name())?;
        write_str_attr(&g, "observer", obs.name())?;
        write_scalar_attr(&g, "observer_deg", obs.degrees())?;
    }
    if let Some(s) = a.colours.as_ref().and_then(|c| c.spread.as_ref()) {
        let what = "of the tile's L*, a*, b* (viewing, 1 + illumination, 3)";
        described(
            &g,
            "tile_lab_se",
            s.lab_se.view(),
            "1",
            &format!("standard error {what}"),
        )?;
        let what = "of each tile colour in ΔE00 (viewing, 1 + illumination)";
        described(
            &g,
            "tile_de00_se",
            s.de00_se.view(),
            "1",
            &format!("standard error {what}"),
        )?;
        let what = "CIELAB of every realisation (realisation, viewing, 1 + illumination, 3)";
        described(
            &g,
            "tile_lab_realisations",
            s.realisation_lab.view(),
            "1",
            what,
        )?;
    }
    if !a.measured.is_empty() {
        let mg = g.create_group("measured")?;
        for m in &a.measured {
            write_measured(&mg, m)?;
        }
    }
    if let Some(png) = tile_png {
        g.new_dataset_builder().with_data(png).create("tile_png")?;
    }
    Ok(())
}

/// `/appearance/measured/<slug>`: one measurement geometry's colour.
fn write_measured(parent: &hdf5::Group, m: &MeasuredColour) -> hdf5::Result<()> {
    let g = parent.create_group(m.geometry.slug())?;
    write_str_attr(&g, "geometry", m.geometry.name())?;
    write_estimate(&g, "reflectance_factor", &m.reflectance)?;
    let vector = |name: &str, data: &[f64], units: &str, desc: &str| {
        described(&g, name, ndarray::aview1(data), units, desc)
    };
    vector(
        "spectrum_wavelengths_nm",
        &m.spectrum_wavelengths_nm,
        "nm",
        "wavelengths of the spectrum colour is integrated from",
    )?;
    vector(
        "spectrum",
        &m.spectrum,
        "1",
        "reflectance factor colour is integrated from (through the spectral proxy where there is one)",
    )?;
    vector("xyz", &m.xyz, "1", "CIE XYZ, white Y = 100")?;
    vector("lab", &m.lab, "1", "CIELAB L*, a*, b*")?;
    vector("lch", &m.lch, "1, 1, deg", "CIE LCh(ab): L*, C*ab, h_ab")?;
    if let (Some(se), Some(de)) = (m.lab_se, m.de00_se) {
        vector("lab_se", &se, "1", "standard errors of L*, a*, b*")?;
        vector(
            "de00_se",
            &[de],
            "1",
            "standard error of the colour in ΔE00",
        )?;
    }
    Ok(())
}

/// A dataset with `units` and `description` attributes.
fn described<D: ndarray::Dimension>(
    g: &hdf5::Group,
    name: &str,
    data: ndarray::ArrayView<'_, f64, D>,
    units: &str,
    description: &str,
) -> hdf5::Result<()> {
    let d = g.new_dataset_builder().with_data(data).create(name)?;
    write_str_attr(&d, "units", units)?;
    write_str_attr(&d, "description", description)
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
