//! `/stack` and the colours of a stack solved layer by layer: the adding
//! method's directions, each layer's flux matrices (ensemble means), the
//! whole stack's reflectance, transmittance and absorption in air, and in
//! `/appearance` the white sky and the measured colours as a single layer
//! stores them (docs/FORMAT.md).

use ndarray::{Array3, Ix2, Ix3};

use super::appearance::{write_baselines, write_colours, write_estimate, write_measured, LIV};
use super::attrs::{write_scalar_attr, write_str_attr};
use super::described::{about, dim, Scales};
use crate::optics::appearance::{Colours, Estimate, MeasuredColour};
use crate::optics::baseline::BaselineColour;
use crate::optics::colour::{Illuminant, StandardObserver};

/// Dimension names of the stack's tables.
const NODE: &str = "node";
const NODE_IN: &str = "node_in";
const LAYER: &str = "layer";

/// One layer's flux matrices, ensemble means, (wavelength, out, in).
#[derive(Debug, Clone)]
pub struct LayerMatrices {
    pub r_down: Array3<f64>,
    pub t_down: Array3<f64>,
    pub r_up: Array3<f64>,
    pub t_up: Array3<f64>,
}

/// What a stack solved layer by layer stores besides the solves.
#[derive(Debug, Clone)]
pub struct StackTables {
    pub coupling: String,
    pub layer_thickness_nm: Vec<f64>,
    /// The pigments of each layer, comma-separated.
    pub layer_pigments: Vec<String>,
    /// Share of the area each layer is printed on (1: all of it).
    pub layer_coverage: Vec<f64>,
    /// Yule–Nielsen's n of a halftone's area mixture.
    pub yule_nielsen_n: f64,
    /// The directions: polar angle in the binder, in air (NaN where trapped),
    /// flux weight.
    pub binder_polar_deg: Vec<f64>,
    pub air_polar_deg: Vec<f64>,
    pub flux_weight: Vec<f64>,
    pub wavelengths_nm: Vec<f64>,
    pub layers: Vec<LayerMatrices>,
    pub realisations: usize,
    /// Air angles of the whole stack's R, T, A.
    pub above_deg: Vec<f64>,
    /// The stack in air without paper, (wavelength, above).
    pub reflectance: Estimate<Ix2>,
    pub transmittance: Estimate<Ix2>,
    pub absorption: Estimate<Ix2>,
    pub viewing_deg: Vec<f64>,
    /// Radiance factor under a white sky, on the paper, (wavelength, viewing).
    pub natural: Estimate<Ix2>,
    /// Illumination polar angles of the BRDF square (the tile's columns).
    pub illumination_deg: Vec<f64>,
    /// Diffuse BRDF of the stack on its paper in the plane of incidence on
    /// the specular side, 1/sr, (wavelength, illumination, viewing), when
    /// the tile was asked for.
    pub brdf_total: Option<Estimate<Ix3>>,
    /// The tile's colours, when it was asked for.
    pub colours: Option<Colours>,
    pub measured: Vec<MeasuredColour>,
    /// The classical baselines' colours (adding–doubling of the stack).
    pub baseline: Vec<BaselineColour>,
    pub conditions: (Illuminant, StandardObserver),
}

