//! The spectral proxy: the homogeneous slab that carries the shape of the
//! pigments' absorption bands between the solved wavelengths.

use super::AppearanceSpec;
use crate::optics::substrate::Hemisphere;
use crate::solver::airy;
use ndarray::{Array2, Array3};
use num_complex::Complex64 as C64;
use std::f64::consts::PI;

/// The homogeneous slab of the volume-averaged ε (the molecular mixture of
/// the same pigments) on the same paper, known in closed form at any
/// wavelength. Colours integrate spectra over 1 nm; the layer is solved at a
/// few wavelengths only, and pigment absorption bands are narrower than a
/// coarse step, so linear interpolation of the layer's spectra misses the
/// bands' shape (ΔE00 ≈ 9 at a 50 nm step, docs/ACCURACY.md). Instead the
/// *ratio* layer / proxy is interpolated linearly and multiplied by the proxy
/// on the fine grid: the proxy carries the bands' shape, the solves the
/// effect of the grains. At the solved wavelengths the result is exact.
#[derive(Debug, Clone)]
pub struct SpectralProxy {
    /// Fine grid (includes every solved wavelength), nm.
    pub wavelengths_nm: Vec<f64>,
    /// ⟨ε⟩ on the fine grid.
    pub eps: Vec<C64>,
    pub thickness_nm: f64,
}

impl SpectralProxy {
    /// Proxy BRDF square `(fine λ, illumination, viewing)` and sky strip
    /// `(fine λ, viewing)` of the slab on paper of albedo `albedo`.
    pub(super) fn spectra(
        &self,
        spec: &AppearanceSpec,
        albedo: f64,
        h: &Hemisphere,
    ) -> (Array3<f64>, Array2<f64>) {
        let nf = self.wavelengths_nm.len();
        let (ni, nv) = (spec.illumination_deg.len(), spec.viewing_deg.len());
        let mut f = Array3::zeros((nf, ni, nv));
        let mut sky = Array2::zeros((nf, nv));
        for (l, (&wl, &eps)) in self.wavelengths_nm.iter().zip(&self.eps).enumerate() {
            let SlabOnPaper { rt, td, denom } = self.on_paper(wl, eps, albedo, h);
            let ti: Vec<f64> = spec.illumination_deg.iter().map(|&a| rt(a).1).collect();
            for (o, &v) in spec.viewing_deg.iter().enumerate() {
                let (ro, to) = rt(v);
                sky[[l, o]] = ro + albedo * td * to / denom;
                for i in 0..ni {
                    f[[l, i, o]] = albedo * ti[i] * to / (PI * denom);
                }
            }
        }
        (f, sky)
    }

    /// The slab at `wl` (permittivity `eps`) on paper of albedo `albedo`:
    /// its power coefficients at any polar angle and its diffuse terms by the
    /// quadrature `h`.
    pub(super) fn on_paper(
        &self,
        wl: f64,
        eps: C64,
        albedo: f64,
        h: &Hemisphere,
    ) -> SlabOnPaper<impl Fn(f64) -> (f64, f64) + '_> {
        let thickness = self.thickness_nm;
        let rt = move |polar: f64| {
            let r = airy::slab(eps, thickness, wl, polar);
            (r.r.norm_sqr(), r.t.norm_sqr())
        };
        let nodes: Vec<(f64, f64)> = h.polar_deg().into_iter().map(&rt).collect();
        let rdd = h.diffuse(&nodes.iter().map(|x| x.0).collect::<Vec<_>>());
        let td = h.diffuse(&nodes.iter().map(|x| x.1).collect::<Vec<_>>());
        SlabOnPaper {
            rt,
            td,
            denom: 1.0 - albedo * rdd,
        }
    }
}

/// A homogeneous slab on Lambertian paper at one wavelength.
pub(super) struct SlabOnPaper<F: Fn(f64) -> (f64, f64)> {
    /// `(R, T)` of the slab at a polar angle (deg).
    pub rt: F,
    /// Diffuse transmittance `T_d`.
    pub td: f64,
    /// `1 − ρ R_dd↑`.
    pub denom: f64,
}

