//! A paint's materials at one wavelength: a material's index, the paint's
//! lacquer index and a flake's reflector (what the paint run and its
//! sparkle both read).

use num_complex::Complex64 as C64;

use crate::config::paint::{FilmSpec, PaintScene, ReflectorSpec};
use crate::config::Material;
use crate::optics::flakes::reflector::{Layer as Film, Reflector};

use super::PipelineError;

pub(super) fn index(m: &Material, wavelength_nm: f64) -> Result<C64, PipelineError> {
    m.index_at(wavelength_nm)
        .ok_or_else(|| PipelineError::Material {
            material: m.to_string(),
            wavelength_nm,
        })
}

/// The paint's lacquer index at a wavelength: the top layer's real part.
pub fn lacquer_index(scene: &PaintScene, wavelength_nm: f64) -> Result<f64, PipelineError> {
    Ok(index(&scene.layers[0].lacquer, wavelength_nm)?.re)
}

fn film(f: &FilmSpec, wavelength_nm: f64) -> Result<Film, PipelineError> {
    Ok(Film {
        index: index(&f.material, wavelength_nm)?,
        thickness_nm: f.thickness_nm,
        thickness_sd_nm: f.thickness_sd_nm,
    })
}

/// A flake's optics at a wavelength.
pub fn reflector(r: &ReflectorSpec, wavelength_nm: f64) -> Result<Reflector, PipelineError> {
    Ok(match r {
        ReflectorSpec::Metal { film: f } => Reflector::Metal(film(f, wavelength_nm)?),
        ReflectorSpec::Spectrum { reflectance, .. } => {
            Reflector::Spectrum(reflectance.at(wavelength_nm))
        }
        ReflectorSpec::Coated { substrate, coating } => Reflector::Coated {
            coating: film(coating, wavelength_nm)?,
            substrate: film(substrate, wavelength_nm)?,
        },
    })
}
