//! A stack of layers (`[[stack]]`): each layer as a scene gives one, with
//! its own pigments, from the top down, on one binder; and how they are
//! combined (`[stacking]`).

use super::{GridSpec, Layer, Scene, Species};

/// Most layers a stack may hold.
pub const MAX_STACK_LAYERS: usize = 8;
/// Default directions of the adding method: Gauss nodes on the trapped
/// panel, and nodes per unit of the air cosine on the escaping panels.
pub const DEFAULT_TRAPPED_DIRECTIONS: usize = 4;
pub const DEFAULT_ESCAPE_DIRECTIONS: usize = 6;
/// Largest `stacking.trapped_directions` and `stacking.escape_directions`.
pub const MAX_STACK_DIRECTIONS: usize = 32;
/// Largest `stacking.yule_nielsen_n`.
pub const MAX_YULE_NIELSEN_N: f64 = 10.0;

/// One layer of a stack: its slab, its pigments and its grid.
#[derive(Debug, Clone)]
pub struct StackLayer {
    pub layer: Layer,
    pub species: Vec<Species>,
    /// The grid of this layer alone (its own `nz`).
    pub grid: GridSpec,
    /// Share of the area the layer is printed on, (0, 1]: below 1 the layer
    /// is a halftone, its dots much wider than a fragment (docs/STACKS.md).
    pub coverage: f64,
}

/// How light couples between the layers of a stack.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StackCoupling {
    /// Each layer solved on its own, inside its binder, from above and from
    /// below at the directions of the adding method; the layers combined by
    /// the adding method, incoherently (one layer's fragment uncorrelated
    /// with the next's), under the binder's flat top surface.
    Incoherent,
    /// All layers in one fragment, solved together: every wave effect
    /// between them kept.
    Coherent,
}

impl StackCoupling {
    /// The name in a scene file.
    pub fn name(self) -> &'static str {
        match self {
            StackCoupling::Incoherent => "incoherent",
            StackCoupling::Coherent => "coherent",
        }
    }
}

/// The layers of a stack, from the top down, and how they are combined.
#[derive(Debug, Clone)]
pub struct Stack {
    pub layers: Vec<StackLayer>,
    pub coupling: StackCoupling,
    /// Directions of the adding method (incoherent coupling).
    pub trapped_directions: usize,
    pub escape_directions: usize,
    /// Yule–Nielsen's n for the halftone's area mixture (1: Murray–Davies).
    pub yule_nielsen_n: f64,
}

impl Scene {
    /// Whether the scene is a stack solved layer by layer (incoherent
    /// coupling), which runs, plans and writes its own way.
    pub fn is_incoherent_stack(&self) -> bool {
        self.stack
            .as_ref()
            .is_some_and(|s| s.coupling == StackCoupling::Incoherent)
    }

    /// Stack layer `index` as a scene of its own: its slab, pigments and
    /// grid, with everything else (light, solver, appearance, output, seed)
    /// the stack's; the pipeline seeds each layer's fragments. None for a
    /// scene without a stack.
    pub fn stack_layer(&self, index: usize) -> Option<Scene> {
        let st = self.stack.as_ref()?;
        let l = st.layers.get(index)?;
        let mut scene = self.clone();
        scene.stack = None;
        scene.layer = l.layer.clone();
        scene.species = l.species.clone();
        scene.grid = l.grid;
        Some(scene)
    }
}
