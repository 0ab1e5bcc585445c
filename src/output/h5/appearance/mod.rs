//! The `/appearance` group, written from an [`Appearance`] (ensemble means
//! with their standard errors), every dataset with its units, meaning and
//! axes; read back by `appearance_read`.

pub mod hiding;

use ndarray::Array2;

use super::attrs::{write_scalar_attr, write_str_attr};
use super::described::{about, dim, standard_error, About, Scales};
use crate::config::Baseline;
use crate::optics::appearance::{Appearance, Colours, Estimate, MeasuredColour};
use crate::optics::baseline::BaselineColour;

pub(super) fn write_estimate<D: ndarray::Dimension>(
    s: &Scales,
    g: &hdf5::Group,
    name: &str,
    e: &Estimate<D>,
    a: About,
) -> hdf5::Result<()> {
    s.write(g, name, e.mean.view(), a)?;
    if let Some(se) = &e.se {
        let description = standard_error(a.description);
        let a = About {
            description: &description,
            ..a
        };
        s.write(g, &format!("{name}_se"), se.view(), a)?;
    }
    Ok(())
}

const LA: &[&str] = &[dim::WAVELENGTH, dim::ABOVE];
pub(super) const LIV: &[&str] = &[dim::WAVELENGTH, dim::ILLUMINATION, dim::VIEWING];
const LINN: &[&str] = &[dim::WAVELENGTH, dim::ILLUMINATION, dim::SY, dim::SX];
const TILE: &[&str] = &[dim::VIEWING, dim::TILE_COLUMN];

