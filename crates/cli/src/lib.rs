//! shpb — a split Hopkinson pressure bar virtual-experiment simulator built on the
//! strain-rate-dependent elastoplastic sphere contact law of Burgoyne & Daraio,
//! Phys. Rev. E 89, 032203 (2014).
//!
//! This crate is the `shpb` command line ([`cli`]) and the facade of the workspace: it re-exports
//! the layers so that `shpb::bar`, `shpb::scene::Params` or `shpb::io::write_hdf5` name the same
//! items as `shpb_core::bar`, … (see ARCHITECTURE.md for the map):
//! `shpb-core` (physics and numerics) ← `shpb-input` (files → validated core objects) ←
//! `shpb-output` (writers) ← `shpb-study` (sweeps, uncertainty studies, convergence, bench) ←
//! `shpb-validate`.

#![warn(missing_docs)]

pub mod cli;
pub mod cmd;
pub mod interrupt;

pub use shpb_core::{
    apparatus, bar, contact, estimate, fidelity, gauge, material, numeric, reduce, run, shaper,
    solver, specimen, striker, uncertainty,
};
pub use shpb_input::{
    Error, Result, Validator, csv, distribution, error, gauges, kinds, provenance, resources, units,
};
pub use shpb_output::{batch, io, plot, study as study_table, writer};
pub use shpb_study::{
    api, band, bench, convergence, file as study_file, identity as study_identity, sweep, uq,
};
pub use shpb_validate as validate;

/// The scenes: the validated [`scene::Params`] of the core and the scene-file reader of the input
/// layer ([`scene::SceneFile`]).
pub mod scene {
    pub use shpb_core::scene::*;
    pub use shpb_input::scene::*;
}

/// The reader traits (`Params::from_file`, `Apparatus::from_file`, …).
pub mod prelude {
    pub use shpb_input::prelude::*;
}
