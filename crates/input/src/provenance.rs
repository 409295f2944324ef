//! Which files a scene resolves: every input file read through [`read_to_string`] (the scene,
//! its set-up, gauge, material and pair files, CSV records) is hashed (SHA-256) and, while
//! [`recording`] runs, listed. A sweep records the files of its scene this way, so that its
//! checkpoint and study file can say what they belong to (`shpb sweep --resume` refuses a
//! checkpoint whose files changed); built-in set-ups and materials are compiled in and are
//! covered by the shpb version.

use sha2::{Digest, Sha256};
use std::cell::RefCell;
use std::path::{Path, PathBuf};

/// One input file read: its path (as it was opened) and the SHA-256 of its content.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct InputFile {
    /// The path the file was read from.
    pub path: PathBuf,
    /// The SHA-256 of its bytes, 64 lower-case hex digits (as `sha256sum` prints it).
    pub sha256: String,
}

thread_local! {
    static LOG: RefCell<Option<Vec<InputFile>>> = const { RefCell::new(None) };
}

/// The SHA-256 of `bytes` in lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Reads a text file like [`std::fs::read_to_string`], noting it (path and SHA-256) when a
/// [`recording`] is active on this thread.
pub fn read_to_string(path: impl AsRef<Path>) -> std::io::Result<String> {
    let path = path.as_ref();
    let bytes = std::fs::read(path)?;
    LOG.with(|log| {
        if let Some(files) = log.borrow_mut().as_mut() {
            let file = InputFile {
                path: path.to_path_buf(),
                sha256: sha256_hex(&bytes),
            };
            if !files.contains(&file) {
                files.push(file);
            }
        }
    });
    String::from_utf8(bytes).map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

/// Runs `f` and returns its result with the files it read through [`read_to_string`] on this
/// thread, each once, in the order first read (a nested recording also reports to the outer one).
pub fn recording<T>(f: impl FnOnce() -> T) -> (T, Vec<InputFile>) {
    let outer = LOG.with(|log| log.borrow_mut().replace(Vec::new()));
    let out = f();
    let files = LOG.with(|log| log.borrow_mut().take()).unwrap_or_default();
    LOG.with(|log| {
        *log.borrow_mut() = outer.map(|mut o| {
            for file in &files {
                if !o.contains(file) {
                    o.push(file.clone());
                }
            }
            o
        })
    });
    (out, files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_of_known_texts() {
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn a_recording_lists_each_file_read_once() {
        let dir = std::env::temp_dir().join(format!("shpb-provenance-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.toml"), dir.join("b.toml"));
        std::fs::write(&a, "abc").unwrap();
        std::fs::write(&b, "x").unwrap();
        // Outside a recording nothing is noted.
        read_to_string(&a).unwrap();
        let ((), outer) = recording(|| {
            read_to_string(&a).unwrap();
            let ((), inner) = recording(|| {
                read_to_string(&b).unwrap();
            });
            assert_eq!(inner.len(), 1);
            read_to_string(&a).unwrap();
        });
        assert_eq!(
            outer.iter().map(|f| f.path.clone()).collect::<Vec<_>>(),
            [a.clone(), b.clone()]
        );
        assert_eq!(outer[0].sha256, sha256_hex(b"abc"));
        assert!(recording(|| ()).1.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