pub(super) fn write_appearance(
    file: &hdf5::File,
    a: &Appearance,
    tile_png: Option<&[u8]>,
    s: &mut Scales,
) -> hdf5::Result<()> {
    let g = file.create_group("appearance")?;
    let sp = &a.spec;
    let below = sp.below.as_ref().map(|h| h.polar_deg()).unwrap_or_default();
    for (name, v, units, dims, description) in [
        (
            "wavelengths_nm",
            &sp.wavelengths_nm,
            "nm",
            dim::WAVELENGTH,
            "vacuum wavelengths solved; wavelength",
        ),
        (
            "above_deg",
            &sp.above_deg,
            "deg",
            dim::ABOVE,
            "polar angles of incidence solved from above (the ink side); \
             above",
        ),
        (
            "illumination_deg",
            &sp.illumination_deg,
            "deg",
            dim::ILLUMINATION,
            "illumination polar angles of the BRDF and the tile; \
             illumination",
        ),
        (
            "viewing_deg",
            &sp.viewing_deg,
            "deg",
            dim::VIEWING,
            "viewing polar angles in the plane of incidence; viewing",
        ),
        (
            "below_deg",
            &below,
            "deg",
            dim::BELOW,
            "polar angles of the quadrature nodes solved from below (the layer flipped; \
             empty without them); below",
        ),
    ] {
        s.coordinate(&g, name, v, about(units, description, &[dims]))?;
    }
    write_scalar_attr(&g, "azimuth_deg", sp.azimuth_deg)?;
    write_scalar_attr(&g, "table_cell", sp.table.cell)?;
    write_scalar_attr(&g, "realisations", sp.realisations as u64)?;
    for (name, e, what) in [
        (
            "reflectance",
            &a.reflectance,
            "total reflectance, all orders",
        ),
        (
            "transmittance",
            &a.transmittance,
            "total transmittance, all orders",
        ),
        ("absorption", &a.absorption, "absorbed fraction"),
    ] {
        let description = format!("{what}, ensemble mean; wavelength × above");
        write_estimate(s, &g, name, e, about("1", &description, LA))?;
    }
    for (name, v, description) in [
        (
            "specular_coherent",
            &a.specular_coherent,
            "coherent specular reflectance |⟨r00⟩|²; wavelength × above",
        ),
        (
            "specular_incoherent",
            &a.specular_incoherent,
            "incoherent specular reflectance ⟨|r00|²⟩ − |⟨r00⟩|²; wavelength × above",
        ),
        (
            "direct_coherent",
            &a.direct_coherent,
            "coherent direct transmittance |⟨t00⟩|²; wavelength × above",
        ),
        (
            "direct_incoherent",
            &a.direct_incoherent,
            "incoherent direct transmittance ⟨|t00|²⟩ − |⟨t00⟩|²; wavelength × above",
        ),
    ] {
        s.write(&g, name, v.view(), about("1", description, LA))?;
    }
    let table = |what: &str| {
        format!(
            "{what} power density per projected solid angle on the table nodes \
             s = sin θ (cos φ, sin φ) = (i − N/2, j − N/2)·table_cell (rows j along s_y); \
             the {} is bilinear(table) / bilinear(table_coverage); \
             wavelength × illumination × sy × sx",
            if what == "reflected" { "BRDF" } else { "BTDF" }
        )
    };
    write_estimate(
        s,
        &g,
        "brdf_table",
        &a.brdf_table,
        about("sr-1", &table("reflected"), LINN),
    )?;
    let nt = sp.table.n();
    let coverage = ndarray::Array2::from_shape_fn((nt, nt), |(j, i)| {
        crate::optics::farfield::table::node_coverage(sp.table, i, j)
    });
    let description = "share of each table node's bilinear kernel above the horizon; the \
                       BRDF/BTDF is bilinear(table) / bilinear(table_coverage); sy × sx";
    s.write(
        &g,
        "table_coverage",
        coverage.view(),
        about("1", description, &[dim::SY, dim::SX]),
    )?;
    let description = "diffuse BRDF of the layer alone in the plane of incidence, specular \
                       side; wavelength × illumination × viewing";
    write_estimate(
        s,
        &g,
        "brdf_diffuse",
        &a.brdf_diffuse,
        about("sr-1", description, LIV),
    )?;
    if let Some(t) = &a.btdf_table {
        write_estimate(
            s,
            &g,
            "btdf_table",
            t,
            about("sr-1", &table("transmitted"), LINN),
        )?;
    }
    if let Some(t) = &a.btdf_diffuse {
        let description = "diffuse BTDF of the layer alone in the plane of incidence, forward \
                           side; wavelength × illumination × viewing";
        write_estimate(s, &g, "btdf_diffuse", t, about("sr-1", description, LIV))?;
    }
    if let Some(p) = &a.paper {
        if let Some(albedo) = p.ground.constant() {
            write_scalar_attr(&g, "paper_albedo", albedo)?;
        }
        let description = "albedo of the ground under the layer (paper, a white or measured \
                           ground, a chart's white half) at the solved wavelengths; wavelength";
        s.write(
            &g,
            "ground_albedo",
            p.albedo.view(),
            about("1", description, &[dim::WAVELENGTH]),
        )?;
        let description =
            "albedo of the layer for diffuse light from below (the paper's side); wavelength";
        write_estimate(
            s,
            &g,
            "r_dd_up",
            &p.r_dd_up,
            about("1", description, &[dim::WAVELENGTH]),
        )?;
        let description = "diffuse transmittance of the layer; wavelength";
        write_estimate(
            s,
            &g,
            "t_d",
            &p.t_d,
            about("1", description, &[dim::WAVELENGTH]),
        )?;
    }
    if let Some(t) = &a.brdf_total {
        let description = "diffuse BRDF of the layer on its substrate in the plane of incidence; \
                           wavelength × illumination × viewing";
        s.write(&g, "brdf_total", t.view(), about("sr-1", description, LIV))?;
    }
    if let Some(n) = &a.natural {
        let description = "radiance factor under a uniform white sky; wavelength × viewing";
        s.write(
            &g,
            "natural",
            n.view(),
            about("1", description, &[dim::WAVELENGTH, dim::VIEWING]),
        )?;
    }
    if let Some(c) = &a.colours {
        write_colours(s, &g, c)?;
    }
    if let Some((ill, obs)) = a.colour_conditions {
        write_str_attr(&g, "illuminant", ill.name())?;
        write_str_attr(&g, "observer", obs.name())?;
        write_scalar_attr(&g, "observer_deg", obs.degrees())?;
    }
    if !a.measured.is_empty() {
        let mg = g.create_group("measured")?;
        for m in &a.measured {
            write_measured(s, &mg, m)?;
        }
    }
    if !a.measured_black.is_empty() {
        let mg = g.create_group("measured_black")?;
        write_str_attr(
            &mg,
            "description",
            "the colours over a hiding chart's black half (the layer alone), from the same \
             solves as /appearance/measured (over its white half)",
        )?;
        for m in &a.measured_black {
            write_measured(s, &mg, m)?;
        }
    }
    hiding::write_hiding(s, &g, &a.hiding, sp.thickness_nm)?;
    write_baselines(s, &g, &a.baseline)?;
    if let Some(png) = tile_png {
        let description = "the tile picture as a PNG file (encoded bytes, no units); byte";
        s.write(&g, "tile_png", png, about("", description, &[dim::BYTE]))?;
    }
    Ok(())
}

