//! shpb-study: many runs of one scene. Parameter sweeps (`shpb sweep`, `merge`, `--resume`),
//! uncertainty studies (`shpb study`: Latin-hypercube samples of a scene's distributions, [`uq`]),
//! the convergence of a scene under refinement (`shpb convergence`), the speed/accuracy bench
//! of the fidelity presets (`shpb bench`), and the design search for inputs that meet a target
//! (`shpb design`).

#![warn(missing_docs)]

pub mod api;
pub mod band;
pub mod bench;
pub mod calibrate;
pub mod convergence;
pub mod design;
pub mod file;
pub mod fit;
pub mod identity;
pub mod strain_factor;
pub mod sweep;
pub mod uq;

pub use shpb_input::{Error, Result};
