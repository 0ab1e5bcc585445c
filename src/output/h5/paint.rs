//! The result file of an effect paint (layout: docs/FORMAT.md, "Effect
//! paint results"): the root attributes of every result (`format_version`,
//! `inksim_version`, `config_path`, `input_hash`, `created_unix_s`) with
//! `kind = "paint"`, `/config` and `/plan`, and the `/paint` group: the
//! in-plane BRDF per wavelength on the model's air directions, the mirror
//! reflectance and albedo per direction, the multi-angle reflectance factors
//! and colours (illuminant and observer as attributes), the flop index, the
//! sparkle figures per illumination angle, the graininess, and the pictures.
//! Written atomically; [`read_paint`] reads back what the CSV export and the
//! tests need.

use std::path::Path;

use ndarray::{Array2, Array3};

use super::attrs::{read_str_attr, write_scalar_attr, write_str_attr};
use super::described::{about, dim, Scales};
use super::result::{write_hdf5, write_identity, write_texts, Identity};
use super::IoError;

/// The root attribute `kind` of a paint result.
pub const PAINT_KIND: &str = "paint";

/// Dimension names of the paint group.
mod pdim {
    pub const GEOMETRY: &str = "geometry";
    pub const DIRECTION: &str = "direction_deg";
    pub const VIEW: &str = "view_deg";
    pub const SPARKLE_ILLUMINATION: &str = "sparkle_illumination_deg";
}

/// One multi-angle geometry's colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleRecord {
    pub illumination_deg: f64,
    pub aspecular_deg: f64,
    pub xyz: [f64; 3],
    pub lab: [f64; 3],
    /// L*, C*ab, h (°).
    pub lch: [f64; 3],
}

impl AngleRecord {
    /// `45as15`.
    pub fn label(&self) -> String {
        format!("{}as{}", self.illumination_deg, self.aspecular_deg)
    }
}

/// Sparkle under one directional light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparkleRecord {
    pub illumination_deg: f64,
    pub glints_per_mm2: f64,
    pub glints_per_cell: f64,
    /// Luminous reflectance (Y/100) of a flake at the glint's local angle.
    pub glint_reflectance: f64,
}

/// The sparkle figures of a paint.
#[derive(Debug, Clone, PartialEq)]
pub struct SparkleTable {
    pub viewing_distance_mm: f64,
    pub acceptance_deg: f64,
    pub cell_area_mm2: f64,
    pub flakes_per_mm2: f64,
    /// Relative fluctuation of the flakes per cell under diffuse light.
    pub graininess: f64,
    pub rows: Vec<SparkleRecord>,
}

/// What a paint result holds.
#[derive(Debug, Clone)]
pub struct PaintResultSet<'a> {
    pub identity: Identity<'a>,
    pub config_text: &'a str,
    pub plan: &'a str,
    pub wavelengths_nm: &'a [f64],
    /// Polar angles in air of the model's escaping directions.
    pub directions_deg: &'a [f64],
    /// `f` (1/sr), wavelength × illumination direction × view, the view's
    /// signed polar angle in the plane of incidence ([`Self::view_deg`]).
    pub brdf: &'a Array3<f64>,
    /// Signed view angles: negative on the light's side.
    pub view_deg: &'a [f64],
    /// wavelength × direction.
    pub mirror: &'a Array2<f64>,
    /// Directional–hemispherical reflectance, wavelength × direction.
    pub albedo: &'a Array2<f64>,
    /// Fourier terms kept per wavelength.
    pub terms: &'a [u64],
    /// Reflectance factor per geometry and wavelength.
    pub factors: &'a Array2<f64>,
    pub colours: &'a [AngleRecord],
    pub illuminant: &'a str,
    pub observer_deg: u32,
    pub flop_index: Option<f64>,
    pub sparkle: Option<&'a SparkleTable>,
    pub tile_png: &'a [u8],
    pub flop_png: &'a [u8],
}

/// Write a paint result atomically.
pub fn write_paint(path: &Path, set: &PaintResultSet) -> Result<(), IoError> {
    for (what, s) in [
        ("config text", set.config_text),
        ("plan", set.plan),
        ("config_path", set.identity.config_path),
    ] {
        if s.contains('\0') {
            return Err(IoError::Invalid {
                path: path.to_path_buf(),
                what: what.into(),
                message: "contains a NUL character".into(),
            });
        }
    }
    write_hdf5(path, |file| write_contents(file, set))
}

