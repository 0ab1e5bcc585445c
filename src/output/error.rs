//! The one error type of the output stage: files, folders and HDF5.

use std::path::PathBuf;

/// Everything that can go wrong while writing or reading output files.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    #[error("{path}: output folder cannot be created or used: {source}")]
    Folder {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {}", shown(path), io_message(source))]
    File {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {}", shown(path), hdf5_message(source))]
    Hdf5 { path: PathBuf, source: hdf5::Error },
    #[error("{path}: cannot write {what}: {message}")]
    Invalid {
        path: PathBuf,
        what: String,
        message: String,
    },
    #[error("{path}: not a valid inksim result file: {message}")]
    Format { path: PathBuf, message: String },
}

/// What a full disk is called, whichever layer reports it.
const DISK_FULL: &str = "the disk is full (no space left on device); the file's previous \
                         contents, if any, are kept";

/// The output a path names: a temporary file being written
/// (`<name>.<pid>-<n>.tmp`) is shown as the output it was to become.
fn shown(path: &std::path::Path) -> String {
    crate::output::temp_name::output_of(path)
        .display()
        .to_string()
}

fn io_message(e: &std::io::Error) -> String {
    if e.kind() == std::io::ErrorKind::StorageFull {
        DISK_FULL.to_string()
    } else {
        e.to_string()
    }
}

/// HDF5's error, or one line for a full disk (HDF5 reports the system's
/// "No space left on device" deep in its error stack).
fn hdf5_message(e: &hdf5::Error) -> String {
    let text = e.to_string();
    if text.contains("No space left on device") {
        DISK_FULL.to_string()
    } else {
        format!("HDF5 error: {text}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_disk_is_said_in_one_line_naming_the_output() {
        // /dev/full answers every write with ENOSPC, as a full disk does.
        use std::io::Write;
        let Ok(mut f) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
            return; // not a Linux system
        };
        let source = f
            .write_all(&[0u8; 4096])
            .and_then(|()| f.flush())
            .unwrap_err();
        let e = IoError::File {
            path: PathBuf::from("out/r.h5.4242-7.tmp"),
            source,
        };
        assert_eq!(e.to_string(), format!("out/r.h5: {DISK_FULL}"));
        let other = IoError::File {
            path: PathBuf::from("out/r.png"),
            source: std::io::Error::new(std::io::ErrorKind::PermissionDenied, "denied"),
        };
        assert_eq!(other.to_string(), "out/r.png: denied");
    }
}
