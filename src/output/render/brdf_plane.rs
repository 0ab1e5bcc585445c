//! The in-plane BRDF plot of a run: the layer's diffuse BRDF (specular order
//! excluded, no substrate) in the plane of incidence against the signed
//! viewing angle θₒ (positive on the specular side, φₒ = φᵢ; negative
//! towards the source), one panel per wavelength, one line per angle of
//! incidence. Values are read from the run's angular table by bilinear
//! interpolation every degree; the band is the standard error interpolated
//! the same way, which by the triangle inequality bounds the standard error
//! of the interpolated value from above. Log scale when the values span
//! decades.

use super::plot::{self, Panel, PanelSize, Point, Scale, Series};
use super::spectra::{error_note, incidence_label};
use super::{fmt_num, RenderError};
use crate::optics::appearance::Appearance;
use crate::optics::farfield::table::AngularTable;

/// Wavelengths drawn at most (evenly chosen from the run's).
pub const MAX_WAVELENGTHS: usize = 6;
/// Largest |θₒ| drawn, degrees (the table's f = D / cos θ grows at grazing).
pub const MAX_VIEW_DEG: f64 = 85.0;
const PANEL: PanelSize = PanelSize { w: 300, h: 220 };

/// Indices of at most `max` of `n` items, evenly spread, first and last
/// included.
pub fn pick_evenly(n: usize, max: usize) -> Vec<usize> {
    if n <= max {
        return (0..n).collect();
    }
    let mut v: Vec<usize> = (0..max)
        .map(|k| ((k as f64 * (n - 1) as f64 / (max - 1).max(1) as f64).round()) as usize)
        .collect();
    v.dedup();
    v
}

/// The angular table of wavelength `l`, illumination `i` of a 4-D table
/// array (wavelength, illumination, j, i).
pub(super) fn table_of(
    a: &Appearance,
    tab: &ndarray::Array4<f64>,
    l: usize,
    i: usize,
) -> AngularTable {
    AngularTable {
        spec: a.spec.table,
        density: tab
            .slice(ndarray::s![l, i, .., ..])
            .iter()
            .copied()
            .collect(),
    }
}

/// `f(θₒ)` in the plane of incidence at azimuth `az`, θₒ signed.
fn in_plane(t: &AngularTable, theta_deg: f64, az: f64) -> f64 {
    let az = if theta_deg < 0.0 { az + 180.0 } else { az };
    t.value_at(theta_deg.abs(), az)
}

/// The in-plane BRDF plot of `a` as a PNG, titled with the run's `name`.
pub fn brdf_plane_png(a: &Appearance, name: &str) -> Result<Vec<u8>, RenderError> {
    let s = &a.spec;
    let az = s.azimuth_deg;
    let angles: Vec<f64> = (-(MAX_VIEW_DEG as i32)..=MAX_VIEW_DEG as i32)
        .map(f64::from)
        .collect();
    let picked = pick_evenly(s.wavelengths_nm.len(), MAX_WAVELENGTHS);
    let mut panels = vec![];
    for &l in &picked {
        let series: Vec<Series> = s
            .illumination_deg
            .iter()
            .enumerate()
            .map(|(i, &polar)| {
                let mean = table_of(a, &a.brdf_table.mean, l, i);
                let se = a.brdf_table.se.as_ref().map(|t| table_of(a, t, l, i));
                Series {
                    label: incidence_label(polar),
                    colour: plot::palette(i),
                    dashed: false,
                    points: angles
                        .iter()
                        .map(|&th| Point {
                            x: th,
                            y: in_plane(&mean, th, az),
                            se: se.as_ref().map(|t| in_plane(t, th, az)),
                        })
                        .collect(),
                }
            })
            .collect();
        panels.push(series);
    }
    // One y scale for all panels, so they compare.
    let y = Scale::covering(panels.iter().flatten().flat_map(|s| s.values()), true)
        .ok_or(RenderError::Empty)?;
    let panels: Vec<Panel> = picked
        .iter()
        .zip(panels)
        .map(|(&l, series)| Panel {
            title: format!("λ = {} nm", fmt_num(s.wavelengths_nm[l])),
            x_label: "viewing angle θₒ (°), + specular side".into(),
            y_label: "diffuse BRDF (sr⁻¹)".into(),
            x: Scale::linear(-90.0, 90.0),
            y,
            x_categories: None,
            series,
        })
        .collect();
    let legend = panels[0].legend();
    let shown = if picked.len() < s.wavelengths_nm.len() {
        format!(
            "{} of the run's {} wavelengths shown. ",
            picked.len(),
            s.wavelengths_nm.len()
        )
    } else {
        String::new()
    };
    let notes = [
        format!(
            "The layer alone (no paper), in the plane of incidence (φᵢ = {}°): \
             diffuse part only, the specular order excluded. {shown}{}",
            fmt_num(az),
            if y.log { "Log scale." } else { "" }
        ),
        error_note(s.realisations),
    ];
    let img = plot::figure(
        &format!("{name} — diffuse BRDF in the plane of incidence"),
        &notes,
        &panels,
        3,
        PANEL,
        &legend,
    )?;
    img.encode_png(&format!("{name}: in-plane BRDF"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn picks_spread_evenly_with_both_ends() {
        assert_eq!(pick_evenly(3, 6), vec![0, 1, 2]);
        assert_eq!(pick_evenly(16, 6), vec![0, 3, 6, 9, 12, 15]);
        assert_eq!(pick_evenly(7, 2), vec![0, 6]);
    }
}
