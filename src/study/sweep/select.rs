//! A subset of a study's variants, chosen by axis labels: `--only
//! pigment=red --only pvc=pvc30,pvc50` keeps the variants whose label on
//! each named axis is one of those given. Variants keep their names, seeds,
//! indices and result files, so a subset's results are the full study's
//! results (a later full run resumes from them).

use super::{Expansion, Study};
use crate::study::StudyError;

/// One `AXIS=LABEL[,LABEL…]` restriction.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Selection {
    pub axis: String,
    pub labels: Vec<String>,
}

impl Selection {
    /// Parse `AXIS=LABEL[,LABEL…]` (the axis and labels are checked against a
    /// study by [`Expansion::select`]).
    pub fn parse(text: &str) -> Result<Self, String> {
        let (axis, labels) = text.split_once('=').ok_or_else(|| {
            format!("--only `{text}`: expected AXIS=LABEL[,LABEL…], e.g. pigment=red")
        })?;
        let labels: Vec<String> = labels
            .split(',')
            .map(|l| l.trim().to_string())
            .filter(|l| !l.is_empty())
            .collect();
        if axis.trim().is_empty() || labels.is_empty() {
            return Err(format!(
                "--only `{text}`: expected AXIS=LABEL[,LABEL…], e.g. pigment=red"
            ));
        }
        Ok(Self {
            axis: axis.trim().to_string(),
            labels,
        })
    }
}

impl std::fmt::Display for Selection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}={}", self.axis, self.labels.join(","))
    }
}

impl<S> Expansion<S> {
    /// Keep only the variants every selection admits. An unknown axis or
    /// label, or a selection that keeps nothing, is an error naming what the
    /// study has.
    pub fn select(mut self, study: &Study, only: &[Selection]) -> Result<Self, StudyError> {
        if only.is_empty() {
            return Ok(self);
        }
        for s in only {
            let Some(axis) = study.axes.iter().find(|a| a.name == s.axis) else {
                let names: Vec<&str> = study.axes.iter().map(|a| a.name.as_str()).collect();
                return Err(study.err(format!(
                    "--only {s}: the study has no axis `{}`; its axes are {}",
                    s.axis,
                    names.join(", ")
                )));
            };
            for l in &s.labels {
                if !axis.values.iter().any(|v| &v.label == l) {
                    let labels: Vec<&str> = axis.values.iter().map(|v| v.label.as_str()).collect();
                    return Err(study.err(format!(
                        "--only {s}: axis `{}` has no label `{l}`; its labels are {}",
                        s.axis,
                        labels.join(", ")
                    )));
                }
            }
        }
        self.variants.retain(|v| {
            only.iter().all(|s| {
                v.label(&s.axis)
                    .is_some_and(|l| s.labels.iter().any(|x| x == l))
            })
        });
        if self.variants.is_empty() {
            let text: Vec<String> = only.iter().map(|s| s.to_string()).collect();
            return Err(study.err(format!(
                "--only {}: no variant of the study has these labels together",
                text.join(" --only ")
            )));
        }
        self.selection = only.to_vec();
        Ok(self)
    }

    /// "pigment=red, pvc=pvc30" (empty for the whole study).
    pub fn selection_text(&self) -> String {
        let t: Vec<String> = self.selection.iter().map(|s| s.to_string()).collect();
        t.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_an_axis_and_its_labels() {
        let s = Selection::parse("pvc=pvc30, pvc50").unwrap();
        assert_eq!(s.axis, "pvc");
        assert_eq!(s.labels, vec!["pvc30", "pvc50"]);
        assert_eq!(s.to_string(), "pvc=pvc30,pvc50");
        assert!(Selection::parse("pvc").is_err());
        assert!(Selection::parse("pvc=").is_err());
        assert!(Selection::parse("=red").is_err());
    }
}
