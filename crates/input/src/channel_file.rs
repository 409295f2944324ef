//! Records kept one file per oscilloscope channel, each with a header block (the Tektronix CSV
//! export: `"Record Length",50000,"Points",t,v` / `"Sample Interval",8e-9,s,t,v` /
//! `"Trigger Point"` / `"Trigger Time"` / `"Horizontal Offset"`, optionally `"Vertical Units"`,
//! in the first three columns; the samples as time,value in columns 4–5 of every line), and a
//! record assembled from several such files ([`ChannelSet`]: `shpb reduce --channel
//! incident=FILE --channel transmission=FILE`). A file is recognised by its content
//! ([`is_channel_file`]); every header value is checked against the samples it describes.

use crate::error::{Error, Result};
use shpb_core::gauge::RawRecord;
use std::path::{Path, PathBuf};

/// The header keys a channel file may carry in its first column (the others are refused, so a
/// file of another kind is not read as one).
const KNOWN_KEYS: [&str; 19] = [
    "Record Length",
    "Sample Interval",
    "Trigger Point",
    "Trigger Time",
    "Horizontal Offset",
    "Source",
    "Vertical Units",
    "Vertical Scale",
    "Vertical Offset",
    "Horizontal Units",
    "Horizontal Scale",
    "Pt Fmt",
    "Yzero",
    "Probe Atten",
    "Model Number",
    "Serial Number",
    "Firmware Version",
    "Label",
    "Note",
];

/// What a sample's time may differ by from the header's clock, in sample intervals.
const CLOCK_TOLERANCE: f64 = 1e-3;

/// One oscilloscope channel read from its own file: the header block and the samples, in SI
/// units (time s, value V).
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelFile {
    /// The file, for messages.
    pub source: String,
    /// Sample interval Δt from the header, s.
    pub sample_interval_s: f64,
    /// The sample at which the scope triggered (0-based, from the header), if stated.
    pub trigger_point: Option<usize>,
    /// Time of the trigger relative to its sample, s, if stated.
    pub trigger_time_s: Option<f64>,
    /// Time of the first sample, s (the header's horizontal offset, else the time column's).
    pub horizontal_offset_s: f64,
    /// Sample times, s (the time column; from offset + k Δt where the file has none).
    pub time_s: Vec<f64>,
    /// Sample values, V.
    pub value_v: Vec<f64>,
}

/// Whether `text` is a channel file with a header block: its first line's first field is one
/// of the header keys (`"Record Length"`, …), and it names a record length and a sample interval.
pub fn is_channel_file(text: &str) -> bool {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let first_key = |line: &str| unquote(line.split(',').next().unwrap_or("")).to_string();
    let Some(first) = text.lines().next() else {
        return false;
    };
    if !KNOWN_KEYS.contains(&first_key(first).as_str()) {
        return false;
    }
    let head: Vec<String> = text.lines().take(40).map(first_key).collect();
    head.iter().any(|k| k == "Record Length") && head.iter().any(|k| k == "Sample Interval")
}

/// A field without its surrounding blanks and double quotes.
fn unquote(field: &str) -> &str {
    let t = field.trim();
    t.strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(t)
        .trim()
}

