//! shpb-output: everything shpb writes. One writer trait ([`Writer`]) with one implementation per
//! format (HDF5, CSV, PNG) for a run, and the study file of many runs ([`study::StudyTable`],
//! written and read back by [`study::write_study_hdf5`] and [`study::read_study_hdf5`]). Every
//! file is written atomically: under a temporary name in the same directory, then moved into
//! place by a hard link that fails if the name exists, or with `--force` by a rename
//! ([`atomic`]).

#![warn(missing_docs)]

pub mod atomic;
pub mod batch;
pub mod fit;
pub mod h5;
pub mod io;
pub mod plan;
pub mod plot;
pub mod provenance;
pub mod reduction;
pub mod run_file;
pub mod study;
pub mod writer;

pub use shpb_input::{Error, Result};
pub use writer::{Csv, Hdf5, Png, Writer};
