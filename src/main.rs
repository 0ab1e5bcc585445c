//! `inksim` command line: raw flags → validated scene or study → pipeline.
//!
//! This file holds the flags (clap) and the dispatch; the body of each
//! command is in [`cli`].

mod cli;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
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
    version = inksim::VERSION,
    about,
    long_about,
    after_help = "Examples:\n  inksim run configs/demo.toml                 run the demo scene (results in runs/demo/)\n  inksim check configs/demo.toml               validate and show the work a run would do\n  inksim --threads 1 run scene.toml            same numbers for any thread count\n  inksim plan configs/study.toml               variants, work, estimated time and memory per profile\n  inksim run configs/study.toml --profile quick    run (or resume) the whole study\n  inksim run configs/study.toml --shard 0/4    run a quarter of it\n  inksim slurm configs/study.toml --shards 16  write an sbatch job-array script\n  inksim merge configs/study.toml              summary.h5, comparison grids, summary.md/html\n  inksim export runs/demo/demo.h5              spectra and colours as CSV (or a study: colours.csv)\n  inksim materials                             the stand-in and library materials a scene may name"
)]
struct Cli {
    /// Worker threads (default: all cores). Results do not depend on it.
    /// More than 4 × the cores are capped there.
    #[arg(long, global = true)]
    threads: Option<usize>,
    /// Memory a run may use, e.g. 512M, 24G (default: the machine's
    /// available memory). A scene or variant whose estimate exceeds it stops
    /// before allocating, naming the grid, the estimate and what to change.
    #[arg(long, global = true, value_name = "SIZE", value_parser = inksim::pipeline::memory::parse_bytes)]
    max_memory: Option<u64>,
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
    ///
    /// A scene's solve that runs longer than 10 s reports its iteration,
    /// residual and time every 10 s (INKSIM_HEARTBEAT_S=<seconds> changes
    /// that).
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
        /// Study: only the variants with these labels, e.g. `--only pigment=red
        /// --only pvc=pvc30,pvc50` (repeatable; a variant must match every
        /// one). Names, seeds and result files are the full study's.
        #[arg(long, value_name = "AXIS=LABEL[,LABEL…]")]
        only: Vec<String>,
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
        /// Study: only the variants with these labels, e.g. `--only pigment=red
        /// --only pvc=pvc30,pvc50` (repeatable; a variant must match every
        /// one). Names, seeds and result files are the full study's.
        #[arg(long, value_name = "AXIS=LABEL[,LABEL…]")]
        only: Vec<String>,
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
        /// Only the variants with these labels, e.g. `--only pigment=red
        /// --only pvc=pvc30,pvc50` (repeatable; a variant must match every
        /// one). Names, seeds and result files are the full study's.
        #[arg(long, value_name = "AXIS=LABEL[,LABEL…]")]
        only: Vec<String>,
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
    /// Write a result's numbers, or a study's colours, as CSV tables.
    ///
    /// For a result file (<dir>/<name>.h5): <name>-solves.csv (every solve:
    /// side, realisation, wavelength, angles, R, T, A, energy balance,
    /// method, iterations, residual), and where the result has them
    /// <name>-spectra.csv (ensemble-mean R, T, A ± standard errors per
    /// wavelength and angle) and <name>-colours.csv (CIELAB, LCh ± standard
    /// errors and XYZ of the measurement geometries and of every tile cell,
    /// with illuminant and observer), and <name>-baseline.csv (each
    /// baseline model's colour and its ΔE00 to the wave colour, with
    /// appearance.baseline). For a study config: colours.csv in the study
    /// folder, one row per finished variant and measurement geometry, with
    /// the variant's label on every axis (and the baseline's colour beside,
    /// where the variants have it). Columns are described in docs/FORMAT.md.
    Export {
        /// A result file (.h5) or a study file (TOML with a [study] table).
        target: PathBuf,
        /// Study: the profile to export (default: study.profile).
        #[arg(long)]
        profile: Option<String>,
        /// Study: its results are here instead of its [study] output_dir (as
        /// given to `run --output-dir`).
        #[arg(long)]
        output_dir: Option<PathBuf>,
        /// Write the files (CSV, or with --mitsuba the BSDF) into this folder
        /// instead (default: beside the result file; the study folder).
        #[arg(long)]
        to: Option<PathBuf>,
        /// Result file: write its BRDF as a Mitsuba 3 `measured` BSDF
        /// instead, <name>.bsdf (an RGL tensor file, spectral at the
        /// result's wavelengths, the diffuse part), with
        /// <name>-bsdf-samples.csv, inksim's own evaluations at a set of
        /// directions to check a renderer's reading against (docs/FORMAT.md).
        #[arg(long)]
        mitsuba: bool,
    },
    /// Validate a scene (or every variant of a study, a match file or a fit
    /// file) and
    /// print what a run would compute, without running it.
    Check {
        /// Scene, study, match or fit file (TOML).
        config: PathBuf,
    },
    /// Find recipes for a target colour: the fewest pigments of a palette,
    /// and their volume fractions, whose colour on the fast forward model
    /// (the base scene's Kubelka–Munk baseline) matches a CIELAB target or
    /// a measured reflectance spectrum. See docs/MATCH.md.
    ///
    /// Writes <output_dir>/<name>.h5 and <name>-recipes.csv: per recipe the
    /// composition with standard errors from the target's measurement noise
    /// (and the ingredients it cannot tell apart), ΔE00 per geometry, and
    /// for a spectrum target the metamerism index under CIE A, FL11 and
    /// LED-B3; for an unreachable target the closest reachable colour; and
    /// a page of the target beside the recipes, <name>.html.
    ///
    /// With [match.verify] the best recipes are solved by the wave pipeline
    /// at the base scene's fidelity (held to --max-memory) and corrected by
    /// the fast–exact difference until the wave colour is within the
    /// tolerance, or it says why not (<name>-verify.csv, /verify, each
    /// step's result file under <output_dir>/verify/).
    Match {
        /// Match file (TOML with [match], [target], base and [[palette]]),
        /// e.g. configs/match-red-tint.toml.
        config: PathBuf,
        /// Write results here instead of match.output_dir.
        #[arg(long)]
        output_dir: Option<PathBuf>,
    },
    /// Fit a pigment's optical constants to measured drawdowns: k(λ) with
    /// n known, or n(λ) and k(λ), and if asked its grain diameter, so that
    /// the fast forward model (the base scene's Kubelka–Munk baseline)
    /// reproduces the reflectance spectra of masstones and tints with a
    /// known white, over black and white. See docs/MATCH.md, "Colourants
    /// from drawdowns".
    ///
    /// Writes <output_dir>/<name>.csv, the fitted material as a table any
    /// scene reads (`material = { csv = "<name>.csv" }`, with the fitted
    /// diameter), its header stating the drawdowns, the residuals, the
    /// standard errors, what is not determined and the provenance; and
    /// <name>.h5 with the same, the residual of every reading and the exact
    /// fit file.
    FitMaterial {
        /// Fit file (TOML with [fit], [pigment], [white], base and
        /// [[drawdown]]), e.g. configs/fit-red.toml.
        config: PathBuf,
        /// Write results here instead of fit.output_dir.
        #[arg(long)]
        output_dir: Option<PathBuf>,
    },
    /// List the materials a scene may name: the built-in stand-ins and the
    /// library of published optical constants.
    ///
    /// Each with its kind, wavelength range, licence and source. Stand-ins
    /// (`material = { builtin = "red" }`) are inksim's own documented
    /// spectra (scripts/make_pigments.py). Library materials (`material = {
    /// library = "rutile" }`) are tables converted from the
    /// refractiveindex.info database (public domain, CC0 1.0) by
    /// scripts/make_materials.py, each naming its database page and
    /// reference (data/materials/SOURCE.md has the database commit). Kinds:
    /// `stand-in`; `library` (one table); `crystal o+e` (a uniaxial crystal
    /// with ordinary and extraordinary tables, used in the scalar wave
    /// equation as the orientation average ε = (2 ε_o + ε_e)/3). A scene
    /// whose wavelengths leave a material's range is refused by `check` and
    /// `run` before any work. Your own data: `material = { csv = "file.csv" }`.
    Materials,
    /// Serve an interactive page that draws results on an object: a sphere,
    /// a curved panel or your OBJ under a lamp you drag and a uniform sky,
    /// beside the tile, the spectra and the measured colours; two results
    /// side by side or split on one object (A/B). See docs/VIEW.md.
    ///
    /// Listens on 127.0.0.1 (loopback only) and prints the address; Ctrl-C
    /// stops it. Nothing is fetched from the network.
    View {
        /// Result files (.h5), a study's folder (its variants/) or its
        /// summary.h5 (A and B then also chosen by axis values); the first
        /// is A. A scene file (.toml) is recomputed live by its
        /// radiative-transfer baseline as its controls move (a stack by the
        /// adding-doubling of its layers, each layer's controls offered);
        /// an effect paint ([paint] file, or its result file) by its fast
        /// model, with its whole BRDF and glints. One live input at a time.
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// Port to listen on (0: any free port).
        #[arg(long, default_value_t = 8017)]
        port: u16,
        /// Address to listen on. Anything but a loopback address needs
        /// --allow-remote.
        #[arg(long, default_value = "127.0.0.1")]
        host: std::net::IpAddr,
        /// Allow listening on a non-loopback address (the page and the
        /// results become reachable from other machines).
        #[arg(long)]
        allow_remote: bool,
    },
}

