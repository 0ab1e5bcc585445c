//! The verification's part of the match's files: `/verify/` in the HDF5
//! file (per verified recipe, one row per step: the composition, the wave
//! solution's colour with its standard error, its ΔE00 to the target, the
//! fast model's colour of the same recipe, and the step's result file) and
//! `<name>-verify.csv` (one row per step). Layout in docs/MATCH.md.

use std::fmt::Write as _;

use hdf5::Group;
use ndarray::{Array2, Array3};

use crate::output::h5::{about, dim, vlu, write_scalar_attr, write_str_attr, Scales};

use super::config::MatchSpec;
use super::report::MatchReport;
use super::verify::Verification;

const STEP: &str = "step";
const GEOMETRY: &str = "geometry";
const PIGMENT: &str = "pigment";

/// `/verify`: its fidelity, then one group per verified recipe.
pub(crate) fn write_h5(sc: &mut Scales, f: &Group, r: &MatchReport) -> hdf5::Result<()> {
    let (Some(fidelity), false) = (&r.fidelity, r.verified.is_empty()) else {
        return Ok(());
    };
    let g = f.create_group("verify")?;
    write_str_attr(&g, "fidelity", fidelity)?;
    write_str_attr(
        &g,
        "method",
        "each recipe solved by the wave pipeline at the base scene's fidelity, then corrected \
         by one Gauss-Newton step of the fast model's Jacobian against the wave colour per step",
    )?;
    for v in &r.verified {
        write_one(sc, &g.create_group(&format!("{:03}", v.rank))?, v)?;
    }
    Ok(())
}

fn write_one(sc: &mut Scales, g: &Group, v: &Verification) -> hdf5::Result<()> {
    write_scalar_attr(g, "rank", v.rank as u64)?;
    write_scalar_attr(g, "verified", u8::from(v.verified))?;
    write_str_attr(g, "outcome", &v.outcome)?;
    let n = v.steps.len();
    let ng = v.steps[0].lab.len();
    let np = v.steps[0].fractions.len();
    sc.forget(STEP);
    let steps: Vec<u64> = (0..n as u64).collect();
    sc.coordinate(
        g,
        "step",
        &steps,
        about(
            "1",
            "0: the fast model's recipe; k: after k correction steps; step",
            &[STEP],
        ),
    )?;
    let pvc = Array2::from_shape_fn((n, np), |(s, p)| v.steps[s].fractions[p]);
    sc.write(
        g,
        "pvc",
        pvc.view(),
        about(
            "1",
            "volume fraction of each palette pigment at each step; step × pigment",
            &[STEP, PIGMENT],
        ),
    )?;
    let thick: Vec<f64> = v.steps.iter().map(|s| s.thickness_nm).collect();
    sc.write(
        g,
        "thickness_nm",
        &thick[..],
        about("nm", "layer thickness at each step; step", &[STEP]),
    )?;
    let lab3 = |get: &dyn Fn(usize, usize) -> [f64; 3]| {
        Array3::from_shape_fn((n, ng, 3), |(s, k, c)| get(s, k)[c])
    };
    let lab = lab3(&|s, k| v.steps[s].lab[k]);
    sc.write(g, "lab", lab.view(), about("1", "the wave solution's CIELAB in each target geometry (mean over the realisations); step × geometry × lab", &[STEP, GEOMETRY, dim::LAB]))?;
    let se = lab3(&|s, k| v.steps[s].lab_se[k].unwrap_or([f64::NAN; 3]));
    sc.write(g, "lab_se", se.view(), about("1", "standard error of the wave solution's L*, a*, b* over the realisations (NaN for one realisation); step × geometry × lab", &[STEP, GEOMETRY, dim::LAB]))?;
    let fast = lab3(&|s, k| v.steps[s].fast_lab[k]);
    sc.write(
        g,
        "lab_fast",
        fast.view(),
        about(
            "1",
            "the fast model's CIELAB of the same recipe; step × geometry × lab",
            &[STEP, GEOMETRY, dim::LAB],
        ),
    )?;
    let de = Array2::from_shape_fn((n, ng), |(s, k)| v.steps[s].de00[k]);
    sc.write(
        g,
        "de00",
        de.view(),
        about(
            "1",
            "CIEDE2000 of the wave solution to the target; step × geometry",
            &[STEP, GEOMETRY],
        ),
    )?;
    let de_se = Array2::from_shape_fn((n, ng), |(s, k)| v.steps[s].de00_se[k].unwrap_or(f64::NAN));
    sc.write(g, "de00_se", de_se.view(), about("1", "standard error of the wave solution's colour in ΔE00 (NaN for one realisation); step × geometry", &[STEP, GEOMETRY]))?;
    let err = Array2::from_shape_fn((n, ng), |(s, k)| v.steps[s].model_error()[k]);
    sc.write(g, "de00_fast_vs_wave", err.view(), about("1", "CIEDE2000 between the fast model's and the wave solution's colour of the same recipe: the fast model's error there; step × geometry", &[STEP, GEOMETRY]))?;
    let secs: Vec<f64> = v.steps.iter().map(|s| s.seconds).collect();
    sc.write(
        g,
        "seconds",
        &secs[..],
        about("s", "wall time of each step's wave run; step", &[STEP]),
    )?;
    let files: Vec<_> = v
        .steps
        .iter()
        .map(|s| vlu(&s.result.display().to_string()))
        .collect::<hdf5::Result<_>>()?;
    sc.write(
        g,
        "result_file",
        &files[..],
        about(
            "",
            "each step's wave result file (its exact scene inside); step",
            &[STEP],
        ),
    )?;
    Ok(())
}

/// CSV text of the verification: one row per recipe and step.
pub fn csv(spec: &MatchSpec, r: &MatchReport) -> String {
    let mut s = String::new();
    let geoms: Vec<&str> = r.target_lab.iter().map(|(m, _)| m.name()).collect();
    s.push_str("rank,step,verified,thickness_nm");
    for p in &spec.palette {
        let _ = write!(s, ",pvc {}", p.name);
    }
    for g in &geoms {
        let _ = write!(
            s,
            ",de00 {g},de00_se {g},L* {g},a* {g},b* {g},L*_se {g},a*_se {g},b*_se {g},\
             L*_fast {g},a*_fast {g},b*_fast {g},de00_fast_vs_wave {g}"
        );
    }
    s.push_str(",seconds,result_file\n");
    for v in &r.verified {
        for (k, st) in v.steps.iter().enumerate() {
            let last = k + 1 == v.steps.len();
            let _ = write!(
                s,
                "{},{k},{},{:.1}",
                v.rank,
                if last {
                    u8::from(v.verified).to_string()
                } else {
                    String::new()
                },
                st.thickness_nm
            );
            for f in &st.fractions {
                let _ = write!(s, ",{f:.6}");
            }
            let err = st.model_error();
            for (g, e) in err.iter().enumerate() {
                let opt = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x:.4}"));
                let se = st.lab_se[g];
                let (l, f) = (st.lab[g], st.fast_lab[g]);
                let _ = write!(
                    s,
                    ",{:.4},{},{:.3},{:.3},{:.3},{},{},{},{:.3},{:.3},{:.3},{:.4}",
                    st.de00[g],
                    opt(st.de00_se[g]),
                    l[0],
                    l[1],
                    l[2],
                    opt(se.map(|e| e[0])),
                    opt(se.map(|e| e[1])),
                    opt(se.map(|e| e[2])),
                    f[0],
                    f[1],
                    f[2],
                    e
                );
            }
            let _ = writeln!(s, ",{:.2},{}", st.seconds, st.result.display());
        }
    }
    s
}
