//! Error against cost, one curve per knob, from the tables of
//! docs/ACCURACY.md (what `examples/accuracy.rs` printed).
//!
//! `cargo run --release --example accuracy_plot [docs/ACCURACY.md] [docs]`
//!
//! For every `## … layer` section with knob tables, writes
//! `<out>/accuracy-<layer>.png`: x = CPU seconds of the run (log), y = the
//! tile's worst ΔE00 against the knob's reference (log; values below 0.01,
//! drawn on the floor line). Reference rows (error 0 by definition) are left
//! out; a knob's points are joined in table order.

use inksim::output::render::canvas::{text_width, Canvas, GLYPH_HEIGHT};
use std::collections::BTreeMap;
use std::path::PathBuf;

const W: usize = 980;
const H: usize = 620;
const LEFT: f64 = 90.0;
const RIGHT: f64 = 330.0;
const TOP: f64 = 50.0;
const BOTTOM: f64 = 60.0;
const FLOOR: f64 = 0.01;
const COLOURS: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// (section title, knob → [(cpu s, ΔE00 max)]) in document order.
type Sections = Vec<(String, BTreeMap<String, Vec<(f64, f64)>>)>;

fn parse(text: &str) -> Sections {
    let mut out: Sections = Vec::new();
    for line in text.lines() {
        if let Some(title) = line.strip_prefix("## ") {
            out.push((title.to_string(), BTreeMap::new()));
            continue;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | knob | value | wall | CPU | peak | ΔE max | ΔE mean | L2 | RTA | cost |
        // or the proxy table: | step | CPU | ΔE max | ΔE mean | cost | (linear) |
        let (knob, cpu, de) = match cells.len() {
            12 if !cells[2].contains("(ref)") => (label(cells[1]), cells[4], cells[6]),
            8 if cells[1].ends_with(" nm") => ("spectral step, proxy".into(), cells[2], cells[3]),
            _ => continue,
        };
        let (Ok(cpu), Ok(de)) = (cpu.parse::<f64>(), de.parse::<f64>()) else {
            continue;
        };
        if let Some((_, knobs)) = out.last_mut() {
            knobs.entry(knob).or_default().push((cpu, de));
        }
    }
    out.retain(|(_, k)| !k.is_empty());
    out
}

/// A short legend label: the key without its table, no remarks.
fn label(knob: &str) -> String {
    let k = knob.split(" (").next().unwrap_or(knob);
    let k = k.rsplit('.').next().unwrap_or(k);
    let k = match k {
        "spectral step, linear interpolation" => "spectral step, linear",
        "0" => "spheres per grain",
        "shape" => "spheres per grain",
        other => other,
    };
    k.chars().take(24).collect()
}

fn line(c: &mut Canvas, a: (f64, f64), b: (f64, f64), col: [u8; 3]) {
    let n = ((b.0 - a.0).hypot(b.1 - a.1) * 2.0).ceil().max(1.0) as usize;
    for k in 0..=n {
        let t = k as f64 / n as f64;
        c.disk(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1), 1.2, col);
    }
}

fn plot(title: &str, knobs: &BTreeMap<String, Vec<(f64, f64)>>) -> Canvas {
    let mut c = Canvas::new(W, H, [255, 255, 255]);
    let pts = knobs.values().flatten();
    let (mut x0, mut x1) = (f64::INFINITY, 0.0f64);
    let mut y1 = 1.0f64;
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y1 = y1.max(y);
    }
    let (lx0, lx1) = (x0.log10().floor(), x1.log10().ceil());
    let (ly0, ly1) = (FLOOR.log10(), y1.log10().ceil());
    let pw = W as f64 - LEFT - RIGHT;
    let ph = H as f64 - TOP - BOTTOM;
    let px = |x: f64| LEFT + (x.log10() - lx0) / (lx1 - lx0) * pw;
    let py = |y: f64| TOP + (ly1 - y.max(FLOOR).log10()) / (ly1 - ly0) * ph;
    let grey = [200, 200, 200];
    let black = [0, 0, 0];
    for d in lx0 as i32..=lx1 as i32 {
        let x = px(10f64.powi(d));
        line(&mut c, (x, TOP), (x, TOP + ph), grey);
        let s = format!("{}", 10f64.powi(d));
        c.text(
            (x as usize).saturating_sub(text_width(&s) / 2),
            (TOP + ph + 8.0) as usize,
            &s,
            black,
        );
    }
    for d in ly0 as i32..=ly1 as i32 {
        let y = py(10f64.powi(d));
        line(&mut c, (LEFT, y), (LEFT + pw, y), grey);
        let s = format!("{}", 10f64.powi(d));
        let s = if d == ly0 as i32 { format!("<{s}") } else { s };
        c.text(
            (LEFT as usize).saturating_sub(text_width(&s) + 8),
            (y as usize).saturating_sub(GLYPH_HEIGHT / 2),
            &s,
            black,
        );
    }
    let head = format!("{title}: TILE DE00 (MAX) VS CPU SECONDS");
    c.text(LEFT as usize, 15, &head, black);
    let xl = "CPU SECONDS PER RUN";
    c.text(
        (LEFT + pw / 2.0) as usize - text_width(xl) / 2,
        H - 24,
        xl,
        black,
    );
    for (k, (knob, pts)) in knobs.iter().enumerate() {
        let col = COLOURS[k % COLOURS.len()];
        let xy: Vec<(f64, f64)> = pts.iter().map(|&(x, y)| (px(x), py(y))).collect();
        for w in xy.windows(2) {
            line(&mut c, w[0], w[1], col);
        }
        for &(x, y) in &xy {
            c.disk(x, y, 5.0, col);
        }
        let ly = TOP as usize + k * (GLYPH_HEIGHT + 10);
        let lx = (LEFT + pw) as usize + 20;
        c.rect(lx as i64, ly as i64 + 2, 14, 10, col);
        c.text(lx + 22, ly, knob, black);
    }
    c
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let src = PathBuf::from(args.first().map_or("docs/ACCURACY.md", String::as_str));
    let out = PathBuf::from(args.get(1).map_or("docs", String::as_str));
    let text = std::fs::read_to_string(&src)?;
    for (title, knobs) in parse(&text) {
        let name = title
            .split_whitespace()
            .next()
            .unwrap_or("layer")
            .to_lowercase();
        let png = plot(&title, &knobs).encode_png(&title)?;
        let path = out.join(format!("accuracy-{name}.png"));
        std::fs::write(&path, png)?;
        println!("{}: {} knobs -> {}", title, knobs.len(), path.display());
    }
    Ok(())
}
