//! The reader of a result's identity (version, input hash, plan, seed) and
//! per-solve numbers, with the headline colours when the file has them: what
//! a study needs to skip finished work and to merge results.

use std::path::Path;

use hdf5::types::VarLenUnicode;
use hdf5::Location;

use super::attrs::read_str_attr;
use super::IoError;
use crate::config::Method;
use crate::optics::farfield::Side;

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
    /// Operator applications the solve cost, fallbacks and re-solves
    /// included (None in a file written before it was recorded).
    pub operator_applications: Option<u64>,
    pub residual: f64,
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
    let file = super::open(path).map_err(hdf)?;
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
            operator_applications: g
                .attr("operator_applications")
                .and_then(|a| a.read_scalar::<u64>())
                .ok(),
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
