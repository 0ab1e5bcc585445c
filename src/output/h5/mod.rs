//! The HDF5 result file: the writer and the readers (layout: docs/FORMAT.md).
//!
//! It takes plain data ([`ResultSet`]) from the pipeline and knows nothing
//! about how it was computed; it gives back the file's identity and per-solve
//! numbers ([`read_summary`]) and its appearance arrays ([`read_appearance`]).
//! A result is written to `<path>.tmp` in the destination folder, flushed,
//! closed, synced and then renamed onto `<path>`, so a reader (or a resumed
//! run) never sees a half-written result: either the old file or the complete
//! new one. On any error the temporary file is removed.
//!
//! - `result`: the writer ([`ResultSet`] → file), with `geometry` for the
//!   `/geometry` group;
//! - `summary`: the reader of identity and per-solve numbers;
//! - `appearance`: the `/appearance` group's writer, `appearance_read` its
//!   readers;
//! - `brdf_read`: what drawing the layer on an object needs (the RGB
//!   BRDF's data, the measured spectra, the tile);
//! - `paint`: an effect paint's result file, its writer and reader;
//! - `study_labels`: a study summary's variant axis labels, read back;
//! - `attrs`: scalar and string attribute helpers shared by all of them;
//! - `described`: every dataset's `units`, `description` and axis names,
//!   written with it; `scales`: the HDF5 dimension scales behind the axes;
//! - [`create`] and [`open`] (from `config::h5file`, where the scene's
//!   inputs are read too), which every reader and writer uses, so that no
//!   child process inherits an open file and none takes HDF5's own lock.
//!
//! # Layout
//!
//! The layout of a result file (format version 1: groups, datasets, their
//! units and axes, the order-index convention and the `side` field) is
//! documented for users in docs/FORMAT.md. The file describes itself too:
//! every dataset carries `units` and `description` attributes and labelled
//! dimensions (see `described`).

mod appearance;
mod appearance_read;
mod attrs;
mod brdf_read;
mod described;
mod geometry;
mod paint;
mod result;
mod scales;
mod stack;
mod study_labels;
mod summary;

pub use crate::config::h5file::{create, open};
pub use crate::output::error::IoError;
pub use appearance::hiding::{read_hiding, HidingRecord};
pub use appearance_read::{
    read_appearance, read_baseline, read_measured, read_measured_black, read_optional,
    AppearanceArrays, BaselineRecord, MeasuredRecord,
};
pub(crate) use attrs::{vlu, write_scalar_attr, write_str_attr};
pub use brdf_read::{read_brdf_data, read_measured_spectra, read_tile_png, MeasuredSpectrum};
pub(crate) use described::{about, dim, Scales};
pub use geometry::GeometrySummary;
pub use paint::{
    is_paint_result, read_paint, read_paint_config, write_paint, AngleRecord, PaintRecord,
    PaintResultSet, SparkleRecord, SparkleTable, PAINT_KIND,
};
pub use result::{write_result, Identity, RealisationStop, ResultSet};
pub use stack::{read_stack_totals, LayerMatrices, StackTables};
pub use study_labels::{read_study_labels, VariantLabels};
pub use summary::{read_summary, AppearanceSummary, EntrySummary, ResultSummary};

/// Version of the layout described in docs/FORMAT.md, stored as `format_version`.
pub const FORMAT_VERSION: u32 = 1;
