//! What a stack shows, and a halftone of stacks: each Neugebauer primary
//! (the layers printed at a point, top first, or the bare substrate) added
//! as a whole stack ([`look`]), and the primaries mixed by area
//! ([`halftone`]): Demichel's areas, Yule–Nielsen's mixture of everything
//! seen on the paper (`optics::baseline::halftone`), and the plain area
//! mixture of the stack's totals in air.

use ndarray::Array2;

use super::combine::{free_stack, plane_factors, stack_reflection, white_sky, Below};
use super::flux::LayerSlab;
use crate::optics::appearance::Measurement;
use crate::optics::baseline::fresnel::Fresnel;
use crate::optics::baseline::halftone::{primaries, yule_nielsen};
use crate::optics::baseline::ordinates::Ordinates;
use crate::optics::baseline::BaselineError;

/// The directions a stack is looked at from.
#[derive(Debug, Clone, Copy)]
pub struct Views<'a> {
    /// The colorimetric geometries.
    pub measurements: &'a [Measurement],
    /// Viewing angles of the white sky (and of the BRDF square).
    pub viewing_deg: &'a [f64],
    /// Illumination angles of the BRDF square; None: no square.
    pub illumination_deg: Option<&'a [f64]>,
    /// Air angles of the totals in air.
    pub above_deg: &'a [f64],
    /// How the binder's flat surfaces reflect: by the law of the equation
    /// the layers were solved in (`Fresnel::of`).
    pub surfaces: Fresnel,
}

/// What a stack (or a halftone of stacks) shows at one wavelength.
#[derive(Debug, Clone, PartialEq)]
pub struct Look {
    /// Reflectance factor in each measurement geometry, on `below`.
    pub factors: Vec<f64>,
    /// White-sky radiance factor per viewing angle, on `below`.
    pub natural: Vec<f64>,
    /// `π f` of the diffuse BRDF in the plane of incidence, (illumination,
    /// viewing), on `below`.
    pub plane: Option<Array2<f64>>,
    /// R, T, A of the stack in air without the substrate, per above angle.
    pub totals: Vec<[f64; 3]>,
}

/// What the stack of `layers` (top first) between the binder's flat
/// surfaces on `below` shows; the bare substrate (no binder on it) when
/// `layers` is empty.
pub fn look(
    ords: &Ordinates,
    layers: &[&LayerSlab],
    below: Below,
    v: &Views,
) -> Result<Look, BaselineError> {
    if layers.is_empty() {
        // A Lambertian paper of albedo ρ reads ρ in every geometry and
        // under the sky; air reads nothing.
        let rho = match below {
            Below::Paper { albedo } => albedo,
            Below::Air => 0.0,
        };
        return Ok(Look {
            factors: vec![rho; v.measurements.len()],
            natural: vec![rho; v.viewing_deg.len()],
            plane: v
                .illumination_deg
                .map(|ill| Array2::from_elem((ill.len(), v.viewing_deg.len()), rho)),
            totals: vec![[0.0, 1.0, 0.0]; v.above_deg.len()],
        });
    }
    let sr = stack_reflection(ords, layers, below, v.surfaces)?;
    let factors = v
        .measurements
        .iter()
        .map(|&m| sr.factor(m))
        .collect::<Result<_, _>>()?;
    let natural = v
        .viewing_deg
        .iter()
        .map(|&deg| white_sky(&sr, deg))
        .collect::<Result<_, _>>()?;
    let plane = match v.illumination_deg {
        Some(ill) => Some(plane_factors(
            ords,
            layers,
            &sr,
            ill,
            v.viewing_deg,
            v.surfaces,
        )?),
        None => None,
    };
    // The stack in air, only when its totals are asked for.
    let totals = if v.above_deg.is_empty() {
        Vec::new()
    } else {
        let free = free_stack(
            ords,
            &layers.iter().map(|l| &l.total).collect::<Vec<_>>(),
            v.surfaces,
        )?;
        v.above_deg
            .iter()
            .map(|&deg| {
                let j = ords.air_node(deg).ok_or(BaselineError::NoDirection(deg))?;
                let r: f64 = (0..ords.len()).map(|i| free.r_down[(i, j)]).sum();
                let t: f64 = (0..ords.len()).map(|i| free.t_down[(i, j)]).sum();
                Ok([r, t, 1.0 - r - t])
            })
            .collect::<Result<_, BaselineError>>()?
    };
    Ok(Look {
        factors,
        natural,
        plane,
        totals,
    })
}

/// The stack of `layers` (top first) printed at `coverage` each: its
/// primaries' looks mixed by Demichel's areas, by Yule–Nielsen's `n` on
/// the substrate and by area for the totals. With every coverage 1 it is
/// the one stack's [`look`], exactly.
pub fn halftone(
    ords: &Ordinates,
    layers: &[LayerSlab],
    coverage: &[f64],
    n: f64,
    below: Below,
    v: &Views,
) -> Result<Look, BaselineError> {
    let mut parts = Vec::new();
    for p in primaries(coverage) {
        let printed: Vec<&LayerSlab> = p.layers.iter().map(|&i| &layers[i]).collect();
        parts.push((p.area, look(ords, &printed, below, v)?));
    }
    if let [(_, only)] = &parts[..] {
        return Ok(only.clone());
    }
    let mix = |value: &dyn Fn(&Look) -> f64| {
        let at: Vec<(f64, f64)> = parts.iter().map(|(w, l)| (*w, value(l))).collect();
        yule_nielsen(n, &at)
    };
    let first = &parts[0].1;
    Ok(Look {
        factors: (0..first.factors.len())
            .map(|g| mix(&|l| l.factors[g]))
            .collect(),
        natural: (0..first.natural.len())
            .map(|o| mix(&|l| l.natural[o]))
            .collect(),
        plane: first.plane.as_ref().map(|p| {
            Array2::from_shape_fn(p.dim(), |(c, o)| {
                mix(&|l| l.plane.as_ref().map_or(0.0, |q| q[[c, o]]))
            })
        }),
        totals: (0..first.totals.len())
            .map(|a| {
                let mut t = [0.0; 3];
                for (w, l) in &parts {
                    for (x, y) in t.iter_mut().zip(l.totals[a]) {
                        *x += w * y;
                    }
                }
                t
            })
            .collect(),
    })
}
