//! Light sources for judging metamerism, beside the scene illuminants
//! (D50, D65, A): CIE FL11 (F11, a tri-band fluorescent lamp of 4000 K, the
//! classic test of a metameric pair; CIE 015:2004 Table T.8.2) and CIE
//! LED-B3 (a phosphor-converted white LED of 4103 K; CIE 015:2018 Table
//! 11.4). Both are shipped as the CIE's 5 nm tables, 380–780 nm
//! (`data/cie/cie_fl11_5nm.csv`, `cie_led_b3_5nm.csv`, source in each file),
//! and put on the observer's 1 nm grid as D50 is: linear interpolation,
//! held at the end values beyond 380 and 780 nm.

use super::conditions::{bradford, cmf_csv, SRGB_WHITE};
use super::{parse_table, scale, Observer, StandardObserver};

/// CIE FL11 relative spectral power, 380–780 nm at 5 nm (source in the file).
const FL11_CSV: &str = include_str!("../../../data/cie/cie_fl11_5nm.csv");
/// CIE LED-B3 relative spectral power, 380–780 nm at 5 nm (source in the file).
const LED_B3_CSV: &str = include_str!("../../../data/cie/cie_led_b3_5nm.csv");

/// A test light source of the metamerism index.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TestSource {
    /// CIE illuminant A (incandescent, 2856 K).
    A,
    /// CIE FL11 (tri-band fluorescent, 4000 K).
    Fl11,
    /// CIE LED-B3 (phosphor-converted white LED, 4103 K).
    LedB3,
}

impl TestSource {
    /// The sources of the metamerism report, in order.
    pub const ALL: [TestSource; 3] = [TestSource::A, TestSource::Fl11, TestSource::LedB3];

    /// The CIE name, as written in result files.
    pub fn name(self) -> &'static str {
        match self {
            TestSource::A => "A",
            TestSource::Fl11 => "FL11",
            TestSource::LedB3 => "LED-B3",
        }
    }

    /// `observer` under this source (white `Y` = 100).
    pub fn observer(self, observer: StandardObserver) -> Observer {
        let table: Vec<(f64, f64)> = match self {
            TestSource::A => return Observer::standard(super::Illuminant::A, observer),
            TestSource::Fl11 => tabulated(FL11_CSV),
            TestSource::LedB3 => tabulated(LED_B3_CSV),
        };
        // The embedded tables are fixed data checked by tests/metamerism.rs.
        let cmf = parse_table(cmf_csv(observer), "colour-matching functions", 3)
            .expect("embedded CIE tables are valid");
        let mut obs = Observer::under_table(&cmf, &table).expect("embedded CIE tables are valid");
        obs.set_adaptation(bradford(scale(obs.white_xyz, 0.01), SRGB_WHITE));
        obs
    }
}

/// A shipped `wavelength_nm,S` table.
fn tabulated(csv: &str) -> Vec<(f64, f64)> {
    parse_table(csv, "illuminant", 1)
        .expect("embedded CIE tables are valid")
        .into_iter()
        .map(|(w, v)| (w, v[0]))
        .collect()
}
