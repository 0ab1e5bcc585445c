//! The smooth BRDF/BTDF: order efficiencies spread onto a fixed angular table.
//!
//! Directions are indexed by their projected coordinates
//! `s = sin θ (cos φ, sin φ)`, in which the propagating orders of a periodic
//! fragment form a regular lattice of spacing `λ/L` and the projected solid
//! angle is the area element (`cos θ dΩ = ds_x ds_y`). One realisation's
//! BRDF is `f cos θ = Σ R_mn δ(ω − ω_mn)` with δ in solid angle, that is
//! `f = Σ R_mn δ²(s − s_mn)` in `s`: the density of reflected power per unit
//! projected solid angle *is* the BRDF (1/sr; a Lambertian reflector of
//! albedo ρ has the uniform density ρ/π over the unit disc). The table holds
//! that density `D(s)` on square nodes `s = (i, j)·cell`. Each order's power
//! `P` is shared among the four surrounding nodes with bilinear
//! (cloud-in-cell) weights, which sum to 1, so `Σ D·cell² = Σ P` exactly: the
//! spreading preserves power. The kernel is a tent two cells wide, so a cell
//! of at least the order spacing leaves no empty nodes; `default_cell` takes
//! two spacings at the longest wavelength, which keeps the aliasing ripple
//! of the lattice below a few per cent.
//!
//! **Read-back** ([`AngularTable::value_at`]): `f(s) = D(s) / C(s)`, both
//! bilinear, where `C` is each node's *coverage*, the share of its tent
//! kernel inside the unit disc ([`node_coverage`]). Near the horizon part of
//! a node's kernel lies beyond `|s| = 1`, where no order can deposit power,
//! so `D` alone would read a smooth BRDF low there (half or less at grazing
//! angles); dividing by `C` (normalised convolution) reads a uniform density
//! back exactly at every angle. In the interior `C = 1`.

/// Node layout of an angular table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableSpec {
    /// Node spacing in `s` (sin θ units).
    pub cell: f64,
    /// Nodes run over `i, j ∈ [−half, half]`, covering |s| ≤ 1 plus one cell.
    pub half: usize,
}

impl TableSpec {
    /// Table of node spacing `cell` (0 < cell ≤ 1).
    pub fn new(cell: f64) -> Self {
        TableSpec {
            cell,
            half: (1.0 / cell).ceil() as usize + 1,
        }
    }

    /// Two order spacings at the longest wavelength on the smaller period.
    pub fn default_cell(max_wavelength_nm: f64, fragment_nm: [f64; 2]) -> f64 {
        (2.0 * max_wavelength_nm / fragment_nm[0].min(fragment_nm[1])).min(1.0)
    }

    /// Nodes per axis.
    pub fn n(&self) -> usize {
        2 * self.half + 1
    }

    /// Coordinate of node index `i` (0-based).
    pub fn coord(&self, i: usize) -> f64 {
        (i as f64 - self.half as f64) * self.cell
    }

    /// Bilinear cell and weights of `s`: lower node indices and fractions
    /// (None outside the table).
    pub fn locate(&self, sx: f64, sy: f64) -> Option<(usize, usize, f64, f64)> {
        let h = self.half as f64;
        let (x, y) = (sx / self.cell + h, sy / self.cell + h);
        let max = (self.n() - 1) as f64;
        if !(x >= 0.0 && y >= 0.0 && x <= max && y <= max) {
            return None;
        }
        let (i, j) = (
            (x.floor() as usize).min(self.n() - 2),
            (y.floor() as usize).min(self.n() - 2),
        );
        Some((i, j, x - i as f64, y - j as f64))
    }

    /// Node values `v` (row-major `[j][i]`) read bilinearly in the cell
    /// [`Self::locate`] gave.
    pub fn bilinear(&self, v: &[f64], (i, j, fx, fy): (usize, usize, f64, f64)) -> f64 {
        let n = self.n();
        v[j * n + i] * (1.0 - fx) * (1.0 - fy)
            + v[j * n + i + 1] * fx * (1.0 - fy)
            + v[(j + 1) * n + i] * (1.0 - fx) * fy
            + v[(j + 1) * n + i + 1] * fx * fy
    }
}

