//! Closed-form references for homogeneous layers, derived here and
//! independent of the solver they check: the Airy slab and the transfer
//! matrix of a stack, both on one branch of the vertical wavenumber.

use num_complex::Complex64 as C64;
use std::f64::consts::PI;

/// Vertical wavenumber `√(k²)` on the physical branch `Im kz ≥ 0` (waves
/// decay away from the layer; a propagating wave has `kz > 0`).
pub fn kz(k2: C64) -> C64 {
    let g = k2.sqrt();
    if g.im < 0.0 {
        -g
    } else {
        g
    }
}

/// Exact Airy amplitudes `(r, t)` of a homogeneous slab of permittivity `eps`
/// and thickness `h` in vacuum, for vacuum wavenumber `k0` and lateral
/// wavenumber `kap`.
pub fn airy(k0: f64, eps: C64, kap: f64, h: f64) -> (C64, C64) {
    let g = kz(k0 * k0 * eps - kap * kap);
    let b = kz(C64::new(k0 * k0 - kap * kap, 0.0));
    let rho = (g - b) / (g + b);
    let e = (2.0 * C64::i() * g * h).exp();
    let a = 2.0 * b / ((g + b) * (1.0 - rho * rho * e));
    (
        a * (1.0 + rho * e) - 1.0,
        a * (C64::i() * g * h).exp() * (1.0 + rho),
    )
}

/// Exact Airy amplitudes of the same slab in p polarisation, for the
/// magnetic field H_y (continuous with H_y'/ε): the same formula with the
/// inside admittance γ/ε in place of γ. `(r_H, t_H)`; powers `|r_H|²`,
/// `|t_H|²` (vacuum on both sides).
#[allow(dead_code)]
pub fn airy_p(k0: f64, eps: C64, kap: f64, h: f64) -> (C64, C64) {
    let g = kz(k0 * k0 * eps - kap * kap);
    let y = g / eps;
    let b = kz(C64::new(k0 * k0 - kap * kap, 0.0));
    let rho = (y - b) / (y + b);
    let e = (2.0 * C64::i() * g * h).exp();
    let a = 2.0 * b / ((y + b) * (1.0 - rho * rho * e));
    (
        a * (1.0 + rho * e) - 1.0,
        a * (C64::i() * g * h).exp() * (1.0 + rho),
    )
}

/// Airy power coefficients `(|r|², |t|²)` of the same slab.
pub fn airy_power(k0: f64, eps: C64, kap: f64, h: f64) -> (f64, f64) {
    let (r, t) = airy(k0, eps, kap, h);
    (r.norm_sqr(), t.norm_sqr())
}

/// `(R, T)` of a slab of real permittivity `eps`, thickness `h` (nm), at
/// wavelength `wl` (nm) and polar angle `polar_deg`.
pub fn airy_rt(eps: f64, h: f64, wl: f64, polar_deg: f64) -> (f64, f64) {
    let k0 = 2.0 * PI / wl;
    airy_power(k0, C64::new(eps, 0.0), k0 * polar_deg.to_radians().sin(), h)
}

/// Transfer matrix of a stack of homogeneous layers `(ε, thickness)`, top
/// first, in vacuum: power reflectance and transmittance at wavelength `wl`
/// (nm) and polar angle `polar` (degrees).
pub fn tmm(layers: &[(C64, f64)], wl: f64, polar: f64) -> (f64, f64) {
    let k0 = 2.0 * PI / wl;
    let kx = k0 * polar.to_radians().sin();
    let kz = |eps: C64| kz(eps * k0 * k0 - kx * kx);
    // Field (u, u'/i) propagated from the bottom (transmitted wave t = 1).
    let b = kz(C64::new(1.0, 0.0));
    let (mut u, mut du) = (C64::new(1.0, 0.0), b);
    for &(eps, d) in layers.iter().rev() {
        let g = kz(eps);
        let (c, s) = ((g * d).cos(), (g * d).sin());
        let (u2, du2) = (
            c * u - C64::i() * s * du / g,
            -C64::i() * g * s * u + c * du,
        );
        u = u2;
        du = du2;
    }
    // Above: u = a + r, du = b (a − r).
    let a = (u + du / b) / 2.0;
    let r = (u - du / b) / 2.0;
    ((r / a).norm_sqr(), (1.0 / a).norm_sqr())
}

/// [`tmm`] in p polarisation: the magnetic field H_y and `H_y'/(iε)`,
/// both continuous, propagated from the bottom; power reflectance and
/// transmittance (vacuum on both sides).
#[allow(dead_code)]
pub fn tmm_p(layers: &[(C64, f64)], wl: f64, polar: f64) -> (f64, f64) {
    let uniaxial: Vec<(C64, C64, f64)> = layers.iter().map(|&(e, d)| (e, e, d)).collect();
    tmm_p_uniaxial(&uniaxial, wl, polar)
}

/// [`tmm_p`] for uniaxial layers `(ε_xx, ε_zz, thickness)` whose optic
/// axis lies along x or z (plane of incidence x-z): H_y and `H_y'/(iε_xx)`
/// continuous, `k_z² = ε_xx (k0² − κ²/ε_zz)` inside.
#[allow(dead_code)]
pub fn tmm_p_uniaxial(layers: &[(C64, C64, f64)], wl: f64, polar: f64) -> (f64, f64) {
    let k0 = 2.0 * PI / wl;
    let kx = k0 * polar.to_radians().sin();
    let b = kz(C64::new(k0 * k0 - kx * kx, 0.0));
    let (mut u, mut w) = (C64::new(1.0, 0.0), b);
    for &(exx, ezz, d) in layers.iter().rev() {
        let g = kz(exx * (k0 * k0 - kx * kx / ezz));
        let (c, s) = ((g * d).cos(), (g * d).sin());
        let (u2, w2) = (
            c * u - C64::i() * s * exx * w / g,
            -C64::i() * g * s * u / exx + c * w,
        );
        u = u2;
        w = w2;
    }
    let a = (u + w / b) / 2.0;
    let r = (u - w / b) / 2.0;
    ((r / a).norm_sqr(), (1.0 / a).norm_sqr())
}

/// `2 ∫₀¹ f(μ) μ dμ` by composite Simpson with many points (the
/// diffuse terms of a closed-form slab, `R_dd` and `T_d`).
pub fn hemispherical(f: impl Fn(f64) -> f64) -> f64 {
    let n = 20_000;
    let h = 1.0 / n as f64;
    let mut s = 0.0;
    for i in 0..=n {
        let mu = i as f64 * h;
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        s += w * f(mu) * mu;
    }
    2.0 * s * h / 3.0
}
