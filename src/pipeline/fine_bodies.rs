//! Bodies of an explicit structure thinner than a grid cell: they are
//! rasterised as a volume fraction of the cells they touch, so their shape
//! (and, in the extreme, their position within the cell) is lost. The run
//! goes on; its plan, which `check` prints and every result stores, says so.

use crate::config::{Body, Scene, Structure};

/// Extent of a body along x, y and z (nm); a slab spans the fragment; for
/// a layered structure's boxes, the narrowest box on each axis.
fn extent(body: &Body, fragment: [f64; 2]) -> [f64; 3] {
    match *body {
        Body::Boxes { ref boxes } => [0, 1, 2].map(|a| {
            boxes
                .iter()
                .map(|b| (b[1][a] - b[0][a]).abs())
                .fold(f64::INFINITY, f64::min)
        }),
        Body::Slab { z_nm } => [fragment[0], fragment[1], (z_nm[1] - z_nm[0]).abs()],
        Body::Box { min_nm, max_nm } => [0, 1, 2].map(|a| (max_nm[a] - min_nm[a]).abs()),
        Body::Sphere { radius_nm, .. } => [2.0 * radius_nm; 3],
        Body::Cylinder {
            radius_nm,
            length_nm,
            axis,
            ..
        } => [0, 1, 2].map(|a| {
            if a == axis {
                length_nm
            } else {
                2.0 * radius_nm
            }
        }),
    }
}

fn kind(body: &Body) -> &'static str {
    match body {
        Body::Slab { .. } => "slab",
        Body::Box { .. } => "box",
        Body::Sphere { .. } => "sphere",
        Body::Cylinder { .. } => "cylinder",
        Body::Boxes { .. } => "layers: the cells of one material",
    }
}

/// One warning line per body of `scene`'s structure that is thinner than
/// one cell along some axis; none for other layers.
pub fn fine_body_lines(scene: &Scene) -> Vec<String> {
    let Some(Structure::Primitives(bodies)) = &scene.structure else {
        return Vec::new();
    };
    let l = &scene.layer;
    let cell = [
        l.fragment_x_nm / scene.grid.nx as f64,
        l.fragment_y_nm / scene.grid.ny as f64,
        l.thickness_nm / scene.grid.nz as f64,
    ];
    let mut lines = Vec::new();
    for (i, p) in bodies.iter().enumerate() {
        let e = extent(&p.body, [l.fragment_x_nm, l.fragment_y_nm]);
        let thin: Vec<String> = (0..3)
            .filter(|&a| e[a] < cell[a])
            .map(|a| {
                format!(
                    "{} ({:.3} nm < cell {:.3} nm)",
                    ["x", "y", "z"][a],
                    e[a],
                    cell[a]
                )
            })
            .collect();
        if !thin.is_empty() {
            lines.push(format!(
                "WARNING: structure body {i} ({}) is thinner than one grid cell along {}: it is \
                 rasterised as a volume fraction of its cells and its shape is lost; use finer \
                 cells (grid.cell_nm, grid.z_cell_nm or grid.n) to resolve it",
                kind(&p.body),
                thin.join(", ")
            ));
        }
    }
    lines
}
