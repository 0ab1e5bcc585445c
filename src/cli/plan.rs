//! `inksim plan`: what a study costs, per variant and per profile, by a
//! time model calibrated now on this machine.

use super::ConfigFile;
use anyhow::Result;
use inksim::config::{Equation, Method, Precision};
use inksim::pipeline::accuracy;
use inksim::pipeline::memory::{self, human_bytes, MemoryLimit};
use inksim::study::plan::{self, human_time};
use inksim::study::run::{self as srun, Shard, State};
use inksim::study::sweep::{Expansion, Selection};

/// `inksim plan STUDY`: the variants of a profile (or of a shard of it) with
/// their work, estimated time and memory, and totals per profile.
pub fn plan(
    config: &ConfigFile,
    profile: Option<&str>,
    shard: Option<&str>,
    only: &[Selection],
    nthreads: usize,
    limit: Option<MemoryLimit>,
) -> Result<()> {
    let study = config.study(None)?;
    let shard = match shard {
        Some(s) => Shard::parse(s).map_err(anyhow::Error::msg)?,
        None => Shard::ALL,
    };
    if study.is_paint() {
        return super::effect_study::plan(&study, profile, shard, only, nthreads);
    }
    let chosen = study.expand(profile)?.select(&study, only)?;
    let mut others = vec![];
    for p in study.profiles.keys() {
        if Some(p) != chosen.profile.as_ref() {
            others.push(study.expand(Some(p))?.select(&study, only)?);
        }
    }
    println!(
        "study `{}` ({}): {} variants{}; profile {} → {}",
        study.name,
        study.path.display(),
        chosen.variants.len(),
        selected(&chosen),
        chosen.profile.as_deref().unwrap_or("(none)"),
        chosen.study_dir.display()
    );
    let cal = plan::calibrate(&chosen.variants, &chosen.variants);
    println!(
        "time model (calibrated now on this machine, {nthreads} thread(s)): per solve = setup + \
         applications × one operator application with BiCGStab's vector work, timed as the \
         difference of {} and {} iterations in the fields' precision (Maxwell: per polarisation \
         solved, \
         natural light one random-phase solve for an ensemble, else two); applications per solve {:.0} under a \
         flat top, {:.0} under relief or a conformal or rough surface ({:.0} on the binder \
         background; measured at a tolerance of 1e-4, 1e-6 on the binder, and scaled to each \
         scene's as 2.5 + log10(1/tolerance)); flat tops × {:.2}: {}; surfaces × {:.2}: {}",
        plan::CALIBRATION_ITERATIONS[0],
        plan::CALIBRATION_ITERATIONS[1],
        plan::MEAN_APPLICATIONS,
        plan::MEAN_APPLICATIONS_SURFACE,
        plan::BINDER_APPLICATIONS,
        cal.ratio,
        cal.applications_source,
        cal.surface_ratio,
        cal.surface_source
    );
    for ((pigments, flat), (ratio, source)) in &cal.pigments {
        let kind = if *flat { "flat tops" } else { "surfaces" };
        println!("  pigments {pigments}, {kind} × {ratio:.2}: {source}");
    }
    for (key, g) in &cal.groups {
        let pilot = match &g.pilot {
            Ok(p) => format!(
                "pilot solve of {} at {} nm, 0°: {:.0} applications per solve, {:.1}× the assumed \
                 {:.0} ({:.1} s CPU)",
                p.variant,
                p.wavelength_nm,
                p.applications,
                p.applications / g.assumed,
                g.assumed,
                p.cpu_s
            ),
            Err(e) => format!("pilot solve failed ({e}); the assumed rates"),
        };
        println!(
            "  high-contrast grains (|n/n_b − 1| > {}), {} variant(s), {key}: {pilot}; × {:.2}: {}",
            inksim::study::pilot::HIGH_CONTRAST,
            g.members,
            g.ratio,
            g.source
        );
    }
    for (key, t) in &cal.grids {
        let g = &key.grid;
        println!(
            "  grid {}×{}×{} ({}, {} fields{}): setup {:.1} ms, one application {:.2} ms{}",
            g[0],
            g[1],
            g[2],
            key.equation.name(),
            key.precision,
            if key.porous {
                ", air deep at both faces: each layered over a quarter of the cells"
            } else {
                ""
            },
            t.setup_s * 1e3,
            t.apply_s * 1e3,
            if t.timed != *g {
                format!(
                    " (timed on {}×{}×{}, scaled by N log N)",
                    t.timed[0], t.timed[1], t.timed[2]
                )
            } else {
                String::new()
            }
        );
    }
    let rates: Vec<String> = Method::ALL
        .into_iter()
        .filter(|m| m.in_records() && *m != Method::Airy)
        .map(|m| {
            format!(
                "{} {:.0}/{:.0}",
                m.name(),
                memory::bytes_per_voxel(m, Precision::F64, Equation::Helmholtz),
                memory::bytes_per_voxel(m, Precision::F32, Equation::Helmholtz)
            )
        })
        .collect();
    println!(
        "memory model: {} + voxels × (bytes per voxel of the method, f64/f32 storage: {}; \
         Maxwell {}× the method's own share; docs/PERFORMANCE.md) + 8 B per voxel and species",
        human_bytes(memory::BASELINE_BYTES),
        rates.join(", "),
        memory::MAXWELL_PER_SCALAR
    );
    println!(
        "{:>4}  {:<34} {:>6} {:>14} {:>10} {:>5} {:>6} {:>10} {:>9}  state",
        "#", "variant", "solves", "grid", "voxels", "real.", "ΔE00", "est. time", "memory"
    );
    let (mut t_sum, mut s_sum, mut peak, mut n) = (0.0, 0usize, 0.0f64, 0usize);
    let mut over = 0usize;
    for v in chosen.variants.iter().filter(|v| shard.contains(v.index)) {
        let e = plan::estimate(&v.scene, &cal);
        let st = srun::state(v);
        println!(
            "{:>4}  {:<34} {:>6} {:>14} {:>10} {:>5} {:>6.2} {:>10} {:>9}  {}",
            v.index,
            v.name,
            e.solves,
            format!("{}×{}×{}", e.grid[0], e.grid[1], e.grid[2]),
            e.voxels,
            e.realisations,
            accuracy::expected_de00(&v.scene),
            human_time(e.seconds),
            human_bytes(e.bytes),
            if memory::fits(&v.scene, limit).is_err() {
                over += 1;
                "OVER MEMORY LIMIT".to_string()
            } else if st == State::Done {
                "done".to_string()
            } else {
                st.reason()
            }
        );
        t_sum += e.seconds;
        s_sum += e.solves;
        peak = peak.max(e.bytes);
        n += 1;
    }
    let jobs = srun::default_jobs(nthreads, peak, n, limit);
    println!(
        "total ({} variants{}): {s_sum} solves, est. {} of compute on this machine (its CPU time \
         over {nthreads} threads: the wall time while the cores are kept busy); peak memory \
         {} per variant; default --jobs {jobs} ({} peak at once)",
        n,
        if shard.count > 1 {
            format!(", shard {}/{}", shard.index, shard.count)
        } else {
            String::new()
        },
        human_time(t_sum),
        human_bytes(peak),
        human_bytes(peak * jobs as f64)
    );
    if over > 0 {
        println!(
            "WARNING: {over} variant(s) exceed the memory limit {} and would stop before \
             solving (`inksim check` names the grid and what to change)",
            limit.map(|m| m.describe()).unwrap_or_default()
        );
    }
    println!("expected ΔE00 (column ΔE00): {}", de_summary(&chosen));
    if let Some(line) = unbounded_scalar(&chosen) {
        println!("{line}");
    }
    for target in [1.0, 0.5] {
        if let Some(line) = statistics_cost(&chosen, &cal, target, t_sum) {
            println!("{line}");
        }
    }
    if let Some(v) = chosen
        .variants
        .iter()
        .filter(|v| !v.scene.is_molecular())
        .max_by(|a, b| {
            accuracy::expected_de00(&a.scene).total_cmp(&accuracy::expected_de00(&b.scene))
        })
        .or(chosen.variants.first())
    {
        println!(
            "expected error of this profile's settings, the least certain variant ({}):",
            v.name
        );
        for line in accuracy::expected_error(&v.scene) {
            println!("  {line}");
        }
    }
    if !others.is_empty() {
        println!("other profiles (same model):");
        for exp in &others {
            let est = estimates(exp);
            let grids: std::collections::BTreeSet<String> = est
                .iter()
                .map(|e| format!("{}×{}×{}", e.grid[0], e.grid[1], e.grid[2]))
                .collect();
            let de = format!("expected ΔE00 {}", de_summary(exp));
            println!(
                "  {:<10} {} variants, {} solves, grid {}, est. {} total, peak memory {} per \
                 variant; {de}",
                exp.profile.as_deref().unwrap_or(""),
                exp.variants.len(),
                est.iter().map(|e| e.solves).sum::<usize>(),
                grids.into_iter().collect::<Vec<_>>().join(", "),
                human_time(est.iter().map(|e| e.seconds).sum()),
                human_bytes(est.iter().map(|e| e.bytes).fold(0.0, f64::max))
            );
        }
    }
    Ok(())
}

