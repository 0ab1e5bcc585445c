//! `inksim view`: the server refuses what it must (a non-loopback address
//! unless asked, a missing or corrupt result) with one line; and the page,
//! served by `inksim view` and drawn by headless Chromium in software WebGL2
//! (skipped, saying so, where no Chromium is installed), is not blank, draws
//! the object's centre under a 45° lamp in the result's 45°/0° colour as sRGB
//! shows it (within ΔE00 2, the pixel read back from the page and converted
//! here, independently of the page's own arithmetic), changes picture and
//! numbers when a control moves, and shows both results of an A/B.
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use inksim::config::{Illuminant, StandardObserver};
use inksim::optics::colour::{delta_e2000, gamut, srgb_decode, xyz_to_lab, Observer};
use inksim::output::h5::read_measured;
use inksim::output::render::Canvas;

mod common;
use common::browser::chromium;
use common::cli::inksim_in;
use common::json::Json;
use common::scene::{PigmentToml, SceneToml};

/// Held by each test that times the server or runs Chromium for its whole
/// run: the tests of this file run in parallel threads, and a software-
/// rendering browser beside a timed recompute would time the browser.
fn exclusive() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// A small result of `pigment` in `dir` (`dir/<pigment>.h5`).
fn result(dir: &Path, pigment: &str) -> PathBuf {
    let sub = dir.join(pigment);
    std::fs::create_dir_all(&sub).unwrap();
    SceneToml::tiny()
        .pigment(PigmentToml::builtin(pigment).pvc(0.15).diameter_nm(150.0))
        .output(dir, pigment)
        .run(&sub);
    dir.join(format!("{pigment}.h5"))
}

/// `inksim view` serving `files` on a free loopback port; the child and its
/// address (`http://127.0.0.1:PORT`).
struct Served(Child, String);

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Start `inksim view args…`: the child and the first line it printed.
fn start(args: &[&str]) -> (Child, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_inksim"))
        .arg("view")
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    if line.is_empty() {
        // It stopped: say why.
        let mut why = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut why).unwrap();
        line = why;
    }
    (child, line)
}

fn serve(files: &[&Path]) -> Served {
    let mut args: Vec<&str> = files.iter().map(|f| f.to_str().unwrap()).collect();
    args.extend(["--port", "0"]);
    let (child, line) = start(&args);
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://127.0.0.1:"))
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .trim_end_matches('/')
        .to_string();
    Served(child, url)
}

/// Headless Chromium with software WebGL2, in a fresh profile under `dir`.
fn browser(chrome: &Path, dir: &Path) -> Command {
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = RUNS.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let profile = dir.join(format!("chromium-profile-{n}"));
    let mut c = Command::new(chrome);
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--use-gl=angle",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--virtual-time-budget=15000",
    ])
    .arg(format!("--user-data-dir={}", profile.display()));
    c
}

/// The page at `url` (with a `probe` in its query): what it wrote into #probe.
fn probe(chrome: &Path, dir: &Path, url: &str) -> Json {
    let out = browser(chrome, dir)
        .arg("--dump-dom")
        .arg(url)
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&out.stdout);
    let start = dom
        .find("<pre id=\"probe\"")
        .and_then(|i| dom[i..].find('>').map(|j| i + j + 1))
        .unwrap_or_else(|| panic!("no probe in the page: {dom}"));
    let end = start + dom[start..].find("</pre>").unwrap();
    let text = dom[start..end]
        .replace("&quot;", "\"")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    let j = Json::parse(&text);
    if let Json::Obj(m) = &j {
        assert!(
            !m.iter().any(|(k, _)| k == "error"),
            "the page failed: {text}"
        );
    }
    j
}

/// The 45°/0° colour of a result file as sRGB shows it (gamut mapped) and
/// the observer it is under.
fn colour_45_0(path: &Path) -> ([f64; 3], Observer) {
    let (records, ill, deg) = read_measured(path).unwrap().unwrap();
    let obs = Observer::standard(
        Illuminant::from_name(&ill).unwrap(),
        StandardObserver::from_degrees(deg).unwrap(),
    );
    let m = records.iter().find(|m| m.geometry == "45/0").unwrap();
    (gamut::map_lab(&obs, m.lab).lab, obs)
}

