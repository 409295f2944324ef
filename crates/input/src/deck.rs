//! A lab's input deck in the LANL/HopPyBar form (`PMMA_13_Input.dat`): tab-separated lines
//! `key<TAB>value<TAB>unit<TAB>note`, in UTF-8 or Windows-1252 (PMMA-13's `ºC` and `µs` are the
//! single bytes 0xBA and 0xB5), read into the bars, gauges and specimen a reduction needs
//! ([`Deck`]). `shpb reduce --bars DECK`
//! recognises it by its content ([`is_deck`]); every error names the deck's line and key.
//!
//! What the deck states and how it is used (HopPyBar.py, the mini-Kolsky branch, reads the same
//! keys by row): each bar's Young's modulus, Poisson ratio, rod sound speed, density, diameter
//! (the deck's equivalent round diameter of a square bar, as the deck states it), strain-gauge
//! location (distance from the specimen face), gauge factor and excitation; the channel gains
//! (`Incident/Reflected Bar Gain`, `Transmitted Bar Gain`); the specimen's initial diameter
//! (equivalent round) and length; the striker's length. Strain from recorded volts is HopPyBar's
//! `ε = 2V/(GF·gain·Vex)` to first order: a half bridge of two axial gauges
//! ([`BridgeKind::HalfAxial`]), compression giving negative volts (polarity +1).
//!
//! What the deck does not state, and what stands in for it:
//! - the bars' lengths: each bar is taken twice as long as the larger gauge distance (gauges at
//!   mid-length at most, as HopPyBar's dispersion correction assumes), the transmission bar's
//!   far end free. A reduction's window is bounded by the incident–reflected separation
//!   2 d_I/c0 at the incident gauge; with these lengths no far-end reflection reaches a gauge
//!   sooner (2 (L − d)/c0 ≥ 2 d_I/c0), so the lengths do not enter the reduction.
//! - the gun: a deck states a breech pressure but no gun calibration, so the set-up's gun is a
//!   zero line (`k = 0`: no pressure moves the striker). A deck is a set-up for reducing records
//!   (`shpb reduce`), not for firing virtual shots.
//! - the digitiser: the records carry their own clock; the channels state 8 bits over ±10 V at
//!   125 MHz (the LANL files' 8 ns), which no reduction uses.

use crate::error::{Error, Result};
use shpb_core::apparatus::{Apparatus, BarGeometry, Inserts};
use shpb_core::bar::BarMaterial;
use shpb_core::gauge::{Bridge, BridgeKind, Digitiser, GaugeChannel, GaugeSetup};
use shpb_core::reduce_cylinder::CylinderGeometry;
use shpb_core::striker::{Gun, LinearGun, PSI_PA};
use std::path::Path;

/// The key whose presence tells a deck from other files ([`is_deck`]).
const SIGNATURE: &str = "Incident Bar Strain Gage Location (mm)";

/// How far the stated density may differ from E/c0² of the stated modulus and rod speed.
const DENSITY_TOLERANCE: f64 = 0.02;

/// A deck read and validated: the set-up it states and the specimen it names.
#[derive(Debug, Clone, PartialEq)]
pub struct Deck {
    /// The bars, gauges and striker (module docs: what stands in for what the deck omits).
    pub apparatus: Apparatus,
    /// The specimen: a cylinder of the deck's initial (equivalent round) diameter and length.
    pub specimen: CylinderGeometry,
    /// The stated breech pressure, Pa (gauge), if any.
    pub breech_pressure_pa: Option<f64>,
    /// The sample description, if any.
    pub sample: Option<String>,
}

/// Whether `text` is an input deck: tab-separated lines, one of them keyed
/// `Incident Bar Strain Gage Location (mm)`.
pub fn is_deck(text: &str) -> bool {
    text.lines()
        .take(200)
        .any(|l| l.split('\t').next().map(str::trim) == Some(SIGNATURE) && l.contains('\t'))
}

