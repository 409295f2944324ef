//! Record layouts (`shpb reduce --layout FILE`, `shpb strain --layout FILE`): how to read a lab's
//! own oscilloscope or DAQ text export — header lines, delimiter, decimal mark, a time column or
//! a sample rate, the two channels' columns, units and polarities — without a conversion script.
//!
//! ```toml
//! description = "scope export: 3 header lines, time in µs, mV, semicolons, decimal commas"
//! delimiter = "semicolon"   # comma (default), tab, semicolon, whitespace
//! decimal = ","             # "." (default) or ","
//! skip_lines = 3            # lines before the data (lines starting with '#' are skipped too)
//! time_column = 1           # 1-based; or leave it out and give sample_rate_hz
//! time_unit = "us"          # s (default), ms, us, ns
//! [incident]
//! column = 2
//! unit = "mV"               # V, mV (bridge output: read through the set-up's bridges),
//!                           # strain, microstrain (bar strain, tension positive: used as is)
//! polarity = 1              # +1 or -1: multiplies the channel as read
//! [transmission]
//! column = 3
//! unit = "mV"
//! polarity = -1
//! ```
//!
//! Two more keys for spreadsheets and other encodings ([`crate::sheet`]): `sheet = "Sheet2"`
//! (an XLS/XLSX record's sheet; default the first), `encoding = "gbk"` (a text record's encoding:
//! `utf-8`, `gbk` or `gb18030`; default: UTF-8 if the bytes are valid UTF-8, else GB18030).
//! A time column printed with too few digits (equal neighbours, never decreasing) is replaced by
//! its least-squares line t₀ + k·Δt over the sample index k.

use crate::error::{Error, Result, Validator};
use serde::Deserialize;
use shpb_core::gauge::RawRecord;
use shpb_core::reduce::ReductionInput;
use std::path::Path;

/// The column separator of a record export.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delimiter {
    /// `,`
    Comma,
    /// A tab.
    Tab,
    /// `;`
    Semicolon,
    /// Any run of spaces or tabs.
    Whitespace,
}

/// What a channel's numbers are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChannelUnit {
    /// Bridge output, V.
    Volt,
    /// Bridge output, mV.
    Millivolt,
    /// Bar strain (tension positive).
    Strain,
    /// Bar strain in µε (tension positive).
    Microstrain,
}

impl ChannelUnit {
    /// Factor from the file's number to V or to strain.
    fn factor(self) -> f64 {
        match self {
            ChannelUnit::Volt | ChannelUnit::Strain => 1.0,
            ChannelUnit::Millivolt => 1e-3,
            ChannelUnit::Microstrain => 1e-6,
        }
    }

    /// Whether the channel is a bridge voltage (else a strain).
    pub fn is_voltage(self) -> bool {
        matches!(self, ChannelUnit::Volt | ChannelUnit::Millivolt)
    }
}

/// One channel of a layout, validated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelLayout {
    /// 0-based column.
    pub column: usize,
    /// Unit of the numbers.
    pub unit: ChannelUnit,
    /// +1 or −1.
    pub polarity: f64,
}

/// Where the times come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeSource {
    /// A column (0-based) in seconds times `factor`.
    Column {
        /// 0-based column.
        column: usize,
        /// Factor from the file's unit to s.
        factor: f64,
    },
    /// t_k = k / rate.
    SampleRate {
        /// Samples per second, Hz.
        rate_hz: f64,
    },
}

/// The encoding of a text record (layout key `encoding`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextEncoding {
    /// UTF-8 (a leading byte-order mark is dropped).
    Utf8,
    /// GB18030, the superset of GBK (what `gbk` names too).
    Gb18030,
}

impl TextEncoding {
    /// The names a layout may give, for messages.
    pub const ALLOWED: &'static str = "utf-8, gbk or gb18030";

    /// The encoding called `name` in a layout (`utf-8`, `utf8`, `gbk`, `gb18030`, any case).
    pub fn from_name(name: &str) -> Option<TextEncoding> {
        match name.trim().to_ascii_lowercase().as_str() {
            "utf-8" | "utf8" => Some(TextEncoding::Utf8),
            "gbk" | "gb18030" | "gb2312" | "cp936" => Some(TextEncoding::Gb18030),
            _ => None,
        }
    }
}