/// CIELAB under `obs` of an 8-bit sRGB pixel: decoded, then XYZ by solving
/// `obs.linear_srgb(xyz) = rgb` (a linear map) by Gaussian elimination.
fn lab_of_pixel(obs: &Observer, rgb8: [u8; 3]) -> [f64; 3] {
    let rgb = rgb8.map(|v| srgb_decode(v as f64 / 255.0));
    let mut a = [[0.0; 4]; 3];
    for k in 0..3 {
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let col = obs.linear_srgb(e);
        for r in 0..3 {
            a[r][k] = col[r];
        }
    }
    for r in 0..3 {
        a[r][3] = rgb[r];
    }
    for c in 0..3 {
        let p = (c..3)
            .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
            .unwrap();
        a.swap(c, p);
        for r in 0..3 {
            if r != c {
                let (pivot, f) = (a[c], a[r][c] / a[c][c]);
                for (v, p) in a[r].iter_mut().zip(pivot).skip(c) {
                    *v -= f * p;
                }
            }
        }
    }
    let xyz = [a[0][3] / a[0][0], a[1][3] / a[1][1], a[2][3] / a[2][2]];
    xyz_to_lab(xyz, obs.white_xyz())
}

fn rgb(j: &Json) -> [u8; 3] {
    let v = j.arr("rgb");
    std::array::from_fn(|k| v[k].as_num() as u8)
}

#[test]
fn view_refuses_remote_binds_and_bad_results_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let one_line = |args: &[&str], want: &str| {
        let (ok, out, err) = inksim_in(d, args);
        assert!(!ok, "{args:?} succeeded: {out}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    };
    one_line(
        &["view", "missing.h5", "--port", "0"],
        "missing.h5: no such file",
    );
    std::fs::write(d.join("corrupt.h5"), b"not an HDF5 file at all").unwrap();
    one_line(&["view", "corrupt.h5", "--port", "0"], "corrupt.h5");
    let ok = result(d, "yellow");
    let ok = ok.to_str().unwrap();
    one_line(
        &["view", ok, "--host", "0.0.0.0", "--port", "0"],
        "refusing to listen on 0.0.0.0",
    );
    // Asked explicitly, it binds (and is stopped here).
    let (mut child, line) = start(&[ok, "--host", "0.0.0.0", "--port", "0", "--allow-remote"]);
    let _ = child.kill();
    let _ = child.wait();
    assert!(line.contains("http://0.0.0.0:"), "{line}");
    // Nothing was written beside the inputs.
    let mut names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with("yellow"))
        .collect();
    names.sort();
    assert_eq!(names, ["corrupt.h5"]);
}

#[test]
fn the_page_draws_the_results_colour_and_answers_its_controls() {
    let _only = exclusive();
    let Some(chrome) = chromium() else {
        eprintln!(
            "SKIPPED the_page_draws_the_results_colour_and_answers_its_controls: no chromium, \
             chromium-browser or google-chrome on PATH (scripts/setup.sh --with-browser \
             installs it)"
        );
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (a, b) = (result(d, "yellow"), result(d, "blue"));
    let served = serve(&[&a, &b]);
    let url = &served.1;

    // One object under the lamp at 45° from the view, no sky, 0 EV; then the
    // lamp's slider moved to 15°.
    let p = probe(
        &chrome,
        d,
        &format!("{url}/?probe=move&theta=45&phi=0&sky=0&ev=0"),
    );
    let (w, h) = (p.num("width"), p.num("height"));
    let object = p.num("object_pixels");
    assert!(object > 0.2 * w * h, "blank: {object} of {} pixels", w * h);
    let centre = rgb(&p.arr("centres")[0]);
    let (want, obs) = colour_45_0(&a);
    let de = delta_e2000(lab_of_pixel(&obs, centre), want);
    eprintln!("page centre {centre:?} vs the result's 45°/0° colour: ΔE00 {de:.2}");
    assert!(de < 2.0, "centre {centre:?}: ΔE00 {de:.2} to {want:?}");
    let after = p.get("after");
    let moved = rgb(&after.arr("centres")[0]);
    assert_ne!(moved, centre, "moving the lamp changed nothing");
    assert_ne!(after.str("readout"), p.str("readout"));
    assert!(p.str("readout").contains("ΔE00"), "{}", p.str("readout"));

    // A/B side by side and split: each half in its own result's colour.
    let (want_b, obs_b) = colour_45_0(&b);
    for mode in ["side", "split"] {
        let p = probe(
            &chrome,
            d,
            &format!("{url}/?probe=ab&a=0&b=1&mode={mode}&theta=45&phi=0&sky=0&ev=0"),
        );
        let c = p.arr("centres");
        assert_eq!(c.len(), 2, "{mode}");
        let (ca, cb) = (rgb(&c[0]), rgb(&c[1]));
        let da = delta_e2000(lab_of_pixel(&obs, ca), want);
        let db = delta_e2000(lab_of_pixel(&obs_b, cb), want_b);
        eprintln!("A/B {mode}: A {ca:?} ΔE00 {da:.2}, B {cb:?} ΔE00 {db:.2}");
        assert!(da < 2.0 && db < 2.0, "{mode}: {da:.2} {db:.2}");
        assert!(p.str("colours").contains("A: yellow") && p.str("colours").contains("B: blue"));
    }

    // A screenshot of the whole page, kept for looking at when asked.
    let shot = d.join("view.png");
    browser(&chrome, d)
        .args(["--window-size=1300,1100"])
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("{url}/?a=0&b=1"))
        .output()
        .unwrap();
    let img = Canvas::decode_png(&std::fs::read(&shot).unwrap()).unwrap();
    let distinct: std::collections::HashSet<&[u8]> = img.px.chunks_exact(3).collect();
    assert!(distinct.len() > 500, "{} colours", distinct.len());
    if let Some(keep) = std::env::var_os("INKSIM_VIEW_SHOT") {
        std::fs::copy(&shot, keep).unwrap();
    }
}

