//! shpb-input: TOML scene and set-up files, material and specimen files, gauge files and raw
//! records (CSV) read once and validated into the objects of `shpb-core`. This crate owns every
//! "file, key, allowed range" error ([`Error`]) and the one unit parser ([`units`]).
//!
//! The readers are extension traits on the core types (`Params::from_file`,
//! `Apparatus::from_file`, …); `use shpb_input::prelude::*` brings them into scope.

#![warn(missing_docs)]

pub mod builtin;
pub mod channel_file;
pub mod csv;
pub mod cylinder;
pub mod deck;
pub mod distribution;
pub mod error;
pub mod files;
pub mod gauges;
pub mod kinds;
pub mod layout;
pub mod material;
pub mod provenance;
pub mod resources;
pub mod scene;
pub mod setup;
pub mod shots;
pub mod specimen;
pub mod specimen_file;
mod toml_file;
pub mod uncertainty;
pub mod units;

pub use error::{Error, Result, Validator};

/// The reader traits, to `use shpb_input::prelude::*`.
pub mod prelude {
    pub use crate::gauges::{GaugeSetupFile, RawRecordFile};
    pub use crate::material::MaterialFile;
    pub use crate::scene::SceneFile;
    pub use crate::setup::ApparatusFile;
}
