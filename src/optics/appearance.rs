//! Optics — appearance: from the solves of every realisation to what a
//! person sees (METHOD §5–§6).
//!
//! Inputs are plain solve entries (orders, r00/t00, R, T, A) of `R`
//! realisations; outputs are ensemble means with their standard errors
//! (sample standard deviation / √R, present only when R ≥ 2):
//! - per wavelength and incidence from above: R, T, A and the specular split
//!   (coherent `|⟨r00⟩|²`, incoherent `⟨|r00|²⟩ − |⟨r00⟩|²`; the same for t00);
//! - the diffuse BRDF (and on request BTDF) table of every illumination angle
//!   ([`crate::optics::farfield::table`]: power-preserving, orders (0,0) excluded) and
//!   its values in the plane of incidence on the specular side
//!   (`φ_o = φ_i`: the diagonal θo = θi holds the specular direction);
//! - with paper: the layer's albedo for diffuse light from below `R_dd↑` and
//!   its diffuse transmittance `T_d` (Gauss–Legendre in cos θ over the solves
//!   from below; by reciprocity `2∫T_up μ dμ = 2∫T_down μ dμ`), the BRDF of
//!   layer + paper `f = f_layer + ρ T(θi) T(θo) / (π (1 − ρ R_dd↑))`, and
//!   the radiance factor under a uniform white sky
//!   `R(θo) + ρ T_d T(θo) / (1 − ρ R_dd↑)` (all reflected orders, specular
//!   included, by reciprocity);
//! - colours (CIE 1931 2°, D65, sRGB) of the tile: the sky strip and `π f`
//!   of the BRDF square, and CIELAB of the sky strip for comparing variants.
//!
//! Ensemble-mean quantities are combined (products of means), as METHOD §5
//! describes the layer by its mean scattering functions.

use crate::optics::colour::{self, ColourError, Observer};
use crate::optics::farfield::table::{self, AngularTable, Part, TableSpec};
use crate::optics::farfield::{Side, SolveEntry};
use crate::optics::substrate::Hemisphere;
use crate::solver::airy;
use ndarray::{Array, Array1, Array2, Array3, Array4, Dimension, Ix1, Ix2, Ix3, Ix4};
use num_complex::Complex64 as C64;
use std::f64::consts::PI;

