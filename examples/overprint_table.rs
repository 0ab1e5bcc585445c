//! The overprint study's couplings side by side: for every ink and binder
//! of `configs/study-overprint.toml`, the colour of the stack combined by
//! adding (incoherent) and solved as one fragment (coherent) in each
//! measurement geometry, and their CIEDE2000 with its standard error
//! (linear propagation of both colours' L*, a*, b* standard errors).
//!
//!   inksim run configs/study-overprint.toml
//!   cargo run --release --example overprint_table -- runs/study-overprint
//!
//! Prints a Markdown table (docs/STACKS.md quotes it), then the classical
//! baseline beside them: adding–doubling of the same stack (each variant's
//! stored config) in 45°/0° and its ΔE00 to each coupling. Given two result
//! files instead (`-- a.h5 b.h5`), prints their ΔE00 per geometry.

use inksim::config::{parse_scene, Baseline, Measurement};
use inksim::optics::baseline::stack_baseline_colours;
use inksim::optics::colour::{delta_e2000, delta_e2000_se, Observer};
use inksim::output::h5::{read_measured, MeasuredRecord};
use std::path::Path;

fn measured(dir: &Path, name: &str) -> Vec<MeasuredRecord> {
    let path = dir.join("variants").join(format!("{name}.h5"));
    match read_measured(&path) {
        Ok(Some((m, _, _))) => m,
        other => panic!("{}: no measured colours ({other:?})", path.display()),
    }
}

/// ΔE00 of `a` to `b` and its standard error (the two colours taken as
/// independent: the couplings solve the same fragments, so this bounds it).
fn de00_with_se(a: &MeasuredRecord, b: &MeasuredRecord) -> (f64, f64) {
    let zero = [0.0; 3];
    (
        delta_e2000(a.lab, b.lab),
        delta_e2000_se(
            a.lab,
            a.lab_se.unwrap_or(zero),
            b.lab,
            b.lab_se.unwrap_or(zero),
        ),
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [a, b] = &args[..] {
        let read = |p: &str| match read_measured(Path::new(p)) {
            Ok(Some((m, _, _))) => m,
            other => panic!("{p}: no measured colours ({other:?})"),
        };
        let (a, b) = (read(a), read(b));
        for x in &a {
            if let Some(y) = b.iter().find(|y| y.geometry == x.geometry) {
                let (d, se) = de00_with_se(x, y);
                println!("{}: ΔE00 {d:.2} ± {se:.2}", x.geometry);
            }
        }
        return;
    }
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "runs/study-overprint".to_string());
    let dir = Path::new(&dir);
    println!(
        "| binder | inks | geometry | incoherent L*, a*, b* | coherent L*, a*, b* | ΔE00 ± s.e. |"
    );
    println!("|---|---|---|---|---|---|");
    for binder in ["n1.5", "n1.0"] {
        for inks in ["yellow", "blue", "yellow-over-blue", "blue-over-yellow"] {
            let apart = measured(dir, &format!("{inks}_incoherent_{binder}"));
            let whole = measured(dir, &format!("{inks}_coherent_{binder}"));
            for a in &apart {
                let Some(b) = whole.iter().find(|b| b.geometry == a.geometry) else {
                    continue;
                };
                let (d, se) = de00_with_se(a, b);
                let lab = |m: &MeasuredRecord| {
                    format!("{:.1}, {:.1}, {:.1}", m.lab[0], m.lab[1], m.lab[2])
                };
                println!(
                    "| {binder} | {inks} | {} | {} | {} | {d:.2} ± {se:.2} |",
                    a.geometry,
                    lab(a),
                    lab(b)
                );
            }
        }
    }
    println!();
    println!("| binder | inks | adding–doubling 45/0 L*, a*, b* | ΔE00 to incoherent | ΔE00 to coherent |");
    println!("|---|---|---|---|---|");
    for binder in ["n1.5", "n1.0"] {
        for inks in ["yellow", "blue", "yellow-over-blue", "blue-over-yellow"] {
            let name = format!("{inks}_coherent_{binder}");
            let path = dir.join("variants").join(format!("{name}.h5"));
            let text = inksim::output::h5::open(&path)
                .and_then(|f| {
                    f.dataset("config")?
                        .read_scalar::<hdf5::types::VarLenUnicode>()
                })
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .to_string();
            let scene = parse_scene(&path, &text).expect("the stored config");
            let st = scene.stack.as_ref().expect("a stack");
            let inputs: Vec<_> = (0..st.layers.len())
                .map(|i| {
                    let layer = scene.stack_layer(i).expect("a layer");
                    inksim::pipeline::baseline_input(&layer)
                        .expect("baseline input")
                        .expect("paper")
                })
                .collect();
            let obs = Observer::standard(scene.appearance.illuminant, scene.appearance.observer);
            let ad = stack_baseline_colours(
                Baseline::AddingDoubling,
                &inputs,
                (
                    &st.layers.iter().map(|l| l.coverage).collect::<Vec<_>>(),
                    st.yule_nielsen_n,
                ),
                &[Measurement::FortyFiveZero],
                &|_| None,
                &obs,
            )
            .expect("adding-doubling");
            let lab = ad[0].lab;
            let to = |coupling: &str| {
                let m = measured(dir, &format!("{inks}_{coupling}_{binder}"));
                m.iter()
                    .find(|c| c.geometry == "45/0")
                    .map_or(f64::NAN, |c| delta_e2000(lab, c.lab))
            };
            println!(
                "| {binder} | {inks} | {:.1}, {:.1}, {:.1} | {:.2} | {:.2} |",
                lab[0],
                lab[1],
                lab[2],
                to("incoherent"),
                to("coherent")
            );
        }
    }
}
