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

/// `shpb run SCENE --plot` of the repository scene `scene` draws a cylinder test's figure
/// (three panels of 800 × 620 pixels across above the bars' x–t diagram, 2400 × 1300 in all),
/// a PNG with the specimen's own curves (solid orange) and the 1-wave reduction (dashed dark
/// red) in both specimen panels (the second and third): more than 300 pixels of each.
pub fn assert_cylinder_figure(scene: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let out = shpb(tmp.path(), &["run", &repo_path(scene), "--plot", "c.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let png = std::fs::read(tmp.path().join("c.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));
    let img = image::load_from_memory(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (2400, 1300));
    let pixels_in = |panel: u32, rgb: [u8; 3]| {
        (800 * panel..800 * (panel + 1))
            .flat_map(|x| (0..620).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0 == rgb)
            .count()
    };
    for panel in [1, 2] {
        let own = pixels_in(panel, [230, 140, 20]);
        let reduced = pixels_in(panel, [140, 20, 20]);
        assert!(
            own > 300 && reduced > 300,
            "{scene}, panel {panel}: {own}, {reduced}"
        );
    }
}