/// What to assemble; built by the pipeline from the scene and its plan.
#[derive(Debug, Clone)]
pub struct AppearanceSpec {
    pub wavelengths_nm: Vec<f64>,
    /// Azimuth of the plane of incidence (deg).
    pub azimuth_deg: f64,
    /// Illumination polar angles: the BRDF square's columns.
    pub illumination_deg: Vec<f64>,
    /// Viewing polar angles: the tile's rows.
    pub viewing_deg: Vec<f64>,
    /// Polar angles solved from above (⊇ illumination, and ⊇ viewing when
    /// the paper term or the sky strip is wanted).
    pub above_deg: Vec<f64>,
    /// Quadrature for the solves from below (with paper), nodes = polar angles.
    pub below: Option<Hemisphere>,
    pub paper_albedo: Option<f64>,
    pub table: TableSpec,
    pub realisations: usize,
    pub btdf: bool,
    /// Compute the paper term, the sky strip and the colours (the tile).
    pub tile: bool,
    /// Spectral proxy for colour (with paper): see [`SpectralProxy`].
    pub proxy: Option<SpectralProxy>,
}

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
    fn spectra(
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
            let rt = |polar: f64| {
                let r = airy::slab(eps, self.thickness_nm, wl, polar);
                (r.r.norm_sqr(), r.t.norm_sqr())
            };
            let nodes: Vec<(f64, f64)> = h.polar_deg().into_iter().map(rt).collect();
            let rdd = h.diffuse(&nodes.iter().map(|x| x.0).collect::<Vec<_>>());
            let td = h.diffuse(&nodes.iter().map(|x| x.1).collect::<Vec<_>>());
            let denom = 1.0 - albedo * rdd;
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
fn through_proxy(wl: &[f64], values: &[f64], fine: &[f64], proxy_fine: &[f64]) -> Vec<f64> {
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

/// A mean over realisations and its standard error (None when R = 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate<D: Dimension> {
    pub mean: Array<f64, D>,
    pub se: Option<Array<f64, D>>,
}

/// The paper's part.
#[derive(Debug, Clone)]
pub struct PaperTerms {
    pub albedo: f64,
    /// Layer albedo for diffuse light from below, per wavelength.
    pub r_dd_up: Estimate<Ix1>,
    /// Layer diffuse transmittance, per wavelength.
    pub t_d: Estimate<Ix1>,
}

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
                let sq: f64 = labs
                    .iter()
                    .map(|l| colour::delta_e2000(at(l), at(lab)).powi(2))
                    .sum();
                de00_se[[o, c]] = (sq / (r as f64 - 1.0) / r as f64).sqrt();
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

/// Everything assembled; array axes are named in each field.
#[derive(Debug, Clone)]
pub struct Appearance {
    pub spec: AppearanceSpec,
    /// (wavelength, above angle).
    pub reflectance: Estimate<Ix2>,
    pub transmittance: Estimate<Ix2>,
    pub absorption: Estimate<Ix2>,
    pub specular_coherent: Array2<f64>,
    pub specular_incoherent: Array2<f64>,
    pub direct_coherent: Array2<f64>,
    pub direct_incoherent: Array2<f64>,
    /// Density tables `f cos θ`, (wavelength, illumination, j, i).
    pub brdf_table: Estimate<Ix4>,
    pub btdf_table: Option<Estimate<Ix4>>,
    /// Layer-only diffuse BRDF in the plane of incidence, (wavelength,
    /// illumination, viewing), 1/sr.
    pub brdf_diffuse: Estimate<Ix3>,
    /// Diffuse BTDF below the layer in the plane of incidence (forward side).
    pub btdf_diffuse: Option<Estimate<Ix3>>,
    pub paper: Option<PaperTerms>,
    /// Diffuse BRDF of layer + substrate, (wavelength, illumination, viewing).
    pub brdf_total: Option<Array3<f64>>,
    /// Radiance factor under a uniform white sky, (wavelength, viewing).
    pub natural: Option<Array2<f64>>,
    pub colours: Option<Colours>,
}

/// Why the appearance cannot be assembled.
#[derive(Debug, thiserror::Error)]
pub enum AppearanceError {
    #[error("appearance: no {side} solve for realisation {realisation} at {wavelength_nm} nm, polar {polar_deg}°")]
    Missing {
        side: Side,
        realisation: usize,
        wavelength_nm: f64,
        polar_deg: f64,
    },
    #[error("appearance: viewing angle {0}° was not solved from above")]
    NotSolved(f64),
    #[error("appearance: colour: {0}")]
    Colour(#[from] ColourError),
}

/// Mean and standard error along the first axis of `samples`.
fn reduce<D: Dimension>(samples: &[Array<f64, D>]) -> Estimate<D> {
    let n = samples.len() as f64;
    let mut mean = samples[0].clone();
    for s in &samples[1..] {
        mean += s;
    }
    mean /= n;
    let se = (samples.len() > 1).then(|| {
        let mut var: Array<f64, D> = Array::zeros(mean.raw_dim());
        for s in samples {
            var.zip_mut_with(&(s - &mean), |v, d| *v += d * d);
        }
        var.mapv(|v: f64| (v / (n - 1.0) / n).sqrt())
    });
    Estimate { mean, se }
}

fn index_of(list: &[f64], v: f64) -> Option<usize> {
    list.iter().position(|&x| x == v)
}

/// Assemble the appearance of a scene from its solves.
pub fn assemble(
    spec: &AppearanceSpec,
    entries: &[SolveEntry],
    observer: &Observer,
) -> Result<Appearance, AppearanceError> {
    let nl = spec.wavelengths_nm.len();
    let na = spec.above_deg.len();
    let ni = spec.illumination_deg.len();
    let nv = spec.viewing_deg.len();
    let nt = spec.table.n();
    let find = |side: Side, r: usize, wl: f64, polar: f64| {
        entries
            .iter()
            .find(|e| {
                e.side == side
                    && e.realisation == r
                    && e.wavelength_nm == wl
                    && e.incidence.polar_deg == polar
            })
            .ok_or(AppearanceError::Missing {
                side,
                realisation: r,
                wavelength_nm: wl,
                polar_deg: polar,
            })
    };
    let illum_idx: Vec<usize> = spec
        .illumination_deg
        .iter()
        .map(|&a| index_of(&spec.above_deg, a).ok_or(AppearanceError::NotSolved(a)))
        .collect::<Result<_, _>>()?;

    let rr = spec.realisations;
    let mut s_r = Vec::with_capacity(rr);
    let mut s_t = Vec::with_capacity(rr);
    let mut s_a = Vec::with_capacity(rr);
    let mut s_brdf_tab = Vec::with_capacity(rr);
    let mut s_btdf_tab = Vec::with_capacity(rr);
    let mut s_brdf = Vec::with_capacity(rr);
    let mut s_btdf = Vec::with_capacity(rr);
    let mut s_rdd = Vec::with_capacity(rr);
    let mut s_td = Vec::with_capacity(rr);
    let mut r00 = Array2::<C64>::zeros((nl, na));
    let mut r00_sq = Array2::<f64>::zeros((nl, na));
    let mut t00 = Array2::<C64>::zeros((nl, na));
    let mut t00_sq = Array2::<f64>::zeros((nl, na));
    let az = spec.azimuth_deg;
    for r in 0..rr {
        let mut tr = Array2::zeros((nl, na));
        let mut tt = Array2::zeros((nl, na));
        let mut ta = Array2::zeros((nl, na));
        let mut brdf_tab = Array4::zeros((nl, ni, nt, nt));
        let mut btdf_tab = Array4::zeros((nl, ni, nt, nt));
        let mut brdf = Array3::zeros((nl, ni, nv));
        let mut btdf = Array3::zeros((nl, ni, nv));
        let mut rdd = Array1::zeros(nl);
        let mut td = Array1::zeros(nl);
        for (l, &wl) in spec.wavelengths_nm.iter().enumerate() {
            for (a, &polar) in spec.above_deg.iter().enumerate() {
                let e = &find(Side::Above, r, wl, polar)?.efficiencies;
                tr[[l, a]] = e.total_reflectance;
                tt[[l, a]] = e.total_transmittance;
                ta[[l, a]] = e.absorption;
                r00[[l, a]] += e.r00;
                r00_sq[[l, a]] += e.r00.norm_sqr();
                t00[[l, a]] += e.t00;
                t00_sq[[l, a]] += e.t00.norm_sqr();
            }
            for (i, &polar) in spec.illumination_deg.iter().enumerate() {
                let e = &find(Side::Above, r, wl, polar)?.efficiencies;
                let put = |tab: &AngularTable, dst: &mut Array4<f64>, vals: &mut Array3<f64>| {
                    for (k, d) in tab.density.iter().enumerate() {
                        dst[[l, i, k / nt, k % nt]] = *d;
                    }
                    for (o, &view) in spec.viewing_deg.iter().enumerate() {
                        vals[[l, i, o]] = tab.value_at(view, az);
                    }
                };
                put(
                    &table::spread(e, Part::DiffuseReflection, spec.table),
                    &mut brdf_tab,
                    &mut brdf,
                );
                if spec.btdf {
                    put(
                        &table::spread(e, Part::DiffuseTransmission, spec.table),
                        &mut btdf_tab,
                        &mut btdf,
                    );
                }
            }
            if let (Some(h), Some(_)) = (&spec.below, spec.paper_albedo) {
                let mut ru = Vec::with_capacity(h.mu.len());
                let mut tu = Vec::with_capacity(h.mu.len());
                for polar in h.polar_deg() {
                    let e = &find(Side::Below, r, wl, polar)?.efficiencies;
                    ru.push(e.total_reflectance);
                    tu.push(e.total_transmittance);
                }
                rdd[l] = h.diffuse(&ru);
                td[l] = h.diffuse(&tu);
            }
        }
        s_r.push(tr);
        s_t.push(tt);
        s_a.push(ta);
        s_brdf_tab.push(brdf_tab);
        s_brdf.push(brdf);
        if spec.btdf {
            s_btdf_tab.push(btdf_tab);
            s_btdf.push(btdf);
        }
        s_rdd.push(rdd);
        s_td.push(td);
    }
    let n = rr as f64;
    let coherent = |sum: &Array2<C64>| sum.mapv(|z| (z / n).norm_sqr());
    let specular_coherent = coherent(&r00);
    let direct_coherent = coherent(&t00);
    let incoherent = |sq: &Array2<f64>, coh: &Array2<f64>| {
        let mut out = sq / n - coh;
        out.mapv_inplace(|v| v.max(0.0));
        out
    };
    let specular_incoherent = incoherent(&r00_sq, &specular_coherent);
    let direct_incoherent = incoherent(&t00_sq, &direct_coherent);
    let reflectance = reduce(&s_r);
    let transmittance = reduce(&s_t);
    let absorption = reduce(&s_a);
    let brdf_diffuse = reduce(&s_brdf);
    let paper = match (&spec.below, spec.paper_albedo) {
        (Some(_), Some(albedo)) => Some(PaperTerms {
            albedo,
            r_dd_up: reduce(&s_rdd),
            t_d: reduce(&s_td),
        }),
        _ => None,
    };

    let (mut brdf_total, mut natural, mut colours) = (None, None, None);
    if spec.tile {
        let view_idx: Vec<usize> = spec
            .viewing_deg
            .iter()
            .map(|&v| index_of(&spec.above_deg, v).ok_or(AppearanceError::NotSolved(v)))
            .collect::<Result<_, _>>()?;
        let on_paper = |brdf: &Array3<f64>, refl: &Array2<f64>, trans: &Array2<f64>, rdd, td| {
            let paper = paper
                .as_ref()
                .zip(rdd)
                .zip(td)
                .map(|((p, r), t)| (p.albedo, r, t));
            layer_on_paper(&illum_idx, &view_idx, brdf, refl, trans, paper)
        };
        let (total, sky) = on_paper(
            &brdf_diffuse.mean,
            &reflectance.mean,
            &transmittance.mean,
            paper.as_ref().map(|p| &p.r_dd_up.mean),
            paper.as_ref().map(|p| &p.t_d.mean),
        );
        let proxy = match (&spec.proxy, spec.paper_albedo, &spec.below) {
            (Some(p), Some(albedo), Some(h)) => Some((p, p.spectra(spec, albedo, h))),
            _ => None,
        };
        let proxy = proxy.as_ref().map(|(p, (f, sky))| (*p, f, sky));
        let mut c = colours_of(spec, &total, &sky, observer, proxy)?;
        if rr >= 2 {
            let mut labs = Vec::with_capacity(rr);
            for r in 0..rr {
                let (total_r, sky_r) = on_paper(
                    &s_brdf[r],
                    &s_r[r],
                    &s_t[r],
                    Some(&s_rdd[r]),
                    Some(&s_td[r]),
                );
                labs.push(colours_of(spec, &total_r, &sky_r, observer, proxy)?.tile_lab);
            }
            c.spread = Some(ColourSpread::of(&labs, &c.tile_lab));
        }
        colours = Some(c);
        brdf_total = Some(total);
        natural = Some(sky);
    }

    Ok(Appearance {
        spec: spec.clone(),
        reflectance,
        transmittance,
        absorption,
        specular_coherent,
        specular_incoherent,
        direct_coherent,
        direct_incoherent,
        brdf_table: reduce(&s_brdf_tab),
        btdf_table: spec.btdf.then(|| reduce(&s_btdf_tab)),
        brdf_diffuse,
        btdf_diffuse: spec.btdf.then(|| reduce(&s_btdf)),
        paper,
        brdf_total,
        natural,
        colours,
    })
}

/// Tile colours from the BRDF of layer + substrate and the sky strip.
/// `proxy` is the spectral proxy with its BRDF square and sky strip on its
/// fine grid ([`SpectralProxy::spectra`]).
fn colours_of(
    spec: &AppearanceSpec,
    total: &Array3<f64>,
    sky: &Array2<f64>,
    obs: &Observer,
    proxy: Option<(&SpectralProxy, &Array3<f64>, &Array2<f64>)>,
) -> Result<Colours, AppearanceError> {
    let wl = &spec.wavelengths_nm;
    let (nv, ni) = (spec.viewing_deg.len(), spec.illumination_deg.len());
    // XYZ of a spectrum sampled at the solved wavelengths.
    let xyz = |values: Vec<f64>, proxy_fine: Option<Vec<f64>>| match (&proxy, proxy_fine) {
        (Some((p, _, _)), Some(pf)) => {
            let fine = through_proxy(wl, &values, &p.wavelengths_nm, &pf);
            colour::xyz_from_reflectance(obs, &p.wavelengths_nm, &fine)
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

/// BRDF of layer + substrate `(wavelength, illumination, viewing)` and the
/// radiance factor under a white sky `(wavelength, viewing)` from the layer's
/// diffuse BRDF, R and T (per above angle), and with paper its albedo, `R_dd↑`
/// and `T_d` (per wavelength). `illum_idx`/`view_idx` index the above angles.
fn layer_on_paper(
    illum_idx: &[usize],
    view_idx: &[usize],
    brdf_diffuse: &Array3<f64>,
    reflectance: &Array2<f64>,
    transmittance: &Array2<f64>,
    paper: Option<(f64, &Array1<f64>, &Array1<f64>)>,
) -> (Array3<f64>, Array2<f64>) {
    let nl = brdf_diffuse.dim().0;
    let mut total = brdf_diffuse.clone();
    let mut sky = Array2::zeros((nl, view_idx.len()));
    for l in 0..nl {
        for (o, &vo) in view_idx.iter().enumerate() {
            sky[[l, o]] = reflectance[[l, vo]];
        }
        if let Some((albedo, rdd, td)) = paper {
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
