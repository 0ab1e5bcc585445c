//! Scalar and string attributes and variable-length UTF-8 strings, shared
//! by the writer and the readers.

use std::str::FromStr;

use hdf5::types::VarLenUnicode;
use hdf5::{H5Type, Location};

pub(crate) fn vlu(s: &str) -> hdf5::Result<VarLenUnicode> {
    VarLenUnicode::from_str(s).map_err(|e| hdf5::Error::from(e.to_string()))
}

pub(crate) fn write_str_attr(loc: &Location, name: &str, value: &str) -> hdf5::Result<()> {
    loc.new_attr::<VarLenUnicode>()
        .shape(())
        .create(name)?
        .write_scalar(&vlu(value)?)
}

pub(crate) fn write_scalar_attr<T: H5Type>(
    loc: &Location,
    name: &str,
    value: T,
) -> hdf5::Result<()> {
    loc.new_attr::<T>()
        .shape(())
        .create(name)?
        .write_scalar(&value)
}

pub(super) fn read_str_attr(loc: &Location, name: &str) -> hdf5::Result<String> {
    let v: VarLenUnicode = loc.attr(name)?.read_scalar()?;
    Ok(v.as_str().to_owned())
}
