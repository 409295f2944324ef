//! Scene files: one TOML file per virtual test, with a `kind` key, parsed once into a validated
//! [`Params`] of the core (physics code never sees unchecked input).

use crate::error::{Error, Result, Validator};
use crate::kinds;
use crate::toml_file::parse_as;
use shpb_core::fidelity::Fidelity;
use shpb_core::scene::Params;
use std::path::{Path, PathBuf};

/// A TOML value, as given to [`SceneFile::from_file_overridden`] and [`with_overrides`].
pub use toml::Value;

/// Reading and validating scene files into the core's [`Params`].
pub trait SceneFile: Sized {
    /// Reads and validates a scene file.
    fn from_file(path: &Path) -> Result<Self>;
    /// Validates scene TOML text; relative paths inside it are resolved against `base_dir`. A run
    /// that cannot finish on this machine is refused (`crate::resources::check_run`).
    fn from_toml(text: &str, file: &str, base_dir: &Path) -> Result<Self>;
    /// Reads a scene file with its `fidelity` replaced by `fidelity` (when given): what
    /// `--fidelity` does. The stored scene text is the file's with the preset set.
    fn from_file_with(path: &Path, fidelity: Option<Fidelity>) -> Result<Self>;
    /// Reads a scene file with some keys replaced (dotted paths such as `shaper.thickness_m`
    /// reach into tables); the stored scene text is the modified TOML.
    fn from_file_overridden(path: &Path, overrides: &[(String, toml::Value)]) -> Result<Self>;
}

impl SceneFile for Params {
    /// Reads and validates a scene file.
    fn from_file(path: &Path) -> Result<Params> {
        Params::from_file_overridden(path, &[])
    }

    /// Validates scene TOML text; relative paths inside it are resolved against `base_dir`.
    fn from_toml(text: &str, file: &str, base_dir: &Path) -> Result<Params> {
        let v = Validator::new(file);
        let table: toml::Table = parse_as(text, file)?;
        // A distribution (`shpb study`) is not one value: a single run refuses it.
        crate::distribution::refuse_distributions(&table, file)?;
        let kind = match table.get("kind") {
            Some(toml::Value::String(k)) => k.clone(),
            Some(_) => return Err(v.error("kind", "not a string", kinds::allowed())),
            None => return Err(v.error("kind", "missing", kinds::allowed())),
        };
        let fidelity = match table.get("fidelity") {
            None => Fidelity::default(),
            Some(toml::Value::String(name)) => Fidelity::parse(name).ok_or_else(|| {
                v.error(
                    "fidelity",
                    format!("unknown preset `{name}`"),
                    "fast, standard, reference",
                )
            })?,
            Some(_) => {
                return Err(v.error("fidelity", "not a string", "fast, standard, reference"));
            }
        };
        let Some(scene_kind) = kinds::find(&kind) else {
            return Err(v.error(
                "kind",
                format!("unknown scene kind `{kind}`"),
                kinds::allowed(),
            ));
        };
        let (specimen, params) = (scene_kind.parse)(text, file, base_dir, fidelity, &v)?;
        let params = Params {
            source: file.to_string(),
            text: text.to_string(),
            kind,
            specimen,
            fidelity,
            params,
        };
        // Refuse a run that cannot finish on this machine before anything is allocated for it.
        crate::resources::check_run(&params)?;
        Ok(params)
    }

    /// Reads a scene file with its `fidelity` replaced by `fidelity` (when given): what
    /// `--fidelity` does. The stored scene text is the file's with the preset set.
    fn from_file_with(path: &Path, fidelity: Option<Fidelity>) -> Result<Params> {
        let overrides: Vec<(String, toml::Value)> = fidelity
            .map(|f| ("fidelity".to_string(), toml::Value::String(f.name().into())))
            .into_iter()
            .collect();
        Params::from_file_overridden(path, &overrides)
    }

    /// Reads a scene file with some keys replaced (dotted paths such as `shaper.thickness_m`
    /// reach into tables); the stored scene text is the modified TOML.
    fn from_file_overridden(path: &Path, overrides: &[(String, toml::Value)]) -> Result<Params> {
        let file = path.display().to_string();
        let original = crate::files::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let text = if overrides.is_empty() {
            original.clone()
        } else {
            with_overrides(&original, &file, overrides)?
        };
        let base = path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        Params::from_toml(&text, &file, &base).map_err(|e| match e {
            Error::Parse { .. } => not_a_scene(path, &file)
                .or_else(|| {
                    (!overrides.is_empty())
                        .then(|| blame_override(&original, &file, &base, overrides))
                        .flatten()
                })
                .unwrap_or(e),
            e => e,
        })
    }
}

