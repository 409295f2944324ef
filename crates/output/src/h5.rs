//! HDF5 helpers shared by the writers: error mapping, string attributes, datasets with units.

use hdf5::types::VarLenUnicode;
use shpb_input::{Error, Result};
use std::path::Path;
use std::str::FromStr;

/// Converts an HDF5 error into the crate's error naming `file`.
pub fn h5err(file: &Path) -> impl Fn(hdf5::Error) -> Error + '_ {
    move |e| Error::Hdf5 {
        file: file.display().to_string(),
        message: e.to_string(),
    }
}

/// An HDF5 variable-length UTF-8 string.
pub fn vlu(s: &str) -> VarLenUnicode {
    VarLenUnicode::from_str(s)
        .unwrap_or_else(|_| VarLenUnicode::from_str("").expect("empty string is valid"))
}

/// Writes a string attribute.
pub fn string_attr(loc: &hdf5::Location, name: &str, value: &str, file: &Path) -> Result<()> {
    loc.new_attr::<VarLenUnicode>()
        .shape(())
        .create(name)
        .and_then(|a| a.write_scalar(&vlu(value)))
        .map_err(h5err(file))
}

/// Writes a 1-D f64 dataset with a `units` attribute.
pub fn write_dataset(
    group: &hdf5::Group,
    name: &str,
    data: &[f64],
    units: &str,
    file: &Path,
) -> Result<()> {
    let ds = group
        .new_dataset_builder()
        .with_data(data)
        .create(name)
        .map_err(h5err(file))?;
    string_attr(&ds, "units", units, file)
}