/// A deck's bytes as text: UTF-8 if they are, else Windows-1252 (a superset of Latin-1 for the
/// printable bytes; HopPyBar reads decks as `cp1252`).
pub fn decode(bytes: &[u8]) -> String {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => encoding_rs::WINDOWS_1252.decode(bytes).0.into_owned(),
    }
}

/// The deck's lines: key → (value, unit, line number), keys as written (trimmed).
struct Lines<'a> {
    file: &'a str,
    entries: Vec<(String, String, String, usize)>,
}

impl Lines<'_> {
    fn parse<'a>(text: &str, file: &'a str) -> Result<Lines<'a>> {
        let mut entries: Vec<(String, String, String, usize)> = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let fields: Vec<&str> = line.trim_end_matches('\r').split('\t').collect();
            let key = fields[0].trim();
            if key.is_empty() {
                continue;
            }
            let field = |k: usize| {
                let f = fields.get(k).copied().unwrap_or("").trim();
                f.strip_prefix('"')
                    .and_then(|s| s.strip_suffix('"'))
                    .unwrap_or(f)
                    .to_string()
            };
            if let Some((.., first)) = entries.iter().find(|(k, ..)| k == key) {
                return Err(Error::Input {
                    file: format!("{file}:{}", n + 1),
                    key: key.to_string(),
                    problem: format!("given again (first on line {first})"),
                    allowed: "each key once".into(),
                });
            }
            entries.push((key.to_string(), field(1), field(2), n + 1));
        }
        Ok(Lines { file, entries })
    }

    fn get(&self, key: &str) -> Option<&(String, String, String, usize)> {
        self.entries.iter().find(|(k, ..)| k == key)
    }

    /// The error for `key` at its line (or the whole file if it is missing).
    fn error(&self, key: &str, problem: impl Into<String>, allowed: impl Into<String>) -> Error {
        Error::Input {
            file: match self.get(key) {
                Some((.., line)) => format!("{}:{line}", self.file),
                None => self.file.to_string(),
            },
            key: key.to_string(),
            problem: problem.into(),
            allowed: allowed.into(),
        }
    }

    /// The text value of `key`, if present and not empty.
    fn text(&self, key: &str) -> Option<String> {
        self.get(key)
            .map(|(_, v, ..)| v.clone())
            .filter(|v| !v.is_empty())
    }

    /// The number of `key` in `unit` (the unit column must be `unit` or empty), within
    /// (lo, hi] (or [lo, hi] if `closed`).
    fn number(&self, key: &str, unit: &str, lo: f64, hi: f64, closed: bool) -> Result<f64> {
        let (_, value, stated, _) = self.get(key).ok_or_else(|| {
            self.error(
                key,
                "missing",
                format!("a line `{key}<TAB>value<TAB>{unit}`"),
            )
        })?;
        if !stated.is_empty() && stated != unit {
            return Err(self.error(
                key,
                format!("unit `{stated}`"),
                if unit.is_empty() {
                    "no unit".to_string()
                } else {
                    unit.to_string()
                },
            ));
        }
        let x: f64 = value
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite())
            .ok_or_else(|| self.error(key, format!("`{value}` is not a number"), "a number"))?;
        let inside = if closed { x >= lo } else { x > lo } && x <= hi;
        if !inside {
            return Err(self.error(
                key,
                format!("{x} is out of range"),
                format!(
                    "{} {lo}, at most {hi}{}",
                    if closed { "at least" } else { "greater than" },
                    if unit.is_empty() {
                        String::new()
                    } else {
                        format!(" {unit}")
                    }
                ),
            ));
        }
        Ok(x)
    }
}

/// One bar as the deck states it (SI units).
struct DeckBar {
    modulus_pa: f64,
    poisson: f64,
    rod_speed_m_s: f64,
    diameter_m: f64,
    gauge_m: f64,
    gauge_factor: f64,
    excitation_v: f64,
    gain: f64,
}

