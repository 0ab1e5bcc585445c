//! The material library, `material = { library = "rutile" }`: optical
//! constants from published measurements.
//!
//! The tables in `data/materials/` are converted from the refractiveindex.info
//! database (public domain, CC0 1.0) by `scripts/make_materials.py`, never
//! edited by hand (`data/materials/SOURCE.md` names the database commit), and
//! embedded in the binary. Each states its provenance in `# key: value` header
//! comments, read into [`TableInfo`]: the material, the database page
//! (shelf/book/page), the reference, the wavelength range it covers (checked
//! against its rows), the licence and the source file.
//!
//! A uniaxial crystal (`rutile`, `hematite`, `cds`, `calcite`) is one name
//! with an ordinary and an extraordinary table; the scalar wave equation sees
//! their orientation average ([`Material::uniaxial`]), and
//! [`Material::epsilon_axes_at`] keeps both.
//!
//! Metals fit the table limits ([`MAX_INDEX`](super::MAX_INDEX)) in the
//! visible: aluminium's k is at most 9.9 in its table (310–1033 nm, Rakić
//! 1995; 8.5 at 775 nm), so the limit is not raised for library metals
//! (`aluminium_fits_the_index_limit_in_the_visible` below checks it).

use super::{Material, MaterialError, MaterialSource};

/// The tables of one library material.
#[derive(Debug, Clone, Copy)]
pub enum Tables {
    /// One table (an isotropic material, a film or a powder).
    Isotropic(&'static str),
    /// A uniaxial crystal: ordinary and extraordinary ray.
    Uniaxial {
        ordinary: &'static str,
        extraordinary: &'static str,
    },
}

/// One library material: its name in scenes and its embedded tables.
#[derive(Debug, Clone, Copy)]
pub struct LibraryEntry {
    pub name: &'static str,
    pub tables: Tables,
}

macro_rules! table {
    ($file:literal) => {
        include_str!(concat!("../../../data/materials/", $file))
    };
}

/// Every library material, in the order `inksim materials` lists them.
pub const LIBRARY: [LibraryEntry; 9] = [
    LibraryEntry {
        name: "rutile",
        tables: Tables::Uniaxial {
            ordinary: table!("rutile-o.csv"),
            extraordinary: table!("rutile-e.csv"),
        },
    },
    LibraryEntry {
        name: "anatase",
        tables: Tables::Isotropic(table!("anatase.csv")),
    },
    LibraryEntry {
        name: "zno",
        tables: Tables::Isotropic(table!("zno.csv")),
    },
    LibraryEntry {
        name: "calcite",
        tables: Tables::Uniaxial {
            ordinary: table!("calcite-o.csv"),
            extraordinary: table!("calcite-e.csv"),
        },
    },
    LibraryEntry {
        name: "hematite",
        tables: Tables::Uniaxial {
            ordinary: table!("hematite-o.csv"),
            extraordinary: table!("hematite-e.csv"),
        },
    },
    LibraryEntry {
        name: "cds",
        tables: Tables::Uniaxial {
            ordinary: table!("cds-o.csv"),
            extraordinary: table!("cds-e.csv"),
        },
    },
    LibraryEntry {
        name: "soot",
        tables: Tables::Isotropic(table!("soot.csv")),
    },
    LibraryEntry {
        name: "amorphous-carbon",
        tables: Tables::Isotropic(table!("amorphous-carbon.csv")),
    },
    LibraryEntry {
        name: "aluminium",
        tables: Tables::Isotropic(table!("aluminium.csv")),
    },
];

/// The library's names, in [`LIBRARY`] order.
pub fn library_names() -> Vec<&'static str> {
    LIBRARY.iter().map(|e| e.name).collect()
}

/// The library entry called `name`.
pub fn library_entry(name: &str) -> Option<&'static LibraryEntry> {
    LIBRARY.iter().find(|e| e.name == name)
}

/// The header keys every library table states, in file order.
pub const INFO_KEYS: [&str; 6] = [
    "material",
    "page",
    "reference",
    "range",
    "licence",
    "source",
];

