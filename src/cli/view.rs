//! `inksim view`: load the results, bind the server, print the address,
//! serve until Ctrl-C.

use anyhow::{bail, Result};
use inksim::view::live::{LiveModel, RadiativeTransfer};
use inksim::view::live_stack::StackTransfer;
use inksim::view::paint::LivePaint;
use inksim::view::{result, server, source};
use std::net::IpAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set while the page is being served: Ctrl-C then ends quietly (exit 0).
pub static SERVING: AtomicBool = AtomicBool::new(false);

/// Serve `inputs` (result files, study folders, summary files, and at most
/// one scene file or effect paint's result recomputed live) on
/// `host`:`port`.
pub fn view(inputs: &[PathBuf], host: IpAddr, port: u16, allow_remote: bool) -> Result<()> {
    let mut results = vec![];
    let mut live: Option<Box<dyn LiveModel>> = None;
    for input in inputs {
        let scene_file = input.extension().and_then(|e| e.to_str()) == Some("toml");
        let paint_result = !scene_file
            && input.is_file()
            && inksim::output::h5::is_paint_result(input).unwrap_or(false);
        if scene_file || paint_result {
            if live.is_some() {
                bail!(
                    "{}: one scene is recomputed live at a time",
                    input.display()
                );
            }
            live = Some(live_model(input, paint_result)?);
            continue;
        }
        let files = source::result_files(input)?;
        let labels = source::study_labels(&files)?;
        for path in files {
            let mut r = result::load(&path)?;
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
            if let Some(l) = stem.and_then(|s| labels.get(&s)) {
                r.page.labels = l.clone();
            }
            results.push(r);
        }
    }
    let (srv, addr) = server::bind(server::Listen {
        host,
        port,
        allow_remote,
    })?;
    let mut site = server::Site::new(results);
    if let Some(model) = live {
        site = site.with_live(model)?;
    }
    println!("inksim view: http://{addr}/  (Ctrl-C stops it)");
    SERVING.store(true, Ordering::SeqCst);
    let stop = AtomicBool::new(false);
    server::serve(&srv, &site, &stop);
    Ok(())
}

/// The live model of a scene or paint file, or of a paint's result (its
/// fast model from the exact config the file holds).
fn live_model(input: &Path, paint_result: bool) -> Result<Box<dyn LiveModel>> {
    if paint_result {
        let (config_path, text) = inksim::output::h5::read_paint_config(input)?;
        let scene = inksim::config::parse_paint(Path::new(&config_path), &text)?;
        return Ok(Box::new(LivePaint::new(scene)?));
    }
    let config = super::ConfigFile::read(input)?;
    if config.is_study() {
        bail!(
            "{}: a study file; give its results' folder (<output_dir>/<profile>) or its summary.h5",
            config.display()
        );
    }
    Ok(if config.is_paint() {
        let scene = inksim::config::parse_paint(input, &config.text)?;
        Box::new(LivePaint::new(scene)?)
    } else {
        let scene = config.scene()?;
        if scene.stack.is_some() {
            Box::new(StackTransfer::new(&scene)?)
        } else {
            Box::new(RadiativeTransfer::new(&scene)?)
        }
    })
}
