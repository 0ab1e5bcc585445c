//! The names of temporary files (`<name>.<pid>-<n>.tmp`, or `<name>.tmp`
//! from older writers): which output a temporary file is for. Shared by the
//! atomic writer, which makes and finds them, and the error messages, which
//! name the output rather than its temporary file.

use std::path::{Path, PathBuf};

/// The output a temporary file is written for (`<name>` of
/// `<name>.<pid>-<n>.tmp` or `<name>.tmp`); any other path is itself.
pub fn output_of(path: &Path) -> PathBuf {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return path.to_path_buf();
    };
    // The suffix starts at one of the name's dots.
    for (i, _) in name.match_indices('.') {
        if i > 0 && is_temp_suffix(&name[i..]) {
            return path.with_file_name(&name[..i]);
        }
    }
    path.to_path_buf()
}

/// `.tmp` or `.<digits>-<digits>.tmp`.
pub(crate) fn is_temp_suffix(rest: &str) -> bool {
    let Some(mid) = rest.strip_suffix(".tmp") else {
        return false;
    };
    if mid.is_empty() {
        return true;
    }
    let Some(mid) = mid.strip_prefix('.') else {
        return false;
    };
    let Some((pid, n)) = mid.split_once('-') else {
        return false;
    };
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    digits(pid) && digits(n)
}
