//! The commands on a study: `run`, `check` and `merge`.

use super::ConfigFile;
use anyhow::{bail, Context, Result};
use inksim::pipeline::memory::{human_bytes, MemoryLimit};
use inksim::study::run::{self as srun, RunOptions, RunReport, RunScene, State};
use inksim::study::sweep::{Expansion, Selection, Variant};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The flags of `inksim run` on a study.
pub struct RunFlags<'a> {
    pub output_dir: Option<PathBuf>,
    pub profile: Option<&'a str>,
    pub shard: Option<&'a str>,
    pub jobs: Option<usize>,
    pub only: Vec<Selection>,
}

/// `inksim run STUDY`: every unfinished variant (of the shard and the
/// `--only` subset); the exit code says whether any failed.
pub fn run(
    config: &ConfigFile,
    flags: RunFlags,
    nthreads: usize,
    memory: Option<MemoryLimit>,
) -> Result<ExitCode> {
    let study = config.study(flags.output_dir.clone())?;
    if study.is_paint() {
        return super::effect_study::run(&study, flags, nthreads);
    }
    let RunFlags {
        profile,
        shard,
        jobs,
        only,
        ..
    } = flags;
    let shard = super::shard_of(shard)?;
    let exp = study.expand(profile)?.select(&study, &only)?;
    let to_run = exp
        .variants
        .iter()
        .filter(|v| shard.contains(v.index))
        .count();
    // The results still to write must fit the disk, before any solve.
    let need: f64 = exp
        .variants
        .iter()
        .filter(|v| shard.contains(v.index) && srun::state(v) != State::Done)
        .map(|v| {
            inksim::pipeline::disk::estimate_bytes(
                &v.scene,
                &inksim::pipeline::RunPlan::of(&v.scene),
            )
        })
        .sum();
    inksim::pipeline::disk::preflight(&exp.study_dir, need)
        .with_context(|| config.display().to_string())?;
    let peak = peak_bytes(&exp);
    let jobs = match jobs {
        Some(0) => bail!("--jobs must be at least 1"),
        Some(j) => {
            let held = srun::jobs_memory_holds(peak, memory).max(1);
            if j > held {
                eprintln!(
                    "[inksim] --jobs {j} capped at {held}: {held} variant(s) of up to {} each \
                     fit in {}",
                    human_bytes(peak),
                    memory.map(|m| m.describe()).unwrap_or_default()
                );
            }
            j.min(held)
        }
        None => srun::default_jobs(nthreads, peak, to_run, memory),
    };
    let opts = RunOptions {
        jobs,
        shard,
        quiet: false,
        memory,
    };
    run_then_merge("study", &study, &exp, &opts, || {
        print_merge(&inksim::study::merge::merge(&study, &exp)?);
        Ok(())
    })
}

/// Say what a run of `exp` will do (`kind`: "study", "effect study"), run
/// the variants of `opts.shard` and [`finish`].
pub fn run_then_merge<S: RunScene>(
    kind: &str,
    study: &inksim::study::Study,
    exp: &Expansion<S>,
    opts: &RunOptions,
    merge: impl FnOnce() -> Result<()>,
) -> Result<ExitCode> {
    let shard = opts.shard;
    let to_run = exp
        .variants
        .iter()
        .filter(|v| shard.contains(v.index))
        .count();
    eprintln!(
        "[inksim] {kind} {} profile {}: {} variants{} ({} in shard {}/{}, {} job(s)), results \
         in {}",
        study.name,
        exp.profile.as_deref().unwrap_or("(none)"),
        exp.variants.len(),
        super::plan::selected(exp),
        to_run,
        shard.index,
        shard.count,
        opts.jobs,
        exp.study_dir.join("variants").display()
    );
    let report = srun::run_variants(&exp.variants, opts);
    finish(&report, &exp.variants, merge)
}

