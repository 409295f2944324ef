//! Numeric CSV tables: `#` comment lines, one header line, then rows of numbers. Errors name the
//! file, line and column.

use crate::error::{Error, Result};
use std::path::Path;
use std::str::FromStr;

/// A numeric CSV table: `#` comment lines, one header line, then rows of numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvTable {
    /// The file it came from (for error messages).
    pub file: String,
    /// Column names from the header line.
    pub names: Vec<String>,
    /// Column data, one vector per name.
    pub columns: Vec<Vec<f64>>,
}

impl CsvTable {
    /// Parses CSV text; `file` names the source in errors.
    pub fn parse(text: &str, file: &str) -> Result<CsvTable> {
        let input = |line: usize, key: &str, problem: String, allowed: &str| Error::Input {
            file: format!("{file}:{line}"),
            key: key.to_string(),
            problem,
            allowed: allowed.to_string(),
        };
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let (hline, header) = lines.next().ok_or_else(|| {
            input(
                1,
                "header",
                "the file has no header line".into(),
                "a header line naming the columns, then numeric rows",
            )
        })?;
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
        if names.iter().any(|n| n.is_empty()) {
            return Err(input(
                hline,
                "header",
                "empty column name".into(),
                "comma-separated column names",
            ));
        }
        let mut columns = vec![Vec::new(); names.len()];
        for (line, row) in lines {
            let cells: Vec<&str> = row.split(',').collect();
            if cells.len() != names.len() {
                return Err(input(
                    line,
                    "row",
                    format!(
                        "{} values where the header has {}",
                        cells.len(),
                        names.len()
                    ),
                    "one value per header column",
                ));
            }
            for (k, cell) in cells.iter().enumerate() {
                let v = f64::from_str(cell.trim()).map_err(|_| {
                    input(
                        line,
                        &names[k],
                        format!("`{}` is not a number", cell.trim()),
                        "a finite decimal number",
                    )
                })?;
                if !v.is_finite() {
                    return Err(input(
                        line,
                        &names[k],
                        format!("{v} is not finite"),
                        "a finite decimal number",
                    ));
                }
                columns[k].push(v);
            }
        }
        if columns[0].is_empty() {
            return Err(input(
                hline,
                "rows",
                "the file has no data rows".into(),
                "at least two rows",
            ));
        }
        Ok(CsvTable {
            file: file.to_string(),
            names,
            columns,
        })
    }

    /// Reads and parses a CSV file.
    pub fn read(path: &Path) -> Result<CsvTable> {
        let text = crate::provenance::read_to_string(path).map_err(|e| Error::io(path, e))?;
        CsvTable::parse(&text, &path.display().to_string())
    }

    /// The column called `name`, or an error listing the columns there are.
    pub fn column(&self, name: &str) -> Result<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
            .ok_or_else(|| Error::Input {
                file: self.file.clone(),
                key: name.to_string(),
                problem: "column missing".into(),
                allowed: format!("a header with `{name}` (found: {})", self.names.join(", ")),
            })
    }

    /// The column called `name` if present.
    pub fn optional_column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
    }

    /// The column `name`, checked to be strictly increasing (a time axis).
    pub fn time_column(&self, name: &str) -> Result<&[f64]> {
        let t = self.column(name)?;
        if t.len() < 2 {
            return Err(Error::Input {
                file: self.file.clone(),
                key: name.to_string(),
                problem: "fewer than two samples".into(),
                allowed: "at least two strictly increasing times".into(),
            });
        }
        if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::Input {
                file: self.file.clone(),
                key: name.to_string(),
                problem: format!(
                    "not strictly increasing at data row {} ({:e} after {:e})",
                    i + 2,
                    t[i + 1],
                    t[i]
                ),
                allowed: "strictly increasing times".into(),
            });
        }
        Ok(t)
    }
}
