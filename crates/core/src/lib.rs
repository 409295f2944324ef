//! shpb-core: the physics and numerics of a split Hopkinson pressure bar test built on the
//! strain-rate-dependent elastoplastic sphere contact law of Burgoyne & Daraio, Phys. Rev. E 89,
//! 032203 (2014). Every equation is written out in `docs/physics.md`, which the items cite.
//!
//! This crate reads no file and knows no configuration format: it receives validated numbers
//! (SI units) and returns typed errors ([`Error`]). The modules follow the test from the gun to the
//! reduction: materials and specimens, the contact law, bars, striker and gun, shaper, gauges,
//! the apparatus, solvers, scenes and their runs, and the laboratory's data reduction.

#![warn(missing_docs)]

pub mod apparatus;
pub mod bar;
pub mod contact;
pub mod dispersion;
pub mod error;
pub mod estimate;
pub mod fidelity;
pub mod filter;
#[cfg(test)]
mod fixtures;
pub mod flow;
pub mod gauge;
pub mod loading;
pub mod material;
pub mod numeric;
pub mod reduce;
/// The cylinder analysis under its former name (now the specimen stage of the reduction).
pub use reduce::specimen as reduce_cylinder;
pub mod run;
pub mod scene;
pub mod shaper;
pub mod solver;
pub mod specimen;
pub mod striker;
pub mod transit;
pub mod uncertainty;

pub use error::{Error, Result};