impl ChannelFile {
    /// Parses a channel file's text; `file` names it in errors, which give `file:line` and the
    /// header key or column at fault.
    pub fn parse(text: &str, file: &str) -> Result<ChannelFile> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let at = |line: usize| format!("{file}:{line}");
        let mut header: Vec<(String, String, String, usize)> = Vec::new();
        let (mut times, mut values) = (Vec::new(), Vec::new());
        let mut has_time = None;
        for (n, line) in text.lines().enumerate() {
            let line = line.trim_end_matches('\r');
            if line.trim().is_empty() {
                continue;
            }
            let fields: Vec<&str> = line.split(',').collect();
            let key = unquote(fields[0]);
            if !key.is_empty() {
                if !KNOWN_KEYS.contains(&key) {
                    return Err(Error::Input {
                        file: at(n + 1),
                        key: key.to_string(),
                        problem: "not a header key of a channel file".into(),
                        allowed: KNOWN_KEYS.join(", "),
                    });
                }
                header.push((
                    key.to_string(),
                    unquote(fields.get(1).copied().unwrap_or("")).to_string(),
                    unquote(fields.get(2).copied().unwrap_or("")).to_string(),
                    n + 1,
                ));
            }
            // The samples: time and value in columns 4 and 5, or the value alone in column 4.
            let sample: Vec<&str> = fields.iter().skip(3).map(|f| unquote(f)).collect();
            let sample: Vec<&str> = match sample.iter().rposition(|f| !f.is_empty()) {
                Some(last) => sample[..=last].to_vec(),
                None => continue,
            };
            let number = |f: &str, column: usize| -> Result<f64> {
                f.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| Error::Input {
                        file: at(n + 1),
                        key: format!("column {column}"),
                        problem: format!("`{f}` is not a finite number"),
                        allowed: "a sample as time,value (s, V) in columns 4 and 5".into(),
                    })
            };
            let with_time = match sample.len() {
                2 => true,
                1 => false,
                k => {
                    return Err(Error::Input {
                        file: at(n + 1),
                        key: "columns 4-5".into(),
                        problem: format!("{k} fields after the header block's three columns"),
                        allowed:
                            "time,value (s, V) in columns 4 and 5, or the value alone in column 4"
                                .into(),
                    });
                }
            };
            if *has_time.get_or_insert(with_time) != with_time {
                return Err(Error::Input {
                    file: at(n + 1),
                    key: "columns 4-5".into(),
                    problem: "this line's sample has a different number of fields than the first's"
                        .into(),
                    allowed: "every sample as time,value, or every sample as a value alone".into(),
                });
            }
            if with_time {
                times.push(number(sample[0], 4)?);
                values.push(number(sample[1], 5)?);
            } else {
                values.push(number(sample[0], 4)?);
            }
        }
        let find = |key: &str| header.iter().find(|(k, ..)| k == key);
        let header_number = |key: &str| -> Result<Option<(f64, String, usize)>> {
            match find(key) {
                None => Ok(None),
                Some((_, v, unit, line)) => match v.parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(Some((x, unit.clone(), *line))),
                    _ => Err(Error::Input {
                        file: at(*line),
                        key: key.to_string(),
                        problem: format!("`{v}` is not a finite number"),
                        allowed: "a number in the header's second column".into(),
                    }),
                },
            }
        };
        let missing = |key: &str| Error::Input {
            file: file.to_string(),
            key: key.to_string(),
            problem: "missing from the header block".into(),
            allowed: "a channel file whose header names Record Length and Sample Interval".into(),
        };
        let seconds = |key: &str, unit: &str, line: usize| -> Result<()> {
            if unit.is_empty() || unit == "s" {
                Ok(())
            } else {
                Err(Error::Input {
                    file: at(line),
                    key: key.to_string(),
                    problem: format!("unit `{unit}`"),
                    allowed: "s".into(),
                })
            }
        };
        let (length, _, length_line) =
            header_number("Record Length")?.ok_or_else(|| missing("Record Length"))?;
        let (dt, dt_unit, dt_line) =
            header_number("Sample Interval")?.ok_or_else(|| missing("Sample Interval"))?;
        seconds("Sample Interval", &dt_unit, dt_line)?;
        if !(dt > 0.0 && dt <= 1.0) {
            return Err(Error::Input {
                file: at(dt_line),
                key: "Sample Interval".into(),
                problem: format!("{dt:e} s"),
                allowed: "greater than 0, at most 1 s".into(),
            });
        }
        if let Some((_, unit, _, line)) = find("Horizontal Units") {
            seconds("Horizontal Units", unit, *line)?;
        }
        // Vertical units: V (the default) or mV.
        let volts_per_unit = match find("Vertical Units") {
            None => 1.0,
            Some((_, u, _, line)) => match u.as_str() {
                "V" | "Volts" | "" => 1.0,
                "mV" => 1e-3,
                other => {
                    return Err(Error::Input {
                        file: at(*line),
                        key: "Vertical Units".into(),
                        problem: format!("unit `{other}`"),
                        allowed: "V, mV".into(),
                    });
                }
            },
        };
        if length.fract() != 0.0 || length < 2.0 || length as usize != values.len() {
            return Err(Error::Input {
                file: at(length_line),
                key: "Record Length".into(),
                problem: format!("{length} points stated, the file holds {}", values.len()),
                allowed: "the number of samples in the file (at least 2)".into(),
            });
        }
        let n = values.len();
        let trigger_point = match header_number("Trigger Point")? {
            None => None,
            Some((p, _, line)) => {
                if p.fract() != 0.0 || p < 0.0 || p as usize >= n {
                    return Err(Error::Input {
                        file: at(line),
                        key: "Trigger Point".into(),
                        problem: format!("sample {p}"),
                        allowed: format!("a sample index from 0 to {}", n - 1),
                    });
                }
                Some(p as usize)
            }
        };
        let trigger_time_s = match header_number("Trigger Time")? {
            None => None,
            Some((t, unit, line)) => {
                seconds("Trigger Time", &unit, line)?;
                Some(t)
            }
        };
        let offset = match header_number("Horizontal Offset")? {
            None => None,
            Some((t, unit, line)) => {
                seconds("Horizontal Offset", &unit, line)?;
                Some((t, line))
            }
        };
        let time_s: Vec<f64> = if times.is_empty() {
            let (t0, _) = offset.ok_or_else(|| Error::Input {
                file: file.to_string(),
                key: "Horizontal Offset".into(),
                problem: "the file has no time column and its header no horizontal offset".into(),
                allowed: "a time column (column 4) or a Horizontal Offset in the header".into(),
            })?;
            (0..n).map(|k| t0 + k as f64 * dt).collect()
        } else {
            // The time column must be the header's clock: t_k = t_0 + k Δt.
            let t0 = times[0];
            if let Some((off, line)) = offset
                && (off - t0).abs() > CLOCK_TOLERANCE * dt
            {
                return Err(Error::Input {
                    file: at(line),
                    key: "Horizontal Offset".into(),
                    problem: format!("{off:e} s, but the first sample is at {t0:e} s"),
                    allowed: "the time of the first sample".into(),
                });
            }
            if let Some(k) =
                (0..n).find(|&k| (times[k] - (t0 + k as f64 * dt)).abs() > CLOCK_TOLERANCE * dt)
            {
                return Err(Error::Input {
                    file: file.to_string(),
                    key: "Sample Interval".into(),
                    problem: format!(
                        "sample {} is at {:e} s, not at {:e} s as the header's {dt:e} s interval puts it",
                        k + 1,
                        times[k],
                        t0 + k as f64 * dt
                    ),
                    allowed: "samples evenly spaced by the stated interval".into(),
                });
            }
            times
        };
        Ok(ChannelFile {
            source: file.to_string(),
            sample_interval_s: dt,
            trigger_point,
            trigger_time_s,
            horizontal_offset_s: offset.map_or(time_s[0], |(t, _)| t),
            time_s,
            value_v: values.iter().map(|v| v * volts_per_unit).collect(),
        })
    }

    /// Reads a channel file (see [`ChannelFile::parse`]).
    pub fn read(path: &Path) -> Result<ChannelFile> {
        let text = crate::csv::read_text(path)?;
        ChannelFile::parse(&text, &path.display().to_string())
    }
}

