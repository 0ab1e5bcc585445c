//! The writer: a [`ResultSet`] checked, then written atomically in the
//! layout of docs/FORMAT.md (root attributes, `/config`, `/plan`,
//! `/geometry`, `/realisations`, `/solves`, `/summary`, `/picture_png`; the
//! `/geometry` group through the `geometry` module, the `/appearance` group
//! through the `appearance` module).

use crate::config::Equation;
use std::path::Path;

use hdf5::types::VarLenUnicode;
use hdf5::{H5Type, Location};
use ndarray::Array2;

use super::appearance::write_appearance;
use super::attrs::{vlu, write_scalar_attr, write_str_attr};
use super::described::{about, dim, Scales};
use super::geometry::{write_geometry, GeometrySummary};
use super::stack::{write_stack, StackTables};
use super::{IoError, FORMAT_VERSION};
use crate::optics::appearance::Appearance;
use crate::optics::farfield::{Side, SolveEntry};
use crate::output::atomic::write_atomic_with;

/// Everything a result file holds; plain data filled by the pipeline.
#[derive(Debug, Clone, Copy)]
pub struct ResultSet<'a> {
    pub version: &'a str,
    pub config_path: &'a str,
    /// The exact TOML text of the scene.
    pub config_text: &'a str,
    pub input_hash: &'a str,
    /// The run's plan, one line per decision: what ran, what was skipped, why.
    pub plan: &'a str,
    pub seed: u64,
    pub created_unix_s: u64,
    pub geometry: GeometrySummary<'a>,
    /// Raster grid: nx, ny, nz.
    pub grid: [usize; 3],
    /// Fragment size: Lx, Ly, H in nm.
    pub size_nm: [f64; 3],
    pub entries: &'a [SolveEntry],
    pub picture_png: Option<&'a [u8]>,
    /// Seed and achieved PVC of each realisation.
    pub realisations: &'a [(u64, f64)],
    /// Why the realisations stopped, when the scene gave a target.
    pub realisation_stop: Option<RealisationStop>,
    pub appearance: Option<&'a Appearance>,
    /// The tile PNG (stored in `/appearance`).
    pub tile_png: Option<&'a [u8]>,
    /// A stack solved layer by layer: `/stack` and its colours in
    /// `/appearance` (then `appearance` is None).
    pub stack: Option<&'a StackTables>,
}

/// A run with `realisations = { target_de00, … }`: the target, the standard
/// error reached, and whether the target was met (else the most realisations
/// allowed were run).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RealisationStop {
    pub target_de00: f64,
    /// Largest standard error of ΔE00 to the mean over the measured colours.
    pub de00_se: f64,
    pub target_met: bool,
}

/// Write a result file atomically (layout: docs/FORMAT.md).
///
/// Writes `<path>.tmp` in the same folder (created if missing), closes and
/// syncs it, then renames it onto `path`. On any error the temporary file is
/// removed and an existing `path` is left untouched.
pub fn write_result(path: &Path, set: &ResultSet) -> Result<(), IoError> {
    check_result_set(path, set)?;
    write_hdf5(path, |file| write_contents(file, set))
}

/// Write an HDF5 file atomically by `contents` (`<path>.tmp`, closed,
/// synced, renamed; removed on any error).
pub(super) fn write_hdf5(
    path: &Path,
    contents: impl FnOnce(&hdf5::File) -> hdf5::Result<()>,
) -> Result<(), IoError> {
    write_atomic_with(path, |tmp| {
        let hdf = |source| IoError::Hdf5 {
            path: tmp.to_path_buf(),
            source,
        };
        let file = super::create(tmp).map_err(hdf)?;
        contents(&file).map_err(hdf)?;
        file.close().map_err(hdf)
    })
}

/// The identity every result file carries as root attributes.
#[derive(Debug, Clone, Copy)]
pub struct Identity<'a> {
    pub version: &'a str,
    pub config_path: &'a str,
    pub input_hash: &'a str,
    pub created_unix_s: u64,
}

/// `format_version`, `inksim_version`, `config_path`, `input_hash` and
/// `created_unix_s` on the root.
pub(super) fn write_identity(file: &hdf5::File, id: &Identity) -> hdf5::Result<()> {
    let root: &Location = file;
    write_scalar_attr(root, "format_version", FORMAT_VERSION)?;
    write_str_attr(root, "inksim_version", id.version)?;
    write_str_attr(root, "config_path", id.config_path)?;
    write_str_attr(root, "input_hash", id.input_hash)?;
    write_scalar_attr(root, "created_unix_s", id.created_unix_s)
}