/// Where a library table came from, as its header comments state it.
#[derive(Debug, Clone, PartialEq)]
pub struct TableInfo {
    /// What the table is of: `rutile TiO2 (titanium white), ordinary ray (o)`.
    pub material: String,
    /// The database page, `shelf/book/page (url)`.
    pub page: String,
    /// The publication the data come from.
    pub reference: String,
    /// The wavelengths the table covers, nm, as stated (equal to its rows').
    pub range_nm: (f64, f64),
    /// The licence of the data.
    pub licence: String,
    /// The database, its commit and the entry's file.
    pub source: String,
}

impl TableInfo {
    /// Reads the `# key: value` comment lines before the column header;
    /// every key of [`INFO_KEYS`] must be there, `range` as `lo-hi nm`.
    pub fn from_header(text: &str) -> Result<TableInfo, String> {
        let mut found: [String; 6] = Default::default();
        for line in text.lines().map(str::trim) {
            let Some(comment) = line.strip_prefix('#') else {
                if line.is_empty() {
                    continue;
                }
                break;
            };
            if let Some((key, value)) = comment.trim().split_once(": ") {
                if let Some(i) = INFO_KEYS.iter().position(|k| *k == key.trim()) {
                    found[i] = value.trim().to_string();
                }
            }
        }
        if let Some(i) = found.iter().position(String::is_empty) {
            return Err(format!("header lacks `# {}: …`", INFO_KEYS[i]));
        }
        let [material, page, reference, range, licence, source] = found;
        let range_nm = range
            .strip_suffix(" nm")
            .and_then(|r| r.split_once('-'))
            .and_then(|(lo, hi)| Some((lo.trim().parse().ok()?, hi.trim().parse().ok()?)))
            .ok_or_else(|| format!("header range `{range}` is not `lo-hi nm`"))?;
        Ok(TableInfo {
            material,
            page,
            reference,
            range_nm,
            licence,
            source,
        })
    }
}

impl Material {
    /// The library material `name` ([`LIBRARY`]); a uniaxial crystal is the
    /// orientation average of its two tables ([`Material::uniaxial`]).
    /// An unknown name is an error listing the known ones.
    pub fn library(name: &str) -> Result<Material, MaterialError> {
        let entry = library_entry(name).ok_or_else(|| MaterialError::UnknownLibrary {
            name: name.to_string(),
            known: library_names().join(", "),
        })?;
        let mut m = match entry.tables {
            Tables::Isotropic(text) => library_table(name, text)?,
            Tables::Uniaxial {
                ordinary,
                extraordinary,
            } => Material::uniaxial(
                name,
                library_table(&format!("{name}-o"), ordinary)?,
                library_table(&format!("{name}-e"), extraordinary)?,
            )?,
        };
        m.source = MaterialSource::Library(name.to_string());
        Ok(m)
    }
}