/// The gauge a channel file records (`--channel ROLE=FILE`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The incident-bar gauge (incident and reflected waves).
    Incident,
    /// The transmission-bar gauge.
    Transmission,
}

impl Role {
    /// The roles with their names on the command line.
    pub const ALL: [(Role, &'static str); 2] = [
        (Role::Incident, "incident"),
        (Role::Transmission, "transmission"),
    ];

    /// The role's name.
    pub fn name(self) -> &'static str {
        Role::ALL
            .iter()
            .find(|(r, _)| *r == self)
            .map_or("?", |(_, n)| n)
    }
}

/// A record kept as one file per channel: the files of each gauge (several files of one gauge,
/// e.g. gauges on opposite faces of the bar, are averaged sample by sample, as the labs average
/// them to cancel bending; HopPyBar's mini-Kolsky reduction takes (Ch1 + Ch2)/2 and (Ch3 + Ch4)/2).
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelSet {
    /// The files in the order given, each with its role.
    pub files: Vec<(Role, PathBuf)>,
}

impl ChannelSet {
    /// The set of `--channel ROLE=FILE` specifications (`key` names the flag in errors): every
    /// role at least once.
    /// A file name that is not UTF-8 is taken as it is.
    pub fn from_specs<S: AsRef<std::ffi::OsStr>>(specs: &[S], key: &str) -> Result<ChannelSet> {
        use std::os::unix::ffi::OsStrExt;
        let allowed = "ROLE=FILE with ROLE incident or transmission, each role at least once";
        let mut files = Vec::new();
        for spec in specs {
            let bytes = spec.as_ref().as_bytes();
            let s = spec.as_ref().to_string_lossy();
            let Some(at) = bytes.iter().position(|&b| b == b'=') else {
                return Err(Error::Input {
                    file: "command line".into(),
                    key: key.into(),
                    problem: format!("`{s}` has no `=`"),
                    allowed: allowed.into(),
                });
            };
            let role = String::from_utf8_lossy(&bytes[..at]);
            let role = Role::ALL
                .iter()
                .find(|(_, n)| *n == role.trim())
                .map(|(r, _)| *r)
                .ok_or_else(|| Error::Input {
                    file: "command line".into(),
                    key: key.into(),
                    problem: format!("unknown channel role `{}`", role.trim()),
                    allowed: allowed.into(),
                })?;
            let file = bytes[at + 1..].trim_ascii();
            if file.is_empty() {
                return Err(Error::Input {
                    file: "command line".into(),
                    key: key.into(),
                    problem: format!("`{s}` names no file"),
                    allowed: allowed.into(),
                });
            }
            files.push((role, PathBuf::from(std::ffi::OsStr::from_bytes(file))));
        }
        for (role, name) in Role::ALL {
            if !files.iter().any(|(r, _)| *r == role) {
                return Err(Error::Input {
                    file: "command line".into(),
                    key: key.into(),
                    problem: format!("no {name} channel file"),
                    allowed: allowed.into(),
                });
            }
        }
        Ok(ChannelSet { files })
    }

