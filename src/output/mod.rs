//! Output — what a run leaves behind and what it tells the user.
//!
//! - [`h5`]: result and summary files, written atomically;
//! - [`render`]: PNG pictures (tile, orders, geometry);
//! - [`lock`]: one writer per result (an OS file lock per output);
//! - [`merl`]: the BRDF in MERL's binary format for renderers (and
//!   [`merl::RgbBrdf`], that BRDF in RGB at any pair of directions, which
//!   `render`'s preview shades a sphere with);
//! - [`progress`]: timestamped progress lines on long work;
//! - [`space`]: the free space of an output's file system;
//! - [`html`]: text escaped for the pages;
//! - [`export`]: a result's numbers as CSV tables ([`csv`]: the table
//!   writer; [`export_paint`]: an effect paint's tables).
//!
//! Imports from every earlier stage (`config` … `optics`), never from
//! `pipeline` or `study`.

pub mod atomic;
pub mod csv;
pub mod error;
pub mod export;
pub mod export_paint;
pub mod h5;
pub mod hiding;
pub mod html;
pub mod lock;
pub mod merl;
pub mod mitsuba;
pub mod progress;
pub mod render;
pub mod space;
mod temp_name;
pub mod tensor_file;