/// A validated record layout (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct RecordLayout {
    /// The layout file, for messages.
    pub source: String,
    /// Column separator.
    pub delimiter: Delimiter,
    /// Decimal mark (`.` or `,`).
    pub decimal: char,
    /// Lines before the data.
    pub skip_lines: usize,
    /// Time axis.
    pub time: TimeSource,
    /// Incident-gauge channel.
    pub incident: ChannelLayout,
    /// Transmission-gauge channel.
    pub transmission: ChannelLayout,
    /// The sheet of a spreadsheet record (None: the first).
    pub sheet: Option<String>,
    /// The encoding of a text record (None: UTF-8 if valid, else GB18030).
    pub encoding: Option<TextEncoding>,
}

/// A record read through a layout: bridge voltages (to go through the set-up's bridges) or bar
/// strains.
#[derive(Debug, Clone, PartialEq)]
pub enum LayoutRecord {
    /// Both channels are bridge voltages, V.
    Voltages(RawRecord),
    /// Both channels are bar strains.
    Strains(ReductionInput),
}

impl LayoutRecord {
    /// Samples in the record.
    pub fn samples(&self) -> usize {
        match self {
            LayoutRecord::Voltages(r) => r.time_s.len(),
            LayoutRecord::Strains(s) => s.time_s.len(),
        }
    }