    /// The files of role `role`.
    pub fn of(&self, role: Role) -> impl Iterator<Item = &Path> {
        self.files
            .iter()
            .filter(move |(r, _)| *r == role)
            .map(|(_, p)| p.as_path())
    }

    /// The record's name in messages and outputs: its first incident file.
    pub fn name(&self) -> PathBuf {
        self.of(Role::Incident)
            .next()
            .map_or_else(PathBuf::new, Path::to_path_buf)
    }

    /// The `--channel` flags that give this set (each preceded by a space).
    pub fn command_flags(&self) -> String {
        self.files
            .iter()
            .map(|(r, p)| format!(" --channel {}={}", r.name(), p.display()))
            .collect()
    }

    /// Reads every file and assembles the record: each gauge's files averaged, on the first
    /// file's clock. All files must share the sample interval, the length and the first sample's
    /// time (within a thousandth of an interval); an error names the file that differs.
    pub fn read(&self) -> Result<RawRecord> {
        let channels: Vec<(Role, ChannelFile)> = self
            .files
            .iter()
            .map(|(r, p)| ChannelFile::read(p).map(|c| (*r, c)))
            .collect::<Result<_>>()?;
        assemble(&channels)
    }
}

/// The record of channels read from their files ([`ChannelSet::read`]).
pub fn assemble(channels: &[(Role, ChannelFile)]) -> Result<RawRecord> {
    let (_, first) = channels.first().ok_or_else(|| Error::Input {
        file: "command line".into(),
        key: "--channel".into(),
        problem: "no channel files".into(),
        allowed: "incident=FILE and transmission=FILE".into(),
    })?;
    let dt = first.sample_interval_s;
    for (_, c) in &channels[1..] {
        let differs = |what: &str, theirs: String, ours: String| {
            Error::Input {
            file: c.source.clone(),
            key: what.into(),
            problem: format!("{theirs}, but {} has {ours}", first.source),
            allowed: "channel files of one record: the same sample interval, record length and first-sample time".into(),
        }
        };
        if (c.sample_interval_s - dt).abs() > CLOCK_TOLERANCE * dt {
            return Err(differs(
                "Sample Interval",
                format!("{:e} s", c.sample_interval_s),
                format!("{dt:e} s"),
            ));
        }
        if c.value_v.len() != first.value_v.len() {
            return Err(differs(
                "Record Length",
                format!("{} points", c.value_v.len()),
                format!("{} points", first.value_v.len()),
            ));
        }
        if (c.time_s[0] - first.time_s[0]).abs() > CLOCK_TOLERANCE * dt {
            return Err(differs(
                "Horizontal Offset",
                format!("first sample at {:e} s", c.time_s[0]),
                format!("{:e} s", first.time_s[0]),
            ));
        }
    }
    // A gauge read from several files is the mean of them: a clipped file among them would be
    // hidden by the others (a peak rounded instead of flat), a dead one would halve the pulse.
    // So each file of such a gauge is checked alone first: clipped always, dead when another
    // file of the gauge is alive (issue 42; the mean record is checked as a whole later).
    use shpb_core::reduce::plausibility::{Channel, check_channels_named};
    let alone = |role: Role, c: &ChannelFile, check: &str| {
        let channel = Channel {
            name: role.name(),
            time_s: &c.time_s,
            strain: &c.value_v,
            volts: true,
            youngs_modulus_pa: None,
            baseline_samples: 0,
            smoothing_window_s: 0.0,
            pulse_due_s: None,
        };
        check_channels_named(&[channel], &c.source, &[check])
    };
    for (role, _) in Role::ALL {
        let of: Vec<&ChannelFile> = channels
            .iter()
            .filter(|(r, _)| *r == role)
            .map(|(_, c)| c)
            .collect();
        if of.len() < 2 {
            continue;
        }
        for c in &of {
            alone(role, c, "clipped")?;
        }
        let dead: Vec<shpb_core::Result<()>> =
            of.iter().map(|c| alone(role, c, "dead-channel")).collect();
        if dead.iter().any(|d| d.is_ok()) {
            dead.into_iter().collect::<shpb_core::Result<()>>()?;
        }
    }
    let mean = |role: Role| -> Vec<f64> {
        let of: Vec<&ChannelFile> = channels
            .iter()
            .filter(|(r, _)| *r == role)
            .map(|(_, c)| c)
            .collect();
        let k = of.len() as f64;
        (0..first.value_v.len())
            .map(|i| of.iter().map(|c| c.value_v[i]).sum::<f64>() / k)
            .collect()
    };
    Ok(RawRecord {
        time_s: first.time_s.clone(),
        incident_v: mean(Role::Incident),
        transmission_v: mean(Role::Transmission),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Tektronix export of six samples `dt` apart from `offset`, its header block as the
    /// LANL files have it.
    fn tek(values: [f64; 6], dt: f64, offset: f64) -> String {
        let head = [
            "\"Record Length\",6,\"Points\"".to_string(),
            format!("\"Sample Interval\",{dt:e},s"),
            "\"Trigger Point\",2,\"Samples\"".to_string(),
            "\"Trigger Time\",7.8e-9,s".to_string(),
            "\"\",,".to_string(),
            format!("\"Horizontal Offset\",{offset:e},s"),
        ];
        let mut s = String::new();
        for (k, v) in values.iter().enumerate() {
            s.push_str(&format!(
                "{},{:e},{v:e}\r\n",
                head[k],
                offset + k as f64 * dt
            ));
        }
        s
    }

    #[test]
    fn a_tektronix_channel_reads_with_its_header() {
        let text = tek([0.1, -0.2, 0.3, 0.4, 0.5, 0.6], 8e-9, -16e-9);
        assert!(is_channel_file(&text));
        let c = ChannelFile::parse(&text, "ch1.csv").unwrap();
        assert_eq!(c.sample_interval_s, 8e-9);
        assert_eq!(c.trigger_point, Some(2));
        assert_eq!(c.trigger_time_s, Some(7.8e-9));
        assert_eq!(c.horizontal_offset_s, -16e-9);
        assert_eq!(c.value_v, vec![0.1, -0.2, 0.3, 0.4, 0.5, 0.6]);
        assert!((c.time_s[3] - 8e-9).abs() < 1e-20);
    }

    #[test]
    fn other_files_are_not_channel_files() {
        assert!(!is_channel_file(
            "time_s,incident_V,transmission_V\n0,1,2\n"
        ));
        assert!(!is_channel_file("Test Date\t3/2/18\t\t\n"));
        assert!(!is_channel_file(""));
    }

    #[test]
    fn a_header_that_contradicts_the_samples_is_named() {
        let err = |t: &str| ChannelFile::parse(t, "c.csv").unwrap_err().to_string();
        let t = tek([0.1, 0.2, 0.3, 0.4, 0.5, 0.6], 8e-9, -16e-9)
            .replace("\"Record Length\",6", "\"Record Length\",7");
        let e = err(&t);
        assert!(
            e.contains("c.csv:1") && e.contains("Record Length") && e.contains("holds 6"),
            "{e}"
        );
        let t = tek([0.1, 0.2, 0.3, 0.4, 0.5, 0.6], 8e-9, -16e-9)
            .replace("\"Sample Interval\",8e-9", "\"Sample Interval\",1e-8");
        let e = err(&t);
        assert!(
            e.contains("Sample Interval") && e.contains("evenly spaced"),
            "{e}"
        );
        let t = tek([0.1, 0.2, 0.3, 0.4, 0.5, 0.6], 8e-9, -16e-9).replace("7.8e-9", "x");
        assert!(err(&t).contains("c.csv:4") && err(&t).contains("Trigger Time"));
        let t = tek([0.1, 0.2, 0.3, 0.4, 0.5, 0.6], 8e-9, -16e-9).replacen(
            ",-8e-9,",
            ",-8e-9,oops,",
            1,
        );
        let e = err(&t);
        assert!(e.contains("3 fields"), "{e}");
    }

    #[test]
    fn channels_of_one_record_are_averaged_on_one_clock() {
        let read = |v, dt, off, name: &str| ChannelFile::parse(&tek(v, dt, off), name).unwrap();
        let a = read([1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 8e-9, -16e-9, "ch1.csv");
        let b = read([3.0, 2.0, 1.0, 0.0, -1.0, -2.0], 8e-9, -16e-9, "ch2.csv");
        let t = read([0.5; 6], 8e-9, -16e-9, "ch3.csv");
        let r = assemble(&[
            (Role::Incident, a.clone()),
            (Role::Incident, b),
            (Role::Transmission, t),
        ])
        .unwrap();
        assert_eq!(r.incident_v, vec![2.0; 6]);
        assert_eq!(r.transmission_v, vec![0.5; 6]);
        let other = read([0.5; 6], 4e-9, -16e-9, "slow.csv");
        let e = assemble(&[(Role::Incident, a.clone()), (Role::Transmission, other)])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("slow.csv") && e.contains("Sample Interval") && e.contains("ch1.csv"),
            "{e}"
        );
        let late = read([0.5; 6], 8e-9, 0.0, "late.csv");
        let e = assemble(&[(Role::Incident, a), (Role::Transmission, late)])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("late.csv") && e.contains("Horizontal Offset"),
            "{e}"
        );
    }

    /// A pulse of `n` samples with a little alternating noise, its top cut at `rail` V.
    fn pulse_file(name: &str, n: usize, rail: f64) -> ChannelFile {
        let dt = 1e-7;
        let value_v: Vec<f64> = (0..n)
            .map(|k| {
                let x = (k as f64 - n as f64 / 2.0) / (n as f64 / 10.0);
                let noise = if k % 2 == 0 { 1e-4 } else { -1e-4 };
                ((-x * x).exp() + noise).min(rail)
            })
            .collect();
        ChannelFile {
            source: name.into(),
            sample_interval_s: dt,
            trigger_point: None,
            trigger_time_s: None,
            horizontal_offset_s: 0.0,
            time_s: (0..n).map(|k| k as f64 * dt).collect(),
            value_v,
        }
    }

    #[test]
    fn a_clipped_or_dead_file_among_averaged_files_is_named() {
        // Averaged with an unclipped opposite gauge, the flat top sits at half height, not at
        // the mean channel's extreme: only the file alone shows it.
        let good = pulse_file("ch1.csv", 400, 2.0);
        let clipped = pulse_file("ch2.csv", 400, 0.6);
        let other = pulse_file("ch3.csv", 400, 2.0);
        let e = assemble(&[
            (Role::Incident, good.clone()),
            (Role::Incident, clipped),
            (Role::Transmission, other.clone()),
        ])
        .unwrap_err()
        .to_string();
        assert!(e.contains("ch2.csv") && e.contains("clipped"), "{e}");
        let mut dead = good.clone();
        dead.source = "dead.csv".into();
        dead.value_v.iter_mut().for_each(|v| *v = 0.0);
        let e = assemble(&[
            (Role::Incident, good.clone()),
            (Role::Incident, dead),
            (Role::Transmission, other.clone()),
        ])
        .unwrap_err()
        .to_string();
        assert!(e.contains("dead.csv") && e.contains("dead"), "{e}");
        assemble(&[
            (Role::Incident, good.clone()),
            (Role::Incident, good),
            (Role::Transmission, other),
        ])
        .unwrap();
    }

    #[test]
    fn channel_specs_need_both_roles() {
        let s = |v: &[&str]| {
            ChannelSet::from_specs(
                &v.iter().map(|s| s.to_string()).collect::<Vec<_>>(),
                "--channel",
            )
        };
        let set = s(&["incident=a.csv", "incident=b.csv", "transmission=c.csv"]).unwrap();
        assert_eq!(set.of(Role::Incident).count(), 2);
        assert_eq!(set.name(), PathBuf::from("a.csv"));
        assert!(
            set.command_flags()
                .contains(" --channel transmission=c.csv")
        );
        let e = s(&["incident=a.csv"]).unwrap_err().to_string();
        assert!(e.contains("no transmission channel file"), "{e}");
        let e = s(&["reflected=a.csv"]).unwrap_err().to_string();
        assert!(e.contains("unknown channel role `reflected`"), "{e}");
        assert!(
            s(&["a.csv"])
                .unwrap_err()
                .to_string()
                .contains("has no `=`")
        );
    }
}
