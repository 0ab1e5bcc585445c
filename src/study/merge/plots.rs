//! The study plots: L* and C*ab of every variant's measured colour (and,
//! over a hiding chart, Kubelka's S per unit pigment volume and the contrast
//! ratio, `plots/hiding-<axis>….png`) against each axis, one line per label of the series axis (the axis named
//! `pigment`, else the first), ± one standard error where the variants have
//! two or more realisations. The axes that are neither the x axis nor the
//! series axis split the plots: one picture per combination of their labels,
//! named `plots/<axis>[__<axis>-<label>…].png`.
//!
//! An axis whose every value sets one number at one key is drawn at those
//! numbers (`pvc`, a diameter); any other axis is categorical, its labels
//! equally spaced in axis order.

use super::Row;
use crate::config::GrainShape;
use crate::optics::colour::{lab_to_lch, lch_se};
use crate::output::render::plot::{self, Panel, PanelSize, Point, Scale, Series};
use crate::output::render::Canvas;
use crate::study::sweep::{sanitise, Axis, Study};
use crate::study::StudyError;

const PANEL: PanelSize = PanelSize { w: 380, h: 260 };

/// The axis the lines are drawn for.
pub(super) fn series_axis(study: &Study) -> Option<&Axis> {
    study
        .axes
        .iter()
        .find(|a| a.name == "pigment")
        .or(study.axes.first())
}

/// The numbers an axis sets, when every value sets exactly one number at
/// one and the same key: (key, value per label).
pub(super) fn numeric_axis(axis: &Axis) -> Option<(String, Vec<f64>)> {
    let key = &axis.values.first()?.set.first()?.key;
    let xs = axis
        .values
        .iter()
        .map(|v| match v.set.as_slice() {
            [o] if &o.key == key => o
                .value
                .as_float()
                .or(o.value.as_integer().map(|i| i as f64))
                .filter(|x| x.is_finite()),
            _ => None,
        })
        .collect::<Option<Vec<f64>>>()?;
    Some((key.clone(), xs))
}

/// A variant's value of a plotted quantity and its standard error.
type ValueOf = Box<dyn Fn(&Row) -> Option<(f64, Option<f64>)>>;

/// One plotted quantity of a variant.
struct Quantity {
    /// Panel title ("lightness L*").
    title: &'static str,
    /// The y axis's label, with units.
    axis_label: &'static str,
    of: ValueOf,
}

/// One kind of study plot: a picture per x axis and combination of the
/// other axes, one panel per quantity.
struct Figure {
    /// File name prefix ("" for the colour plots).
    prefix: &'static str,
    /// "L* and C*ab".
    what: &'static str,
    /// The note's first sentence(s).
    note: String,
    quantities: Vec<Quantity>,
}

/// The volume fraction of scattering grains in a variant's layer (its
/// species' volume fractions, dissolved ones left out).
fn grain_volume_fraction(r: &Row) -> f64 {
    r.v.scene
        .species
        .iter()
        .filter(|s| s.shape != GrainShape::Molecular)
        .map(|s| s.volume_fraction)
        .sum()
}