fn write_contents(file: &hdf5::File, set: &PaintResultSet) -> hdf5::Result<()> {
    write_identity(file, &set.identity)?;
    write_str_attr(file, "kind", PAINT_KIND)?;
    let mut scales = Scales::default();
    let s = &mut scales;
    write_texts(
        s,
        file,
        set.config_text,
        "the paint's exact TOML text (text, no units)",
        set.plan,
        "what the run computed, one line per part (text, no units)",
    )?;
    let g = file.create_group("paint")?;
    write_str_attr(
        &g,
        "description",
        "an effect paint by the fast model (adding–doubling of its layers in azimuthal Fourier \
         terms, flakes as oriented mirrors; METHOD §9)",
    )?;
    write_str_attr(&g, "illuminant", set.illuminant)?;
    write_scalar_attr(&g, "observer_deg", set.observer_deg)?;
    s.coordinate(
        &g,
        "wavelength_nm",
        set.wavelengths_nm,
        about("nm", "vacuum wavelength; wavelength", &[dim::WAVELENGTH]),
    )?;
    s.coordinate(
        &g,
        "direction_deg",
        set.directions_deg,
        about(
            "deg",
            "polar angle in air of the model's directions that leave the paint (illumination \
             of the BRDF, mirror reflectance and albedo); direction",
            &[pdim::DIRECTION],
        ),
    )?;
    s.coordinate(
        &g,
        "view_deg",
        set.view_deg,
        about(
            "deg",
            "view in the plane of incidence: polar angle in air, negative on the light's side \
             of the normal, positive on the mirror direction's side; view",
            &[pdim::VIEW],
        ),
    )?;
    s.write(
        &g,
        "brdf",
        set.brdf.view(),
        about(
            "sr-1",
            "BRDF f of the scattered light (the mirror reflection excluded) in the plane of \
             incidence, Fejér-summed over the Fourier terms; wavelength × illumination \
             direction × view",
            &[dim::WAVELENGTH, pdim::DIRECTION, pdim::VIEW],
        ),
    )?;
    s.write(
        &g,
        "mirror_reflectance",
        set.mirror.view(),
        about(
            "1",
            "reflectance into the mirror direction (surface, metal ground, their round trips); \
             wavelength × direction",
            &[dim::WAVELENGTH, pdim::DIRECTION],
        ),
    )?;
    s.write(
        &g,
        "albedo",
        set.albedo.view(),
        about(
            "1",
            "directional–hemispherical reflectance (mirror part included); wavelength × \
             direction",
            &[dim::WAVELENGTH, pdim::DIRECTION],
        ),
    )?;
    s.write(
        &g,
        "fourier_terms",
        set.terms,
        about(
            "1",
            "azimuthal Fourier terms kept; wavelength",
            &[dim::WAVELENGTH],
        ),
    )?;
    write_multiangle(s, &g, set)?;
    if let Some(sp) = set.sparkle {
        write_sparkle(s, &g, sp)?;
    }
    s.write(
        &g,
        "tile_png",
        set.tile_png,
        about(
            "",
            "the multi-angle patches as a PNG file (encoded bytes, no units); byte",
            &[dim::BYTE],
        ),
    )?;
    s.write(
        &g,
        "flop_png",
        set.flop_png,
        about(
            "",
            "the flop plot as a PNG file (encoded bytes, no units); byte",
            &[dim::BYTE],
        ),
    )?;
    Ok(())
}