/// `/config` and `/plan`, scalar strings with their descriptions.
pub(super) fn write_texts(
    s: &Scales,
    file: &hdf5::File,
    config: &str,
    config_description: &str,
    plan: &str,
    plan_description: &str,
) -> hdf5::Result<()> {
    for (name, text, description) in [
        ("config", config, config_description),
        ("plan", plan, plan_description),
    ] {
        let d = file.new_dataset::<VarLenUnicode>().shape(()).create(name)?;
        d.write_scalar(&vlu(text)?)?;
        s.describe(&d, about("", description, &[]))?;
    }
    Ok(())
}

/// One row of `/summary`.
#[derive(H5Type, Clone, Copy, Debug)]
#[repr(C)]
struct SummaryRow {
    wavelength_nm: f64,
    polar_deg: f64,
    azimuth_deg: f64,
    reflectance: f64,
    transmittance: f64,
    absorption: f64,
    energy_balance: f64,
    residual: f64,
    iterations: u64,
    /// 0: lit from above (the ink side); 1: from below (the layer flipped,
    /// lit from the paper's side, for the paper term).
    side: u8,
    realisation: u64,
    layer: u64,
}

/// The sign convention of the order indices, stored with `orders_mn`.
pub const ORDER_CONVENTION: &str =
    "order (m, n): lateral wave vector κ = κ_inc + 2π (m/Lx, n/Ly), \
     κ_inc = k0 sin θ (cos φ, sin φ) of the incident wave (light travelling towards +x for \
     φ = 0); the order leaves at sin θ (cos φ, sin φ) = κ/k0, reflected orders back towards \
     the light's side, transmitted ones onward; (0, 0) is the specular (mirror) order";

/// Units and meaning of each `/summary` field, stored as attributes
/// `<field>_units` and `<field>_description` on the dataset.
const SUMMARY_FIELDS: [(&str, &str, &str); 12] = [
    ("wavelength_nm", "nm", "vacuum wavelength"),
    ("polar_deg", "deg", "polar angle of incidence"),
    ("azimuth_deg", "deg", "azimuth of incidence"),
    ("reflectance", "1", "total reflectance, all orders"),
    ("transmittance", "1", "total transmittance, all orders"),
    ("absorption", "1", "absorbed fraction"),
    ("energy_balance", "1", "R + T + A − 1"),
    ("residual", "1", "relative residual of the solve"),
    ("iterations", "1", "solver iterations"),
    (
        "side",
        "1",
        "0: lit from above (the ink side, what a viewer sees); 1: from below (the layer \
         flipped and lit from the paper's side, used for the paper term)",
    ),
    ("realisation", "1", "index of the random fragment (0-based)"),
    (
        "layer",
        "1",
        "index of the layer in a stack solved layer by layer, from the top (0-based; 0 for one \
         layer)",
    ),
];

/// Refuse inconsistent input before any file is touched.
fn check_result_set(path: &Path, set: &ResultSet) -> Result<(), IoError> {
    let invalid = |what: &str, message: String| IoError::Invalid {
        path: path.to_path_buf(),
        what: what.to_string(),
        message,
    };
    let strings = [
        ("inksim_version", set.version),
        ("config_path", set.config_path),
        ("config text", set.config_text),
        ("input_hash", set.input_hash),
        ("plan", set.plan),
    ];
    for (what, s) in strings {
        if s.contains('\0') {
            return Err(invalid(what, "contains a NUL character".into()));
        }
    }
    for (i, e) in set.entries.iter().enumerate() {
        if e.record.note.contains('\0') {
            return Err(invalid(
                &format!("solve {i} note"),
                "contains a NUL character".into(),
            ));
        }
    }
    let g = &set.geometry;
    if let Some(name) = g.species_names.iter().find(|n| n.contains('\0')) {
        return Err(invalid(
            "geometry species_names",
            format!("name {name:?} contains a NUL character"),
        ));
    }
    let n = g.centers_nm.len();
    if g.radii_nm.len() != n || g.particle_of_sphere.len() != n {
        return Err(invalid(
            "geometry",
            format!(
                "sphere arrays differ in length: centers_nm {n}, radii_nm {}, particle_of_sphere {}",
                g.radii_nm.len(),
                g.particle_of_sphere.len()
            ),
        ));
    }
    let s = g.species_names.len();
    for (name, len) in [
        ("target_fraction", g.target_fraction.len()),
        ("achieved_fraction", g.achieved_fraction.len()),
        ("raster_fraction", g.raster_fraction.len()),
    ] {
        if len != s {
            return Err(invalid(
                "geometry",
                format!("{name} has {len} values for {s} species"),
            ));
        }
    }
    Ok(())
}