pub(super) fn write_stack(
    file: &hdf5::File,
    t: &StackTables,
    tile_png: Option<&[u8]>,
    s: &mut Scales,
) -> hdf5::Result<()> {
    let g = file.create_group("stack")?;
    write_str_attr(&g, "coupling", &t.coupling)?;
    write_scalar_attr(&g, "realisations", t.realisations as u64)?;
    write_scalar_attr(&g, "yule_nielsen_n", t.yule_nielsen_n)?;
    s.coordinate(
        &g,
        "layer_thickness_nm",
        &t.layer_thickness_nm,
        about(
            "nm",
            "thickness of each layer, from the top; layer",
            &[LAYER],
        ),
    )?;
    let names: Vec<hdf5::types::VarLenUnicode> = t
        .layer_pigments
        .iter()
        .map(|n| n.parse().unwrap_or_default())
        .collect();
    s.write(
        &g,
        "layer_coverage",
        &t.layer_coverage[..],
        about(
            "1",
            "share of the area each layer is printed on (below 1: a halftone, its primaries \
             mixed by area); layer",
            &[LAYER],
        ),
    )?;
    s.write(
        &g,
        "layer_pigments",
        &names[..],
        about("", "the pigments of each layer (text); layer", &[LAYER]),
    )?;
    s.coordinate(
        &g,
        "binder_polar_deg",
        &t.binder_polar_deg,
        about(
            "deg",
            "polar angle in the binder of each direction of the adding method (ascending \
             cos θ); node",
            &[NODE],
        ),
    )?;
    s.write(
        &g,
        "air_polar_deg",
        &t.air_polar_deg[..],
        about(
            "deg",
            "the same direction in air after refraction at the flat surface (NaN: trapped by \
             total internal reflection); node",
            &[NODE],
        ),
    )?;
    s.write(
        &g,
        "flux_weight",
        &t.flux_weight[..],
        about(
            "1",
            "share of a Lambertian radiance's flux in each direction's bin (sum 1); node",
            &[NODE],
        ),
    )?;
    s.coordinate(
        &g,
        "wavelengths_nm",
        &t.wavelengths_nm,
        about(
            "nm",
            "vacuum wavelengths solved; wavelength",
            &[dim::WAVELENGTH],
        ),
    )?;
    for (i, l) in t.layers.iter().enumerate() {
        let lg = g.create_group(&format!("layer{i}"))?;
        for (name, m, what) in [
            ("r_down", &l.r_down, "reflection of light from above"),
            ("t_down", &l.t_down, "transmission of light from above"),
            ("r_up", &l.r_up, "reflection of light from below"),
            ("t_up", &l.t_up, "transmission of light from below"),
        ] {
            let description = format!(
                "{what}, inside the binder: flux into each direction (row) per unit flux \
                 arriving in each direction (column), azimuthal mean, ensemble mean; \
                 wavelength × node × node_in"
            );
            s.write(
                &lg,
                name,
                m.view(),
                about("1", &description, &[dim::WAVELENGTH, NODE, NODE_IN]),
            )?;
        }
    }
    s.coordinate(
        &g,
        "above_deg",
        &t.above_deg,
        about(
            "deg",
            "air polar angles of incidence from above; above",
            &[dim::ABOVE],
        ),
    )?;
    for (name, e, what) in [
        ("reflectance", &t.reflectance, "total reflectance"),
        (
            "transmittance",
            &t.transmittance,
            "total transmittance into the air below",
        ),
        ("absorption", &t.absorption, "absorbed fraction"),
    ] {
        let description =
            format!("{what} of the stack in air, without paper, ensemble mean; wavelength × above");
        write_estimate(
            s,
            &g,
            name,
            e,
            about("1", &description, &[dim::WAVELENGTH, dim::ABOVE]),
        )?;
    }

    let a = file.create_group("appearance")?;
    let (ill, obs) = t.conditions;
    write_str_attr(&a, "illuminant", ill.name())?;
    write_str_attr(&a, "observer", obs.name())?;
    write_scalar_attr(&a, "observer_deg", obs.degrees())?;
    write_scalar_attr(&a, "realisations", t.realisations as u64)?;
    s.coordinate(
        &a,
        "viewing_deg",
        &t.viewing_deg,
        about("deg", "viewing polar angles; viewing", &[dim::VIEWING]),
    )?;
    write_estimate(
        s,
        &a,
        "natural",
        &t.natural,
        about(
            "1",
            "radiance factor of the stack on its substrate under a uniform white sky, \
             specular included; wavelength × viewing",
            &[dim::WAVELENGTH, dim::VIEWING],
        ),
    )?;
    if let Some(brdf) = &t.brdf_total {
        s.coordinate(
            &a,
            "illumination_deg",
            &t.illumination_deg,
            about(
                "deg",
                "illumination polar angles of the BRDF and the tile; illumination",
                &[dim::ILLUMINATION],
            ),
        )?;
        write_estimate(
            s,
            &a,
            "brdf_total",
            brdf,
            about(
                "sr-1",
                "diffuse BRDF of the stack on its substrate in the plane of incidence on the \
                 specular side (azimuthal Fourier terms of the layers added), ensemble mean; \
                 wavelength × illumination × viewing",
                LIV,
            ),
        )?;
    }
    if let Some(c) = &t.colours {
        write_colours(s, &a, c)?;
    }
    if !t.measured.is_empty() {
        let mg = a.create_group("measured")?;
        for m in &t.measured {
            write_measured(s, &mg, m)?;
        }
    }
    write_baselines(s, &a, &t.baseline)?;
    if let Some(png) = tile_png {
        let description = "the tile picture as a PNG file (encoded bytes, no units); byte";
        s.write(&a, "tile_png", png, about("", description, &[dim::BYTE]))?;
    }
    Ok(())
}

/// The mean reflectance, transmittance and absorption of a stack solved
/// layer by layer (`/stack`, over wavelengths and angles, the stack in air
/// without paper); None for any other result.
pub fn read_stack_totals(path: &std::path::Path) -> Result<Option<[f64; 3]>, super::IoError> {
    let hdf = |source| super::IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = super::open(path).map_err(hdf)?;
    if !file.link_exists("stack/reflectance") {
        return Ok(None);
    }
    let mean = |name: &str| -> Result<f64, super::IoError> {
        let v: Vec<f64> = file
            .dataset(&format!("stack/{name}"))
            .and_then(|d| d.read_raw())
            .map_err(hdf)?;
        Ok(v.iter().sum::<f64>() / v.len().max(1) as f64)
    };
    Ok(Some([
        mean("reflectance")?,
        mean("transmittance")?,
        mean("absorption")?,
    ]))
}
