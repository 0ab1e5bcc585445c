//! Stage 6 — output: the HDF5 result file and atomic file writes.
//!
//! This stage owns the on-disk format. It receives plain data ([`ResultSet`])
//! from the pipeline and knows nothing about how it was computed. Every file is
//! written to `<path>.tmp` in the destination folder, flushed, closed, synced
//! and then renamed onto `<path>`, so a reader (or a resumed run) never sees a
//! half-written result: either the old file or the complete new one. On any
//! error the temporary file is removed.
//!
//! # Layout of a result file (format version 1)
//!
//! Root attributes:
//! - `format_version` (u32, = 1), `inksim_version`, `config_path`,
//!   `input_hash` (UTF-8 strings), `seed` (u64), `created_unix_s` (u64),
//!   `grid` (3 × u64: nx, ny, nz), `size_nm` (3 × f64: Lx, Ly, H).
//!
//! `/config` — scalar variable-length UTF-8 string: the exact TOML text
//! (byte-exact round trip; a text containing NUL is refused).
//!
//! `/plan` — scalar UTF-8 string: the run's plan, one line per decision
//! (which packer and why, which solves, which solver each used and why).
//!
//! `/geometry` (group):
//! - datasets `centers_nm` (N × 3 f64), `radii_nm` (N f64),
//!   `particle_of_sphere` (N u32), `species_of_particle` (P u32),
//!   `species_names` (S variable-length UTF-8 strings),
//!   `target_fraction`, `achieved_fraction`, `raster_fraction` (S f64 each);
//! - attribute `min_gap_nm` (f64; absent for a molecular mixture, which has
//!   no grains);
//! - group `statistics` (absent without grains): attributes `pvc_total`,
//!   `min_gap_nm`, `worst_overlap_nm`, `mean_diameter_nm`, `protrusion_nm`,
//!   `bottom_excess_nm`, `rdf_slab_nm`, `contact_gap_nm`, `order_parameter`
//!   (when the grains have axes); datasets `count` (S u64), `volume_nm3`,
//!   `pvc` (S f64), `profile_z_nm` (B+1) and `profile_fraction` (B: grain
//!   volume fraction per z bin), `rdf_r_nm`, `rdf` (pair correlation of the
//!   centres), `cluster_sizes` (u64, largest first); see `geometry::stats`.
//!
//! `/realisations` (group): `seed` (R u64), `achieved_pvc` (R f64), the
//! geometry of each random fragment (`/geometry` holds realisation 0's).
//!
//! `/solves/NNNN` (one group per solve, `NNNN` = zero-padded index 0000, 0001, …
//! in the order given), attributes:
//! `wavelength_nm`, `polar_deg`, `azimuth_deg`, `total_reflectance`,
//! `total_transmittance`, `absorption`, `energy_balance` (f64), `r00`, `t00`
//! (2 × f64: re, im), `method` (string: `born` | `time-marching` | `gmres` | `bicgstab` | `airy`),
//! `side` (string: `above` | `below`, the face lit; below = layer flipped),
//! `realisation` (u64),
//! `iterations`, `operator_applications` (u64), `residual`, `seconds` (f64),
//! `note` (string); datasets over the K propagating orders: `orders_mn`
//! (K × 2 i32: m, n), `orders_theta_deg`, `orders_phi_deg`,
//! `orders_reflectance`, `orders_transmittance` (K f64).
//!
//! `/summary` — one compound row per solve, in solve order, with fields
//! `wavelength_nm`, `polar_deg`, `azimuth_deg`, `reflectance`, `transmittance`,
//! `absorption`, `energy_balance`, `residual` (f64) and `iterations` (u64);
//! in Python: `h5py.File(p)["summary"]["reflectance"]`.
//!
//! `/picture_png` — the rendered PNG as a 1-D u8 dataset (present when given).
//!
//! `/appearance` (group, present when the scene asked for appearance
//! products), ensemble means over the realisations with standard errors
//! (`*_se`, same shape, present when R ≥ 2). Axes: L wavelengths, A polar
//! angles solved from above, I illumination and V viewing angles, Q
//! quadrature nodes from below, N×N table nodes.
//! - `wavelengths_nm` (L), `above_deg` (A), `illumination_deg` (I),
//!   `viewing_deg` (V), `below_deg` (Q, may be empty); attributes
//!   `azimuth_deg`, `table_cell` (node spacing in sin θ), `realisations` (u64);
//! - `reflectance`, `transmittance`, `absorption` (L × A);
//!   `specular_coherent`, `specular_incoherent`, `direct_coherent`,
//!   `direct_incoherent` (L × A: |⟨r00⟩|², ⟨|r00|²⟩ − |⟨r00⟩|², same for t00);
//! - `brdf_table` (L × I × N × N: density f cos θ on nodes
//!   s = (i − N/2, j − N/2)·cell, row j along sin θ sin φ), `brdf_diffuse`
//!   (L × I × V, 1/sr, plane of incidence, specular side); `btdf_table`,
//!   `btdf_diffuse` likewise when requested;
//! - with paper: attribute `paper_albedo`, `r_dd_up`, `t_d` (L);
//! - with the tile: `brdf_total` (L × I × V, layer + substrate, 1/sr),
//!   `natural` (L × V, radiance factor under a uniform white sky),
//!   `tile_srgb8` (V × (1 + I) × 3 u8), `tile_lab` (V × (1 + I) × 3 f64), `natural_srgb8` (V × 3 u8),
//!   `natural_lab` (V × 3 f64), `tile_png` (u8).