/// A density table `D(s)`, row-major `[j][i]` (j along s_y).
#[derive(Debug, Clone, PartialEq)]
pub struct AngularTable {
    pub spec: TableSpec,
    pub density: Vec<f64>,
}

impl AngularTable {
    pub fn zeros(spec: TableSpec) -> Self {
        AngularTable {
            spec,
            density: vec![0.0; spec.n() * spec.n()],
        }
    }

    /// Spread power `p` arriving at direction `s` onto the four nearest nodes.
    pub fn deposit(&mut self, sx: f64, sy: f64, p: f64) {
        let n = self.spec.n();
        let area = self.spec.cell * self.spec.cell;
        let Some((i, j, fx, fy)) = self.spec.locate(sx, sy) else {
            // |s| ≤ 1 always lies inside the table.
            debug_assert!(false, "direction outside the table");
            return;
        };
        let d = p / area;
        self.density[j * n + i] += d * (1.0 - fx) * (1.0 - fy);
        self.density[j * n + i + 1] += d * fx * (1.0 - fy);
        self.density[(j + 1) * n + i] += d * (1.0 - fx) * fy;
        self.density[(j + 1) * n + i + 1] += d * fx * fy;
    }

    /// Total power `Σ D·cell²`.
    pub fn total(&self) -> f64 {
        self.density.iter().sum::<f64>() * self.spec.cell * self.spec.cell
    }

    /// `D(s)` by bilinear interpolation (0 outside the table).
    pub fn density_at(&self, sx: f64, sy: f64) -> f64 {
        self.spec
            .locate(sx, sy)
            .map_or(0.0, |at| self.spec.bilinear(&self.density, at))
    }

    /// The scattering function `f = D / C` (1/sr) in direction `(θ, φ)`,
    /// θ < 90° (module docs).
    pub fn value_at(&self, theta_deg: f64, phi_deg: f64) -> f64 {
        let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
        let (sx, sy) = (t.sin() * p.cos(), t.sin() * p.sin());
        let Some((i, j, fx, fy)) = self.spec.locate(sx, sy) else {
            return 0.0;
        };
        let c = |ii: usize, jj: usize| node_coverage(self.spec, ii, jj);
        let cov = c(i, j) * (1.0 - fx) * (1.0 - fy)
            + c(i + 1, j) * fx * (1.0 - fy)
            + c(i, j + 1) * (1.0 - fx) * fy
            + c(i + 1, j + 1) * fx * fy;
        if cov > 0.0 {
            self.density_at(sx, sy) / cov
        } else {
            0.0
        }
    }
}

/// Sub-samples per cell and axis of the coverage quadrature.
const COVERAGE_SAMPLES: usize = 16;

/// The share of node `(i, j)`'s tent kernel (bilinear weight, two cells
/// wide) that lies inside the unit disc `|s| ≤ 1`: 1 for a node whose whole
/// support is inside, else a midpoint quadrature of 32 × 32 points (error
/// well below 1 % of the node's weight).
pub fn node_coverage(spec: TableSpec, i: usize, j: usize) -> f64 {
    let (x0, y0, h) = (spec.coord(i), spec.coord(j), spec.cell);
    if x0.hypot(y0) + h * std::f64::consts::SQRT_2 <= 1.0 {
        return 1.0;
    }
    let n = 2 * COVERAGE_SAMPLES;
    let step = 2.0 * h / n as f64;
    let mut inside = 0.0;
    for a in 0..n {
        let u = -h + (a as f64 + 0.5) * step;
        let wx = 1.0 - u.abs() / h;
        for b in 0..n {
            let v = -h + (b as f64 + 0.5) * step;
            if (x0 + u).hypot(y0 + v) <= 1.0 {
                inside += wx * (1.0 - v.abs() / h);
            }
        }
    }
    // The tent integrates to h² over its support: normalise.
    inside * step * step / (h * h)
}

/// Which orders go into a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// Reflected orders except the specular (0, 0): the diffuse BRDF.
    DiffuseReflection,
    /// Transmitted orders except the direct (0, 0): the diffuse BTDF.
    DiffuseTransmission,
}

