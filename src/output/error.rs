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
    #[error("{path}: {source}")]
    File {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: HDF5 error: {source}")]
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
