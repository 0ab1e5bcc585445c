//! Result files: exact round trip through HDF5, atomic replacement, and
//! errors that name the path and leave nothing behind.

use std::fs;
use std::path::Path;

use hdf5::types::VarLenUnicode;
use inksim::config::Incidence;
use inksim::config::Method;
use inksim::optics::farfield::{Efficiencies, Order, Side, SolveEntry};
use inksim::output::atomic::write_atomic;
use inksim::output::h5::{read_summary, write_result, GeometrySummary, IoError, ResultSet};
use inksim::solver::SolveRecord;
use num_complex::Complex64;

const CONFIG: &str = "# Grün ink — π ≈ 3.14159, 日本語, emoji 🎨\n\
[layer]\r\nthickness_nm = 1000.0\n\tname = \"a \\\"quoted\\\" value\"\n\n\nlast line without newline";

fn order(m: i32, n: i32, theta: f64, phi: f64, r: f64, t: f64) -> Order {
    Order {
        m,
        n,
        theta_deg: theta,
        phi_deg: phi,
        reflectance: r,
        transmittance: t,
    }
}

fn entries() -> Vec<SolveEntry> {
    vec![
        SolveEntry {
            wavelength_nm: 450.0,
            side: Side::Above,
            realisation: 0,
            layer: 0,
            incidence: Incidence {
                polar_deg: 0.0,
                azimuth_deg: 0.0,
            },
            efficiencies: Efficiencies {
                orders: vec![
                    order(0, 0, 0.0, 0.0, 0.041_234_567_890_123, 0.812_345_678_901_234),
                    order(1, 0, 26.743_561_2, 0.0, 1.0e-7, 3.3e-5),
                    order(-1, 2, 61.25, 116.565_051_177_077_99, 2.5e-300, 0.1 + 0.2),
                ],
                r00: Complex64::new(-0.123_456_789, 0.987_654_321),
                t00: Complex64::new(0.5, -1.0e-12),
                specular_p: None,
                total_reflectance: 0.041_234_667_890_123,
                total_transmittance: 0.812_378_978_901_234,
                absorption: 0.146_386_353_208_643,
                energy_balance: -2.220_446_049_250_313e-16,
            },
            record: SolveRecord {
                method: Method::Born,
                background: inksim::config::Background::Binder,
                iterations: 17,
                operator_applications: 18,
                residual: 3.2e-9,
                seconds: 0.25,
                note: "born: estimated contraction 0.61 — OK".into(),
            },
            polarised: Vec::new(),
            random_phase_deg: None,
        },
        SolveEntry {
            wavelength_nm: 632.8,
            side: Side::Above,
            realisation: 0,
            layer: 0,
            incidence: Incidence {
                polar_deg: 30.0,
                azimuth_deg: 45.0,
            },
            efficiencies: Efficiencies {
                orders: vec![],
                r00: Complex64::new(0.0, 0.0),
                t00: Complex64::new(1.0, 0.0),
                specular_p: None,
                total_reflectance: 0.0,
                total_transmittance: 1.0,
                absorption: 0.0,
                energy_balance: 0.0,
            },
            record: SolveRecord {
                method: Method::TimeMarching,
                background: inksim::config::Background::Binder,
                iterations: 1234,
                operator_applications: 2469,
                residual: 9.9e-7,
                seconds: 12.5,
                note: String::new(),
            },
            polarised: Vec::new(),
            random_phase_deg: None,
        },
        SolveEntry {
            wavelength_nm: 700.000_000_000_1,
            side: Side::Below,
            realisation: 1,
            layer: 0,
            incidence: Incidence {
                polar_deg: 60.0,
                azimuth_deg: -90.0,
            },
            efficiencies: Efficiencies {
                orders: vec![order(0, 0, 60.0, 180.0, 0.3, 0.6)],
                r00: Complex64::new(0.1, 0.2),
                t00: Complex64::new(0.3, 0.4),
                specular_p: None,
                total_reflectance: 0.3,
                total_transmittance: 0.6,
                absorption: 0.1,
                energy_balance: 1.0e-3,
            },
            record: SolveRecord {
                method: Method::TimeMarching,
                background: inksim::config::Background::Binder,
                iterations: 0,
                operator_applications: 0,
                residual: f64::MIN_POSITIVE,
                seconds: 0.0,
                note: "fallback after Born diverged\nsecond line".into(),
            },
            polarised: Vec::new(),
            random_phase_deg: None,
        },
    ]
}