/// Time and memory estimates of every variant, calibrated now.
pub fn estimates(exp: &Expansion) -> Vec<plan::Estimate> {
    let cal = plan::calibrate(&exp.variants, &exp.variants);
    exp.variants
        .iter()
        .map(|v| plan::estimate(&v.scene, &cal))
        .collect()
}

/// " (only pigment=red, pvc=pvc30)" for a selection, else nothing.
pub(super) fn selected<S>(exp: &Expansion<S>) -> String {
    if exp.selection.is_empty() {
        String::new()
    } else {
        format!(" (only {})", exp.selection_text())
    }
}

/// "median 0.62, largest 1.85 (red_pvc15_s450); 12 of 22 above 1 ΔE00, 0
/// above 3" over a profile's variants.
fn de_summary(exp: &Expansion) -> String {
    let mut de: Vec<(f64, &str)> = exp
        .variants
        .iter()
        .map(|v| (accuracy::expected_de00(&v.scene), v.name.as_str()))
        .collect();
    if de.is_empty() {
        return String::new();
    }
    de.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (worst, name) = de[de.len() - 1];
    let above = |x: f64| de.iter().filter(|d| d.0 > x).count();
    format!(
        "median {:.2}, largest {worst:.2} ({name}); {} of {} variants above 1, {} above 3",
        de[de.len() / 2].0,
        above(1.0),
        de.len(),
        above(3.0)
    )
}

