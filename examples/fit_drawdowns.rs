//! Synthetic drawdown spectra for a fit file: what its drawdowns would
//! measure if the unknown pigment were a known material (a builtin or
//! library name) of a known grain diameter, on the fit's own fast model,
//! with seeded Gaussian noise (`inksim::r#match::fit::synthetic`).
//!
//! ```sh
//! cargo run --release --example fit_drawdowns -- configs/fit-red.toml red 150 0.002 1
//! ```
//! Arguments: fit file, material, diameter (nm), noise (1σ), seed. Writes
//! every spectrum file the fit file names.

use inksim::config::Material;
use inksim::r#match::fit::synthetic::synthesise;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [file, material, diameter, noise, seed] = args.as_slice() else {
        return Err("usage: fit_drawdowns FIT.toml MATERIAL DIAMETER_NM NOISE SEED".into());
    };
    let m = match Material::builtin(material) {
        Some(m) => m,
        None => Material::library(material)?,
    };
    let written = synthesise(
        Path::new(file),
        &m,
        diameter.parse()?,
        noise.parse()?,
        seed.parse()?,
    )?;
    for f in written {
        println!("{}", f.display());
    }
    Ok(())
}