/// The keys of bar `b` (`Incident`, `Transmitted`) read and checked.
fn bar(l: &Lines, b: &str, gain_key: &str) -> Result<DeckBar> {
    let k = |what: &str| format!("{b} Bar {what}");
    let modulus_gpa = l.number(&k("Young's Modulus (GPa)"), "GPa", 0.0, 1000.0, false)?;
    let poisson = l.number(&k("Poisson Ratio"), "", 0.0, 0.5, true)?;
    let rod_speed_m_s = l.number(&k("Rod Sound Speed (m/s)"), "m/s", 0.0, 20000.0, false)?;
    let density_g_cm3 = l.number(&k("Density (g/cm^3)"), "g/cm^3", 0.0, 25.0, false)?;
    // The set-up's density is E/c0², so the wave speed is the deck's rod speed, as HopPyBar
    // uses it; a stated density that disagrees means the deck contradicts itself.
    let from_speed = modulus_gpa * 1e9 / (rod_speed_m_s * rod_speed_m_s) / 1e3;
    if (density_g_cm3 - from_speed).abs() > DENSITY_TOLERANCE * from_speed {
        return Err(l.error(
            &k("Density (g/cm^3)"),
            format!(
                "{density_g_cm3} g/cm^3, but E/c0² of `{}` and `{}` is {from_speed:.4} g/cm^3",
                k("Young's Modulus (GPa)"),
                k("Rod Sound Speed (m/s)")
            ),
            format!(
                "a density within {:.0} % of E/c0²",
                DENSITY_TOLERANCE * 100.0
            ),
        ));
    }
    Ok(DeckBar {
        modulus_pa: modulus_gpa * 1e9,
        poisson,
        rod_speed_m_s,
        diameter_m: l.number(&k("Diameter (mm)"), "mm", 0.0, 1000.0, false)? * 1e-3,
        gauge_m: l.number(&k("Strain Gage Location (mm)"), "mm", 0.0, 100_000.0, false)? * 1e-3,
        gauge_factor: l.number(&k("Calibrated Gage Factor"), "", 0.0, 1000.0, false)?,
        excitation_v: l.number(&k("Excitation Voltage (V)"), "V", 0.0, 1000.0, false)?,
        gain: l.number(gain_key, "", 0.0, 1e6, false)?,
    })
}

