//! `[[pigment]]`: each species' share of the PVC, name, material, shape,
//! diameter, orientation and alignment, size distribution and
//! agglomeration, and the total PVC.

use super::{Checker, REL_EPS};
use crate::config::raw::{RawOrientation, RawPigment, RawShape, RawSize};
use crate::config::{
    ConfigError, GrainOrientation, GrainShape, GrainSize, Layer, Species, MAX_CLUSTER_SIZE,
    MAX_GRAINS, MAX_LOG_NORMAL_SIGMA, MAX_NORMAL_SIGMA, MAX_PVC,
};
use std::collections::HashMap;

impl Checker<'_> {
    pub(super) fn pigments(
        &self,
        raw: &[RawPigment],
        layer: &Layer,
        total_pvc: Option<f64>,
    ) -> Result<Vec<Species>, ConfigError> {
        if raw.is_empty() {
            return Err(self.invalid("pigment", "at least one [[pigment]] table is required"));
        }
        if let Some(t) = total_pvc {
            self.range(
                "layer.pvc",
                t,
                t > 0.0 && t <= MAX_PVC,
                &format!("(0, {MAX_PVC}] (the most the packer reaches)"),
            )?;
        }
        let mut shares = Vec::with_capacity(raw.len());
        for (i, p) in raw.iter().enumerate() {
            let key = |field: &str| format!("pigment[{i}].{field}");
            match (total_pvc, p.pvc, p.share) {
                (Some(_), Some(_), _) => {
                    return Err(self.invalid(
                        key("pvc"),
                        "layer.pvc is given: set this pigment's `share` of it instead",
                    ))
                }
                (None, _, Some(_)) => {
                    return Err(self.invalid(
                        key("share"),
                        "a share needs the total layer.pvc; or give this pigment's pvc",
                    ))
                }
                (None, None, None) => {
                    return Err(self.invalid(
                        key("pvc"),
                        "missing; give each pigment's pvc, or layer.pvc with shares",
                    ))
                }
                (None, Some(v), None) => shares.push(v),
                (Some(_), None, sh) => {
                    let sh = sh.unwrap_or(1.0);
                    shares.push(self.range(
                        &key("share"),
                        sh,
                        sh >= 0.0 && sh.is_finite(),
                        "[0, inf) (0: absent)",
                    )?);
                }
            }
        }
        let sum: f64 = shares.iter().sum();
        // A negative or non-finite value is named by its own key below.
        if sum == 0.0 {
            return Err(self.invalid(
                "pigment[*].pvc",
                "every pigment is at 0: at least one needs a volume fraction above 0",
            ));
        }
        let fractions: Vec<f64> = match total_pvc {
            None => shares,
            Some(t) => shares.iter().map(|s| t * s / sum).collect(),
        };
        let molecular: Vec<bool> = raw
            .iter()
            .map(|p| matches!(p.shape, Some(RawShape::Molecular)))
            .collect();
        if molecular.iter().any(|&m| m) && !molecular.iter().all(|&m| m) {
            let i = molecular.iter().position(|&m| !m).unwrap_or(0);
            return Err(self.invalid(
                format!("pigment[{i}].shape"),
                "another pigment is molecular; dissolved and particulate pigments cannot be mixed",
            ));
        }
        let mut seen: HashMap<&str, usize> = HashMap::new();
        let mut species = Vec::with_capacity(raw.len());
        let max_d = layer
            .thickness_nm
            .min(layer.fragment_x_nm)
            .min(layer.fragment_y_nm);
        for (i, p) in raw.iter().enumerate() {
            let key = |field: &str| format!("pigment[{i}].{field}");
            let name = p.name.trim();
            if name.is_empty() {
                return Err(self.invalid(key("name"), "must not be empty"));
            }
            if let Some(j) = seen.insert(name, i) {
                return Err(self.invalid(
                    key("name"),
                    format!("duplicate pigment name `{name}` (also pigment[{j}].name)"),
                ));
            }
            let material = self.material(&p.material, &key("material"))?;
            let vf = fractions[i];
            let vf_key = if total_pvc.is_some() {
                "layer.pvc".to_string()
            } else {
                key("pvc")
            };
            let shape = self.shape(p.shape.as_ref(), &key("shape"))?;
            // Grains are packed (at most MAX_PVC); a dissolved dye is not.
            let volume_fraction = if shape == GrainShape::Molecular {
                self.range(
                    &vf_key,
                    vf,
                    (0.0..1.0).contains(&vf),
                    "[0, 1) (a dissolved dye; 0: absent)",
                )?
            } else {
                self.range(
                    &vf_key,
                    vf,
                    (0.0..=MAX_PVC).contains(&vf),
                    &format!(
                        "[0, {MAX_PVC}] (the most the packer reaches; 0: absent, as the first \
                         step of a let-down series)"
                    ),
                )?
            };
            // A molecular pigment's diameter is not used (documented).
            let diameter_nm = match (shape, p.diameter_nm) {
                (GrainShape::Molecular, _) => 0.0,
                (_, None) => return Err(self.invalid(key("diameter_nm"), "missing")),
                (_, Some(d)) => self.range(
                    &key("diameter_nm"),
                    d,
                    d > 0.0 && d <= max_d,
                    &format!("(0, {max_d}] nm (at most the layer thickness and the fragment size)"),
                )?,
            };
            if diameter_nm > 0.0 {
                let volume = layer.thickness_nm * layer.fragment_x_nm * layer.fragment_y_nm;
                let grains =
                    volume_fraction * volume / (std::f64::consts::PI / 6.0 * diameter_nm.powi(3));
                if grains > MAX_GRAINS as f64 {
                    return Err(self.invalid(
                        key("diameter_nm"),
                        format!(
                            "{} nm grains at PVC {volume_fraction} make about {} grains in this \
                             layer, more than the {MAX_GRAINS} a layer may hold; use larger \
                             grains or a smaller fragment, or shape = {{ kind = \"molecular\" }} \
                             for a dye dissolved in the binder",
                            super::num(diameter_nm),
                            if grains < 1e7 {
                                format!("{grains:.0}")
                            } else {
                                format!("{grains:.1e}")
                            }
                        ),
                    ));
                }
            }
            let orientation = match p.orientation {
                None | Some(RawOrientation::Random) => GrainOrientation::Random,
                Some(RawOrientation::InPlane) => GrainOrientation::InPlane,
                Some(RawOrientation::Perpendicular) => GrainOrientation::Perpendicular,
            };
            let f = p.alignment_field.unwrap_or(0.0);
            let alignment_field = self.range(
                &key("alignment_field"),
                f,
                (0.0..=100.0).contains(&f),
                "[0, 100]",
            )?;
            if alignment_field > 0.0 && orientation == GrainOrientation::Random {
                return Err(self.invalid(
                    key("alignment_field"),
                    "needs orientation \"in-plane\" or \"perpendicular\" (the direction it aligns towards)",
                ));
            }
            if alignment_field > 0.0 && matches!(shape, GrainShape::Sphere | GrainShape::Molecular)
            {
                return Err(self.invalid(
                    key("alignment_field"),
                    "spheres and dissolved pigments have no axis to align",
                ));
            }
            let size = self.grain_size(p.size.as_ref(), &key("size"))?;
            if shape != GrainShape::Molecular {
                let largest = size.max_diameter(diameter_nm);
                if largest > max_d * (1.0 + REL_EPS) {
                    return Err(self.invalid(
                        key("size"),
                        format!(
                            "the largest grain (3 sigma) is {largest} nm; it must be at most \
                             {max_d} nm (the layer thickness and the fragment size)"
                        ),
                    ));
                }
            }
            let cluster_size = match &p.agglomeration {
                None => 1,
                Some(a) => {
                    let c = a.cluster_size;
                    if !(1..=MAX_CLUSTER_SIZE as i64).contains(&c) {
                        return Err(self.invalid(
                            key("agglomeration.cluster_size"),
                            format!(
                                "must be in [1, {MAX_CLUSTER_SIZE}] (grains per cluster), got {c}"
                            ),
                        ));
                    }
                    c as usize
                }
            };
            if shape == GrainShape::Molecular && (p.size.is_some() || cluster_size > 1) {
                return Err(self.invalid(
                    key(if p.size.is_some() {
                        "size"
                    } else {
                        "agglomeration"
                    }),
                    "a dissolved (molecular) pigment has no grains to size or cluster",
                ));
            }
            species.push(Species {
                name: name.to_string(),
                material,
                volume_fraction,
                diameter_nm,
                shape,
                orientation,
                alignment_field,
                size,
                cluster_size,
            });
        }
        let total: f64 = species.iter().map(|s| s.volume_fraction).sum();
        if total > MAX_PVC * (1.0 + REL_EPS) {
            return Err(self.invalid(
                "pigment[*].pvc",
                format!("total pvc {total} exceeds {MAX_PVC}, the most the packer reaches"),
            ));
        }
        Ok(species)
    }

    pub(super) fn shape(
        &self,
        raw: Option<&RawShape>,
        key: &str,
    ) -> Result<GrainShape, ConfigError> {
        let parts = |aspect: Option<f64>, spheres: Option<i64>, def_a: f64, def_n: i64| {
            let a = aspect.unwrap_or(def_a);
            let a = self.range(
                &format!("{key}.aspect"),
                a,
                (1.0..=20.0).contains(&a),
                "[1, 20]",
            )?;
            let n = spheres.unwrap_or(def_n);
            if !(2..=64).contains(&n) {
                return Err(self.invalid(
                    format!("{key}.spheres"),
                    format!("must be in [2, 64], got {n}"),
                ));
            }
            Ok((a, n as usize))
        };
        Ok(match raw {
            None | Some(RawShape::Sphere) => GrainShape::Sphere,
            Some(RawShape::Molecular) => GrainShape::Molecular,
            Some(RawShape::Cylinder { aspect, spheres }) => {
                let (aspect, spheres) = parts(*aspect, *spheres, 3.0, 5)?;
                if (spheres as f64) <= aspect - 1.0 {
                    return Err(self.invalid(
                        format!("{key}.spheres"),
                        format!("a cylinder of aspect {aspect} needs more than {} spheres so neighbours overlap", aspect - 1.0),
                    ));
                }
                GrainShape::Cylinder { aspect, spheres }
            }
            Some(RawShape::Rice { aspect, spheres }) => {
                let (aspect, spheres) = parts(*aspect, *spheres, 3.0, 7)?;
                GrainShape::Rice { aspect, spheres }
            }
        })
    }

    /// `size`: fixed, or normal / log-normal with `sigma` in range.
    pub(super) fn grain_size(
        &self,
        raw: Option<&RawSize>,
        key: &str,
    ) -> Result<GrainSize, ConfigError> {
        let sigma_key = format!("{key}.sigma");
        Ok(match raw {
            None | Some(RawSize::Fixed) => GrainSize::Fixed,
            Some(RawSize::Normal { sigma }) => GrainSize::Normal {
                sigma: self.range(
                    &sigma_key,
                    *sigma,
                    (0.0..=MAX_NORMAL_SIGMA).contains(sigma),
                    &format!("[0, {MAX_NORMAL_SIGMA}] (relative to diameter_nm)"),
                )?,
            },
            Some(RawSize::LogNormal { sigma }) => GrainSize::LogNormal {
                sigma: self.range(
                    &sigma_key,
                    *sigma,
                    (0.0..=MAX_LOG_NORMAL_SIGMA).contains(sigma),
                    &format!("[0, {MAX_LOG_NORMAL_SIGMA}] (standard deviation of ln d)"),
                )?,
            },
        })
    }
}
