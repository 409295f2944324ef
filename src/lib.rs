//! shpb — a split Hopkinson pressure bar virtual-experiment simulator built on the
//! strain-rate-dependent elastoplastic sphere contact law of Burgoyne & Daraio,
//! Phys. Rev. E 89, 032203 (2014).
//!
//! Modules read top-down like the test itself: materials and specimens, the contact law,
//! scenes, the solver, input/output and the command line.

#![warn(missing_docs)]

pub mod apparatus;
pub mod bar;
pub mod bench;
pub mod cli;
pub mod contact;
pub mod convergence;
pub mod error;
pub mod fidelity;
pub mod gauge;
pub mod io;
pub mod material;
pub mod plot;
pub mod reduce;
pub mod scene;
pub mod shaper;
pub mod solver;
pub mod specimen;
pub mod striker;
pub mod sweep;
pub mod validate;

pub use error::{Error, Result};
