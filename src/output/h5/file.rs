//! Opening and creating HDF5 files so that no child process holds them.
//!
//! HDF5 opens a file without close-on-exec and locks it with `flock(2)`. A
//! process started by any thread of the program while the file is open (a
//! test's CLI, a Python user's worker, a cluster helper) inherits the
//! descriptor, and with it the lock, and keeps both after the program has
//! closed the file: the next open of that file then fails with "unable to
//! lock file". Every file inksim opens or creates is therefore marked
//! close-on-exec as soon as HDF5 has opened it.
use std::os::raw::{c_int, c_void};
use std::path::Path;

use hdf5::file::FileDriver;

/// Create (truncate) `path` for writing, close-on-exec.
pub fn create(path: &Path) -> hdf5::Result<hdf5::File> {
    let file = hdf5::File::create(path)?;
    close_on_exec(&file)?;
    Ok(file)
}

/// Open `path` read-only, close-on-exec.
pub fn open(path: &Path) -> hdf5::Result<hdf5::File> {
    let file = hdf5::File::open(path)?;
    close_on_exec(&file)?;
    Ok(file)
}

/// Mark the descriptor behind `file` close-on-exec. Only the default POSIX
/// driver (sec2) hands out a plain descriptor; the others are left as HDF5
/// opened them.
fn close_on_exec(file: &hdf5::File) -> hdf5::Result<()> {
    if !matches!(file.access_plist()?.driver(), FileDriver::Sec2) {
        return Ok(());
    }
    let mut handle: *mut c_void = std::ptr::null_mut();
    // SAFETY: the file id is valid while `file` lives; HDF5's global lock
    // is held for the call, as for every call the hdf5 crate makes.
    let rc = hdf5::sync::sync(|| unsafe {
        hdf5_sys::h5f::H5Fget_vfd_handle(file.id(), hdf5_sys::h5p::H5P_DEFAULT, &mut handle)
    });
    if rc < 0 || handle.is_null() {
        return Err(hdf5::Error::from("no file handle from the sec2 driver"));
    }
    // SAFETY: for the sec2 driver the handle points at the file's descriptor.
    let fd = unsafe { *(handle as *const c_int) };
    // SAFETY: fcntl on a descriptor this process owns.
    let ok = unsafe {
        let flags = libc::fcntl(fd, libc::F_GETFD);
        flags >= 0 && libc::fcntl(fd, libc::F_SETFD, flags | libc::FD_CLOEXEC) == 0
    };
    if ok {
        Ok(())
    } else {
        Err(hdf5::Error::from(
            std::io::Error::last_os_error().to_string().as_str(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A child started while a file is open does not keep it: once the child
    /// has replaced its image, none of its descriptors leads to the file, and
    /// the file opens again at once after the program closes it. Without
    /// close-on-exec the child holds the descriptor (and HDF5's lock) for its
    /// whole life and the wait below runs out.
    ///
    /// The wait is needed because the kernel lets a parent of `vfork`
    /// (`posix_spawn`) go on as soon as the child's new memory is in place,
    /// a few microseconds before it closes its close-on-exec descriptors.
    #[test]
    fn a_child_process_does_not_inherit_an_open_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.h5");
        let file = create(&path).unwrap();
        let mut child = std::process::Command::new("sleep")
            .arg("5")
            .spawn()
            .unwrap();
        let fds = format!("/proc/{}/fd", child.id());
        let holds = || {
            std::fs::read_dir(&fds).is_ok_and(|entries| {
                entries
                    .flatten()
                    .any(|e| std::fs::read_link(e.path()).is_ok_and(|t| t == path))
            })
        };
        let start = std::time::Instant::now();
        while holds() && start.elapsed() < std::time::Duration::from_secs(2) {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        let held = holds();
        file.close().unwrap();
        let reopened = open(&path);
        child.kill().unwrap();
        child.wait().unwrap();
        assert!(!held, "the child still holds the file after 2 s");
        reopened.unwrap();
    }
}
