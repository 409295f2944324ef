//! Parsing TOML text into a file's schema, with the parser's message (key and line) named by file.

use crate::error::{Error, Result};
use serde::de::DeserializeOwned;

/// Deserializes the whole TOML `text` of `file` into `T` (a syntax error, unknown key or wrong
/// type is an [`Error::Parse`] naming the file).
pub(crate) fn parse_as<T: DeserializeOwned>(text: &str, file: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| Error::Parse {
        file: file.to_string(),
        message: e.to_string(),
    })
}
