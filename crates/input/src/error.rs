//! The errors a user of shpb meets: every bad input names the file, the key and what is allowed;
//! the core's typed errors ([`shpb_core::Error`]) are mapped here to the file and key the user
//! wrote ([`Validator::core`]). The output layer reuses this type, so the whole program has one
//! error type with one set of exit codes.

use std::path::{Path, PathBuf};

/// The crate's error type; `Input` errors are the user's to fix, the rest are failures of a run.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A value in an input file (or on the command line) is missing, malformed or out of range.
    #[error("{file}: `{key}`: {problem}; allowed: {allowed}")]
    Input {
        /// The file (or `command line`) the value came from.
        file: String,
        /// The key (dotted TOML path, CSV column or CLI option) that is wrong.
        key: String,
        /// What is wrong with it.
        problem: String,
        /// The allowed range or set of values.
        allowed: String,
    },
    /// A file could not be parsed at all (syntax error, unknown key, wrong type).
    #[error("{file}: {message}")]
    Parse {
        /// The file that failed to parse.
        file: String,
        /// The parser's message (it names the key and line).
        message: String,
    },
    /// A file could not be read or written.
    #[error("{file}: {source}")]
    Io {
        /// The file concerned.
        file: String,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// An output file exists and `--force` was not given.
    #[error("{0}: output file exists; pass --force to overwrite it")]
    OutputExists(PathBuf),
    /// The HDF5 library failed while writing or reading.
    #[error("HDF5 error on {file}: {message}")]
    Hdf5 {
        /// The HDF5 file concerned.
        file: String,
        /// The library's message.
        message: String,
    },
    /// A run became numerically unstable; names the step, time and quantity.
    #[error("numerical instability at step {step} (t = {time_s:.6e} s): {quantity} = {value:e}")]
    Unstable {
        /// Step index at which the problem was detected.
        step: usize,
        /// Simulated time of that step, s.
        time_s: f64,
        /// The quantity that became non-finite or blew up.
        quantity: String,
        /// Its value.
        value: f64,
    },
    /// A run stopped by its caller (Ctrl-C in Python, a progress callback that said stop).
    #[error("run interrupted at step {step} (t = {time_s:.6e} s)")]
    Interrupted {
        /// Steps done.
        step: usize,
        /// Simulated time reached, s.
        time_s: f64,
    },
    /// A run that cannot finish on this machine (too many steps, too much memory), refused before
    /// it starts (`crate::resources`).
    #[error(
        "{file}: the run cannot finish on this machine: it needs {needs}; limit: {limit}; {hint}"
    )]
    TooLarge {
        /// The scene.
        file: String,
        /// The estimate: steps, node updates, memory and output.
        needs: String,
        /// The limits and where the memory limit comes from.
        limit: String,
        /// The keys that make the run smaller.
        hint: String,
    },
    /// A design search (`shpb design`) found no input within the bounds that meets its target
    /// (exit code 4): the message names the target, the bounds and what the runs gave.
    #[error("{0}")]
    NoSolution(String),
    /// A design search met its target, but no solution satisfies every `--require` constraint
    /// (exit code 5): the message names the constraints and the values at the solutions.
    #[error("{0}")]
    RequirementUnmet(String),
    /// A physical quantity outside its model's range, reported by the core without a file
    /// (a caller of the library passed it directly).
    #[error("{quantity}: {problem}; allowed: {allowed}")]
    Invalid {
        /// The core quantity.
        quantity: String,
        /// What is wrong with it.
        problem: String,
        /// The allowed range or set of values.
        allowed: String,
    },
}

