//! Datasets that explain themselves: every dataset inksim writes carries
//! string attributes `units` (UCUM-like: `nm`, `deg`, `sr-1`, `s`, `1` for
//! dimensionless; `""` only for text, labels and encoded bytes, which its
//! description says) and `description` (what it is, its axes in order),
//! and labels on its dimensions; a dimension whose coordinates the file
//! holds gets that dataset attached as its HDF5 dimension scale.
//!
//! [`About`] is the one statement of a dataset's units, meaning and axes,
//! given where the dataset is written; [`Scales`] writes it.

use hdf5::{Dataset, Group, H5Type};
use ndarray::{ArrayView, Dimension};

use super::attrs::write_str_attr;
use super::scales::{attach_scale, set_label, set_scale};

/// Units, meaning and axes (one name per dimension, in order) of a dataset.
#[derive(Debug, Clone, Copy)]
pub(crate) struct About<'a> {
    pub units: &'a str,
    pub description: &'a str,
    pub dims: &'a [&'a str],
}

/// Shorthand for an [`About`].
pub(crate) const fn about<'a>(
    units: &'a str,
    description: &'a str,
    dims: &'a [&'a str],
) -> About<'a> {
    About {
        units,
        description,
        dims,
    }
}

/// The coordinate datasets of one file, each the scale of the dimension it
/// names; datasets written later with that dimension get it attached.
#[derive(Default)]
pub(crate) struct Scales(Vec<(String, Dataset)>);

impl Scales {
    /// Write `data` as `name` in `g`, described by `a`.
    pub fn write<'d, T, D, A>(
        &self,
        g: &Group,
        name: &str,
        data: A,
        a: About,
    ) -> hdf5::Result<Dataset>
    where
        T: H5Type + 'd,
        D: Dimension,
        A: Into<ArrayView<'d, T, D>>,
    {
        let d = g.new_dataset_builder().with_data(data).create(name)?;
        self.describe(&d, a)?;
        Ok(d)
    }

    /// Write a 1-D coordinate and make it the scale of dimension `a.dims[0]`.
    pub fn coordinate<T: H5Type>(
        &mut self,
        g: &Group,
        name: &str,
        data: &[T],
        a: About,
    ) -> hdf5::Result<Dataset> {
        let d = self.write(g, name, data, a)?;
        let dim = a.dims[0];
        set_scale(&d, dim)?;
        self.0.push((dim.to_string(), d.clone()));
        Ok(d)
    }

    /// Stop attaching the scale of `dim` (a coordinate local to one group).
    pub fn forget(&mut self, dim: &str) {
        self.0.retain(|(n, _)| n != dim);
    }

    /// Describe an existing dataset `d` by `a`: attributes `units` and
    /// `description`, dimension labels and the scales of its dimensions.
    pub fn describe(&self, d: &Dataset, a: About) -> hdf5::Result<()> {
        let shape = d.shape();
        if a.dims.len() != shape.len() {
            return Err(hdf5::Error::from(format!(
                "{}: {} axis names {:?} for {} dimensions",
                d.name(),
                a.dims.len(),
                a.dims,
                shape.len()
            )));
        }
        write_str_attr(d, "units", a.units)?;
        write_str_attr(d, "description", a.description)?;
        for (i, dim) in a.dims.iter().enumerate() {
            set_label(d, i, dim)?;
            let Some((_, scale)) = self.0.iter().find(|(n, _)| n == dim) else {
                continue;
            };
            if scale.size() != shape[i] {
                return Err(hdf5::Error::from(format!(
                    "{}: dimension {i} ({dim}) has {} values but its scale {} has {}",
                    d.name(),
                    shape[i],
                    scale.name(),
                    scale.size()
                )));
            }
            attach_scale(d, scale, i)?;
        }
        Ok(())
    }
}

/// `about.description` for the standard errors of a quantity.
pub(crate) fn standard_error(description: &str) -> String {
    format!("standard error of the mean over the realisations of: {description}")
}

/// Axis names shared by the writers (and by the Python package's layout
/// table, python/src/inksim/_layout.py).
pub(crate) mod dim {
    pub const WAVELENGTH: &str = "wavelength_nm";
    pub const ABOVE: &str = "above_deg";
    pub const ILLUMINATION: &str = "illumination_deg";
    pub const VIEWING: &str = "viewing_deg";
    pub const BELOW: &str = "below_deg";
    /// Table nodes: rows along s_y = sin θ sin φ, columns along s_x.
    pub const SY: &str = "sy";
    pub const SX: &str = "sx";
    /// Tile cells: 0 the white-sky strip, then one per illumination angle.
    pub const TILE_COLUMN: &str = "tile_column";
    pub const REALISATION: &str = "realisation";
    pub const SOLVE: &str = "solve";
    pub const ORDER: &str = "order";
    /// The two order indices m, n.
    pub const MN: &str = "mn";
    pub const SPHERE: &str = "sphere";
    pub const PARTICLE: &str = "particle";
    pub const SPECIES: &str = "species";
    pub const CLUSTER: &str = "cluster";
    /// Edges of the z bins of the volume profile (one more than `Z`).
    pub const Z_EDGE: &str = "z_edge";
    pub const Z: &str = "z";
    pub const R: &str = "r";
    /// Components x, y, z of a position.
    pub const XYZ: &str = "xyz";
    /// Components X, Y, Z of a CIE colour.
    pub const TRISTIMULUS: &str = "tristimulus";
    pub const LAB: &str = "lab";
    pub const LCH: &str = "lch";
    pub const RGB: &str = "rgb";
    pub const SPECTRUM_WAVELENGTH: &str = "spectrum_wavelength_nm";
    pub const VALUE: &str = "value";
    /// Bytes of an encoded file (PNG).
    pub const BYTE: &str = "byte";
    pub const VARIANT: &str = "variant";
}
