//! Opening and creating HDF5 files, the one way every stage does it: the
//! scene's inputs (an ε grid, read by `raster`) and the results (`output::h5`
//! re-exports both functions). HDF5 refuses a second open of a file that is
//! already open in the process with other locking flags, so everything in
//! inksim, its tests included, opens files through here.
//!
//! HDF5 opens a file without close-on-exec and locks it with `flock(2)`. A
//! process started by any thread of the program while the file is open (a
//! test's CLI, a Python user's worker, a cluster helper) inherits the
//! descriptor, and with it the lock, and keeps both after the program has
//! closed the file: the next open of that file then fails with "unable to
//! lock file". Every file inksim opens or creates is therefore marked
//! close-on-exec as soon as HDF5 has opened it.
//!
//! That still leaves the moment between HDF5's `open(2)` and the mark, in
//! which another thread may start a child. So inksim also opens its files
//! without HDF5's own lock: it never needs it, because every result is
//! written under a temporary name, renamed into place when complete and
//! guarded by inksim's own lock file (`output::lock`), and no file is ever
//! opened for writing in place. A reader therefore never meets a file that
//! is being written, and a stray descriptor in a child can no longer make a
//! later open fail.
use std::ffi::CString;
use std::os::raw::{c_int, c_void};
use std::path::Path;

use hdf5::file::FileDriver;
use hdf5_sys::h5f::{H5Fcreate, H5Fopen, H5F_ACC_RDONLY, H5F_ACC_TRUNC};
use hdf5_sys::h5i::hid_t;
use hdf5_sys::h5p::{H5Pset_file_locking, H5P_DEFAULT};

/// Create (truncate) `path` for writing, close-on-exec, without HDF5's lock.
pub fn create(path: impl AsRef<Path>) -> hdf5::Result<hdf5::File> {
    let name = c_path(path.as_ref())?;
    let file = with_unlocked_access(|fapl| {
        // SAFETY: `name` is a valid C string and `fapl` a valid property
        // list for the call; HDF5's global lock is held by the caller.
        unsafe { H5Fcreate(name.as_ptr(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl) }
    })?;
    close_on_exec(&file)?;
    Ok(file)
}

/// Open `path` read-only, close-on-exec, without HDF5's lock.
pub fn open(path: impl AsRef<Path>) -> hdf5::Result<hdf5::File> {
    let name = c_path(path.as_ref())?;
    let file = with_unlocked_access(|fapl| {
        // SAFETY: as in `create`.
        unsafe { H5Fopen(name.as_ptr(), H5F_ACC_RDONLY, fapl) }
    })?;
    close_on_exec(&file)?;
    Ok(file)
}

fn c_path(path: &Path) -> hdf5::Result<CString> {
    let text = path
        .to_str()
        .ok_or_else(|| hdf5::Error::from(format!("file name is not UTF-8: {path:?}").as_str()))?;
    CString::new(text)
        .map_err(|_| hdf5::Error::from(format!("file name holds a NUL byte: {path:?}").as_str()))
}

/// Run `open_file` with the file access list the hdf5 crate would use, less
/// HDF5's file locking, and take the file id it returns. The crate's builder
/// cannot carry that property, so the call is made here.
fn with_unlocked_access(open_file: impl FnOnce(hid_t) -> hid_t) -> hdf5::Result<hdf5::File> {
    hdf5::sync::sync(|| {
        let fapl = hdf5::plist::FileAccess::build().finish()?;
        // SAFETY: `fapl` is a file access property list owned here.
        if unsafe { H5Pset_file_locking(fapl.id(), 0, 1) } < 0 {
            return Err(hdf5::Error::query().unwrap_or_else(|e| e));
        }
        let id = open_file(fapl.id());
        if id < 0 {
            return Err(hdf5::Error::query().unwrap_or_else(|e| e));
        }
        // SAFETY: `id` is a file id just returned by HDF5 and owned by no one
        // else; the returned `File` closes it.
        unsafe { hdf5::from_id::<hdf5::File>(id) }
    })
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

    /// A file another descriptor holds locked (as a child that inherited it
    /// in the moment before close-on-exec was set would) still opens and is
    /// created anew: inksim does not ask for HDF5's lock. With HDF5's
    /// locking on, both calls fail with "unable to lock file".
    #[test]
    fn a_file_locked_elsewhere_still_opens() {
        use std::os::fd::AsRawFd;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.h5");
        create(&path).unwrap().close().unwrap();
        let holder = std::fs::File::open(&path).unwrap();
        // SAFETY: flock on a descriptor owned by `holder`.
        let rc = unsafe { libc::flock(holder.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
        assert_eq!(rc, 0);
        open(&path).unwrap().close().unwrap();
        create(&path).unwrap().close().unwrap();
        drop(holder);
    }
}