struct Geo {
    names: Vec<String>,
    centers: Vec<[f64; 3]>,
    radii: Vec<f64>,
    pos: Vec<u32>,
    sop: Vec<u32>,
    target: Vec<f64>,
    achieved: Vec<f64>,
    raster: Vec<f64>,
}

fn geo() -> Geo {
    Geo {
        names: vec!["Yellow".into(), "Blau–Grün".into()],
        centers: vec![
            [10.5, 20.25, 30.125],
            [1.0e-3, 9999.999, 500.0],
            [0.0, 0.0, 0.1],
        ],
        radii: vec![50.0, 75.5, 100.000_000_1],
        pos: vec![0, 1, 1],
        sop: vec![1, 0],
        target: vec![0.15, 0.15],
        achieved: vec![0.149_9, 0.150_1],
        raster: vec![0.151, 0.148],
    }
}

fn set<'a>(g: &'a Geo, e: &'a [SolveEntry], hash: &'a str, png: Option<&'a [u8]>) -> ResultSet<'a> {
    ResultSet {
        version: "0.1.0",
        config_path: "configs/grün study.toml",
        config_text: CONFIG,
        plan: "geometry: rsa (spheres at PVC 0.2)\nsolves: 2 × auto",
        input_hash: hash,
        seed: u64::MAX - 7,
        created_unix_s: 1_700_000_000,
        geometry: GeometrySummary {
            species_names: &g.names,
            centers_nm: &g.centers,
            radii_nm: &g.radii,
            particle_of_sphere: &g.pos,
            species_of_particle: &g.sop,
            target_fraction: &g.target,
            achieved_fraction: &g.achieved,
            raster_fraction: &g.raster,
            min_gap_nm: Some(2.5),
            statistics: None,
        },
        grid: [64, 48, 20],
        size_nm: [2000.0, 1500.5, 1000.0],
        entries: e,
        picture_png: png,
        realisations: &[(7, 0.3)],
        realisation_stop: None,
        appearance: None,
        stack: None,
        tile_png: None,
    }
}

fn dir_names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[derive(hdf5::H5Type, Clone, Copy, Debug, PartialEq)]
#[repr(C)]
struct Row {
    wavelength_nm: f64,
    polar_deg: f64,
    azimuth_deg: f64,
    reflectance: f64,
    transmittance: f64,
    absorption: f64,
    energy_balance: f64,
    residual: f64,
    iterations: u64,
    side: u8,
    realisation: u64,
}

#[test]
fn summary_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nested/deeper/result.h5");
    let (g, e) = (geo(), entries());
    write_result(&path, &set(&g, &e, "abc123", None)).unwrap();
    assert_eq!(dir_names(path.parent().unwrap()), vec!["result.h5"]);

    let s = read_summary(&path).unwrap();
    assert_eq!(s.version, "0.1.0");
    assert_eq!(s.input_hash, "abc123");
    assert_eq!(
        s.plan,
        "geometry: rsa (spheres at PVC 0.2)\nsolves: 2 × auto"
    );
    assert_eq!(s.seed, u64::MAX - 7);
    assert_eq!(s.created_unix_s, 1_700_000_000);
    assert_eq!(s.entries.len(), e.len());
    for (got, want) in s.entries.iter().zip(&e) {
        let eff = &want.efficiencies;
        assert_eq!(got.wavelength_nm, want.wavelength_nm);
        assert_eq!(got.polar_deg, want.incidence.polar_deg);
        assert_eq!(got.azimuth_deg, want.incidence.azimuth_deg);
        assert_eq!(got.total_reflectance, eff.total_reflectance);
        assert_eq!(got.total_transmittance, eff.total_transmittance);
        assert_eq!(got.absorption, eff.absorption);
        assert_eq!(got.energy_balance, eff.energy_balance);
        assert_eq!(got.method, want.record.method);
        assert_eq!(got.iterations, want.record.iterations as u64);
        assert_eq!(got.residual, want.record.residual);
    }
}

