//! Merging a finished effect study, into the study folder, each file
//! atomically:
//! - `summary.h5`: a link per variant and the table of the variants (flop
//!   index, L*a*b* and L*C*h per geometry, sparkle per illumination,
//!   graininess, axis labels).
//! - `grids/<grid>[__<axis>-<label>…].png`: per declared grid (or the
//!   default one) the variants' multi-angle patches, and beside each
//!   `…-flop.png` their flop curves (L*, C*ab, h against the aspecular
//!   angle), both as each variant drew them.
//! - `summary.md`, `summary.html`: the findings, the per-label table, the
//!   variants' table and every variant's flop curve and patches.

use super::findings;
use super::page;
use super::row::EffectRow;
use crate::config::paint::PaintScene;
use crate::output::atomic;
use crate::output::h5;
use crate::output::render::canvas::Canvas;
use crate::pipeline::paint_files;
use crate::study::merge::{all_finished, compose, pictures, shrink, CELL_PX};
use crate::study::sweep::{Expansion, Study};
use crate::study::StudyError;
use std::path::PathBuf;

/// Largest side of a flop curve in a grid, pixels.
pub const FLOP_CELL_PX: usize = 360;

/// What the merge of an effect study wrote.
#[derive(Debug, Clone)]
pub struct EffectMergeReport {
    pub summary_h5: PathBuf,
    pub summary_md: PathBuf,
    pub summary_html: PathBuf,
    /// The grids of patches and of flop curves.
    pub grids: Vec<PathBuf>,
}

/// Merge a finished effect study (see the module docs).
pub fn merge(study: &Study, exp: &Expansion<PaintScene>) -> Result<EffectMergeReport, StudyError> {
    all_finished(study, exp)?;
    let rows = exp
        .variants
        .iter()
        .map(|v| {
            let [path, ..] = paint_files(&v.scene);
            Ok(EffectRow {
                v,
                rec: h5::read_paint(&path)?,
            })
        })
        .collect::<Result<Vec<_>, StudyError>>()?;
    let dir = &exp.study_dir;
    let grids = draw_grids(study, exp)?;
    let summary_h5 = dir.join("summary.h5");
    super::summary_h5::write(study, exp, &rows, &summary_h5)?;
    let steps = findings::steps(study, &rows);
    let means = findings::label_means(study, &rows);
    let blocks = page::blocks(study, exp, &rows, &steps, &means, &grids);
    let summary_md = dir.join("summary.md");
    let summary_html = dir.join("summary.html");
    atomic::write_atomic(&summary_md, page::markdown(&blocks).as_bytes())?;
    let title = format!("Effect study {}", study.name);
    atomic::write_atomic(&summary_html, page::html(&title, &blocks).as_bytes())?;
    Ok(EffectMergeReport {
        summary_h5,
        summary_md,
        summary_html,
        grids,
    })
}

/// Every grid picture: the patches, then the flop curves.
fn draw_grids(study: &Study, exp: &Expansion<PaintScene>) -> Result<Vec<PathBuf>, StudyError> {
    let grids_dir = exp.study_dir.join("grids");
    let mut out = vec![];
    for g in &study.grids {
        for pic in pictures(study, exp, g) {
            for (file, suffix, px, what) in [
                (1, "", CELL_PX, "multi-angle patches"),
                (
                    2,
                    "-flop",
                    FLOP_CELL_PX,
                    "flop curves: L*, C*ab, h against aspecular angle",
                ),
            ] {
                let mut tiles: Vec<Vec<Option<Canvas>>> = vec![];
                for line in &pic.cells {
                    let mut drawn = vec![];
                    for cell in line {
                        drawn.push(match cell {
                            Some(v) => {
                                let path = paint_files(&v.scene)[file].clone();
                                let bytes = std::fs::read(&path).map_err(|source| {
                                    StudyError::Io(h5::IoError::File { path, source })
                                })?;
                                Some(shrink(&Canvas::decode_png(&bytes)?, px))
                            }
                            None => None,
                        });
                    }
                    tiles.push(drawn);
                }
                let subtitle = format!(
                    "rows: {}, columns: {}; cells: {what}",
                    pic.rows_axis, pic.cols_axis
                );
                let canvas = compose(&pic.title, &subtitle, &pic.rows, &pic.cols, &tiles);
                let p = grids_dir.join(format!("{}{suffix}.png", pic.stem));
                atomic::write_atomic(&p, &canvas.encode_png(&pic.title)?)?;
                out.push(p);
            }
        }
    }
    Ok(out)
}
