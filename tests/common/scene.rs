//! Scene files built in code: a preset, then only what a test varies.
//!
//! `SceneToml::grains().seed(3).thickness_nm(400.0).wavelengths_nm(&[500.0])`
//! writes the TOML a user would; typed setters cover the keys the tests
//! change, [`SceneToml::set`] / [`SceneToml::raw`] reach any other key by
//! its dotted path (`pigment.0.shape`), and [`SceneToml::without`] drops one.

use super::keys::{self, floats, key_setters, strings, value};
use inksim::config::{parse_scene, ConfigError, Scene};
use inksim::pipeline::{self, RunReport};
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// A scene file under construction.
#[derive(Clone, Debug)]
pub struct SceneToml(Table);

/// One `[[pigment]]` entry.
#[derive(Clone, Debug)]
pub struct PigmentToml(Table);

/// One `[[structure.primitive]]` body and its material.
#[derive(Clone, Debug)]
pub struct PrimitiveToml(Table);

key_setters!(SceneToml);
key_setters!(PigmentToml);

impl SceneToml {
    /// One red pigment (20 % PVC of 200 nm spheres) in a 1 µm layer on a
    /// 2 µm × 2 µm fragment, 25 nm cells, 450/550/650 nm at 0° and 30°;
    /// every other key left to its default.
    pub fn grains() -> Self {
        Self(Table::new())
            .thickness_nm(1000.0)
            .fragment_nm(2000.0)
            .pigment(PigmentToml::builtin("red").pvc(0.2).diameter_nm(200.0))
            .cell_nm(25.0)
            .wavelengths_nm(&[450.0, 550.0, 650.0])
            .polar_deg(&[0.0, 30.0])
    }

    /// The layer of [`grains`](Self::grains) with its pigment dissolved
    /// (`molecular`): a homogeneous slab, solved in closed form.
    pub fn slab() -> Self {
        Self::grains().pigment(PigmentToml::builtin("red").pvc(0.2).molecular())
    }

    /// Red spheres, 15 % PVC of 150 nm, in a 400 nm layer: 20 × 20 × 20
    /// cells, two wavelengths, two angles; results named `tiny`.
    pub fn tiny() -> Self {
        Self::grains()
            .seed(3)
            .thickness_nm(400.0)
            .fragment_nm(500.0)
            .pvc(0.15)
            .diameter_nm(150.0)
            .z_cell_nm(20.0)
            .wavelengths_nm(&[500.0, 600.0])
            .polar_deg(&[0.0, 40.0])
            .tolerance(1e-7)
            .output_name("tiny")
    }

    /// The layer of [`grains`](Self::grains) given as explicit bodies in
    /// the binder instead of pigments.
    pub fn structure(bodies: &[PrimitiveToml]) -> Self {
        let list = bodies.iter().map(|p| Value::Table(p.0.clone())).collect();
        Self::grains()
            .without("pigment")
            .set("structure.kind", "primitives")
            .set("structure.primitive", Value::Array(list))
    }

    /// `structure = { kind = "hdf5", file }`, replacing any structure.
    pub fn structure_file(self, file: &str) -> Self {
        let mut t = Table::new();
        t.insert("kind".into(), "hdf5".into());
        t.insert("file".into(), file.into());
        self.set("structure", t)
    }

    pub fn seed(self, seed: i64) -> Self {
        self.set("seed", seed)
    }

    pub fn realisations(self, n: i64) -> Self {
        self.set("realisations", n)
    }

    pub fn thickness_nm(self, h: f64) -> Self {
        self.set("layer.thickness_nm", h)
    }

    /// A square fragment of side `l`.
    pub fn fragment_nm(self, l: f64) -> Self {
        self.set("layer.fragment_nm", floats(&[l, l]))
    }

    pub fn binder_index(self, n: f64) -> Self {
        self.set("layer.binder_index", n)
    }

    /// The total PVC `layer.pvc`, shared among the pigments.
    pub fn layer_pvc(self, pvc: f64) -> Self {
        self.set("layer.pvc", pvc)
    }

    pub fn relief_fraction(self, f: f64) -> Self {
        self.set("layer.relief_fraction", f)
    }

    pub fn equilibrate_sweeps(self, n: i64) -> Self {
        self.set("layer.equilibrate_sweeps", n)
    }

    /// This pigment alone.
    pub fn pigment(self, p: PigmentToml) -> Self {
        self.set("pigment", Value::Array(vec![Value::Table(p.0)]))
    }

    /// One more pigment.
    pub fn add_pigment(self, p: PigmentToml) -> Self {
        let n = self
            .0
            .get("pigment")
            .and_then(Value::as_array)
            .map_or(0, Vec::len);
        self.set(&format!("pigment.{n}"), p.0)
    }

    /// `pvc` of the first pigment.
    pub fn pvc(self, pvc: f64) -> Self {
        self.set("pigment.0.pvc", pvc)
    }

    /// `diameter_nm` of the first pigment.
    pub fn diameter_nm(self, d: f64) -> Self {
        self.set("pigment.0.diameter_nm", d)
    }

