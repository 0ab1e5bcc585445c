//! `inksim slurm`: a ready sbatch script running a study as a Slurm job
//! array.

use super::ConfigFile;
use anyhow::{Context, Result};
use inksim::study::slurm;
use std::path::{Path, PathBuf};

/// `inksim slurm STUDY`: write the sbatch job-array script, its memory and
/// time limits from the plan's estimates.
pub fn slurm(
    config: &ConfigFile,
    profile: Option<&str>,
    shards: Option<usize>,
    cpus: usize,
    partition: Option<String>,
    script: Option<PathBuf>,
) -> Result<()> {
    let study = config.study(None)?;
    anyhow::ensure!(cpus >= 1, "--cpus must be at least 1");
    let here = super::threads(None);
    // Per variant: estimated seconds on this machine and peak bytes; the
    // profile and the study's folder. An effect study's variants are timed
    // by its own plan (the fast model at each middle wavelength).
    let (est, profile, study_dir): (Vec<(f64, f64)>, Option<String>, PathBuf) = if study.is_paint()
    {
        let exp = study.expand_paint(profile)?;
        let est = exp
            .variants
            .iter()
            .map(|v| {
                inksim::study::effect::plan::estimate(v, here)
                    .map(|e| (e.seconds, e.bytes))
                    .map_err(|e| anyhow::anyhow!("variant {}: {e}", v.name))
            })
            .collect::<Result<_>>()?;
        (est, exp.profile, exp.study_dir)
    } else {
        let exp = study.expand(profile)?;
        let est = super::plan::estimates(&exp)
            .iter()
            .map(|e| (e.seconds, e.bytes))
            .collect();
        (est, exp.profile, exp.study_dir)
    };
    let n = est.len();
    let shards = shards.unwrap_or(n.min(64));
    anyhow::ensure!(shards >= 1, "--shards must be at least 1");
    // Longest shard, at the calibrated speed scaled to the task's CPUs.
    let longest = (0..shards)
        .map(|k| {
            est.iter()
                .enumerate()
                .filter(|(i, _)| i % shards == k)
                .map(|(_, e)| e.0)
                .sum::<f64>()
        })
        .fold(0.0, f64::max)
        * here as f64
        / cpus as f64;
    let time_min = ((3.0 * longest / 60.0).ceil() as u64 + 10).max(15);
    let peak = est.iter().map(|e| e.1).fold(0.0, f64::max);
    let mem_mb = ((1.5 * peak / 1e6).ceil() as u64).max(256);
    let cwd = std::env::current_dir().context("current directory")?;
    let abs = |p: &Path| {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            cwd.join(p)
        }
    };
    let log_dir = abs(&study_dir.join("slurm"));
    std::fs::create_dir_all(&log_dir).with_context(|| format!("creating {}", log_dir.display()))?;
    let exe = std::env::current_exe().context("locating the inksim executable")?;
    let o = slurm::SlurmOptions {
        job_name: format!("inksim-{}", study.name),
        shards,
        cpus_per_task: cpus,
        mem_mb,
        time_min,
        partition,
        profile: profile.clone(),
        exe,
        workdir: cwd.clone(),
        sweep: abs(&study.path),
        log_dir,
        variants: n,
    };
    let path = script.unwrap_or_else(|| {
        study_dir.join(format!(
            "{}{}.sbatch",
            study.name,
            profile
                .as_deref()
                .map(|p| format!("-{p}"))
                .unwrap_or_default()
        ))
    });
    inksim::output::atomic::write_atomic(&path, slurm::script(&o).as_bytes())?;
    println!("wrote {}", path.display());
    println!(
        "{n} variants in {shards} array tasks of {cpus} CPU(s), --mem {mem_mb}M (1.5 × the \
         largest estimate), --time {time_min} min (3 × the longest shard's estimate + 10 min)"
    );
    println!("submit: sbatch {}", path.display());
    println!(
        "then, when all tasks are done: inksim merge {}{}",
        study.path.display(),
        profile
            .as_deref()
            .map(|p| format!(" --profile {p}"))
            .unwrap_or_default()
    );
    Ok(())
}
