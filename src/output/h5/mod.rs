//! The HDF5 result file: its layout (below, the format spec), the writer
//! and the readers.
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
//! - `attrs`: scalar and string attribute helpers shared by all of them;
//! - `described`: every dataset's `units`, `description` and axis names,
//!   written with it; `scales`: the HDF5 dimension scales behind the axes.
//!
//! # Layout of a result file (format version 1)
//!
//! Root attributes:
//! - `format_version` (u32, = 1), `inksim_version`, `config_path`,
//!   `input_hash` (UTF-8 strings), `seed` (u64), `created_unix_s` (u64),
//!   `grid` (3 × u64: nx, ny, nz), `size_nm` (3 × f64: Lx, Ly, H).
//!
//! `/config` — scalar variable-length UTF-8 string: the exact TOML text
//! (byte-exact round trip; a text containing NUL is refused).
//!
//! `/plan` — scalar UTF-8 string: the run's plan, one line per decision
//! (which packer and why, which solves, which solver each used and why).
//!
//! `/geometry` (group):
//! - datasets `centers_nm` (N × 3 f64), `radii_nm` (N f64),
//!   `particle_of_sphere` (N u32), `species_of_particle` (P u32),
//!   `species_names` (S variable-length UTF-8 strings),
//!   `target_fraction`, `achieved_fraction`, `raster_fraction` (S f64 each);
//! - attribute `min_gap_nm` (f64; absent for a molecular mixture, which has
//!   no grains);
//! - group `statistics` (absent without grains): attributes `pvc_total`,
//!   `min_gap_nm`, `worst_overlap_nm`, `mean_diameter_nm`, `protrusion_nm`,
//!   `bottom_excess_nm`, `rdf_slab_nm`, `contact_gap_nm`, `order_parameter`
//!   (when the grains have axes); datasets `count` (S u64), `volume_nm3`,
//!   `pvc` (S f64), `profile_z_nm` (B+1) and `profile_fraction` (B: grain
//!   volume fraction per z bin), `rdf_r_nm`, `rdf` (pair correlation of the
//!   centres), `cluster_sizes` (u64, largest first); see `geometry::stats`.
//!
//! `/realisations` (group): `seed` (R u64), `achieved_pvc` (R f64), the
//! geometry of each random fragment (`/geometry` holds realisation 0's);
//! with a target uncertainty the attributes `target_de00_se`,
//! `achieved_de00_se` and `stopped_because`.
//!
//! `/solves/NNNN` (one group per solve, `NNNN` = zero-padded index 0000, 0001, …
//! in the order given), attributes:
//! `wavelength_nm`, `polar_deg`, `azimuth_deg`, `total_reflectance`,
//! `total_transmittance`, `absorption`, `energy_balance` (f64), `r00`, `t00`
//! (2 × f64: re, im), `method` (string: `born` | `time-marching` | `gmres` | `bicgstab` | `airy`),
//! `side` (string: `above` | `below`, the face lit; below = layer flipped),
//! `realisation` (u64),
//! `iterations`, `operator_applications` (u64), `residual`, `seconds` (f64),
//! `note` (string); datasets over the K propagating orders: `orders_mn`
//! (K × 2 i32: m, n; its `description` attribute states the convention:
//! κ = κ_inc + 2π (m/Lx, n/Ly), leaving at sin θ (cos φ, sin φ) = κ/k0),
//! `orders_theta_deg`, `orders_phi_deg`,
//! `orders_reflectance`, `orders_transmittance` (K f64).
//!
//! `/summary` — one compound row per solve, in solve order, with fields
//! `wavelength_nm`, `polar_deg`, `azimuth_deg`, `reflectance`, `transmittance`,
//! `absorption`, `energy_balance`, `residual` (f64), `iterations` (u64),
//! `side` (u8: 0 lit from above, the ink side; 1 from below, the layer
//! flipped for the paper term) and `realisation` (u64); units and meaning of
//! each field as attributes `<field>_units`, `<field>_description`. In
//! Python: `s = h5py.File(p)["summary"][()]; s[s["side"] == 0]["reflectance"]`.
//!
//! `/picture_png` — the rendered PNG as a 1-D u8 dataset (present when given).
//!
//! `/appearance` (group, present when the scene asked for appearance
//! products), ensemble means over the realisations with standard errors
//! (`*_se`, same shape, present when R ≥ 2). Axes: L wavelengths, A polar
//! angles solved from above, I illumination and V viewing angles, Q
//! quadrature nodes from below, N×N table nodes.
//! - `wavelengths_nm` (L), `above_deg` (A), `illumination_deg` (I),
//!   `viewing_deg` (V), `below_deg` (Q, may be empty); attributes
//!   `azimuth_deg`, `table_cell` (node spacing in sin θ), `realisations` (u64);
//! - `reflectance`, `transmittance`, `absorption` (L × A);
//!   `specular_coherent`, `specular_incoherent`, `direct_coherent`,
//!   `direct_incoherent` (L × A: |⟨r00⟩|², ⟨|r00|²⟩ − |⟨r00⟩|², same for t00);
//! - `brdf_table` (L × I × N × N: density per projected solid angle on nodes
//!   s = (i − N/2, j − N/2)·cell, row j along sin θ sin φ; the BRDF is the
//!   density over `table_coverage`, N × N), `brdf_diffuse`
//!   (L × I × V, 1/sr, plane of incidence, specular side); `btdf_table`,
//!   `btdf_diffuse` likewise when requested;
//! - with paper: attribute `paper_albedo`, `r_dd_up`, `t_d` (L);
//! - with the tile: `brdf_total` (L × I × V, layer + substrate, 1/sr),
//!   `natural` (L × V, radiance factor under a uniform white sky),
//!   `tile_srgb8` (V × (1 + I) × 3 u8), `tile_lab` (V × (1 + I) × 3 f64), `natural_srgb8` (V × 3 u8),
//!   `natural_lab` (V × 3 f64), `tile_png` (u8).

mod appearance;
mod appearance_read;
mod attrs;
mod described;
mod geometry;
mod result;
mod scales;
mod summary;

pub use crate::output::error::IoError;
pub use appearance_read::{read_appearance, read_measured, AppearanceArrays, MeasuredRecord};
pub(crate) use described::{about, dim, Scales};
pub use result::{write_result, GeometrySummary, RealisationStop, ResultSet};
pub use summary::{read_summary, AppearanceSummary, EntrySummary, ResultSummary};

/// Version of the layout described in the module docs, stored as `format_version`.
pub const FORMAT_VERSION: u32 = 1;
