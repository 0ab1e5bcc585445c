//! Colour as an instrument measures it: the CIE/ISO measurement geometries.
//!
//! A colorimeter does not look at a tile under a white sky; it lights and
//! views the sample in a standard geometry (CIE 15, ISO 13655):
//! - **45°/0°** (ISO 13655's geometry for print; by reciprocity the same as
//!   0°/45°): light at 45°, viewed along the normal. The specular reflection
//!   leaves at 45° and is not seen. Reflectance factor `π f(45° → 0°)` with `f`
//!   the diffuse BRDF of layer + paper: `f_layer(45→0) + ρ T(45°) T(0°) /
//!   (π (1 − ρ R_dd↑))`. The BRDF is read in the plane of incidence; an
//!   isotropic layer looks the same from every azimuth, so a ring-lit (45°a)
//!   instrument gives the same mean.
//! - **d/8° SCI** (specular component included, paints and CIE 15's
//!   integrating sphere): uniform diffuse light, viewed at 8°. By reciprocity
//!   the reflectance factor is the total directional-hemispherical reflectance
//!   at 8°, `R(8°) + ρ T_d T(8°) / (1 − ρ R_dd↑)`, the white-sky formula.
//! - **d/8° SCE** (specular component excluded, a gloss trap): the same minus
//!   the power of the mirror reflection, the (0,0) order at 8°, mean `|r00|²`
//!   (coherent and incoherent parts). The model's mirror reflection is a
//!   single direction; a real trap removes a cone of a few degrees, which for
//!   a layer whose diffuse BRDF is smooth there changes the result by that
//!   cone's share of the diffuse light (well below 1 %).
//!
//! Each geometry needs solves from above at its angles ([`Measurement::above_deg`]).
//! Colour follows the scene's observer and illuminant (D50, 2° is ISO 13655's);
//! with R ≥ 2 realisations every colour carries the standard errors of L*, a*,
//! b* and of ΔE00, as the tile's do ([`super::ColourSpread`]).

pub use crate::config::Measurement;

use super::colours::de00_standard_error;
use super::proxy::{through_proxy, SlabOnPaper, SpectralProxy};
use super::{find_entry, reduce, AppearanceError, AppearanceSpec, Estimate};
use crate::config::GroundReflectance;
use crate::optics::colour::{self, Observer};
use crate::optics::farfield::table::{self, Part};
use crate::optics::farfield::{Side, SolveEntry};
use ndarray::{Array1, Ix1};
use std::f64::consts::PI;

/// The colour of the sample in one measurement geometry.
#[derive(Debug, Clone)]
pub struct MeasuredColour {
    pub geometry: Measurement,
    /// Reflectance factor at the solved wavelengths: mean and standard error.
    pub reflectance: Estimate<Ix1>,
    /// The spectrum the colour is integrated from (the spectral proxy's fine
    /// grid where there is one, else the solved wavelengths), nm.
    pub spectrum_wavelengths_nm: Vec<f64>,
    pub spectrum: Vec<f64>,
    /// CIE XYZ (white Y = 100), CIELAB and CIE LCh(ab) (h in degrees).
    pub xyz: [f64; 3],
    pub lab: [f64; 3],
    pub lch: [f64; 3],
    /// Standard errors of L*, a*, b* and of the colour in ΔE00 (R ≥ 2).
    pub lab_se: Option<[f64; 3]>,
    pub de00_se: Option<f64>,
    /// Each realisation's own XYZ and CIELAB, from its own spectrum through
    /// the same proxy (R ≥ 2; empty for one).
    pub realisation_xyz: Vec<[f64; 3]>,
    pub realisation_lab: Vec<[f64; 3]>,
    /// Each realisation's reflectance factor at the solved wavelengths
    /// (R ≥ 2; empty for one).
    pub realisation_reflectance: Vec<Array1<f64>>,
}

/// The per-realisation quantities a measurement reads, besides the solves.
pub(super) struct PaperPerRealisation<'a> {
    pub ground: &'a GroundReflectance,
    /// The ground's albedo at each solved wavelength.
    pub albedo: &'a Array1<f64>,
    pub r_dd_up: &'a [Array1<f64>],
    pub t_d: &'a [Array1<f64>],
}

/// Reflectance factor of geometry `m` at wavelength index `l` for realisation
/// `r`; `at(polar)` gives that realisation's solve from above at `polar`,
/// `paper` its (albedo, `R_dd↑`, `T_d`) at that wavelength.
fn reflectance_factor<'e>(
    m: Measurement,
    spec: &AppearanceSpec,
    at: &dyn Fn(f64) -> Result<&'e SolveEntry, AppearanceError>,
    paper: Option<(f64, f64, f64)>,
) -> Result<f64, AppearanceError> {
    let t = |polar: f64| -> Result<f64, AppearanceError> {
        Ok(at(polar)?.efficiencies.total_transmittance)
    };
    Ok(match m {
        Measurement::FortyFiveZero => {
            let e = &at(45.0)?.efficiencies;
            let f_layer = table::spread(e, Part::DiffuseReflection, spec.table)
                .value_at(0.0, spec.azimuth_deg);
            let f_paper = match paper {
                Some((albedo, rdd, _)) => albedo * t(45.0)? * t(0.0)? / (PI * (1.0 - albedo * rdd)),
                None => 0.0,
            };
            colour::lambertian_reflectance(f_layer + f_paper)
        }
        Measurement::DiffuseEightSci | Measurement::DiffuseEightSce => {
            let e = &at(8.0)?.efficiencies;
            let mut v = e.total_reflectance;
            if let Some((albedo, rdd, td)) = paper {
                v += albedo * td * e.total_transmittance / (1.0 - albedo * rdd);
            }
            if m == Measurement::DiffuseEightSce {
                v -= e.specular_power().0;
            }
            v
        }
    })
}