    /// Lateral cell size (the grid from cells, replacing `nx`, `ny`, `nz`).
    pub fn cell_nm(mut self, cell: f64) -> Self {
        for k in ["nx", "ny", "nz"] {
            self.grid_table().remove(k);
        }
        self.set("grid.cell_nm", cell)
    }

    pub fn z_cell_nm(self, cell: f64) -> Self {
        self.set("grid.z_cell_nm", cell)
    }

    /// The grid by its cell counts (replacing `cell_nm`, `z_cell_nm`).
    pub fn grid_n(mut self, n: [i64; 3]) -> Self {
        let g = self.grid_table();
        g.clear();
        for (k, v) in ["nx", "ny", "nz"].into_iter().zip(n) {
            g.insert(k.into(), v.into());
        }
        self
    }

    fn grid_table(&mut self) -> &mut Table {
        self.0
            .entry("grid")
            .or_insert_with(|| Value::Table(Table::new()))
            .as_table_mut()
            .expect("grid is a table")
    }

    /// The wavelength list (replacing a range).
    pub fn wavelengths_nm(mut self, wl: &[f64]) -> Self {
        if let Some(t) = self.0.get_mut("illumination").and_then(Value::as_table_mut) {
            t.remove("wavelength_range_nm");
        }
        self.set("illumination.wavelengths_nm", floats(wl))
    }

    /// `wavelength_range_nm = { start, stop, step }` (replacing the list).
    pub fn wavelength_range_nm(self, start: f64, stop: f64, step: f64) -> Self {
        self.without("illumination.wavelengths_nm").raw(
            "illumination.wavelength_range_nm",
            &format!("{{ start = {start:?}, stop = {stop:?}, step = {step:?} }}"),
        )
    }

    pub fn polar_deg(self, polar: &[f64]) -> Self {
        self.set("illumination.polar_deg", floats(polar))
    }

    pub fn azimuth_deg(self, azimuth: f64) -> Self {
        self.set("illumination.azimuth_deg", azimuth)
    }

    pub fn method(self, name: &str) -> Self {
        self.set("solver.method", name)
    }

    pub fn tolerance(self, tol: f64) -> Self {
        self.set("solver.tolerance", tol)
    }

    pub fn max_iterations(self, n: i64) -> Self {
        self.set("solver.max_iterations", n)
    }

    pub fn precision(self, p: &str) -> Self {
        self.set("solver.precision", p)
    }

    pub fn equation(self, e: &str) -> Self {
        self.set("solver.equation", e)
    }

    pub fn effective_medium_tolerance(self, tol: f64) -> Self {
        self.set("solver.effective_medium_tolerance", tol)
    }

    pub fn energy_balance_limit(self, limit: f64) -> Self {
        self.set("solver.energy_balance_limit", limit)
    }

    /// Results as `dir/name.*`.
    pub fn output(self, dir: &Path, name: &str) -> Self {
        self.set("output.dir", dir.display().to_string())
            .output_name(name)
    }

    pub fn output_name(self, name: &str) -> Self {
        self.set("output.name", name)
    }

    /// `appearance.outputs`: any of "brdf", "btdf", "tile", "merl".
    pub fn outputs(self, products: &[&str]) -> Self {
        self.set("appearance.outputs", strings(products))
    }

    pub fn viewing_deg(self, angles: &[f64]) -> Self {
        self.set("appearance.viewing_deg", floats(angles))
    }

    pub fn quadrature_points(self, n: i64) -> Self {
        self.set("appearance.quadrature_points", n)
    }

    pub fn illuminant(self, name: &str) -> Self {
        self.set("appearance.illuminant", name)
    }

    pub fn observer_deg(self, deg: i64) -> Self {
        self.set("appearance.observer_deg", deg)
    }

    pub fn measurements(self, names: &[&str]) -> Self {
        self.set("appearance.measurements", strings(names))
    }

    /// Lambertian paper of this albedo under the layer.
    pub fn paper(self, albedo: f64) -> Self {
        self.set("substrate.kind", "paper")
            .set("substrate.albedo", albedo)
    }

    /// `substrate = { kind = "none" }`.
    pub fn no_substrate(self) -> Self {
        self.raw("substrate", "{ kind = \"none\" }")
    }

    /// The scene's keys.
    pub fn table(&self) -> &Table {
        &self.0
    }

    /// The scene file's text.
    pub fn toml(&self) -> String {
        keys::text(&self.0)
    }

    /// Writes the text to `dir/scene.toml`; returns that path.
    pub fn write(&self, dir: &Path) -> PathBuf {
        let path = dir.join("scene.toml");
        std::fs::write(&path, self.toml()).unwrap();
        path
    }

    /// Read as the program reads it from a file at `path` (not written).
    pub fn parse(&self, path: &Path) -> Result<Scene, ConfigError> {
        parse_scene(path, &self.toml())
    }

