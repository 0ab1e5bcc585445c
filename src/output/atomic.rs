//! Atomic file writes, used by every writer (result files, geometry, pictures,
//! study summaries, sbatch scripts).
//!
//! A file is written to `<path>.<pid>-<n>.tmp` in the destination folder
//! (unique per process and write, so concurrent writers never share one),
//! synced and renamed onto `<path>`, and the folder is synced after the
//! rename: a reader (or a resumed run) sees either the old file or the
//! complete new one, never a half-written one. On any error the temporary
//! file is removed and an existing `path` is left untouched. Temporary files
//! being written are registered so that an interrupt handler can remove them
//! ([`remove_unfinished`]); those of a killed process are found by
//! [`stale_temporaries`] and removed by the next writer of the same output.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use crate::output::error::IoError;
use crate::output::temp_name::is_temp_suffix;
pub use crate::output::temp_name::output_of;

/// Temporary files this process is writing now.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Numbers the temporary files of this process.
static NEXT: AtomicU64 = AtomicU64::new(0);

/// Remove every temporary file this process is writing (for an interrupt:
/// the outputs keep their previous contents). Returns how many were removed.
pub fn remove_unfinished() -> usize {
    let live = match LIVE.lock() {
        Ok(g) => g.clone(),
        Err(e) => e.into_inner().clone(),
    };
    live.iter().filter(|p| fs::remove_file(p).is_ok()).count()
}

/// Temporary files of `target` left in its folder, by this or any process
/// (`<name>.tmp` or `<name>.<pid>-<n>.tmp`). Only the writer that holds the
/// output's lock ([`crate::output::lock`]) may remove them.
pub fn stale_temporaries(target: &Path) -> Vec<PathBuf> {
    let Some(name) = target.file_name() else {
        return Vec::new();
    };
    let name = name.to_string_lossy();
    let folder = folder_of(target);
    let Ok(entries) = fs::read_dir(&folder) else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy())
                .and_then(|n| n.strip_prefix(name.as_ref()).map(str::to_string))
                .is_some_and(|rest| is_temp_suffix(&rest))
        })
        .collect()
}

fn folder_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Write arbitrary bytes atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    write_atomic_with(path, |tmp| {
        let err = |source| IoError::File {
            path: tmp.to_path_buf(),
            source,
        };
        let mut f = fs::OpenOptions::new()
            .write(true)
            .truncate(true)
            .open(tmp)
            .map_err(err)?;
        f.write_all(bytes).map_err(err)
    })
}

/// Write a file atomically through `write`, which creates and fills the
/// temporary path it is given (for writers that open files themselves, such
/// as HDF5). Errors of `write` pass through unchanged.
pub fn write_atomic_with<E: From<IoError>>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    let tmp = TempFile::prepare(path)?;
    write(&tmp.path)?;
    Ok(tmp.commit()?)
}

/// `<path>.<pid>-<n>.tmp`, removed on drop unless renamed onto `<path>` by [`TempFile::commit`].
struct TempFile {
    path: PathBuf,
    target: PathBuf,
    committed: bool,
}

impl TempFile {
    /// Check the destination: folder exists or can be created, and a file can
    /// be created in it (the temporary file itself, left empty).
    fn prepare(target: &Path) -> Result<Self, IoError> {
        let folder_err = |source| IoError::Folder {
            path: target.to_path_buf(),
            source,
        };
        let Some(name) = target.file_name() else {
            return Err(folder_err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "path does not name a file",
            )));
        };
        let folder = folder_of(target);
        fs::create_dir_all(&folder).map_err(folder_err)?;
        if target.is_dir() {
            return Err(IoError::File {
                path: target.to_path_buf(),
                source: std::io::Error::new(
                    std::io::ErrorKind::AlreadyExists,
                    "is a directory, expected a file path",
                ),
            });
        }
        let mut tmp_name = name.to_os_string();
        tmp_name.push(format!(
            ".{}-{}.tmp",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        let path = folder.join(tmp_name);
        fs::File::create(&path).map_err(|source| IoError::Folder {
            path: path.clone(),
            source,
        })?;
        if let Ok(mut live) = LIVE.lock() {
            live.push(path.clone());
        }
        Ok(TempFile {
            path,
            target: target.to_path_buf(),
            committed: false,
        })
    }

    fn io_err(&self, source: std::io::Error) -> IoError {
        IoError::File {
            path: self.path.clone(),
            source,
        }
    }

    /// Sync the finished temporary file to disk and rename it onto the target.
    fn commit(mut self) -> Result<(), IoError> {
        fs::File::open(&self.path)
            .and_then(|f| f.sync_all())
            .map_err(|source| self.io_err(source))?;
        fs::rename(&self.path, &self.target).map_err(|source| IoError::File {
            path: self.target.clone(),
            source,
        })?;
        self.committed = true;
        // Best effort: make the rename itself durable.
        if let Some(dir) = self.target.parent().filter(|p| !p.as_os_str().is_empty()) {
            if let Ok(d) = fs::File::open(dir) {
                let _ = d.sync_all();
            }
        }
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_file(&self.path);
        }
        if let Ok(mut live) = LIVE.lock() {
            live.retain(|p| p != &self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporaries_are_unique_registered_and_found_when_stale() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("r.h5");
        let mut seen = Vec::new();
        write_atomic_with(&target, |tmp| -> Result<(), IoError> {
            seen.push(tmp.to_path_buf());
            assert!(LIVE.lock().unwrap().contains(&tmp.to_path_buf()));
            // A second write of the same output at the same time gets its own name.
            write_atomic_with(&target, |tmp2| -> Result<(), IoError> {
                assert_ne!(tmp, tmp2);
                seen.push(tmp2.to_path_buf());
                fs::write(tmp2, b"inner").unwrap();
                Ok(())
            })?;
            fs::write(tmp, b"outer").unwrap();
            Ok(())
        })
        .unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"outer");
        let me = format!("r.h5.{}-", std::process::id());
        for p in &seen {
            assert!(p.file_name().unwrap().to_string_lossy().starts_with(&me));
            assert!(!p.exists());
            assert!(!LIVE.lock().unwrap().contains(p));
        }
        // Left by killed writers (old and new naming), and look-alikes that are not.
        for n in [
            "r.h5.tmp",
            "r.h5.77-3.tmp",
            "r.h5.x-3.tmp",
            "r.h5.7.tmp",
            "r.h5x.1-2.tmp",
        ] {
            fs::write(dir.path().join(n), b"").unwrap();
        }
        let mut stale: Vec<String> = stale_temporaries(&target)
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        stale.sort();
        assert_eq!(stale, ["r.h5.77-3.tmp", "r.h5.tmp"]);
        // Errors name the output a temporary file was for.
        for (tmp, out) in [
            ("d/r.h5.77-3.tmp", "d/r.h5"),
            ("d/r.h5.tmp", "d/r.h5"),
            ("d/r.tile.png.1-0.tmp", "d/r.tile.png"),
            ("d/r.h5.7tmp", "d/r.h5.7tmp"),
            ("d/r.h5", "d/r.h5"),
        ] {
            assert_eq!(output_of(Path::new(tmp)), Path::new(out));
        }
    }
}
