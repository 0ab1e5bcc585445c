//! `inksim export`: a result file's numbers, or a study's colours, as CSV.

use super::ConfigFile;
use anyhow::{bail, Context, Result};
use inksim::output::atomic;
use std::path::{Path, PathBuf};

/// Export `target`: a result file (`.h5`) → its tables beside it (or in
/// `to`); a study config → `<study dir>/colours.csv` (or in `to`).
pub fn export(
    target: &Path,
    profile: Option<&str>,
    output_dir: Option<PathBuf>,
    to: Option<PathBuf>,
) -> Result<()> {
    if target.extension().is_some_and(|e| e == "h5") {
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
