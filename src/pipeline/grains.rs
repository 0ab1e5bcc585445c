//! From a scene's pigments to generated grains: which packer a scene needs
//! and why, the scene's species translated into the packers' parameters
//! (one `From` impl per kind of setting), the particle set of a seed, and
//! the raster grid the grains are drawn on.

use std::fmt;

use crate::config::{GrainOrientation, GrainShape, GrainSize, Scene};
use crate::geometry::{
    self, DynParams, DynSpecies, Geometry, Orientation, PackParams, Shape, SizeDistribution,
    SpeciesOptions, SpeciesParams, StackPart,
};
use crate::raster::Grid;

use super::surface::surface_top_nm;
use super::PipelineError;

/// Total PVC up to which random sequential addition of spheres is used: RSA
/// jams near 0.30–0.38 in thin slabs (METHOD §2), so above this the
/// dynamics packer runs.
pub const RSA_MAX_PVC: f64 = 0.30;

/// The packer that builds a scene's grains.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Packer {
    /// Random sequential addition of spheres.
    Rsa,
    /// First-order dynamics packing (any shape, any PVC).
    Dynamics,
}

impl fmt::Display for Packer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Packer::Rsa => "rsa",
            Packer::Dynamics => "dynamics",
        })
    }
}

impl Packer {
    /// Which packer a scene needs, and why.
    pub fn of(scene: &Scene) -> (Packer, String) {
        let spheres = scene.species.iter().all(|s| s.shape == GrainShape::Sphere);
        let pvc = scene.total_pvc();
        if spheres && pvc <= RSA_MAX_PVC {
            (Packer::Rsa, format!("spheres at PVC {pvc:.3} ≤ {RSA_MAX_PVC}: random sequential addition reaches it, no dynamics needed"))
        } else if !spheres {
            (
                Packer::Dynamics,
                "non-spherical grains: first-order dynamics packing".to_string(),
            )
        } else {
            (Packer::Dynamics, format!("PVC {pvc:.3} > {RSA_MAX_PVC}: beyond random sequential addition, first-order dynamics packing"))
        }
    }
}

impl From<GrainSize> for SizeDistribution {
    fn from(size: GrainSize) -> Self {
        match size {
            GrainSize::Fixed => SizeDistribution::Fixed,
            GrainSize::Normal { sigma } => SizeDistribution::Normal { sigma },
            GrainSize::LogNormal { sigma } => SizeDistribution::LogNormal { sigma },
        }
    }
}

/// A molecular pigment has no grains; were one packed, it would be a sphere.
impl From<GrainShape> for Shape {
    fn from(shape: GrainShape) -> Self {
        match shape {
            GrainShape::Sphere | GrainShape::Molecular => Shape::Sphere,
            GrainShape::Cylinder { aspect, spheres } => Shape::Cylinder { aspect, spheres },
            GrainShape::Rice { aspect, spheres } => Shape::Rice { aspect, spheres },
        }
    }
}

impl From<GrainOrientation> for Orientation {
    fn from(orientation: GrainOrientation) -> Self {
        match orientation {
            GrainOrientation::Random => Orientation::Random,
            GrainOrientation::InPlane => Orientation::InPlane,
            GrainOrientation::Perpendicular => Orientation::Perpendicular,
        }
    }
}

/// The fragment `[Lx, Ly, H]` of a scene, nm.
pub fn fragment_nm(scene: &Scene) -> [f64; 3] {
    let l = &scene.layer;
    [l.fragment_x_nm, l.fragment_y_nm, l.thickness_nm]
}

/// The largest diameter any grain of the scene can have, nm (0 without
/// species).
pub fn largest_grain_nm(scene: &Scene) -> f64 {
    scene
        .species
        .iter()
        .map(|s| s.size.max_diameter(s.diameter_nm))
        .fold(0.0, f64::max)
}

/// The seed of stack layer `index` from a realisation's seed `seed`: its
/// own stream, [`realisation_seed`] of the seed marked for stacks, so the
/// layer's fragment is the same under either coupling.
pub fn stack_layer_seed(seed: u64, index: usize) -> u64 {
    realisation_seed(seed ^ 0x5354_4143_4b00_0000, index + 1)
}

