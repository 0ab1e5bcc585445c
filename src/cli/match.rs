//! `inksim match`: a match file → ranked recipes (HDF5 + CSV), with
//! timestamped progress lines; `inksim check` of a match file.

use anyhow::Result;
use inksim::output::progress::utc_stamp;
use inksim::pipeline::memory::MemoryLimit;
use inksim::r#match::{report, write, MatchReport, MatchSpec};
use std::path::PathBuf;
use std::time::SystemTime;

use super::ConfigFile;

/// A progress line with its UTC time.
pub(super) fn say(line: &str) {
    eprintln!("{} [inksim] match: {line}", utc_stamp(SystemTime::now()));
}

/// The checked match file.
fn spec(config: &ConfigFile) -> Result<MatchSpec> {
    Ok(MatchSpec::parse(&config.path, &config.text)?)
}

/// `inksim check` of a match file: the file, its base scene and palette,
/// and the fast model built, without searching.
pub fn check(config: &ConfigFile, memory: Option<MemoryLimit>) -> Result<()> {
    if config.is_effect_match() {
        return super::match_effect::check(config);
    }
    let spec = spec(config)?;
    let problem = report::problem(&spec)?;
    report::check_verification(&spec, memory)?;
    println!(
        "{}: match file OK: target in {} ({}, {}), {} palette pigment(s), up to {} colourant(s), \
         {} start(s) per subset, objective {}, tolerance {} ΔE00; fast model {} on {} \
         wavelengths; results in {}",
        config.display(),
        spec.target
            .geometries()
            .iter()
            .map(|m| m.name())
            .collect::<Vec<_>>()
            .join(", "),
        spec.target.illuminant.name(),
        spec.target.observer.name(),
        spec.palette.len(),
        spec.search.max_colourants,
        spec.search.starts,
        spec.search.objective.name(),
        spec.search.tolerance_de00,
        spec.model.name(),
        problem.model.wavelengths_nm().len(),
        spec.output_dir.display()
    );
    if let Some(v) = &spec.verify {
        println!(
            "  verification: the best {} recipe(s) by the wave solver, up to {} correction \
             step(s): {}",
            v.recipes,
            v.max_steps,
            inksim::r#match::verify::fidelity(&spec)
        );
    }
    Ok(())
}

/// `inksim match FILE`.
pub fn run(
    config: &ConfigFile,
    output_dir: Option<PathBuf>,
    memory: Option<MemoryLimit>,
) -> Result<()> {
    if config.is_effect_match() {
        return super::match_effect::run(config, output_dir);
    }
    let mut spec = spec(config)?;
    if let Some(d) = output_dir {
        spec.output_dir = d;
    }
    say(&format!(
        "{} ({} palette pigment(s))",
        config.display(),
        spec.palette.len()
    ));
    let report = inksim::r#match::report::run_with(&spec, memory, &say)?;
    let written = write::write_outputs(&spec, &report, &spec.output_dir)?;
    print_report(&spec, &report);
    if let Some(why) = &written.figure_skipped {
        say(&format!(
            "{why}; the page {} goes without it",
            written.page.display()
        ));
    }
    say(&format!(
        "{} subset(s) in {:.2} s ({} model evaluations); wrote {}, {}{} and the page {}",
        report.subsets,
        report.seconds,
        report.evaluations,
        written.h5.display(),
        written.csv.display(),
        written
            .verify_csv
            .map_or(String::new(), |p| format!(", {}", p.display())),
        written.page.display()
    ));
    Ok(())
}

/// A number with four significant digits or so: fixed between 0.01 and
/// 10⁵, scientific otherwise.
/// The line above the recipes: whether the best one is within the
/// tolerance, under the target's `conditions`.
pub(super) fn print_heading(reached: bool, tolerance_de00: f64, conditions: &str) {
    if reached {
        println!("within {tolerance_de00} ΔE00 ({conditions}):");
    } else {
        println!(
            "no recipe within {tolerance_de00} ΔE00; the closest reachable colour is recipe 1 ({conditions}):"
        );
    }
}

/// `name value ± se` of each unknown of a recipe (without `± se` where the
/// standard errors are not known).
pub(super) fn composition(unknowns: &[String], x: &[f64], se: Option<&[f64]>) -> Vec<String> {
    unknowns
        .iter()
        .zip(x)
        .enumerate()
        .map(|(k, (n, &v))| match se {
            Some(se) => format!("{n} {} ± {}", num(v), num(se[k])),
            None => format!("{n} {}", num(v)),
        })
        .collect()
}

pub(super) fn num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if (0.01..1e5).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}

fn print_report(spec: &MatchSpec, r: &MatchReport) {
    let conditions = format!(
        "{}, {}",
        spec.target.illuminant.name(),
        spec.target.observer.name()
    );
    print_heading(r.reached(), spec.search.tolerance_de00, &conditions);
    for x in &r.recipes {
        let parts = composition(&x.unknowns, &x.candidate.x, x.uncertainty.se.as_deref());
        let de: Vec<String> = r
            .target_lab
            .iter()
            .zip(x.candidate.fit.de00.iter().zip(&x.de00_se))
            .map(|((m, _), (d, se))| format!("{d:.3} ± {se:.3} ΔE00 at {}", m.name()))
            .collect();
        let mi: Vec<String> = x
            .metamerism
            .iter()
            .map(|(s, m)| format!("{} {:.2}", s.name(), m.index))
            .collect();
        println!(
            "  {}. {}{}: {}{}{}",
            x.rank,
            parts.join(", "),
            if spec.search.thickness_range_nm.is_some() {
                " (thickness nm)"
            } else {
                ""
            },
            de.join(", "),
            if mi.is_empty() {
                String::new()
            } else {
                format!("; metamerism index {}", mi.join(", "))
            },
            match x.not_determined() {
                f if f.is_empty() => String::new(),
                f => format!("\n     not determined: {}", f.join("; ")),
            }
        );
    }
    print_verified(spec, r);
}

/// The wave-optics verification: per verified recipe its corrected
/// composition, the wave colour's ΔE00 (± its standard error) and the
/// outcome.
fn print_verified(spec: &MatchSpec, r: &MatchReport) {
    let Some(fidelity) = &r.fidelity else {
        return;
    };
    println!("verified with the wave solver ({fidelity}):");
    for v in &r.verified {
        let last = v.answer();
        let de: Vec<String> = r
            .target_lab
            .iter()
            .enumerate()
            .map(|(k, (m, _))| match last.de00_se[k] {
                Some(se) => format!("{:.3} ± {se:.3} ΔE00 at {}", last.de00[k], m.name()),
                None => format!("{:.3} ΔE00 at {}", last.de00[k], m.name()),
            })
            .collect();
        println!(
            "  {}. {} (thickness {:.0} nm): {}\n     {}",
            v.rank,
            v.composition(spec, &|n, f| format!("{n} {}", num(f))),
            last.thickness_nm,
            de.join(", "),
            v.outcome
        );
    }
}
