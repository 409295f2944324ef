//! Every input shpb reads (scene, set-up, gauge, material and specimen files, CSV records) and
//! every built-in it resolves goes through here, so that a run can record exactly what it read
//! ([`capture`]: the provenance a run file stores) and be read again from that record alone
//! ([`replay`]: `shpb run RUN.h5`), without the original files.

use std::cell::RefCell;
use std::path::Path;

/// One input as read: its name (the path as read, or `built-in:<name>`) and its text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputFile {
    /// The path as read (relative paths are relative to the working directory of the run), or
    /// `built-in:<name>` for a set-up, gauge file or material compiled into shpb.
    pub name: String,
    /// The file's text.
    pub text: String,
}

/// What a run read and how it was asked for: stored in the run file's `/provenance`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Provenance {
    /// The scene file as named on the command line.
    pub scene_file: String,
    /// The `--fidelity` given on the command line, if any.
    pub fidelity_override: Option<String>,
    /// The command line, arguments joined by spaces.
    pub command_line: String,
    /// Every input read, in the order first read (the scene first).
    pub inputs: Vec<InputFile>,
}

thread_local! {
    static CAPTURED: RefCell<Option<Vec<InputFile>>> = const { RefCell::new(None) };
    static REPLAYED: RefCell<Option<Vec<InputFile>>> = const { RefCell::new(None) };
}

fn note(name: &str, text: &str) {
    CAPTURED.with(|c| {
        if let Some(log) = c.borrow_mut().as_mut()
            && !log.iter().any(|f| f.name == name)
        {
            log.push(InputFile {
                name: name.to_string(),
                text: text.to_string(),
            });
        }
    });
}

fn replayed(name: &str) -> Option<Option<String>> {
    REPLAYED.with(|r| {
        r.borrow().as_ref().map(|files| {
            files
                .iter()
                .find(|f| f.name == name)
                .map(|f| f.text.clone())
        })
    })
}

/// Reads a file's bytes (or, while replaying, its stored copy), noting it while capturing (as
/// text: the inputs shpb reads are text; a binary file is refused by its reader anyway).
pub fn read(path: &Path) -> std::io::Result<Vec<u8>> {
    let name = path.display().to_string();
    let bytes = match replayed(&name) {
        Some(Some(text)) => text.into_bytes(),
        Some(None) => {
            return Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "not among the inputs stored in the run file",
            ));
        }
        None => std::fs::read(path)?,
    };
    note(&name, &String::from_utf8_lossy(&bytes));
    Ok(bytes)
}

/// Reads a text file (or, while replaying, its stored copy), noting it while capturing.
pub fn read_to_string(path: &Path) -> std::io::Result<String> {
    String::from_utf8(read(path)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

/// Why `path` is not a readable file, for the message of an [`is_file`] check: "no such file",
/// "a directory, not a file", or the operating system's reason.
pub fn not_a_file(path: &Path) -> String {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => "a directory, not a file".into(),
        Ok(_) => "not a regular file".into(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => "no such file".into(),
        Err(e) => e.to_string(),
    }
}

/// Whether `path` is a readable file (while replaying: whether the run file stored it).
pub fn is_file(path: &Path) -> bool {
    match replayed(&path.display().to_string()) {
        Some(stored) => stored.is_some(),
        None => path.is_file(),
    }
}

/// A built-in text (set-up, gauge file, material): while replaying, the copy stored in the run
/// file (so a run file reruns with the built-ins of the shpb that wrote it); noted while capturing.
pub fn builtin(name: &str, text: &'static str) -> &'static str {
    let key = format!("built-in:{name}");
    let text = match replayed(&key) {
        Some(Some(stored)) if stored != text => &*Box::leak(stored.into_boxed_str()),
        _ => text,
    };
    note(&key, text);
    text
}

/// Runs `f`, returning what it returns and every input it read (on this thread).
pub fn capture<T>(f: impl FnOnce() -> T) -> (T, Vec<InputFile>) {
    let outer = CAPTURED.with(|c| c.borrow_mut().replace(Vec::new()));
    let value = f();
    let log = CAPTURED.with(|c| std::mem::replace(&mut *c.borrow_mut(), outer));
    if let Some(files) = &log {
        for file in files {
            note(&file.name, &file.text);
        }
    }
    (value, log.unwrap_or_default())
}

/// Runs `f` with every read served from `inputs` (a file not among them cannot be read).
pub fn replay<T>(inputs: &[InputFile], f: impl FnOnce() -> T) -> T {
    let outer = REPLAYED.with(|r| r.borrow_mut().replace(inputs.to_vec()));
    let value = f();
    REPLAYED.with(|r| *r.borrow_mut() = outer);
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capture_notes_each_file_once_and_replay_serves_only_stored_files() {
        let dir = std::env::temp_dir().join(format!("shpb-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = dir.join("a.toml");
        std::fs::write(&a, "x = 1\n").unwrap();
        let ((), log) = capture(|| {
            assert_eq!(read_to_string(&a).unwrap(), "x = 1\n");
            read_to_string(&a).unwrap();
            assert_eq!(builtin("authors", "built-in text"), "built-in text");
        });
        assert_eq!(log.len(), 2, "{log:?}");
        assert_eq!(log[0].name, a.display().to_string());
        assert_eq!(log[1].name, "built-in:authors");
        // The original may change or vanish: the replay reads the stored copy.
        std::fs::remove_file(&a).unwrap();
        std::fs::remove_dir(&dir).unwrap();
        let stored = vec![
            InputFile {
                name: a.display().to_string(),
                text: "x = 1\n".into(),
            },
            InputFile {
                name: "built-in:authors".into(),
                text: "older text".into(),
            },
        ];
        replay(&stored, || {
            assert_eq!(read_to_string(&a).unwrap(), "x = 1\n");
            assert!(read_to_string(&dir.join("b.toml")).is_err());
            assert_eq!(builtin("authors", "built-in text"), "older text");
        });
        // Outside the replay, the disk again.
        assert!(read_to_string(&a).is_err());
    }
}
