//! Merging a finished study: one summary HDF5 file, the labelled comparison
//! grids and a summary page.
//!
//! Takes a [`Study`] and its [`Expansion`] for one profile, every variant's
//! result file finished; gives the files below and a [`MergeReport`] naming
//! them.
//!
//! Written into the study folder, each atomically:
//! - `summary.h5`: one HDF5 external link per variant (`/variants/<name>`)
//!   and the table of the variants (names, seeds, means, colours, axis
//!   labels and values), every dataset with `units`, `description` and
//!   labelled axes; layout for users in docs/FORMAT.md.
//! - `grids/<grid>[__<axis>-<label>…].png`: for each declared grid (or the
//!   default: first axis as rows, second as columns), one picture per
//!   combination of the labels of the remaining axes not fixed by `where`;
//!   each cell is the variant's 45°/0° colour card (its tile, shrunk to at
//!   most [`CELL_PX`] pixels, where the result has no measured colour), with
//!   row and column labels; an empty cell is grey with a dash.
//! - `grids/<grid>[__<axis>-<label>…]-de00.png`: beside each grid picture
//!   with measured colours, a heat map of the CIEDE2000 difference of every
//!   cell to the grid's reference cell (the first row and column), ± its
//!   standard error, cells within two standard errors of 0 hatched
//!   ([`de00`]).
//! - `plots/<axis>[__<axis>-<label>…].png`: L* and C*ab against each axis
//!   ([`plots`]).
//! - `summary.md` and `summary.html`: facts of the run, the effects table
//!   ([`effects`]), the plots and grids, the variants with links to their
//!   files ([`page`]).
//!
//! Merge refuses to run until every variant is finished, and lists what is
//! missing and why.
//!
//! - `grid`: the comparison-grid pictures; `de00` their ΔE00 heat maps.
//! - `plots`: the study plots.
//! - `effects`: the effects table's numbers.
//! - `summary_h5`: the summary HDF5 file; `summary_values` its typed axis
//!   values and measured colours.
//! - `page`, `markdown`: the HTML and Markdown pages.

mod de00;
mod effects;
mod grid;
mod markdown;
mod page;
mod plots;
mod summary_h5;
mod summary_values;

pub use de00::{de00_maps, draw as draw_de00_map, De00Cell, De00Map};
pub(crate) use grid::{compose, pictures};
pub use grid::{shrink, CELL_PX};
pub(crate) use summary_h5::{vlu, write_variants};

use super::run::{self, RunScene, State};
use super::sweep::{Expansion, Study, Variant};
use super::StudyError;
use crate::output::atomic;
use crate::output::h5::{self, ResultSummary};
use std::path::PathBuf;

/// What merge wrote.
#[derive(Debug, Clone)]
pub struct MergeReport {
    pub summary_h5: PathBuf,
    pub summary_md: PathBuf,
    pub summary_html: PathBuf,
    pub grids: Vec<PathBuf>,
    /// The ΔE00 heat map of each grid picture (`grids/…-de00.png`), in the
    /// order of `grids`, where the picture has measured colours.
    pub de00_maps: Vec<PathBuf>,
    /// L* and C*ab against each axis (`plots/`).
    pub plots: Vec<PathBuf>,
}

/// One row of the summary table.
struct Row<'a> {
    v: &'a Variant,
    s: ResultSummary,
    r: f64,
    t: f64,
    a: f64,
    /// The variant's colour in [`COLOUR_GEOMETRY`] (else its first
    /// measurement geometry), when the result has measured colours.
    measured: Option<Measured>,
    /// The classical baselines' colours in the geometry of `measured`.
    baseline: Vec<h5::BaselineRecord>,
    /// Over a hiding chart: the contrast ratio and Kubelka's S and K in
    /// [`HIDING_GEOMETRY`] (else the first geometry measured).
    hiding: Option<h5::HidingRecord>,
}

/// The measurement geometry of the contrast ratio in the study's tables
/// (ISO 6504-3's).
const HIDING_GEOMETRY: &str = "d/8 SCI";

/// A result's hiding power in [`HIDING_GEOMETRY`], else its first.
fn hiding(path: &std::path::Path) -> Result<Option<h5::HidingRecord>, StudyError> {
    let all = h5::read_hiding(path)?;
    let k = all
        .iter()
        .position(|h| h.geometry == HIDING_GEOMETRY)
        .or((!all.is_empty()).then_some(0));
    Ok(k.map(|k| all[k].clone()))
}

/// The measurement geometry the plots, the effects table and the grid cards
/// show.
const COLOUR_GEOMETRY: &str = "45/0";

/// A variant's measured colour and the conditions it was computed for.
struct Measured {
    record: h5::MeasuredRecord,
    /// "D50, 2°".
    conditions: String,
}

