//! Atomic file writes, used by every writer (result files, geometry, pictures,
//! study summaries, sbatch scripts).
//!
//! A file is written to `<path>.tmp` in the destination folder, synced and
//! renamed onto `<path>`, and the folder is synced after the rename: a reader
//! (or a resumed run) sees either the old file or the complete new one, never
//! a half-written one. On any error the temporary file is removed and an
//! existing `path` is left untouched.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::output::error::IoError;

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

/// `<path>.tmp`, removed on drop unless renamed onto `<path>` by [`TempFile::commit`].
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
        let folder = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
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
        tmp_name.push(".tmp");
        let path = folder.join(tmp_name);
        fs::File::create(&path).map_err(|source| IoError::Folder {
            path: path.clone(),
            source,
        })?;
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
    }
}