impl Deck {
    /// Parses and validates a deck's text; `file` names it in errors (`file:line`, the key).
    pub fn parse(text: &str, file: &str) -> Result<Deck> {
        let l = Lines::parse(text, file)?;
        if l.get(SIGNATURE).is_none() {
            return Err(l.error(
                SIGNATURE,
                "missing: not an input deck",
                "a LANL/HopPyBar input deck (tab-separated key, value, unit lines)",
            ));
        }
        let inc = bar(&l, "Incident", "Incident/Reflected Bar Gain")?;
        let tra = bar(&l, "Transmitted", "Transmitted Bar Gain")?;
        // One material for both bars (the set-up has one): the same E, ν and c0.
        for (what, a, b) in [
            ("Young's Modulus (GPa)", inc.modulus_pa, tra.modulus_pa),
            ("Poisson Ratio", inc.poisson, tra.poisson),
            (
                "Rod Sound Speed (m/s)",
                inc.rod_speed_m_s,
                tra.rod_speed_m_s,
            ),
        ] {
            if (a - b).abs() > 1e-9 * a.abs().max(b.abs()) {
                return Err(l.error(
                    &format!("Transmitted Bar {what}"),
                    "differs from the incident bar's",
                    "bars of one material (the set-up has one bar material)",
                ));
            }
        }
        let material = BarMaterial {
            density_kg_m3: inc.modulus_pa / (inc.rod_speed_m_s * inc.rod_speed_m_s),
            youngs_modulus_pa: inc.modulus_pa,
            poisson_ratio: inc.poisson,
        };
        let length_m = 2.0 * inc.gauge_m.max(tra.gauge_m);
        let striker_length_m = l.number("Striker Length (mm)", "mm", 0.0, 100_000.0, false)? * 1e-3;
        let channel = |name: &str, b: &DeckBar| GaugeChannel {
            name: name.into(),
            bar: name.into(),
            distance_from_specimen_m: b.gauge_m,
            bridge: Bridge {
                kind: BridgeKind::HalfAxial,
                gauge_factor: b.gauge_factor,
                excitation_v: b.excitation_v,
                poisson_ratio: b.poisson,
            },
            amplifier_gain: b.gain,
            polarity: 1.0,
            digitiser: Digitiser {
                sample_rate_hz: 125e6,
                bits: 8,
                range_v: 10.0,
                noise_rms_v: 0.0,
                seed: 0,
            },
        };
        let apparatus = Apparatus {
            source: file.to_string(),
            material,
            incident: BarGeometry {
                length_m,
                diameter_m: inc.diameter_m,
            },
            transmission: BarGeometry {
                length_m,
                diameter_m: tra.diameter_m,
            },
            transmission_absorbing: false,
            striker: BarGeometry {
                length_m: striker_length_m,
                diameter_m: inc.diameter_m,
            },
            gun: Gun::Linear(LinearGun {
                k_m2_per_s2_per_pa: 0.0,
                loss_pressure_pa: 0.0,
                calibration_mass_kg: material.density_kg_m3
                    * std::f64::consts::PI
                    * 0.25
                    * inc.diameter_m.powi(2)
                    * striker_length_m,
                min_pressure_pa: 0.0,
                max_pressure_pa: 1e8,
            }),
            gun_calibrated_pa: None,
            gun_velocity_scatter: None,
            shaper: None,
            gauges: GaugeSetup {
                channels: vec![channel("incident", &inc), channel("transmission", &tra)],
            },
            inserts: Inserts::default(),
            // A deck states no uncertainty of its constants.
            uncertainty: None,
        };
        let specimen = CylinderGeometry {
            length_m: l.number("Initial Sample Length (mm)", "mm", 0.0, 1000.0, false)? * 1e-3,
            diameter_m: l.number("Initial Sample Diameter (mm)", "mm", 0.0, 1000.0, false)? * 1e-3,
        };
        let breech_pressure_pa = match l.text("Breech Pressure (psi)") {
            Some(_) => Some(l.number("Breech Pressure (psi)", "psi", 0.0, 1e5, true)? * PSI_PA),
            None => None,
        };
        Ok(Deck {
            apparatus,
            specimen,
            breech_pressure_pa,
            sample: l.text("Sample Description"),
        })
    }

    /// Reads a deck file (UTF-8 or Windows-1252, [`decode`]; see [`Deck::parse`]).
    pub fn read(path: &Path) -> Result<Deck> {
        let bytes = crate::files::read(path).map_err(|e| Error::io(path, e))?;
        Deck::parse(&decode(&bytes), &path.display().to_string())
    }