fn write_multiangle(s: &mut Scales, g: &hdf5::Group, set: &PaintResultSet) -> hdf5::Result<()> {
    let m = g.create_group("multiangle")?;
    write_str_attr(
        &m,
        "description",
        "ASTM E2194 / E2539, DIN 6175-2: 45° illumination at aspecular −15°, 15°, 25°, 45°, \
         75°, 110° and 15° illumination at −15°, 15°, 25°, 45°, 75°; the aspecular angle from \
         the mirror direction towards the normal",
    )?;
    write_str_attr(&m, "illuminant", set.illuminant)?;
    write_scalar_attr(&m, "observer_deg", set.observer_deg)?;
    let c = set.colours;
    let col = |f: &dyn Fn(&AngleRecord) -> f64| c.iter().map(f).collect::<Vec<f64>>();
    let geometry = &[pdim::GEOMETRY][..];
    s.write(
        &m,
        "illumination_deg",
        &col(&|r| r.illumination_deg)[..],
        about("deg", "illumination polar angle; geometry", geometry),
    )?;
    s.write(
        &m,
        "aspecular_deg",
        &col(&|r| r.aspecular_deg)[..],
        about("deg", "aspecular angle of the view; geometry", geometry),
    )?;
    s.write(
        &m,
        "reflectance_factor",
        set.factors.view(),
        about(
            "1",
            "reflectance factor π f of the scattered light; geometry × wavelength",
            &[pdim::GEOMETRY, dim::WAVELENGTH],
        ),
    )?;
    let table = |f: &dyn Fn(&AngleRecord) -> [f64; 3]| {
        Array2::from_shape_fn((c.len(), 3), |(i, k)| f(&c[i])[k])
    };
    s.write(
        &m,
        "xyz",
        table(&|r| r.xyz).view(),
        about(
            "1",
            "CIE X, Y, Z (Y of the perfect diffuser = 100); geometry × tristimulus",
            &[pdim::GEOMETRY, dim::TRISTIMULUS],
        ),
    )?;
    s.write(
        &m,
        "lab",
        table(&|r| r.lab).view(),
        about(
            "1",
            "CIELAB L*, a*, b* (white: the perfect diffuser); geometry × lab",
            &[pdim::GEOMETRY, dim::LAB],
        ),
    )?;
    s.write(
        &m,
        "lch",
        table(&|r| r.lch).view(),
        about(
            "1",
            "L*, C*ab, hue angle h in degrees; geometry × lch",
            &[pdim::GEOMETRY, dim::LCH],
        ),
    )?;
    if let Some(fi) = set.flop_index {
        let d = m.new_dataset::<f64>().shape(()).create("flop_index")?;
        d.write_scalar(&fi)?;
        s.describe(
            &d,
            about(
                "1",
                "flop index 2.69 (L*15 − L*110)^1.11 / (L*45)^0.86 at 45° illumination \
                 (absent when L*45 is 0)",
                &[],
            ),
        )?;
    }
    Ok(())
}

fn write_sparkle(s: &mut Scales, g: &hdf5::Group, sp: &SparkleTable) -> hdf5::Result<()> {
    let k = g.create_group("sparkle")?;
    write_str_attr(
        &k,
        "description",
        "Poisson glints per resolution cell (the eye's 1 arcminute at the viewing distance) \
         under a small light at each illumination angle, viewed along the normal; none under \
         diffuse light, where the graininess remains",
    )?;
    for (name, v, units, description) in [
        (
            "viewing_distance_mm",
            sp.viewing_distance_mm,
            "mm",
            "viewing distance",
        ),
        (
            "acceptance_deg",
            sp.acceptance_deg,
            "deg",
            "acceptance half-angle of a glint about the half vector, in the lacquer",
        ),
        (
            "cell_area_mm2",
            sp.cell_area_mm2,
            "mm2",
            "area of one resolution cell",
        ),
        (
            "flakes_per_mm2",
            sp.flakes_per_mm2,
            "mm-2",
            "flakes per mm² of paint, every flake layer",
        ),
        (
            "graininess",
            sp.graininess,
            "1",
            "relative fluctuation of the flakes per resolution cell under diffuse light, \
             1/√(flakes per cell)",
        ),
    ] {
        let d = k.new_dataset::<f64>().shape(()).create(name)?;
        d.write_scalar(&v)?;
        s.describe(&d, about(units, description, &[]))?;
    }
    let col = |f: fn(&SparkleRecord) -> f64| sp.rows.iter().map(f).collect::<Vec<f64>>();
    s.coordinate(
        &k,
        "illumination_deg",
        &col(|r| r.illumination_deg)[..],
        about(
            "deg",
            "polar angle of the light; sparkle illumination",
            &[pdim::SPARKLE_ILLUMINATION],
        ),
    )?;
    let dims = &[pdim::SPARKLE_ILLUMINATION][..];
    for (name, f, units, description) in [
        (
            "glints_per_mm2",
            (|r: &SparkleRecord| r.glints_per_mm2) as fn(&SparkleRecord) -> f64,
            "mm-2",
            "sparkle density: glints per mm²; sparkle illumination",
        ),
        (
            "glints_per_cell",
            |r: &SparkleRecord| r.glints_per_cell,
            "1",
            "mean glints per resolution cell (Poisson); sparkle illumination",
        ),
        (
            "glint_reflectance",
            |r: &SparkleRecord| r.glint_reflectance,
            "1",
            "sparkle intensity: luminous reflectance (Y/100) of a flake at the glint's local \
             angle; sparkle illumination",
        ),
    ] {
        s.write(&k, name, &col(f)[..], about(units, description, dims))?;
    }
    s.forget(pdim::SPARKLE_ILLUMINATION);
    Ok(())
}

