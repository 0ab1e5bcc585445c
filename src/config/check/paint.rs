//! `[paint]`: an effect paint's layers (lacquer, pigments, flakes), its
//! ground, spectrum, colour conditions, sparkle conditions and model
//! resolution, each value against its range; every material against every
//! wavelength; the input hash over the file's tables and data files.

use super::scene::{hex_digest, result_defining_text};
use super::{Checker, MAX_POLAR_DEG};
use crate::config::paint::{
    FilmSpec, FlakeSpec, PaintGround, PaintLayerSpec, PaintModel, PaintPigment, PaintScene,
    ReflectorSpec, SparkleSpec, DEFAULT_ACCEPTANCE_DEG, DEFAULT_SPARKLE_ILLUMINATION_DEG,
    DEFAULT_VIEWING_DISTANCE_MM, MAX_FLAKE_FRACTION, MAX_LACQUER_MISMATCH, MAX_PAINT_LAYERS,
};
use crate::config::raw::RawMaterial;
use crate::config::raw_paint::{
    RawFilm, RawFlakes, RawPaintConfig, RawPaintGround, RawPaintLayer, RawPaintModel, RawReflector,
    RawSparkle,
};
use crate::config::{
    ConfigError, GroundReflectance, Material, Provenance, DEFAULT_PAPER_ALBEDO,
    DEFAULT_WHITE_ALBEDO, MAX_PVC,
};
use sha2::{Digest, Sha256};
use std::path::Path;

/// Thickest paint layer, µm.
const MAX_LAYER_UM: f64 = 1000.0;
/// Largest flake diameter, µm.
const MAX_FLAKE_DIAMETER_UM: f64 = 500.0;
/// Largest film of a flake, nm.
const MAX_FILM_NM: f64 = 5000.0;
/// Largest tilt spread of the flakes' normals, degrees.
const MAX_ORIENTATION_SD_DEG: f64 = 45.0;

