//! Which results a command line names: result files, or a study's folder
//! (its `variants/`), or its `summary.h5`.

use std::path::{Path, PathBuf};

use super::ViewError;

/// The result files `input` names, in name order: the file itself, or the
/// `*.h5` of a folder's `variants/` (a study) or of the folder itself, or
/// those beside a study's `summary.h5`. `summary.h5` is never one of them.
pub fn result_files(input: &Path) -> Result<Vec<PathBuf>, ViewError> {
    if !input.exists() {
        return Err(ViewError::Missing(input.to_path_buf()));
    }
    let folder = if input.is_dir() {
        input.to_path_buf()
    } else if input.file_name().and_then(|n| n.to_str()) == Some("summary.h5") {
        input.parent().unwrap_or(Path::new(".")).to_path_buf()
    } else {
        return Ok(vec![input.to_path_buf()]);
    };
    let variants = folder.join("variants");
    let dir = if variants.is_dir() { variants } else { folder };
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|_| ViewError::Missing(dir.clone()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().and_then(|e| e.to_str()) == Some("h5")
                && p.file_name().and_then(|n| n.to_str()) != Some("summary.h5")
        })
        .collect();
    out.sort();
    if out.is_empty() {
        return Err(ViewError::NoResults(input.to_path_buf()));
    }
    Ok(out)
}

/// The axis labels of the variants among `files`, by file stem, from the
/// study's `summary.h5` beside their `variants/` folder (none where there is
/// no summary: the study has not been merged).
pub fn study_labels(
    files: &[PathBuf],
) -> Result<std::collections::HashMap<String, Vec<(String, String)>>, ViewError> {
    let mut out = std::collections::HashMap::new();
    let mut seen = std::collections::HashSet::new();
    for f in files {
        let Some(variants) = f.parent() else { continue };
        if variants.file_name().and_then(|n| n.to_str()) != Some("variants") {
            continue;
        }
        let summary = variants
            .parent()
            .unwrap_or(Path::new("."))
            .join("summary.h5");
        if !summary.is_file() || !seen.insert(summary.clone()) {
            continue;
        }
        for (name, labels) in crate::output::h5::read_study_labels(&summary)? {
            out.insert(name, labels);
        }
    }
    Ok(out)
}
