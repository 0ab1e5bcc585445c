//! Optics — far field: order efficiencies, absorption, energy balance.
//!
//! The Kirchhoff far field of a periodic layer is a finite set of plane waves,
//! one per propagating Bloch order, so no numerical far-field integral is
//! needed (METHOD §5). Energy balance `ΣR + ΣT + A = 1` is checked on every
//! solve. [`table`] spreads the orders onto a fixed angular table (the
//! smooth BRDF/BTDF of METHOD §5).

pub mod table;

use crate::config::{Incidence, Linear};
use crate::solver::SolveRecord;
use num_complex::Complex64;

/// One propagating diffraction order (Kirchhoff far field of a periodic layer).
#[derive(Debug, Clone, Copy)]
pub struct Order {
    pub m: i32,
    pub n: i32,
    /// Direction of the outgoing plane wave: polar angle from the layer normal
    /// (reflected orders go up, transmitted down; both share these angles).
    pub theta_deg: f64,
    pub phi_deg: f64,
    /// Efficiency R_mn = |r_mn|² Re β_mn / β_00.
    pub reflectance: f64,
    /// Efficiency T_mn = |t_mn|² Re β_mn / β_00.
    pub transmittance: f64,
}

/// Far-field summary of one solve.
#[derive(Debug, Clone)]
pub struct Efficiencies {
    pub orders: Vec<Order>,
    /// Specular amplitudes r_00 and t_00, co-polarised for Maxwell (for
    /// natural light, s's).
    pub r00: Complex64,
    pub t00: Complex64,
    /// p's co-polarised specular amplitudes (r_00, t_00) where the
    /// efficiencies stand for natural light (`r00`, `t00` then being s's);
    /// `None` for the scalar wave and one linear polarisation.
    pub specular_p: Option<[Complex64; 2]>,
    pub total_reflectance: f64,
    pub total_transmittance: f64,
    pub absorption: f64,
    /// ΣR + ΣT + A − 1 (zero for an exact solve).
    pub energy_balance: f64,
}

impl Efficiencies {
    /// The specular (0, 0) order's reflected and transmitted power: `|r00|²`
    /// and `|t00|²` for the scalar wave; for Maxwell both outgoing
    /// polarisations, averaged like every order for natural light.
    pub fn specular_power(&self) -> (f64, f64) {
        self.orders
            .iter()
            .find(|o| o.m == 0 && o.n == 0)
            .map_or((0.0, 0.0), |o| (o.reflectance, o.transmittance))
    }

    /// The co-polarised specular amplitudes (r_00, t_00) of each incident
    /// polarisation these efficiencies average (one, or s and p), whose
    /// ensemble means give the coherent specular power.
    pub fn specular_amplitudes(&self) -> Vec<[Complex64; 2]> {
        std::iter::once([self.r00, self.t00])
            .chain(self.specular_p)
            .collect()
    }

    /// The totals by their stored names: reflectance, transmittance,
    /// absorption and the energy balance.
    pub fn totals(&self) -> [(&'static str, f64); 4] {
        [
            ("total_reflectance", self.total_reflectance),
            ("total_transmittance", self.total_transmittance),
            ("absorption", self.absorption),
            ("energy_balance", self.energy_balance),
        ]
    }
}

/// Which face of the layer the light comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Side {
    /// From the viewer's side (z < 0), the normal case.
    #[default]
    Above,
    /// From the paper's side: the layer is flipped (z → H − z) and lit from
    /// above; "reflected" orders then go back down towards the paper.
    Below,
}

impl std::fmt::Display for Side {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Side::Above => "above",
            Side::Below => "below",
        })
    }
}

impl std::str::FromStr for Side {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "above" => Ok(Side::Above),
            "below" => Ok(Side::Below),
            _ => Err(format!("`{s}` is not one of above, below")),
        }
    }
}

/// One solve of the scene: a wavelength, a direction of incidence, a side
/// and a realisation of the random layer.
#[derive(Debug, Clone)]
pub struct SolveEntry {
    pub wavelength_nm: f64,
    pub incidence: Incidence,
    pub side: Side,
    /// Index of the random fragment (0-based).
    pub realisation: usize,
    /// Index of the layer in a stack from the top (0 for a single layer).
    pub layer: usize,
    pub efficiencies: Efficiencies,
    pub record: SolveRecord,
    /// Maxwell: each incident polarisation's own efficiencies (the mean
    /// of which is `efficiencies`); empty for the scalar wave.
    pub polarised: Vec<(crate::config::Linear, Efficiencies)>,
    /// Maxwell's natural light solved as one mixed state
    /// `(ŝ + e^{iφ} p̂)/√2`: its φ in degrees (`polarised` is then empty).
    pub random_phase_deg: Option<f64>,
}

