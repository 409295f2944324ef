//! Records as labs keep them: the one entry point every command that reads a gauge record goes
//! through ([`read_record`]: `shpb reduce`, `shpb strain`, `shpb calibrate`).
//!
//! - **Spreadsheets** (`.xls`, `.xlsx`, `.xlsm`, `.xlsb`, `.ods`), read by the `calamine` crate:
//!   the first sheet, or the layout's `sheet = "..."`.
//! - **Text** (CSV, tab- or semicolon-separated) in any of these encodings, by the `encoding_rs`
//!   crate: UTF-8 when the bytes are valid UTF-8 (a byte-order mark is dropped), otherwise
//!   GB18030 (the superset of GBK that Chinese-locale Excel writes); a layout's
//!   `encoding = "gbk"` (or `"utf-8"`, `"gb18030"`) names it instead. A NUL byte (UTF-16, a
//!   binary file) is refused as not text.
//! - **Columns from their headers**, without a layout: the authors' CSV
//!   (`time_s,incident_V,transmission_V`), or a header row whose names carry their units after a
//!   slash, as Yao et al.'s exports (`Time/s`, `incident_bar_signal/με`,
//!   `transmission_bar_signal/voltage`): the time column is named `time`/`t` with unit s, ms, us
//!   or µs; the incident channel is the column whose name contains `incident`, the transmission
//!   channel the one containing `transmi`, each with unit `με`, `ue`, `µε`, `microstrain`
//!   (microstrain), `ε` or `strain` (strain), `V`, `voltage` (volt) or `mV` (millivolt). Strains
//!   are taken as bar strain, tension positive (shpb's convention; Yao et al.'s records show
//!   compression negative, as it is), volts go through the set-up's gauge channels.
//!   Anything else is an error listing the columns found and how to write a layout
//!   (`--layout FILE`, [`crate::layout`]).

use crate::error::{Error, Result};
pub use crate::layout::TextEncoding;
use crate::layout::{
    ChannelLayout, ChannelUnit, Delimiter, LayoutRecord, RecordLayout, TimeSource,
};
use std::path::Path;

/// Whether `path` names a spreadsheet by its extension (xls, xlsx, xlsm, xlsb, ods).
pub fn is_spreadsheet(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .is_some_and(|e| matches!(e.as_str(), "xls" | "xlsx" | "xlsm" | "xlsb" | "ods"))
}

/// The text of a record's bytes in `encoding`, or by the module's rule (UTF-8 if valid, else
/// GB18030) when None; `file` names it in errors.
pub fn decode_text(bytes: &[u8], encoding: Option<TextEncoding>, file: &str) -> Result<String> {
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        return Err(Error::Parse {
            file: file.to_string(),
            message: format!(
                "not a text CSV (a NUL byte at byte {at}: UTF-16 or binary data); expected \
                 text in UTF-8 or GBK/GB18030, or a spreadsheet (.xls, .xlsx)"
            ),
        });
    }
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let utf8 = std::str::from_utf8(bytes);
    let encoding = match (encoding, &utf8) {
        (Some(e), _) => e,
        (None, Ok(_)) => TextEncoding::Utf8,
        (None, Err(_)) => TextEncoding::Gb18030,
    };
    let (name, decoder) = match encoding {
        TextEncoding::Utf8 => ("UTF-8", encoding_rs::UTF_8),
        TextEncoding::Gb18030 => ("GB18030", encoding_rs::GB18030),
    };
    decoder
        .decode_without_bom_handling_and_without_replacement(bytes)
        .map(|t| crate::csv::normalise_line_ends(t.into_owned()))
        .ok_or_else(|| Error::Parse {
            file: file.to_string(),
            message: format!(
                "not valid {name} text; give the record's encoding in a layout (`encoding = \
                 \"...\"`: {})",
                TextEncoding::ALLOWED
            ),
        })
}

