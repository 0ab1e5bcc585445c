//! `inksim plan`: what a study costs, per variant and per profile, by a
//! time model calibrated now on this machine.

use anyhow::Result;
use inksim::config::{Method, Precision};
use inksim::pipeline::memory::{self, human_bytes, MemoryLimit};
use inksim::study::plan::{self, human_time};
use inksim::study::run::{self as srun, Shard, State};
use inksim::study::sweep::{Expansion, Selection};
use std::path::Path;

/// `inksim plan STUDY`: the variants of a profile (or of a shard of it) with
/// their work, estimated time and memory, and totals per profile.
pub fn plan(
    config: &Path,
    profile: Option<&str>,
    shard: Option<&str>,
    only: &[Selection],
    nthreads: usize,
    limit: Option<MemoryLimit>,
) -> Result<()> {
    let study = super::load_study(config, None)?;
    let shard = match shard {
        Some(s) => Shard::parse(s).map_err(anyhow::Error::msg)?,
        None => Shard::ALL,
    };
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
         applications × one operator application × {}; applications per solve {:.0}: {}",
        plan::KRYLOV_OVERHEAD,
        cal.applications,
        cal.applications_source
    );
    for (g, t) in &cal.grids {
        println!(
            "  grid {}×{}×{}: setup {:.1} ms, one application {:.2} ms{}",
            g[0],
            g[1],
            g[2],
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
                memory::bytes_per_voxel(m, Precision::F64),
                memory::bytes_per_voxel(m, Precision::F32)
            )
        })
        .collect();
    println!(
        "memory model: {} + voxels × (bytes per voxel of the method, f64/f32 storage: {}; \
         docs/PERFORMANCE.md) + 8 B per voxel and species",
        human_bytes(memory::BASELINE_BYTES),
        rates.join(", ")
    );
    println!(
        "{:>4}  {:<34} {:>6} {:>14} {:>10} {:>5} {:>10} {:>9}  state",
        "#", "variant", "solves", "grid", "voxels", "real.", "est. time", "memory"
    );
    let (mut t_sum, mut s_sum, mut peak, mut n) = (0.0, 0usize, 0.0f64, 0usize);
    let mut over = 0usize;
    for v in chosen.variants.iter().filter(|v| shard.contains(v.index)) {
        let e = plan::estimate(&v.scene, &cal);
        let st = srun::state(v);
        println!(
            "{:>4}  {:<34} {:>6} {:>14} {:>10} {:>5} {:>10} {:>9}  {}",
            v.index,
            v.name,
            e.solves,
            format!("{}×{}×{}", e.grid[0], e.grid[1], e.grid[2]),
            e.voxels,
            e.realisations,
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
        "total ({} variants{}): {s_sum} solves, est. {} of compute on this machine; peak memory \
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
    if let Some(v) = chosen
        .variants
        .iter()
        .find(|v| !v.scene.is_molecular())
        .or(chosen.variants.first())
    {
        println!(
            "expected error of this profile's settings (variant {}):",
            v.name
        );
        for line in inksim::pipeline::accuracy::expected_error(&v.scene) {
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
            let de = exp
                .variants
                .iter()
                .find(|v| !v.scene.is_molecular())
                .or(exp.variants.first())
                .and_then(|v| inksim::pipeline::accuracy::expected_error(&v.scene).pop())
                .unwrap_or_default();
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
pub(super) fn selected(exp: &Expansion) -> String {
    if exp.selection.is_empty() {
        String::new()
    } else {
        format!(" (only {})", exp.selection_text())
    }
}
