//! Synthetic drawdowns: the spectra a fit file's drawdowns would give if
//! its unknown pigment were a known material of a known grain diameter,
//! computed on the fit's own forward model ([`DrawdownModel`]) with seeded
//! Gaussian noise of the instrument's size added (and the result held in
//! [0, 1], as a reflectance table must be). For the round-trip tests and
//! the example (configs/fit-red.toml): a fit of such spectra must give the
//! material's constants back within their standard errors.

use crate::geometry::normal::standard_normal as gaussian;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

use crate::config::Material;
use crate::output::atomic::write_atomic;

use super::super::config::read_text;
use super::super::MatchError;
use super::config::FitSpec;
use super::model::DrawdownModel;

/// The spectrum files the fit file `path` names (relative to it), in
/// drawdown order.
fn named_files(path: &Path, text: &str) -> Vec<PathBuf> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let table: Table = text.parse().unwrap_or_default();
    let Some(Value::Array(drawdowns)) = table.get("drawdown") else {
        return Vec::new();
    };
    drawdowns
        .iter()
        .filter_map(Value::as_table)
        .flat_map(|d| {
            ["csv", "csv_black", "csv_white"]
                .into_iter()
                .filter_map(|k| d.get(k).and_then(Value::as_str).map(|f| dir.join(f)))
        })
        .collect()
}

/// Fill the spectrum files of the fit file `path` with the synthetic
/// drawdowns of `material` at grain diameter `diameter_nm`, noise `noise`
/// (1σ) from `seed` (module docs); the files written. A file not there yet
/// is first written flat, so that the fit file can be checked.
pub fn synthesise(
    path: &Path,
    material: &Material,
    diameter_nm: f64,
    noise: f64,
    seed: u64,
) -> Result<Vec<PathBuf>, MatchError> {
    let text = read_text(path)?;
    for f in named_files(path, &text) {
        if !f.exists() {
            if let Some(d) = f.parent() {
                std::fs::create_dir_all(d).map_err(|e| MatchError::Config {
                    file: f.clone(),
                    message: format!("cannot create its folder: {e}"),
                })?;
            }
            write_atomic(&f, b"wavelength_nm,reflectance\n1,0.5\n100000,0.5\n")?;
        }
    }
    let spec = FitSpec::parse(path, &text)?;
    let model = DrawdownModel::new(&spec)?;
    let grid = model.wavelengths_nm().to_vec();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut columns: Vec<Vec<f64>> = vec![Vec::with_capacity(grid.len()); model.readings()];
    for (l, &w) in grid.iter().enumerate() {
        let nk = material.index_at(w).ok_or_else(|| MatchError::Config {
            file: path.to_path_buf(),
            message: format!("material `{}` has no data at {w} nm", material.name),
        })?;
        for (c, f) in columns
            .iter_mut()
            .zip(model.factors(l, nk.re, nk.im, diameter_nm))
        {
            c.push((f + noise * gaussian(&mut rng)).clamp(0.0, 1.0));
        }
    }
    let mut written = Vec::new();
    let readings = spec
        .drawdowns
        .iter()
        .flat_map(|d| d.readings.iter().map(move |r| (d, r)));
    for ((d, r), column) in readings.zip(&columns) {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# synthetic drawdown `{}` {}: material `{}` at grain diameter {diameter_nm} nm, \
             pvc {}, white_pvc {}, {} nm",
            d.name, r.over, material.name, d.pvc, d.white_pvc, d.thickness_nm
        );
        let _ = writeln!(
            s,
            "# inksim {} fast model {} in geometry {}, Gaussian noise sigma {noise} (seed {seed})",
            crate::VERSION,
            spec.model.name(),
            spec.geometry.name()
        );
        s.push_str("wavelength_nm,reflectance\n");
        for (w, v) in grid.iter().zip(column) {
            let _ = writeln!(s, "{w},{v:.6}");
        }
        let file = path.parent().unwrap_or(Path::new("")).join(&r.csv);
        write_atomic(&file, s.as_bytes())?;
        written.push(file);
    }
    Ok(written)
}
