//! A study's summary file read back for its variants' axis labels: the
//! `name` coordinate and `/labels/<axis>` (written by the merge; layout in
//! docs/FORMAT.md).

use std::path::Path;

use hdf5::types::VarLenUnicode;

use super::IoError;

/// Each variant's name and its `(axis, label)` pairs (axes where the
/// variant has no label left out), in the summary's order.
pub type VariantLabels = Vec<(String, Vec<(String, String)>)>;

/// The variants' axis labels of the study summary `path`.
pub fn read_study_labels(path: &Path) -> Result<VariantLabels, IoError> {
    let hdf = |source| IoError::Hdf5 {
        path: path.to_path_buf(),
        source,
    };
    let strings = |d: hdf5::Dataset| -> Result<Vec<String>, IoError> {
        Ok(d.read_raw::<VarLenUnicode>()
            .map_err(hdf)?
            .iter()
            .map(|s| s.as_str().to_string())
            .collect())
    };
    let file = super::open(path).map_err(hdf)?;
    let names = strings(file.dataset("name").map_err(hdf)?)?;
    let group = file.group("labels").map_err(hdf)?;
    let mut out: VariantLabels = names.into_iter().map(|n| (n, vec![])).collect();
    for axis in group.member_names().map_err(hdf)? {
        let labels = strings(group.dataset(&axis).map_err(hdf)?)?;
        if labels.len() != out.len() {
            return Err(IoError::Format {
                path: path.to_path_buf(),
                message: format!(
                    "/labels/{axis} has {} entries for {} variants",
                    labels.len(),
                    out.len()
                ),
            });
        }
        for ((_, pairs), label) in out.iter_mut().zip(labels) {
            if !label.is_empty() {
                pairs.push((axis.clone(), label));
            }
        }
    }
    Ok(out)
}
