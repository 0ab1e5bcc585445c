//! One writer per output: an advisory lock on `<folder>/.<name>.lock`, taken
//! before a result (a scene's, or one study variant's) is computed and held
//! until its files are written.
//!
//! The lock is the operating system's (`flock` on Unix, `LockFileEx` on
//! Windows, through [`std::fs::File::try_lock`]): it belongs to the open file,
//! so it is released when the process ends, however it ends (a kill, a
//! crash, a lost node); a lock file left behind by a dead process locks
//! nothing. The file holds the holder's process id and host for messages.
//! A run that computed something leaves its lock file in the folder (empty
//! of results, hidden by its leading dot); a refused run removes it
//! ([`OutputLock::remove`]), so that a refusal leaves nothing behind. A lock
//! is only held once the file it was taken on is still the one at the path
//! (checked after locking, retried otherwise): a process that waited on a
//! file another one then removed does not hold "the" lock beside a third.

use crate::output::error::IoError;
use std::fs;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// A held lock; released on drop.
#[derive(Debug)]
pub struct OutputLock {
    file: fs::File,
    path: PathBuf,
}

/// The lock file guarding `target`: `.<file name>.lock` beside it.
pub fn lock_path(target: &Path) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let folder = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    folder.join(format!(".{name}.lock"))
}

impl OutputLock {
    /// Take the lock of `target` if no other process holds it: `Ok(None)`
    /// when one does. The folder is created if missing.
    pub fn try_acquire(target: &Path) -> Result<Option<OutputLock>, IoError> {
        loop {
            let (file, path) = open(target)?;
            match file.try_lock() {
                Ok(()) if is_current(&file, &path) => {
                    return Ok(Some(OutputLock::held(file, path)?))
                }
                Ok(()) => continue,
                Err(fs::TryLockError::WouldBlock) => return Ok(None),
                Err(fs::TryLockError::Error(source)) => return Err(IoError::File { path, source }),
            }
        }
    }

    /// Take the lock of `target`, waiting for another process to release it.
    pub fn acquire(target: &Path) -> Result<OutputLock, IoError> {
        loop {
            let (file, path) = open(target)?;
            file.lock().map_err(|source| IoError::File {
                path: path.clone(),
                source,
            })?;
            if is_current(&file, &path) {
                return OutputLock::held(file, path);
            }
        }
    }

    /// Remove the lock file and let go: for a run that wrote nothing.
    pub fn remove(self) {
        let _ = fs::remove_file(&self.path);
    }

    fn held(mut file: fs::File, path: PathBuf) -> Result<OutputLock, IoError> {
        let io = |source| IoError::File {
            path: path.clone(),
            source,
        };
        file.set_len(0).map_err(io)?;
        file.rewind().map_err(io)?;
        file.write_all(holder_text().as_bytes()).map_err(io)?;
        Ok(OutputLock { file, path })
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        let _ = self.file.unlock();
    }
}

/// Who holds (or last held) the lock of `target`, as its file says:
/// `pid 1234 on host`, or `another process` when it cannot be read.
pub fn holder(target: &Path) -> String {
    let mut s = String::new();
    match fs::File::open(lock_path(target)).and_then(|mut f| f.read_to_string(&mut s)) {
        Ok(_) if !s.trim().is_empty() => s.trim().to_string(),
        _ => "another process".into(),
    }
}

fn open(target: &Path) -> Result<(fs::File, PathBuf), IoError> {
    let path = lock_path(target);
    if let Some(folder) = path.parent() {
        fs::create_dir_all(folder).map_err(|source| IoError::Folder {
            path: folder.to_path_buf(),
            source,
        })?;
    }
    let file = fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(|source| IoError::File {
            path: path.clone(),
            source,
        })?;
    Ok((file, path))
}

/// Whether `file` is still the file at `path` (not removed, not replaced).
fn is_current(file: &fs::File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (file, path);
        true
    }
}

fn holder_text() -> String {
    let host = fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "this host".into());
    format!("pid {} on {host}", std::process::id())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A removed lock file is gone, and a lock taken on a file that was
    /// removed meanwhile is not held: the next taker gets the new file.
    #[test]
    fn a_removed_lock_leaves_nothing_and_stale_files_are_not_locks() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("a.h5");
        let lock = OutputLock::try_acquire(&target).unwrap().expect("free");
        let path = lock.path().to_path_buf();
        lock.remove();
        assert!(!path.exists());
        // A file opened before its removal is not the lock any more.
        let (stale, _) = open(&target).unwrap();
        fs::remove_file(&path).unwrap();
        assert!(!is_current(&stale, &path));
        let (fresh, _) = open(&target).unwrap();
        assert!(is_current(&fresh, &path));
        assert!(!is_current(&stale, &path));
    }

    #[test]
    fn a_second_holder_is_refused_until_the_first_lets_go() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("sub").join("a.h5");
        let first = OutputLock::try_acquire(&target).unwrap().expect("free");
        assert!(first.path().ends_with("sub/.a.h5.lock"));
        // A second open file description conflicts even within one process.
        assert!(OutputLock::try_acquire(&target).unwrap().is_none());
        assert!(holder(&target).starts_with(&format!("pid {} on ", std::process::id())));
        drop(first);
        assert!(OutputLock::try_acquire(&target).unwrap().is_some());
        // Another target is independent.
        let _a = OutputLock::acquire(&target).unwrap();
        assert!(OutputLock::try_acquire(&dir.path().join("b.h5"))
            .unwrap()
            .is_some());
    }
}
