//! The solution methods by name: what scenes may ask for in
//! `[solver] method` and what solve records say produced a result. What each
//! method does, costs and where it is valid is the solver's registry
//! (`solver::methods`, [`Method::solver`](crate::solver::methods)); this
//! stage only knows the names, so that a scene naming an unknown method is
//! refused as it is read.

use std::fmt;
use std::sync::OnceLock;

/// A solution method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Plain Born series; stops and reports divergence.
    Born,
    /// Pseudo-time marching with the convergent-Born-series preconditioner.
    TimeMarching,
    /// Restarted GMRES on the same CBS-preconditioned equation.
    Gmres,
    /// BiCGStab on the same CBS-preconditioned equation.
    BiCgStab,
    /// Born where a cheap estimate says it converges, BiCGStab otherwise or
    /// when Born diverges; time-marching if BiCGStab fails.
    Auto,
    /// Closed-form homogeneous slab: no grains, no iteration.
    Airy,
}

impl Method {
    /// Every method, in the order their names are listed.
    pub const ALL: [Method; 6] = [
        Method::Born,
        Method::TimeMarching,
        Method::Gmres,
        Method::BiCgStab,
        Method::Auto,
        Method::Airy,
    ];

    /// The name scenes and result files use.
    pub fn name(self) -> &'static str {
        match self {
            Method::Born => "born",
            Method::TimeMarching => "time-marching",
            Method::Gmres => "gmres",
            Method::BiCgStab => "bicgstab",
            Method::Auto => "auto",
            Method::Airy => "airy",
        }
    }

    /// Whether a scene may ask for it (the pipeline picks `airy` itself, for
    /// layers without grains).
    pub fn in_config(self) -> bool {
        self != Method::Airy
    }

    /// Whether a solve record may name it (`auto` hands every solve to
    /// another method, which the record names).
    pub fn in_records(self) -> bool {
        self != Method::Auto
    }

    /// The names a scene may give, in [`Method::ALL`] order.
    pub fn config_names() -> &'static [&'static str] {
        static NAMES: OnceLock<Vec<&'static str>> = OnceLock::new();
        NAMES.get_or_init(|| {
            Method::ALL
                .into_iter()
                .filter(|m| m.in_config())
                .map(Method::name)
                .collect()
        })
    }

    /// The method a scene names, if it may name it.
    pub fn from_config_name(name: &str) -> Option<Method> {
        Method::ALL
            .into_iter()
            .find(|m| m.in_config() && m.name() == name)
    }
}

/// A method as a solve record names it.
impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let recorded = || Method::ALL.into_iter().filter(|m| m.in_records());
        recorded().find(|m| m.name() == s).ok_or_else(|| {
            let names: Vec<&str> = recorded().map(Method::name).collect();
            format!("`{s}` is not one of {}", names.join(", "))
        })
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.to_string(), m.name());
            if m.in_config() {
                assert_eq!(Method::from_config_name(m.name()), Some(m));
            }
            if m.in_records() {
                assert_eq!(m.name().parse::<Method>(), Ok(m));
            }
        }
        assert_eq!(
            Method::config_names(),
            ["born", "time-marching", "gmres", "bicgstab", "auto"]
        );
        assert_eq!(
            "cg".parse::<Method>().unwrap_err(),
            "`cg` is not one of born, time-marching, gmres, bicgstab, airy"
        );
    }
}
