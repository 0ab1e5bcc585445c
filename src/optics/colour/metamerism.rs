//! The special metamerism index for a change of illuminant (ISO 18314-4):
//! how far apart two colours that match (or nearly match) under a reference
//! illuminant look under a test source.
//!
//! A pair that does not match exactly under the reference would show a
//! difference under the test source even if it were not metameric at all,
//! so the trial is first corrected by the **multiplicative parameric
//! correction in XYZ** (CIE 015:2004 §9.2; Fairman 1987): under the test
//! source its tristimulus values are scaled channel by channel by the
//! standard's over the trial's under the reference,
//! `X'_trial,test = X_trial,test · X_std,ref / X_trial,ref` (and Y, Z). The
//! index is CIEDE2000 between the standard and the corrected trial under the
//! test source, both in CIELAB relative to the test source's perfect
//! reflecting diffuser. For a pair that matches exactly under the reference
//! the correction is the identity; for a spectral match the index is 0.

use super::{delta_e2000, xyz_from_reflectance, xyz_to_lab, ColourError, Observer};

/// The metamerism of a pair under one test source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metamerism {
    /// CIEDE2000 of the pair under the reference illuminant.
    pub de00_reference: f64,
    /// CIEDE2000 of the pair under the test source, uncorrected.
    pub de00_test: f64,
    /// The special metamerism index: CIEDE2000 under the test source after
    /// the multiplicative parameric correction (module docs).
    pub index: f64,
}

/// The special metamerism index of the trial spectrum against the standard
/// (both reflectance factors on `wavelengths_nm`), from the `reference`
/// observer–illuminant to the `test` one (the same standard observer).
pub fn special_metamerism_index(
    reference: &Observer,
    test: &Observer,
    wavelengths_nm: &[f64],
    standard: &[f64],
    trial: &[f64],
) -> Result<Metamerism, ColourError> {
    let xyz = |obs: &Observer, r: &[f64]| xyz_from_reflectance(obs, wavelengths_nm, r);
    let (s_ref, t_ref) = (xyz(reference, standard)?, xyz(reference, trial)?);
    let (s_test, t_test) = (xyz(test, standard)?, xyz(test, trial)?);
    let lab = |obs: &Observer, v: [f64; 3]| xyz_to_lab(v, obs.white_xyz());
    // A channel the trial does not reflect at all under the reference (a
    // perfect black) cannot be scaled: it is left uncorrected.
    let corrected: [f64; 3] = std::array::from_fn(|c| {
        if t_ref[c] > 0.0 {
            t_test[c] * s_ref[c] / t_ref[c]
        } else {
            t_test[c]
        }
    });
    Ok(Metamerism {
        de00_reference: delta_e2000(lab(reference, s_ref), lab(reference, t_ref)),
        de00_test: delta_e2000(lab(test, s_test), lab(test, t_test)),
        index: delta_e2000(lab(test, s_test), lab(test, corrected)),
    })
}
