//! shpb-output: everything shpb writes. One writer trait ([`Writer`]) with one implementation per
//! format (HDF5, CSV, PNG); every file is written atomically (a temporary name in the same
//! directory, then a rename that never replaces an existing file without `--force`).

#![warn(missing_docs)]

pub mod atomic;
pub mod h5;
pub mod io;
pub mod plot;
pub mod reduction;
pub mod writer;

pub use shpb_input::{Error, Result};
pub use writer::{Csv, Hdf5, Png, Writer};