/// One GET of `url` (`http://127.0.0.1:PORT/path`) over a plain socket: the
/// body and the wall-clock time it took.
fn get(url: &str) -> (String, f64) {
    use std::io::{Read, Write};
    let rest = url.strip_prefix("http://").unwrap();
    let (host, path) = rest.split_at(rest.find('/').unwrap());
    let t0 = std::time::Instant::now();
    let mut s = std::net::TcpStream::connect(host).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.0\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut text = String::new();
    s.read_to_string(&mut text).unwrap();
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    let body = text
        .split_once("\r\n\r\n")
        .map(|x| x.1)
        .unwrap_or("")
        .to_string();
    (body, ms)
}

/// The live model's parameters, checked to include `keys`; then one GET of
/// `/api/live/compute?<query>` per query: the slowest (ms, server work and
/// HTTP round trip together) and each answer's `result`.
fn live_sweep(url: &str, keys: &[&str], queries: &[String]) -> (f64, Vec<Json>) {
    let (params, _) = get(&format!("{url}/api/live"));
    for k in keys {
        assert!(
            params.contains(&format!("\"key\":\"{k}\"")),
            "{k}: {params}"
        );
    }
    let mut worst: f64 = 0.0;
    let mut out = vec![];
    for q in queries {
        let (body, ms) = get(&format!("{url}/api/live/compute?{q}"));
        worst = worst.max(ms);
        out.push(Json::parse(&body).get("result").clone());
    }
    (worst, out)
}

/// The page's probe `kind` (e.g. `live`: its first live control moved) under
/// a 45° lamp, no sky, 0 EV; None, saying so, where no Chromium is
/// installed.
fn probe_live(d: &Path, url: &str, kind: &str) -> Option<Json> {
    let Some(chrome) = chromium() else {
        eprintln!("SKIPPED the page part: no chromium on PATH");
        return None;
    };
    Some(probe(
        &chrome,
        d,
        &format!("{url}/?probe={kind}&theta=45&phi=0&sky=0&ev=0"),
    ))
}

#[test]
fn a_scene_is_recomputed_live_within_200_ms_and_the_page_follows() {
    let _only = exclusive();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = SceneToml::grains().paper(0.9).output(d, "live").write(d);
    let served = serve(&[&scene]);
    let url = &served.1;
    // Every change a user makes is one request: time a sweep of the
    // pigment's volume fraction, server work and HTTP round trip together.
    let queries: Vec<String> = (1..=10)
        .map(|k| format!("pvc0={}&thickness_nm=2000", 0.03 * k as f64))
        .collect();
    let (worst, results) = live_sweep(url, &["pvc0", "thickness_nm"], &queries);
    let mut l_star = vec![];
    for r in &results {
        let c = &r.arr("colours")[0];
        assert_eq!(c.str("geometry"), "45/0");
        l_star.push(c.arr("lab")[0].as_num());
    }
    eprintln!("live recompute, 10 changes: slowest {worst:.1} ms (limit 200); L* {l_star:.1?}");
    assert!(worst < 200.0, "{worst} ms");
    // More pigment, darker: the model answers the control.
    assert!(l_star.windows(2).all(|w| w[1] < w[0]), "{l_star:?}");

    let Some(p) = probe_live(d, url, "live") else {
        return;
    };
    let after = p.get("after");
    let (before_px, after_px) = (rgb(&p.arr("centres")[0]), rgb(&after.arr("centres")[0]));
    assert_ne!(
        before_px, after_px,
        "the picture did not follow the control"
    );
    assert_ne!(
        p.str("colours"),
        after.str("colours"),
        "the numbers did not follow"
    );
    assert!(p.str("readout").contains("ΔE00"), "{}", p.str("readout"));
}

