//! The two-flux layer: Kubelka–Munk reflectance on a Lambertian backing,
//! and Saunderson's correction for the layer's surface (whose reflectances
//! `r_e`, `r_i`, `r_ed` are [`super::fresnel`]'s, re-exported here).

pub use super::fresnel::{
    diffuse_external_reflectance, diffuse_external_reflectance_scalar, external_reflectance,
    external_reflectance_scalar, fresnel_unpolarised, internal_reflectance,
    internal_reflectance_scalar,
};

/// Kubelka–Munk reflectance of a layer of absorption coefficient `k`,
/// scattering coefficient `s` (1/length) and thickness `x` on a backing of
/// reflectance `rg`.
///
/// With `a = 1 + K/S`, `b = √(a² − 1)` and `t = tanh(b S X)/b`:
/// `R = [t (1 − R_g a) + R_g] / [t (a − R_g) + 1]`, the usual closed form
/// divided by `b coth(b S X)`, which stays finite in both limits:
/// - `K → 0` (`b → 0`, `t → S X`): `R = (R_g + SX(1 − R_g)) / (1 + SX(1 − R_g))`;
/// - `S → 0`: Beer's law through the layer and back, `R = R_g e^{−2KX}`
///   (taken exactly when S = 0 or K/S > 10¹²);
/// - `X → ∞`: `R∞ = a − b = 1 + K/S − √((K/S)² + 2K/S)`.
pub fn reflectance(k: f64, s: f64, x: f64, rg: f64) -> f64 {
    if s <= 0.0 || k > 1e12 * s {
        return rg * (-2.0 * k * x).exp();
    }
    let q = k / s;
    let a = 1.0 + q;
    let b = (q * q + 2.0 * q).sqrt();
    let bsx = b * s * x;
    let t = if bsx < 1e-8 { s * x } else { bsx.tanh() / b };
    (t * (1.0 - rg * a) + rg) / (t * (a - rg) + 1.0)
}

/// Reflectance of an infinitely thick layer, `R∞ = 1 + K/S − √((K/S)² + 2K/S)`
/// (1 for K = 0, 0 for S = 0).
pub fn reflectance_infinite(k: f64, s: f64) -> f64 {
    if s <= 0.0 {
        return 0.0;
    }
    let q = k / s;
    // 1 + q − √(q² + 2q) = 1 / (1 + q + √(q² + 2q)), without cancellation.
    1.0 / (1.0 + q + (q * q + 2.0 * q).sqrt())
}

/// Saunderson's correction: what an instrument measures of a layer whose
/// body reflectance (inside the surface) is `r`, with external reflectance
/// `r_e` of the surface (light arriving from outside) and internal diffuse
/// reflectance `r_i`:
/// `R_meas = r_e + (1 − r_e)(1 − r_i) R / (1 − r_i R)`. Pass `r_e` as the
/// specular term when it is included; [`saunderson_excluded`] leaves it out.
pub fn saunderson(r: f64, r_e: f64, r_i: f64) -> f64 {
    r_e + saunderson_excluded(r, r_e, r_i)
}

/// Saunderson's correction without the specular reflection itself
/// (geometries that do not see it: 45°/0°, d/8° SCE).
pub fn saunderson_excluded(r: f64, r_e: f64, r_i: f64) -> f64 {
    (1.0 - r_e) * (1.0 - r_i) * r / (1.0 - r_i * r)
}

/// The backing a Kubelka–Munk layer sees in the wave scene: the binder's
/// lower surface over an air gap over Lambertian paper of `albedo`. Diffuse
/// light from inside is reflected by the surface (`r_i`) or leaves into the
/// gap (`1 − r_i`); there paper and surface exchange light (`albedo`,
/// `r_ed`) until it re-enters (`1 − r_ed`):
/// `R_g = r_i + (1 − r_i) ρ (1 − r_ed) / (1 − ρ r_ed)`.
pub fn scene_backing(albedo: f64, r_i: f64, r_ed: f64) -> f64 {
    r_i + (1.0 - r_i) * albedo * (1.0 - r_ed) / (1.0 - albedo * r_ed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_of_the_closed_form() {
        let (x, rg) = (2.0, 0.8);
        // K → 0: the lossless formula, continuous into K = 0.
        let s = 0.7;
        let lossless = (rg + s * x * (1.0 - rg)) / (1.0 + s * x * (1.0 - rg));
        assert!((reflectance(0.0, s, x, rg) - lossless).abs() < 1e-15);
        assert!((reflectance(1e-12, s, x, rg) - lossless).abs() < 1e-10);
        // S → 0: Beer's law, continuous into S = 0.
        let k = 0.3;
        let beer = rg * (-2.0 * k * x).exp();
        assert_eq!(reflectance(k, 0.0, x, rg), beer);
        assert!((reflectance(k, 1e-9, x, rg) - beer).abs() < 1e-8);
        // Very thick: R∞, whatever the backing.
        let r_inf = reflectance_infinite(k, s);
        let direct = 1.0 + k / s - ((k / s).powi(2) + 2.0 * k / s).sqrt();
        assert!((r_inf - direct).abs() < 1e-14);
        for rg in [0.0, 0.5, 1.0] {
            assert!((reflectance(k, s, 1e4, rg) - r_inf).abs() < 1e-12);
        }
        // No layer: the backing.
        assert!((reflectance(k, s, 0.0, rg) - rg).abs() < 1e-15);
        // Never NaN, always in [0, 1].
        for k in [0.0, 1e-300, 1e-6, 1.0, 1e6] {
            for s in [0.0, 1e-300, 1e-6, 1.0, 1e6] {
                let r = reflectance(k, s, x, rg);
                assert!((0.0..=1.0).contains(&r), "K {k}, S {s}: {r}");
            }
        }
    }

    #[test]
    fn saunderson_without_surface_is_the_identity() {
        for r in [0.0, 0.3, 0.9, 1.0] {
            assert_eq!(saunderson(r, 0.0, 0.0), r);
        }
    }
}
