//! `plan`, `run`, `check` and `merge` of a study whose base is an effect
//! paint (`[paint]`): the variants run by the fast model.

use super::study::RunFlags;
use super::ConfigFile;
use anyhow::{bail, Result};
use inksim::config::paint::PaintScene;
use inksim::pipeline::memory::human_bytes;
use inksim::study::effect::{self, plan::PaintEstimate};
use inksim::study::plan::human_time;
use inksim::study::run::{self as srun, RunOptions, Shard, State};
use inksim::study::sweep::{Expansion, Selection};
use inksim::study::Study;
use std::process::ExitCode;

/// `inksim plan STUDY` of an effect study: every variant timed at its
/// middle wavelength.
pub fn plan(
    study: &Study,
    profile: Option<&str>,
    shard: Shard,
    only: &[Selection],
    nthreads: usize,
) -> Result<()> {
    let exp = study.expand_paint(profile)?.select(study, only)?;
    println!(
        "effect study `{}` ({}): {} variants{}; profile {} → {}",
        study.name,
        study.path.display(),
        exp.variants.len(),
        super::plan::selected(&exp),
        exp.profile.as_deref().unwrap_or("(none)"),
        exp.study_dir.display()
    );
    println!(
        "time model (measured now on this machine, {nthreads} thread(s)): each variant solved \
         by the fast model at its middle wavelength, that CPU time × its wavelengths over the \
         threads + {} s for colours, sparkle and pictures; memory: the reflection kept per \
         wavelength × wavelengths + {}",
        effect::plan::FIXED_S,
        human_bytes(effect::plan::BASE_BYTES)
    );
    println!(
        "{:<40} {:>6} {:>5} {:>9} {:>9} {:>9}  state",
        "variant", "λ", "terms", "probe", "time", "memory"
    );
    let (mut total, mut todo, mut peak) = (0.0, 0.0, 0.0f64);
    for v in exp.variants.iter().filter(|v| shard.contains(v.index)) {
        let e: PaintEstimate = effect::plan::estimate(v, nthreads)
            .map_err(|e| anyhow::anyhow!("variant {}: {e}", v.name))?;
        let state = srun::state(v);
        total += e.seconds;
        if state != State::Done {
            todo += e.seconds;
        }
        peak = peak.max(e.bytes);
        println!(
            "{:<40} {:>6} {:>5} {:>8.2}s {:>9} {:>9}  {}",
            v.name,
            e.wavelengths,
            e.terms,
            e.probe_cpu_s,
            human_time(e.seconds),
            human_bytes(e.bytes),
            if state == State::Done {
                "finished"
            } else {
                "to run"
            }
        );
    }
    println!(
        "total {} (one variant at a time on {nthreads} thread(s)); still to run {}; largest \
         variant {}",
        human_time(total),
        human_time(todo),
        human_bytes(peak)
    );
    Ok(())
}

/// `inksim run STUDY` of an effect study.
pub fn run(study: &Study, flags: RunFlags, nthreads: usize) -> Result<ExitCode> {
    let shard = super::shard_of(flags.shard)?;
    let exp = study
        .expand_paint(flags.profile)?
        .select(study, &flags.only)?;
    let jobs = match flags.jobs {
        Some(0) => bail!("--jobs must be at least 1"),
        Some(j) => j,
        // Each variant spreads its wavelengths over the threads.
        None => 1,
    };
    let opts = RunOptions {
        jobs,
        shard,
        quiet: false,
        memory: None,
    };
    eprintln!("[inksim] the fast model on {nthreads} thread(s) per variant");
    super::study::run_then_merge("effect study", study, &exp, &opts, || {
        print_merge(&effect::merge(study, &exp)?);
        Ok(())
    })
}

/// `inksim check STUDY` of an effect study: every profile's variants are
/// valid paints.
pub fn check(config: &ConfigFile, study: &Study) -> Result<()> {
    println!("{}: valid effect study `{}`", config.display(), study.name);
    let profiles: Vec<Option<String>> = if study.profiles.is_empty() {
        vec![None]
    } else {
        study.profiles.keys().cloned().map(Some).collect()
    };
    for p in profiles {
        let exp: Expansion<PaintScene> = study.expand_paint(p.as_deref())?;
        println!(
            "profile {}: {} variants, all valid effect paints; results in {}",
            p.as_deref().unwrap_or("(none)"),
            exp.variants.len(),
            exp.study_dir.display()
        );
    }
    Ok(())
}

/// `inksim merge STUDY` of an effect study.
pub fn merge(study: &Study, profile: Option<&str>, only: &[Selection]) -> Result<()> {
    let exp = study.expand_paint(profile)?.select(study, only)?;
    print_merge(&effect::merge(study, &exp)?);
    Ok(())
}

fn print_merge(r: &effect::EffectMergeReport) {
    super::study::print_summary(&r.summary_h5, &r.summary_md, &r.summary_html, &r.grids);
}
