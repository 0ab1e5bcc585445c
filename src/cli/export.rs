//! `inksim export`: a result file's numbers, or a study's colours, as CSV;
//! a result's BRDF as a Mitsuba 3 measured BSDF.

use super::ConfigFile;
use anyhow::{bail, Context, Result};
use inksim::output::atomic;
use std::path::{Path, PathBuf};

/// Export `target`: a result file (`.h5`) → its tables beside it (or in
/// `to`); a study config → `<study dir>/colours.csv` (or in `to`). With
/// `mitsuba`, a result file's BRDF as `<name>.bsdf` instead.
pub fn export(
    target: &Path,
    profile: Option<&str>,
    output_dir: Option<PathBuf>,
    to: Option<PathBuf>,
    mitsuba: bool,
) -> Result<()> {
    let is_result = target.extension().is_some_and(|e| e == "h5");
    if mitsuba && !is_result {
        bail!(
            "{}: --mitsuba exports a result file's BRDF; give a result file (.h5)",
            target.display()
        );
    }
    if is_result {
        if profile.is_some() || output_dir.is_some() {
            bail!(
                "{}: --profile and --output-dir apply to a study; a result file is exported as it is",
                target.display()
            );
        }
        let stem = target
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let dir = to.unwrap_or_else(|| {
            target
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_else(|| PathBuf::from("."))
        });
        if mitsuba {
            return export_mitsuba(target, &dir, &stem);
        }
        let tables = inksim::output::export::result_tables(target)?;
        for (suffix, text) in tables {
            let p = dir.join(format!("{stem}-{suffix}.csv"));
            atomic::write_atomic(&p, text.as_bytes())?;
            println!("{suffix}: {}", p.display());
        }
        return Ok(());
    }
    let config = ConfigFile::read(target)?;
    if !config.is_study() {
        bail!(
            "{}: export takes a result file (.h5) or a study (a TOML file with a [study] \
             table); for a scene, export its result, e.g. `inksim export <dir>/<name>.h5`",
            config.display()
        );
    }
    let study = config.study(output_dir)?;
    let exp = study.expand(profile)?;
    let (text, missing) = inksim::study::export::colours_csv(&study, &exp)
        .with_context(|| config.display().to_string())?;
    let p = to
        .unwrap_or_else(|| exp.study_dir.clone())
        .join("colours.csv");
    atomic::write_atomic(&p, text.as_bytes())?;
    println!("colours: {}", p.display());
    if !missing.is_empty() {
        eprintln!(
            "[inksim] {} of {} variants are not finished and have no rows (first: {}); \
             export again when `inksim run` has finished them",
            missing.len(),
            exp.variants.len(),
            missing[0]
        );
    }
    Ok(())
}

/// `<dir>/<stem>.bsdf` and `<dir>/<stem>-bsdf-samples.csv` from the result
/// file `target`.
fn export_mitsuba(target: &Path, dir: &Path, stem: &str) -> Result<()> {
    use inksim::output::mitsuba;
    let data = inksim::output::h5::read_brdf_data(target)?.with_context(|| {
        format!(
            "{}: no BRDF tables to export (the scene needs appearance outputs \"brdf\" or \"tile\", solved as one layer)",
            target.display()
        )
    })?;
    if data.wavelengths_nm.len() < 2 {
        bail!(
            "{}: a spectral BSDF needs at least two wavelengths; this result has one",
            target.display()
        );
    }
    let ctx = || target.display().to_string();
    let bytes = mitsuba::encode(&data, stem).with_context(ctx)?;
    let samples = mitsuba::reference_samples(&data).with_context(ctx)?;
    let p = dir.join(format!("{stem}.bsdf"));
    atomic::write_atomic(&p, &bytes)?;
    println!("mitsuba bsdf: {}", p.display());
    let p = dir.join(format!("{stem}-bsdf-samples.csv"));
    atomic::write_atomic(&p, samples.as_bytes())?;
    println!("bsdf samples: {}", p.display());
    Ok(())
}