/// The tile's and the white sky's colours, with their spread.
pub(super) fn write_colours(s: &Scales, g: &hdf5::Group, c: &Colours) -> hdf5::Result<()> {
    let cells = "the tile's cells (column 0 under the uniform white sky, then one per \
                 illumination angle)";
    let description = format!("sRGB 8-bit code values of {cells}; viewing × tile column × R, G, B");
    let dims = [dim::VIEWING, dim::TILE_COLUMN, dim::RGB];
    s.write(
        g,
        "tile_srgb8",
        c.tile_srgb8.view(),
        about("1", &description, &dims),
    )?;
    let description =
        format!("CIELAB L*, a*, b* (D65 white) of {cells}; viewing × tile column × L*, a*, b*");
    let dims = [dim::VIEWING, dim::TILE_COLUMN, dim::LAB];
    s.write(
        g,
        "tile_lab",
        c.tile_lab.view(),
        about("1", &description, &dims),
    )?;
    let rgb = Array2::from_shape_fn((c.natural_srgb8.len(), 3), |(i, j)| c.natural_srgb8[i][j]);
    let description = "sRGB 8-bit code values under a uniform white sky; viewing × R, G, B";
    s.write(
        g,
        "natural_srgb8",
        &rgb,
        about("1", description, &[dim::VIEWING, dim::RGB]),
    )?;
    let lab = Array2::from_shape_fn((c.natural_lab.len(), 3), |(i, j)| c.natural_lab[i][j]);
    let description =
        "CIELAB L*, a*, b* (D65 white) under a uniform white sky; viewing × L*, a*, b*";
    s.write(
        g,
        "natural_lab",
        &lab,
        about("1", description, &[dim::VIEWING, dim::LAB]),
    )?;
    if let Some(sp) = &c.spread {
        let description =
            "standard error of the tile's L*, a*, b*; viewing × tile column × L*, a*, b*";
        let dims = [dim::VIEWING, dim::TILE_COLUMN, dim::LAB];
        s.write(
            g,
            "tile_lab_se",
            sp.lab_se.view(),
            about("1", description, &dims),
        )?;
        let description = "standard error of each tile colour in ΔE00; viewing × tile column";
        s.write(
            g,
            "tile_de00_se",
            sp.de00_se.view(),
            about("1", description, TILE),
        )?;
        let description =
            "CIELAB of every realisation's tile; realisation × viewing × tile column × L*, a*, b*";
        let dims = [dim::REALISATION, dim::VIEWING, dim::TILE_COLUMN, dim::LAB];
        s.write(
            g,
            "tile_lab_realisations",
            sp.realisation_lab.view(),
            about("1", description, &dims),
        )?;
    }
    Ok(())
}

/// `/appearance/measured/<slug>`: one measurement geometry's colour.
pub(super) fn write_measured(
    s: &mut Scales,
    parent: &hdf5::Group,
    m: &MeasuredColour,
) -> hdf5::Result<()> {
    let g = parent.create_group(m.geometry.slug())?;
    write_str_attr(&g, "geometry", m.geometry.name())?;
    let description = "reflectance factor in this geometry at the solved wavelengths; wavelength";
    write_estimate(
        s,
        &g,
        "reflectance_factor",
        &m.reflectance,
        about("1", description, &[dim::WAVELENGTH]),
    )?;
    let description =
        "wavelengths of the spectrum the colour is integrated from; spectrum wavelength";
    s.coordinate(
        &g,
        "spectrum_wavelengths_nm",
        &m.spectrum_wavelengths_nm,
        about("nm", description, &[dim::SPECTRUM_WAVELENGTH]),
    )?;
    // One coordinate per geometry: the next geometry's replaces it.
    let description = "reflectance factor the colour is integrated from (through the spectral \
                       proxy where there is one); spectrum wavelength";
    s.write(
        &g,
        "spectrum",
        &m.spectrum[..],
        about("1", description, &[dim::SPECTRUM_WAVELENGTH]),
    )?;
    s.forget(dim::SPECTRUM_WAVELENGTH);
    let vector = |name: &str, data: &[f64], units: &str, description: &str, d: &str| {
        s.write(&g, name, data, about(units, description, &[d]))
    };
    vector(
        "xyz",
        &m.xyz,
        "1",
        "CIE XYZ, white Y = 100; X, Y, Z",
        dim::TRISTIMULUS,
    )?;
    vector("lab", &m.lab, "1", "CIELAB L*, a*, b*", dim::LAB)?;
    vector(
        "lch",
        &m.lch,
        "1, 1, deg",
        "CIE LCh(ab): L*, C*ab, h_ab",
        dim::LCH,
    )?;
    if let (Some(se), Some(de)) = (m.lab_se, m.de00_se) {
        vector(
            "lab_se",
            &se,
            "1",
            "standard errors of L*, a*, b*",
            dim::LAB,
        )?;
        let description = "standard error of the colour in ΔE00 (one value)";
        vector("de00_se", &[de], "1", description, dim::VALUE)?;
    }
    for (name, rows, what, d) in [
        (
            "xyz_realisations",
            &m.realisation_xyz,
            "CIE XYZ of each realisation's own spectrum, white Y = 100; realisation × X, Y, Z",
            dim::TRISTIMULUS,
        ),
        (
            "lab_realisations",
            &m.realisation_lab,
            "CIELAB of each realisation's own spectrum; realisation × L*, a*, b*",
            dim::LAB,
        ),
    ] {
        if rows.is_empty() {
            continue;
        }
        let a = ndarray::Array2::from_shape_fn((rows.len(), 3), |(r, c)| rows[r][c]);
        s.write(&g, name, a.view(), about("1", what, &[dim::REALISATION, d]))?;
    }
    Ok(())
}

