//! `inksim` command line: raw flags → validated scene or study → pipeline.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use inksim::study::plan::{self, human_bytes, human_time};
use inksim::study::run::{self as srun, RunOptions, Shard, State};
use inksim::study::{slurm, sweep::Expansion, Study};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Wave-optics simulator for printed ink layers.
///
/// inksim builds a random layer of pigment grains in a binder (geometry),
/// rasterises its complex refractive index, solves the scalar Helmholtz
/// equation in Fourier/Bloch form for every wavelength and angle of
/// incidence, turns the diffraction orders into BRDF/BTDF, combines them
/// with a Lambertian paper and renders the colour tile (white-sky strip and
/// BRDF square), and writes everything (config, plan, geometry statistics,
/// every solve, ensemble means with standard errors) to an HDF5 file plus
/// PNG pictures. A scene may also give the layer explicitly ([structure]).
///
/// A study (a TOML file with a [study] table: a base scene, profiles and
/// axes; see docs/STUDY.md) runs many such scenes: `plan` shows its cost,
/// `run` runs it resumably (sharded with --shard or under Slurm), `slurm`
/// writes a job-array script, `merge` builds the summary and the
/// comparison grids.
#[derive(Parser)]
#[command(
    name = "inksim",
    version,
    about,
    long_about,
    after_help = "Examples:\n  inksim run configs/demo.toml                 run the demo scene (results in runs/demo/)\n  inksim check configs/demo.toml               validate and show the work a run would do\n  inksim --threads 1 run scene.toml            same numbers for any thread count\n  inksim plan configs/study.toml               variants, work, estimated time and memory per profile\n  inksim run configs/study.toml --profile quick    run (or resume) the whole study\n  inksim run configs/study.toml --shard 0/4    run a quarter of it\n  inksim slurm configs/study.toml --shards 16  write an sbatch job-array script\n  inksim merge configs/study.toml              summary.h5, comparison grids, summary.md/html"
)]
struct Cli {
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene (geometry, raster, solves; write <dir>/<name>.h5 and .png),
    /// or, for a file with a [study] table, every unfinished variant of the study.
    ///
    /// A study run skips variants whose result file reads back with the
    /// variant's input hash, and (re)does missing, truncated, corrupt or
    /// mismatched ones, saying why. Results go to
    /// <study.output_dir>/<profile>/variants/<name>.h5 (+ .png), each written
    /// atomically. A failed variant does not stop the others; the exit code is
    /// non-zero if any failed.
    Run {
        /// Scene or study file (TOML), e.g. configs/demo.toml, configs/study.toml.
        config: PathBuf,
        /// Scene: write results here instead of [output] dir. Study: use this
        /// folder instead of study.output_dir.
        #[arg(long)]
        output_dir: Option<PathBuf>,
        /// Study: the profile to run (default: study.profile).
        #[arg(long)]
        profile: Option<String>,
        /// Study: run only shard I of N (0 <= I < N): the variants whose index
        /// is I mod N. Default: from SLURM_ARRAY_TASK_ID / SLURM_ARRAY_TASK_COUNT
        /// when set, else the whole study.
        #[arg(long)]
        shard: Option<String>,
        /// Study: variants run in parallel. Default: the smallest of the
        /// threads, what 80 % of the available memory holds (by the plan's
        /// memory estimate) and the number of variants to run.
        #[arg(long)]
        jobs: Option<usize>,
    },
    /// Study: list the variants, the work each needs (solves, grid, voxels,
    /// realisations), its estimated time and memory, and totals per profile.
    ///
    /// Memory from the bytes per voxel of docs/PERFORMANCE.md; time from a
    /// model calibrated now, on this machine, by timing the solver's setup
    /// and one operator application on each grid (see docs/STUDY.md).
    Plan {
        /// Study file (TOML with a [study] table).
        config: PathBuf,
        /// Profile whose variants are listed (default: study.profile).
        #[arg(long)]
        profile: Option<String>,
        /// Also list the variants of a shard only.
        #[arg(long)]
        shard: Option<String>,
    },
    /// Study: write an sbatch script that runs the study as a Slurm job array
    /// (one task per shard), into <study dir>/<name>.sbatch.
    Slurm {
        /// Study file (TOML with a [study] table).
        config: PathBuf,
        #[arg(long)]
        profile: Option<String>,
        /// Array tasks (default: the number of variants, at most 64).
        #[arg(long)]
        shards: Option<usize>,
        /// CPUs per task (default 2).
        #[arg(long, default_value_t = 2)]
        cpus: usize,
        /// Slurm partition (default: the cluster's default).
        #[arg(long)]
        partition: Option<String>,
        /// Write the script here instead.
        #[arg(long)]
        script: Option<PathBuf>,
    },
    /// Study: once every variant is finished, write <study dir>/summary.h5
    /// (external links to every variant file plus a table), the comparison
    /// grids grids/*.png and summary.md / summary.html. Lists what is missing
    /// otherwise.
    Merge {
        /// Study file (TOML with a [study] table).
        config: PathBuf,
        #[arg(long)]
        profile: Option<String>,
        /// The study's results are here instead of its [study] output_dir
        /// (as given to `run --output-dir`).
        #[arg(long)]
        output_dir: Option<PathBuf>,
    },
    /// Build the layer only: particle set and statistics to
    /// <dir>/<name>-geometry.h5, a top view and cross-section to <name>-geometry.png.
    Geometry {
        /// Scene file (TOML).
        config: PathBuf,
        /// Write results here instead of the scene's [output] dir.
        #[arg(long)]
        output_dir: Option<PathBuf>,
    },
    /// Validate a scene (or every variant of a study) and print what a run
    /// would compute, without running it.
    Check {
        /// Scene or study file (TOML).
        config: PathBuf,
    },
}