/// Print a run's report; merge (by `merge`) when every variant is finished;
/// the exit code says whether any failed.
pub fn finish<S: RunScene>(
    report: &RunReport,
    variants: &[Variant<S>],
    merge: impl FnOnce() -> Result<()>,
) -> Result<ExitCode> {
    print!("{}", report.text());
    if variants.iter().all(|v| srun::state(v) == State::Done) {
        println!(
            "all {} variants finished; merging (as `inksim merge` does)",
            variants.len()
        );
        merge()?;
    }
    Ok(if report.failed().next().is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// `inksim check STUDY`: expand every profile (which validates every
/// variant's scene), hold every variant to the memory limit and say how
/// many variants each has.
pub fn check(config: &ConfigFile, memory: Option<MemoryLimit>) -> Result<()> {
    let study = config.study(None)?;
    if study.is_paint() {
        return super::effect_study::check(config, &study);
    }
    let profiles: Vec<Option<String>> = if study.profiles.is_empty() {
        vec![None]
    } else {
        study.profiles.keys().cloned().map(Some).collect()
    };
    println!("{}: valid study `{}`", config.display(), study.name);
    for p in profiles {
        let exp = study.expand(p.as_deref())?;
        for v in &exp.variants {
            inksim::pipeline::memory::fits(&v.scene, memory)
                .and_then(|()| inksim::pipeline::check_output_files(&v.scene))
                .and_then(|()| inksim::pipeline::check_inputs(&v.scene))
                .with_context(|| {
                    format!(
                        "{}: profile {}, variant {}",
                        config.display(),
                        p.as_deref().unwrap_or("(none)"),
                        v.name
                    )
                })?;
        }
        let need: f64 = exp
            .variants
            .iter()
            .map(|v| {
                inksim::pipeline::disk::estimate_bytes(
                    &v.scene,
                    &inksim::pipeline::RunPlan::of(&v.scene),
                )
            })
            .sum();
        inksim::pipeline::disk::preflight(&exp.study_dir, need).with_context(|| {
            format!(
                "{}: profile {}",
                config.display(),
                p.as_deref().unwrap_or("(none)")
            )
        })?;
        println!(
            "profile {}: {} variants, all valid scenes; results in {} (about {} on disk)",
            p.as_deref().unwrap_or("(none)"),
            exp.variants.len(),
            exp.study_dir.display(),
            human_bytes(need)
        );
    }
    Ok(())
}

/// `inksim merge STUDY`: the summary file, page and grids of a finished
/// study.
pub fn merge(
    config: &ConfigFile,
    profile: Option<&str>,
    output_dir: Option<PathBuf>,
    only: &[Selection],
) -> Result<()> {
    let study = config.study(output_dir)?;
    if study.is_paint() {
        return super::effect_study::merge(&study, profile, only);
    }
    let exp = study.expand(profile)?.select(&study, only)?;
    print_merge(&inksim::study::merge::merge(&study, &exp)?);
    Ok(())
}

/// Say where merge wrote the summary, the pages and the grids.
pub fn print_summary(h5: &Path, md: &Path, html: &Path, grids: &[PathBuf]) {
    println!("summary: {}", h5.display());
    println!("page: {} and {}", md.display(), html.display());
    for g in grids {
        println!("grid: {}", g.display());
    }
}

/// Say where merge wrote its files.
fn print_merge(r: &inksim::study::merge::MergeReport) {
    print_summary(&r.summary_h5, &r.summary_md, &r.summary_html, &r.grids);
    for m in &r.de00_maps {
        println!("ΔE00 map: {}", m.display());
    }
    for p in &r.plots {
        println!("plot: {}", p.display());
    }
}

/// Largest memory estimate over the variants (bytes).
fn peak_bytes(exp: &Expansion) -> f64 {
    exp.variants
        .iter()
        .map(|v| inksim::pipeline::memory::estimate_bytes(&v.scene))
        .fold(0.0, f64::max)
}