/// Largest factor by which the ratio layer / proxy may change across one
/// interval between solved wavelengths for the proxy to be trusted there.
pub const PROXY_RATIO_SPREAD: f64 = 10.0;

/// Spectrum on the proxy's fine grid: `ratio(λ) · proxy(λ)` with the ratio
/// interpolated linearly between the solved wavelengths (held at the ends).
/// Where the ratio changes by more than [`PROXY_RATIO_SPREAD`] across an
/// interval, the proxy does not describe the layer there (e.g. a strongly
/// absorbing layer seen by its surface scattering, while the slab's double
/// pass through the band is orders of magnitude darker): that interval falls
/// back to linear interpolation of the layer's own values.
pub(super) fn through_proxy(
    wl: &[f64],
    values: &[f64],
    fine: &[f64],
    proxy_fine: &[f64],
) -> Vec<f64> {
    let at = |x: f64| fine.iter().position(|&f| f == x);
    let ratio: Vec<f64> = wl
        .iter()
        .zip(values)
        .map(|(&w, &v)| {
            let p = at(w).map_or(0.0, |k| proxy_fine[k]);
            if p > 0.0 {
                v / p
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let trusted = |k: usize| {
        let (a, b) = (ratio[k], ratio[k + 1]);
        a.is_finite()
            && b.is_finite()
            && a > 0.0
            && b > 0.0
            && a.max(b) <= PROXY_RATIO_SPREAD * a.min(b)
    };
    let n = wl.len();
    let held = |k: usize, p: f64| {
        if ratio[k].is_finite() {
            ratio[k] * p
        } else {
            values[k]
        }
    };
    fine.iter()
        .zip(proxy_fine)
        .map(|(&x, &p)| {
            if x <= wl[0] || n == 1 {
                return held(0, p);
            }
            if x >= wl[n - 1] {
                return held(n - 1, p);
            }
            let k = wl.windows(2).position(|w| x < w[1]).unwrap_or(0);
            let t = (x - wl[k]) / (wl[k + 1] - wl[k]);
            if trusted(k) {
                (ratio[k] * (1.0 - t) + ratio[k + 1] * t) * p
            } else {
                values[k] * (1.0 - t) + values[k + 1] * t
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn proxy_shapes_between_solves_and_falls_back_where_it_does_not_fit() {
        let fine: Vec<f64> = (0..=20).map(|i| 400.0 + 10.0 * i as f64).collect();
        let wl = [400.0, 500.0, 600.0];
        // A proxy with a band at 450 nm and a deep one at 600 nm.
        let proxy: Vec<f64> = fine
            .iter()
            .map(|&x| {
                0.5 - 0.3 * (-((x - 450.0) / 20.0).powi(2)).exp()
                    - 0.4999 * (-((x - 600.0) / 20.0).powi(2)).exp()
            })
            .collect();
        let p_at = |x: f64| proxy[fine.iter().position(|&f| f == x).unwrap()];
        // Layer = 0.8 × proxy at 400 and 500 nm (the proxy fits there), but
        // a flat 0.1 at 600 nm where the proxy's band darkens it 5000-fold.
        let values = [0.8 * p_at(400.0), 0.8 * p_at(500.0), 0.1];
        let out = through_proxy(&wl, &values, &fine, &proxy);
        let at = |x: f64| out[fine.iter().position(|&f| f == x).unwrap()];
        for (w, v) in wl.iter().zip(values) {
            assert!((at(*w) - v).abs() < 1e-15, "solved wavelengths are exact");
        }
        // 400–500 nm: constant ratio, so the band at 450 nm is reproduced.
        assert!((at(450.0) - 0.8 * p_at(450.0)).abs() < 1e-12);
        assert!(at(450.0) < 0.8 * 0.21, "the band is there");
        // 500–600 nm: the ratio jumps far beyond the spread; linear values.
        let lin = 0.5 * (values[1] + values[2]);
        assert!((at(550.0) - lin).abs() < 1e-12, "{} vs {lin}", at(550.0));
    }
}
