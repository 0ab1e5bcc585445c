//! `run` and `check` of an effect paint (a file with a `[paint]` table).

use super::ConfigFile;
use anyhow::{Context, Result};
use inksim::config::paint::PaintScene;
use inksim::output::lock::{self, OutputLock};
use std::path::PathBuf;

fn scene(config: &ConfigFile, output_dir: Option<PathBuf>) -> Result<PaintScene> {
    let mut scene = inksim::config::parse_paint(&config.path, &config.text)?;
    if let Some(d) = output_dir {
        scene.output.dir = d;
    }
    Ok(scene)
}

/// No result file's name is taken by a folder.
fn check_outputs(config: &ConfigFile, scene: &PaintScene) -> Result<()> {
    let dir = &scene.output.dir;
    anyhow::ensure!(
        !dir.exists() || dir.is_dir(),
        "{}: output folder {}: is a file, not a folder",
        config.display(),
        dir.display()
    );
    for f in inksim::pipeline::paint_files(scene) {
        anyhow::ensure!(
            !f.is_dir(),
            "{}: {}: is a folder where a result file goes; remove it or choose another \
             [output] name",
            config.display(),
            f.display()
        );
    }
    Ok(())
}

/// `inksim run PAINT`: the fast model, the result file and the pictures;
/// prints the multi-angle colours, the flop index and the sparkle.
pub fn run(config: &ConfigFile, output_dir: Option<PathBuf>) -> Result<()> {
    let scene = scene(config, output_dir)?;
    check_outputs(config, &scene)?;
    let [result_path, ..] = inksim::pipeline::paint_files(&scene);
    let fresh_folder = (!scene.output.dir.exists()).then(|| scene.output.dir.clone());
    let Some(held) =
        OutputLock::try_acquire(&result_path).with_context(|| config.display().to_string())?
    else {
        anyhow::bail!(
            "{}: another inksim run ({}) is writing {}; wait for it to finish, or give this \
             run another --output-dir",
            config.display(),
            lock::holder(&result_path),
            result_path.display()
        );
    };
    let report = match inksim::pipeline::run_paint(&scene, false) {
        Ok(r) => r,
        Err(e) => {
            held.remove();
            if let Some(f) = &fresh_folder {
                let _ = std::fs::remove_dir(f);
            }
            return Err(e).with_context(|| config.display().to_string());
        }
    };
    drop(held);
    println!("results: {}", report.result_path.display());
    println!("picture: {}", report.picture_path.display());
    println!("plot: {}", report.flop_path.display());
    println!("sparkle: {}", report.sparkle_path.display());
    println!(
        "multi-angle colour ({}, {}°):",
        scene.illuminant.name(),
        scene.observer.degrees()
    );
    for c in &report.colours {
        println!(
            "  {:>8}  L* {:6.1}  C*ab {:5.1}  h {:5.1}°",
            c.label(),
            c.lch[0],
            c.lch[1],
            c.lch[2]
        );
    }
    match report.flop_index {
        Some(f) => println!("flop index {f:.2}"),
        None => println!("flop index not defined (L*45 = 0)"),
    }
    if let Some(s) = &report.sparkle {
        for r in &s.rows {
            println!(
                "sparkle at {}° illumination: {:.3} glints/mm², {:.3} per cell at {} mm",
                r.illumination_deg, r.glints_per_mm2, r.glints_per_cell, s.viewing_distance_mm
            );
        }
        println!("graininess {:.3} (diffuse light)", s.graininess);
    }
    println!("{:.1} s", report.seconds);
    Ok(())
}

/// `inksim check PAINT`: validate and print what a run would compute.
pub fn check(config: &ConfigFile) -> Result<()> {
    let scene = scene(config, None)?;
    check_outputs(config, &scene)?;
    println!("{}: valid (an effect paint)", config.display());
    println!("plan:");
    for line in inksim::pipeline::paint_plan(&scene) {
        println!("  {line}");
    }
    let files: Vec<String> = inksim::pipeline::paint_files(&scene)
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    println!("would write {}", files.join(", "));
    Ok(())
}
