//! Optics — stacks of layers (METHOD §5): each layer solved on its own
//! inside the binder, from above and from below at the directions of the
//! adding method, its solves turned into flux matrices ([`flux`]), and the
//! layers combined by adding between the binder's flat surfaces over the
//! paper ([`combine`]), with the same interfaces and paper as the
//! adding–doubling baseline (`optics::baseline::adding`).
//!
//! The layers couple incoherently: between two layers only fluxes pass, so
//! interference between them and the near field of a grain in one layer on
//! a grain in the next are not in it. A stack solved as one fragment
//! (`stacking.coupling = "coherent"`) keeps both; the difference between
//! the two is what the incoherent combination leaves out.

pub mod combine;
pub mod flux;
pub mod halftone;

pub use combine::{free_stack, plane_factors, stack_reflection, white_sky, Below};
pub use flux::{layer_slab, BinQuadrature, LayerSlab, AZIMUTHAL_TERMS};
pub use halftone::{halftone, look, Look, Views};