    /// Written to `dir/scene.toml` and read as the program reads it.
    pub fn scene(&self, dir: &Path) -> Scene {
        self.parse(&self.write(dir)).unwrap()
    }

    /// Written to `dir/scene.toml`, read and run.
    pub fn run(&self, dir: &Path) -> RunReport {
        pipeline::run(&self.scene(dir)).unwrap()
    }

    /// This scene with `layers` (each one's `[layer]` and `[[pigment]]`),
    /// top first, as its `[[stack]]` instead of its own layer, coupled
    /// `coupling` (`"incoherent"` or `"coherent"`).
    /// As a layer of a stack: printed on this share of the area.
    pub fn coverage(self, coverage: f64) -> Self {
        self.set("coverage", coverage)
    }

    pub fn stack_of(mut self, layers: &[SceneToml], coupling: &str) -> Self {
        let stack: Vec<Value> = layers
            .iter()
            .map(|l| {
                let mut t = Table::new();
                for key in ["layer", "pigment", "coverage"] {
                    if let Some(v) = l.0.get(key) {
                        t.insert(key.to_string(), v.clone());
                    }
                }
                Value::Table(t)
            })
            .collect();
        self.0.remove("layer");
        self.0.remove("pigment");
        self.0.insert("stack".to_string(), Value::Array(stack));
        self.raw("stacking", &format!("{{ coupling = \"{coupling}\" }}"))
    }
}

impl PigmentToml {
    /// A pigment named after the built-in material it is made of.
    pub fn builtin(name: &str) -> Self {
        Self(Table::new())
            .set("name", name)
            .raw("material", &format!("{{ builtin = \"{name}\" }}"))
    }

    /// A pigment of constant index `n + ik` at every wavelength.
    pub fn index(name: &str, n: f64, k: f64) -> Self {
        Self(Table::new())
            .set("name", name)
            .raw("material", &format!("{{ index = [{n}, {k}] }}"))
    }

    /// A pigment named after the library material it is made of.
    pub fn library(name: &str) -> Self {
        Self(Table::new())
            .set("name", name)
            .raw("material", &format!("{{ library = \"{name}\" }}"))
    }

    /// A pigment from a CSV table of n, k.
    pub fn csv(name: &str, file: &str) -> Self {
        Self(Table::new())
            .set("name", name)
            .raw("material", &format!("{{ csv = \"{file}\" }}"))
    }

    pub fn named(self, name: &str) -> Self {
        self.set("name", name)
    }

    pub fn pvc(self, pvc: f64) -> Self {
        self.set("pvc", pvc)
    }

    /// Part of the layer's total PVC.
    pub fn share(self, share: f64) -> Self {
        self.set("share", share)
    }

    pub fn diameter_nm(self, d: f64) -> Self {
        self.set("diameter_nm", d)
    }

    /// Dissolved: `shape = { kind = "molecular" }`.
    pub fn molecular(self) -> Self {
        self.raw("shape", "{ kind = \"molecular\" }")
    }

    /// `shape`, written as TOML: `{ kind = "rice", aspect = 3.0 }`.
    pub fn shape(self, text: &str) -> Self {
        self.raw("shape", text)
    }

    pub fn orientation(self, o: &str) -> Self {
        self.set("orientation", o)
    }

    pub fn alignment_field(self, f: f64) -> Self {
        self.set("alignment_field", f)
    }
}

impl PrimitiveToml {
    /// The layer between heights `z0` and `z1` (nm), all across.
    pub fn slab(z0: f64, z1: f64) -> Self {
        Self(Table::new()).body(&format!("{{ kind = \"slab\", z_nm = [{z0:?}, {z1:?}] }}"))
    }

    /// A sphere.
    pub fn sphere(center_nm: [f64; 3], radius_nm: f64) -> Self {
        let [x, y, z] = center_nm;
        Self(Table::new()).body(&format!(
            "{{ kind = \"sphere\", center_nm = [{x:?}, {y:?}, {z:?}], radius_nm = {radius_nm:?} }}"
        ))
    }

    fn body(mut self, text: &str) -> Self {
        self.0.insert("shape".into(), value(text));
        self
    }

    /// Made of the constant index `n + ik`.
    pub fn index(mut self, n: f64, k: f64) -> Self {
        self.0.insert(
            "material".into(),
            value(&format!("{{ index = [{n:?}, {k:?}] }}")),
        );
        self
    }

    /// Made of a built-in material.
    pub fn builtin(mut self, name: &str) -> Self {
        self.0.insert(
            "material".into(),
            value(&format!("{{ builtin = \"{name}\" }}")),
        );
        self
    }
}

/// A CSV material of constant index n + 0i over 380–780 nm.
pub fn constant_material(dir: &Path, name: &str, n: f64) -> String {
    let mut text = String::from("wavelength_nm,n,k\n");
    for wl in (380..=780).step_by(20) {
        text.push_str(&format!("{wl},{n},0\n"));
    }
    std::fs::write(dir.join(format!("{name}.csv")), text).unwrap();
    format!("{name}.csv")
}
