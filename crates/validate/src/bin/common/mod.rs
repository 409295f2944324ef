//! What the report generators of `validation/` share (each binary includes this module with
//! `mod common;`; it is not a binary itself because it has no `main.rs`).

use std::path::{Path, PathBuf};

/// The repository root the reports are read from and written to: the working directory when it
/// is the root (it holds `bars/authors.toml`, so the relative paths printed stay short), else the
/// workspace root two levels above this crate's manifest (so `cargo run` works from anywhere in
/// the repository).
pub fn repo_root() -> PathBuf {
    if Path::new("bars/authors.toml").is_file() {
        PathBuf::new()
    } else {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        std::fs::canonicalize(&root).unwrap_or(root)
    }
}