/// Spread the orders of one solve onto a table.
pub fn spread(eff: &super::Efficiencies, part: Part, spec: TableSpec) -> AngularTable {
    let mut t = AngularTable::zeros(spec);
    for o in &eff.orders {
        if o.m == 0 && o.n == 0 {
            continue;
        }
        let p = match part {
            Part::DiffuseReflection => o.reflectance,
            Part::DiffuseTransmission => o.transmittance,
        };
        let (th, ph) = (o.theta_deg.to_radians(), o.phi_deg.to_radians());
        t.deposit(th.sin() * ph.cos(), th.sin() * ph.sin(), p);
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spreading_preserves_power_and_reads_back_a_uniform_density() {
        // A regular lattice of equal orders of spacing d fills the disk with
        // density P/d²; with cell = 2d the interior nodes read exactly that.
        let d = 0.05;
        let spec = TableSpec::new(2.0 * d);
        let mut t = AngularTable::zeros(spec);
        let mut total = 0.0;
        for m in -30i32..=30 {
            for n in -30i32..=30 {
                let (sx, sy) = (m as f64 * d + 0.013, n as f64 * d - 0.021);
                if sx * sx + sy * sy < 1.0 {
                    t.deposit(sx, sy, 1e-3);
                    total += 1e-3;
                }
            }
        }
        assert!((t.total() - total).abs() < 1e-12 * total);
        let expect = 1e-3 / (d * d);
        for (sx, sy) in [(0.0, 0.0), (0.3, -0.2), (-0.5, 0.4)] {
            let got = t.density_at(sx, sy);
            assert!((got / expect - 1.0).abs() < 1e-9, "{got} vs {expect}");
        }
    }

    #[test]
    fn a_lambertian_lattice_reads_back_as_rho_over_pi_at_every_angle() {
        // Orders of equal power on a fine lattice filling the unit disc: a
        // Lambertian reflector of albedo ρ, f = ρ/π at every angle, also at
        // 60°, 75° and 85°, where half of the nodes' kernels lie beyond the
        // horizon. Reading D/cos θ would give ρ/(π cos θ); reading D alone
        // would give about half near the rim.
        let rho = 0.8;
        let d = 0.01;
        let spec = TableSpec::new(0.1);
        let mut t = AngularTable::zeros(spec);
        let m = (1.0 / d) as i32 + 1;
        for a in -m..=m {
            for b in -m..=m {
                let (sx, sy) = (a as f64 * d + 0.003, b as f64 * d - 0.004);
                if sx * sx + sy * sy < 1.0 {
                    t.deposit(sx, sy, rho / std::f64::consts::PI * d * d);
                }
            }
        }
        let f = rho / std::f64::consts::PI;
        for theta in [0.0, 30.0, 60.0, 75.0, 85.0] {
            for phi in [0.0, 37.0, 180.0] {
                let got = t.value_at(theta, phi);
                // Bilinear reads of D and C: within 2 % to 75°, 5 % at 85°.
                let tol = if theta > 80.0 { 0.05 } else { 0.02 };
                assert!((got / f - 1.0).abs() < tol, "θ {theta}: {got} vs {f}");
            }
        }
    }

    #[test]
    fn coverage_is_one_inside_and_a_quarter_to_a_half_on_the_rim() {
        let spec = TableSpec::new(0.25);
        let h = spec.half;
        assert_eq!(node_coverage(spec, h, h), 1.0);
        // The node at s = (1, 0) sits on the rim: about half its kernel is
        // inside; the node at (1.25, 0) only a sliver.
        let rim = node_coverage(spec, h + 4, h);
        assert!((rim - 0.5).abs() < 0.06, "{rim}");
        let out = node_coverage(spec, h + 5, h);
        assert!(out < 0.05, "{out}");
    }

    #[test]
    fn grazing_directions_stay_in_the_table() {
        let spec = TableSpec::new(0.3);
        let mut t = AngularTable::zeros(spec);
        t.deposit(1.0, 0.0, 0.5);
        t.deposit(0.0, -1.0, 0.25);
        let c = std::f64::consts::FRAC_1_SQRT_2;
        t.deposit(-c, c, 0.25);
        assert!((t.total() - 1.0).abs() < 1e-14);
    }
}
