//! The subcommands of `shpb`, one file each.

pub mod reduce;
