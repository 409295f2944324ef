//! Embeds the validation reference data in the library, so that `shpb validate` runs from any
//! directory: the repository's `validation/` (its `*.toml` and `*.csv` files, at any depth),
//! `bars/*.toml` and `specimens/*.toml` become `$OUT_DIR/embedded.rs`:
//! `pub static FILES: &[(&str, &[u8])] = &[("validation/…", include_bytes!("/abs/path")), …];`
//! (paths relative to the repository root, `/`-separated, sorted).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// (directory below the repository root, whether to descend, file extensions kept).
const SOURCES: &[(&str, bool, &[&str])] = &[
    ("validation", true, &["toml", "csv"]),
    ("bars", false, &["toml"]),
    ("specimens", false, &["toml"]),
];

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let root = manifest.join("../..");
    let root = root.canonicalize().unwrap_or(root);
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    for (dir, recursive, extensions) in SOURCES {
        let path = root.join(dir);
        println!("cargo:rerun-if-changed={}", path.display());
        if !path.is_dir() {
            println!(
                "cargo:warning=shpb-validate: no {} to embed; `shpb validate` will need --data",
                path.display()
            );
            continue;
        }
        collect(&path, dir, *recursive, extensions, &mut files);
    }
    files.sort();
    let mut out = String::from(
        "/// The embedded reference data: (path relative to the repository root, contents).\n\
         pub static FILES: &[(&str, &[u8])] = &[\n",
    );
    for (relative, absolute) in &files {
        let absolute = absolute.to_str().expect("UTF-8 repository path");
        writeln!(out, "    ({relative:?}, include_bytes!({absolute:?})),").expect("string");
    }
    out.push_str("];\n");
    let target = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo")).join("embedded.rs");
    std::fs::write(&target, out).expect("write embedded.rs");
}

/// Adds the files of `dir` (named `relative` below the root) whose extension is one of
/// `extensions`, descending into subdirectories when `recursive`.
fn collect(
    dir: &Path,
    relative: &str,
    recursive: bool,
    extensions: &[&str],
    files: &mut Vec<(String, PathBuf)>,
) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("read {}: {e}", dir.display()));
    for entry in entries {
        let entry = entry.unwrap_or_else(|e| panic!("read {}: {e}", dir.display()));
        let path = entry.path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        let name = format!("{relative}/{name}");
        if path.is_dir() {
            if recursive {
                collect(&path, &name, recursive, extensions, files);
            }
        } else if path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| extensions.contains(&e))
        {
            files.push((name, path));
        }
    }
}
