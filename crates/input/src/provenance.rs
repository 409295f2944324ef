//! Which files a scene resolves, as hashes: the files read through [`crate::files`] while
//! [`recording`] runs, each with the SHA-256 of its content. A sweep records the files of its
//! scene this way, so that its checkpoint and study file can say what they belong to
//! (`shpb sweep --resume` refuses a checkpoint whose files changed); built-in set-ups and
//! materials are compiled in and are covered by the shpb version.

use sha2::{Digest, Sha256};
use std::path::PathBuf;

/// One input file read: its path (as it was opened) and the SHA-256 of its content.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct InputFile {
    /// The path the file was read from.
    pub path: PathBuf,
    /// The SHA-256 of its bytes, 64 lower-case hex digits (as `sha256sum` prints it).
    pub sha256: String,
}

/// The SHA-256 of `bytes` in lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Runs `f` and returns its result with the files it read on this thread (built-ins left
/// out), each once, in the order first read (a nested recording also reports to the outer one).
pub fn recording<T>(f: impl FnOnce() -> T) -> (T, Vec<InputFile>) {
    let (out, files) = crate::files::capture(f);
    let files = files
        .into_iter()
        .filter(|f| !f.name.starts_with("built-in:"))
        .map(|f| InputFile {
            path: PathBuf::from(f.name),
            sha256: sha256_hex(f.text.as_bytes()),
        })
        .collect();
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
        crate::files::read_to_string(&a).unwrap();
        let ((), outer) = recording(|| {
            crate::files::read_to_string(&a).unwrap();
            let ((), inner) = recording(|| {
                crate::files::read_to_string(&b).unwrap();
            });
            assert_eq!(inner.len(), 1);
            crate::files::read_to_string(&a).unwrap();
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