use std::path::Path;
use std::str::FromStr;

use hdf5::types::VarLenUnicode;
use hdf5::{H5Type, Location};
use ndarray::Array2;

use crate::config::Method;
use crate::geometry::Statistics;
use crate::optics::appearance::{Appearance, Estimate};
use crate::optics::farfield::{Side, SolveEntry};

/// Version of the layout described in the module docs, stored as `format_version`.
pub const FORMAT_VERSION: u32 = 1;

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
    pub appearance: Option<&'a Appearance>,
    /// The tile PNG (stored in `/appearance`).
    pub tile_png: Option<&'a [u8]>,
}

/// Statistics of the generated fragment. Sphere arrays (`centers_nm`,
/// `radii_nm`, `particle_of_sphere`) share one length, species arrays
/// (`species_names` and the three fractions) another.
#[derive(Debug, Clone, Copy)]
pub struct GeometrySummary<'a> {
    pub species_names: &'a [String],
    pub centers_nm: &'a [[f64; 3]],
    pub radii_nm: &'a [f64],
    pub particle_of_sphere: &'a [u32],
    pub species_of_particle: &'a [u32],
    pub target_fraction: &'a [f64],
    pub achieved_fraction: &'a [f64],
    pub raster_fraction: &'a [f64],
    /// Smallest surface gap between grains (None: no grains).
    pub min_gap_nm: Option<f64>,
    /// Full statistics of the fragment (None: no grains).
    pub statistics: Option<&'a Statistics>,
}

/// What [`read_summary`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultSummary {
    pub version: String,
    pub input_hash: String,
    pub plan: String,
    pub seed: u64,
    pub created_unix_s: u64,
    /// One per `/solves/NNNN` group, in index order.
    pub entries: Vec<EntrySummary>,
    /// The colour of the layer (on its substrate) under natural light, when
    /// the file has an `/appearance` group.
    pub appearance: Option<AppearanceSummary>,
}

/// The headline colour figures of a result, from `/appearance` (present
/// when the scene asked for the tile).
#[derive(Debug, Clone, PartialEq)]
pub struct AppearanceSummary {
    /// Viewing polar angles, deg.
    pub viewing_deg: Vec<f64>,
    /// sRGB (8 bit) under a uniform white sky, one per viewing angle.
    pub natural_srgb8: Vec<[u8; 3]>,
    /// CIELAB (D65 white) of the same, one per viewing angle.
    pub natural_lab: Vec<[f64; 3]>,
}

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

/// The per-solve numbers of a result file.
#[derive(Debug, Clone, PartialEq)]
pub struct EntrySummary {
    pub side: Side,
    pub realisation: usize,
    pub wavelength_nm: f64,
    pub polar_deg: f64,
    pub azimuth_deg: f64,
    pub total_reflectance: f64,
    pub total_transmittance: f64,
    pub absorption: f64,
    pub energy_balance: f64,
    pub method: Method,
    pub iterations: u64,
    pub residual: f64,
}

