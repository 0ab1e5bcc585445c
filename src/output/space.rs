//! Free space of the file system that holds a folder, for the disk
//! preflight of a run (`pipeline::disk`). The standard library has no call
//! for it; `statvfs(3)` (through the `libc` crate) gives the blocks an
//! unprivileged process may still use.

use std::path::Path;

/// Bytes an unprivileged process may still write on the file system of
/// `dir`, or of its nearest existing ancestor (the output folder may not be
/// there yet); `None` where the system does not say.
pub fn available_bytes(dir: &Path) -> Option<u64> {
    // An empty relative path (the parent of a bare name) is the working
    // directory.
    let mut at = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    while !at.exists() {
        at = match at.parent() {
            Some(p) if p.as_os_str().is_empty() => Path::new("."),
            Some(p) => p,
            None => return None,
        };
    }
    statvfs_available(at)
}

#[cfg(unix)]
fn statvfs_available(at: &Path) -> Option<u64> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let c = CString::new(at.as_os_str().as_bytes()).ok()?;
    let mut s = std::mem::MaybeUninit::<libc::statvfs>::uninit();
    // SAFETY: `c` is a valid NUL-terminated path and `s` points to writable
    // memory of the struct's size; the struct is read only when the call
    // reports success, which means it filled it in.
    let rc = unsafe { libc::statvfs(c.as_ptr(), s.as_mut_ptr()) };
    if rc != 0 {
        return None;
    }
    let s = unsafe { s.assume_init() };
    #[allow(clippy::unnecessary_cast)] // the field types differ between systems
    Some((s.f_bavail as u64).saturating_mul(s.f_frsize as u64))
}

#[cfg(not(unix))]
fn statvfs_available(_: &Path) -> Option<u64> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_not_yet_there_is_measured_on_its_nearest_ancestor() {
        let dir = tempfile::tempdir().unwrap();
        let here = available_bytes(dir.path()).expect("statvfs on a temporary folder");
        assert!(here > 0);
        let deeper = available_bytes(&dir.path().join("a/b/c")).unwrap();
        // The same file system, measured moments apart.
        let diff = here.abs_diff(deeper) as f64;
        assert!(diff < 0.01 * here as f64 + 1e8, "{here} vs {deeper}");
        assert!(available_bytes(Path::new("")).is_some());
        assert!(available_bytes(Path::new("not-here-yet/deeper")).is_some());
    }
}
