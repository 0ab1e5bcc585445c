//! The overprint study's couplings side by side: for every ink and binder
//! of `configs/study-overprint.toml`, the colour of the stack combined by
//! adding (incoherent) and solved as one fragment (coherent) in each
//! measurement geometry, and their CIEDE2000 with its standard error
//! (linear propagation of both colours' L*, a*, b* standard errors).
//!
//!   inksim run configs/study-overprint.toml
//!   cargo run --release --example overprint_table -- runs/study-overprint
//!
//! Prints a Markdown table (docs/STACKS.md quotes it). Given two result
//! files instead (`-- a.h5 b.h5`), prints their ΔE00 per geometry.

use inksim::optics::colour::{delta_e2000, delta_e2000_se};
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
}
