//! The incident plane wave's polarisation state for Maxwell's equations:
//! complex amplitudes along ŝ and p̂ of the plane of incidence.

use crate::config::Linear;
use num_complex::Complex64 as C64;

/// `E_inc = s ŝ + p p̂` with `|s|² + |p|² = 1` (unit incident power).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jones {
    pub s: C64,
    pub p: C64,
}

impl Jones {
    /// One linear polarisation.
    pub fn linear(l: Linear) -> Self {
        let (one, zero) = (C64::new(1.0, 0.0), C64::new(0.0, 0.0));
        match l {
            Linear::S => Jones { s: one, p: zero },
            Linear::P => Jones { s: zero, p: one },
        }
    }

    /// `(ŝ + e^{iφ} p̂)/√2`: half the power in each polarisation, at relative
    /// phase `φ` (radians). Every power it gives is natural light's (the
    /// mean of s and p) plus a cross term `Re(e^{iφ} a_s* a_p)` between the
    /// two polarisations' answers, whose mean over a uniform `φ` is zero.
    pub fn phased(phi: f64) -> Self {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        Jones {
            s: C64::new(h, 0.0),
            p: C64::from_polar(h, phi),
        }
    }

    /// The linear polarisation this state is, if it is one.
    pub fn as_linear(&self) -> Option<Linear> {
        if self.p == C64::new(0.0, 0.0) {
            Some(Linear::S)
        } else if self.s == C64::new(0.0, 0.0) {
            Some(Linear::P)
        } else {
            None
        }
    }

    /// "s", "p", or the relative phase of a mixed state.
    pub fn name(&self) -> String {
        match self.as_linear() {
            Some(l) => l.name().to_string(),
            None => format!(
                "s + p at phase {:.1}°",
                (self.p / self.s).arg().to_degrees()
            ),
        }
    }
}

impl From<Linear> for Jones {
    fn from(l: Linear) -> Self {
        Jones::linear(l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_carry_unit_power_and_know_their_kind() {
        for j in [
            Jones::linear(Linear::S),
            Jones::linear(Linear::P),
            Jones::phased(1.3),
        ] {
            assert!((j.s.norm_sqr() + j.p.norm_sqr() - 1.0).abs() < 1e-15);
        }
        assert_eq!(Jones::linear(Linear::P).as_linear(), Some(Linear::P));
        assert_eq!(Jones::from(Linear::S).as_linear(), Some(Linear::S));
        assert_eq!(Jones::phased(0.0).as_linear(), None);
        assert_eq!(
            Jones::phased(0.5 * std::f64::consts::PI).name(),
            "s + p at phase 90.0°"
        );
    }
}
