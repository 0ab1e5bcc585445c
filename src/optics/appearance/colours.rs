//! The tile's colours and their uncertainty, and the layer-on-paper spectra
//! they are computed from.

use super::proxy::through_proxy;
use super::{reduce, AppearanceError};
use crate::optics::colour::{self, Observer};
use ndarray::{Array1, Array2, Array3, Array4};
use std::f64::consts::PI;

/// Colours of the tile.
#[derive(Debug, Clone)]
pub struct Colours {
    /// (viewing, 1 + illumination, 3): column 0 the sky strip, then the
    /// BRDF square (`π f` as a reflectance factor).
    pub tile_srgb8: Array3<u8>,
    /// CIELAB (D65 white) of the same cells.
    pub tile_lab: Array3<f64>,
    /// Sky strip per viewing angle: sRGB8 and CIELAB (D65 white).
    pub natural_srgb8: Vec<[u8; 3]>,
    pub natural_lab: Vec<[f64; 3]>,
    /// How sure each colour is (R ≥ 2 realisations; `None` for one).
    pub spread: Option<ColourSpread>,
}

/// The statistical uncertainty of the tile's colours.
///
/// Each realisation's colour is computed from that realisation's own spectra
/// (layer on paper, through the same spectral proxy); the reported colour is
/// that of the ensemble-mean spectra. Over `R` realisations:
/// - `lab_se`: standard error of L*, a*, b* — the sample standard deviation of
///   the realisations' values divided by √R;
/// - `de00_se`: standard error of the colour in ΔE00 — the root mean square
///   ΔE00 between each realisation's colour and the reported colour, with
///   R − 1 degrees of freedom, divided by √R. A difference between two
///   variants is resolved when it exceeds about twice the root sum of
///   squares of their `de00_se`.
#[derive(Debug, Clone)]
pub struct ColourSpread {
    /// CIELAB of every realisation, (realisation, viewing, 1 + illumination, 3).
    pub realisation_lab: Array4<f64>,
    /// (viewing, 1 + illumination, 3).
    pub lab_se: Array3<f64>,
    /// (viewing, 1 + illumination).
    pub de00_se: Array2<f64>,
}

impl ColourSpread {
    /// The spread of the realisations' colours `labs` around the reported `lab`.
    pub fn of(labs: &[Array3<f64>], lab: &Array3<f64>) -> ColourSpread {
        let r = labs.len();
        assert!(r >= 2, "a spread needs two realisations or more");
        let (nv, nc, _) = lab.dim();
        let lab_se = reduce(labs).se.expect("two or more realisations");
        let mut de00_se = Array2::zeros((nv, nc));
        for o in 0..nv {
            for c in 0..nc {
                let at = |a: &Array3<f64>| [a[[o, c, 0]], a[[o, c, 1]], a[[o, c, 2]]];
                let cell: Vec<[f64; 3]> = labs.iter().map(at).collect();
                de00_se[[o, c]] = de00_standard_error(&cell, at(lab));
            }
        }
        let mut realisation_lab = Array4::zeros((r, nv, nc, 3));
        for (k, l) in labs.iter().enumerate() {
            realisation_lab
                .index_axis_mut(ndarray::Axis(0), k)
                .assign(l);
        }
        ColourSpread {
            realisation_lab,
            lab_se,
            de00_se,
        }
    }
}

/// The spectra a tile is coloured from, at the solved wavelengths: the
/// diffuse BRDF of layer + substrate `(wavelength, illumination, viewing)`
/// in 1/sr and the sky strip `(wavelength, viewing)`.
pub type TileSpectra = (Array3<f64>, Array2<f64>);

/// The same on the spectral proxy's fine grid: its wavelengths, BRDF
/// square and sky strip ([`SpectralProxy::spectra`]).
pub type ProxySpectra<'a> = (&'a [f64], &'a Array3<f64>, &'a Array2<f64>);

/// The tile's colours from the ensemble's spectra `mean`, with their
/// spread over the realisations' own spectra when there are two or more.
pub fn tile_colours(
    wavelengths_nm: &[f64],
    mean: (&Array3<f64>, &Array2<f64>),
    realisations: &[TileSpectra],
    obs: &Observer,
    proxy: Option<ProxySpectra>,
) -> Result<Colours, AppearanceError> {
    let mut c = colours_of(wavelengths_nm, mean.0, mean.1, obs, proxy)?;
    if realisations.len() >= 2 {
        let labs = realisations
            .iter()
            .map(|(f, sky)| Ok(colours_of(wavelengths_nm, f, sky, obs, proxy)?.tile_lab))
            .collect::<Result<Vec<_>, AppearanceError>>()?;
        c.spread = Some(ColourSpread::of(&labs, &c.tile_lab));
    }
    Ok(c)
}