    /// The record as bar strains: voltages through the set-up's bridges, the mean of their first
    /// `baseline_samples` samples removed ([`shpb_core::reduce::record_strains`]); strains as read.
    pub fn into_strains(
        self,
        apparatus: &shpb_core::apparatus::Apparatus,
        baseline_samples: usize,
    ) -> shpb_core::Result<ReductionInput> {
        match self {
            LayoutRecord::Voltages(raw) => {
                shpb_core::reduce::record_strains(&raw, apparatus, baseline_samples)
            }
            LayoutRecord::Strains(input) => Ok(input),
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ChannelFile {
    column: i64,
    unit: String,
    #[serde(default = "plus_one")]
    polarity: f64,
}

fn plus_one() -> f64 {
    1.0
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LayoutFile {
    #[serde(default)]
    #[allow(dead_code)]
    description: Option<String>,
    #[serde(default)]
    delimiter: Option<String>,
    #[serde(default)]
    decimal: Option<String>,
    #[serde(default)]
    skip_lines: i64,
    time_column: Option<i64>,
    #[serde(default)]
    time_unit: Option<String>,
    sample_rate_hz: Option<f64>,
    #[serde(default)]
    sheet: Option<String>,
    #[serde(default)]
    encoding: Option<String>,
    incident: ChannelFile,
    transmission: ChannelFile,
}

impl RecordLayout {
    /// Parses and validates a layout's TOML text; `file` names it in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<RecordLayout> {
        let raw: LayoutFile = crate::toml_file::parse_as(text, file)?;
        let v = Validator::new(file);
        let delimiter = match raw.delimiter.as_deref().unwrap_or("comma") {
            "comma" | "," => Delimiter::Comma,
            "tab" | "\t" => Delimiter::Tab,
            "semicolon" | ";" => Delimiter::Semicolon,
            "whitespace" | "space" => Delimiter::Whitespace,
            other => {
                return Err(v.error(
                    "delimiter",
                    format!("`{other}`"),
                    "comma, tab, semicolon or whitespace",
                ));
            }
        };
        let decimal = match raw.decimal.as_deref().unwrap_or(".") {
            "." => '.',
            "," => ',',
            other => return Err(v.error("decimal", format!("`{other}`"), "\".\" or \",\"")),
        };
        if decimal == ',' && delimiter == Delimiter::Comma {
            return Err(v.error(
                "decimal",
                "`,` with `delimiter = \"comma\"`",
                "a decimal comma with tab, semicolon or whitespace delimiters",
            ));
        }
        if !(0..=100_000).contains(&raw.skip_lines) {
            return Err(v.error(
                "skip_lines",
                format!("{}", raw.skip_lines),
                "0 to 100000 lines",
            ));
        }
        let column = |key: &str, c: i64| -> Result<usize> {
            if (1..=1000).contains(&c) {
                Ok((c - 1) as usize)
            } else {
                Err(v.error(
                    key,
                    format!("{c}"),
                    "a column number from 1 (the first) to 1000",
                ))
            }
        };
        let time = match (raw.time_column, raw.sample_rate_hz) {
            (Some(c), None) => {
                let factor = match raw.time_unit.as_deref().unwrap_or("s") {
                    "s" => 1.0,
                    "ms" => 1e-3,
                    "us" | "µs" => 1e-6,
                    "ns" => 1e-9,
                    other => {
                        return Err(v.error("time_unit", format!("`{other}`"), "s, ms, us or ns"));
                    }
                };
                TimeSource::Column {
                    column: column("time_column", c)?,
                    factor,
                }
            }
            (None, Some(rate)) => {
                if !(rate.is_finite() && rate > 0.0) {
                    return Err(v.error(
                        "sample_rate_hz",
                        format!("{rate}"),
                        "a positive rate, Hz",
                    ));
                }
                if raw.time_unit.is_some() {
                    return Err(v.error(
                        "time_unit",
                        "given without time_column",
                        "time_unit only with time_column",
                    ));
                }
                TimeSource::SampleRate { rate_hz: rate }
            }
            (Some(_), Some(_)) => {
                return Err(v.error(
                    "sample_rate_hz",
                    "given with time_column",
                    "either time_column or sample_rate_hz",
                ));
            }
            (None, None) => {
                return Err(v.error(
                    "time_column",
                    "missing",
                    "time_column (1-based) or sample_rate_hz",
                ));
            }
        };
        let channel = |name: &str, c: &ChannelFile| -> Result<ChannelLayout> {
            let unit = match c.unit.as_str() {
                "V" => ChannelUnit::Volt,
                "mV" => ChannelUnit::Millivolt,
                "strain" => ChannelUnit::Strain,
                "microstrain" | "µε" => ChannelUnit::Microstrain,
                other => {
                    return Err(v.error(
                        &format!("{name}.unit"),
                        format!("`{other}`"),
                        "V, mV, strain or microstrain",
                    ));
                }
            };
            if c.polarity != 1.0 && c.polarity != -1.0 {
                return Err(v.error(
                    &format!("{name}.polarity"),
                    format!("{}", c.polarity),
                    "1 or -1",
                ));
            }
            Ok(ChannelLayout {
                column: column(&format!("{name}.column"), c.column)?,
                unit,
                polarity: c.polarity,
            })
        };
        let incident = channel("incident", &raw.incident)?;
        let transmission = channel("transmission", &raw.transmission)?;
        if incident.unit.is_voltage() != transmission.unit.is_voltage() {
            return Err(v.error(
                "transmission.unit",
                "a voltage and a strain channel mixed",
                "both channels bridge voltages (V, mV) or both bar strains (strain, microstrain)",
            ));
        }
        let encoding =
            match raw.encoding.as_deref() {
                None => None,
                Some(name) => Some(TextEncoding::from_name(name).ok_or_else(|| {
                    v.error("encoding", format!("`{name}`"), TextEncoding::ALLOWED)
                })?),
            };
        Ok(RecordLayout {
            source: file.to_string(),
            delimiter,
            decimal,
            skip_lines: raw.skip_lines as usize,
            time,
            incident,
            transmission,
            sheet: raw.sheet,
            encoding,
        })
    }

    /// Reads and validates a layout file.
    pub fn from_file(path: &Path) -> Result<RecordLayout> {
        let text = crate::files::read_to_string(path).map_err(|e| Error::io(path, e))?;
        RecordLayout::from_toml(&text, &path.display().to_string())
    }

    /// The fields of one data line.
    fn fields<'a>(&self, line: &'a str) -> Vec<&'a str> {
        match self.delimiter {
            Delimiter::Comma => line.split(',').collect(),
            Delimiter::Tab => line.split('\t').collect(),
            Delimiter::Semicolon => line.split(';').collect(),
            Delimiter::Whitespace => line.split_whitespace().collect(),
        }
    }

    /// Parses a record's text through the layout; `file` names it in errors, which give
    /// `file:line` and the layout key of the column at fault.
    pub fn parse(&self, text: &str, file: &str) -> Result<LayoutRecord> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let rows = text.lines().enumerate().map(|(n, line)| {
            let trimmed = line.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                (n + 1, Vec::new())
            } else {
                (n + 1, self.fields(line.trim_end_matches('\r')))
            }
        });
        self.parse_rows(rows, file)
    }

    /// Parses a record's rows (1-based line or row number, the row's fields; a row without
    /// fields is skipped) through the layout: the text lines of [`RecordLayout::parse`] or a
    /// spreadsheet's rows ([`crate::sheet`]). The first `skip_lines` rows are skipped.
    pub fn parse_rows<S: AsRef<str>>(
        &self,
        rows: impl Iterator<Item = (usize, Vec<S>)>,
        file: &str,
    ) -> Result<LayoutRecord> {
        let (mut time_s, mut incident, mut transmission) = (Vec::new(), Vec::new(), Vec::new());
        let number = |field: &str, line: usize, key: &str| -> Result<f64> {
            let t = field.trim();
            let t = if self.decimal == ',' {
                t.replace(',', ".")
            } else {
                t.to_string()
            };
            match t.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(Error::Input {
                    file: format!("{file}:{line}"),
                    key: key.to_string(),
                    problem: format!("`{}` is not a finite number", field.trim()),
                    allowed: format!(
                        "numbers with the decimal mark `{}` (layout {})",
                        self.decimal, self.source
                    ),
                }),
            }
        };
        for (line, fields) in rows.skip(self.skip_lines) {
            if fields.is_empty() {
                continue;
            }
            let get = |c: usize, key: &str| -> Result<f64> {
                match fields.get(c) {
                    Some(f) => number(f.as_ref(), line, key),
                    None => Err(Error::Input {
                        file: format!("{file}:{line}"),
                        key: key.to_string(),
                        problem: format!(
                            "the line has {} fields, the layout reads column {}",
                            fields.len(),
                            c + 1
                        ),
                        allowed: format!("lines with the columns layout {} names", self.source),
                    }),
                }
            };
            let k = incident.len();
            time_s.push(match self.time {
                TimeSource::Column { column, factor } => get(column, "time_column")? * factor,
                TimeSource::SampleRate { rate_hz } => k as f64 / rate_hz,
            });
            let ch = |c: &ChannelLayout, key: &str| -> Result<f64> {
                Ok(get(c.column, key)? * c.unit.factor() * c.polarity)
            };
            incident.push(ch(&self.incident, "incident.column")?);
            transmission.push(ch(&self.transmission, "transmission.column")?);
        }
        if time_s.len() < 2 {
            return Err(Error::Input {
                file: file.to_string(),
                key: "skip_lines".into(),
                problem: format!("{} data lines after the skipped ones", time_s.len()),
                allowed: format!("at least two data lines (layout {})", self.source),
            });
        }
        if time_s.windows(2).all(|w| w[1] >= w[0]) && time_s.first() < time_s.last() {
            // Times printed with too few digits (e.g. `-1.98E-04` for many samples in a row):
            // the least-squares line through them over the sample index (module docs).
            let index: Vec<f64> = (0..time_s.len()).map(|k| k as f64).collect();
            let ones = vec![1.0; time_s.len()];
            if time_s.windows(2).any(|w| w[1] == w[0])
                && let Some(line) = shpb_core::numeric::least_squares(&[&ones, &index], &time_s)
                && line[1] > 0.0
            {
                time_s = index.iter().map(|k| line[0] + line[1] * k).collect();
            }
        }
        if let Some(i) = time_s.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::Input {
                file: file.to_string(),
                key: "time_column".into(),
                problem: format!(
                    "time {:e} s (data line {}) does not follow {:e} s",
                    time_s[i + 1],
                    i + 2,
                    time_s[i]
                ),
                allowed: "strictly increasing times".into(),
            });
        }
        Ok(if self.incident.unit.is_voltage() {
            LayoutRecord::Voltages(RawRecord {
                time_s,
                incident_v: incident,
                transmission_v: transmission,
            })
        } else {
            LayoutRecord::Strains(ReductionInput {
                time_s,
                incident_strain: incident,
                transmission_strain: transmission,
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCOPE: &str = "description = \"scope\"\ndelimiter = \"semicolon\"\ndecimal = \",\"\n\
        skip_lines = 2\ntime_column = 1\ntime_unit = \"us\"\n\
        [incident]\ncolumn = 2\nunit = \"mV\"\n[transmission]\ncolumn = 3\nunit = \"mV\"\npolarity = -1\n";

    #[test]
    fn a_scope_export_reads_in_si_with_its_polarity() {
        let layout = RecordLayout::from_toml(SCOPE, "scope.toml").unwrap();
        let text = "\u{feff}Model XYZ\nTime(us);CH1(mV);CH2(mV)\n0,0;1,5;2\n0,1;-3;4,25\n";
        let LayoutRecord::Voltages(r) = layout.parse(text, "rec.txt").unwrap() else {
            panic!("voltages expected");
        };
        assert_eq!(r.time_s, vec![0.0, 0.1 * 1e-6]);
        assert_eq!(r.incident_v, vec![1.5 * 1e-3, -3.0 * 1e-3]);
        assert_eq!(r.transmission_v, vec![-2.0 * 1e-3, -4.25 * 1e-3]);
    }

    #[test]
    fn bad_layouts_and_lines_are_named() {
        let err = |text: &str| {
            RecordLayout::from_toml(text, "l.toml")
                .unwrap_err()
                .to_string()
        };
        let e = err(&SCOPE.replace("column = 2", "column = 0"));
        assert!(
            e.contains("`incident.column`") && e.contains("from 1"),
            "{e}"
        );
        let e = err(&SCOPE.replace("polarity = -1", "polarity = 2"));
        assert!(
            e.contains("`transmission.polarity`") && e.contains("1 or -1"),
            "{e}"
        );
        let e = err(&SCOPE.replace(
            "unit = \"mV\"\n[transmission]",
            "unit = \"strain\"\n[transmission]",
        ));
        assert!(e.contains("mixed"), "{e}");
        let e = err(&SCOPE.replace("time_column = 1\ntime_unit = \"us\"\n", ""));
        assert!(e.contains("`time_column`: missing"), "{e}");
        let e = err(&format!("{SCOPE}gain = 2\n"));
        assert!(e.contains("gain"), "{e}");
        let layout = RecordLayout::from_toml(SCOPE, "scope.toml").unwrap();
        let e = layout
            .parse("a\nb\n0,0;1\n", "rec.txt")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("rec.txt:3: `transmission.column`"), "{e}");
        let e = layout
            .parse("a\nb\n0,0;x;1\n", "rec.txt")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`x` is not a finite number"), "{e}");
    }

    #[test]
    fn a_sample_rate_makes_the_time_axis() {
        let text = "sample_rate_hz = 1e7\n[incident]\ncolumn = 1\nunit = \"microstrain\"\n\
            [transmission]\ncolumn = 2\nunit = \"strain\"\n";
        let layout = RecordLayout::from_toml(text, "l.toml").unwrap();
        let LayoutRecord::Strains(r) = layout.parse("100,1e-4\n-50,2e-4\n", "r.csv").unwrap()
        else {
            panic!("strains expected");
        };
        assert_eq!(r.time_s, vec![0.0, 1e-7]);
        assert_eq!(r.incident_strain, vec![100.0 * 1e-6, -50.0 * 1e-6]);
        assert_eq!(r.transmission_strain, vec![1e-4, 2e-4]);
    }
}
