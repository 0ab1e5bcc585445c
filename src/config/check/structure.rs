//! `[structure]`: an explicit layer, either primitive bodies (each inside the
//! layer, with a material), slices of material maps (`kind = "layers"`,
//! turned into one body of boxes per material) or an ε grid from an HDF5
//! file.

use super::Checker;
use crate::config::raw::{RawAxis, RawBody, RawMaterial, RawSlice, RawStructure};
use crate::config::{Body, ConfigError, Layer, Primitive, Structure};
use std::path::Path;

impl Checker<'_> {
    pub(super) fn structure(
        &self,
        raw: &RawStructure,
        layer: &Layer,
    ) -> Result<Structure, ConfigError> {
        match raw {
            RawStructure::Hdf5 { file } => {
                if file.trim().is_empty() {
                    return Err(self.invalid("structure.file", "must not be empty"));
                }
                let path = self.file.parent().unwrap_or(Path::new("")).join(file);
                if !path.is_file() {
                    return Err(self.invalid(
                        "structure.file",
                        format!("{} is not a readable file", path.display()),
                    ));
                }
                Ok(Structure::Hdf5(path))
            }
            RawStructure::Primitives { primitive } => {
                if primitive.is_empty() {
                    return Err(self.invalid(
                        "structure.primitive",
                        "at least one [[structure.primitive]] is required",
                    ));
                }
                let h = layer.thickness_nm;
                let mut out = Vec::with_capacity(primitive.len());
                for (i, p) in primitive.iter().enumerate() {
                    let key = format!("structure.primitive[{i}]");
                    let material = self.material(&p.material, &format!("{key}.material"))?;
                    let three = |k: &str, v: &[f64]| -> Result<[f64; 3], ConfigError> {
                        if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
                            return Err(self.invalid(
                                format!("{key}.shape.{k}"),
                                format!("must be 3 finite values [x, y, z] in nm, got {v:?}"),
                            ));
                        }
                        Ok([v[0], v[1], v[2]])
                    };
                    let positive = |k: &str, v: f64| {
                        self.range(
                            &format!("{key}.shape.{k}"),
                            v,
                            v > 0.0 && v.is_finite(),
                            "(0, inf) nm",
                        )
                    };
                    let in_layer = |k: &str, z: f64| {
                        self.range(
                            &format!("{key}.shape.{k}"),
                            z,
                            (0.0..=h).contains(&z),
                            &format!("z in [0, {h}] nm (inside the layer)"),
                        )
                    };
                    let body = match &p.shape {
                        RawBody::Slab { z_nm } => {
                            if z_nm.len() != 2 || z_nm[0] >= z_nm[1] {
                                return Err(self.invalid(
                                    format!("{key}.shape.z_nm"),
                                    format!("must be [z0, z1] with z0 < z1, got {z_nm:?}"),
                                ));
                            }
                            in_layer("z_nm", z_nm[0])?;
                            in_layer("z_nm", z_nm[1])?;
                            Body::Slab {
                                z_nm: [z_nm[0], z_nm[1]],
                            }
                        }
                        RawBody::Box { min_nm, max_nm } => {
                            let (lo, hi) = (three("min_nm", min_nm)?, three("max_nm", max_nm)?);
                            if (0..3).any(|a| lo[a] >= hi[a]) {
                                return Err(self.invalid(
                                    format!("{key}.shape"),
                                    "min_nm must be below max_nm on every axis",
                                ));
                            }
                            in_layer("min_nm", lo[2])?;
                            in_layer("max_nm", hi[2])?;
                            Body::Box {
                                min_nm: lo,
                                max_nm: hi,
                            }
                        }
                        RawBody::Sphere {
                            center_nm,
                            radius_nm,
                        } => {
                            let c = three("center_nm", center_nm)?;
                            let r = positive("radius_nm", *radius_nm)?;
                            in_layer("center_nm", c[2] - r)?;
                            in_layer("center_nm", c[2] + r)?;
                            Body::Sphere {
                                center_nm: c,
                                radius_nm: r,
                            }
                        }
                        RawBody::Cylinder {
                            center_nm,
                            radius_nm,
                            length_nm,
                            axis,
                        } => {
                            let c = three("center_nm", center_nm)?;
                            let r = positive("radius_nm", *radius_nm)?;
                            let l = positive("length_nm", *length_nm)?;
                            let axis = match axis {
                                RawAxis::X => 0,
                                RawAxis::Y => 1,
                                RawAxis::Z => 2,
                            };
                            let half_z = if axis == 2 { l / 2.0 } else { r };
                            in_layer("center_nm", c[2] - half_z)?;
                            in_layer("center_nm", c[2] + half_z)?;
                            Body::Cylinder {
                                center_nm: c,
                                radius_nm: r,
                                length_nm: l,
                                axis,
                            }
                        }
                    };
                    out.push(Primitive { body, material });
                }
                Ok(Structure::Primitives(out))
            }
            RawStructure::Layers {
                materials,
                layer: slices,
            } => self.layers(materials, slices, layer),
        }
    }
}