/// Order efficiencies, absorption and the energy balance of a solution.
///
/// A harmonic propagates when `Re β > 0`; it leaves at
/// `sin θ (cos φ, sin φ) = κ / k0`, `cos θ = β / k0`.
pub fn efficiencies(sol: &crate::solver::Solution) -> Efficiencies {
    let lat = &sol.lattice;
    let beta00 = lat.beta(0, 0).re;
    let mut orders = Vec::new();
    let (mut tr, mut tt) = (0.0, 0.0);
    for ix in 0..lat.nx {
        for iy in 0..lat.ny {
            let beta = lat.beta(ix, iy);
            if beta.re <= 0.0 {
                continue;
            }
            let [kx, ky] = lat.kappa(ix, iy);
            let (pr, pt) = sol.order_power(ix, iy);
            let (rr, t) = (pr * beta.re / beta00, pt * beta.re / beta00);
            tr += rr;
            tt += t;
            let s = (kx.hypot(ky) / lat.k0).min(1.0);
            orders.push(Order {
                m: crate::solver::Lattice::order(ix, lat.nx),
                n: crate::solver::Lattice::order(iy, lat.ny),
                theta_deg: s.asin().to_degrees(),
                phi_deg: ky.atan2(kx).to_degrees(),
                reflectance: rr,
                transmittance: t,
            });
        }
    }
    orders.sort_by_key(|o| (o.m, o.n));
    Efficiencies {
        orders,
        r00: sol.specular_r(),
        t00: sol.specular_t(),
        specular_p: sol.specular_p(),
        total_reflectance: tr,
        total_transmittance: tt,
        absorption: sol.absorption,
        energy_balance: tr + tt + sol.absorption - 1.0,
    }
}

/// Natural light from linear polarisations solved apart: the incoherent mean
/// of their powers, order by order (the same lattice, so the same orders),
/// and of the totals, absorption and balance. Amplitudes of different
/// polarisations do not average: the specular ones are kept per
/// polarisation (the first's in `r00`, `t00`; p's beside them when s and p
/// were both solved).
pub fn polarisation_mean(parts: &[(Linear, Efficiencies)]) -> Efficiencies {
    let n = parts.len() as f64;
    let first = &parts[0].1;
    let mean = |f: &dyn Fn(&Efficiencies) -> f64| parts.iter().map(|(_, e)| f(e)).sum::<f64>() / n;
    let orders = first
        .orders
        .iter()
        .enumerate()
        .map(|(i, o)| Order {
            reflectance: mean(&|e| e.orders[i].reflectance),
            transmittance: mean(&|e| e.orders[i].transmittance),
            ..*o
        })
        .collect();
    Efficiencies {
        orders,
        r00: first.r00,
        t00: first.t00,
        specular_p: match parts {
            [(Linear::S, _), (Linear::P, p)] => Some([p.r00, p.t00]),
            _ => None,
        },
        total_reflectance: mean(&|e| e.total_reflectance),
        total_transmittance: mean(&|e| e.total_transmittance),
        absorption: mean(&|e| e.absorption),
        energy_balance: mean(&|e| e.energy_balance),
    }
}

/// Far field of a homogeneous slab: only the specular order propagates.
pub fn slab_efficiencies(
    resp: &crate::solver::airy::SlabResponse,
    inc: &Incidence,
) -> Efficiencies {
    let (rr, t) = (resp.r.norm_sqr(), resp.t.norm_sqr());
    Efficiencies {
        orders: vec![Order {
            m: 0,
            n: 0,
            theta_deg: inc.polar_deg,
            phi_deg: if inc.polar_deg == 0.0 {
                0.0
            } else {
                let a = inc.azimuth_deg.to_radians();
                a.sin().atan2(a.cos()).to_degrees()
            },
            reflectance: rr,
            transmittance: t,
        }],
        r00: resp.r,
        t00: resp.t,
        specular_p: None,
        total_reflectance: rr,
        total_transmittance: t,
        absorption: resp.absorption,
        energy_balance: rr + t + resp.absorption - 1.0,
    }
}
