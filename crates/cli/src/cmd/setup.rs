//! `shpb setup new`: a complete, commented set-up file from the numbers a lab states (bars,
//! gauges), which `--bars FILE` loads directly (gauge channels inline, no gun: virtual tests give
//! the striker's velocity).

use shpb_core::apparatus::Apparatus;
use shpb_core::gauge::{BridgeKind, GaugeSetup};
use shpb_input::prelude::*;
use shpb_input::{Result, Validator};
use std::path::Path;

/// What `shpb setup new` is told (SI values, flags of the same names).
#[derive(Debug, Clone, Default)]
pub struct SetupNew {
    /// Bar diameter, m (`--diameter`).
    pub diameter_m: f64,
    /// Bar Young's modulus, Pa (`--modulus`).
    pub modulus_pa: f64,
    /// Bar density, kg/m³ (`--density`).
    pub density_kg_m3: f64,
    /// Bar Poisson's ratio (`--poisson`; None: 0.3 assumed, said in the file).
    pub poisson: Option<f64>,
    /// Incident bar length, m (`--incident-length`).
    pub incident_length_m: f64,
    /// Transmission bar length, m (`--transmission-length`).
    pub transmission_length_m: f64,
    /// Incident gauge distance from the specimen face, m (`--incident-gauge`).
    pub incident_gauge_m: f64,
    /// Transmission gauge distance from the specimen face, m (`--transmission-gauge`).
    pub transmission_gauge_m: f64,
    /// Striker length, m (`--striker-length`).
    pub striker_length_m: Option<f64>,
    /// Bridge kind (`--bridge`: quarter-axial, half-poisson, full-poisson, linear).
    pub bridge: Option<String>,
    /// Gauge factor (`--gauge-factor`).
    pub gauge_factor: Option<f64>,
    /// Bridge excitation, V (`--excitation`).
    pub excitation_v: Option<f64>,
    /// Amplifier gain (`--gain`).
    pub gain: Option<f64>,
    /// Strain per volt at the recorder, tension positive (`--strain-per-volt`; a linear channel).
    pub strain_per_volt: Option<f64>,
    /// Recorder sample rate, Hz (`--sample-rate`).
    pub sample_rate_hz: Option<f64>,
}

/// A number as a person writes it: plain between 1e-3 and 1e5, else with an exponent.
fn num(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e5 || x.abs() < 1e-3) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The gauge channels' bridge as the flags give it: a Wheatstone bridge (kind, gauge factor,
/// excitation) or a linear factor (None: not stated).
enum Channel {
    Wheatstone {
        kind: BridgeKind,
        gauge_factor: f64,
        excitation_v: f64,
    },
    Linear(Option<f64>),
}

