//! Records the source revision in the binary: `INKSIM_COMMIT` is the short
//! git commit checked out at build time, or `unknown` outside a git
//! checkout (e.g. a source archive). Uncommitted changes are not flagged:
//! tracking them would rebuild the crate on every `git add`.

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    if !out.status.success() {
        return None;
    }
    Some(String::from_utf8(out.stdout).ok()?.trim().to_string())
}

fn main() {
    let commit = git(&["rev-parse", "--short=12", "HEAD"]);
    let value = commit.unwrap_or_else(|| "unknown".to_string());
    println!("cargo:rustc-env=INKSIM_COMMIT={value}");
    // Rebuild when HEAD moves or the branch it names gets a new commit.
    for dir in [
        git(&["rev-parse", "--git-dir"]),
        git(&["rev-parse", "--git-common-dir"]),
    ]
    .into_iter()
    .flatten()
    {
        for f in ["HEAD", "packed-refs"] {
            println!("cargo:rerun-if-changed={dir}/{f}");
        }
    }
    if let Some(r) = git(&["symbolic-ref", "-q", "HEAD"]) {
        if let Some(dir) = git(&["rev-parse", "--git-common-dir"]) {
            println!("cargo:rerun-if-changed={dir}/{r}");
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
}