impl Checker<'_> {
    pub(super) fn paint(
        &self,
        path: &Path,
        text: &str,
        raw: RawPaintConfig,
    ) -> Result<PaintScene, ConfigError> {
        let p = &raw.paint;
        let (wavelengths_nm, wl_key) = self.wavelength_list(
            "paint",
            p.wavelengths_nm.as_ref(),
            p.wavelength_range_nm.as_ref(),
        )?;
        let (illuminant, observer) =
            self.colour_conditions("paint", p.illuminant.as_deref(), p.observer_deg)?;
        if p.layer.is_empty() {
            return Err(self.invalid(
                "paint.layer",
                "at least one [[paint.layer]] table is required (from the top down)",
            ));
        }
        if p.layer.len() > MAX_PAINT_LAYERS {
            return Err(self.invalid(
                "paint.layer",
                format!("at most {MAX_PAINT_LAYERS} layers, got {}", p.layer.len()),
            ));
        }
        let mut layers = Vec::with_capacity(p.layer.len());
        for (i, l) in p.layer.iter().enumerate() {
            layers.push(self.paint_layer(l, &format!("paint.layer[{i}]"), &wavelengths_nm)?);
        }
        let ground = self.paint_ground(&p.ground, &wavelengths_nm)?;
        let sparkle = self.sparkle(p.sparkle.as_ref())?;
        let model = self.paint_model(p.model.as_ref())?;
        let output = self.output(path, raw.output.as_ref())?;

        let mut materials: Vec<(&Material, String)> = Vec::new();
        for (i, l) in layers.iter().enumerate() {
            materials.push((&l.lacquer, format!("paint.layer[{i}].lacquer")));
            for (j, pg) in l.pigments.iter().enumerate() {
                materials.push((&pg.material, format!("paint.layer[{i}].pigment[{j}]")));
            }
            if let Some(f) = &l.flakes {
                match &f.reflector {
                    ReflectorSpec::Metal { film } => {
                        materials.push((&film.material, format!("paint.layer[{i}].flakes")))
                    }
                    ReflectorSpec::Coated { substrate, coating } => {
                        materials.push((&substrate.material, format!("paint.layer[{i}].flakes")));
                        materials.push((&coating.material, format!("paint.layer[{i}].flakes")));
                    }
                    ReflectorSpec::Spectrum { .. } => {}
                }
            }
        }
        if let PaintGround::Metal(m) = &ground {
            materials.push((&**m, "paint.ground".into()));
        }
        self.coverage(wl_key, &wavelengths_nm, &materials)?;
        self.one_lacquer(&layers, &wavelengths_nm)?;

        let mut hasher = Sha256::new();
        hasher.update(result_defining_text(text).as_bytes());
        for (m, _) in &materials {
            hasher.update(m.table_bytes());
        }
        for l in &layers {
            if let Some(FlakeSpec {
                reflector: ReflectorSpec::Spectrum { reflectance, .. },
                ..
            }) = &l.flakes
            {
                hasher.update(&reflectance.bytes);
            }
        }
        if let PaintGround::Lambertian(GroundReflectance::Spectrum(s)) = &ground {
            hasher.update(&s.bytes);
        }
        Ok(PaintScene {
            provenance: Provenance {
                path: path.to_path_buf(),
                text: text.to_string(),
                input_hash: hex_digest(hasher),
            },
            wavelengths_nm,
            illuminant,
            observer,
            layers,
            ground,
            sparkle,
            model,
            output,
        })
    }

    fn paint_layer(
        &self,
        raw: &RawPaintLayer,
        key: &str,
        wavelengths_nm: &[f64],
    ) -> Result<PaintLayerSpec, ConfigError> {
        let k = |field: &str| format!("{key}.{field}");
        let name = raw.name.trim();
        if name.is_empty() {
            return Err(self.invalid(k("name"), "must not be empty"));
        }
        let thickness_um = self.range(
            &k("thickness_um"),
            raw.thickness_um,
            raw.thickness_um > 0.0 && raw.thickness_um <= MAX_LAYER_UM,
            &format!("(0, {MAX_LAYER_UM}] µm"),
        )?;
        let lacquer = self.material(&raw.lacquer, &k("lacquer"))?;
        let mut pigments = Vec::with_capacity(raw.pigment.len());
        for (j, pg) in raw.pigment.iter().enumerate() {
            let pk = |field: &str| format!("{key}.pigment[{j}].{field}");
            if pg.name.trim().is_empty() {
                return Err(self.invalid(pk("name"), "must not be empty"));
            }
            let volume_fraction = self.range(
                &pk("pvc"),
                pg.pvc,
                pg.pvc > 0.0 && pg.pvc <= MAX_PVC,
                &format!("(0, {MAX_PVC}]"),
            )?;
            let largest_nm = thickness_um * 1000.0;
            let diameter_nm = self.range(
                &pk("diameter_nm"),
                pg.diameter_nm,
                pg.diameter_nm > 0.0 && pg.diameter_nm <= largest_nm,
                &format!("(0, {largest_nm}] nm (the layer's thickness)"),
            )?;
            pigments.push(PaintPigment {
                name: pg.name.trim().to_string(),
                material: self.material(&pg.material, &pk("material"))?,
                volume_fraction,
                diameter_nm,
                size: self.grain_size(pg.size.as_ref(), &pk("size"))?,
            });
        }
        let flakes = match &raw.flakes {
            None => None,
            Some(f) => Some(self.flakes(f, &k("flakes"), thickness_um, wavelengths_nm)?),
        };
        let total: f64 = pigments.iter().map(|p| p.volume_fraction).sum::<f64>()
            + flakes.as_ref().map_or(0.0, |f| f.volume_fraction);
        if total > MAX_PVC {
            return Err(self.invalid(
                k("pigment"),
                format!(
                    "pigments and flakes fill {total:.3} of the layer; at most {MAX_PVC} in all"
                ),
            ));
        }
        Ok(PaintLayerSpec {
            name: name.to_string(),
            thickness_um,
            lacquer,
            pigments,
            flakes,
        })
    }

    fn flakes(
        &self,
        raw: &RawFlakes,
        key: &str,
        layer_um: f64,
        wavelengths_nm: &[f64],
    ) -> Result<FlakeSpec, ConfigError> {
        let k = |field: &str| format!("{key}.{field}");
        let volume_fraction = self.range(
            &k("volume_fraction"),
            raw.volume_fraction,
            raw.volume_fraction > 0.0 && raw.volume_fraction <= MAX_FLAKE_FRACTION,
            &format!("(0, {MAX_FLAKE_FRACTION}]"),
        )?;
        let diameter_um = self.range(
            &k("diameter_um"),
            raw.diameter_um,
            raw.diameter_um > 0.0 && raw.diameter_um <= MAX_FLAKE_DIAMETER_UM,
            &format!("(0, {MAX_FLAKE_DIAMETER_UM}] µm"),
        )?;
        let sd = raw.diameter_sd_um.unwrap_or(0.0);
        let diameter_sd_um = self.range(
            &k("diameter_sd_um"),
            sd,
            sd >= 0.0 && sd <= diameter_um,
            &format!("[0, diameter_um] = [0, {diameter_um}] µm"),
        )?;
        let orientation_sd_deg = self.range(
            &k("orientation_sd_deg"),
            raw.orientation_sd_deg,
            (0.0..=MAX_ORIENTATION_SD_DEG).contains(&raw.orientation_sd_deg),
            &format!("[0, {MAX_ORIENTATION_SD_DEG}] degrees"),
        )?;
        let rk = |field: &str| format!("{key}.reflector.{field}");
        let reflector = match &raw.reflector {
            RawReflector::Metal {
                material,
                thickness_nm,
                thickness_sd_nm,
            } => ReflectorSpec::Metal {
                film: Box::new(self.film(
                    material,
                    *thickness_nm,
                    *thickness_sd_nm,
                    &format!("{key}.reflector"),
                )?),
            },
            RawReflector::Spectrum { csv, thickness_nm } => ReflectorSpec::Spectrum {
                reflectance: self.ground_spectrum(&rk("csv"), csv, wavelengths_nm)?,
                thickness_nm: self.film_thickness(&rk("thickness_nm"), *thickness_nm)?,
            },
            RawReflector::Coated { substrate, coating } => ReflectorSpec::Coated {
                substrate: Box::new(self.coated_film(substrate, &rk("substrate"))?),
                coating: Box::new(self.coated_film(coating, &rk("coating"))?),
            },
        };
        let flake = FlakeSpec {
            volume_fraction,
            diameter_um,
            diameter_sd_um,
            orientation_sd_deg,
            diffraction: raw.diffraction.unwrap_or(true),
            reflector,
        };
        if flake.thickness_nm() / 1000.0 > layer_um {
            return Err(self.invalid(
                k("reflector"),
                format!(
                    "a flake {} nm thick does not fit the layer of {layer_um} µm",
                    flake.thickness_nm()
                ),
            ));
        }
        Ok(flake)
    }

    fn film_thickness(&self, key: &str, v: f64) -> Result<f64, ConfigError> {
        self.range(
            key,
            v,
            v > 0.0 && v <= MAX_FILM_NM,
            &format!("(0, {MAX_FILM_NM}] nm"),
        )
    }

    fn coated_film(&self, raw: &RawFilm, key: &str) -> Result<FilmSpec, ConfigError> {
        self.film(&raw.material, raw.thickness_nm, raw.thickness_sd_nm, key)
    }

    fn film(
        &self,
        material: &RawMaterial,
        thickness_nm: f64,
        thickness_sd_nm: Option<f64>,
        key: &str,
    ) -> Result<FilmSpec, ConfigError> {
        let thickness_nm = self.film_thickness(&format!("{key}.thickness_nm"), thickness_nm)?;
        let sd = thickness_sd_nm.unwrap_or(0.0);
        let thickness_sd_nm = self.range(
            &format!("{key}.thickness_sd_nm"),
            sd,
            sd >= 0.0 && sd <= 0.5 * thickness_nm,
            &format!("[0, thickness_nm / 2] = [0, {}] nm", 0.5 * thickness_nm),
        )?;
        Ok(FilmSpec {
            material: self.material(material, &format!("{key}.material"))?,
            thickness_nm,
            thickness_sd_nm,
        })
    }

    fn paint_ground(
        &self,
        raw: &RawPaintGround,
        wavelengths_nm: &[f64],
    ) -> Result<PaintGround, ConfigError> {
        let albedo = |a: Option<f64>, default: f64| {
            let a = a.unwrap_or(default);
            self.range("paint.ground.albedo", a, (0.0..=1.0).contains(&a), "[0, 1]")
        };
        Ok(match raw {
            RawPaintGround::Black {} => PaintGround::Black,
            RawPaintGround::White { albedo: a } => PaintGround::Lambertian(
                GroundReflectance::Constant(albedo(*a, DEFAULT_WHITE_ALBEDO)?),
            ),
            RawPaintGround::Paper { albedo: a } => PaintGround::Lambertian(
                GroundReflectance::Constant(albedo(*a, DEFAULT_PAPER_ALBEDO)?),
            ),
            RawPaintGround::Csv { file } => PaintGround::Lambertian(GroundReflectance::Spectrum(
                self.ground_spectrum("paint.ground.file", file, wavelengths_nm)?,
            )),
            RawPaintGround::Metal { material } => {
                PaintGround::Metal(Box::new(self.material(material, "paint.ground.material")?))
            }
        })
    }

    fn sparkle(&self, raw: Option<&RawSparkle>) -> Result<SparkleSpec, ConfigError> {
        let d = raw
            .and_then(|s| s.viewing_distance_mm)
            .unwrap_or(DEFAULT_VIEWING_DISTANCE_MM);
        let viewing_distance_mm = self.range(
            "paint.sparkle.viewing_distance_mm",
            d,
            d > 0.0 && d <= 100_000.0,
            "(0, 100000] mm",
        )?;
        let illumination_deg = match raw.and_then(|s| s.illumination_deg.as_ref()) {
            None => DEFAULT_SPARKLE_ILLUMINATION_DEG.to_vec(),
            Some(list) => {
                let key = "paint.sparkle.illumination_deg";
                if list.is_empty() {
                    return Err(self.invalid(key, "must not be empty"));
                }
                self.increasing(
                    key,
                    list,
                    |a| (0.0..=MAX_POLAR_DEG).contains(&a),
                    &format!("[0, {MAX_POLAR_DEG}] degrees"),
                )?;
                list.clone()
            }
        };
        let a = raw
            .and_then(|s| s.acceptance_deg)
            .unwrap_or(DEFAULT_ACCEPTANCE_DEG);
        let acceptance_deg = self.range(
            "paint.sparkle.acceptance_deg",
            a,
            a > 0.0 && a <= 10.0,
            "(0, 10] degrees",
        )?;
        Ok(SparkleSpec {
            viewing_distance_mm,
            illumination_deg,
            acceptance_deg,
            seed: raw.and_then(|s| s.seed).unwrap_or(1),
        })
    }

    fn paint_model(&self, raw: Option<&RawPaintModel>) -> Result<PaintModel, ConfigError> {
        let Some(m) = raw else {
            return Ok(PaintModel::default());
        };
        let count = |key: &str, v: Option<i64>, lo: i64, hi: i64| match v {
            None => Ok(None),
            Some(v) if (lo..=hi).contains(&v) => Ok(Some(v as usize)),
            Some(v) => Err(self.invalid(
                format!("paint.model.{key}"),
                format!("must be in [{lo}, {hi}], got {v}"),
            )),
        };
        Ok(PaintModel {
            trapped_nodes: count("trapped_nodes", m.trapped_nodes, 1, 64)?,
            escape_nodes: count("escape_nodes", m.escape_nodes, 4, 64)?,
            max_terms: count("max_terms", m.max_terms, 1, 256)?,
        })
    }

    /// Every layer's lacquer has the top layer's real index within
    /// [`MAX_LACQUER_MISMATCH`] at every wavelength.
    fn one_lacquer(
        &self,
        layers: &[PaintLayerSpec],
        wavelengths_nm: &[f64],
    ) -> Result<(), ConfigError> {
        let n = |m: &Material, wl: f64| m.index_at(wl).map_or(f64::NAN, |c| c.re);
        for &wl in wavelengths_nm {
            let top = n(&layers[0].lacquer, wl);
            self.range(
                "paint.layer[0].lacquer",
                top,
                (1.0..=3.0).contains(&top),
                &format!("n in [1, 3] (at {wl} nm)"),
            )?;
            for (i, l) in layers.iter().enumerate().skip(1) {
                let v = n(&l.lacquer, wl);
                if (v - top).abs() > MAX_LACQUER_MISMATCH {
                    return Err(self.invalid(
                        format!("paint.layer[{i}].lacquer"),
                        format!(
                            "n = {v} at {wl} nm; the layers share one lacquer index (the fast \
                             model's layer boundaries do not reflect): it must be within \
                             {MAX_LACQUER_MISMATCH} of the top layer's {top}"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}