fn main() -> ExitCode {
    // Output piped into a reader that stops early (`inksim plan … | head`):
    // end quietly, as ripgrep does, instead of a panic message.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let msg = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("Broken pipe") {
            std::process::exit(0);
        }
        default_hook(info)
    }));
    match real_main() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes, `: `-joined; a cause whose text its parent's
/// message already contains (library errors that name their source) is not
/// repeated.
fn chain(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let msg = cause.to_string();
        if !out.contains(&msg) {
            if !out.is_empty() {
                out.push_str(": ");
            }
            out.push_str(&msg);
        }
    }
    out
}

/// Whether `path` is a study file (has a [study] table); unreadable files
/// are left to the scene loader, which names them.
fn is_study(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .map(|t| inksim::study::is_study_text(&t))
        .unwrap_or(false)
}

fn load_study(path: &Path, output_dir: Option<PathBuf>) -> Result<Study> {
    let mut study = Study::load(path)?;
    if let Some(d) = output_dir {
        study.output_dir = d;
    }
    Ok(study)
}

fn threads(cli: Option<usize>) -> usize {
    cli.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

fn shard_of(flag: Option<&str>) -> Result<Shard> {
    match flag {
        Some(s) => Shard::parse(s).map_err(anyhow::Error::msg),
        None => Ok(Shard::from_env(|k| std::env::var(k).ok())
            .map_err(anyhow::Error::msg)?
            .unwrap_or(Shard::ALL)),
    }
}

fn real_main() -> Result<ExitCode> {
    let cli = Cli::parse();
    if let Some(n) = cli.threads {
        anyhow::ensure!(n >= 1, "--threads must be at least 1");
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("setting up threads")?;
    }
    let nthreads = threads(cli.threads);
    match cli.command {
        Command::Run {
            config,
            output_dir,
            profile,
            shard,
            jobs,
        } => {
            if is_study(&config) {
                return run_study(
                    &config,
                    output_dir,
                    profile.as_deref(),
                    shard.as_deref(),
                    jobs,
                    nthreads,
                );
            }
            if profile.is_some() || shard.is_some() || jobs.is_some() {
                bail!(
                    "{}: --profile, --shard and --jobs apply to studies (files with a [study] table)",
                    config.display()
                );
            }
            let mut scene = inksim::config::load_scene(&config)?;
            if let Some(d) = output_dir {
                scene.output.dir = d;
            }
            let report = inksim::pipeline::run(&scene)?;
            let worst = report
                .entries
                .iter()
                .map(|e| e.efficiencies.energy_balance.abs())
                .fold(0.0, f64::max);
            println!("results: {}", report.result_path.display());
            println!("picture: {}", report.picture_path.display());
            println!(
                "{} solves, worst energy balance |ΣR+ΣT+A−1| = {worst:.1e}",
                report.entries.len()
            );
        }
        Command::Plan {
            config,
            profile,
            shard,
        } => {
            let study = load_study(&config, None)?;
            plan_study(&study, profile.as_deref(), shard.as_deref(), nthreads)?;
        }
        Command::Slurm {
            config,
            profile,
            shards,
            cpus,
            partition,
            script,
        } => {
            let study = load_study(&config, None)?;
            slurm_study(&study, profile.as_deref(), shards, cpus, partition, script)?;
        }
        Command::Merge {
            config,
            profile,
            output_dir,
        } => {
            let study = load_study(&config, output_dir)?;
            let exp = study.expand(profile.as_deref())?;
            let r = inksim::study::merge::merge(&study, &exp)?;
            println!("summary: {}", r.summary_h5.display());
            println!(
                "page: {} and {}",
                r.summary_md.display(),
                r.summary_html.display()
            );
            for g in &r.grids {
                println!("grid: {}", g.display());
            }
        }
        Command::Geometry { config, output_dir } => {
            let mut scene = inksim::config::load_scene(&config)?;
            if let Some(d) = output_dir {
                scene.output.dir = d;
            }
            let report = inksim::pipeline::run_geometry(&scene)?;
            for l in &report.lines {
                println!("{l}");
            }
            println!("geometry: {}", report.result_path.display());
            println!("picture: {}", report.picture_path.display());
        }
        Command::Check { config } => {
            if is_study(&config) {
                let study = load_study(&config, None)?;
                let profiles: Vec<Option<String>> = if study.profiles.is_empty() {
                    vec![None]
                } else {
                    study.profiles.keys().cloned().map(Some).collect()
                };
                println!("{}: valid study `{}`", config.display(), study.name);
                for p in profiles {
                    let exp = study.expand(p.as_deref())?;
                    println!(
                        "profile {}: {} variants, all valid scenes; results in {}",
                        p.as_deref().unwrap_or("(none)"),
                        exp.variants.len(),
                        exp.study_dir.display()
                    );
                }
                return Ok(ExitCode::SUCCESS);
            }
            let scene = inksim::config::load_scene(&config)?;
            let g = scene.grid;
            println!("{}: valid", config.display());
            println!(
                "layer {} nm on a {} × {} nm fragment; grid {} × {} × {} = {} voxels",
                scene.layer.thickness_nm,
                scene.layer.fragment_x_nm,
                scene.layer.fragment_y_nm,
                g.nx,
                g.ny,
                g.nz,
                g.nx * g.ny * g.nz
            );
            let run_plan = inksim::pipeline::RunPlan::of(&scene);
            println!(
                "{} solves ({} wavelengths × {} realisations × {} incidences), method {:?}, \
                 tolerance {:.0e}",
                run_plan.solves(&scene),
                scene.wavelengths_nm.len(),
                run_plan.realisations,
                run_plan.solves_per_wavelength(),
                scene.solver.method,
                scene.solver.tolerance
            );
            println!("plan:");
            for line in &run_plan.lines {
                println!("  {line}");
            }
            println!("expected error of these settings:");
            for line in inksim::pipeline::accuracy::expected_error(&scene) {
                println!("  {line}");
            }
            let (h5, png) = inksim::pipeline::result_paths(&scene);
            println!("would write {} and {}", h5.display(), png.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Largest memory estimate over the variants (bytes).
fn peak_bytes(exp: &Expansion) -> f64 {
    let cal = plan::Calibration {
        grids: Default::default(),
        applications: plan::DEFAULT_APPLICATIONS,
        applications_source: String::new(),
    };
    exp.variants
        .iter()
        .map(|v| plan::estimate(&v.scene, &cal).bytes)
        .fold(0.0, f64::max)
}

fn run_study(
    config: &Path,
    output_dir: Option<PathBuf>,
    profile: Option<&str>,
    shard: Option<&str>,
    jobs: Option<usize>,
    nthreads: usize,
) -> Result<ExitCode> {
    let study = load_study(config, output_dir)?;
    let shard = shard_of(shard)?;
    let exp = study.expand(profile)?;
    let to_run = exp
        .variants
        .iter()
        .filter(|v| shard.contains(v.index))
        .count();
    let jobs = match jobs {
        Some(0) => bail!("--jobs must be at least 1"),
        Some(j) => j,
        None => srun::default_jobs(nthreads, peak_bytes(&exp), to_run),
    };
    eprintln!(
        "[inksim] study {} profile {}: {} variants ({} in shard {}/{}), results in {}",
        study.name,
        exp.profile.as_deref().unwrap_or("(none)"),
        exp.variants.len(),
        to_run,
        shard.index,
        shard.count,
        exp.study_dir.join("variants").display()
    );
    let report = srun::run_variants(
        &exp.variants,
        &RunOptions {
            jobs,
            shard,
            quiet: false,
        },
    );
    print!("{}", report.text());
    let all_done = exp.variants.iter().all(|v| srun::state(v) == State::Done);
    if all_done {
        println!(
            "all {} variants finished; next: inksim merge {}{}",
            exp.variants.len(),
            config.display(),
            exp.profile
                .as_deref()
                .map(|p| format!(" --profile {p}"))
                .unwrap_or_default()
        );
    }
    Ok(if report.failed().next().is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

fn plan_study(
    study: &Study,
    profile: Option<&str>,
    shard: Option<&str>,
    nthreads: usize,
) -> Result<()> {
    let shard = match shard {
        Some(s) => Shard::parse(s).map_err(anyhow::Error::msg)?,
        None => Shard::ALL,
    };
    let chosen = study.expand(profile)?;
    let mut others = vec![];
    for p in study.profiles.keys() {
        if Some(p) != chosen.profile.as_ref() {
            others.push(study.expand(Some(p))?);
        }
    }
    println!(
        "study `{}` ({}): {} variants; profile {} → {}",
        study.name,
        study.path.display(),
        chosen.variants.len(),
        chosen.profile.as_deref().unwrap_or("(none)"),
        chosen.study_dir.display()
    );
    let cal = plan::calibrate(&chosen.variants, &chosen.variants);
    println!(
        "time model (calibrated now on this machine, {nthreads} thread(s)): per solve = setup + \
         applications × one operator application × {}; applications per solve {:.0}: {}",
        plan::KRYLOV_OVERHEAD,
        cal.applications,
        cal.applications_source
    );
    for (g, t) in &cal.grids {
        println!(
            "  grid {}×{}×{}: setup {:.1} ms, one application {:.2} ms{}",
            g[0],
            g[1],
            g[2],
            t.setup_s * 1e3,
            t.apply_s * 1e3,
            if t.timed != *g {
                format!(
                    " (timed on {}×{}×{}, scaled by N log N)",
                    t.timed[0], t.timed[1], t.timed[2]
                )
            } else {
                String::new()
            }
        );
    }
    println!(
        "memory model: {} + voxels × (bytes per voxel of the method: time-marching 238, \
         BiCGStab/auto 318, GMRES 574; docs/PERFORMANCE.md) + 8 B per voxel and species",
        human_bytes(plan::BASELINE_BYTES)
    );
    println!(
        "{:>4}  {:<34} {:>6} {:>14} {:>10} {:>5} {:>10} {:>9}  state",
        "#", "variant", "solves", "grid", "voxels", "real.", "est. time", "memory"
    );
    let (mut t_sum, mut s_sum, mut peak, mut n) = (0.0, 0usize, 0.0f64, 0usize);
    for v in chosen.variants.iter().filter(|v| shard.contains(v.index)) {
        let e = plan::estimate(&v.scene, &cal);
        let st = srun::state(v);
        println!(
            "{:>4}  {:<34} {:>6} {:>14} {:>10} {:>5} {:>10} {:>9}  {}",
            v.index,
            v.name,
            e.solves,
            format!("{}×{}×{}", e.grid[0], e.grid[1], e.grid[2]),
            e.voxels,
            e.realisations,
            human_time(e.seconds),
            human_bytes(e.bytes),
            if st == State::Done {
                "done".to_string()
            } else {
                st.reason()
            }
        );
        t_sum += e.seconds;
        s_sum += e.solves;
        peak = peak.max(e.bytes);
        n += 1;
    }
    let jobs = srun::default_jobs(nthreads, peak, n);
    println!(
        "total ({} variants{}): {s_sum} solves, est. {} of compute on this machine; peak memory \
         {} per variant; default --jobs {jobs} ({} peak at once)",
        n,
        if shard.count > 1 {
            format!(", shard {}/{}", shard.index, shard.count)
        } else {
            String::new()
        },
        human_time(t_sum),
        human_bytes(peak),
        human_bytes(peak * jobs as f64)
    );
    if let Some(v) = chosen
        .variants
        .iter()
        .find(|v| !v.scene.is_molecular())
        .or(chosen.variants.first())
    {
        println!(
            "expected error of this profile's settings (variant {}):",
            v.name
        );
        for line in inksim::pipeline::accuracy::expected_error(&v.scene) {
            println!("  {line}");
        }
    }
    if !others.is_empty() {
        println!("other profiles (same model):");
        for exp in &others {
            let est = estimates(exp);
            let grids: std::collections::BTreeSet<String> = est
                .iter()
                .map(|e| format!("{}×{}×{}", e.grid[0], e.grid[1], e.grid[2]))
                .collect();
            let de = exp
                .variants
                .iter()
                .find(|v| !v.scene.is_molecular())
                .or(exp.variants.first())
                .and_then(|v| inksim::pipeline::accuracy::expected_error(&v.scene).pop())
                .unwrap_or_default();
            println!(
                "  {:<10} {} variants, {} solves, grid {}, est. {} total, peak memory {} per \
                 variant; {de}",
                exp.profile.as_deref().unwrap_or(""),
                exp.variants.len(),
                est.iter().map(|e| e.solves).sum::<usize>(),
                grids.into_iter().collect::<Vec<_>>().join(", "),
                human_time(est.iter().map(|e| e.seconds).sum()),
                human_bytes(est.iter().map(|e| e.bytes).fold(0.0, f64::max))
            );
        }
    }
    Ok(())
}

/// Time and memory estimates of every variant, calibrated now.
fn estimates(exp: &Expansion) -> Vec<plan::Estimate> {
    let cal = plan::calibrate(&exp.variants, &exp.variants);
    exp.variants
        .iter()
        .map(|v| plan::estimate(&v.scene, &cal))
        .collect()
}

fn slurm_study(
    study: &Study,
    profile: Option<&str>,
    shards: Option<usize>,
    cpus: usize,
    partition: Option<String>,
    script: Option<PathBuf>,
) -> Result<()> {
    anyhow::ensure!(cpus >= 1, "--cpus must be at least 1");
    let exp = study.expand(profile)?;
    let n = exp.variants.len();
    let shards = shards.unwrap_or(n.min(64));
    anyhow::ensure!(shards >= 1, "--shards must be at least 1");
    let est = estimates(&exp);
    // Longest shard, at the calibrated speed scaled to the task's CPUs.
    let here = threads(None) as f64;
    let longest = (0..shards)
        .map(|k| {
            est.iter()
                .enumerate()
                .filter(|(i, _)| i % shards == k)
                .map(|(_, e)| e.seconds)
                .sum::<f64>()
        })
        .fold(0.0, f64::max)
        * here
        / cpus as f64;
    let time_min = ((3.0 * longest / 60.0).ceil() as u64 + 10).max(15);
    let peak = est.iter().map(|e| e.bytes).fold(0.0, f64::max);
    let mem_mb = ((1.5 * peak / 1e6).ceil() as u64).max(256);
    let cwd = std::env::current_dir().context("current directory")?;
    let abs = |p: &Path| {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            cwd.join(p)
        }
    };
    let log_dir = abs(&exp.study_dir.join("slurm"));
    std::fs::create_dir_all(&log_dir).with_context(|| format!("creating {}", log_dir.display()))?;
    let exe = std::env::current_exe().context("locating the inksim executable")?;
    let o = slurm::SlurmOptions {
        job_name: format!("inksim-{}", study.name),
        shards,
        cpus_per_task: cpus,
        mem_mb,
        time_min,
        partition,
        profile: exp.profile.clone(),
        exe,
        workdir: cwd.clone(),
        sweep: abs(&study.path),
        log_dir,
        variants: n,
    };
    let path = script.unwrap_or_else(|| {
        exp.study_dir.join(format!(
            "{}{}.sbatch",
            study.name,
            exp.profile
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
        exp.profile
            .as_deref()
            .map(|p| format!(" --profile {p}"))
            .unwrap_or_default()
    );
    Ok(())
}
