//! HDF5 dimension scales (the high-level `H5DS` API of `libhdf5_hl`):
//! axis labels on every dimension of a dataset and, where the file holds
//! the axis's coordinates (`wavelengths_nm`, `viewing_deg`, …), that
//! dataset attached as the dimension's scale. HDFView, h5py
//! (`ds.dims[i].label`, `ds.dims[i][0]`) and netCDF-aware tools read both.
//!
//! The `hdf5` crate does not bind `H5DS`; the three functions used here are
//! declared below and called under the crate's library lock, like every
//! other HDF5 call.

use std::ffi::{c_char, c_int, c_uint, CString};

use hdf5::Dataset;

/// HDF5 ≥ 1.10 identifiers (`hid_t = int64_t`); `id()` below checks the
/// width at compile time.
type Hid = i64;

#[link(name = "hdf5_hl")]
extern "C" {
    fn H5DSset_scale(dsid: Hid, dimname: *const c_char) -> c_int;
    fn H5DSattach_scale(did: Hid, dsid: Hid, idx: c_uint) -> c_int;
    fn H5DSset_label(did: Hid, idx: c_uint, label: *const c_char) -> c_int;
}

fn id(d: &Dataset) -> Hid {
    d.id()
}

fn text(s: &str) -> hdf5::Result<CString> {
    CString::new(s).map_err(|_| hdf5::Error::from(format!("`{s}` contains a NUL character")))
}

fn check(status: c_int, what: impl FnOnce() -> String) -> hdf5::Result<()> {
    if status < 0 {
        Err(hdf5::Error::from(what()))
    } else {
        Ok(())
    }
}

/// Make `d` the dimension scale called `dim` (HDF5 attributes `CLASS` and
/// `NAME`).
pub(crate) fn set_scale(d: &Dataset, dim: &str) -> hdf5::Result<()> {
    let name = text(dim)?;
    // SAFETY: `d` is an open dataset for the whole call and `name` a valid
    // NUL-terminated string; the library lock serialises HDF5 calls.
    let status = hdf5::sync::sync(|| unsafe { H5DSset_scale(id(d), name.as_ptr()) });
    check(status, || {
        format!("{}: cannot make it scale `{dim}`", d.name())
    })
}

/// Attach scale `scale` to dimension `idx` of `d`.
pub(crate) fn attach_scale(d: &Dataset, scale: &Dataset, idx: usize) -> hdf5::Result<()> {
    let i = c_uint::try_from(idx).map_err(|e| hdf5::Error::from(e.to_string()))?;
    // SAFETY: both datasets are open for the whole call; the library lock
    // serialises HDF5 calls.
    let status = hdf5::sync::sync(|| unsafe { H5DSattach_scale(id(d), id(scale), i) });
    check(status, || {
        format!(
            "{}: cannot attach {} to dimension {idx}",
            d.name(),
            scale.name()
        )
    })
}

/// Label dimension `idx` of `d` (HDF5 attribute `DIMENSION_LABELS`).
pub(crate) fn set_label(d: &Dataset, idx: usize, label: &str) -> hdf5::Result<()> {
    let i = c_uint::try_from(idx).map_err(|e| hdf5::Error::from(e.to_string()))?;
    let l = text(label)?;
    // SAFETY: `d` is open for the whole call and `l` a valid NUL-terminated
    // string; the library lock serialises HDF5 calls.
    let status = hdf5::sync::sync(|| unsafe { H5DSset_label(id(d), i, l.as_ptr()) });
    check(status, || {
        format!("{}: cannot label dimension {idx} `{label}`", d.name())
    })
}