impl From<shpb_core::Error> for Error {
    fn from(e: shpb_core::Error) -> Self {
        match e {
            shpb_core::Error::Invalid {
                object,
                quantity,
                problem,
                allowed,
            } if !object.is_empty() => Error::Input {
                file: object,
                key: quantity,
                problem,
                allowed,
            },
            shpb_core::Error::Invalid {
                quantity,
                problem,
                allowed,
                ..
            } => Error::Invalid {
                quantity,
                problem,
                allowed,
            },
            shpb_core::Error::Cancelled { step, time_s } => Error::Interrupted { step, time_s },
            shpb_core::Error::Unstable {
                step,
                time_s,
                quantity,
                value,
            } => Error::Unstable {
                step,
                time_s,
                quantity,
                value,
            },
        }
    }
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Process exit code for this error: 2 for bad input (a missing input file or a directory
    /// named as a file included, wherever it is read, and a run too large for the machine), 3 for an unstable run, 130 for
    /// a run interrupted by its caller (as SIGINT), 4 for a design search without a solution, 5
    /// for a design whose solutions violate a `--require` constraint, 1 otherwise.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Input { .. }
            | Error::Parse { .. }
            | Error::OutputExists(_)
            | Error::TooLarge { .. }
            | Error::Invalid { .. } => 2,
            // A missing input, or a directory named where a file belongs (or a file where a
            // directory belongs): the user's input, not a failing disk.
            Error::Io { source, .. }
                if matches!(
                    source.kind(),
                    std::io::ErrorKind::NotFound
                        | std::io::ErrorKind::IsADirectory
                        | std::io::ErrorKind::NotADirectory
                ) =>
            {
                2
            }
            Error::Unstable { .. } => 3,
            Error::NoSolution(_) => 4,
            Error::RequirementUnmet(_) => 5,
            Error::Interrupted { .. } => 130,
            Error::Io { .. } | Error::Hdf5 { .. } => 1,
        }
    }

    /// Wraps an I/O error with the file it concerns.
    pub fn io(file: &Path, source: std::io::Error) -> Self {
        Error::Io {
            file: file.display().to_string(),
            source,
        }
    }
}

/// Validates numbers read from one input file, producing `Error::Input` that names file and key
/// (the dotted keys are the core's [`shpb_core::error::Named`] names, within this file).
#[derive(Debug, Clone)]
pub struct Validator {
    file: String,
    keys: shpb_core::error::Named,
}

impl Validator {
    /// A validator for values read from `file` (a path or a label such as `command line`).
    pub fn new(file: impl Into<String>) -> Self {
        Validator {
            file: file.into(),
            keys: shpb_core::error::Named::new(""),
        }
    }

    /// The same file, with keys reported under the TOML table `table` (e.g. `specimen.sphere1`).
    pub fn table(&self, table: &str) -> Self {
        Validator {
            file: self.file.clone(),
            keys: self.keys.table(table),
        }
    }

    /// Maps a core error about a quantity to an input error for `key` of this file (the key the
    /// user wrote, which may differ from the core's name for it); instabilities pass through.
    pub fn core(&self, key: &str) -> impl Fn(shpb_core::Error) -> Error + '_ {
        let key = key.to_string();
        move |e| match e {
            shpb_core::Error::Invalid {
                problem, allowed, ..
            } => self.error(&key, problem, allowed),
            other => other.into(),
        }
    }

    /// Maps a core error to an input error of this file whose key is the core's quantity name
    /// (for objects whose quantities are named like the file's keys).
    pub fn core_named(&self) -> impl Fn(shpb_core::Error) -> Error + '_ {
        move |e| match e {
            shpb_core::Error::Invalid {
                quantity,
                problem,
                allowed,
                ..
            } => self.error(&quantity, problem, allowed),
            other => other.into(),
        }
    }

    /// The file this validator reports.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The full dotted key for `key` in this table.
    pub fn key(&self, key: &str) -> String {
        self.keys.key(key)
    }

    /// An input error for `key` with the given problem and allowed range.
    pub fn error(
        &self,
        key: &str,
        problem: impl Into<String>,
        allowed: impl Into<String>,
    ) -> Error {
        Error::Input {
            file: self.file.clone(),
            key: self.key(key),
            problem: problem.into(),
            allowed: allowed.into(),
        }
    }

    /// Checks `lo <= value <= hi` (both finite bounds inclusive) and that value is finite
    /// (the core's check, reported for `key` of this file).
    pub fn in_range(&self, key: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<f64> {
        shpb_core::error::in_range(key, value, lo, hi, unit).map_err(self.core(key))
    }

    /// Checks `0 < value <= hi` and finite (the core's check, reported for `key` of this file).
    pub fn positive(&self, key: &str, value: f64, hi: f64, unit: &str) -> Result<f64> {
        shpb_core::error::positive(key, value, hi, unit).map_err(self.core(key))
    }
}