/// The same reflectance factor for the spectral proxy (the homogeneous slab
/// on the same ground, whose reflection is all specular; None: a ground that
/// reflects nothing), on its fine grid.
fn proxy_factor(m: Measurement, p: &SpectralProxy, ground: Option<&GroundReflectance>) -> Vec<f64> {
    p.wavelengths_nm
        .iter()
        .zip(&p.eps)
        .map(|(&wl, &eps)| {
            let albedo = ground.map_or(0.0, |g| g.at(wl));
            let SlabOnPaper { rt, td, denom } = p.on_paper(wl, eps, albedo);
            match m {
                Measurement::FortyFiveZero => albedo * rt(45.0).1 * rt(0.0).1 / denom,
                Measurement::DiffuseEightSci => rt(8.0).0 + albedo * td * rt(8.0).1 / denom,
                Measurement::DiffuseEightSce => albedo * td * rt(8.0).1 / denom,
            }
        })
        .collect()
}

/// Colours of every geometry in `spec.measurements` from the solves.
pub(super) fn measure(
    spec: &AppearanceSpec,
    entries: &[SolveEntry],
    paper: Option<PaperPerRealisation<'_>>,
    observer: &Observer,
) -> Result<Vec<MeasuredColour>, AppearanceError> {
    let rr = spec.realisations;
    let wl = &spec.wavelengths_nm;
    let mut out = Vec::with_capacity(spec.measurements.len());
    for &m in &spec.measurements {
        for &polar in m.above_deg() {
            if !spec.above_deg.contains(&polar) {
                return Err(AppearanceError::NotSolved(polar));
            }
        }
        let mut samples = Vec::with_capacity(rr);
        for r in 0..rr {
            let mut v = Array1::zeros(wl.len());
            for (l, &w) in wl.iter().enumerate() {
                let at = |polar: f64| find_entry(entries, Side::Above, r, w, polar);
                let p = paper
                    .as_ref()
                    .map(|p| (p.albedo[l], p.r_dd_up[r][l], p.t_d[r][l]));
                v[l] = reflectance_factor(m, spec, &at, p)?;
            }
            samples.push(v);
        }
        let proxy = spec
            .proxy
            .as_ref()
            .map(|p| (p, proxy_factor(m, p, paper.as_ref().map(|pp| pp.ground))));
        let proxy = proxy
            .as_ref()
            .map(|(p, fine)| (&p.wavelengths_nm[..], &fine[..]));
        out.push(colour_of_samples(
            m,
            wl,
            &samples,
            proxy,
            spec.deterministic,
            observer,
        )?);
    }
    Ok(out)
}

/// The colour in geometry `m` of per-realisation reflectance factors
/// `samples` at the solved wavelengths `wl`: the mean's spectrum (through
/// the spectral proxy `(fine grid, proxy factor on it)` where there is one),
/// XYZ, CIELAB and LCh, and with two or more realisations the standard
/// errors of L*, a*, b* and of ΔE00 (exactly 0 for a `deterministic` layer).
pub fn colour_of_samples(
    m: Measurement,
    wl: &[f64],
    samples: &[Array1<f64>],
    proxy: Option<(&[f64], &[f64])>,
    deterministic: bool,
    observer: &Observer,
) -> Result<MeasuredColour, AppearanceError> {
    let spectrum_of = |values: &Array1<f64>| -> (Vec<f64>, Vec<f64>) {
        match proxy {
            Some((fine_wl, fine)) => (
                fine_wl.to_vec(),
                through_proxy(wl, values.as_slice().unwrap(), fine_wl, fine),
            ),
            None => (wl.to_vec(), values.to_vec()),
        }
    };
    let lab_of = |values: &Array1<f64>| -> Result<([f64; 3], [f64; 3]), AppearanceError> {
        let (w, s) = spectrum_of(values);
        let xyz = colour::xyz_from_reflectance(observer, &w, &s)?;
        Ok((xyz, colour::xyz_to_lab(xyz, observer.white_xyz())))
    };
    let mut reflectance = reduce(samples);
    if deterministic && reflectance.se.is_none() {
        reflectance.se = Some(Array1::zeros(reflectance.mean.len()));
    }
    let (spectrum_wavelengths_nm, spectrum) = spectrum_of(&reflectance.mean);
    let (xyz, lab) = lab_of(&reflectance.mean)?;
    let (mut lab_se, mut de00_se) = (None, None);
    let (mut realisation_xyz, mut realisation_lab) = (Vec::new(), Vec::new());
    if samples.len() >= 2 {
        (realisation_xyz, realisation_lab) = samples
            .iter()
            .map(lab_of)
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .unzip();
        let labs = &realisation_lab;
        let as_arrays: Vec<Array1<f64>> = labs.iter().map(|l| Array1::from(l.to_vec())).collect();
        let se = reduce(&as_arrays).se.expect("two or more realisations");
        lab_se = Some([se[0], se[1], se[2]]);
        de00_se = Some(de00_standard_error(labs, lab));
    } else if deterministic {
        // Nothing random in the layer: every realisation is this one.
        lab_se = Some([0.0; 3]);
        de00_se = Some(0.0);
    }
    Ok(MeasuredColour {
        geometry: m,
        reflectance,
        spectrum_wavelengths_nm,
        spectrum,
        xyz,
        lab,
        lch: colour::lab_to_lch(lab),
        lab_se,
        de00_se,
        realisation_xyz,
        realisation_lab,
        realisation_reflectance: if samples.len() >= 2 {
            samples.to_vec()
        } else {
            Vec::new()
        },
    })
}