#[test]
fn file_contents_round_trip_through_hdf5() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.h5");
    let (g, e) = (geo(), entries());
    let png: Vec<u8> = (0..=255u8).chain([0, 0, 137]).collect();
    write_result(&path, &set(&g, &e, "h", Some(&png))).unwrap();

    let f = inksim::output::h5::open(&path).unwrap();
    let config: VarLenUnicode = f.dataset("config").unwrap().read_scalar().unwrap();
    assert_eq!(config.as_bytes(), CONFIG.as_bytes());
    let cpath: VarLenUnicode = f.attr("config_path").unwrap().read_scalar().unwrap();
    assert_eq!(cpath.as_str(), "configs/grün study.toml");
    assert_eq!(
        f.attr("format_version")
            .unwrap()
            .read_scalar::<u32>()
            .unwrap(),
        1
    );
    assert_eq!(
        f.attr("grid").unwrap().read_raw::<u64>().unwrap(),
        vec![64, 48, 20]
    );
    assert_eq!(
        f.attr("size_nm").unwrap().read_raw::<f64>().unwrap(),
        vec![2000.0, 1500.5, 1000.0]
    );

    let geo = f.group("geometry").unwrap();
    let centers = geo.dataset("centers_nm").unwrap().read_2d::<f64>().unwrap();
    assert_eq!(centers.shape(), &[3, 3]);
    for (i, c) in g.centers.iter().enumerate() {
        for j in 0..3 {
            assert_eq!(centers[[i, j]], c[j]);
        }
    }
    assert_eq!(
        geo.dataset("radii_nm").unwrap().read_raw::<f64>().unwrap(),
        g.radii
    );
    assert_eq!(
        geo.dataset("particle_of_sphere")
            .unwrap()
            .read_raw::<u32>()
            .unwrap(),
        g.pos
    );
    assert_eq!(
        geo.dataset("species_of_particle")
            .unwrap()
            .read_raw::<u32>()
            .unwrap(),
        g.sop
    );
    let names: Vec<String> = geo
        .dataset("species_names")
        .unwrap()
        .read_raw::<VarLenUnicode>()
        .unwrap()
        .iter()
        .map(|s| s.as_str().to_owned())
        .collect();
    assert_eq!(names, g.names);
    assert_eq!(
        geo.dataset("raster_fraction")
            .unwrap()
            .read_raw::<f64>()
            .unwrap(),
        g.raster
    );
    assert_eq!(
        geo.attr("min_gap_nm")
            .unwrap()
            .read_scalar::<f64>()
            .unwrap(),
        2.5
    );

    let s0 = f.group("solves/0000").unwrap();
    assert_eq!(
        s0.attr("r00").unwrap().read_raw::<f64>().unwrap(),
        vec![-0.123_456_789, 0.987_654_321]
    );
    assert_eq!(
        s0.attr("t00").unwrap().read_raw::<f64>().unwrap(),
        vec![0.5, -1.0e-12]
    );
    let method: VarLenUnicode = s0.attr("method").unwrap().read_scalar().unwrap();
    assert_eq!(method.as_str(), "born");
    let note: VarLenUnicode = s0.attr("note").unwrap().read_scalar().unwrap();
    assert_eq!(note.as_str(), e[0].record.note);
    assert_eq!(
        s0.attr("operator_applications")
            .unwrap()
            .read_scalar::<u64>()
            .unwrap(),
        18
    );
    assert_eq!(
        s0.attr("seconds").unwrap().read_scalar::<f64>().unwrap(),
        0.25
    );
    let mn = s0.dataset("orders_mn").unwrap().read_2d::<i32>().unwrap();
    assert_eq!(mn.shape(), &[3, 2]);
    assert_eq!(mn.row(2).to_vec(), vec![-1, 2]);
    let orders = &e[0].efficiencies.orders;
    let col = |name: &str| s0.dataset(name).unwrap().read_raw::<f64>().unwrap();
    assert_eq!(
        col("orders_theta_deg"),
        orders.iter().map(|o| o.theta_deg).collect::<Vec<_>>()
    );
    assert_eq!(
        col("orders_phi_deg"),
        orders.iter().map(|o| o.phi_deg).collect::<Vec<_>>()
    );
    assert_eq!(
        col("orders_reflectance"),
        orders.iter().map(|o| o.reflectance).collect::<Vec<_>>()
    );
    assert_eq!(
        col("orders_transmittance"),
        orders.iter().map(|o| o.transmittance).collect::<Vec<_>>()
    );
    // A solve without orders still has (empty) order datasets.
    let s1 = f.group("solves/0001").unwrap();
    assert_eq!(s1.dataset("orders_mn").unwrap().shape(), vec![0, 2]);
    assert_eq!(s1.dataset("orders_reflectance").unwrap().size(), 0);
    assert_eq!(
        s1.attr("iterations").unwrap().read_scalar::<u64>().unwrap(),
        1234
    );

    let rows = f.dataset("summary").unwrap().read_raw::<Row>().unwrap();
    let want: Vec<Row> = e
        .iter()
        .map(|x| Row {
            wavelength_nm: x.wavelength_nm,
            polar_deg: x.incidence.polar_deg,
            azimuth_deg: x.incidence.azimuth_deg,
            reflectance: x.efficiencies.total_reflectance,
            transmittance: x.efficiencies.total_transmittance,
            absorption: x.efficiencies.absorption,
            energy_balance: x.efficiencies.energy_balance,
            residual: x.record.residual,
            iterations: x.record.iterations as u64,
            side: match x.side {
                inksim::optics::farfield::Side::Above => 0,
                inksim::optics::farfield::Side::Below => 1,
            },
            realisation: x.realisation as u64,
        })
        .collect();
    assert_eq!(rows, want);
    let summary = f.dataset("summary").unwrap();
    let units = |n: &str| {
        summary
            .attr(&format!("{n}_units"))
            .unwrap()
            .read_scalar::<hdf5::types::VarLenUnicode>()
            .unwrap()
            .to_string()
    };
    assert_eq!(units("wavelength_nm"), "nm");
    assert_eq!(units("polar_deg"), "deg");
    assert_eq!(units("side"), "1");

    assert_eq!(
        f.dataset("picture_png").unwrap().read_raw::<u8>().unwrap(),
        png
    );
}

