//! The commands on one scene: `run`, `geometry` and `check`.

use super::ConfigFile;
use anyhow::{Context, Result};
use inksim::output::lock::{self, OutputLock};
use inksim::pipeline::memory::{human_bytes, MemoryLimit};
use std::path::PathBuf;

/// `inksim run SCENE`: the whole pipeline; prints where the results went and
/// the worst energy balance.
pub fn run(
    config: &ConfigFile,
    output_dir: Option<PathBuf>,
    memory: Option<MemoryLimit>,
) -> Result<()> {
    if config.is_paint() {
        return super::paint::run(config, output_dir);
    }
    let mut scene = config.scene()?;
    if let Some(d) = output_dir {
        scene.output.dir = d;
    }
    let (result_path, _) = inksim::pipeline::result_paths(&scene);
    // A refusal leaves nothing new behind: the lock file, and the output
    // folder if this run made it and nothing else is in it.
    let fresh_folder = result_path
        .parent()
        .filter(|p| !p.as_os_str().is_empty() && !p.exists())
        .map(PathBuf::from);
    // One writer per result: a second run of the same output refuses at
    // once (after the output paths are known to be usable).
    if let Err(e) = inksim::pipeline::check_output_files(&scene) {
        if let Some(f) = &fresh_folder {
            let _ = std::fs::remove_dir(f);
        }
        return Err(e).with_context(|| config.display().to_string());
    }
    let lock = match OutputLock::try_acquire(&result_path)
        .with_context(|| config.display().to_string())?
    {
        Some(l) => l,
        None => anyhow::bail!(
            "{}: another inksim run ({}) is writing {}; wait for it to finish, or give this \
             run another --output-dir",
            config.display(),
            lock::holder(&result_path),
            result_path.display()
        ),
    };
    // Holding the lock, remove what a killed run of this result left.
    for p in inksim::pipeline::output_files(&scene) {
        for tmp in inksim::output::atomic::stale_temporaries(&p) {
            let _ = std::fs::remove_file(tmp);
        }
    }
    inksim::output::progress::set_status(format!(
        "nothing written ({} is written when all its solves are done); run the same \
         command again to start over",
        result_path.display()
    ));
    let report = match inksim::pipeline::run_with(&scene, false, memory) {
        Ok(r) => r,
        Err(e) => {
            lock.remove();
            if let Some(f) = &fresh_folder {
                // Only an empty folder goes (remove_dir refuses others).
                let _ = std::fs::remove_dir(f);
            }
            return Err(e).with_context(|| config.display().to_string());
        }
    };
    drop(lock);
    let worst = report
        .entries
        .iter()
        .map(|e| e.efficiencies.energy_balance.abs())
        .fold(0.0, f64::max);
    println!("results: {}", report.result_path.display());
    if let Some(p) = &report.picture_path {
        println!("picture: {}", p.display());
    }
    if let Some(p) = &report.orders_picture_path {
        println!("orders: {}", p.display());
    }
    for p in &report.plot_paths {
        println!("plot: {}", p.display());
    }
    println!(
        "{} solves, worst energy balance |ΣR+ΣT+A−1| = {worst:.1e}",
        report.entries.len()
    );
    if let Some(a) = &report.appearance {
        let conditions = match a.colour_conditions {
            Some((ill, obs)) => format!("{ill}, {}°", obs.degrees()),
            None => "custom observer".into(),
        };
        for h in &a.hiding {
            let x_um = a.spec.thickness_nm / 1000.0;
            for line in inksim::output::hiding::lines(h, &conditions, x_um) {
                println!("{line}");
            }
        }
    }
    Ok(())
}

/// `inksim geometry SCENE`: the layer only.
pub fn geometry(config: &ConfigFile, output_dir: Option<PathBuf>) -> Result<()> {
    let mut scene = config.scene()?;
    if let Some(d) = output_dir {
        scene.output.dir = d;
    }
    let report = inksim::pipeline::run_geometry(&scene)?;
    for l in &report.lines {
        println!("{l}");
    }
    println!("geometry: {}", report.result_path.display());
    println!("picture: {}", report.picture_path.display());
    Ok(())
}

/// `inksim check SCENE`: validate and print what a run would compute.
pub fn check(config: &ConfigFile, memory: Option<MemoryLimit>) -> Result<()> {
    if config.is_paint() {
        return super::paint::check(config);
    }
    let scene = config.scene()?;
    let run_plan = inksim::pipeline::RunPlan::of(&scene);
    let disk_bytes = inksim::pipeline::disk::estimate_bytes(&scene, &run_plan);
    inksim::pipeline::memory::fits(&scene, memory)
        .and_then(|()| inksim::pipeline::check_output_files(&scene))
        .and_then(|()| inksim::pipeline::check_inputs(&scene))
        .and_then(|()| inksim::pipeline::disk::preflight(&scene.output.dir, disk_bytes))
        .with_context(|| config.display().to_string())?;
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
    println!(
        "estimated peak memory {}{}",
        human_bytes(inksim::pipeline::memory::estimate_bytes(&scene)),
        memory
            .map(|m| format!(" (limit {})", m.describe()))
            .unwrap_or_default()
    );
    let files: Vec<String> = inksim::pipeline::output_files(&scene)
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    println!(
        "would write {} (about {} in all)",
        files.join(", "),
        human_bytes(disk_bytes)
    );
    Ok(())
}
