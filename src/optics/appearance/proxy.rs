//! The spectral proxy: the homogeneous slab that carries the shape of the
//! pigments' absorption bands between the solved wavelengths.

use super::AppearanceSpec;
use crate::config::GroundReflectance;
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
    /// Quadrature of the slab's diffuse terms (the scene's, as for the
    /// solves from below).
    pub quadrature: Hemisphere,
}

impl SpectralProxy {
    /// Proxy BRDF square `(fine λ, illumination, viewing)` and sky strip
    /// `(fine λ, viewing)` of the slab on the ground `ground` (None: one that
    /// reflects nothing).
    pub(super) fn spectra(
        &self,
        spec: &AppearanceSpec,
        ground: Option<&GroundReflectance>,
    ) -> (Array3<f64>, Array2<f64>) {
        let nf = self.wavelengths_nm.len();
        let (ni, nv) = (spec.illumination_deg.len(), spec.viewing_deg.len());
        let mut f = Array3::zeros((nf, ni, nv));
        let mut sky = Array2::zeros((nf, nv));
        for (l, (&wl, &eps)) in self.wavelengths_nm.iter().zip(&self.eps).enumerate() {
            let albedo = ground.map_or(0.0, |g| g.at(wl));
            let SlabOnPaper { rt, td, denom } = self.on_paper(wl, eps, albedo);
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
    /// proxy's quadrature.
    pub(super) fn on_paper(
        &self,
        wl: f64,
        eps: C64,
        albedo: f64,
    ) -> SlabOnPaper<impl Fn(f64) -> (f64, f64) + '_> {
        let h = &self.quadrature;
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
/// interval between solved wavelengths for the ratio model to be trusted
/// there.
pub const PROXY_RATIO_SPREAD: f64 = 10.0;

/// Smallest relative change of the proxy across an interval for the affine
/// model's slope to be determined by the two solved values.
pub const AFFINE_MIN_PROXY_CHANGE: f64 = 0.01;

/// Largest gain a fill may give the proxy's shape: the affine model's `b`
/// and the ratio model's layer / proxy at both ends. A layer reflecting many
/// times what the clear slab does (a scattering white over black: 5–10×)
/// owes the excess to its grains, whose spectrum is smooth; the slab's
/// thin-film fringes between two solved wavelengths, scaled by that much,
/// made impossible colours (a rutile drawdown over black at 450/550/650 nm:
/// L* 91, a* −63 from solved reflectances of 0.49–0.61). Beyond this gain the
/// interval is interpolated linearly.
pub const MAX_PROXY_GAIN: f64 = 2.0;

/// How one interval between solved wavelengths is filled in.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fill {
    /// `a + b·proxy(λ)`, `a ≥ 0`, `b > 0`, through both solved values.
    Affine { a: f64, b: f64 },
    /// Linearly interpolated ratio layer / proxy, times the proxy.
    Ratio,
    /// Linear interpolation of the layer's own values.
    Linear,
}

/// Spectrum on the proxy's fine grid from the layer's `values` at the solved
/// wavelengths `wl` (each of which is on the fine grid).
///
/// Each interval between two solved wavelengths is filled by the first of
/// three models that fits it:
///
/// 1. **Affine**, `layer(λ) = a + b·proxy(λ)` with constant `a ≥ 0`, `b > 0`
///    fixed by the two solved values, where the proxy changes by at least
///    [`AFFINE_MIN_PROXY_CHANGE`] across the interval. It is exact when the grains scale the
///    slab's spectrum (`a = 0`) *and* when they add a smooth, nearly
///    wavelength-independent surface scattering to it (`b = 1`), the case of
///    a strongly absorbing layer seen by the light its top grains scatter
///    back, where the proxy is orders of magnitude darker in the band. With
///    `a ≥ 0` and `b > 0` the result stays within the proxy's own shape: it
///    cannot amplify a proxy peak between a dark and a bright solved value
///    the way an interpolated ratio does (ratio ≫ 1 at the dark end times the
///    proxy's peak overshoots the bright end).
/// 2. **Ratio**, where the affine fit needs `a < 0` or `b ≤ 0` or is not
///    determined: the ratio
///    layer / proxy interpolated linearly, if it changes by at most
///    [`PROXY_RATIO_SPREAD`] across the interval.
/// 3. **Linear** interpolation of the layer's values otherwise: there the
///    proxy does not describe the layer.
///
/// Outside the solved range the nearest interval's affine model is
/// extended (else the nearest ratio held). At the solved wavelengths the
/// result equals the solved values.
pub(super) fn through_proxy(
    wl: &[f64],
    values: &[f64],
    fine: &[f64],
    proxy_fine: &[f64],
) -> Vec<f64> {
    let at = |x: f64| fine.iter().position(|&f| f == x);
    let proxy_at: Vec<f64> = wl
        .iter()
        .map(|&w| at(w).map_or(0.0, |k| proxy_fine[k]))
        .collect();
    let ratio: Vec<f64> = values
        .iter()
        .zip(&proxy_at)
        .map(|(&v, &p)| if p > 0.0 { v / p } else { f64::INFINITY })
        .collect();
    let n = wl.len();
    let fills: Vec<Fill> = (0..n.saturating_sub(1))
        .map(|k| {
            fill_of(
                values[k],
                values[k + 1],
                proxy_at[k],
                proxy_at[k + 1],
                ratio[k],
                ratio[k + 1],
            )
        })
        .collect();
    // Beyond the solved range: the nearest interval's affine model, else
    // the nearest ratio held.
    let held = |k: usize, fill: Option<&Fill>, p: f64| match fill {
        Some(&Fill::Affine { a, b }) => a + b * p,
        _ if ratio[k].is_finite() => ratio[k] * p,
        _ => values[k],
    };
    fine.iter()
        .zip(proxy_fine)
        .map(|(&x, &p)| {
            if x <= wl[0] || n == 1 {
                return held(0, fills.first(), p);
            }
            if x >= wl[n - 1] {
                return held(n - 1, fills.last(), p);
            }
            let k = wl.windows(2).position(|w| x < w[1]).unwrap_or(0);
            let t = (x - wl[k]) / (wl[k + 1] - wl[k]);
            match fills[k] {
                Fill::Affine { a, b } => a + b * p,
                Fill::Ratio => (ratio[k] * (1.0 - t) + ratio[k + 1] * t) * p,
                Fill::Linear => values[k] * (1.0 - t) + values[k + 1] * t,
            }
        })
        .collect()
}

/// The model for one interval: solved values `v0`, `v1`, proxy `p0`, `p1`
/// and ratios `r0`, `r1` at its ends.
fn fill_of(v0: f64, v1: f64, p0: f64, p1: f64, r0: f64, r1: f64) -> Fill {
    let dp = p1 - p0;
    // With nearly equal proxy values at both ends, `b` is a ratio of
    // differences of nearly equal numbers: no longer determined.
    if dp.abs() >= AFFINE_MIN_PROXY_CHANGE * p0.max(p1) && p0 >= 0.0 && p1 >= 0.0 {
        let b = (v1 - v0) / dp;
        let a = v0 - b * p0;
        // Round-off: a layer that is exactly c × proxy gives a ≈ 0 of
        // either sign.
        let tiny = 1e-12 * v0.abs().max(v1.abs());
        if b > 0.0 && b <= MAX_PROXY_GAIN && a >= -tiny {
            return Fill::Affine { a: a.max(0.0), b };
        }
    }
    let ratio_fits = r0.is_finite()
        && r1.is_finite()
        && r0 > 0.0
        && r1 > 0.0
        && r0.max(r1) <= PROXY_RATIO_SPREAD * r0.min(r1)
        && r0.max(r1) <= MAX_PROXY_GAIN;
    if ratio_fits {
        Fill::Ratio
    } else {
        Fill::Linear
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fine grid of 10 nm, solves every 100 nm, and a proxy with a band at
    /// 430 nm, a deep band at 600 nm and a peak above its 700 nm value at
    /// 670 nm.
    fn setup() -> (Vec<f64>, [f64; 4], Vec<f64>) {
        let fine: Vec<f64> = (0..=30).map(|i| 400.0 + 10.0 * i as f64).collect();
        let proxy = fine
            .iter()
            .map(|&x| {
                0.5 - 0.3 * (-((x - 430.0) / 20.0).powi(2)).exp()
                    - 0.4999 * (-((x - 600.0) / 20.0).powi(2)).exp()
                    + 0.4 * (-((x - 670.0) / 15.0).powi(2)).exp()
            })
            .collect();
        (fine, [400.0, 500.0, 600.0, 700.0], proxy)
    }

    #[test]
    fn a_layer_that_scales_the_proxy_is_reproduced_everywhere() {
        let (fine, wl, proxy) = setup();
        let p = |x: f64| proxy[fine.iter().position(|&f| f == x).unwrap()];
        let values = wl.iter().map(|&w| 0.8 * p(w)).collect::<Vec<_>>();
        let out = through_proxy(&wl, &values, &fine, &proxy);
        for (o, q) in out.iter().zip(&proxy) {
            assert!((o - 0.8 * q).abs() < 1e-12, "{o} vs {}", 0.8 * q);
        }
    }

    #[test]
    fn surface_scattering_over_a_dark_band_is_reproduced_without_overshoot() {
        // The layer is the proxy scaled by 0.9 plus 0.02 of flat surface
        // scattering: in the 600 nm band the proxy is 5000× darker than the
        // layer, and the ratio layer / proxy runs from ≈ 40 to ≈ 1. The
        // ratio model would carry that 40 onto the 670 nm peak.
        let (fine, wl, proxy) = setup();
        let p = |x: f64| proxy[fine.iter().position(|&f| f == x).unwrap()];
        let layer = |q: f64| 0.02 + 0.9 * q;
        let values = wl.iter().map(|&w| layer(p(w))).collect::<Vec<_>>();
        let out = through_proxy(&wl, &values, &fine, &proxy);
        for (o, q) in out.iter().zip(&proxy) {
            assert!((o - layer(*q)).abs() < 1e-12, "{o} vs {}", layer(*q));
        }
        let peak = out.iter().cloned().fold(0.0, f64::max);
        assert!(
            peak < 0.9,
            "peak {peak}: no overshoot above the proxy's own shape"
        );
        // The ratio model on the 600–700 nm interval, for contrast.
        let (r0, r1) = (values[2] / p(600.0), values[3] / p(700.0));
        let t = 0.7;
        let ratio_model = ((1.0 - t) * r0 + t * r1) * p(670.0);
        assert!(
            ratio_model > 4.0,
            "the ratio model overshoots: {ratio_model}"
        );
    }

    #[test]
    fn a_layer_far_brighter_than_the_proxy_is_not_given_its_shape() {
        let (fine, wl, proxy) = setup();
        let p = |x: f64| proxy[fine.iter().position(|&f| f == x).unwrap()];
        let at = |out: &[f64], x: f64| out[fine.iter().position(|&f| f == x).unwrap()];
        // Five times the proxy (b = 5 > MAX_PROXY_GAIN): linear, not 5 ×
        // the proxy's band between the solved wavelengths.
        let values: Vec<f64> = wl.iter().map(|&w| 5.0 * p(w)).collect();
        let out = through_proxy(&wl, &values, &fine, &proxy);
        let lin = 0.7 * values[0] + 0.3 * values[1];
        assert!((at(&out, 430.0) - lin).abs() < 1e-12, "{}", at(&out, 430.0));
        // At twice the proxy the shape is kept.
        let values: Vec<f64> = wl.iter().map(|&w| 2.0 * p(w)).collect();
        let out = through_proxy(&wl, &values, &fine, &proxy);
        assert!((at(&out, 430.0) - 2.0 * p(430.0)).abs() < 1e-12);
    }

    #[test]
    fn a_layer_against_the_proxy_falls_back_to_the_ratio_or_to_linear() {
        let (fine, wl, proxy) = setup();
        let p = |x: f64| proxy[fine.iter().position(|&f| f == x).unwrap()];
        let at = |out: &[f64], x: f64| out[fine.iter().position(|&f| f == x).unwrap()];
        // 400–500 nm: the proxy rises (0.47 → 0.50) while the layer falls
        // (0.4 → 0.35): b < 0, the ratio changes by 1.2× → ratio model.
        // 500–600 nm: the layer rises as the proxy falls 5000× → b < 0, the
        // ratio spreads far beyond 10× → linear.
        let values = [0.4, 0.35, 0.5, 0.8 * p(700.0)];
        let out = through_proxy(&wl, &values, &fine, &proxy);
        for (w, v) in wl.iter().zip(values) {
            assert!(
                (at(&out, *w) - v).abs() < 1e-15,
                "solved wavelengths are exact"
            );
        }
        let (r0, r1) = (values[0] / p(400.0), values[1] / p(500.0));
        let t = 0.3;
        let ratio_430 = ((1.0 - t) * r0 + t * r1) * p(430.0);
        assert!((at(&out, 430.0) - ratio_430).abs() < 1e-12);
        assert!(
            at(&out, 430.0) < 0.2,
            "the 430 nm band is carried by the ratio"
        );
        let lin = 0.5 * (values[1] + values[2]);
        assert!(
            (at(&out, 550.0) - lin).abs() < 1e-12,
            "{} vs {lin}",
            at(&out, 550.0)
        );
    }
}