#[test]
fn empty_geometry_and_no_picture_are_fine() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("empty.h5");
    let mut g = geo();
    g.names.clear();
    g.centers.clear();
    g.radii.clear();
    g.pos.clear();
    g.sop.clear();
    g.target.clear();
    g.achieved.clear();
    g.raster.clear();
    write_result(&path, &set(&g, &[], "x", None)).unwrap();
    let s = read_summary(&path).unwrap();
    assert!(s.entries.is_empty());
    let f = inksim::output::h5::open(&path).unwrap();
    assert_eq!(
        f.dataset("geometry/centers_nm").unwrap().shape(),
        vec![0, 3]
    );
    assert!(!f.link_exists("picture_png"));
}

#[test]
fn unwritable_folder_is_an_error_naming_the_path_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("not_a_folder");
    fs::write(&blocker, b"plain file").unwrap();
    let path = blocker.join("sub/result.h5");
    let (g, e) = (geo(), entries());
    let err = write_result(&path, &set(&g, &e, "h", None)).unwrap_err();
    assert!(matches!(err, IoError::Folder { .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains(&path.display().to_string()), "{msg}");
    assert_eq!(dir_names(dir.path()), vec!["not_a_folder"]);
    assert_eq!(fs::read(&blocker).unwrap(), b"plain file");

    let err = write_atomic(&blocker.join("x.png"), b"data").unwrap_err();
    assert!(err.to_string().contains("not_a_folder"), "{err}");
    assert_eq!(dir_names(dir.path()), vec!["not_a_folder"]);
}

#[test]
fn read_only_folder_is_reported() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let ro = dir.path().join("ro");
    fs::create_dir(&ro).unwrap();
    fs::set_permissions(&ro, fs::Permissions::from_mode(0o555)).unwrap();
    // root ignores permission bits; only check when they are enforced.
    let enforced = fs::write(ro.join("probe"), b"").is_err();
    if enforced {
        let (g, e) = (geo(), entries());
        let err = write_result(&ro.join("r.h5"), &set(&g, &e, "h", None)).unwrap_err();
        assert!(err.to_string().contains("r.h5.tmp"), "{err}");
        assert!(dir_names(&ro).is_empty());
    } else {
        let _ = fs::remove_file(ro.join("probe"));
    }
    fs::set_permissions(&ro, fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn existing_result_is_replaced_and_no_temp_file_remains() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.h5");
    let (g, e) = (geo(), entries());
    write_result(&path, &set(&g, &e, "first", None)).unwrap();
    write_result(&path, &set(&g, &e[..1], "second", None)).unwrap();
    let s = read_summary(&path).unwrap();
    assert_eq!(s.input_hash, "second");
    assert_eq!(s.entries.len(), 1);
    assert_eq!(dir_names(dir.path()), vec!["r.h5"]);

    // A stale temp file from a crashed run does not disturb the next write,
    // which writes its own; the stale one is left to the holder of the
    // output's lock (the run), which finds it.
    let stale = dir.path().join("r.h5.4242-1.tmp");
    fs::write(&stale, b"garbage").unwrap();
    write_result(&path, &set(&g, &e, "third", None)).unwrap();
    assert_eq!(read_summary(&path).unwrap().input_hash, "third");
    assert_eq!(dir_names(dir.path()), vec!["r.h5", "r.h5.4242-1.tmp"]);
    assert_eq!(
        inksim::output::atomic::stale_temporaries(&path),
        vec![stale]
    );
}

#[test]
fn rejected_input_leaves_the_old_result_intact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.h5");
    let (mut g, e) = (geo(), entries());
    write_result(&path, &set(&g, &e, "good", None)).unwrap();
    let before = fs::read(&path).unwrap();

    g.radii.pop();
    let err = write_result(&path, &set(&g, &e, "bad", None)).unwrap_err();
    assert!(matches!(err, IoError::Invalid { .. }), "{err:?}");
    assert!(err.to_string().contains("radii_nm 2"), "{err}");

    let g = geo();
    let mut bad = set(&g, &e, "bad", None);
    bad.config_text = "a = 1\0";
    let err = write_result(&path, &bad).unwrap_err();
    assert!(err.to_string().contains("NUL"), "{err}");

    assert_eq!(fs::read(&path).unwrap(), before);
    assert_eq!(read_summary(&path).unwrap().input_hash, "good");
    assert_eq!(dir_names(dir.path()), vec!["r.h5"]);
}

