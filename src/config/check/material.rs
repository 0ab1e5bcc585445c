//! A material key: a builtin or library name, a constant `[n, k]` or
//! `[Re ε, Im ε]`, or a CSV table (resolved next to the config file).

use super::Checker;
use crate::config::materials::BUILTIN_NAMES;
use crate::config::raw::RawMaterial;
use crate::config::{ConfigError, Material};
use std::path::Path;

impl Checker<'_> {
    pub(super) fn material(&self, raw: &RawMaterial, key: &str) -> Result<Material, ConfigError> {
        match raw {
            RawMaterial::Builtin(name) => Material::builtin(name).ok_or_else(|| {
                self.invalid(
                    format!("{key}.builtin"),
                    format!(
                        "unknown builtin material `{name}`; available: {}",
                        BUILTIN_NAMES.join(", ")
                    ),
                )
            }),
            RawMaterial::Library(name) => Material::library(name)
                .map_err(|e| self.invalid(format!("{key}.library"), e.to_string())),
            RawMaterial::Index(nk) => {
                let k = format!("{key}.index");
                if nk.len() != 2 {
                    return Err(self.invalid(k, format!("must be [n, k], got {} values", nk.len())));
                }
                self.range(&k, nk[0], (1.0..=10.0).contains(&nk[0]), "n in [1, 10]")?;
                self.range(&k, nk[1], (0.0..=10.0).contains(&nk[1]), "k in [0, 10]")?;
                let text = format!(
                    "wavelength_nm,n,k\n1,{n},{kk}\n1000000,{n},{kk}\n",
                    n = nk[0],
                    kk = nk[1]
                );
                let name = format!("n{}+{}i", nk[0], nk[1]);
                Material::from_csv_text(&name, &text).map_err(|e| self.invalid(k, e.to_string()))
            }
            RawMaterial::Epsilon(e) => {
                let k = format!("{key}.epsilon");
                if e.len() != 2 {
                    return Err(
                        self.invalid(k, format!("must be [Re ε, Im ε], got {} values", e.len()))
                    );
                }
                self.range(
                    &k,
                    e[1],
                    (0.0..=100.0).contains(&e[1]),
                    "[0, 100] for Im ε (a medium that absorbs or is lossless)",
                )?;
                self.range(
                    &k,
                    e[0],
                    (-100.0..=100.0).contains(&e[0]),
                    "Re ε in [-100, 100]",
                )?;
                let (n, kk) = crate::config::materials::index_of_epsilon(e[0], e[1]);
                if !(n > 0.0 && kk <= 10.0) {
                    return Err(self.invalid(
                        k,
                        format!("√ε = {n:.3} + {kk:.3}i is outside n in (0, 10], k in [0, 10]"),
                    ));
                }
                let text = format!(
                    "wavelength_nm,eps_re,eps_im\n1,{re},{im}\n1000000,{re},{im}\n",
                    re = e[0],
                    im = e[1]
                );
                let name = format!("eps{}+{}i", e[0], e[1]);
                Material::from_csv_text(&name, &text)
                    .map_err(|err| self.invalid(k, err.to_string()))
            }
            RawMaterial::Csv(rel) => {
                if rel.trim().is_empty() {
                    return Err(self.invalid(format!("{key}.csv"), "must not be empty"));
                }
                let base = self.file.parent().unwrap_or(Path::new(""));
                let resolved = base.join(rel);
                Material::from_csv(&resolved).map_err(|e| ConfigError::Material {
                    file: self.file.to_path_buf(),
                    material: rel.clone(),
                    message: e.to_string(),
                })
            }
        }
    }
}
