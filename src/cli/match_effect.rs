//! `inksim match` and `inksim check` of an effect paint's match file (a
//! multi-angle target): recipes of flake concentration, coating thickness
//! and pigments, written as a scene's match writes them.

use anyhow::Result;
use inksim::r#match::effect::{self, write, EffectReport, EffectSpec};
use std::path::PathBuf;

use super::r#match::{composition, print_heading, say};
use super::ConfigFile;

/// The checked effect match file.
fn spec(config: &ConfigFile) -> Result<EffectSpec> {
    Ok(EffectSpec::parse(&config.path, &config.text)?)
}

/// What is varied, one phrase per unknown.
fn unknowns(spec: &EffectSpec) -> String {
    let mut out: Vec<String> = Vec::new();
    for f in &spec.flakes {
        let c = f.concentration_range;
        out.push(format!(
            "{} flakes at volume fraction {}–{}",
            f.layer, c[0], c[1]
        ));
        if let Some([a, b]) = f.coating_nm_range {
            out.push(format!("{} coating {a}–{b} nm", f.layer));
        }
    }
    for p in &spec.pigments {
        out.push(format!(
            "{}.{} pvc {}–{}",
            p.layer, p.pigment, p.pvc_range[0], p.pvc_range[1]
        ));
    }
    out.join(", ")
}

/// `inksim check` of an effect match file: the file, its base paint and
/// its unknowns, and the paint solved once in the middle of the bounds.
pub fn check(config: &ConfigFile) -> Result<()> {
    let spec = spec(config)?;
    let problem = effect::problem::EffectProblem::new(&spec)?;
    println!(
        "{}: effect match file OK: multi-angle target in {} geometries ({}; {}, {}); unknowns: \
         {}; up to {} optional pigment(s), {} start(s) per subset, tolerance {} ΔE00; fast flake \
         model on {} wavelengths; results in {}",
        config.display(),
        problem.target.len(),
        problem
            .target
            .iter()
            .map(|(g, _)| g.label())
            .collect::<Vec<_>>()
            .join(", "),
        spec.target.illuminant.name(),
        spec.target.observer.name(),
        unknowns(&spec),
        spec.search.max_colourants,
        spec.search.starts,
        spec.search.tolerance_de00,
        problem.model.wavelengths_nm().len(),
        spec.output_dir.display()
    );
    Ok(())
}

/// `inksim match FILE` of an effect match file.
pub fn run(config: &ConfigFile, output_dir: Option<PathBuf>) -> Result<()> {
    let mut spec = spec(config)?;
    if let Some(d) = output_dir {
        spec.output_dir = d;
    }
    say(&format!(
        "{} (effect paint: {})",
        config.display(),
        unknowns(&spec)
    ));
    let report = effect::run(&spec, &say)?;
    let written = write::write_outputs(&spec, &report, &spec.output_dir)?;
    print_report(&spec, &report);
    say(&format!(
        "{} subset(s) in {:.2} s ({} model evaluations); wrote {}, {} and the page {}",
        report.subsets,
        report.seconds,
        report.evaluations,
        written.h5.display(),
        written.csv.display(),
        written.page.display()
    ));
    Ok(())
}

fn flop(v: Option<f64>) -> String {
    v.map_or("not defined".into(), |f| format!("{f:.2}"))
}

fn print_report(spec: &EffectSpec, r: &EffectReport) {
    let conditions = format!(
        "{}, {}",
        spec.target.illuminant.name(),
        spec.target.observer.name()
    );
    print_heading(r.reached(), spec.search.tolerance_de00, &conditions);
    println!("  target flop index {}", flop(r.target_flop_index));
    for x in &r.recipes {
        let parts = composition(&x.unknowns, &x.candidate.x, x.uncertainty.se.as_deref());
        let de: Vec<String> = r
            .target
            .iter()
            .zip(&x.candidate.fit.de00)
            .zip(&x.de00_se)
            .map(|(((g, _), d), se)| format!("{d:.3} ± {se:.3} at {}", g.label()))
            .collect();
        println!(
            "  {}. {}; flop index {}\n     ΔE00 {}{}",
            x.rank,
            parts.join(", "),
            flop(x.flop_index),
            de.join(", "),
            match x.not_determined() {
                f if f.is_empty() => String::new(),
                f => format!("\n     not determined: {}", f.join("; ")),
            }
        );
    }
}