impl SetupNew {
    /// Checks every flag (positive and finite, gauges inside their bars, one bridge
    /// description), naming the flag at fault.
    fn check(&self) -> Result<Channel> {
        let v = Validator::new("command line");
        v.positive("--diameter", self.diameter_m, 1.0, "m")?;
        v.positive("--modulus", self.modulus_pa, 1e13, "Pa")?;
        v.positive("--density", self.density_kg_m3, 1e5, "kg/m³")?;
        if let Some(nu) = self.poisson {
            v.in_range("--poisson", nu, 0.0, 0.4999, "")?;
        }
        let li = v.positive("--incident-length", self.incident_length_m, 100.0, "m")?;
        let lt = v.positive(
            "--transmission-length",
            self.transmission_length_m,
            100.0,
            "m",
        )?;
        for (flag, gauge, length, bar) in [
            (
                "--incident-gauge",
                self.incident_gauge_m,
                li,
                "--incident-length",
            ),
            (
                "--transmission-gauge",
                self.transmission_gauge_m,
                lt,
                "--transmission-length",
            ),
        ] {
            v.positive(flag, gauge, 100.0, "m")?;
            if gauge >= length {
                return Err(v.error(
                    flag,
                    format!("{gauge} m is not inside the bar ({bar} {length} m)"),
                    "a distance from the specimen face shorter than the bar",
                ));
            }
        }
        if let Some(l) = self.striker_length_m {
            v.positive("--striker-length", l, 100.0, "m")?;
        }
        if let Some(g) = self.gain {
            v.positive("--gain", g, 1e6, "")?;
        }
        if let Some(r) = self.sample_rate_hz {
            v.in_range(
                "--sample-rate",
                r,
                shpb_input::gauges::MIN_SAMPLE_RATE_HZ,
                1e12,
                "Hz",
            )?;
        }
        let kind = match self.bridge.as_deref() {
            None => None,
            Some(name) => Some(BridgeKind::from_name(name).ok_or_else(|| {
                v.error(
                    "--bridge",
                    format!("unknown bridge `{name}`"),
                    BridgeKind::ALL
                        .iter()
                        .map(|(_, n)| *n)
                        .collect::<Vec<_>>()
                        .join(", "),
                )
            })?),
        };
        if let Some(k) = self.strain_per_volt {
            v.positive("--strain-per-volt", k, 1e3, "per V")?;
            for (flag, given) in [
                ("--gauge-factor", self.gauge_factor.is_some()),
                ("--excitation", self.excitation_v.is_some()),
                ("--gain", self.gain.is_some()),
            ] {
                if given {
                    return Err(v.error(
                        flag,
                        "given with --strain-per-volt",
                        "either --strain-per-volt (a linear channel: gauge factor, excitation \
                         and gain are in it) or --bridge with --gauge-factor and --excitation",
                    ));
                }
            }
            if kind.is_some_and(|k| k != BridgeKind::Linear) {
                return Err(v.error(
                    "--bridge",
                    "a Wheatstone bridge given with --strain-per-volt",
                    "--bridge linear (or no --bridge) with --strain-per-volt",
                ));
            }
            return Ok(Channel::Linear(Some(k)));
        }
        match (kind, self.gauge_factor, self.excitation_v) {
            (None | Some(BridgeKind::Linear), None, None) => Ok(Channel::Linear(None)),
            (Some(BridgeKind::Linear), _, _) => Err(v.error(
                "--bridge",
                "linear without --strain-per-volt, but with a gauge factor or excitation",
                "--bridge linear --strain-per-volt K, or a Wheatstone bridge with --gauge-factor \
                 and --excitation",
            )),
            (Some(kind), Some(gf), Some(ex)) => Ok(Channel::Wheatstone {
                kind,
                gauge_factor: v.positive("--gauge-factor", gf, 1000.0, "")?,
                excitation_v: v.positive("--excitation", ex, 1000.0, "V")?,
            }),
            (kind, gf, _) => {
                let missing = if kind.is_none() {
                    "--bridge"
                } else if gf.is_none() {
                    "--gauge-factor"
                } else {
                    "--excitation"
                };
                Err(v.error(
                    missing,
                    "missing",
                    "--bridge (quarter-axial, half-poisson or full-poisson) with --gauge-factor \
                     and --excitation, or --strain-per-volt, or none of them (records in strain)",
                ))
            }
        }
    }