/// A stack (configs/overprint.toml: yellow over blue) recomputed live by
/// its layers' adding–doubling: every change within 200 ms, each layer's
/// controls offered; as the yellow's area coverage falls the colour turns
/// from green to the blue under it (b* falls); the page follows.
#[test]
fn a_stack_is_recomputed_live_layer_by_layer() {
    let _only = exclusive();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cfg = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/overprint.toml");
    let served = serve(&[&cfg]);
    let url = &served.1;
    let queries: Vec<String> = (0..=9)
        .map(|k| format!("layer1_coverage={}", 1.0 - 0.1 * k as f64))
        .collect();
    let keys = [
        "layer1_pvc0",
        "layer1_thickness_nm",
        "layer1_coverage",
        "layer2_pvc0",
        "layer2_thickness_nm",
        "paper_albedo",
    ];
    let (worst, results) = live_sweep(url, &keys, &queries);
    let b_star: Vec<f64> = results
        .iter()
        .map(|r| r.arr("colours")[0].arr("lab")[2].as_num())
        .collect();
    eprintln!("live stack, 10 changes: slowest {worst:.1} ms (limit 200); b* {b_star:.1?}");
    assert!(worst < 200.0, "{worst} ms");
    assert!(b_star.windows(2).all(|w| w[1] < w[0]), "{b_star:?}");
    assert!(results[0].str("model").contains("stack of 2 layers"));
    let Some(p) = probe_live(d, url, "live") else {
        return;
    };
    let after = p.get("after");
    assert_ne!(
        p.str("colours"),
        after.str("colours"),
        "the numbers did not follow"
    );
}

/// An effect paint (configs/metallic.toml) recomputed live: every change of
/// the flakes' spread within 200 ms (server and HTTP together), the
/// near-specular lightness falling as the spread widens; the page draws the
/// object's centre under a 45° lamp in the paint's 45as45 (45°/0°) colour
/// and follows its first control (the flakes' volume fraction).
#[test]
fn an_effect_paint_is_recomputed_live_within_200_ms_and_drawn_in_its_colour() {
    let _only = exclusive();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/metallic.toml");
    let served = serve(&[&config]);
    let url = &served.1;
    let queries: Vec<String> = (0..10)
        .map(|k| format!("layer1_spread_deg={}", 4.0 + 2.0 * k as f64))
        .collect();
    let (worst, results) = live_sweep(url, &["layer1_flakes", "layer1_spread_deg"], &queries);
    let mut near_specular = vec![];
    for r in &results {
        let colours = r.arr("colours");
        assert_eq!(colours[0].str("geometry"), "45as45");
        let c = colours
            .iter()
            .find(|c| c.str("geometry") == "45as-15")
            .unwrap();
        near_specular.push(c.arr("lab")[0].as_num());
    }
    eprintln!(
        "effect paint live, 10 changes: slowest {worst:.1} ms (limit 200); L*(45as-15) {near_specular:.1?}"
    );
    assert!(worst < 200.0, "{worst} ms");
    assert!(
        near_specular.windows(2).all(|w| w[1] < w[0]),
        "{near_specular:?}"
    );
    let (start, _) = get(&format!("{url}/api/live/compute"));
    let start = Json::parse(&start);
    let result = start.get("result");
    assert!(
        result.str("model").contains("ΔE00"),
        "{}",
        result.str("model")
    );
    let first = &result.arr("colours")[0];
    let mapped: Vec<f64> = first.arr("mapped_lab").iter().map(|v| v.as_num()).collect();
    let want = [mapped[0], mapped[1], mapped[2]];

    // The colour without the glints (a glint may sit on the centre).
    let Some(p) = probe_live(d, url, "live&glints=0") else {
        return;
    };
    let obs = Observer::standard(Illuminant::D65, StandardObserver::TenDegree);
    let centre = rgb(&p.arr("centres")[0]);
    let de = delta_e2000(lab_of_pixel(&obs, centre), want);
    eprintln!("effect paint: page centre {centre:?} vs its 45as45 colour {want:.1?}: ΔE00 {de:.2}");
    assert!(de < 2.0, "centre {centre:?}: ΔE00 {de:.2} to {want:?}");
    let after = p.get("after");
    assert_ne!(
        centre,
        rgb(&after.arr("centres")[0]),
        "the picture did not follow the control"
    );
    assert_ne!(
        p.str("colours"),
        after.str("colours"),
        "the numbers did not follow"
    );

    // The glints: there, as many near the centre as the sparkle model's
    // Poisson mean says (P(≥ 1) = 1 − e^(−N P) at a 45° lamp and a normal
    // view), and elsewhere when the lamp moves by 10°.
    let s = probe_live(d, url, "sparkle").unwrap();
    let g = s.get("sparkle");
    let (glints, moved, both) = (g.num("glints"), g.num("moved"), g.num("both"));
    let share = g.num("centre_glints") / g.num("centre_pixels");
    let want = 1.0 - (-g.num("model_mean_45")).exp();
    eprintln!(
        "glints: {glints} pixels ({moved} after the lamp moved 10°, {both} in both); near the \
         centre {share:.3} of the cells against the model's {want:.3}"
    );
    assert!(glints > 0.01 * s.num("object_pixels"), "{glints}");
    assert!((share / want - 1.0).abs() < 0.25, "{share} vs {want}");
    assert!(
        both < 0.5 * glints.min(moved),
        "{both} of {glints}, {moved}"
    );
}

