//! Optics — appearance: from the solves of every realisation to what a
//! person sees (METHOD §5–§6).
//!
//! Inputs are plain solve entries (orders, r00/t00, R, T, A) of `R`
//! realisations; outputs are ensemble means with their standard errors
//! (sample standard deviation / √R, present only when R ≥ 2):
//! - per wavelength and incidence from above: R, T, A and the specular split
//!   (coherent `|⟨r00⟩|²`, incoherent `⟨|r00|²⟩ − |⟨r00⟩|²`; the same for t00;
//!   for Maxwell `⟨|r00|²⟩` is the (0, 0) order's power in both outgoing
//!   polarisations and the coherent part averages `|⟨r00⟩|²` of the
//!   co-polarised amplitudes over s and p);
//! - the diffuse BRDF (and on request BTDF) table of every illumination angle
//!   ([`crate::optics::farfield::table`]: power-preserving, orders (0,0) excluded) and
//!   its values in the plane of incidence on the specular side
//!   (`φ_o = φ_i`: the diagonal θo = θi holds the specular direction);
//! - with a reflecting ground (paper, a white or measured ground, a chart's
//!   white half; its albedo may vary with wavelength): the layer's albedo for diffuse light from below `R_dd↑` and
//!   its diffuse transmittance `T_d` (Gauss–Legendre in cos θ over the solves
//!   from below; by reciprocity `2∫T_up μ dμ = 2∫T_down μ dμ`), the BRDF of
//!   layer + paper `f = f_layer + ρ T(θi) T(θo) / (π (1 − ρ R_dd↑))`, and
//!   the radiance factor under a uniform white sky
//!   `R(θo) + ρ T_d T(θo) / (1 − ρ R_dd↑)` (all reflected orders, specular
//!   included, by reciprocity);
//! - colours (CIE 1931 2°, D65, sRGB) of the tile: the sky strip and `π f`
//!   of the BRDF square, and CIELAB of the sky strip for comparing variants.
//!
//! - over a hiding chart: the measured colours over its black half too, and
//!   the contrast ratio and Kubelka's S and K ([`crate::optics::appearance::hiding`]).
//!
//! Ensemble-mean quantities are combined (products of means), as METHOD §5
//! describes the layer by its mean scattering functions.

mod colours;
pub mod hiding;
mod measure;
mod proxy;

pub use colours::{tile_colours, ColourSpread, Colours, ProxySpectra, TileSpectra};
pub use measure::{colour_of_samples, MeasuredColour, Measurement};
pub use proxy::{SpectralProxy, PROXY_RATIO_SPREAD};

use crate::config::GroundReflectance;
use crate::optics::baseline::BaselineColour;
use crate::optics::colour::{ColourError, Illuminant, Observer, StandardObserver};
use crate::optics::farfield::table::{self, AngularTable, Part, TableSpec};
use crate::optics::farfield::{Side, SolveEntry};
use crate::optics::substrate::Hemisphere;
use colours::layer_on_paper;
use hiding::Hiding;
use ndarray::{Array, Array1, Array2, Array3, Array4, Dimension, Ix1, Ix2, Ix3, Ix4};
use num_complex::Complex64 as C64;

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
    /// The Lambertian ground under the layer (paper, a white or measured
    /// ground, a chart's white half); None: nothing is added to the layer's
    /// own reflection (no substrate, a black ground).
    pub ground: Option<GroundReflectance>,
    /// A hiding chart: also measure over its black half (the layer alone)
    /// and derive the contrast ratio and Kubelka's S and K.
    pub chart: bool,
    /// The layer's thickness (Kubelka's X), nm.
    pub thickness_nm: f64,
    pub table: TableSpec,
    pub realisations: usize,
    /// Every realisation would be the same (a homogeneous layer or an
    /// explicit structure: nothing random): one is run, and the measured
    /// colours' standard errors are exactly 0 rather than unknown.
    pub deterministic: bool,
    pub btdf: bool,
    /// Compute the paper term, the sky strip and the colours (the tile).
    pub tile: bool,
    /// Spectral proxy for colour (with paper): see [`SpectralProxy`].
    pub proxy: Option<SpectralProxy>,
    /// Colorimetric measurement geometries to report (their angles must be
    /// in `above_deg`); see [`Measurement`].
    pub measurements: Vec<Measurement>,
}

/// A mean over realisations and its standard error (None when R = 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate<D: Dimension> {
    pub mean: Array<f64, D>,
    pub se: Option<Array<f64, D>>,
}