    /// Whether the file at `path` is a deck ([`is_deck`] on its text); false if unreadable.
    pub fn is_deck_file(path: &Path) -> bool {
        std::fs::read(path).is_ok_and(|b| is_deck(&decode(&b)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The keys of the LANL PMMA-13 deck that a reduction reads (values as the lab's).
    fn deck() -> String {
        let mut s = String::from(
            "Test Date\t3/2/18\t\t\r\nSample Description\tPMMA #13\t\t\r\n\
             Initial Sample Diameter (mm)\t1.54\tmm\t\r\nInitial Sample Length (mm)\t1.47\tmm\t\r\n\
             Test Temperature (\u{b0}C)\t20\tC\t\r\nBreech Pressure (psi)\t50.4\tpsi\t\r\n\
             Striker Length (mm)\t25.4\tmm\t\r\nIncident/Reflected Bar Gain\t100\t\t\r\n\
             Transmitted Bar Gain\t100\t\t\r\n\t\t\t\r\n",
        );
        for (b, gauge) in [("Incident", "102.02"), ("Transmitted", "101.35")] {
            s.push_str(&format!(
                "{b} Bar Calibrated Gage Factor\t2.1\t\t\r\n\
                 {b} Bar Young's Modulus (GPa)\t71.7\tGPa\t\r\n\
                 {b} Bar Poisson Ratio\t0.332713755\t\t\r\n\
                 {b} Bar Rod Sound Speed (m/s)\t5051.306803\tm/s\tc_0=c_s*SQRT(2*(1+poisson))\r\n\
                 {b} Bar Density (g/cm^3)\t2.81\tg/cm^3\t\r\n\
                 {b} Bar Diameter (mm)\t2.380880043\tmm\t\r\n\
                 {b} Bar Strain Gage Location (mm)\t{gauge}\tmm\t\r\n\
                 {b} Bar Excitation Voltage (V)\t10\tV\t\r\n"
            ));
        }
        s
    }

    #[test]
    fn the_lanl_deck_gives_bars_gauges_and_specimen() {
        assert!(is_deck(&deck()));
        let d = Deck::parse(&deck(), "deck.dat").unwrap();
        let a = &d.apparatus;
        assert!((a.material.wave_speed_m_s() - 5051.306803).abs() < 1e-6);
        assert!((a.material.density_kg_m3 - 2810.0).abs() < 0.1);
        assert_eq!(a.incident.diameter_m, 2.380880043e-3);
        let i = a.gauges.channel("incident").unwrap();
        assert_eq!(i.distance_from_specimen_m, 102.02e-3);
        assert_eq!(i.amplifier_gain, 100.0);
        // HopPyBar's conversion to first order: ε = 2V/(GF·gain·Vex), V < 0 in compression.
        let v = -1.3;
        let hoppybar = 2.0 * v / (2.1 * 100.0 * 10.0);
        assert!((i.strain_from_voltage(v) / hoppybar - 1.0).abs() < 2e-3);
        assert_eq!(
            a.gauges
                .channel("transmission")
                .unwrap()
                .distance_from_specimen_m,
            101.35e-3
        );
        assert!(a.incident.length_m >= 2.0 * 102.02e-3);
        assert!((d.specimen.length_m - 1.47e-3).abs() < 1e-15);
        assert!((d.specimen.diameter_m - 1.54e-3).abs() < 1e-15);
        assert!((d.breech_pressure_pa.unwrap() / PSI_PA - 50.4).abs() < 1e-9);
        assert_eq!(d.sample.as_deref(), Some("PMMA #13"));
    }

    #[test]
    fn windows_1252_bytes_decode() {
        let bytes = b"Test Temperature (\xb0C)\t20\tC\t\r\n";
        assert_eq!(decode(bytes), "Test Temperature (\u{b0}C)\t20\tC\t\r\n");
        assert_eq!(decode("\u{b0}".as_bytes()), "\u{b0}");
    }

    #[test]
    fn bad_decks_name_the_line_and_key() {
        let err = |t: String| Deck::parse(&t, "d.dat").unwrap_err().to_string();
        let e = err(deck().replace(
            "Incident Bar Excitation Voltage (V)\t10",
            "Incident Bar Excitation Voltage (V)\tten",
        ));
        assert!(
            e.contains("d.dat:")
                && e.contains("Incident Bar Excitation Voltage (V)")
                && e.contains("`ten`"),
            "{e}"
        );
        let e = err(deck().replace(
            "Transmitted Bar Poisson Ratio\t0.332713755",
            "Transmitted Bar Poisson Ratio\t0.3",
        ));
        assert!(
            e.contains("Transmitted Bar") && e.contains("one material"),
            "{e}"
        );
        let e = err(deck().replace("1.54\tmm", "1.54\tin"));
        assert!(
            e.contains("Initial Sample Diameter (mm)") && e.contains("unit `in`"),
            "{e}"
        );
        let e = err(deck().replace(
            "Incident Bar Density (g/cm^3)\t2.81",
            "Incident Bar Density (g/cm^3)\t7.8",
        ));
        assert!(e.contains("E/c0²"), "{e}");
        let e = err(deck().replace("Transmitted Bar Gain\t100\t\t\r\n", ""));
        assert!(e.contains("`Transmitted Bar Gain`: missing"), "{e}");
        let e = err(deck() + "Striker Length (mm)\t30\tmm\t\r\n");
        assert!(e.contains("given again"), "{e}");
    }
}
