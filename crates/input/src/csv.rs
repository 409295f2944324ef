//! Numeric CSV tables: `#` comment lines, one header line, then rows of numbers. Errors name the
//! file, line and column. Files may start with a UTF-8 byte-order mark and end their lines with
//! CRLF (as spreadsheet programs write them); a file that is not UTF-8 text (a binary file, an
//! HDF5 file, a UTF-16 export) is refused as "not a text CSV" ([`read_text`]).

use crate::error::{Error, Result};
use std::path::Path;
use std::str::FromStr;

/// The text of a CSV file, without a leading UTF-8 byte-order mark. A file that is not UTF-8
/// text, or holds a NUL byte (binary data, UTF-16), is an [`Error::Parse`] "not a text CSV"
/// naming the file and where the text stops; a file that cannot be read is an [`Error::Io`].
pub fn read_text(path: &Path) -> Result<String> {
    let bytes = crate::files::read(path).map_err(|e| Error::io(path, e))?;
    let not_text = |at: usize, what: &str| Error::Parse {
        file: path.display().to_string(),
        message: format!(
            "not a text CSV ({what} at byte {at}); expected UTF-8 text: `#` comment lines, a \
             header line naming the columns, then rows of comma-separated numbers"
        ),
    };
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        return Err(not_text(at, "a NUL byte"));
    }
    let text = String::from_utf8(bytes)
        .map_err(|e| not_text(e.utf8_error().valid_up_to(), "invalid UTF-8"))?;
    Ok(normalise_line_ends(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    }))
}

/// The text with every line end written `\n`: CRLF (Windows) and a lone CR (classic Mac OS,
/// some oscilloscopes) alike, so a file with CR-only line ends is read line by line rather than
/// as one long header line.
pub fn normalise_line_ends(text: String) -> String {
    if !text.contains('\r') {
        return text;
    }
    text.replace("\r\n", "\n").replace('\r', "\n")
}

/// The delimiter a header line seems to use when it is not shpb's comma: `;` or a tab, whichever
/// appears more often than commas; None for a comma-separated (or one-column) header.
pub fn foreign_delimiter(header: &str) -> Option<(char, &'static str)> {
    let commas = header.matches(',').count();
    [(';', "semicolons (`;`)"), ('\t', "tabs")]
        .into_iter()
        .map(|(c, name)| (header.matches(c).count(), c, name))
        .filter(|&(n, _, _)| n > commas)
        .max_by_key(|&(n, _, _)| n)
        .map(|(_, c, name)| (c, name))
}

/// Whether the cells of a row, taken two by two, read as numbers written with a decimal comma
/// (`0,5,12,25` as `0,5` and `12,25`): the sign of a CSV written in a decimal-comma locale.
fn looks_decimal_comma(row: &str, header_columns: usize) -> bool {
    let cells: Vec<&str> = row.split(',').map(str::trim).collect();
    cells.len() == 2 * header_columns
        && cells.chunks(2).all(|c| {
            c[1].chars().next().is_some_and(|ch| ch.is_ascii_digit())
                && f64::from_str(&format!("{}.{}", c[0], c[1])).is_ok()
        })
}

/// The sign convention of a force or approach column ([`CsvTable::compression_column`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SignConvention {
    /// Compression positive: the project's convention (docs/physics.md, "Units and signs").
    #[default]
    CompressionPositive,
    /// Tension positive (a bar-side convention): the column is negated on reading.
    TensionPositive,
}

