//! Gauge files (`bars/gauges-*.toml`) and raw gauge records (the authors' CSV), validated into
//! the core's [`GaugeSetup`] and [`RawRecord`].

use crate::csv::CsvTable;
use crate::error::{Error, Result, Validator};
use serde::Deserialize;
use shpb_core::apparatus::Apparatus;
use shpb_core::gauge::{Bridge, BridgeKind, Digitiser, GaugeChannel, GaugeSetup, RawRecord};
use shpb_core::reduce::{
    Reduction, ReductionOptions, ReductionSetup, record_strains, reduce_named,
};
use std::path::Path;

/// The lowest recorder sample rate a gauge channel may have, Hz: 10 samples over a 100 µs
/// pulse (the shortest SHPB pulse of the authors' set-up is ≈ 80 µs), the fewest a reduction
/// window can be cut from.
pub const MIN_SAMPLE_RATE_HZ: f64 = 1e5;

/// One `[[channel]]` table of a gauge file (or of a set-up file's inline channels), before
/// validation. `bridge = "linear"` takes `strain_per_volt` instead of `gauge_factor`,
/// `excitation_v` and `poisson_ratio`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ChannelSpec {
    name: String,
    bar: String,
    distance_from_specimen_m: f64,
    bridge: String,
    gauge_factor: Option<f64>,
    excitation_v: Option<f64>,
    poisson_ratio: Option<f64>,
    strain_per_volt: Option<f64>,
    #[serde(default = "unit_gain")]
    amplifier_gain: f64,
    polarity: f64,
    sample_rate_hz: f64,
    adc_bits: i64,
    adc_range_v: f64,
    #[serde(default)]
    noise_rms_v: f64,
    seed: Option<i64>,
}

fn unit_gain() -> f64 {
    1.0
}

/// A gauge file: an optional description and one or more `[[channel]]` tables.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SetupFile {
    #[serde(default)]
    #[allow(dead_code)]
    description: Option<String>,
    channel: Vec<ChannelSpec>,
}

impl ChannelSpec {
    /// Validates one channel; `index` is its position (seed default), `v` reports `channel[i].*`.
    fn build(&self, index: usize, v: &Validator) -> Result<GaugeChannel> {
        let text = |key: &str, s: &str| -> Result<String> {
            if s.trim().is_empty() {
                Err(v.error(key, "empty", "a non-empty name"))
            } else {
                Ok(s.trim().to_string())
            }
        };
        let kind = BridgeKind::from_name(self.bridge.trim()).ok_or_else(|| {
            v.error(
                "bridge",
                format!("unknown bridge kind `{}`", self.bridge),
                BridgeKind::ALL
                    .iter()
                    .map(|(_, n)| format!("\"{n}\""))
                    .collect::<Vec<_>>()
                    .join(", "),
            )
        })?;
        if self.polarity != 1.0 && self.polarity != -1.0 {
            return Err(v.error(
                "polarity",
                format!("{} is not ±1", self.polarity),
                "1 or -1",
            ));
        }
        if !(1..=32).contains(&self.adc_bits) {
            return Err(v.error(
                "adc_bits",
                format!("{} bits is out of range", self.adc_bits),
                "1 to 32 bits",
            ));
        }
        let seed = match self.seed {
            Some(s) if s < 0 => {
                return Err(v.error(
                    "seed",
                    format!("{s} is negative"),
                    "0 to 9223372036854775807",
                ));
            }
            Some(s) => s as u64,
            None => index as u64,
        };
        Ok(GaugeChannel {
            name: text("name", &self.name)?,
            bar: text("bar", &self.bar)?,
            distance_from_specimen_m: v.in_range(
                "distance_from_specimen_m",
                self.distance_from_specimen_m,
                0.0,
                100.0,
                "m",
            )?,
            bridge: self.bridge(kind, v)?,
            amplifier_gain: v.positive("amplifier_gain", self.amplifier_gain, 1e6, "")?,
            polarity: self.polarity,
            digitiser: Digitiser {
                // Issue 42: at 1 Hz a run digitised no sample and its summaries came out NaN;
                // 100 kHz keeps 10 samples over a 100 µs pulse, the fewest a window holds.
                sample_rate_hz: v.in_range(
                    "sample_rate_hz",
                    self.sample_rate_hz,
                    MIN_SAMPLE_RATE_HZ,
                    1e12,
                    "Hz",
                )?,
                bits: self.adc_bits as u32,
                range_v: v.positive("adc_range_v", self.adc_range_v, 1e4, "V")?,
                noise_rms_v: v.in_range("noise_rms_v", self.noise_rms_v, 0.0, 1e4, "V")?,
                seed,
            },
        })
    }
}