fn write_contents(file: &hdf5::File, set: &ResultSet) -> hdf5::Result<()> {
    let root: &Location = file;
    write_identity(
        file,
        &Identity {
            version: set.version,
            config_path: set.config_path,
            input_hash: set.input_hash,
            created_unix_s: set.created_unix_s,
        },
    )?;
    write_scalar_attr(root, "seed", set.seed)?;
    let grid = set.grid.map(|v| v as u64);
    root.new_attr_builder()
        .with_data(&grid[..])
        .create("grid")?;
    root.new_attr_builder()
        .with_data(&set.size_nm[..])
        .create("size_nm")?;

    let mut scales = Scales::default();
    let s = &mut scales;
    write_texts(
        s,
        file,
        set.config_text,
        "the scene's exact TOML text (text, no units)",
        set.plan,
        "the run's plan, one line per decision (text, no units)",
    )?;

    write_geometry(s, file, &set.geometry)?;
    let real = file.create_group("realisations")?;
    let seeds: Vec<u64> = set.realisations.iter().map(|r| r.0).collect();
    let pvc: Vec<f64> = set.realisations.iter().map(|r| r.1).collect();
    let description = "seed of each random fragment (realisation); realisation";
    let realisation = &[dim::REALISATION][..];
    s.write(
        &real,
        "seed",
        &seeds[..],
        about("1", description, realisation),
    )?;
    let description = "pigment volume concentration each fragment achieved; realisation";
    s.write(
        &real,
        "achieved_pvc",
        &pvc[..],
        about("1", description, realisation),
    )?;
    if let Some(stop) = set.realisation_stop {
        write_scalar_attr(&real, "target_de00_se", stop.target_de00)?;
        write_scalar_attr(&real, "achieved_de00_se", stop.de00_se)?;
        write_str_attr(
            &real,
            "stopped_because",
            if stop.target_met {
                "target standard error reached"
            } else {
                "most realisations allowed reached"
            },
        )?;
    }

    let solves = file.create_group("solves")?;
    let mut rows = Vec::with_capacity(set.entries.len());
    for (i, e) in set.entries.iter().enumerate() {
        let solve = solves.create_group(&format!("{i:04}"))?;
        write_entry(s, &solve, e)?;
        let eff = &e.efficiencies;
        rows.push(SummaryRow {
            wavelength_nm: e.wavelength_nm,
            polar_deg: e.incidence.polar_deg,
            azimuth_deg: e.incidence.azimuth_deg,
            reflectance: eff.total_reflectance,
            transmittance: eff.total_transmittance,
            absorption: eff.absorption,
            energy_balance: eff.energy_balance,
            residual: e.record.residual,
            iterations: e.record.iterations as u64,
            side: match e.side {
                Side::Above => 0,
                Side::Below => 1,
            },
            realisation: e.realisation as u64,
            layer: e.layer as u64,
        });
    }
    let description = "one row per solve, in solve order; select side == 0 for what a viewer \
                       sees; units and meaning per field in the attributes <field>_units and \
                       <field>_description (a table of mixed units: no units of its own); solve";
    let summary = s.write(
        file,
        "summary",
        &rows[..],
        about("", description, &[dim::SOLVE]),
    )?;
    for (field, units, description) in SUMMARY_FIELDS {
        write_str_attr(&summary, &format!("{field}_units"), units)?;
        write_str_attr(&summary, &format!("{field}_description"), description)?;
    }

    if let Some(png) = set.picture_png {
        let description = "the rendered picture as a PNG file (encoded bytes, no units); byte";
        s.write(
            file,
            "picture_png",
            png,
            about("", description, &[dim::BYTE]),
        )?;
    }
    if let Some(app) = set.appearance {
        write_appearance(file, app, set.tile_png, s)?;
    } else if let Some(st) = set.stack {
        write_stack(file, st, set.tile_png, s)?;
    }
    file.flush()
}