impl SignConvention {
    /// The names a scene writes (`force_sign = "..."`).
    pub const NAMES: [(&'static str, SignConvention); 2] = [
        ("compression-positive", SignConvention::CompressionPositive),
        ("tension-positive", SignConvention::TensionPositive),
    ];

    /// The convention called `name`.
    pub fn parse(name: &str) -> Option<SignConvention> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, s)| s)
    }
}

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
    /// Parses CSV text (a leading byte-order mark and CRLF line ends are accepted); `file` names
    /// the source in errors.
    pub fn parse(text: &str, file: &str) -> Result<CsvTable> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let normalised;
        let text = if text.contains('\r') {
            normalised = normalise_line_ends(text.to_string());
            normalised.as_str()
        } else {
            text
        };
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
        if let Some((_, name)) = foreign_delimiter(header) {
            return Err(input(
                hline,
                "header",
                format!("`{header}` is separated by {name}, not commas"),
                "comma-separated columns with decimal points (`time_s,force_N` then rows such as \
                 `1.5e-6,120.5`): save the file as CSV with `,` between columns and `.` as the \
                 decimal mark",
            ));
        }
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
            // The cells are counted first (the count is checked before any value) and then
            // parsed straight from the row, without collecting them.
            let count = row.bytes().filter(|&b| b == b',').count() + 1;
            if count != names.len() {
                let problem = if looks_decimal_comma(row, names.len()) {
                    format!(
                        "`{row}` is written with decimal commas ({count} comma-separated cells \
                         where the header has {} columns)",
                        names.len()
                    )
                } else if let Some((_, name)) = foreign_delimiter(row) {
                    format!("`{row}` is separated by {name}, not commas")
                } else {
                    format!("{count} values where the header has {}", names.len())
                };
                return Err(input(
                    line,
                    "row",
                    problem,
                    "one value per header column, comma-separated, with decimal points \
                     (`1.5e-6,120.5`)",
                ));
            }
            let mut rest = row;
            for k in 0..count {
                // A byte scan for the comma (an ASCII byte, so a char boundary): quicker than a
                // char pattern on cells this short.
                let (cell, tail) = match rest.bytes().position(|b| b == b',') {
                    Some(i) => (&rest[..i], &rest[i + 1..]),
                    None => (rest, ""),
                };
                rest = tail;
                let cell = cell.trim();
                let v = f64::from_str(cell).map_err(|_| {
                    input(
                        line,
                        &names[k],
                        format!("`{cell}` is not a number"),
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

    /// Reads and parses a CSV file ([`read_text`]).
    pub fn read(path: &Path) -> Result<CsvTable> {
        let text = read_text(path)?;
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

    /// The column `name` of a force or approach, compression positive (the project's convention,
    /// docs/physics.md "Units and signs"). `sign` is the file's own convention: a
    /// [`SignConvention::TensionPositive`] column is negated. The sample of largest magnitude
    /// must then be positive (a loading record compresses the spheres): a column whose largest
    /// value is a negative one holds compression negative, and is refused naming the file, the
    /// column and `remedy` (what the user can set to read it), not read as a force that never
    /// loads. A column of zeros is accepted.
    pub fn compression_column(
        &self,
        name: &str,
        sign: SignConvention,
        remedy: &str,
    ) -> Result<Vec<f64>> {
        let factor = match sign {
            SignConvention::CompressionPositive => 1.0,
            SignConvention::TensionPositive => -1.0,
        };
        let column: Vec<f64> = self.column(name)?.iter().map(|x| factor * x).collect();
        let (k, largest) = column
            .iter()
            .copied()
            .enumerate()
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            .unwrap_or((0, 0.0));
        if largest < 0.0 {
            let unit = if name.ends_with("_N") {
                "N"
            } else if name.ends_with("_m") {
                "m"
            } else {
                ""
            };
            return Err(Error::Input {
                file: self.file.clone(),
                key: name.to_string(),
                problem: format!(
                    "the value of largest magnitude, {} (data row {}), is negative{}: this file \
                     holds compression negative",
                    shpb_core::error::format_si(largest, unit),
                    k + 1,
                    match sign {
                        SignConvention::CompressionPositive => "",
                        SignConvention::TensionPositive => " once negated as tension-positive",
                    }
                ),
                allowed: format!(
                    "compression positive (a loading record: force and approach grow positive); {remedy}"
                ),
            });
        }
        Ok(column)
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

    /// Refuses a time column `t` (of column `name`) spanning more than [`MAX_RECORD_SPAN_S`]:
    /// an impact lasts microseconds to milliseconds, so such times are µs or ms under a seconds
    /// header, not a record to run for hours (which would be refused later as a bad
    /// `end_time_s` the scene does not have).
    pub fn check_time_span(&self, name: &str, t: &[f64]) -> Result<()> {
        let (Some(first), Some(last)) = (t.first(), t.last()) else {
            return Ok(());
        };
        let span = last - first;
        if span > MAX_RECORD_SPAN_S {
            return Err(Error::Input {
                file: self.file.clone(),
                key: name.to_string(),
                problem: format!(
                    "the times span {}, from {first:e} to {last:e}: a record of an impact lasts \
                     microseconds to milliseconds, so these look like µs or ms written under a \
                     seconds header",
                    shpb_core::error::format_si(span, "s"),
                ),
                allowed: format!(
                    "times in seconds (1.5e-6 for 1.5 µs) spanning at most {MAX_RECORD_SPAN_S} s"
                ),
            });
        }
        Ok(())
    }
}

/// The longest time a record of one test may span, s: an SHPB or impact test is over within
/// milliseconds (the authors' records span 1 ms), and a scene's `end_time_s` is at most 1 s.
pub const MAX_RECORD_SPAN_S: f64 = 1.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cr_only_line_ends_read_like_lf() {
        let lf = CsvTable::parse("time_s,force_N\n0,1\n1e-6,2.5\n", "lf.csv").unwrap();
        let cr = CsvTable::parse("time_s,force_N\r0,1\r1e-6,2.5\r", "cr.csv").unwrap();
        assert_eq!(lf.columns, cr.columns);
        assert_eq!(normalise_line_ends("a\r\nb\rc\n".into()), "a\nb\nc\n");
    }

    #[test]
    fn semicolons_and_decimal_commas_are_named_not_counted() {
        let e = CsvTable::parse("time_s;force_N\n0;1\n", "s.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("separated by semicolons"), "{e}");
        let e = CsvTable::parse("time_s\tforce_N\n0\t1\n", "t.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("separated by tabs"), "{e}");
        let e = CsvTable::parse("time_s,force_N\n0,5,12,25\n", "d.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("decimal commas"), "{e}");
        // A row that is merely short is still counted.
        let e = CsvTable::parse("time_s,force_N\n0\n", "c.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("1 values where the header has 2"), "{e}");
    }

    #[test]
    fn times_spanning_more_than_a_second_are_named_as_other_units() {
        let t = CsvTable::parse("time_s,force_N\n0,1\n150,2\n", "us.csv").unwrap();
        let e = t
            .check_time_span("time_s", t.column("time_s").unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("µs or ms written under a seconds header"), "{e}");
        let t = CsvTable::parse("time_s,force_N\n0,1\n1.5e-4,2\n", "s.csv").unwrap();
        assert!(
            t.check_time_span("time_s", t.column("time_s").unwrap())
                .is_ok()
        );
    }

    fn temp(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("shpb-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }

    #[test]
    fn a_byte_order_mark_and_crlf_line_ends_read_like_plain_text() {
        let plain = temp("plain.csv", b"# c\ntime_s,force_N\n0,1\n1e-6,2.5\n");
        let excel = temp(
            "excel.csv",
            b"\xef\xbb\xbf# c\r\ntime_s,force_N\r\n0,1\r\n1e-6,2.5\r\n",
        );
        let a = CsvTable::read(&plain).unwrap();
        let b = CsvTable::read(&excel).unwrap();
        assert_eq!(a.names, b.names);
        assert_eq!(a.columns, b.columns);
        assert_eq!(b.column("time_s").unwrap(), [0.0, 1e-6]);
        // Without a comment line the mark sits before the first column's name.
        let bare = temp("bare.csv", b"\xef\xbb\xbftime_s,force_N\r\n0,1\r\n");
        assert_eq!(CsvTable::read(&bare).unwrap().names, ["time_s", "force_N"]);
    }

    #[test]
    fn a_force_column_with_compression_negative_is_refused() {
        let text = "time_s,force_N\n0,0\n1e-6,-5000\n2e-6,-12000\n3e-6,150\n";
        let t = CsvTable::parse(text, "f.csv").unwrap();
        let e = t
            .compression_column("force_N", SignConvention::CompressionPositive, "REMEDY")
            .unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert_eq!(
            e.to_string(),
            "f.csv: `force_N`: the value of largest magnitude, -12 kN (data row 3), is negative: \
             this file holds compression negative; allowed: compression positive (a loading \
             record: force and approach grow positive); REMEDY"
        );
        let flipped = t
            .compression_column("force_N", SignConvention::TensionPositive, "")
            .unwrap();
        assert_eq!(flipped, [-0.0, 5000.0, 12000.0, -150.0]);
        // Declared tension-positive, but compression is positive already: refused too.
        let t = CsvTable::parse("time_s,force_N\n0,0\n1e-6,12000\n", "g.csv").unwrap();
        let e = t
            .compression_column("force_N", SignConvention::TensionPositive, "")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("is negative once negated as tension-positive"),
            "{e}"
        );
        assert_eq!(
            SignConvention::parse("tension-positive"),
            Some(SignConvention::TensionPositive)
        );
    }

    #[test]
    fn a_binary_file_is_not_a_text_csv() {
        let hdf5 = temp("run.h5", b"\x89HDF\r\n\x1a\n\x00\x00\x00\x00");
        let e = CsvTable::read(&hdf5).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let msg = e.to_string();
        assert!(
            msg.starts_with(&format!("{}: not a text CSV (", hdf5.display())),
            "{msg}"
        );
        assert!(!msg.contains("stream did not contain valid UTF-8"), "{msg}");
        let latin1 = temp("latin1.csv", b"time_s,force_N\n0,1\xb0\n");
        let msg = CsvTable::read(&latin1).unwrap_err().to_string();
        assert!(
            msg.contains("not a text CSV (invalid UTF-8 at byte 18)"),
            "{msg}"
        );
    }
}
