//! Periodic boundary helpers of the fragment (periodic in x and y, bounded
//! in z): wrapping a coordinate into its period and reducing a displacement
//! to the nearest periodic image.

/// `x` wrapped into `[0, l)`: `x.rem_euclid(l)`, with a result that rounds
/// up to `l` taken as 0. Within one period of the range (`-l < x < 2l`,
/// every use in the packers) the reduction is one exact add or subtract.
#[inline]
pub(crate) fn wrap(x: f64, l: f64) -> f64 {
    let w = if x < 0.0 {
        if x > -l {
            x + l
        } else {
            x.rem_euclid(l)
        }
    } else if x >= l {
        if x < 2.0 * l {
            x - l
        } else {
            x.rem_euclid(l)
        }
    } else {
        return x;
    };
    if w >= l {
        0.0
    } else {
        w
    }
}

/// Displacement `d` reduced to the nearest periodic image in a period `l`.
#[inline]
pub(crate) fn min_image(d: f64, l: f64) -> f64 {
    d - l * (d / l).round()
}

/// [`min_image`] with a branch for the usual case of coordinates within one
/// period of each other (no rounding call).
#[inline]
pub(crate) fn near_image(d: f64, l: f64) -> f64 {
    let h = 0.5 * l;
    if d > h {
        if d <= 3.0 * h {
            d - l
        } else {
            min_image(d, l)
        }
    } else if d < -h {
        if d >= -3.0 * h {
            d + l
        } else {
            min_image(d, l)
        }
    } else {
        d
    }
}

/// [`near_image`] for two coordinates wrapped into one period (so
/// `|d| < l`), with selects instead of branches.
#[inline(always)]
pub(crate) fn near_image_select(d: f64, l: f64) -> f64 {
    let h = 0.5 * l;
    d - if d > h { l } else { 0.0 } + if d < -h { l } else { 0.0 }
}

/// Squared centre distance of two points, nearest periodic image in x and y.
#[inline]
pub(crate) fn dist2(a: &[f64; 3], b: &[f64; 3], size: &[f64; 3]) -> f64 {
    let dx = near_image(a[0] - b[0], size[0]);
    let dy = near_image(a[1] - b[1], size[1]);
    let dz = a[2] - b[2];
    dx * dx + dy * dy + dz * dz
}

#[cfg(test)]
mod tests {
    use super::wrap;

    /// The fast paths agree bit for bit with `rem_euclid` (result `l` as 0).
    #[test]
    fn wrap_matches_rem_euclid() {
        let reference = |x: f64, l: f64| {
            let w = x.rem_euclid(l);
            if w >= l {
                0.0
            } else {
                w
            }
        };
        for l in [1.0, 3.7, 1e3, 123.456] {
            for x in [
                0.0,
                -0.0,
                -1e-300,
                -l,
                -l + 1e-12,
                -1.5 * l,
                -2.0 * l,
                -7.3 * l,
                0.3 * l,
                l,
                l * (1.0 - f64::EPSILON),
                1.9 * l,
                2.0 * l,
                5.5 * l,
            ] {
                assert_eq!(wrap(x, l).to_bits(), reference(x, l).to_bits(), "{x} {l}");
            }
        }
        assert!(wrap(f64::NAN, 1.0).is_nan());
    }
}