/// The measured colour of a result file (see [`Row::measured`]).
fn measured(path: &std::path::Path) -> Result<Option<Measured>, StudyError> {
    let Some((records, illuminant, observer_deg)) = h5::read_measured(path)? else {
        return Ok(None);
    };
    let pick = records
        .iter()
        .position(|m| m.geometry == COLOUR_GEOMETRY)
        .or((!records.is_empty()).then_some(0));
    Ok(pick.map(|k| Measured {
        record: records[k].clone(),
        conditions: format!("{illuminant}, {observer_deg}°"),
    }))
}

/// Every variant of `exp` finished, else an error naming what is missing
/// and why (at most 20) and the command that finishes them.
pub(crate) fn all_finished<S: RunScene>(
    study: &Study,
    exp: &Expansion<S>,
) -> Result<(), StudyError> {
    let mut missing = vec![];
    for v in &exp.variants {
        let s = run::state(v);
        if s != State::Done {
            missing.push(format!("{} ({})", v.name, s.reason()));
        }
    }
    if missing.is_empty() {
        return Ok(());
    }
    let n = missing.len();
    missing.truncate(20);
    Err(StudyError::Incomplete(format!(
        "{}: {n} of {} variants are not finished, so there is nothing to merge yet: {}{}; \
         run `inksim run {}{}` first",
        study.path.display(),
        exp.variants.len(),
        missing.join(", "),
        if n > 20 { ", …" } else { "" },
        study.path.display(),
        exp.profile
            .as_deref()
            .map(|p| format!(" --profile {p}"))
            .unwrap_or_default()
    )))
}

/// Merge a finished study (see the module docs).
pub fn merge(study: &Study, exp: &Expansion) -> Result<MergeReport, StudyError> {
    all_finished(study, exp)?;
    let mut rows = Vec::with_capacity(exp.variants.len());
    for v in &exp.variants {
        let path = run::paths(v).0;
        let s = h5::read_summary(&path)?;
        // Light from above only (solves from below feed the paper term).
        let above: Vec<&h5::EntrySummary> = s
            .entries
            .iter()
            .filter(|e| e.side == crate::optics::farfield::Side::Above)
            .collect();
        let n = above.len().max(1) as f64;
        let mean = |f: fn(&h5::EntrySummary) -> f64| above.iter().map(|e| f(e)).sum::<f64>() / n;
        // A stack solved layer by layer: the whole stack's, not its layers'.
        let (r, t, a) = match h5::read_stack_totals(&path)? {
            Some([r, t, a]) => (r, t, a),
            None => (
                mean(|e| e.total_reflectance),
                mean(|e| e.total_transmittance),
                mean(|e| e.absorption),
            ),
        };
        let measured = measured(&path)?;
        let baseline = match &measured {
            Some(m) => h5::read_baseline(&path)?
                .into_iter()
                .filter(|b| b.geometry == m.record.geometry)
                .collect(),
            None => Vec::new(),
        };
        rows.push(Row {
            v,
            s,
            r,
            t,
            a,
            measured,
            baseline,
            hiding: hiding(&path)?,
        });
    }
    let dir = &exp.study_dir;
    let grids_dir = dir.join("grids");
    let mut grids = vec![];
    for g in &study.grids {
        for (file, title, canvas) in grid::draw_grid(study, exp, g)? {
            let p = grids_dir.join(file);
            atomic::write_atomic(&p, &canvas.encode_png(&title)?)?;
            grids.push(p);
        }
    }
    // Each grid picture's heat map, by the grid picture it belongs to.
    let mut grid_maps: Vec<Option<PathBuf>> = vec![None; grids.len()];
    let mut de00_maps = vec![];
    for m in de00::de00_maps(study, exp)? {
        let p = grids_dir.join(&m.file);
        atomic::write_atomic(&p, &de00::draw(&m).encode_png(&m.title)?)?;
        if let Some(k) = grids
            .iter()
            .position(|g| *g == grids_dir.join(&m.grid_file))
        {
            grid_maps[k] = Some(p.clone());
        }
        de00_maps.push(p);
    }
    let plots_dir = dir.join("plots");
    let mut plots = vec![];
    let profile = exp.profile.as_deref().unwrap_or("");
    for (file, title, canvas) in plots::draw_plots(study, profile, &rows)? {
        let p = plots_dir.join(file);
        atomic::write_atomic(&p, &canvas.encode_png(&title)?)?;
        plots.push(p);
    }
    let summary_h5 = dir.join("summary.h5");
    summary_h5::write_summary_h5(study, exp, &rows, &summary_h5)?;
    let effects = effects::effects(study, &rows);
    let unix_s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let input = page::PageInput {
        study,
        exp,
        rows: &rows,
        effects: &effects,
        grids: &grids,
        grid_maps: &grid_maps,
        plots: &plots,
        unix_s,
    };
    let (md, html) = (markdown::page(&input), page::html_page(&input));
    let summary_md = dir.join("summary.md");
    let summary_html = dir.join("summary.html");
    atomic::write_atomic(&summary_md, md.as_bytes())?;
    atomic::write_atomic(&summary_html, html.as_bytes())?;
    Ok(MergeReport {
        summary_h5,
        summary_md,
        summary_html,
        grids,
        de00_maps,
        plots,
    })
}
