//! `inksim` command line: raw flags → validated scene → pipeline.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Wave-optics simulator for printed ink layers.
///
/// inksim builds a random layer of pigment grains in a binder (geometry),
/// rasterises its complex refractive index, solves the scalar Helmholtz
/// equation in Fourier/Bloch form for every wavelength and angle of
/// incidence, and writes the diffraction-order efficiencies (BRDF/BTDF),
/// absorption and energy balance to an HDF5 file plus a PNG picture.
#[derive(Parser)]
#[command(
    name = "inksim",
    version,
    about,
    long_about,
    after_help = "Examples:\n  inksim run configs/demo.toml          run the demo scene (results in runs/demo/)\n  inksim check configs/demo.toml        validate and show the work a run would do\n  inksim --threads 1 run scene.toml     same numbers for any thread count"
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
    /// Run a scene: geometry, raster, solves; write <dir>/<name>.h5 and .png.
    Run {
        /// Scene file (TOML), e.g. configs/demo.toml.
        config: PathBuf,
        /// Write results here instead of the scene's [output] dir.
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
    /// Validate a scene and print what a run would compute, without running it.
    Check {
        /// Scene file (TOML).
        config: PathBuf,
    },
}

fn main() -> ExitCode {
    match real_main() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn real_main() -> Result<()> {
    let cli = Cli::parse();
    if let Some(n) = cli.threads {
        anyhow::ensure!(n >= 1, "--threads must be at least 1");
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("setting up threads")?;
    }
    match cli.command {
        Command::Run { config, output_dir } => {
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
            println!(
                "{} wavelengths × {} angles = {} solves, method {:?}, tolerance {:.0e}",
                scene.wavelengths_nm.len(),
                scene.incidence.len(),
                scene.wavelengths_nm.len() * scene.incidence.len(),
                scene.solver.method,
                scene.solver.tolerance
            );
            let (packer, why) = inksim::pipeline::packer_of(&scene);
            println!("packer: {packer} ({why})");
            let (h5, png) = inksim::pipeline::result_paths(&scene);
            println!("would write {} and {}", h5.display(), png.display());
        }
    }
    Ok(())
}