/// The cells of a spreadsheet's sheet (`sheet`, or the first), row by row, as text (numbers
/// written in full precision); `file` names it in errors.
pub fn sheet_rows(bytes: Vec<u8>, sheet: Option<&str>, file: &str) -> Result<Vec<Vec<String>>> {
    use calamine::{Data, Reader};
    let parse = |message: String| Error::Parse {
        file: file.to_string(),
        message,
    };
    let mut book = calamine::open_workbook_auto_from_rs(std::io::Cursor::new(bytes))
        .map_err(|e| parse(format!("not a readable spreadsheet ({e})")))?;
    let names = book.sheet_names();
    let name = match sheet {
        Some(s) if names.iter().any(|n| n == s) => s.to_string(),
        Some(s) => {
            return Err(Error::Input {
                file: file.to_string(),
                key: "sheet".into(),
                problem: format!("no sheet `{s}`"),
                allowed: format!("one of: {}", names.join(", ")),
            });
        }
        None => names
            .first()
            .cloned()
            .ok_or_else(|| parse("the workbook has no sheet".into()))?,
    };
    let range = book
        .worksheet_range(&name)
        .map_err(|e| parse(format!("sheet `{name}` cannot be read ({e})")))?;
    Ok(range
        .rows()
        .map(|row| {
            row.iter()
                .map(|c| match c {
                    Data::Empty => String::new(),
                    Data::Float(x) => format!("{x:e}"),
                    Data::Int(i) => i.to_string(),
                    other => other.to_string(),
                })
                .collect()
        })
        .collect())
}

/// A column header split into its name and unit at the last `/` (or inside brackets:
/// `Time (s)`, `Time[s]`), both trimmed; the unit is empty when there is none.
fn name_and_unit(header: &str) -> (String, String) {
    let h = header.trim();
    if let Some(i) = h.rfind('/') {
        return (h[..i].trim().to_string(), h[i + 1..].trim().to_string());
    }
    for (open, close) in [('(', ')'), ('[', ']')] {
        if let (Some(i), true) = (h.rfind(open), h.ends_with(close)) {
            return (
                h[..i].trim().to_string(),
                h[i + 1..h.len() - 1].trim().to_string(),
            );
        }
    }
    (h.to_string(), String::new())
}

/// The channel unit a header's unit names (module docs), if any.
fn channel_unit(unit: &str) -> Option<ChannelUnit> {
    match unit {
        // SI symbols case-exact (`mv`, `v` are refused: not symbols), or the words.
        "V" | "volt" | "volts" | "voltage" | "Voltage" => Some(ChannelUnit::Volt),
        "mV" => Some(ChannelUnit::Millivolt),
        "ε" | "strain" | "Strain" => Some(ChannelUnit::Strain),
        "με" | "µε" | "ue" | "uε" | "microstrain" | "Microstrain" => {
            Some(ChannelUnit::Microstrain)
        }
        _ => None,
    }
}

/// The factor from a time header's unit to s (module docs), if it is one.
fn time_factor(unit: &str) -> Option<f64> {
    match unit {
        "s" => Some(1.0),
        "ms" => Some(1e-3),
        "us" | "µs" | "μs" => Some(1e-6),
        _ => None,
    }
}

/// How to give a layout, for the errors of [`auto_layout`].
const LAYOUT_HINT: &str = "headers with units (`Time/s`, a column containing `incident` and one \
    containing `transmi`, each `/με`, `/ue`, `/ε`, `/strain`, `/V`, `/mV` or `/voltage`), the \
    authors' `time_s,incident_V,transmission_V`, or a layout file (`--layout FILE`: time_column, \
    [incident] and [transmission] column and unit; README \"Your own bar and records\")";

