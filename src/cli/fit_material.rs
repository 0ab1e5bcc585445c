//! `inksim fit-material`: a fit file → the pigment's fitted constants as a
//! material table (CSV) and an HDF5 result, with timestamped progress
//! lines; `inksim check` of a fit file.

use anyhow::Result;
use inksim::output::progress::utc_stamp;
use inksim::r#match::fit::{self, write, FitOutcome, FitSpec};
use std::path::PathBuf;
use std::time::SystemTime;

use super::ConfigFile;

/// A progress line with its UTC time.
fn say(line: &str) {
    eprintln!(
        "{} [inksim] fit-material: {line}",
        utc_stamp(SystemTime::now())
    );
}

/// `inksim check` of a fit file: the file, its base scene, pigments,
/// drawdowns and spectra, and the model built, without fitting.
pub fn check(config: &ConfigFile) -> Result<()> {
    let spec = FitSpec::parse(&config.path, &config.text)?;
    let model = fit::DrawdownModel::new(&spec)?;
    println!(
        "{}: fit file OK: pigment `{}` ({} unknown, diameter {}), {} drawdown(s), {} reading(s) \
         in {}; fast model {} on {} wavelengths; results in {}",
        config.display(),
        spec.pigment.name,
        spec.pigment.unknowns.name(),
        match spec.pigment.diameter_range_nm {
            None => format!("{} nm", spec.pigment.diameter_nm),
            Some([a, b]) => format!("free in [{a}, {b}] nm"),
        },
        spec.drawdowns.len(),
        model.readings(),
        spec.geometry.name(),
        spec.model.name(),
        model.wavelengths_nm().len(),
        spec.output_dir.display()
    );
    Ok(())
}

/// `inksim fit-material FILE`.
pub fn run(config: &ConfigFile, output_dir: Option<PathBuf>) -> Result<()> {
    let mut spec = FitSpec::parse(&config.path, &config.text)?;
    if let Some(d) = output_dir {
        spec.output_dir = d;
    }
    say(&format!(
        "{}: pigment `{}`, {} drawdown(s)",
        config.display(),
        spec.pigment.name,
        spec.drawdowns.len()
    ));
    let out = fit::run(&spec)?;
    let written = write::write_outputs(&spec, &config.text, &out, &spec.output_dir)?;
    print_report(&spec, &out);
    say(&format!(
        "fitted in {:.2} s ({} model evaluations); wrote {} and {}",
        out.seconds,
        out.evaluations,
        written.csv.display(),
        written.h5.display()
    ));
    Ok(())
}

fn print_report(spec: &FitSpec, out: &FitOutcome) {
    println!(
        "pigment `{}`: grain diameter {}; residual RMS {:.2e} (noise {}), chi2/dof {:.3}",
        spec.pigment.name,
        write::diameter_line(spec, out),
        out.rms(),
        spec.noise,
        out.chi2_per_dof()
    );
    println!("  wavelength_nm  n  k ± s.e.  residual_rms");
    for (w, f) in out.wavelengths_nm.iter().zip(&out.per_wavelength) {
        let n = match f.n_se {
            Some(s) => format!("{:.4} ± {s:.1e}", f.n),
            None => format!("{:.4}", f.n),
        };
        let k = match f.k_se {
            Some(s) => format!("{:.3e} ± {s:.1e}", f.k),
            None => format!("{:.3e} (not determined)", f.k),
        };
        println!("  {w}  {n}  {k}  {:.1e}", f.rms());
    }
    let flags = out.not_determined();
    if !flags.is_empty() {
        println!("not determined ({}):", flags.len());
        for f in flags {
            println!("  {f}");
        }
    }
}