use crate::output::atomic::write_atomic_with;
pub use crate::output::error::IoError;

/// Write a result file atomically (see the module docs for the layout).
///
/// Writes `<path>.tmp` in the same folder (created if missing), closes and
/// syncs it, then renames it onto `path`. On any error the temporary file is
/// removed and an existing `path` is left untouched.
pub fn write_result(path: &Path, set: &ResultSet) -> Result<(), IoError> {
    check_result_set(path, set)?;
    write_atomic_with(path, |tmp| {
        let hdf = |source| IoError::Hdf5 {
            path: tmp.to_path_buf(),
            source,
        };
        let file = hdf5::File::create(tmp).map_err(hdf)?;
        write_contents(&file, set).map_err(hdf)?;
        file.close().map_err(hdf)
    })
}

/// Read back the identity of a result file and the per-solve numbers.
pub fn read_summary(path: &Path) -> Result<ResultSummary, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let format = |message: String| IoError::Format {
        path: path.to_path_buf(),
        message,
    };
    if !path.is_file() {
        return Err(IoError::File {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
        });
    }
    let file = hdf5::File::open(path).map_err(hdf)?;
    let root: &Location = &file;
    let version = read_str_attr(root, "inksim_version").map_err(hdf)?;
    let input_hash = read_str_attr(root, "input_hash").map_err(hdf)?;
    let plan = file
        .dataset("plan")
        .and_then(|d| d.read_scalar::<VarLenUnicode>())
        .map(|s| s.as_str().to_string())
        .map_err(hdf)?;
    let seed: u64 = root
        .attr("seed")
        .and_then(|a| a.read_scalar())
        .map_err(hdf)?;
    let created_unix_s: u64 = root
        .attr("created_unix_s")
        .and_then(|a| a.read_scalar())
        .map_err(hdf)?;

    let solves = file.group("solves").map_err(hdf)?;
    let mut indices = Vec::new();
    for name in solves.member_names().map_err(hdf)? {
        let idx: usize = name
            .parse()
            .map_err(|_| format(format!("unexpected member /solves/{name}")))?;
        indices.push((idx, name));
    }
    indices.sort();
    let mut entries = Vec::with_capacity(indices.len());
    for (k, (idx, name)) in indices.iter().enumerate() {
        if *idx != k {
            return Err(format(format!(
                "solve groups are not numbered 0..{}: found /solves/{name} at position {k}",
                indices.len()
            )));
        }
        let g = solves.group(name).map_err(hdf)?;
        let f = |key: &str| -> Result<f64, IoError> {
            g.attr(key)
                .and_then(|a| a.read_scalar::<f64>())
                .map_err(hdf)
        };
        let method_text = read_str_attr(&g, "method").map_err(hdf)?;
        let method: Method = method_text
            .parse()
            .map_err(|e: String| format(format!("/solves/{name}: attribute `method`: {e}")))?;
        let side_text = read_str_attr(&g, "side").map_err(hdf)?;
        let side: Side = side_text
            .parse()
            .map_err(|e: String| format(format!("/solves/{name}: attribute `side`: {e}")))?;
        entries.push(EntrySummary {
            side,
            realisation: g
                .attr("realisation")
                .and_then(|a| a.read_scalar::<u64>())
                .map_err(hdf)? as usize,
            wavelength_nm: f("wavelength_nm")?,
            polar_deg: f("polar_deg")?,
            azimuth_deg: f("azimuth_deg")?,
            total_reflectance: f("total_reflectance")?,
            total_transmittance: f("total_transmittance")?,
            absorption: f("absorption")?,
            energy_balance: f("energy_balance")?,
            method,
            iterations: g
                .attr("iterations")
                .and_then(|a| a.read_scalar::<u64>())
                .map_err(hdf)?,
            residual: f("residual")?,
        });
    }
    let has_colours = file.link_exists("appearance")
        && file
            .group("appearance")
            .map_err(hdf)?
            .link_exists("natural_srgb8");
    let appearance = if has_colours {
        let g = file.group("appearance").map_err(hdf)?;
        let viewing_deg: Vec<f64> = g
            .dataset("viewing_deg")
            .and_then(|d| d.read_raw())
            .map_err(hdf)?;
        let rgb: Vec<u8> = g
            .dataset("natural_srgb8")
            .and_then(|d| d.read_raw())
            .map_err(hdf)?;
        let lab: Vec<f64> = g
            .dataset("natural_lab")
            .and_then(|d| d.read_raw())
            .map_err(hdf)?;
        let n = viewing_deg.len();
        if rgb.len() != 3 * n || lab.len() != 3 * n {
            return Err(format(format!(
                "/appearance: {n} viewing angles but {} sRGB and {} Lab values",
                rgb.len(),
                lab.len()
            )));
        }
        Some(AppearanceSummary {
            viewing_deg,
            natural_srgb8: rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            natural_lab: lab.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        })
    } else {
        None
    };
    Ok(ResultSummary {
        version,
        input_hash,
        plan,
        seed,
        created_unix_s,
        entries,
        appearance,
    })
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
}

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
    write_scalar_attr(root, "format_version", FORMAT_VERSION)?;
    write_str_attr(root, "inksim_version", set.version)?;
    write_str_attr(root, "config_path", set.config_path)?;
    write_str_attr(root, "input_hash", set.input_hash)?;
    write_scalar_attr(root, "seed", set.seed)?;
    write_scalar_attr(root, "created_unix_s", set.created_unix_s)?;
    let grid = set.grid.map(|v| v as u64);
    root.new_attr_builder()
        .with_data(&grid[..])
        .create("grid")?;
    root.new_attr_builder()
        .with_data(&set.size_nm[..])
        .create("size_nm")?;

    file.new_dataset::<VarLenUnicode>()
        .shape(())
        .create("config")?
        .write_scalar(&vlu(set.config_text)?)?;
    file.new_dataset::<VarLenUnicode>()
        .shape(())
        .create("plan")?
        .write_scalar(&vlu(set.plan)?)?;

    let g = &set.geometry;
    let geo = file.create_group("geometry")?;
    let centers = Array2::from_shape_fn((g.centers_nm.len(), 3), |(i, j)| g.centers_nm[i][j]);
    geo.new_dataset_builder()
        .with_data(&centers)
        .create("centers_nm")?;
    geo.new_dataset_builder()
        .with_data(g.radii_nm)
        .create("radii_nm")?;
    geo.new_dataset_builder()
        .with_data(g.particle_of_sphere)
        .create("particle_of_sphere")?;
    geo.new_dataset_builder()
        .with_data(g.species_of_particle)
        .create("species_of_particle")?;
    let names = g
        .species_names
        .iter()
        .map(|s| vlu(s))
        .collect::<hdf5::Result<Vec<_>>>()?;
    geo.new_dataset_builder()
        .with_data(&names[..])
        .create("species_names")?;
    geo.new_dataset_builder()
        .with_data(g.target_fraction)
        .create("target_fraction")?;
    geo.new_dataset_builder()
        .with_data(g.achieved_fraction)
        .create("achieved_fraction")?;
    geo.new_dataset_builder()
        .with_data(g.raster_fraction)
        .create("raster_fraction")?;
    if let Some(gap) = g.min_gap_nm {
        write_scalar_attr(&geo, "min_gap_nm", gap)?;
    }
    if let Some(st) = g.statistics {
        write_statistics(&geo.create_group("statistics")?, st)?;
    }
    let real = file.create_group("realisations")?;
    let seeds: Vec<u64> = set.realisations.iter().map(|r| r.0).collect();
    let pvc: Vec<f64> = set.realisations.iter().map(|r| r.1).collect();
    real.new_dataset_builder()
        .with_data(&seeds[..])
        .create("seed")?;
    real.new_dataset_builder()
        .with_data(&pvc[..])
        .create("achieved_pvc")?;

    let solves = file.create_group("solves")?;
    let mut rows = Vec::with_capacity(set.entries.len());
    for (i, e) in set.entries.iter().enumerate() {
        let s = solves.create_group(&format!("{i:04}"))?;
        write_entry(&s, e)?;
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
        });
    }
    file.new_dataset_builder()
        .with_data(&rows[..])
        .create("summary")?;

    if let Some(png) = set.picture_png {
        file.new_dataset_builder()
            .with_data(png)
            .create("picture_png")?;
    }
    if let Some(app) = set.appearance {
        write_appearance(file, app, set.tile_png)?;
    }
    file.flush()
}

