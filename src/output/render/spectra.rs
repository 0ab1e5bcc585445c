//! The spectra plot of a run: total reflectance R, transmittance T and
//! absorption A of the layer (no substrate) against wavelength, one line per
//! angle of incidence from above, ± one standard error over the
//! realisations.

use super::plot::{self, Panel, PanelSize, Point, Scale, Series};
use super::{fmt_num, RenderError};
use crate::optics::appearance::{Appearance, Estimate};
use ndarray::Ix2;

/// Size of one panel's data area, pixels.
const PANEL: PanelSize = PanelSize { w: 330, h: 250 };

/// The note under a run plot's title: realisations and what the bars are.
pub(super) fn error_note(realisations: usize) -> String {
    if realisations >= 2 {
        format!(
            "{}; bars and bands: ± one standard error",
            realisations_note(realisations)
        )
    } else {
        realisations_note(realisations)
    }
}

/// How many realisations the means are over.
pub(super) fn realisations_note(realisations: usize) -> String {
    if realisations >= 2 {
        format!("Means over {realisations} realisations")
    } else {
        "One realisation: no standard error".into()
    }
}

/// `θᵢ = 30°` for a legend.
pub(super) fn incidence_label(polar_deg: f64) -> String {
    format!("θᵢ = {}°", fmt_num(polar_deg))
}

/// The spectra plot of `a` as a PNG, titled with the run's `name`.
pub fn spectra_png(a: &Appearance, name: &str) -> Result<Vec<u8>, RenderError> {
    let s = &a.spec;
    let series_of = |e: &Estimate<Ix2>| -> Vec<Series> {
        s.above_deg
            .iter()
            .enumerate()
            .map(|(k, &polar)| Series {
                label: incidence_label(polar),
                colour: plot::palette(k),
                dashed: false,
                points: s
                    .wavelengths_nm
                    .iter()
                    .enumerate()
                    .map(|(l, &wl)| Point {
                        x: wl,
                        y: e.mean[[l, k]],
                        se: e.se.as_ref().map(|se| se[[l, k]]),
                    })
                    .collect(),
            })
            .collect()
    };
    let x = Scale::covering_linear(s.wavelengths_nm.iter().map(|&w| (w, 0.0)), false)
        .ok_or(RenderError::Empty)?
        .padded(0.04);
    let mut panels = vec![];
    for (e, what) in [
        (&a.reflectance, "reflectance R"),
        (&a.transmittance, "transmittance T"),
        (&a.absorption, "absorption A"),
    ] {
        let series = series_of(e);
        let y = Scale::covering_linear(series.iter().flat_map(|s| s.values()), true)
            .ok_or(RenderError::Empty)?;
        panels.push(Panel {
            title: what.to_string(),
            x_label: "wavelength λ (nm)".into(),
            y_label: format!("{} (fraction of incident power)", &what[what.len() - 1..]),
            x,
            y,
            x_categories: None,
            series,
        });
    }
    let legend = panels[0].legend();
    let notes = [
        "The layer alone (no paper), light from above: R and T sum every \
         propagating order, the specular one included; A = 1 − R − T per solve."
            .to_string(),
        error_note(s.realisations),
    ];
    let img = plot::figure(
        &format!("{name} — reflectance, transmittance and absorption against wavelength"),
        &notes,
        &panels,
        3,
        PANEL,
        &legend,
    )?;
    img.encode_png(&format!("{name}: spectra"))
}