/// For a file that does not parse as TOML and is plainly not a scene by its extension (a record,
/// a spreadsheet, or an `.h5` that is not HDF5, since a run file would have been read as one), the
/// error that says so: the TOML parser's message about its first line would mislead. (A TOML
/// scene under another name is read as any scene.)
fn not_a_scene(path: &Path, file: &str) -> Option<Error> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let what = match ext.as_str() {
        "csv" | "txt" | "tsv" | "dat" | "lvm" | "xls" | "xlsx" => {
            format!("a .{ext} file is a record, not a scene")
        }
        "h5" | "hdf5" => {
            "not an HDF5 file (no HDF5 signature), so not a run file of `shpb run -o`".into()
        }
        _ => return None,
    };
    Some(Error::Input {
        file: file.to_string(),
        key: "kind".into(),
        problem: what,
        allowed: "a scene .toml file (with a `kind` key) or a run file (.h5) of `shpb run -o`; \
                  `shpb reduce`, `strain` and `incident` read records"
            .into(),
    })
}

/// The override that makes a valid scene fail to parse (an unknown key, a value of the wrong
/// type), named as set on the command line: the parser's own message would quote a line of the
/// rewritten text that the file does not have. `None` when the file itself does not parse (its
/// own message, with its own lines, is then the right one) or no single override is to blame.
fn blame_override(
    original: &str,
    file: &str,
    base: &Path,
    overrides: &[(String, toml::Value)],
) -> Option<Error> {
    if let Err(e @ Error::Parse { .. }) = Params::from_toml(original, file, base) {
        return Some(e);
    }
    overrides.iter().find_map(|(key, value)| {
        let text = with_overrides(original, file, &[(key.clone(), value.clone())]).ok()?;
        let Err(Error::Parse { message, .. }) = Params::from_toml(&text, file, base) else {
            return None;
        };
        // The parser's reason is its last line (after the quoted line and the caret).
        let reason = message
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or(&message)
            .trim()
            .to_string();
        Some(Error::Input {
            file: file.to_string(),
            key: key.clone(),
            problem: format!("set to {value} on the command line: {reason}"),
            allowed: "a key of this scene's kind, with a value of its type (README.md, the \
                      scene kinds)"
                .into(),
        })
    })
}

/// Scene TOML `text` with `overrides` applied: each dotted key path (`pressure`,
/// `shaper.thickness_m`) set to its value, creating tables on the way; an error names `file`
/// when a path runs through a non-table value.
pub fn with_overrides(
    text: &str,
    file: &str,
    overrides: &[(String, toml::Value)],
) -> Result<String> {
    let v = Validator::new(file);
    let mut table: toml::Table = parse_as(text, file)?;
    // The gun's pressure and the striker's velocity are alternatives: setting one replaces the
    // other (a 10 psi scene with `striker_velocity_m_s` set runs at that velocity); both set is
    // refused rather than one silently winning.
    const EXCLUSIVE: [&str; 2] = ["pressure", "striker_velocity_m_s"];
    if EXCLUSIVE
        .iter()
        .all(|k| overrides.iter().any(|(path, _)| path == k))
    {
        return Err(v.error(
            "striker_velocity_m_s",
            "set with pressure",
            "one of pressure and striker_velocity_m_s (setting one replaces the other)",
        ));
    }
    for (path, value) in overrides {
        if let Some(i) = EXCLUSIVE.iter().position(|k| k == path) {
            table.remove(EXCLUSIVE[1 - i]);
        }
        let parts: Vec<&str> = path.split('.').collect();
        let (last, tables) = parts.split_last().expect("split yields at least one part");
        let mut t = &mut table;
        for part in tables {
            let entry = t
                .entry(part.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            t = match entry {
                toml::Value::Table(inner) => inner,
                _ => {
                    return Err(v.error(
                        path,
                        format!("`{part}` is not a table"),
                        "a key path through tables, e.g. shaper.thickness_m",
                    ));
                }
            };
        }
        t.insert(last.to_string(), value.clone());
    }
    toml::to_string(&table).map_err(|e| Error::Parse {
        file: file.to_string(),
        message: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::with_overrides;
    use toml::Value;

    #[test]
    fn pressure_and_striker_velocity_replace_each_other() {
        let text = "kind = \"pulse\"\nbars = \"authors\"\npressure = \"10psi\"\n";
        let set = |k: &str, v: Value| with_overrides(text, "a.toml", &[(k.to_string(), v)]);
        let t: toml::Table =
            toml::from_str(&set("striker_velocity_m_s", Value::Float(6.0)).unwrap()).unwrap();
        assert!(!t.contains_key("pressure"));
        assert_eq!(t["striker_velocity_m_s"], Value::Float(6.0));
        let back = with_overrides(
            &toml::to_string(&t).unwrap(),
            "a.toml",
            &[("pressure".into(), Value::String("12psi".into()))],
        )
        .unwrap();
        let t: toml::Table = toml::from_str(&back).unwrap();
        assert!(!t.contains_key("striker_velocity_m_s"));
        // Both at once: refused, naming both keys.
        let both = with_overrides(
            text,
            "a.toml",
            &[
                ("pressure".into(), Value::String("12psi".into())),
                ("striker_velocity_m_s".into(), Value::Float(6.0)),
            ],
        )
        .unwrap_err()
        .to_string();
        assert!(
            both.contains("striker_velocity_m_s") && both.contains("pressure"),
            "{both}"
        );
        // A key in a table of that name is not the top-level one.
        let t: toml::Table =
            toml::from_str(&set("shaper.thickness_m", Value::Float(1e-3)).unwrap()).unwrap();
        assert!(t.contains_key("pressure"));
    }
}
