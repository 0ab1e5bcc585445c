//! What one flake reflects and transmits at a local angle inside the
//! lacquer, per wavelength.
//!
//! - **Metal**: a film of the metal's complex index, the flake's thickness,
//!   in the lacquer ([`thin_film`], natural light): practically opaque for
//!   aluminium thicker than ~50 nm.
//! - **Spectrum**: a measured reflectance `R(λ)` at every angle, nothing
//!   transmitted (an opaque flake of unknown optics).
//! - **Coated**: an interference flake, coating / substrate / coating in the
//!   lacquer (both coatings of one thickness, as one deposition makes them),
//!   by the transfer matrix in s and p, the powers averaged, and averaged
//!   over the substrate's and the coating's thickness distributions (normal,
//!   truncated at ±5 σ and at 0) by Gauss–Legendre quadrature with enough
//!   nodes to follow the interference fringes (about one per radian of the
//!   round-trip phase across the range).
//!
//! What a flake does not reflect or absorb goes on undeviated. The result is
//! a table in `cos θ_loc` ([`LocalTable`]), linear between its nodes.

use super::thin_film::{self, Film, Powers};
use crate::optics::baseline::ordinates::gauss_legendre;
use num_complex::Complex64 as C64;

/// A film of the flake with a thickness distribution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layer {
    /// Complex index at the wavelength.
    pub index: C64,
    pub thickness_nm: f64,
    /// Standard deviation of the thickness, nm (0: every flake alike).
    pub thickness_sd_nm: f64,
}

/// A flake's optics at one wavelength.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reflector {
    Metal(Layer),
    Spectrum(f64),
    Coated { coating: Layer, substrate: Layer },
}

/// Nodes of the table in `cos θ_loc`, uniform on `[0, 1]`.
pub const TABLE_NODES: usize = 65;

/// `R` and `T` of a flake against `cos θ_loc` at one wavelength.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalTable {
    r: Vec<f64>,
    t: Vec<f64>,
}

impl LocalTable {
    /// `(R, T)` at `cos_local` in `[0, 1]`, linear between nodes.
    pub fn at(&self, cos_local: f64) -> Powers {
        let x = cos_local.clamp(0.0, 1.0) * (TABLE_NODES - 1) as f64;
        // `x ≥ 0`: truncation is the floor.
        let i = (x as usize).min(TABLE_NODES - 2);
        let f = x - i as f64;
        Powers {
            r: self.r[i] + f * (self.r[i + 1] - self.r[i]),
            t: self.t[i] + f * (self.t[i + 1] - self.t[i]),
        }
    }
}

/// Nodes and normalised weights of a normal thickness distribution.
pub fn thickness_nodes(mean: f64, sd: f64, phase_per_nm: f64) -> Vec<(f64, f64)> {
    if sd <= 0.0 {
        return vec![(mean, 1.0)];
    }
    let lo = (mean - 5.0 * sd).max(0.0);
    let hi = mean + 5.0 * sd;
    let count = ((phase_per_nm * (hi - lo)).ceil() as usize + 8).min(600);
    let (x, w) = gauss_legendre(count);
    let mut out: Vec<(f64, f64)> = x
        .iter()
        .zip(&w)
        .map(|(x, w)| {
            let d = lo + 0.5 * (hi - lo) * (x + 1.0);
            let z = (d - mean) / sd;
            (d, w * (-0.5 * z * z).exp())
        })
        .collect();
    let total: f64 = out.iter().map(|p| p.1).sum();
    for p in &mut out {
        p.1 /= total;
    }
    out
}

impl Reflector {
    /// `(R, T)` of natural light at `cos_local` in a lacquer of index
    /// `lacquer`, at `wavelength_nm`, averaged over the thicknesses.
    pub fn powers(&self, lacquer: f64, wavelength_nm: f64, cos_local: f64) -> Powers {
        let c = cos_local.clamp(1e-6, 1.0);
        let ambient = C64::new(lacquer, 0.0);
        // Round-trip phase per nm of a film of real index n at normal incidence.
        let phase = |n: C64| 4.0 * std::f64::consts::PI * n.re / wavelength_nm;
        match *self {
            Reflector::Spectrum(r) => Powers { r, t: 0.0 },
            Reflector::Metal(layer) => {
                let mut acc = Powers { r: 0.0, t: 0.0 };
                for (d, w) in thickness_nodes(layer.thickness_nm, layer.thickness_sd_nm, 0.0) {
                    let film = Film {
                        index: layer.index,
                        thickness_nm: d,
                    };
                    let p = thin_film::unpolarised(lacquer, &[film], ambient, wavelength_nm, c);
                    acc.r += w * p.r;
                    acc.t += w * p.t;
                }
                acc
            }
            Reflector::Coated { coating, substrate } => {
                let mut acc = Powers { r: 0.0, t: 0.0 };
                let cs = thickness_nodes(
                    coating.thickness_nm,
                    coating.thickness_sd_nm,
                    2.0 * phase(coating.index),
                );
                let ss = thickness_nodes(
                    substrate.thickness_nm,
                    substrate.thickness_sd_nm,
                    phase(substrate.index),
                );
                for &(dc, wc) in &cs {
                    for &(ds, ws) in &ss {
                        let films = [
                            Film {
                                index: coating.index,
                                thickness_nm: dc,
                            },
                            Film {
                                index: substrate.index,
                                thickness_nm: ds,
                            },
                            Film {
                                index: coating.index,
                                thickness_nm: dc,
                            },
                        ];
                        let p = thin_film::unpolarised(lacquer, &films, ambient, wavelength_nm, c);
                        acc.r += wc * ws * p.r;
                        acc.t += wc * ws * p.t;
                    }
                }
                acc
            }
        }
    }

    /// The table of [`Reflector::powers`] against `cos θ_loc`.
    pub fn table(&self, lacquer: f64, wavelength_nm: f64) -> LocalTable {
        let (mut r, mut t) = (Vec::new(), Vec::new());
        for i in 0..TABLE_NODES {
            let c = i as f64 / (TABLE_NODES - 1) as f64;
            let p = self.powers(lacquer, wavelength_nm, c);
            r.push(p.r.clamp(0.0, 1.0));
            t.push(p.t.clamp(0.0, 1.0 - p.r.clamp(0.0, 1.0)));
        }
        LocalTable { r, t }
    }
}