impl ChannelSpec {
    /// The bridge of a channel: a Wheatstone kind with its gauge factor, excitation and ν, or
    /// a linear channel with its `strain_per_volt` (each key only where it is used).
    fn bridge(&self, kind: BridgeKind, v: &Validator) -> Result<Bridge> {
        let wheatstone = [
            ("gauge_factor", self.gauge_factor),
            ("excitation_v", self.excitation_v),
            ("poisson_ratio", self.poisson_ratio),
        ];
        if kind == BridgeKind::Linear {
            if let Some((key, _)) = wheatstone.iter().find(|(_, x)| x.is_some()) {
                return Err(v.error(
                    key,
                    "not a constant of bridge = \"linear\"",
                    "strain_per_volt only (the gauge factor, excitation and gain are in it)",
                ));
            }
            let k = self.strain_per_volt.ok_or_else(|| {
                v.error(
                    "strain_per_volt",
                    "missing for bridge = \"linear\"",
                    "the channel's strain per volt at the recorder, tension positive",
                )
            })?;
            // nan: not stated (a set-up for strain records); volt records are then refused.
            if !(k.is_nan() || (k.is_finite() && k != 0.0 && k.abs() <= 1e3)) {
                return Err(v.error(
                    "strain_per_volt",
                    format!("{k}"),
                    "a non-zero finite factor, |k| <= 1000 per V (nan: not stated)",
                ));
            }
            return Ok(Bridge {
                kind,
                gauge_factor: 0.0,
                excitation_v: 0.0,
                poisson_ratio: 0.0,
                strain_per_volt: k,
            });
        }
        if self.strain_per_volt.is_some() {
            return Err(v.error(
                "strain_per_volt",
                format!("given with bridge = \"{}\"", kind.name()),
                "strain_per_volt only with bridge = \"linear\"",
            ));
        }
        let need = |key: &str, x: Option<f64>| {
            x.ok_or_else(|| {
                v.error(
                    key,
                    format!("missing for bridge = \"{}\"", kind.name()),
                    "a positive number",
                )
            })
        };
        Ok(Bridge {
            kind,
            gauge_factor: v.positive(
                "gauge_factor",
                need("gauge_factor", self.gauge_factor)?,
                1000.0,
                "",
            )?,
            excitation_v: v.positive(
                "excitation_v",
                need("excitation_v", self.excitation_v)?,
                1000.0,
                "V",
            )?,
            poisson_ratio: v.in_range(
                "poisson_ratio",
                need("poisson_ratio", self.poisson_ratio)?,
                0.0,
                0.5,
                "",
            )?,
            strain_per_volt: 0.0,
        })
    }
}

/// Validates the `[[channel]]` tables of a gauge file or a set-up file; `root` names the file
/// (keys `channel[i].*`).
pub(crate) fn gauge_setup(channels: &[ChannelSpec], root: &Validator) -> Result<GaugeSetup> {
    if channels.is_empty() {
        return Err(root.error("channel", "no channels", "one or more [[channel]] tables"));
    }
    let mut built: Vec<GaugeChannel> = Vec::with_capacity(channels.len());
    for (i, c) in channels.iter().enumerate() {
        let v = root.table(&format!("channel[{i}]"));
        let ch = c.build(i, &v)?;
        if built.iter().any(|o| o.name == ch.name) {
            return Err(v.error(
                "name",
                format!("`{}` is used by an earlier channel", ch.name),
                "a name unique in the file",
            ));
        }
        built.push(ch);
    }
    Ok(GaugeSetup { channels: built })
}

