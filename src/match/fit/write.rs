//! The fit's files in its output folder, both written atomically under the
//! output lock:
//!
//! - `<name>.csv`: the fitted material, `wavelength_nm,n,k` on the colour
//!   grid — the table format every scene reads (`material = { csv =
//!   "<name>.csv" }`) — with `#` header lines giving the provenance (inksim
//!   version, the fit file and the SHA-256 of everything it read), the
//!   grain diameter the constants belong to, the drawdowns, the residuals,
//!   the standard errors and what is not determined.
//! - `<name>.h5`: the same with the exact fit file, the residual of every
//!   reading, the free size's scan; every dataset with its units,
//!   description and labelled axes (layout in docs/MATCH.md).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;
use ndarray::Array2;
use sha2::{Digest, Sha256};

use crate::config::GroundReflectance;
use crate::output::atomic::{write_atomic, write_atomic_with};
use crate::output::h5::{about, dim, vlu, write_scalar_attr, write_str_attr, IoError, Scales};
use crate::output::lock::OutputLock;

use super::super::MatchError;
use super::config::{FitSpec, Unknowns};
use super::estimate::FitOutcome;

const READING: &str = "reading";
const SCAN: &str = "size_scan";

/// The files written.
#[derive(Debug, Clone)]
pub struct Written {
    pub csv: PathBuf,
    pub h5: PathBuf,
}