/// Seed of realisation `r`: the scene's seed for r = 0 (so a
/// one-realisation run equals the plain scene), else SplitMix64 of
/// `seed + r · 0x9E3779B97F4A7C15` — fixed by (seed, r), never by scheduling.
pub fn realisation_seed(seed: u64, r: usize) -> u64 {
    if r == 0 {
        return seed;
    }
    let mut z = seed.wrapping_add((r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Build the particle set of a scene (realisation 0) with the packer it needs.
pub fn build_geometry(scene: &Scene) -> Result<Geometry, PipelineError> {
    build_geometry_seeded(scene, scene.seed)
}

/// Build the particle set of a scene from a given seed. A stack's is its
/// layers' fragments on top of each other, layer `i` packed from
/// [`stack_layer_seed`]`(seed, i)` (so an incoherent run of the same stack
/// solves the same fragments); a layer of dissolved pigments has no grains.
pub fn build_geometry_seeded(scene: &Scene, seed: u64) -> Result<Geometry, PipelineError> {
    if let Some(st) = &scene.stack {
        let mut layers = Vec::with_capacity(st.layers.len());
        for i in 0..st.layers.len() {
            let ls = scene.stack_layer(i).expect("a layer of the stack");
            let g = if ls.is_molecular() {
                None
            } else {
                Some(build_geometry_seeded(&ls, stack_layer_seed(seed, i))?)
            };
            layers.push((g, ls));
        }
        return Ok(stacked_geometry(layers));
    }
    let l = &scene.layer;
    let size_nm = fragment_nm(scene);
    let options: Vec<SpeciesOptions> = scene
        .species
        .iter()
        .map(|s| SpeciesOptions {
            size: s.size.into(),
            cluster_size: s.cluster_size,
        })
        .collect();
    match Packer::of(scene).0 {
        Packer::Rsa => {
            let params = PackParams {
                size_nm,
                species: scene
                    .species
                    .iter()
                    .map(|s| SpeciesParams {
                        diameter_nm: s.diameter_nm,
                        volume_fraction: s.volume_fraction,
                    })
                    .collect(),
                options,
                relief_fraction: l.relief_fraction,
                equilibrate_sweeps: l.equilibrate_sweeps,
                ..PackParams::default()
            };
            Ok(geometry::pack_rsa(&params, seed)?)
        }
        Packer::Dynamics => {
            let species = scene
                .species
                .iter()
                .map(|s| DynSpecies {
                    shape: s.shape.into(),
                    effective_diameter_nm: s.diameter_nm,
                    volume_fraction: s.volume_fraction,
                    orientation: s.orientation.into(),
                    field: s.alignment_field,
                })
                .collect();
            let params = DynParams {
                options,
                relief_fraction: l.relief_fraction,
                equilibrate_sweeps: l.equilibrate_sweeps,
                ..DynParams::new(size_nm, species)
            };
            Ok(geometry::pack_dynamics(&params, seed)?)
        }
    }
}

/// The fragments of a stack's layers, top first, each with its scene, as
/// one fragment; a layer without grains (`None`: dissolved pigments, or
/// the homogeneous slab it was solved as) keeps its species' fractions.
pub fn stacked_geometry(layers: Vec<(Option<Geometry>, Scene)>) -> Geometry {
    let (own, scenes): (Vec<Geometry>, Vec<Scene>) = layers
        .into_iter()
        .map(|(g, ls)| {
            let g = g.unwrap_or_else(|| {
                geometry::without_grains(
                    fragment_nm(&ls),
                    ls.species.iter().map(|s| s.volume_fraction).collect(),
                )
            });
            (g, ls)
        })
        .unzip();
    let parts: Vec<StackPart> = own
        .iter()
        .zip(&scenes)
        .map(|(geometry, ls)| StackPart {
            geometry,
            species: ls.species.len(),
        })
        .collect();
    geometry::stacked(&parts)
}

/// The raster grid of a scene: the configured cells over the layer, plus,
/// with surface relief, whole cells above it reaching the highest point a
/// grain may have (relief fraction × largest possible diameter, +1 % for
/// the packer's overlap tolerance) and the binder surface above them, the
/// same for every realisation.
pub fn grid_of(scene: &Scene) -> Grid {
    let grid = Grid {
        nx: scene.grid.nx,
        ny: scene.grid.ny,
        nz: scene.grid.nz,
        size_nm: fragment_nm(scene),
    };
    let relief = 1.01 * scene.layer.relief_fraction * largest_grain_nm(scene);
    grid.with_top_nm(relief.max(surface_top_nm(scene, relief)))
}