/// The figures drawn: the colour's L* and C*ab always; over a hiding chart
/// (`hiding`: its geometry) also Kubelka's S per unit pigment volume and the
/// contrast ratio.
fn figures(geometry: &str, conditions: &str, hiding: Option<&str>) -> Vec<Figure> {
    let colour = |k: usize| {
        move |r: &Row| {
            let m = r.measured.as_ref()?;
            let lch = lab_to_lch(m.record.lab);
            let se = m.record.lab_se.map(|se| lch_se(m.record.lab, se)[k]);
            Some((lch[k], se))
        }
    };
    let mut out = vec![Figure {
        prefix: "",
        what: "L* and C*ab",
        note: format!("Each point: one variant's {geometry} colour ({conditions}); "),
        quantities: vec![
            Quantity {
                title: "lightness L*",
                axis_label: "L*",
                of: Box::new(colour(0)),
            },
            Quantity {
                title: "chroma C*ab",
                axis_label: "C*ab",
                of: Box::new(colour(1)),
            },
        ],
    }];
    if let Some(h) = hiding {
        out.push(Figure {
            prefix: "hiding-",
            what: "scattering per pigment volume and contrast ratio",
            note: format!(
                "Over a hiding chart, {h} ({conditions}): Kubelka's S at Y per µm of layer \
                 divided by the grains' volume fraction (the scattering power of the pigment \
                 itself), and CR = Y(over black)/Y(over white); "
            ),
            quantities: vec![
                Quantity {
                    title: "S per pigment volume",
                    axis_label: "S / PVC (1/µm)",
                    of: Box::new(|r: &Row| {
                        let h = r.hiding.as_ref()?;
                        let f = grain_volume_fraction(r);
                        let (s, se) = h.at_y[1];
                        (f > 0.0).then(|| (s / f, se.map(|e| e / f)))
                    }),
                },
                Quantity {
                    title: "contrast ratio",
                    axis_label: "CR",
                    of: Box::new(|r: &Row| {
                        let h = r.hiding.as_ref()?;
                        Some((h.contrast_ratio, h.contrast_ratio_se))
                    }),
                },
            ],
        });
    }
    out
}