/// `/appearance/baseline`: every baseline model's colours, one group per
/// model in the order first met (nothing when there are none).
pub(super) fn write_baselines(
    s: &mut Scales,
    g: &hdf5::Group,
    baseline: &[BaselineColour],
) -> hdf5::Result<()> {
    if baseline.is_empty() {
        return Ok(());
    }
    let bg = g.create_group("baseline")?;
    let mut models: Vec<Baseline> = Vec::new();
    for b in baseline {
        if !models.contains(&b.model) {
            models.push(b.model);
        }
    }
    let names: Vec<&str> = models.iter().map(|m| m.name()).collect();
    write_str_attr(&bg, "models", &names.join(","))?;
    for model in models {
        let mg = bg.create_group(model.name())?;
        write_str_attr(&mg, "model", model.name())?;
        let mut first = true;
        for b in baseline.iter().filter(|b| b.model == model) {
            if first {
                write_models(&mg, b)?;
                first = false;
            }
            write_baseline(s, &mg, b)?;
        }
    }
    Ok(())
}

/// The grain and surface models a baseline used, on its model's group:
/// `grain_model` and `surface_model` by name, each with a
/// `<attribute>_description`.
fn write_models(g: &hdf5::Group, b: &BaselineColour) -> hdf5::Result<()> {
    write_str_attr(g, "grain_model", b.grains.name())?;
    write_str_attr(g, "grain_model_description", b.grains.description())?;
    write_str_attr(g, "surface_model", b.surfaces.name())?;
    write_str_attr(g, "surface_model_description", b.surfaces.description())
}

/// `/appearance/baseline/<model>/<slug>`: one baseline model's colour in
/// one measurement geometry.
fn write_baseline(s: &mut Scales, parent: &hdf5::Group, b: &BaselineColour) -> hdf5::Result<()> {
    let g = parent.create_group(b.geometry.slug())?;
    write_str_attr(&g, "geometry", b.geometry.name())?;
    let model = b.model.name();
    let description = format!(
        "wavelengths of the {model} spectrum (the spectral proxy's grid); spectrum wavelength"
    );
    s.coordinate(
        &g,
        "spectrum_wavelengths_nm",
        &b.spectrum_wavelengths_nm,
        about("nm", &description, &[dim::SPECTRUM_WAVELENGTH]),
    )?;
    let description = format!(
        "{model} reflectance factor in this geometry ({}); spectrum wavelength",
        b.model.summary()
    );
    s.write(
        &g,
        "reflectance_factor",
        &b.reflectance_factor[..],
        about("1", &description, &[dim::SPECTRUM_WAVELENGTH]),
    )?;
    // One coordinate per geometry: the next geometry's replaces it.
    s.forget(dim::SPECTRUM_WAVELENGTH);
    let description = format!("CIELAB L*, a*, b* of the {model} spectrum");
    s.write(&g, "lab", &b.lab[..], about("1", &description, &[dim::LAB]))?;
    if let Some(de) = b.de00_to_wave {
        let description = format!(
            "CIEDE2000 from the {model} colour to the wave solution's colour in the same \
             geometry (/appearance/measured); one value"
        );
        s.write(
            &g,
            "de00_to_wave",
            &[de][..],
            about("1", &description, &[dim::VALUE]),
        )?;
    }
    Ok(())
}
