//! The fast model of an effect paint (METHOD §10): its layers from the top
//! down (each lacquer with ordinary pigments and flakes) on a ground, under
//! the paint's flat surface, solved by adding–doubling term by term in the
//! azimuthal Fourier series ([`super::kernel`]).
//!
//! Every layer shares the lacquer's index (the layers' boundaries do not
//! reflect); the surface to air reflects natural light by Fresnel's law
//! (`baseline::fresnel`), with total internal reflection from inside. Each
//! layer is a doubled slab of its kernel (`baseline::doubling`); the layers
//! and the ground are added (`baseline::adding`). Grounds: a Lambertian one
//! (primer, paper; its albedo, in optical contact, term 0 only), a flat
//! metal (its Fresnel reflectance from the lacquer, every term), or black.
//!
//! The **mirror part** (what no scatterer deviates: the surface's and the
//! metal ground's reflections and their round trips, attenuated by the
//! layers) is a delta in direction; it is computed apart (the same adding
//! with the scattering left out) and subtracted from every term, so the
//! terms hold only the scattered light, whose BRDF is the Fourier sum
//! `π f(i → o, φ) = [R₀ + 2 Σ_{m≥1} R_m cos mφ]_oi / c_o` (`c_o` the view
//! bin's flux weight in air, `φ` the azimuth of the view from the mirror
//! direction's side), summed with Fejér's weights `1 − m/M` over the `M`
//! terms kept: Fejér's kernel is positive, so the sum of a positive
//! distribution stays positive (a plain cut series rings and can go
//! negative beside a narrow lobe), at an azimuthal resolution of about
//! `360°/M`.
//!
//! Each layer's series is cut where its kernel of term `m` is below
//! [`ModelParams::mode_tolerance`] of its term 0 (at most
//! [`ModelParams::max_terms`]; beyond its cut a layer only attenuates). The
//! paint's series is cut sooner, where no layer's kernel **into or out of an
//! escaping node** is above the tolerance: light from air enters on an
//! escaping node and leaves on one, so every path from air to air begins
//! with a scattering out of an escaping node and ends with one into an
//! escaping node, and the term `m` of a path is the product of its
//! scatterings' terms, each no larger than its term 0 (the kernels are
//! positive). The trapped nodes near grazing keep a lobe narrow in azimuth
//! (a grazing ray mirrored by a tilted flake barely turns), whose terms decay
//! slowly but reach air only through those first and last scatterings.
//! The Fejér weights are those of [`ModelParams::max_terms`] whatever the
//! cut (the terms beyond it count as zero), so the cut changes the sum only
//! by the terms it drops, not its azimuthal resolution (`360°/M`, M =
//! `max_terms`). Angular detail finer than the nodes' spacing in `μ` is not
//! resolved.

use super::kernel::{layer_kernels, FlakeMedium, NormalQuadrature};
use super::thin_film;
use crate::optics::baseline::adding::{self, Slab};
use crate::optics::baseline::doubling::{self, FluxKernel, Medium};
use crate::optics::baseline::fresnel::Fresnel;
use crate::optics::baseline::matrix::Matrix;
use crate::optics::baseline::ordinates::{OrdinateParams, Ordinates};
use crate::optics::baseline::BaselineError;
use num_complex::Complex64 as C64;
use rayon::prelude::*;

/// One layer of the paint at one wavelength.
#[derive(Debug, Clone)]
pub struct PaintLayer {
    pub thickness_nm: f64,
    /// The ordinary pigments (and the lacquer's own absorption).
    pub pigments: Medium,
    pub flakes: Option<FlakeMedium>,
}

/// What the paint lies on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ground {
    /// A diffuse (Lambertian) ground in optical contact with the lacquer.
    Lambertian { albedo: f64 },
    /// A flat metal (or any medium) of complex index.
    Mirror { index: C64 },
    /// Absorbs everything.
    Black,
}

/// Resolution of the fast model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelParams {
    pub ordinates: OrdinateParams,
    /// Largest number of Fourier terms.
    pub max_terms: usize,
    /// Relative size below which a term's kernels count as zero.
    pub mode_tolerance: f64,
    pub normals: NormalQuadrature,
    /// The thin layer's largest attenuation `e Δz` before doubling.
    pub start: f64,
}

impl Default for ModelParams {
    fn default() -> Self {
        ModelParams {
            ordinates: OrdinateParams {
                trapped_nodes: 8,
                escape_nodes: 16,
            },
            max_terms: 64,
            mode_tolerance: 1e-3,
            normals: NormalQuadrature::default(),
            start: 1e-4,
        }
    }
}

/// The paint's reflection at one wavelength.
#[derive(Debug, Clone)]
pub struct PaintReflection {
    pub ords: Ordinates,
    /// Scattered reflection per Fourier term (flux matrices, air bins).
    pub terms: Vec<Matrix>,
    /// The mirror part's reflectance per bin.
    pub mirror: Vec<f64>,
    /// The length `M` of the Fejér sum (≥ `terms.len()`; the terms beyond
    /// those kept count as zero).
    pub fejer_terms: usize,
}

impl PaintReflection {
    fn node(&self, polar_deg: f64) -> Result<usize, BaselineError> {
        self.ords
            .air_node(polar_deg)
            .ok_or(BaselineError::NoDirection(polar_deg))
    }

