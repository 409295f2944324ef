//! The subcommands of `shpb`, one file each, and the helpers they share ([`common`]).

pub mod bench;
pub mod calibrate;
pub mod common;
pub mod convergence;
pub mod curve;
pub mod design;
pub mod fit;
pub mod gun;
pub mod incident;
pub mod list;
pub mod merge;
pub mod reduce;
pub mod run;
pub mod setup;
pub mod strain;
pub mod study;
pub mod sweep;
pub mod validate;
