//! 3-vector helpers on `[f64; 3]` (the packers' centres, axes, forces and
//! torques).

#[inline]
pub(crate) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a += s b`.
#[inline]
pub(crate) fn add(a: &mut [f64; 3], b: &[f64; 3], s: f64) {
    a[0] += s * b[0];
    a[1] += s * b[1];
    a[2] += s * b[2];
}

#[inline]
pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn norm(a: &[f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// `a` turned by the rotation vector `om dt` (Rodrigues), renormalised.
#[inline]
pub(crate) fn rotate(a: &[f64; 3], om: &[f64; 3], dt: f64) -> [f64; 3] {
    let no = norm(om);
    let phi = no * dt;
    if phi <= 0.0 {
        return *a;
    }
    let k = [om[0] / no, om[1] / no, om[2] / no];
    let kxa = cross(&k, a);
    let kd = dot(&k, a);
    let (s, co) = phi.sin_cos();
    let mut b = [0.0; 3];
    for ax in 0..3 {
        b[ax] = a[ax] * co + kxa[ax] * s + k[ax] * kd * (1.0 - co);
    }
    let nb = norm(&b);
    [b[0] / nb, b[1] / nb, b[2] / nb]
}