impl Checker<'_> {
    /// `kind = "layers"`: each slice's map cut into boxes (runs of one code
    /// along a row), one [`Body::Boxes`] per material that occurs.
    fn layers(
        &self,
        materials: &[RawMaterial],
        slices: &[RawSlice],
        layer: &Layer,
    ) -> Result<Structure, ConfigError> {
        if materials.is_empty() || materials.len() > 9 {
            return Err(self.invalid(
                "structure.materials",
                format!(
                    "must list 1 to 9 materials (map codes 1–9), got {}",
                    materials.len()
                ),
            ));
        }
        if slices.is_empty() {
            return Err(self.invalid(
                "structure.layer",
                "at least one [[structure.layer]] is required",
            ));
        }
        let mats = materials
            .iter()
            .enumerate()
            .map(|(i, m)| self.material(m, &format!("structure.materials[{i}]")))
            .collect::<Result<Vec<_>, _>>()?;
        let h = layer.thickness_nm;
        let (lx, ly) = (layer.fragment_x_nm, layer.fragment_y_nm);
        let mut boxes: Vec<Vec<[[f64; 3]; 2]>> = vec![Vec::new(); mats.len()];
        let mut previous_bottom = 0.0;
        for (s, slice) in slices.iter().enumerate() {
            let key = format!("structure.layer[{s}]");
            let z = &slice.z_nm;
            if z.len() != 2
                || z.iter().any(|v| !v.is_finite())
                || z[0] >= z[1]
                || z[0] < 0.0
                || z[1] > h
            {
                return Err(self.invalid(
                    format!("{key}.z_nm"),
                    format!(
                        "must be [z0, z1] with 0 <= z0 < z1 <= {h} (inside the layer), got {z:?}"
                    ),
                ));
            }
            if z[0] < previous_bottom {
                return Err(self.invalid(
                    format!("{key}.z_nm"),
                    format!(
                        "starts at {} nm, above the end of the slice before ({previous_bottom} nm): \
                         slices go from the top down and do not overlap",
                        z[0]
                    ),
                ));
            }
            previous_bottom = z[1];
            let rows: Vec<Vec<char>> = slice
                .map
                .iter()
                .map(|r| r.chars().filter(|c| !c.is_whitespace()).collect())
                .collect();
            let cols = rows.first().map_or(0, Vec::len);
            if rows.is_empty() || cols == 0 {
                return Err(self.invalid(
                    format!("{key}.map"),
                    "must have at least one row and column",
                ));
            }
            for (j, row) in rows.iter().enumerate() {
                if row.len() != cols {
                    return Err(self.invalid(
                        format!("{key}.map[{j}]"),
                        format!(
                            "has {} columns, the first row {cols}: every row covers the fragment",
                            row.len()
                        ),
                    ));
                }
                if let Some(c) = row
                    .iter()
                    .find(|c| c.to_digit(10).is_none_or(|d| d as usize > mats.len()))
                {
                    return Err(self.invalid(
                        format!("{key}.map[{j}]"),
                        format!(
                            "`{c}` is not a material code: 0 (the binder) or 1–{} (structure.materials)",
                            mats.len()
                        ),
                    ));
                }
            }
            let (dx, dy) = (lx / cols as f64, ly / rows.len() as f64);
            for (j, row) in rows.iter().enumerate() {
                let mut i = 0;
                while i < cols {
                    let code = row[i].to_digit(10).unwrap_or(0) as usize;
                    let start = i;
                    while i < cols && row[i] == row[start] {
                        i += 1;
                    }
                    if code > 0 {
                        boxes[code - 1].push([
                            [start as f64 * dx, j as f64 * dy, z[0]],
                            [i as f64 * dx, (j + 1) as f64 * dy, z[1]],
                        ]);
                    }
                }
            }
        }
        let out: Vec<Primitive> = mats
            .into_iter()
            .zip(boxes)
            .filter(|(_, b)| !b.is_empty())
            .map(|(material, boxes)| Primitive {
                body: Body::Boxes { boxes },
                material,
            })
            .collect();
        if out.is_empty() {
            return Err(self.invalid(
                "structure.layer",
                "every map is all binder (0): nothing to rasterise",
            ));
        }
        Ok(Structure::Primitives(out))
    }
}