    /// The set-up file's text (module docs): every key with its unit and what to edit.
    pub fn text(&self) -> Result<String> {
        let channel = self.check()?;
        let nu = self.poisson.unwrap_or(0.3);
        let c0 = (self.modulus_pa / self.density_kg_m3).sqrt();
        // One comment line: a name that is not UTF-8 shown with U+FFFD, line ends as spaces.
        let command: Vec<String> = std::env::args_os()
            .map(|a| a.to_string_lossy().replace(['\n', '\r'], " "))
            .collect();
        let mut t = String::new();
        t.push_str(&format!(
            "# A split Hopkinson bar set-up, written by `shpb setup new` from the numbers a lab \
             states:\n#   {}\n\
             # SI units throughout (m, Pa, kg/m^3, V, Hz). Edit any value; `--bars THIS-FILE` \
             reads it\n\
             # (shpb reduce, shpb strain, shpb run). Keys and ranges: README \"Your own bar and \
             records\".\n\
             description = \"set-up of shpb setup new\"\n\n",
            command.join(" ")
        ));
        t.push_str(&format!(
            "# Bar material (incident and transmission bars, striker). c0 = sqrt(E/rho) = {c0:.1} \
             m/s.\n[material]\n\
             density_kg_m3 = {}      # --density\n\
             youngs_modulus_pa = {}  # --modulus\n\
             poisson_ratio = {nu}         # {}; used by the dispersion correction\n\n",
            num(self.density_kg_m3),
            num(self.modulus_pa),
            if self.poisson.is_some() {
                "--poisson"
            } else {
                "NOT STATED: 0.3 assumed (steel); give --poisson or edit"
            }
        ));
        t.push_str(&format!(
            "# The bars: length and diameter, m.\n[incident]\n\
             length_m = {}      # --incident-length\ndiameter_m = {}    # --diameter\n\n\
             [transmission]\nlength_m = {}      # --transmission-length\n\
             diameter_m = {}    # --diameter\n\
             far_end = \"absorbing\"  # or \"free\": only virtual tests (shpb run) use it\n\n",
            self.incident_length_m, self.diameter_m, self.transmission_length_m, self.diameter_m
        ));
        let striker = match self.striker_length_m {
            Some(l) => format!("length_m = {}      # --striker-length\n", num(l)),
            None => "length_m = 0.2        # NOT STATED (--striker-length): a placeholder that \
                     only virtual tests use;\n                      # the reduction of records \
                     never does. Edit it before `shpb run`.\n"
                .to_string(),
        };
        t.push_str(&format!(
            "# The striker (same material and bore as the bars).\n[striker]\n{striker}\
             diameter_m = {}    # --diameter\n\n\
             # No [gun] and no [shaper]: a virtual test on this set-up gives the striker's \
             velocity\n\
             # (`striker_velocity_m_s` in the scene, or `shpb run --set \
             striker_velocity_m_s=...`). Add a\n\
             # [gun] and a [shaper] table as in bars/authors.toml to simulate shots by \
             pressure.\n\n",
            num(self.diameter_m)
        ));
        let rate = self.sample_rate_hz.unwrap_or(10e6);
        let rate_note = if self.sample_rate_hz.is_some() {
            "--sample-rate"
        } else {
            "NOT STATED: 10 MHz; records carry their own times"
        };
        t.push_str(
            "# The gauge channels (as in a gauge file, here inline; `gauges = \"FILE\"` instead \
             names a\n\
             # gauge file). distance_from_specimen_m: from the gauge to the bar's specimen face.\n\
             # Bar strain is positive in tension. A record in strain or microstrain (a column \
             named\n\
             # `.../με`, `.../ε`) is used as read; a record in volts goes through the bridge \
             below.\n",
        );
        for (name, bar, distance, flag) in [
            (
                "incident",
                "incident",
                self.incident_gauge_m,
                "--incident-gauge",
            ),
            (
                "transmission",
                "transmission",
                self.transmission_gauge_m,
                "--transmission-gauge",
            ),
        ] {
            t.push_str(&format!(
                "[[channel]]\nname = \"{name}\"\nbar = \"{bar}\"\n\
                 distance_from_specimen_m = {}   # {flag}\n",
                num(distance)
            ));
            match &channel {
                Channel::Linear(k) => {
                    t.push_str(
                        "bridge = \"linear\"                # strain = strain_per_volt x \
                         recorded volts\n",
                    );
                    match k {
                        Some(k) => t.push_str(&format!(
                            "strain_per_volt = {}     # --strain-per-volt, tension positive\n",
                            num(*k)
                        )),
                        None => t.push_str(
                            "strain_per_volt = nan            # NOT STATED: volt records are \
                             refused until it is given\n\
                             #                                   (--strain-per-volt, or `shpb \
                             calibrate` from paired volt and strain files)\n",
                        ),
                    }
                }
                Channel::Wheatstone {
                    kind,
                    gauge_factor,
                    excitation_v,
                } => t.push_str(&format!(
                    "bridge = \"{}\"   # --bridge: quarter-axial, half-poisson, full-poisson \
                     (src/gauge.rs)\n\
                     gauge_factor = {gauge_factor}     # --gauge-factor\n\
                     excitation_v = {excitation_v}     # --excitation, V\n\
                     poisson_ratio = {nu}      # of the bar (the transverse gauges)\n\
                     amplifier_gain = {}       # --gain\n",
                    kind.name(),
                    self.gain.unwrap_or(1.0)
                )),
            }
            t.push_str(&format!(
                "polarity = 1.0     # +1: the recorded volts have the strain's sign; -1 if \
                 compression reads positive\n\
                 # The recorder (used to simulate records; a lab record carries its own \
                 times):\n\
                 sample_rate_hz = {}   # {rate_note}\n\
                 adc_bits = 16\nadc_range_v = 10.0\n\n",
                num(rate)
            ));
        }
        // The text must load as it is: checked here, before it is written.
        let gauges = |_: &str| -> Result<GaugeSetup> { unreachable!("the channels are inline") };
        Apparatus::from_toml(&t, "shpb setup new", &gauges)?;
        Ok(t)
    }
}

/// `shpb setup new -o FILE [--force] --diameter D --modulus E --density RHO [--poisson NU]
/// --incident-length L --transmission-length L --incident-gauge X --transmission-gauge X ...`:
/// writes the commented set-up (atomically, no clobbering without `--force`).
pub fn new(args: &SetupNew, output: &Path, force: bool) -> Result<()> {
    let outputs = super::common::plan(force, &[(Some(output), "--output", &["toml"])])?;
    let text = args.text()?;
    super::common::write_all(&outputs, || {
        shpb_output::atomic::write_text_atomically(output, force, &text)
    })?;
    if args.striker_length_m.is_none() {
        eprintln!(
            "note: no --striker-length: [striker] length_m is a placeholder (edit it before a \
             virtual test)"
        );
    }
    Ok(())
}
