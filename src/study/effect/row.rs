//! A finished variant of an effect study and its result, as the merge,
//! the findings, the page and the summary file read it.

use crate::config::paint::PaintScene;
use crate::output::h5::PaintRecord;
use crate::study::sweep::Variant;

/// A finished variant and its result.
pub struct EffectRow<'a> {
    pub v: &'a Variant<PaintScene>,
    pub rec: PaintRecord,
}