#[test]
fn write_atomic_round_trips_and_replaces() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("pic/x.png");
    write_atomic(&path, b"first version, longer").unwrap();
    write_atomic(&path, b"second").unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"second");
    assert_eq!(dir_names(path.parent().unwrap()), vec!["x.png"]);
    write_atomic(&path, b"").unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"");
}

#[test]
fn reading_bad_files_names_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.h5");
    let err = read_summary(&missing).unwrap_err();
    assert!(err.to_string().contains("missing.h5"), "{err}");

    let junk = dir.path().join("junk.h5");
    fs::write(&junk, b"this is not HDF5").unwrap();
    let err = read_summary(&junk).unwrap_err();
    assert!(err.to_string().contains("junk.h5"), "{err}");

    // A valid HDF5 file that is not a result file.
    let other = dir.path().join("other.h5");
    inksim::output::h5::create(&other).unwrap().close().unwrap();
    let err = read_summary(&other).unwrap_err();
    assert!(err.to_string().contains("other.h5"), "{err}");
}

#[test]
fn write_into_a_directory_path_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("is_dir.h5");
    fs::create_dir(&target).unwrap();
    let (g, e) = (geo(), entries());
    let err = write_result(&target, &set(&g, &e, "h", None)).unwrap_err();
    assert!(err.to_string().contains("is_dir.h5"), "{err}");
    assert_eq!(dir_names(dir.path()), vec!["is_dir.h5"]);
}