    /// `π f` of the scattered light (Fejér-summed) from `incidence_deg` into `view_deg`,
    /// the view at azimuth `azimuth_deg` from the mirror direction's side
    /// (0: in the plane of incidence beyond the normal, 180: back towards
    /// the light). Both angles must be air nodes.
    pub fn factor(
        &self,
        incidence_deg: f64,
        view_deg: f64,
        azimuth_deg: f64,
    ) -> Result<f64, BaselineError> {
        let (i, j) = (self.node(view_deg)?, self.node(incidence_deg)?);
        let phi = azimuth_deg.to_radians();
        let count = self.fejer_terms.max(self.terms.len()) as f64;
        let mut sum = self.terms[0][(i, j)];
        for (m, t) in self.terms.iter().enumerate().skip(1) {
            let fejer = 1.0 - m as f64 / count;
            sum += 2.0 * fejer * t[(i, j)] * (m as f64 * phi).cos();
        }
        Ok(sum / self.ords.air_flux_weight(i))
    }

    /// All the light reflected for incidence from bin `j` (mirror part
    /// included): the directional–hemispherical reflectance.
    pub fn albedo(&self, j: usize) -> f64 {
        (0..self.ords.len())
            .map(|i| self.terms[0][(i, j)])
            .sum::<f64>()
            + self.mirror[j]
    }
}

/// The paint `layers` (top first) in a lacquer of index `lacquer` on
/// `ground` at `wavelength_nm`, with the air directions `air_deg` among the
/// nodes.
pub fn reflect(
    lacquer: f64,
    layers: &[PaintLayer],
    ground: Ground,
    wavelength_nm: f64,
    air_deg: &[f64],
    params: &ModelParams,
) -> Result<PaintReflection, BaselineError> {
    let ords = Ordinates::new(lacquer, params.ordinates, air_deg)?;
    let n = ords.len();
    let kernels: Vec<Vec<FluxKernel>> = layers
        .iter()
        .map(|l| {
            layer_kernels(
                &ords,
                &l.pigments,
                l.flakes.as_ref(),
                params.max_terms.max(1),
                params.normals,
            )
        })
        .collect();
    // Per layer, the terms that matter; beyond them a layer only attenuates.
    let every = vec![true; n];
    let counts: Vec<usize> = kernels
        .iter()
        .map(|k| significant_terms(k, params.mode_tolerance, &every))
        .collect();
    // The paint's: those that reach air.
    let escaping: Vec<bool> = ords.mu_air.iter().map(Option::is_some).collect();
    let terms = kernels
        .iter()
        .map(|k| significant_terms(k, params.mode_tolerance, &escaping))
        .max()
        .unwrap_or(1);
    let surface = adding::surface_air_over_binder(&ords, Fresnel::Unpolarised);
    let mirror_ground: Vec<f64> = match ground {
        Ground::Mirror { index } => ords
            .mu
            .iter()
            .map(|&mu| thin_film::unpolarised(lacquer, &[], index, wavelength_nm, mu).r)
            .collect(),
        _ => vec![0.0; n],
    };
    let reflection = |term: Option<usize>| -> Result<Matrix, BaselineError> {
        let mut body = Slab::transparent(n);
        for ((layer, k), &count) in layers.iter().zip(&kernels).zip(&counts) {
            let kernel = match term {
                Some(m) if m < count => k[m].clone(),
                _ => FluxKernel {
                    rate: k[0].rate.clone(),
                    same: Matrix::zeros(n),
                    opposite: Matrix::zeros(n),
                },
            };
            let slab = doubling::slab(&kernel, layer.thickness_nm, params.start)?.to_slab();
            body = adding::add(&body, &slab)?;
        }
        let mut backing = Matrix::diagonal(&mirror_ground);
        if let (Ground::Lambertian { albedo }, Some(0)) = (ground, term) {
            backing = backing.add(&adding::lambertian_in_binder(&ords, albedo));
        }
        let under = adding::on_backing(&body, &backing)?;
        adding::on_backing(&surface, &under)
    };
    let mirror_matrix = reflection(None)?;
    let mirror: Vec<f64> = (0..n).map(|i| mirror_matrix[(i, i)]).collect();
    let out = (0..terms)
        .into_par_iter()
        .map(|m| {
            let mut r = reflection(Some(m))?;
            for (i, v) in mirror.iter().enumerate() {
                r[(i, i)] -= v;
            }
            Ok(r)
        })
        .collect::<Result<Vec<Matrix>, BaselineError>>()?;
    Ok(PaintReflection {
        ords,
        terms: out,
        mirror,
        fejer_terms: params.max_terms.max(1),
    })
}

/// How many leading terms of a layer's kernels are not negligible on the
/// node pairs with at least one node in `nodes` (row or column).
fn significant_terms(kernels: &[FluxKernel], tolerance: f64, nodes: &[bool]) -> usize {
    let largest = |k: &FluxKernel| {
        let n = k.rate.len();
        let mut m = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                if nodes[i] || nodes[j] {
                    m = m.max(k.same[(i, j)].abs()).max(k.opposite[(i, j)].abs());
                }
            }
        }
        m
    };
    let scale = kernels.first().map_or(0.0, largest);
    if scale == 0.0 {
        return 1;
    }
    let mut count = 1;
    for (m, k) in kernels.iter().enumerate().skip(1) {
        if largest(k) > tolerance * scale {
            count = m + 1;
        }
    }
    count
}