/// "WARNING: the scalar approximation is not bounded for N variant(s) …":
/// the variants whose grains scatter beyond the stand-ins' range in the
/// scalar equation (`model_error::grain_ratio`), or `None`.
fn unbounded_scalar(exp: &Expansion) -> Option<String> {
    use inksim::pipeline::model_error::{grain_ratio, GRAIN_RATIO_LIMIT};
    let beyond: Vec<(String, f64)> = exp
        .variants
        .iter()
        .filter_map(|v| grain_ratio(&v.scene).map(|g| (v.name.clone(), g.ratio)))
        .filter(|(_, r)| r.ln().abs() > GRAIN_RATIO_LIMIT.ln())
        .collect();
    let (name, ratio) = beyond
        .iter()
        .max_by(|a, b| a.1.ln().abs().total_cmp(&b.1.ln().abs()))?;
    Some(format!(
        "WARNING: the scalar approximation is not bounded for {} of {} variants: their grains \
         scatter beyond {GRAIN_RATIO_LIMIT}× what they scatter in Maxwell's equations (up to \
         {ratio:.1}× in transport, {name}); their ΔE00 column holds the stand-ins' term, a \
         lower bound (docs/ACCURACY.md, \"High-index grains\"); solver.equation = \
         \"maxwell\" removes it",
        beyond.len(),
        exp.variants.len()
    ))
}

/// What a realisation target of `target` would cost: "fragment s.e. ≤ 0.5
/// for every variant: `realisations = { target_de00 = 0.5, min = 2, max =
/// 24 }`, about 3.1× the realisations, est. 32 h of compute (10 h now)", or
/// `None` when every variant is there already.
fn statistics_cost(
    exp: &Expansion,
    cal: &plan::Calibration,
    target: f64,
    now_s: f64,
) -> Option<String> {
    let (mut seconds, mut now_r, mut then_r, mut most, mut short) = (0.0, 0, 0, 0, 0);
    for v in &exp.variants {
        let e = plan::estimate(&v.scene, cal);
        let r = accuracy::realisations_for(&v.scene, target).max(e.realisations);
        if r > e.realisations {
            short += 1;
        }
        seconds += e.seconds / e.realisations.max(1) as f64 * r as f64;
        now_r += e.realisations;
        then_r += r;
        most = most.max(r);
    }
    (short > 0).then(|| {
        format!(
            "fragment s.e. ≤ {target} for every variant ({short} need more realisations): \
             `realisations = {{ target_de00 = {target}, min = 2, max = {most} }}`, {:.1}× the \
             realisations, est. {} of compute ({} now; docs/ACCURACY.md, \"Statistics of the \
             fragment\")",
            then_r as f64 / now_r.max(1) as f64,
            human_time(seconds),
            human_time(now_s)
        )
    })
}