fn write_statistics(g: &hdf5::Group, st: &Statistics) -> hdf5::Result<()> {
    for (name, v) in [
        ("pvc_total", st.pvc_total),
        ("min_gap_nm", st.min_gap_nm),
        ("worst_overlap_nm", st.worst_overlap_nm),
        ("mean_diameter_nm", st.mean_diameter_nm),
        ("protrusion_nm", st.protrusion_nm),
        ("bottom_excess_nm", st.bottom_excess_nm),
        ("rdf_slab_nm", st.rdf_slab_nm),
        ("contact_gap_nm", st.contact_gap_nm),
    ] {
        write_scalar_attr(g, name, v)?;
    }
    if let Some(s) = st.order_parameter {
        write_scalar_attr(g, "order_parameter", s)?;
    }
    let count: Vec<u64> = st.count.iter().map(|&c| c as u64).collect();
    let clusters: Vec<u64> = st.cluster_sizes.iter().map(|&c| c as u64).collect();
    g.new_dataset_builder()
        .with_data(&count[..])
        .create("count")?;
    g.new_dataset_builder()
        .with_data(&clusters[..])
        .create("cluster_sizes")?;
    for (name, v) in [
        ("volume_nm3", &st.volume_nm3),
        ("pvc", &st.pvc),
        ("profile_z_nm", &st.profile_z_nm),
        ("profile_fraction", &st.profile_fraction),
        ("rdf_r_nm", &st.rdf_r_nm),
        ("rdf", &st.rdf),
    ] {
        g.new_dataset_builder().with_data(&v[..]).create(name)?;
    }
    Ok(())
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

fn write_appearance(
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
    if let Some(png) = tile_png {
        g.new_dataset_builder().with_data(png).create("tile_png")?;
    }
    Ok(())
}

fn write_entry(g: &hdf5::Group, e: &SolveEntry) -> hdf5::Result<()> {
    let eff = &e.efficiencies;
    let rec = &e.record;
    for (name, v) in [
        ("wavelength_nm", e.wavelength_nm),
        ("polar_deg", e.incidence.polar_deg),
        ("azimuth_deg", e.incidence.azimuth_deg),
        ("total_reflectance", eff.total_reflectance),
        ("total_transmittance", eff.total_transmittance),
        ("absorption", eff.absorption),
        ("energy_balance", eff.energy_balance),
        ("residual", rec.residual),
        ("seconds", rec.seconds),
    ] {
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
    g.new_dataset_builder().with_data(&mn).create("orders_mn")?;
    let column = |f: fn(&crate::optics::farfield::Order) -> f64| {
        eff.orders.iter().map(f).collect::<Vec<_>>()
    };
    for (name, values) in [
        ("orders_theta_deg", column(|o| o.theta_deg)),
        ("orders_phi_deg", column(|o| o.phi_deg)),
        ("orders_reflectance", column(|o| o.reflectance)),
        ("orders_transmittance", column(|o| o.transmittance)),
    ] {
        g.new_dataset_builder()
            .with_data(&values[..])
            .create(name)?;
    }
    Ok(())
}

fn vlu(s: &str) -> hdf5::Result<VarLenUnicode> {
    VarLenUnicode::from_str(s).map_err(|e| hdf5::Error::from(e.to_string()))
}

fn write_str_attr(loc: &Location, name: &str, value: &str) -> hdf5::Result<()> {
    loc.new_attr::<VarLenUnicode>()
        .shape(())
        .create(name)?
        .write_scalar(&vlu(value)?)
}

fn write_scalar_attr<T: H5Type>(loc: &Location, name: &str, value: T) -> hdf5::Result<()> {
    loc.new_attr::<T>()
        .shape(())
        .create(name)?
        .write_scalar(&value)
}

fn read_str_attr(loc: &Location, name: &str) -> hdf5::Result<String> {
    let v: VarLenUnicode = loc.attr(name)?.read_scalar()?;
    Ok(v.as_str().to_owned())
}