fn main() -> ExitCode {
    cli::exit_quietly_on_broken_pipe();
    cli::exit_cleanly_on_interrupt();
    match real_main() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", cli::chain(&e));
            ExitCode::FAILURE
        }
    }
}

fn real_main() -> Result<ExitCode> {
    let args = Cli::parse();
    let threads = args.threads.map(cli::capped_threads).transpose()?;
    if let Some(n) = threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("setting up threads")?;
    }
    let nthreads = cli::threads(threads);
    let memory = inksim::pipeline::memory::MemoryLimit::resolve(args.max_memory);
    match args.command {
        Command::Run {
            config,
            output_dir,
            profile,
            shard,
            jobs,
            only,
        } => {
            let config = cli::ConfigFile::read(&config)?;
            if config.is_study() {
                let flags = cli::study::RunFlags {
                    output_dir,
                    profile: profile.as_deref(),
                    shard: shard.as_deref(),
                    jobs,
                    only: cli::selections(&only)?,
                };
                return cli::study::run(&config, flags, nthreads, memory);
            }
            if profile.is_some() || shard.is_some() || jobs.is_some() || !only.is_empty() {
                bail!(
                    "{}: --profile, --shard, --jobs and --only apply to studies (files with a [study] table)",
                    config.display()
                );
            }
            cli::scene::run(&config, output_dir, memory)?;
        }
        Command::Plan {
            config,
            profile,
            shard,
            only,
        } => cli::plan::plan(
            &cli::ConfigFile::read(&config)?,
            profile.as_deref(),
            shard.as_deref(),
            &cli::selections(&only)?,
            nthreads,
            memory,
        )?,
        Command::Slurm {
            config,
            profile,
            shards,
            cpus,
            partition,
            script,
        } => cli::slurm::slurm(
            &cli::ConfigFile::read(&config)?,
            profile.as_deref(),
            shards,
            cpus,
            partition,
            script,
        )?,
        Command::Merge {
            config,
            profile,
            output_dir,
            only,
        } => cli::study::merge(
            &cli::ConfigFile::read(&config)?,
            profile.as_deref(),
            output_dir,
            &cli::selections(&only)?,
        )?,
        Command::Geometry { config, output_dir } => {
            cli::scene::geometry(&cli::ConfigFile::read(&config)?, output_dir)?
        }
        Command::Export {
            target,
            profile,
            output_dir,
            to,
            mitsuba,
        } => cli::export::export(&target, profile.as_deref(), output_dir, to, mitsuba)?,
        Command::Materials => cli::materials::materials()?,
        Command::View {
            inputs,
            port,
            host,
            allow_remote,
        } => cli::view::view(&inputs, host, port, allow_remote)?,
        Command::Match { config, output_dir } => {
            cli::r#match::run(&cli::ConfigFile::read(&config)?, output_dir, memory)?
        }
        Command::FitMaterial { config, output_dir } => {
            cli::fit_material::run(&cli::ConfigFile::read(&config)?, output_dir)?
        }
        Command::Check { config } => {
            let config = cli::ConfigFile::read(&config)?;
            if config.is_fit() {
                cli::fit_material::check(&config)?;
            } else if config.is_match() {
                cli::r#match::check(&config, memory)?;
            } else if config.is_study() {
                cli::study::check(&config, memory)?;
            } else {
                cli::scene::check(&config, memory)?;
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