/// One embedded table and its header's [`TableInfo`]; the stated range must
/// be the rows' range.
fn library_table(name: &str, text: &str) -> Result<Material, MaterialError> {
    let origin = format!("library table `{name}`");
    let mut m = Material::parse(name, &origin, text)?;
    let table_err = |message: String| MaterialError::Table {
        origin: origin.clone(),
        message,
    };
    let info = TableInfo::from_header(text).map_err(table_err)?;
    if info.range_nm != m.range_nm() {
        return Err(table_err(format!(
            "header range {:?} nm differs from the rows' {:?} nm",
            info.range_nm,
            m.range_nm()
        )));
    }
    m.source = MaterialSource::Library(name.to_string());
    m.info = Some(info);
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::super::MAX_INDEX;
    use super::*;
    use num_complex::Complex64;
    use std::path::Path;

    fn data_dir() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/materials")
    }

    /// Every embedded table, as (file stem, text).
    fn embedded() -> Vec<(String, &'static str)> {
        let mut out = Vec::new();
        for e in LIBRARY {
            match e.tables {
                Tables::Isotropic(t) => out.push((e.name.to_string(), t)),
                Tables::Uniaxial {
                    ordinary,
                    extraordinary,
                } => {
                    out.push((format!("{}-o", e.name), ordinary));
                    out.push((format!("{}-e", e.name), extraordinary));
                }
            }
        }
        out
    }

    #[test]
    fn every_file_is_embedded_and_every_table_states_its_provenance() {
        let mut on_disk: Vec<String> = std::fs::read_dir(data_dir())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter_map(|f| f.strip_suffix(".csv").map(str::to_string))
            .collect();
        on_disk.sort();
        let mut names: Vec<String> = embedded().into_iter().map(|(n, _)| n).collect();
        names.sort();
        assert_eq!(on_disk, names, "data/materials/*.csv against LIBRARY");
        for (name, text) in embedded() {
            let file = std::fs::read_to_string(data_dir().join(format!("{name}.csv"))).unwrap();
            assert_eq!(file, text, "{name}");
            let m = library_table(&name, text).unwrap_or_else(|e| panic!("{e}"));
            let info = m.info().unwrap();
            assert!(info.page.contains('/'), "{name}: {}", info.page);
            assert!(info.reference.len() > 20, "{name}: {}", info.reference);
            assert!(info.licence.starts_with("CC0 1.0"), "{name}");
            assert!(info.source.contains("refractiveindex.info-database"));
            assert!(info.source.contains("commit "), "{name}");
            assert!(
                text.contains("# generated by scripts/make_materials.py; do not edit"),
                "{name}"
            );
        }
    }

    #[test]
    fn every_material_covers_the_visible_but_rutile_from_430_nm() {
        // Rutile's crystal entries (Devore 1951, Bond 1965) start at 430 and
        // 450 nm; everything else covers 380-780 nm.
        for name in library_names() {
            let m = Material::library(name).unwrap();
            let (lo, hi) = m.range_nm();
            let want_lo = if name == "rutile" { 430.0 } else { 380.0 };
            assert!(lo <= want_lo && hi >= 780.0, "{name}: {lo}-{hi}");
            assert_eq!(m.source, MaterialSource::Library(name.to_string()));
            assert_eq!(m.to_string(), format!("library `{name}`"));
        }
        let (lo, hi) = Material::library("rutile").unwrap().range_nm();
        assert_eq!((lo, hi), (430.0, 1100.0));
    }

    /// n of the database's formula 4 (Devore 1951, rutile) and formula 2
    /// (Ghosh 1999, calcite) with the entries' own coefficients (λ in µm).
    fn devore(a: f64, b: f64, c: f64, wl_um: f64) -> f64 {
        (a + b / (wl_um * wl_um - c)).sqrt()
    }
    fn ghosh(c: [f64; 4], wl_um: f64) -> f64 {
        let w2 = wl_um * wl_um;
        (1.0 + c[0] + c[1] * w2 / (w2 - c[2]) + c[3] * w2 / (w2 - 120.0)).sqrt()
    }

    #[test]
    fn values_match_the_database_entries() {
        // main/TiO2/Devore-o, -e: formula 4, n² = C1 + C2 / (λ² − C4).
        let rutile = Material::library("rutile").unwrap();
        let (o, e) = rutile.axes().unwrap();
        // On the 5 nm grid to the 6 digits written; between rows, linear
        // interpolation is within 3.1e-5 of the formula at 552.5 nm (n_e).
        for (wl, tol) in [(450.0, 1e-6), (550.0, 1e-6), (552.5, 4e-5), (700.0, 1e-6)] {
            let um = wl / 1000.0;
            let no = devore(5.913, 0.2441, 0.0803, um);
            let ne = devore(7.197, 0.3322, 0.0843, um);
            assert!((o.index_at(wl).unwrap().re - no).abs() < tol, "{wl}");
            assert!((e.index_at(wl).unwrap().re - ne).abs() < tol, "{wl}");
            assert_eq!(o.index_at(wl).unwrap().im, 0.0);
        }
        // Devore's n_o at 550 nm, as published: 2.65.
        assert!((o.index_at(550.0).unwrap().re - 2.648).abs() < 1e-3);
        // main/CaCO3/Ghosh-o, -e: formula 2; calcite n_o(589.3 nm) = 1.658.
        let calcite = Material::library("calcite").unwrap();
        let (o, e) = calcite.axes().unwrap();
        let co = [0.73358749, 0.96464345, 1.94325203e-2, 1.82831454];
        let ce = [0.35859695, 0.82427830, 1.06689543e-2, 0.14429128];
        for (wl, tol) in [(400.0, 1e-6), (589.3, 1e-5), (700.0, 1e-6)] {
            let um = wl / 1000.0;
            assert!((o.index_at(wl).unwrap().re - ghosh(co, um)).abs() < tol);
            assert!((e.index_at(wl).unwrap().re - ghosh(ce, um)).abs() < tol);
        }
        assert!((o.index_at(589.3).unwrap().re - 1.6584).abs() < 1e-3);
        // Tabulated entries, rows of the database files: main/Fe2O3/Querry-o
        // `0.5500 3.318 0.498`, main/Al/Rakic `0.56357 1.0728 6.7839`.
        let hematite = Material::library("hematite").unwrap();
        let o = hematite.axes().unwrap().0;
        assert_eq!(o.index_at(550.0), Some(Complex64::new(3.318, 0.498)));
        let al = Material::library("aluminium").unwrap();
        assert_eq!(al.index_at(563.57), Some(Complex64::new(1.0728, 6.7839)));
    }

    #[test]
    fn a_crystal_is_the_orientation_average_of_its_axes() {
        for name in ["rutile", "calcite", "hematite", "cds"] {
            let m = Material::library(name).unwrap();
            let (o, e) = m.axes().unwrap();
            assert!(m.info().is_none(), "the tables carry the provenance");
            assert!(o.info().unwrap().material.ends_with("ordinary ray (o)"));
            assert!(e
                .info()
                .unwrap()
                .material
                .ends_with("extraordinary ray (e)"));
            let mut bytes = o.table_bytes().to_vec();
            bytes.extend_from_slice(e.table_bytes());
            assert_eq!(
                m.table_bytes(),
                bytes.as_slice(),
                "{name}: both tables count"
            );
            for wl in [450.0, 551.0, 600.0, 777.0] {
                let (eo, ee) = m.epsilon_axes_at(wl).unwrap();
                let no = o.index_at(wl).unwrap();
                let ne = e.index_at(wl).unwrap();
                assert_eq!((eo, ee), (no * no, ne * ne));
                let n = m.index_at(wl).unwrap();
                let avg = (2.0 * eo + ee) / 3.0;
                assert!((n * n - avg).norm() < 1e-12, "{name} {wl}");
                assert!(
                    n.re > no.re.min(ne.re) && n.re < no.re.max(ne.re),
                    "{name} {wl}"
                );
            }
        }
        // Rutile at 550 nm: √((2·2.647935² + 2.952873²)/3) = 2.753336.
        let n = Material::library("rutile")
            .unwrap()
            .index_at(550.0)
            .unwrap();
        assert!((n.re - 2.753336).abs() < 1e-6, "{n}");
        // An isotropic material's pair is its ε twice.
        let zno = Material::library("zno").unwrap();
        let n = zno.index_at(500.0).unwrap();
        assert_eq!(zno.epsilon_axes_at(500.0), Some((n * n, n * n)));
        assert!(zno.axes().is_none());
    }

    #[test]
    fn aluminium_fits_the_index_limit_in_the_visible() {
        let al = Material::library("aluminium").unwrap();
        let k_max = al.k_values().iter().cloned().fold(0.0, f64::max);
        assert!(k_max <= MAX_INDEX && k_max > 9.0, "{k_max}");
        for wl in (380..=780).step_by(20) {
            let k = al.index_at(wl as f64).unwrap().im;
            assert!(k > 4.5 && k < 8.6, "a metal: k = {k} at {wl} nm");
        }
    }

    #[test]
    fn unknown_names_are_told_the_known_ones() {
        let err = Material::library("titanium-white").unwrap_err().to_string();
        assert_eq!(
            err,
            "unknown library material `titanium-white`; known: rutile, anatase, zno, \
             calcite, hematite, cds, soot, amorphous-carbon, aluminium"
        );
    }

    #[test]
    fn a_header_without_its_provenance_is_refused() {
        let good = embedded()[0].1;
        for key in INFO_KEYS {
            let text: String = good
                .lines()
                .filter(|l| !l.starts_with(&format!("# {key}: ")))
                .map(|l| format!("{l}\n"))
                .collect();
            let err = library_table("t", &text).unwrap_err().to_string();
            assert!(err.contains(&format!("lacks `# {key}:")), "{err}");
        }
        let shifted = good.replace("# range: 430-1100 nm", "# range: 400-1100 nm");
        let err = library_table("t", &shifted).unwrap_err().to_string();
        assert!(err.contains("differs from the rows'"), "{err}");
    }
}
