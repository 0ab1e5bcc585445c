//! `[structure]`: an explicit layer, either primitive bodies (each inside the
//! layer, with a material) or an ε grid from an HDF5 file.

use super::Checker;
use crate::config::raw::{RawAxis, RawBody, RawStructure};
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
        }
    }
}
