//! The fast model's reflection at any air angles: what a renderer or a
//! table on a regular grid needs from a [`PaintReflection`], whose values
//! live on the adding–doubling nodes.
//!
//! - **Between nodes.** The escaping nodes' air angles (the multi-angle
//!   geometries' among them) are the sample points; a value at any polar
//!   angle is linear in the angle between the two nodes around it, and held
//!   at the last node beyond the outermost (the grazing node sits within a
//!   few degrees of 90°). At a node the value is the node's own, exactly.
//! - **In azimuth.** At a pair of nodes the scattered light is the Fejér
//!   sum of the Fourier terms ([`PaintReflection::factor`]), evaluated at
//!   any azimuth; the bilinear weights over the four node pairs around
//!   `(θi, θo)` are applied to the terms before the sum, which is the same.
//! - **The parts.** The scattered reflectance factor `π f`; the scattered
//!   directional–hemispherical reflectance (what a uniform sky returns into
//!   a view direction, by reciprocity); the mirror part's reflectance (the
//!   surface's and a metal ground's, attenuated by the layers).

use super::paint::PaintReflection;

/// The air angles of a reflection's escaping nodes, ascending, with the
/// nodes and the Fejér weights of the terms (module docs).
#[derive(Debug, Clone)]
pub struct AirNodes {
    /// Air polar angles (deg), ascending.
    pub angles_deg: Vec<f64>,
    /// The node of each angle.
    pub nodes: Vec<usize>,
    /// `1` for term 0, `2 (1 − m/M)` for term `m ≥ 1`.
    fejer: Vec<f64>,
}

impl AirNodes {
    pub fn new(r: &PaintReflection) -> AirNodes {
        let mut pairs: Vec<(f64, usize)> = r
            .ords
            .mu_air
            .iter()
            .enumerate()
            .filter_map(|(i, m)| m.map(|m| (m.clamp(-1.0, 1.0).acos().to_degrees(), i)))
            .collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (angles_deg, nodes) = pairs.into_iter().unzip();
        let count = r.fejer_terms.max(r.terms.len()) as f64;
        let fejer = (0..r.terms.len())
            .map(|m| {
                if m == 0 {
                    1.0
                } else {
                    2.0 * (1.0 - m as f64 / count)
                }
            })
            .collect();
        AirNodes {
            angles_deg,
            nodes,
            fejer,
        }
    }

    /// The two nodes around `polar_deg` and their linear weights (the last
    /// node's value held beyond the outermost).
    pub fn around(&self, polar_deg: f64) -> [(usize, f64); 2] {
        let a = &self.angles_deg;
        let last = a.len() - 1;
        if polar_deg <= a[0] {
            return [(self.nodes[0], 1.0), (self.nodes[0], 0.0)];
        }
        if polar_deg >= a[last] {
            return [(self.nodes[last], 1.0), (self.nodes[last], 0.0)];
        }
        let k = a.partition_point(|&x| x <= polar_deg) - 1;
        let t = (polar_deg - a[k]) / (a[k + 1] - a[k]);
        [(self.nodes[k], 1.0 - t), (self.nodes[k + 1], t)]
    }

    /// The weighted Fourier terms of the scattered `π f` from `incidence_deg`
    /// into `view_deg` (one per term, Fejér weights applied): `π f` at
    /// azimuth `φ` is `Σ_m terms[m] cos mφ` ([`AirNodes::sum`]).
    pub fn terms(
        &self,
        r: &PaintReflection,
        incidence_deg: f64,
        view_deg: f64,
        out: &mut Vec<f64>,
    ) {
        out.clear();
        out.resize(r.terms.len(), 0.0);
        for (i, wi) in self.around(view_deg) {
            if wi == 0.0 {
                continue;
            }
            let scale = wi / r.ords.air_flux_weight(i);
            for (j, wj) in self.around(incidence_deg) {
                if wj == 0.0 {
                    continue;
                }
                for ((o, t), f) in out.iter_mut().zip(&r.terms).zip(&self.fejer) {
                    *o += scale * wj * f * t[(i, j)];
                }
            }
        }
    }

    /// `Σ_m terms[m] cos mφ` for the azimuth `azimuth_deg` from the mirror
    /// direction's side (as [`PaintReflection::factor`]).
    pub fn sum(terms: &[f64], azimuth_deg: f64) -> f64 {
        let phi = azimuth_deg.to_radians();
        terms
            .iter()
            .enumerate()
            .map(|(m, t)| t * (m as f64 * phi).cos())
            .sum()
    }

    /// The scattered `π f` at any angles (module docs).
    pub fn factor(
        &self,
        r: &PaintReflection,
        incidence_deg: f64,
        view_deg: f64,
        azimuth_deg: f64,
    ) -> f64 {
        let mut t = Vec::new();
        self.terms(r, incidence_deg, view_deg, &mut t);
        AirNodes::sum(&t, azimuth_deg)
    }

    /// The scattered light's directional–hemispherical reflectance for
    /// light from `polar_deg` (by reciprocity, what a uniform sky of unit
    /// radiance returns into that direction).
    pub fn scattered_albedo(&self, r: &PaintReflection, polar_deg: f64) -> f64 {
        self.around(polar_deg)
            .iter()
            .map(|&(j, w)| w * (r.albedo(j) - r.mirror[j]))
            .sum()
    }

    /// The mirror part's reflectance for light from `polar_deg`.
    pub fn mirror(&self, r: &PaintReflection, polar_deg: f64) -> f64 {
        self.around(polar_deg)
            .iter()
            .map(|&(j, w)| w * r.mirror[j])
            .sum()
    }
}
