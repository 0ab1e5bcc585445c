//! The disk a run needs: the estimate holds what a run writes, and a run
//! (or `check`) whose results the output's file system cannot hold is
//! refused before any solve, in one line.
use std::path::Path;
use std::process::Command;

mod common;
use common::scene::SceneToml;
use inksim::pipeline::disk;

/// The shared tiny scene, on paper.
fn tiny() -> SceneToml {
    SceneToml::tiny().quadrature_points(3).paper(0.8)
}

fn bytes_in(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().metadata().unwrap().len())
        .sum()
}

#[test]
fn the_disk_estimate_holds_what_a_run_writes() {
    // The estimate is on the safe side but not absurdly so: between the
    // bytes written and ten times them, for the result alone, the usual
    // products and every product (with two realisations).
    for (outputs, realisations) in [
        (vec![], 1),
        (vec!["brdf", "tile"], 1),
        (vec!["brdf", "btdf", "tile", "merl", "preview"], 2),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let toml = tiny()
            .outputs(&outputs)
            .realisations(realisations)
            .output(&out, "tiny");
        let scene = toml.scene(dir.path());
        let estimate = disk::estimate_bytes(&scene, &inksim::pipeline::RunPlan::of(&scene));
        toml.run(dir.path());
        let written = bytes_in(&out) as f64;
        assert!(
            written <= estimate && estimate <= 10.0 * written,
            "{outputs:?}: wrote {written} bytes, estimated {estimate}"
        );
    }
}

/// A small file system of `kb` kilobytes at `at`, where this process may
/// mount one (root on Linux); `None` otherwise.
fn small_file_system(at: &Path, kb: u32) -> Option<Mount> {
    std::fs::create_dir_all(at).ok()?;
    let ok = Command::new("mount")
        .args(["-t", "tmpfs", "-o", &format!("size={kb}k"), "tmpfs"])
        .arg(at)
        .output()
        .ok()?
        .status
        .success();
    ok.then(|| Mount(at.to_path_buf()))
}

struct Mount(std::path::PathBuf);

impl Drop for Mount {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

#[test]
fn a_run_the_disk_cannot_hold_is_refused_before_any_solve() {
    let dir = tempfile::tempdir().unwrap();
    let small = dir.path().join("small");
    let Some(_mount) = small_file_system(&small, 256) else {
        eprintln!("skipped: this process cannot mount a small file system (needs root)");
        return;
    };
    let out = small.join("out");
    let cfg = tiny()
        .outputs(&["brdf", "tile"])
        .output(&out, "tiny")
        .write(dir.path());
    let scene = tiny()
        .outputs(&["brdf", "tile"])
        .output(&out, "tiny")
        .scene(dir.path());
    let need = disk::estimate_bytes(&scene, &inksim::pipeline::RunPlan::of(&scene));
    assert!(
        need > 256e3,
        "the test needs a result larger than the file system"
    );
    for cmd in ["check", "run"] {
        let o = Command::new(env!("CARGO_BIN_EXE_inksim"))
            .args([cmd, cfg.to_str().unwrap()])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{cmd}: {err}");
        let last = err.trim().lines().last().unwrap_or("");
        assert!(
            last.contains("not enough disk space") && last.contains("free some space"),
            "{cmd}: {err}"
        );
        // Refused before the first solve: no progress line, no file.
        assert!(!err.contains("1/"), "{cmd}: {err}");
        assert!(!out.join("tiny.h5").exists());
    }
}
