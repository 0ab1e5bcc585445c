//! The colorimetric conditions a scene asks for, by name: the CIE illuminant,
//! the CIE standard observer and the measurement geometries. Their tables and
//! formulas are the optics stage's (`optics::colour`, `optics::appearance`);
//! configs and result files name them as written here.

use std::fmt;

/// A CIE illuminant colour can be computed under.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Illuminant {
    /// CIE D50 (horizon daylight, 5003 K): print viewing and measurement, ISO 3664 / ISO 13655.
    D50,
    /// CIE D65 (average daylight, 6504 K): the sRGB display white.
    D65,
    /// CIE A (incandescent tungsten, 2856 K).
    A,
}

impl Illuminant {
    /// Every illuminant, in the order of the names.
    pub const ALL: [Illuminant; 3] = [Illuminant::D50, Illuminant::D65, Illuminant::A];

    /// The CIE name, as written in configs and result files.
    pub fn name(self) -> &'static str {
        match self {
            Illuminant::D50 => "D50",
            Illuminant::D65 => "D65",
            Illuminant::A => "A",
        }
    }

    /// The illuminant named `name` (case-insensitive), if there is one.
    pub fn from_name(name: &str) -> Option<Illuminant> {
        Self::ALL
            .into_iter()
            .find(|i| i.name().eq_ignore_ascii_case(name))
    }
}

impl fmt::Display for Illuminant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A CIE standard colorimetric observer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StandardObserver {
    /// CIE 1931 2° (fields up to 4°; the print standard).
    TwoDegree,
    /// CIE 1964 10° (large fields; paint and textile practice).
    TenDegree,
}

impl StandardObserver {
    /// Every observer.
    pub const ALL: [StandardObserver; 2] =
        [StandardObserver::TwoDegree, StandardObserver::TenDegree];

    /// The field of view in degrees (2 or 10), as written in configs and files.
    pub fn degrees(self) -> u32 {
        match self {
            StandardObserver::TwoDegree => 2,
            StandardObserver::TenDegree => 10,
        }
    }

    /// The observer of `degrees` (2 or 10), if there is one.
    pub fn from_degrees(degrees: u32) -> Option<StandardObserver> {
        Self::ALL.into_iter().find(|o| o.degrees() == degrees)
    }

    /// The CIE name.
    pub fn name(self) -> &'static str {
        match self {
            StandardObserver::TwoDegree => "CIE 1931 2°",
            StandardObserver::TenDegree => "CIE 1964 10°",
        }
    }
}

impl fmt::Display for StandardObserver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A colorimetric measurement geometry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Measurement {
    /// 45°/0°: directional light at 45°, viewed at 0° (ISO 13655, print).
    FortyFiveZero,
    /// d/8° with the specular component included (SCI).
    DiffuseEightSci,
    /// d/8° with the specular component excluded (SCE).
    DiffuseEightSce,
}

impl Measurement {
    /// Every geometry, in the order results list them.
    pub const ALL: [Measurement; 3] = [
        Measurement::FortyFiveZero,
        Measurement::DiffuseEightSci,
        Measurement::DiffuseEightSce,
    ];

    /// The name configs and result files use: `45/0`, `d/8 SCI`, `d/8 SCE`.
    pub fn name(self) -> &'static str {
        match self {
            Measurement::FortyFiveZero => "45/0",
            Measurement::DiffuseEightSci => "d/8 SCI",
            Measurement::DiffuseEightSce => "d/8 SCE",
        }
    }

    /// The geometry named `name` (case-insensitive), if there is one.
    pub fn from_name(name: &str) -> Option<Measurement> {
        Self::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(name))
    }

    /// A name usable as an HDF5 group or file name: `45_0`, `d8_sci`, `d8_sce`.
    pub fn slug(self) -> &'static str {
        match self {
            Measurement::FortyFiveZero => "45_0",
            Measurement::DiffuseEightSci => "d8_sci",
            Measurement::DiffuseEightSce => "d8_sce",
        }
    }

    /// Polar angles (deg) that must be solved from above.
    pub fn above_deg(self) -> &'static [f64] {
        match self {
            Measurement::FortyFiveZero => &[45.0, 0.0],
            Measurement::DiffuseEightSci | Measurement::DiffuseEightSce => &[8.0],
        }
    }
}

impl fmt::Display for Measurement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