/// What [`read_paint`] gives back.
#[derive(Debug, Clone)]
pub struct PaintRecord {
    /// The SHA-256 of the scene it was computed from (root attribute).
    pub input_hash: String,
    pub illuminant: String,
    pub observer_deg: u32,
    pub colours: Vec<AngleRecord>,
    pub flop_index: Option<f64>,
    pub sparkle: Option<SparkleTable>,
}

/// Whether `path` is a paint result (root attribute `kind = "paint"`).
pub fn is_paint_result(path: &Path) -> Result<bool, IoError> {
    let file = super::open(path).map_err(|source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(read_str_attr(&file, "kind").is_ok_and(|k| k == PAINT_KIND))
}

/// The exact TOML text a paint result was computed from (`/config`) and the
/// path it was read from then (root attribute `config_path`).
pub fn read_paint_config(path: &Path) -> Result<(String, String), IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = super::open(path).map_err(hdf)?;
    let text = file
        .dataset("config")
        .and_then(|d| d.read_scalar::<hdf5::types::VarLenUnicode>())
        .map(|s| s.as_str().to_string())
        .map_err(hdf)?;
    let config_path = read_str_attr(&file, "config_path").map_err(hdf)?;
    Ok((config_path, text))
}

/// The multi-angle colours, flop index and sparkle of a paint result.
pub fn read_paint(path: &Path) -> Result<PaintRecord, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let file = super::open(path).map_err(hdf)?;
    let input_hash = read_str_attr(&file, "input_hash").map_err(hdf)?;
    let g = file.group("paint").map_err(hdf)?;
    let m = g.group("multiangle").map_err(hdf)?;
    let illuminant = read_str_attr(&m, "illuminant").map_err(hdf)?;
    let observer_deg: u32 = m
        .attr("observer_deg")
        .and_then(|a| a.read_scalar())
        .map_err(hdf)?;
    let vec = |name: &str| m.dataset(name).and_then(|d| d.read_raw::<f64>());
    let ill = vec("illumination_deg").map_err(hdf)?;
    let asp = vec("aspecular_deg").map_err(hdf)?;
    let three = |name: &str| -> Result<Array2<f64>, IoError> {
        m.dataset(name)
            .and_then(|d| d.read_2d::<f64>())
            .map_err(hdf)
    };
    let (xyz, lab, lch) = (three("xyz")?, three("lab")?, three("lch")?);
    if [xyz.nrows(), lab.nrows(), lch.nrows(), asp.len()] != [ill.len(); 4] {
        return Err(IoError::Format {
            path: path.to_path_buf(),
            message: "/paint/multiangle: arrays of different lengths".into(),
        });
    }
    let row = |a: &Array2<f64>, i: usize| [a[[i, 0]], a[[i, 1]], a[[i, 2]]];
    let colours = (0..ill.len())
        .map(|i| AngleRecord {
            illumination_deg: ill[i],
            aspecular_deg: asp[i],
            xyz: row(&xyz, i),
            lab: row(&lab, i),
            lch: row(&lch, i),
        })
        .collect();
    let flop_index = match m.dataset("flop_index") {
        Ok(d) => Some(d.read_scalar::<f64>().map_err(hdf)?),
        Err(_) => None,
    };
    let sparkle = match g.group("sparkle") {
        Err(_) => None,
        Ok(k) => {
            let scalar = |name: &str| k.dataset(name).and_then(|d| d.read_scalar::<f64>());
            let col = |name: &str| k.dataset(name).and_then(|d| d.read_raw::<f64>());
            let illumination = col("illumination_deg").map_err(hdf)?;
            let (density, per_cell, refl) = (
                col("glints_per_mm2").map_err(hdf)?,
                col("glints_per_cell").map_err(hdf)?,
                col("glint_reflectance").map_err(hdf)?,
            );
            Some(SparkleTable {
                viewing_distance_mm: scalar("viewing_distance_mm").map_err(hdf)?,
                acceptance_deg: scalar("acceptance_deg").map_err(hdf)?,
                cell_area_mm2: scalar("cell_area_mm2").map_err(hdf)?,
                flakes_per_mm2: scalar("flakes_per_mm2").map_err(hdf)?,
                graininess: scalar("graininess").map_err(hdf)?,
                rows: (0..illumination.len())
                    .map(|i| SparkleRecord {
                        illumination_deg: illumination[i],
                        glints_per_mm2: density[i],
                        glints_per_cell: per_cell[i],
                        glint_reflectance: refl[i],
                    })
                    .collect(),
            })
        }
    };
    Ok(PaintRecord {
        input_hash,
        illuminant,
        observer_deg,
        colours,
        flop_index,
        sparkle,
    })
}