/// The (file name, title, picture) of every study plot.
pub(super) fn draw_plots(
    study: &Study,
    profile: &str,
    rows: &[Row],
) -> Result<Vec<(String, String, Canvas)>, StudyError> {
    let Some(series_ax) = series_axis(study) else {
        return Ok(vec![]);
    };
    let Some((geometry, conditions)) = rows.iter().find_map(|r| {
        r.measured
            .as_ref()
            .map(|m| (m.record.geometry.clone(), m.conditions.clone()))
    }) else {
        return Ok(vec![]);
    };
    let hiding_geometry = rows
        .iter()
        .find_map(|r| r.hiding.as_ref().map(|h| h.geometry.clone()));
    let multi = study.axes.len() > 1;
    let mut out = vec![];
    for x_ax in study
        .axes
        .iter()
        .filter(|a| !multi || a.name != series_ax.name)
    {
        // An axis the rows hold one label of (a subset) has nothing to plot
        // against.
        let mut labels: Vec<&str> = rows.iter().filter_map(|r| r.v.label(&x_ax.name)).collect();
        labels.sort_unstable();
        labels.dedup();
        if labels.len() < 2 {
            continue;
        }
        let series_ax = if multi { Some(series_ax) } else { None };
        let rest: Vec<&Axis> = study
            .axes
            .iter()
            .filter(|a| {
                a.name != x_ax.name && Some(a.name.as_str()) != series_ax.map(|s| s.name.as_str())
            })
            .collect();
        let mut combos: Vec<Vec<Option<&str>>> = vec![];
        for r in rows {
            let c: Vec<Option<&str>> = rest.iter().map(|a| r.v.label(&a.name)).collect();
            if !combos.contains(&c) {
                combos.push(c);
            }
        }
        let numeric = numeric_axis(x_ax);
        let x_of = |label: &str| -> Option<f64> {
            let k = x_ax.values.iter().position(|v| v.label == label)?;
            Some(numeric.as_ref().map_or(k as f64, |(_, xs)| xs[k]))
        };
        for combo in combos {
            let in_combo = |r: &&Row| {
                rest.iter()
                    .zip(&combo)
                    .all(|(a, l)| r.v.label(&a.name) == *l)
            };
            let lines: Vec<(String, Vec<&Row>)> = match series_ax {
                Some(s) => s
                    .values
                    .iter()
                    .map(|v| {
                        let rs = rows
                            .iter()
                            .filter(in_combo)
                            .filter(|r| r.v.label(&s.name) == Some(v.label.as_str()))
                            .collect();
                        (v.label.clone(), rs)
                    })
                    .collect(),
                None => vec![(String::new(), rows.iter().filter(in_combo).collect())],
            };
            let series_for = |value: &Quantity| -> Vec<Series> {
                lines
                    .iter()
                    .enumerate()
                    .map(|(i, (label, rs))| {
                        let mut points: Vec<Point> = rs
                            .iter()
                            .filter_map(|r| {
                                let x = x_of(r.v.label(&x_ax.name)?)?;
                                let (y, se) = (value.of)(r)?;
                                y.is_finite().then_some(Point {
                                    x,
                                    y,
                                    se: se.filter(|s| s.is_finite()),
                                })
                            })
                            .collect();
                        points.sort_by(|a, b| a.x.total_cmp(&b.x));
                        Series {
                            label: if label.is_empty() {
                                "variants".into()
                            } else {
                                label.clone()
                            },
                            colour: plot::palette(i),
                            dashed: false,
                            points,
                        }
                    })
                    .filter(|s| !s.points.is_empty())
                    .collect()
            };
            let numeric_scale = numeric.as_ref().and_then(|(key, xs)| {
                Some((
                    key,
                    Scale::covering_linear(xs.iter().map(|&x| (x, 0.0)), false)?.padded(0.05),
                ))
            });
            let (x, x_label, cats) = match numeric_scale {
                Some((key, x)) => (x, format!("{} ({key})", x_ax.name), None),
                None => (
                    Scale::categories(x_ax.values.len()),
                    x_ax.name.clone(),
                    Some(x_ax.values.iter().map(|v| v.label.clone()).collect()),
                ),
            };
            let fixed: Vec<String> = rest
                .iter()
                .zip(&combo)
                .map(|(a, l)| format!("{} = {}", a.name, l.unwrap_or("none")))
                .collect();
            let suffix: String = rest
                .iter()
                .zip(&combo)
                .map(|(a, l)| format!("__{}-{}", sanitise(&a.name), sanitise(l.unwrap_or("none"))))
                .collect();
            for figure in figures(&geometry, &conditions, hiding_geometry.as_deref()) {
                let mut panels = vec![];
                for q in &figure.quantities {
                    let series = series_for(q);
                    let Some(y) =
                        Scale::covering_linear(series.iter().flat_map(|s| s.values()), false)
                    else {
                        continue;
                    };
                    panels.push(Panel {
                        title: format!("{} against {}", q.title, x_ax.name),
                        x_label: x_label.clone(),
                        y_label: q.axis_label.to_string(),
                        x,
                        y,
                        x_categories: cats.clone(),
                        series,
                    });
                }
                if panels.is_empty() {
                    continue;
                }
                let title = format!(
                    "{} {profile}: {} against {}{}",
                    study.name,
                    figure.what,
                    x_ax.name,
                    if fixed.is_empty() {
                        String::new()
                    } else {
                        format!(" ({})", fixed.join(", "))
                    }
                );
                let with_se = panels[0]
                    .series
                    .iter()
                    .any(|s| s.points.iter().any(|p| p.se.is_some()));
                let notes = [format!(
                    "{}{}{}",
                    figure.note,
                    match series_ax {
                        Some(s) => format!("one line per {}. ", s.name),
                        None => String::new(),
                    },
                    if with_se {
                        "Bars: ± one standard error over the variant's realisations."
                    } else {
                        "One realisation per variant: no standard error."
                    }
                )];
                let legend: Vec<_> = panels[0]
                    .series
                    .iter()
                    .map(|s| (s.label.clone(), s.colour, s.dashed))
                    .collect();
                let canvas = plot::figure(&title, &notes, &panels, 2, PANEL, &legend)?;
                out.push((
                    format!("{}{}{suffix}.png", figure.prefix, sanitise(&x_ax.name)),
                    title,
                    canvas,
                ));
            }
        }
    }
    Ok(out)
}
