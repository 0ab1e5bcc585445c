//! View — an interactive page that draws the layer on an object
//! (`inksim view`).
//!
//! A small HTTP server on the loopback interface serves one page (plain
//! WebGL2; every asset is embedded in the binary, nothing is fetched from
//! elsewhere) and the data it draws: per result the BRDF table of
//! [`table`], the measured colours with their spectra and the tile
//! ([`result`]). The page renders a sphere, a curved panel or an uploaded OBJ
//! coated with the layer on its ground under a directional light the user
//! drags and a uniform sky, beside the tile, the spectra and the colours; two
//! results side by side or split on one object (A/B).
//!
//! - [`table`]: the BRDF, sky and specular tables the shader reads;
//! - [`result`]: a result file loaded for the page;
//! - [`source`]: which results a command line names (files, a study's folder);
//! - [`live`]: the recompute hook ([`live::LiveModel`]) and the scenes' radiative-transfer
//!   baselines recomputed as a control moves;
//! - [`live_stack`]: a stack's adding–doubling baseline recomputed live;
//! - [`paint`]: an effect paint's fast model recomputed live, its whole BRDF
//!   on the page's grid;
//! - [`server`]: the HTTP server and its routes; [`page`]: the embedded page.
//!
//! Imports from every earlier stage; nothing imports from it.

pub mod live;
pub mod live_stack;
pub mod page;
pub mod paint;
pub mod result;
pub mod server;
pub mod source;
pub mod table;

use std::path::PathBuf;

use crate::output::h5::IoError;
use crate::output::merl::MerlError;

/// Why the page cannot be served.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error("{}: no such file or folder", .0.display())]
    Missing(PathBuf),
    #[error("{}: not a result with BRDF tables (no /appearance/brdf_table: run the scene with appearance products)", .0.display())]
    NoBrdf(PathBuf),
    #[error("{}: no result files (*.h5) in this folder or its variants/", .0.display())]
    NoResults(PathBuf),
    #[error("{}: cannot be recomputed live: {why}", .path.display())]
    NotLive { path: PathBuf, why: String },
    #[error("recompute: {0}")]
    Live(String),
    #[error(transparent)]
    Io(#[from] IoError),
    #[error("BRDF: {0}")]
    Brdf(#[from] MerlError),
    #[error(
        "refusing to listen on {0}: not a loopback address, so the page would be reachable \
         from other machines; pass --allow-remote to allow it"
    )]
    NotLoopback(std::net::IpAddr),
    #[error("cannot listen on {addr}: {reason}")]
    Bind {
        addr: std::net::SocketAddr,
        reason: String,
    },
}