/// The layout a header row implies (module docs: columns named with their units), read with
/// `delimiter`; `header_row` is the 0-based row of the header (the data follow it); `file`
/// names the record in errors, which list the columns found.
pub fn auto_layout(
    header: &[String],
    header_row: usize,
    delimiter: Delimiter,
    file: &str,
) -> Result<RecordLayout> {
    let found = || {
        header
            .iter()
            .map(|h| format!("`{}`", h.trim()))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let fail = |key: &str, problem: String| Error::Input {
        file: file.to_string(),
        key: key.to_string(),
        problem: format!("{problem} (columns found: {})", found()),
        allowed: LAYOUT_HINT.to_string(),
    };
    let split: Vec<(String, String)> = header.iter().map(|h| name_and_unit(h)).collect();
    let time = split.iter().enumerate().find_map(|(i, (name, unit))| {
        let n = name.to_lowercase();
        (n == "time" || n == "t" || n.starts_with("time"))
            .then(|| time_factor(unit).map(|f| (i, f)))
            .flatten()
    });
    let Some((time_column, factor)) = time else {
        // A scene or set-up given where a record goes: its first line is `key = value`.
        if header.len() == 1
            && header[0].contains('=')
            && toml::from_str::<toml::Table>(&header[0]).is_ok()
        {
            return Err(Error::Input {
                file: file.to_string(),
                key: "record".into(),
                problem: format!(
                    "this is TOML (`{}`: a scene or a set-up?), not a gauge record",
                    header[0].trim()
                ),
                allowed: LAYOUT_HINT.to_string(),
            });
        }
        return Err(fail(
            "time",
            "no time column named with its unit (`Time/s`, `/ms`, `/us`, `/µs`)".into(),
        ));
    };
    let channel = |key: &str, part: &str| -> Result<ChannelLayout> {
        let matches: Vec<usize> = split
            .iter()
            .enumerate()
            .filter(|(_, (name, _))| name.to_lowercase().contains(part))
            .map(|(i, _)| i)
            .collect();
        let column = match matches.as_slice() {
            [c] => *c,
            [] => return Err(fail(key, format!("no column whose name contains `{part}`"))),
            _ => {
                return Err(fail(
                    key,
                    format!("{} columns whose names contain `{part}`", matches.len()),
                ));
            }
        };
        let unit = channel_unit(&split[column].1).ok_or_else(|| {
            fail(
                key,
                format!(
                    "`{}` has no unit shpb knows (`/με`, `/ue`, `/ε`, `/strain`, `/V`, `/mV`, \
                     `/voltage`)",
                    header[column].trim()
                ),
            )
        })?;
        Ok(ChannelLayout {
            column,
            unit,
            polarity: 1.0,
        })
    };
    let incident = channel("incident", "incident")?;
    let transmission = channel("transmission", "transmi")?;
    if incident.unit.is_voltage() != transmission.unit.is_voltage() {
        return Err(fail(
            "transmission",
            "a voltage and a strain channel mixed".into(),
        ));
    }
    Ok(RecordLayout {
        source: format!("columns of {file} by their headers"),
        delimiter,
        decimal: '.',
        skip_lines: header_row + 1,
        time: TimeSource::Column {
            column: time_column,
            factor,
        },
        incident,
        transmission,
        sheet: None,
        encoding: None,
    })
}

/// The delimiter of a header line: tab, semicolon or comma, whichever splits it into the most
/// fields (comma when none does).
fn sniff_delimiter(line: &str) -> Delimiter {
    [
        (Delimiter::Comma, ','),
        (Delimiter::Tab, '\t'),
        (Delimiter::Semicolon, ';'),
    ]
    .into_iter()
    .max_by_key(|(_, c)| line.matches(*c).count())
    .map_or(Delimiter::Comma, |(d, _)| d)
}

/// Reads a gauge record: THE entry point of every command that reads one (module docs).
/// With a layout, the record is read through it (a spreadsheet's sheet, a text file's encoding);
/// without, the authors' CSV (`time_s,incident_V,transmission_V`) or columns named with their
/// units ([`auto_layout`]).
pub fn read_record(path: &Path, layout: Option<&RecordLayout>) -> Result<LayoutRecord> {
    use crate::gauges::RawRecordFile;
    let file = path.display().to_string();
    let bytes = crate::files::read(path).map_err(|e| Error::io(path, e))?;
    if is_spreadsheet(path) {
        let rows = sheet_rows(bytes, layout.and_then(|l| l.sheet.as_deref()), &file)?;
        let numbered = |rows: Vec<Vec<String>>| {
            rows.into_iter().enumerate().map(|(i, r)| {
                // A row of empty cells is skipped, as a blank text line.
                let r = if r.iter().all(|c| c.trim().is_empty()) {
                    Vec::new()
                } else {
                    r
                };
                (i + 1, r)
            })
        };
        return match layout {
            Some(l) => l.parse_rows(numbered(rows), &file),
            None => {
                let header_row = rows
                    .iter()
                    .position(|r| r.iter().any(|c| !c.trim().is_empty()))
                    .unwrap_or(0);
                let header = rows.get(header_row).cloned().unwrap_or_default();
                auto_layout(&header, header_row, Delimiter::Comma, &file)?
                    .parse_rows(numbered(rows), &file)
            }
        };
    }
    let text = decode_text(&bytes, layout.and_then(|l| l.encoding), &file)?;
    if let Some(l) = layout {
        return l.parse(&text, &file);
    }
    let (header_row, header_line) = text
        .lines()
        .enumerate()
        .find(|(_, l)| !l.trim().is_empty() && !l.trim().starts_with('#'))
        .unwrap_or((0, ""));
    let delimiter = sniff_delimiter(header_line);
    let names: Vec<String> = match delimiter {
        Delimiter::Tab => header_line.split('\t').map(str::to_string).collect(),
        Delimiter::Semicolon => header_line.split(';').map(str::to_string).collect(),
        _ => header_line.split(',').map(str::to_string).collect(),
    };
    let decimal = sniff_decimal(&text, header_row, delimiter);
    let authors = ["time_s", "incident_V", "transmission_V"];
    let column = |a: &str| names.iter().position(|n| n.trim() == a);
    if let [Some(t), Some(i), Some(tr)] = authors.map(column) {
        if delimiter == Delimiter::Comma {
            return Ok(LayoutRecord::Voltages(shpb_core::gauge::RawRecord::parse(
                &text, &file,
            )?));
        }
        // The authors' columns written in a semicolon or tab locale: read as such, not refused
        // for a column count.
        let channel = |column| ChannelLayout {
            column,
            unit: ChannelUnit::Volt,
            polarity: 1.0,
        };
        return RecordLayout {
            source: format!("columns of {file} by their headers"),
            delimiter,
            decimal,
            skip_lines: header_row + 1,
            time: TimeSource::Column {
                column: t,
                factor: 1.0,
            },
            incident: channel(i),
            transmission: channel(tr),
            sheet: None,
            encoding: None,
        }
        .parse(&text, &file);
    }
    let mut layout = auto_layout(&names, header_row, delimiter, &file)?;
    layout.decimal = decimal;
    layout.parse(&text, &file)
}

/// The decimal mark of a text record whose columns are separated by `delimiter`: `,` when the
/// columns are not comma-separated and the first data line after the header row writes its
/// numbers with commas (`-9,99e-05;0,00011`), else `.`.
fn sniff_decimal(text: &str, header_row: usize, delimiter: Delimiter) -> char {
    if delimiter == Delimiter::Comma {
        return '.';
    }
    let first = text
        .lines()
        .skip(header_row + 1)
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'));
    match first {
        Some(l) if l.contains(',') && !l.contains('.') => ',',
        _ => '.',
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn headers_with_units_give_the_columns() {
        let l = auto_layout(
            &strings(&[
                "Time/s",
                "incident_bar_signal/με",
                "transmission_bar_signal/με",
            ]),
            0,
            Delimiter::Comma,
            "r.xls",
        )
        .unwrap();
        assert_eq!(
            l.time,
            TimeSource::Column {
                column: 0,
                factor: 1.0
            }
        );
        assert_eq!(
            (l.incident.column, l.incident.unit),
            (1, ChannelUnit::Microstrain)
        );
        assert_eq!(
            (l.transmission.column, l.transmission.unit),
            (2, ChannelUnit::Microstrain)
        );
        let l = auto_layout(
            &strings(&["t (us)", "CH incident/voltage", "transmitted/mV"]),
            3,
            Delimiter::Tab,
            "r.txt",
        )
        .unwrap();
        assert_eq!(
            l.time,
            TimeSource::Column {
                column: 0,
                factor: 1e-6
            }
        );
        assert_eq!(l.incident.unit, ChannelUnit::Volt);
        assert_eq!(l.transmission.unit, ChannelUnit::Millivolt);
        assert_eq!(l.skip_lines, 4);
    }

    #[test]
    fn an_unmatched_header_lists_the_columns_and_the_layout() {
        let e = auto_layout(
            &strings(&["Time/s", "CH1/V", "CH2/V"]),
            0,
            Delimiter::Comma,
            "scope.csv",
        )
        .unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let m = e.to_string();
        assert!(m.contains("`incident`"), "{m}");
        assert!(
            m.contains("columns found: `Time/s`, `CH1/V`, `CH2/V`"),
            "{m}"
        );
        assert!(m.contains("--layout FILE"), "{m}");
        let m = auto_layout(
            &strings(&["Time/s", "incident/furlongs", "transmission/V"]),
            0,
            Delimiter::Comma,
            "r.csv",
        )
        .unwrap_err()
        .to_string();
        assert!(m.contains("no unit shpb knows"), "{m}");
    }

    #[test]
    fn gbk_text_is_decoded_when_it_is_not_utf8() {
        // "时间/s" in GBK: 时 = CA B1, 间 = BC E4.
        let gbk = b"\xca\xb1\xbc\xe4/s,incident/V\n0,1\n";
        let t = decode_text(gbk, None, "g.csv").unwrap();
        assert!(t.starts_with("时间/s,"), "{t}");
        let utf8 = "时间/s\n".as_bytes();
        assert_eq!(decode_text(utf8, None, "u.csv").unwrap(), "时间/s\n");
        // Named as UTF-8, GBK bytes are refused with the way out.
        let e = decode_text(gbk, Some(TextEncoding::Utf8), "g.csv").unwrap_err();
        assert!(e.to_string().contains("encoding = "), "{e}");
        assert!(decode_text(b"a\x00b", None, "w.csv").is_err());
    }

    #[test]
    fn rounded_times_become_their_least_squares_line() {
        let text = "Time/s,incident/ε,transmission/ε\n\
            -1.98E-04,0,0\n-1.98E-04,1e-6,0\n-1.97E-04,2e-6,0\n-1.97E-04,3e-6,0\n";
        let l = auto_layout(
            &strings(&["Time/s", "incident/ε", "transmission/ε"]),
            0,
            Delimiter::Comma,
            "r.csv",
        )
        .unwrap();
        let LayoutRecord::Strains(r) = l.parse(text, "r.csv").unwrap() else {
            panic!("strains expected")
        };
        // The line through (k, t/1e-4 s) = (0, -1.98), (1, -1.98), (2, -1.97), (3, -1.97):
        // slope Σ(k - 1.5)(t - t̄)/Σ(k - 1.5)² = 0.02/5 = 0.004, intercept -1.975 - 1.5·0.004.
        let dt = r.time_s[1] - r.time_s[0];
        assert!((dt - 4e-7).abs() < 1e-15, "{dt}");
        assert!((r.time_s[0] + 1.981e-4).abs() < 1e-15, "{}", r.time_s[0]);
        assert_eq!(r.incident_strain[3], 3e-6);
    }
}
