//! Fixtures shared by the command-line tests: the repository root, running the `shpb` binary
//! in a directory, and its output as text. (`mod common;` in a test file; not every test file
//! uses every helper.)
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root (scenes, bars, validation data).
pub fn repo() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The path of a repository file as a string.
pub fn repo_path(rel: &str) -> String {
    repo().join(rel).display().to_string()
}

/// Runs `shpb ARGS` in `dir` with extra environment variables (and no `SHPB_MEMORY_LIMIT`
/// inherited from the caller's environment).
pub fn shpb_env(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_shpb"));
    c.current_dir(dir)
        .args(args)
        .env_remove("SHPB_MEMORY_LIMIT");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run the shpb binary")
}

/// Runs `shpb ARGS` in `dir`.
pub fn shpb(dir: &Path, args: &[&str]) -> Output {
    shpb_env(dir, args, &[])
}

/// Standard output as text.
pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}