/// The paper's (the reflecting ground's) part.
#[derive(Debug, Clone)]
pub struct PaperTerms {
    /// The ground.
    pub ground: GroundReflectance,
    /// Its albedo at each solved wavelength.
    pub albedo: Array1<f64>,
    /// Layer albedo for diffuse light from below, per wavelength.
    pub r_dd_up: Estimate<Ix1>,
    /// Layer diffuse transmittance, per wavelength.
    pub t_d: Estimate<Ix1>,
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
    /// Density tables (power per projected solid angle; the BRDF is the
    /// density over the node coverage), (wavelength, illumination, j, i).
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
    /// Colour in each of `spec.measurements`, in that order (over a chart:
    /// over its white half).
    pub measured: Vec<MeasuredColour>,
    /// Over a chart: the colours over its black half, in the same order
    /// (empty otherwise).
    pub measured_black: Vec<MeasuredColour>,
    /// Over a chart: contrast ratio and Kubelka's S and K, one per geometry
    /// of `spec.measurements` (empty otherwise).
    pub hiding: Vec<Hiding>,
    /// The classical baselines' colours, model by model (in the scene's
    /// order) and in each measurement geometry, when the scene asked for
    /// them (filled in by the pipeline).
    pub baseline: Vec<BaselineColour>,
    /// The CIE illuminant and observer every colour was computed for (None
    /// for an observer built from custom tables).
    pub colour_conditions: Option<(Illuminant, StandardObserver)>,
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
pub fn reduce<D: Dimension>(samples: &[Array<f64, D>]) -> Estimate<D> {
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

/// The solve of realisation `r` at wavelength `wl` and polar angle `polar`
/// from `side`.
pub fn find_entry(
    entries: &[SolveEntry],
    side: Side,
    r: usize,
    wl: f64,
    polar: f64,
) -> Result<&SolveEntry, AppearanceError> {
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
    let find = |side, r, wl, polar| find_entry(entries, side, r, wl, polar);
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
    // Specular amplitudes summed per incident polarisation (one, or s and
    // p for Maxwell's natural light) and specular powers.
    let mut r00: Vec<Array2<C64>> = Vec::new();
    let mut r00_sq = Array2::<f64>::zeros((nl, na));
    let mut t00: Vec<Array2<C64>> = Vec::new();
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
                for (k, [r, t]) in e.specular_amplitudes().into_iter().enumerate() {
                    if r00.len() <= k {
                        r00.push(Array2::zeros((nl, na)));
                        t00.push(Array2::zeros((nl, na)));
                    }
                    r00[k][[l, a]] += r;
                    t00[k][[l, a]] += t;
                }
                let (rs, ts) = e.specular_power();
                r00_sq[[l, a]] += rs;
                t00_sq[[l, a]] += ts;
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
            if let (Some(h), Some(_)) = (&spec.below, &spec.ground) {
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
    // |⟨amplitude⟩|², averaged over the incident polarisations.
    let coherent = |sums: &[Array2<C64>]| {
        let mut out = Array2::<f64>::zeros((nl, na));
        for sum in sums {
            out += &sum.mapv(|z| (z / n).norm_sqr());
        }
        out / sums.len().max(1) as f64
    };
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
    let paper = match (&spec.below, &spec.ground) {
        (Some(_), Some(ground)) => Some(PaperTerms {
            ground: ground.clone(),
            albedo: spec.wavelengths_nm.iter().map(|&w| ground.at(w)).collect(),
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
                .map(|((p, r), t)| (&p.albedo, r, t));
            layer_on_paper(&illum_idx, &view_idx, brdf, refl, trans, paper)
        };
        let (total, sky) = on_paper(
            &brdf_diffuse.mean,
            &reflectance.mean,
            &transmittance.mean,
            paper.as_ref().map(|p| &p.r_dd_up.mean),
            paper.as_ref().map(|p| &p.t_d.mean),
        );
        let proxy = spec
            .proxy
            .as_ref()
            .map(|p| (p, p.spectra(spec, spec.ground.as_ref())));
        let proxy = proxy
            .as_ref()
            .map(|(p, (f, sky))| (&p.wavelengths_nm[..], f, sky));
        let per: Vec<TileSpectra> = if rr >= 2 {
            (0..rr)
                .map(|r| {
                    on_paper(
                        &s_brdf[r],
                        &s_r[r],
                        &s_t[r],
                        Some(&s_rdd[r]),
                        Some(&s_td[r]),
                    )
                })
                .collect()
        } else {
            Vec::new()
        };
        let c = tile_colours(&spec.wavelengths_nm, (&total, &sky), &per, observer, proxy)?;
        colours = Some(c);
        brdf_total = Some(total);
        natural = Some(sky);
    }

    let measured = measure::measure(
        spec,
        entries,
        paper.as_ref().map(|p| measure::PaperPerRealisation {
            ground: &p.ground,
            albedo: &p.albedo,
            r_dd_up: &s_rdd,
            t_d: &s_td,
        }),
        observer,
    )?;
    // The chart's black half: the same solves without the ground's term.
    let (measured_black, hiding) = match (&paper, spec.chart) {
        (Some(p), true) => {
            let black = measure::measure(spec, entries, None, observer)?;
            let hiding = hiding::of_chart(spec, &black, &measured, &p.ground, observer)?;
            (black, hiding)
        }
        _ => (Vec::new(), Vec::new()),
    };

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
        measured,
        measured_black,
        hiding,
        baseline: Vec::new(),
        colour_conditions: observer.conditions(),
    })
}