/// Tile colours from the BRDF of layer + substrate and the sky strip.
fn colours_of(
    wl: &[f64],
    total: &Array3<f64>,
    sky: &Array2<f64>,
    obs: &Observer,
    proxy: Option<ProxySpectra>,
) -> Result<Colours, AppearanceError> {
    let (_, ni, nv) = total.dim();
    // XYZ of a spectrum sampled at the solved wavelengths.
    let xyz = |values: Vec<f64>, proxy_fine: Option<Vec<f64>>| match (&proxy, proxy_fine) {
        (Some((fine_wl, _, _)), Some(pf)) => {
            let fine = through_proxy(wl, &values, fine_wl, &pf);
            colour::xyz_from_reflectance(obs, fine_wl, &fine)
        }
        _ => colour::xyz_from_reflectance(obs, wl, &values),
    };
    let mut tile = Array3::zeros((nv, 1 + ni, 3));
    let mut tile_lab = Array3::zeros((nv, 1 + ni, 3));
    let mut natural_srgb8 = Vec::with_capacity(nv);
    let mut natural_lab = Vec::with_capacity(nv);
    let white = obs.white_xyz();
    for o in 0..nv {
        let pf = proxy.map(|(_, _, s)| s.column(o).to_vec());
        let x = xyz(sky.column(o).to_vec(), pf)?;
        let rgb = colour::to_srgb8(obs, x);
        natural_srgb8.push(rgb);
        natural_lab.push(colour::xyz_to_lab(x, white));
        for (c, v) in colour::xyz_to_lab(x, white).into_iter().enumerate() {
            tile_lab[[o, 0, c]] = v;
        }
        tile.slice_mut(ndarray::s![o, 0, ..])
            .iter_mut()
            .zip(rgb)
            .for_each(|(t, c)| *t = c);
        for i in 0..ni {
            let spectrum: Vec<f64> = (0..wl.len())
                .map(|l| colour::lambertian_reflectance(total[[l, i, o]]))
                .collect();
            let pf = proxy.map(|(_, f, _)| {
                (0..f.dim().0)
                    .map(|l| colour::lambertian_reflectance(f[[l, i, o]]))
                    .collect()
            });
            let x = xyz(spectrum, pf)?;
            for (c, v) in colour::xyz_to_lab(x, white).into_iter().enumerate() {
                tile_lab[[o, 1 + i, c]] = v;
            }
            let rgb = colour::to_srgb8(obs, x);
            tile.slice_mut(ndarray::s![o, 1 + i, ..])
                .iter_mut()
                .zip(rgb)
                .for_each(|(t, c)| *t = c);
        }
    }
    Ok(Colours {
        tile_srgb8: tile,
        tile_lab,
        natural_srgb8,
        natural_lab,
        spread: None,
    })
}

/// Standard error in ΔE00 of the colour `center` reported for realisations
/// whose colours are `labs` (R ≥ 2): the root mean square ΔE00 of each to
/// `center` with R − 1 degrees of freedom, divided by √R.
pub(super) fn de00_standard_error(labs: &[[f64; 3]], center: [f64; 3]) -> f64 {
    let r = labs.len() as f64;
    let sq: f64 = labs
        .iter()
        .map(|l| colour::delta_e2000(*l, center).powi(2))
        .sum();
    (sq / (r - 1.0) / r).sqrt()
}

/// BRDF of layer + substrate `(wavelength, illumination, viewing)` and the
/// radiance factor under a white sky `(wavelength, viewing)` from the layer's
/// diffuse BRDF, R and T (per above angle), and with paper its albedo (per
/// wavelength), `R_dd↑`
/// and `T_d` (per wavelength). `illum_idx`/`view_idx` index the above angles.
pub(super) fn layer_on_paper(
    illum_idx: &[usize],
    view_idx: &[usize],
    brdf_diffuse: &Array3<f64>,
    reflectance: &Array2<f64>,
    transmittance: &Array2<f64>,
    paper: Option<(&Array1<f64>, &Array1<f64>, &Array1<f64>)>,
) -> (Array3<f64>, Array2<f64>) {
    let nl = brdf_diffuse.dim().0;
    let mut total = brdf_diffuse.clone();
    let mut sky = Array2::zeros((nl, view_idx.len()));
    for l in 0..nl {
        for (o, &vo) in view_idx.iter().enumerate() {
            sky[[l, o]] = reflectance[[l, vo]];
        }
        if let Some((albedo, rdd, td)) = paper {
            let albedo = albedo[l];
            let denom = 1.0 - albedo * rdd[l];
            for (i, &ai) in illum_idx.iter().enumerate() {
                for (o, &vo) in view_idx.iter().enumerate() {
                    total[[l, i, o]] +=
                        albedo * transmittance[[l, ai]] * transmittance[[l, vo]] / (PI * denom);
                }
            }
            for (o, &vo) in view_idx.iter().enumerate() {
                sky[[l, o]] += albedo * td[l] * transmittance[[l, vo]] / denom;
            }
        }
    }
    (total, sky)
}