fn write_entry(s: &Scales, g: &hdf5::Group, e: &SolveEntry) -> hdf5::Result<()> {
    let eff = &e.efficiencies;
    let rec = &e.record;
    for (name, v) in [
        ("wavelength_nm", e.wavelength_nm),
        ("polar_deg", e.incidence.polar_deg),
        ("azimuth_deg", e.incidence.azimuth_deg),
        ("residual", rec.residual),
        ("seconds", rec.seconds),
    ]
    .into_iter()
    .chain(eff.totals())
    {
        write_scalar_attr(g, name, v)?;
    }
    g.new_attr_builder()
        .with_data(&[eff.r00.re, eff.r00.im][..])
        .create("r00")?;
    g.new_attr_builder()
        .with_data(&[eff.t00.re, eff.t00.im][..])
        .create("t00")?;
    write_str_attr(g, "method", &rec.method.to_string())?;
    write_str_attr(g, "side", &e.side.to_string())?;
    write_scalar_attr(g, "realisation", e.realisation as u64)?;
    write_scalar_attr(g, "iterations", rec.iterations as u64)?;
    write_scalar_attr(g, "operator_applications", rec.operator_applications as u64)?;
    write_str_attr(g, "note", &rec.note)?;

    let k = eff.orders.len();
    let mn = Array2::from_shape_fn((k, 2), |(i, j)| {
        if j == 0 {
            eff.orders[i].m
        } else {
            eff.orders[i].n
        }
    });
    let description =
        format!("indices of the propagating orders; order × (m, n). {ORDER_CONVENTION}");
    s.write(
        g,
        "orders_mn",
        &mn,
        about("1", &description, &[dim::ORDER, dim::MN]),
    )?;
    let column = |f: fn(&crate::optics::farfield::Order) -> f64| {
        eff.orders.iter().map(f).collect::<Vec<_>>()
    };
    for (name, values, units, description) in [
        (
            "orders_theta_deg",
            column(|o| o.theta_deg),
            "deg",
            "polar angle each order leaves at; order",
        ),
        (
            "orders_phi_deg",
            column(|o| o.phi_deg),
            "deg",
            "azimuth each order leaves at; order",
        ),
        (
            "orders_reflectance",
            column(|o| o.reflectance),
            "1",
            "share of the incident power reflected into each order; order",
        ),
        (
            "orders_transmittance",
            column(|o| o.transmittance),
            "1",
            "share of the incident power transmitted into each order; order",
        ),
    ] {
        s.write(
            g,
            name,
            &values[..],
            about(units, description, &[dim::ORDER]),
        )?;
    }
    write_polarised(s, g, e)
}

/// Maxwell solves: the equation and polarisation as attributes, and each
/// incident polarisation's totals (attributes `<total>_s`, `<total>_p`) and
/// order efficiencies (`orders_reflectance_s`, …) beside their mean.
fn write_polarised(s: &Scales, g: &hdf5::Group, e: &SolveEntry) -> hdf5::Result<()> {
    if let Some(phi) = e.random_phase_deg {
        write_str_attr(g, "equation", Equation::Maxwell.name())?;
        write_scalar_attr(g, "random_phase_deg", phi)?;
        return write_str_attr(
            g,
            "polarisation",
            &format!(
                "unpolarised: one random-phase state (s + exp(i phi) p)/sqrt 2 at phi = \
                 {phi:.2} deg, whose s-p cross term averages out over the realisations"
            ),
        );
    }
    if e.polarised.is_empty() {
        write_str_attr(g, "equation", Equation::Helmholtz.name())?;
        return write_str_attr(
            g,
            "polarisation",
            "none (scalar wave: surfaces reflect as s)",
        );
    }
    write_str_attr(g, "equation", Equation::Maxwell.name())?;
    let names: Vec<&str> = e.polarised.iter().map(|(p, _)| p.name()).collect();
    write_str_attr(
        g,
        "polarisation",
        &if names.len() > 1 {
            format!(
                "unpolarised: the mean of {} solved apart",
                names.join(" and ")
            )
        } else {
            names[0].to_string()
        },
    )?;
    for (pol, eff) in &e.polarised {
        let p = pol.name();
        for (name, v) in eff.totals() {
            write_scalar_attr(g, &format!("{name}_{p}"), v)?;
        }
        for (name, values, what) in [
            (
                "orders_reflectance",
                eff.orders
                    .iter()
                    .map(|o| o.reflectance)
                    .collect::<Vec<f64>>(),
                "reflected",
            ),
            (
                "orders_transmittance",
                eff.orders.iter().map(|o| o.transmittance).collect(),
                "transmitted",
            ),
        ] {
            let description = format!(
                "share of the incident {p}-polarised power {what} into each order (both \
                 outgoing polarisations summed); order"
            );
            s.write(
                g,
                &format!("{name}_{p}"),
                &values[..],
                about("1", &description, &[dim::ORDER]),
            )?;
        }
    }
    Ok(())
}
