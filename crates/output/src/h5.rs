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

/// Opens an HDF5 file for reading. The HDF5 library takes only UTF-8 names, so a name that is
/// not UTF-8 is opened through its file descriptor (`/proc/self/fd/N`, Linux).
pub fn open(path: &Path) -> hdf5::Result<hdf5::File> {
    if path.to_str().is_some() {
        return hdf5::File::open(path);
    }
    let f = std::fs::File::open(path).map_err(|e| hdf5::Error::from(e.to_string()))?;
    hdf5::File::open(fd_path(&f))
}

/// Creates (truncates) an HDF5 file for writing, a name that is not UTF-8 through its file
/// descriptor as in [`open`].
pub fn create(path: &Path) -> hdf5::Result<hdf5::File> {
    if path.to_str().is_some() {
        return hdf5::File::create(path);
    }
    let f = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)
        .map_err(|e| hdf5::Error::from(e.to_string()))?;
    hdf5::File::create(fd_path(&f))
}

/// The `/proc/self/fd` name of an open file.
fn fd_path(f: &std::fs::File) -> String {
    format!("/proc/self/fd/{}", std::os::fd::AsRawFd::as_raw_fd(f))
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