/// A study's folder: the variants' axis labels come from its summary.h5,
/// and the page chooses A by its axis values (one select per axis).
#[test]
fn a_studys_variants_are_chosen_by_their_axis_values() {
    use hdf5::types::VarLenUnicode;
    let _only = exclusive();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let variants = d.join("variants");
    std::fs::create_dir_all(&variants).unwrap();
    let names = ["pigment-yellow", "pigment-blue"];
    for (name, pigment) in names.iter().zip(["yellow", "blue"]) {
        let r = result(d, pigment);
        std::fs::rename(&r, variants.join(format!("{name}.h5"))).unwrap();
    }
    // The summary's /name and /labels/<axis>, as the merge writes them
    // (docs/FORMAT.md).
    let text =
        |xs: &[&str]| -> Vec<VarLenUnicode> { xs.iter().map(|s| s.parse().unwrap()).collect() };
    {
        let f = inksim::output::h5::create(d.join("summary.h5")).unwrap();
        f.new_dataset_builder()
            .with_data(&text(&names))
            .create("name")
            .unwrap();
        let g = f.create_group("labels").unwrap();
        g.new_dataset_builder()
            .with_data(&text(&["yellow", "blue"]))
            .create("pigment")
            .unwrap();
    } // every handle closed: the server opens the file next

    let served = serve(&[d]);
    let url = &served.1;
    let (list, _) = get(&format!("{url}/api/results"));
    assert!(list.contains("[\"pigment\",\"blue\"]"), "{list}");
    let Some(p) = probe_live(d, url, "axes") else {
        return;
    };
    let a = p.get("axes");
    eprintln!("axes probe: {a:?}");
    assert_eq!(a.num("pickers"), 1.0);
    // A starts at the first file (pigment-blue); the probe picks the last
    // label of the axis, yellow.
    assert_eq!(a.str("a"), "pigment-yellow", "{a:?}");
    assert_eq!(a.str("note"), "");
}

/// An effect paint's result file is served as its paint, recomputed live
/// from the exact config the file holds.
#[test]
fn a_paint_result_is_recomputed_from_the_config_it_holds() {
    // Its run takes both cores for a second: not beside a timed recompute.
    let _only = exclusive();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/metallic.toml");
    let out = d.to_str().unwrap();
    let (ok, _, err) = inksim_in(d, &["run", config.to_str().unwrap(), "--output-dir", out]);
    assert!(ok, "{err}");
    let served = serve(&[&d.join("metallic.h5")]);
    let url = &served.1;
    let (queries, ran) = (vec!["layer1_flakes=0.03".to_string()], "metallic (live)");
    let (_, results) = live_sweep(url, &["layer1_flakes", "layer1_spread_deg"], &queries);
    assert_eq!(results[0].str("name"), ran);
    assert!(results[0].get("sparkle").num("flakes_per_cell") > 0.0);
}