/// Hex SHA-256 of everything the fit read: the fit file's text, the base
/// scene's input hash (its tables and the white's material data) and the
/// bytes of every spectrum (readings and grounds).
pub fn input_hash(spec: &FitSpec, text: &str) -> String {
    let mut h = Sha256::new();
    h.update(text.as_bytes());
    h.update(spec.scene.provenance.input_hash.as_bytes());
    for r in spec.drawdowns.iter().flat_map(|d| &d.readings) {
        h.update(&r.spectrum.bytes);
        if let GroundReflectance::Spectrum(s) = &r.ground {
            h.update(&s.bytes);
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// `name (over …)` of every reading, in the model's order.
pub fn reading_names(spec: &FitSpec) -> Vec<String> {
    spec.drawdowns
        .iter()
        .flat_map(|d| {
            d.readings
                .iter()
                .map(move |r| format!("{} {}", d.name, r.over))
        })
        .collect()
}

/// Write the fit of `spec` (its file's `text`) into `dir`.
pub fn write_outputs(
    spec: &FitSpec,
    text: &str,
    out: &FitOutcome,
    dir: &Path,
) -> Result<Written, MatchError> {
    let csv = dir.join(format!("{}.csv", spec.name));
    let h5 = dir.join(format!("{}.h5", spec.name));
    let lock = OutputLock::acquire(&h5)?;
    write_atomic(&csv, material_csv(spec, text, out).as_bytes())?;
    write_atomic_with(&h5, |tmp| -> Result<(), IoError> {
        write_h5(spec, text, out, tmp).map_err(|source| IoError::Hdf5 {
            path: tmp.to_path_buf(),
            source,
        })
    })?;
    drop(lock);
    Ok(Written { csv, h5 })
}

/// A standard error or `-`.
fn se(v: Option<f64>) -> String {
    v.map_or("-".into(), |s| format!("{s:.3e}"))
}

/// The diameter as the header states it.
pub fn diameter_line(spec: &FitSpec, out: &FitOutcome) -> String {
    match spec.pigment.diameter_range_nm {
        None => format!("{} nm (fixed)", out.diameter_nm),
        Some([lo, hi]) => format!(
            "{:.2} ± {} nm (fitted within [{lo}, {hi}] nm)",
            out.diameter_nm,
            out.diameter_se
                .map_or("- (not determined)".into(), |s| format!("{s:.2}"))
        ),
    }
}

/// The material table with its header (module docs).
pub fn material_csv(spec: &FitSpec, text: &str, out: &FitOutcome) -> String {
    let mut s = String::new();
    let p = &spec.pigment;
    let unknowns = match p.unknowns {
        Unknowns::K { n } => format!("k(λ) fitted, n = {n} known"),
        Unknowns::NAndK { n_range } => {
            format!(
                "n(λ) and k(λ) fitted, n within [{}, {}]",
                n_range[0], n_range[1]
            )
        }
    };
    let _ = writeln!(
        s,
        "# inksim fit-material: pigment `{}` from drawdowns ({unknowns})",
        p.name
    );
    let _ = writeln!(
        s,
        "# inksim version {}; fit file {}",
        crate::VERSION,
        spec.path.display()
    );
    let _ = writeln!(s, "# input sha256 {}", input_hash(spec, text));
    let _ = writeln!(
        s,
        "# fast model {}, geometry {}, binder index {}, noise (1 sigma) {} per reflectance factor",
        spec.model.name(),
        spec.geometry.name(),
        spec.scene.layer.binder_index,
        spec.noise
    );
    let _ = writeln!(
        s,
        "# grain diameter {}: use it as the pigment's diameter_nm with this table",
        diameter_line(spec, out)
    );
    if let Some(w) = &spec.white {
        let _ = writeln!(s, "# white in the tints: {w}");
    }
    for d in &spec.drawdowns {
        let files: Vec<String> = d
            .readings
            .iter()
            .map(|r| format!("{} {}", r.over, r.csv))
            .collect();
        let _ = writeln!(
            s,
            "# drawdown {}: {} nm, pvc {}, white_pvc {}; {}",
            d.name,
            d.thickness_nm,
            d.pvc,
            d.white_pvc,
            files.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "# residuals: RMS {:.3e} over {} readings x {} wavelengths; chi2/dof {:.3} (dof {})",
        out.rms(),
        out.per_wavelength.first().map_or(0, |w| w.residuals.len()),
        out.wavelengths_nm.len(),
        out.chi2_per_dof(),
        out.dof
    );
    let flags = out.not_determined();
    let _ = writeln!(
        s,
        "# not determined: {}",
        if flags.is_empty() {
            "none".into()
        } else {
            flags.len().to_string() + " (below)"
        }
    );
    let _ = writeln!(
        s,
        "# per wavelength: wavelength_nm, n_se, k_se, residual_rms, not determined"
    );
    for (w, f) in out.wavelengths_nm.iter().zip(&out.per_wavelength) {
        let why: Vec<String> = [("n", &f.n_flags), ("k", &f.k_flags)]
            .iter()
            .filter(|(_, x)| !x.is_empty())
            .map(|(c, x)| format!("{c}: {x}"))
            .collect();
        let _ = writeln!(
            s,
            "#   {w}, {}, {}, {:.3e}, {}",
            se(f.n_se),
            se(f.k_se),
            f.rms(),
            why.join("; ")
        );
    }
    s.push_str("wavelength_nm,n,k\n");
    for (w, f) in out.wavelengths_nm.iter().zip(&out.per_wavelength) {
        let _ = writeln!(s, "{w},{},{}", f.n, f.k);
    }
    s
}

fn strings(xs: &[String]) -> hdf5::Result<Vec<VarLenUnicode>> {
    xs.iter().map(|s| vlu(s)).collect()
}

fn write_h5(spec: &FitSpec, text: &str, out: &FitOutcome, path: &Path) -> hdf5::Result<()> {
    let f = crate::output::h5::create(path)?;
    let p = &spec.pigment;
    for (k, v) in [
        ("inksim_version", crate::VERSION),
        ("fit_file", &spec.path.display().to_string()),
        ("fit_toml", text),
        ("input_sha256", &input_hash(spec, text)),
        ("model", spec.model.name()),
        ("geometry", spec.geometry.name()),
        ("unknowns", p.unknowns.name()),
        ("pigment", &p.name),
        ("white", spec.white.as_deref().unwrap_or("")),
        ("diameter_flags", &out.diameter_flags),
    ] {
        write_str_attr(&f, k, v)?;
    }
    write_scalar_attr(&f, "noise_reflectance", spec.noise)?;
    write_scalar_attr(&f, "binder_index", spec.scene.layer.binder_index)?;
    write_scalar_attr(&f, "diameter_nm", out.diameter_nm)?;
    write_scalar_attr(&f, "diameter_free", u8::from(p.diameter_range_nm.is_some()))?;
    write_scalar_attr(&f, "diameter_se_nm", out.diameter_se.unwrap_or(f64::NAN))?;
    write_scalar_attr(&f, "chi2", out.chi2)?;
    write_scalar_attr(&f, "dof", out.dof as u64)?;
    write_scalar_attr(&f, "residual_rms", out.rms())?;
    write_scalar_attr(&f, "model_evaluations", out.evaluations as u64)?;
    write_scalar_attr(&f, "seconds", out.seconds)?;
    let mut sc = Scales::default();
    let w = &out.wavelengths_nm;
    sc.coordinate(
        &f,
        "wavelength_nm",
        w,
        about(
            "nm",
            "the colour grid of the fit (vacuum wavelengths)",
            &[dim::WAVELENGTH],
        ),
    )?;
    sc.coordinate(
        &f,
        "reading",
        &strings(&reading_names(spec))?,
        about(
            "",
            "every drawdown over each of its grounds (names)",
            &[READING],
        ),
    )?;
    let per = &out.per_wavelength;
    let col = |g: &dyn Fn(&super::estimate::WavelengthFit) -> f64| -> Vec<f64> {
        per.iter().map(g).collect()
    };
    let wl = [dim::WAVELENGTH];
    sc.write(
        &f,
        "n",
        &col(&|x| x.n)[..],
        about(
            "1",
            "real refractive index of the pigment (fitted, or the known one); wavelength",
            &wl,
        ),
    )?;
    sc.write(
        &f,
        "k",
        &col(&|x| x.k)[..],
        about(
            "1",
            "absorption index of the pigment (fitted); wavelength",
            &wl,
        ),
    )?;
    sc.write(&f, "n_se", &col(&|x| x.n_se.unwrap_or(f64::NAN))[..], about("1", "standard error of n from the stated noise (NaN: n known, or not determined); wavelength", &wl))?;
    sc.write(
        &f,
        "k_se",
        &col(&|x| x.k_se.unwrap_or(f64::NAN))[..],
        about(
            "1",
            "standard error of k from the stated noise (NaN: not determined); wavelength",
            &wl,
        ),
    )?;
    sc.write(
        &f,
        "correlation_nk",
        &col(&|x| x.correlation_nk.unwrap_or(f64::NAN))[..],
        about(
            "1",
            "correlation of the n and k estimates (NaN: n known, or not determined); wavelength",
            &wl,
        ),
    )?;
    sc.write(
        &f,
        "residual_rms",
        &col(&|x| x.rms())[..],
        about(
            "1",
            "RMS over the readings of model minus measured reflectance factor; wavelength",
            &wl,
        ),
    )?;
    let nr = per.first().map_or(0, |x| x.residuals.len());
    let res = Array2::from_shape_fn((w.len(), nr), |(l, i)| per[l].residuals[i]);
    sc.write(
        &f,
        "residuals",
        res.view(),
        about(
            "1",
            "model minus measured reflectance factor; wavelength × reading",
            &[dim::WAVELENGTH, READING],
        ),
    )?;
    let flags: Vec<String> = per
        .iter()
        .map(|x| {
            [("n", &x.n_flags), ("k", &x.k_flags)]
                .iter()
                .filter(|(_, s)| !s.is_empty())
                .map(|(c, s)| format!("{c}: {s}"))
                .collect::<Vec<_>>()
                .join("; ")
        })
        .collect();
    sc.write(
        &f,
        "flags",
        &strings(&flags)?[..],
        about(
            "",
            "why a constant is not determined at the wavelength (empty: both are); wavelength",
            &wl,
        ),
    )?;
    let readings: Vec<(f64, f64, f64)> = spec
        .drawdowns
        .iter()
        .flat_map(|d| {
            d.readings
                .iter()
                .map(|_| (d.thickness_nm, d.pvc, d.white_pvc))
        })
        .collect();
    let g = f.create_group("drawdowns")?;
    sc.write(
        &g,
        "thickness_nm",
        &readings.iter().map(|r| r.0).collect::<Vec<_>>()[..],
        about(
            "nm",
            "layer thickness of each reading's drawdown; reading",
            &[READING],
        ),
    )?;
    sc.write(
        &g,
        "pvc",
        &readings.iter().map(|r| r.1).collect::<Vec<_>>()[..],
        about(
            "1",
            "volume fraction of the fitted pigment; reading",
            &[READING],
        ),
    )?;
    sc.write(
        &g,
        "white_pvc",
        &readings.iter().map(|r| r.2).collect::<Vec<_>>()[..],
        about("1", "volume fraction of the white; reading", &[READING]),
    )?;
    if !out.size_scan.is_empty() {
        let s = f.create_group("size_scan")?;
        let d: Vec<f64> = out.size_scan.iter().map(|x| x.0).collect();
        let c: Vec<f64> = out.size_scan.iter().map(|x| x.1).collect();
        sc.coordinate(
            &s,
            "diameter_nm",
            &d,
            about("nm", "grain diameters of the free size's scan", &[SCAN]),
        )?;
        sc.write(&s, "chi2", &c[..], about("1", "sum over wavelengths and readings of (residual/noise)^2 with each wavelength's best constants at the diameter; size_scan", &[SCAN]))?;
    }
    Ok(())
}