/// Reading and validating gauge files.
pub trait GaugeSetupFile: Sized {
    /// Parses and validates a gauge file's text; `file` names it in errors (keys `channel[i].*`).
    fn from_toml(text: &str, file: &str) -> Result<Self>;
    /// Reads and validates a gauge file.
    fn from_file(path: impl AsRef<Path>) -> Result<Self>;
}

impl GaugeSetupFile for GaugeSetup {
    /// Parses and validates a gauge file's text; `file` names it in errors (keys `channel[i].*`).
    fn from_toml(text: &str, file: &str) -> Result<GaugeSetup> {
        let spec: SetupFile = toml::from_str(text).map_err(|e| Error::Parse {
            file: file.to_string(),
            message: e.to_string(),
        })?;
        gauge_setup(&spec.channel, &Validator::new(file))
    }

    /// Reads and validates a gauge file.
    fn from_file(path: impl AsRef<Path>) -> Result<GaugeSetup> {
        let path = path.as_ref();
        let text = crate::files::read_to_string(path).map_err(|e| Error::io(path, e))?;
        GaugeSetup::from_toml(&text, &path.display().to_string())
    }
}

/// Reading raw gauge records (`time_s,incident_V,transmission_V`).
pub trait RawRecordFile: Sized {
    /// Parses a record from CSV text; `file` names it in errors, which give `file:line`.
    fn parse(text: &str, file: &str) -> Result<Self>;
    /// Reads a record file (see [`RawRecord::parse`]).
    fn read(path: &Path) -> Result<Self>;
}

impl RawRecordFile for RawRecord {
    /// Parses a record from CSV text; `file` names it in errors, which give `file:line`.
    fn parse(text: &str, file: &str) -> Result<RawRecord> {
        let table = CsvTable::parse(text, file)?;
        let time_s = table.column("time_s")?.to_vec();
        let incident_v = table.column("incident_V")?.to_vec();
        let transmission_v = table.column("transmission_V")?.to_vec();
        if time_s.len() < 2 {
            return Err(Error::Input {
                file: file.to_string(),
                key: "time_s".into(),
                problem: "fewer than two samples".into(),
                allowed: "at least two strictly increasing times".into(),
            });
        }
        if let Some(i) = time_s.windows(2).position(|w| w[1] <= w[0]) {
            // Data row i + 1 is the offender; find its line in the file as CsvTable counts them.
            let line = text
                .lines()
                .enumerate()
                .filter(|(_, l)| !l.trim().is_empty() && !l.trim().starts_with('#'))
                .nth(i + 2)
                .map(|(n, _)| n + 1)
                .unwrap_or(0);
            return Err(Error::Input {
                file: format!("{file}:{line}"),
                key: "time_s".into(),
                problem: format!(
                    "time {:e} s does not follow {:e} s on the line before",
                    time_s[i + 1],
                    time_s[i]
                ),
                allowed: "strictly increasing times".into(),
            });
        }
        Ok(RawRecord {
            time_s,
            incident_v,
            transmission_v,
        })
    }

    /// Reads a record file (see [`RawRecord::parse`]; a byte-order mark and CRLF line ends are
    /// accepted, a binary file is "not a text CSV").
    fn read(path: &Path) -> Result<RawRecord> {
        let text = crate::csv::read_text(path)?;
        RawRecord::parse(&text, &path.display().to_string())
    }
}

/// Reduces a raw gauge record in the authors' CSV format (`time_s,incident_V,transmission_V`)
/// with the bars and gauge channels of `apparatus` (`shpb reduce` reads any record through
/// `sheet::read_record`).
pub fn reduce_record_file(
    record: &Path,
    apparatus: &Apparatus,
    options: &ReductionOptions,
) -> Result<Reduction> {
    let rec = RawRecord::read(record)?;
    let input = record_strains(&rec, apparatus, options.baseline_samples)?;
    let setup = ReductionSetup::from_apparatus(apparatus)?;
    let name = record.display().to_string();
    // Checked for plausibility first, as every record read (shpb_core::reduce::plausibility).
    shpb_core::reduce::plausibility::check_input(&input, &setup, options, &name)?;
    reduce_named(&input, &setup, options, &name).map_err(Error::from)
}
