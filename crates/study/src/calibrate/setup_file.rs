//! The calibrated set-up file: the base set-up's text with each calibrated value replaced
//! (toml_edit: every comment kept, a comment above each replaced value saying what it was fitted
//! on, the old value after it), the gauge file beside it (the base's, with calibrated gauge
//! constants replaced) and the `[uncertainty]` table (/work/briefs/interfaces.md §2; BANDS
//! parses it).

use super::{Calibration, Fitted};
use shpb_input::{Error, Result};
use toml_edit::{Array, DocumentMut, Item, Table, Value};

/// The texts `shpb calibrate -o` writes.
#[derive(Debug, Clone, PartialEq)]
pub struct SetupTexts {
    /// The set-up file.
    pub setup: String,
    /// The gauge file its `gauges` key names (beside it), when the base names one.
    pub gauges: Option<String>,
}

/// `x` rounded to 4 significant digits (through its decimal form), as the shipped set-ups
/// state calibrated constants.
pub fn round4(x: f64) -> f64 {
    format!("{x:.3e}").parse().unwrap_or(x)
}

/// A float value with a trailing comment: 4 significant digits in scientific form when
/// `round` (a fitted constant), else as it is (a bookkeeping value such as a pressure bound).
fn number(x: f64, round: bool, comment: &str) -> Value {
    let mut v = if round {
        format!("{x:.3e}")
            .parse::<Value>()
            .unwrap_or(Value::from(x))
    } else {
        Value::from(x)
    };
    v.decor_mut().set_suffix(format!("   # {comment}"));
    v
}

/// The comment lines above a replaced key (`values`: every value of the key, for an array).
fn comment(f: &Fitted, values: &[f64]) -> String {
    let sd = match f.sd {
        Some(sd) => format!(" +- {} {} (1-sigma, {})", fmt(sd), f.unit, f.sd_from.name()),
        None => String::new(),
    };
    let shown = values
        .iter()
        .map(|v| fmt(*v))
        .collect::<Vec<_>>()
        .join(", ");
    let mut lines = format!("# shpb calibrate: {shown}{sd}\n");
    for chunk in wrap(&f.fitted_on, 94) {
        lines.push_str(&format!("#   {chunk}\n"));
    }
    lines
}

/// 4 significant digits in scientific form.
fn fmt(x: f64) -> String {
    format!("{x:.3e}")
}

/// `text` broken into lines of at most `width` characters at spaces.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut out = vec![String::new()];
    for w in text.split_whitespace() {
        let last = out.last_mut().expect("one line");
        if !last.is_empty() && last.len() + 1 + w.len() > width {
            out.push(w.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(w);
        }
    }
    out
}

/// Sets `key` of `table` to `v`, with `above` appended to the comments above it (kept).
fn set(table: &mut Table, key: &str, v: Value, above: &str) {
    let prefix = table.key_mut(key).and_then(|k| {
        k.leaf_decor()
            .prefix()
            .and_then(|p| p.as_str().map(String::from))
    });
    table.insert(key, Item::Value(v));
    if let Some(mut k) = table.key_mut(key) {
        let old = prefix.unwrap_or_default();
        let indent_free = old.trim_end_matches([' ', '\t']);
        k.leaf_decor_mut()
            .set_prefix(format!("{indent_free}{above}"));
    }
}

/// The old value of `key` in `table`, as written.
fn was(table: &Table, key: &str) -> String {
    table
        .get(key)
        .and_then(|i| i.as_value())
        .map_or("absent".into(), |v| {
            format!("was {}", v.clone().decorated("", "").to_string().trim())
        })
}

/// An error about the base set-up `file`.
fn base_err(file: &str, key: &str, problem: impl Into<String>) -> Error {
    Error::Input {
        file: file.into(),
        key: key.into(),
        problem: problem.into(),
        allowed: "a set-up file with the tables and gauge channels `shpb calibrate` replaces"
            .into(),
    }
}

/// Rewrites the base set-up text `setup` (named `setup_name`) and its gauge file text `gauges`
/// (None: the base names none) with the calibration; the set-up's `gauges` key becomes
/// `gauges_file_name` (the gauge file written beside it). `header` goes on top.
pub fn rewrite(
    setup: &str,
    setup_name: &str,
    gauges: Option<&str>,
    gauges_file_name: &str,
    c: &Calibration,
    header: &str,
) -> Result<SetupTexts> {
    let parse_err = |file: &str, e: toml_edit::TomlError| Error::Parse {
        file: file.into(),
        message: e.to_string(),
    };
    let mut doc: DocumentMut = setup.parse().map_err(|e| parse_err(setup_name, e))?;
    let mut gdoc: Option<DocumentMut> = match gauges {
        Some(t) => Some(t.parse().map_err(|e| parse_err("gauge file", e))?),
        None => None,
    };
    let mut done: Vec<&str> = Vec::new();
    for f in &c.constants {
        if done.contains(&f.key.as_str()) {
            continue;
        }
        done.push(&f.key);
        let same: Vec<&Fitted> = c.constants.iter().filter(|g| g.key == f.key).collect();
        let parts: Vec<&str> = f.key.split('.').collect();
        if parts[0] == "gauges" && parts.len() == 3 {
            // The channels of the gauge file, or those inline in the set-up (`[[channel]]`).
            let g = match gdoc.as_mut() {
                Some(g) => g,
                None => &mut doc,
            };
            set_gauge(g, parts[1], parts[2], f, setup_name)?;
            continue;
        }
        let [table, key] = parts[..] else {
            return Err(base_err(setup_name, &f.key, "not a `table.key` set-up key"));
        };
        let t = doc
            .get_mut(table)
            .and_then(Item::as_table_mut)
            .ok_or_else(|| base_err(setup_name, table, format!("no [{table}] table")))?;
        let old = was(t, key);
        let v = if same.len() > 1 {
            let mut a = Array::new();
            for g in &same {
                a.push(g.value);
            }
            let mut v = Value::Array(a);
            v.decor_mut().set_suffix(format!("   # {old}"));
            v
        } else {
            number(f.value, f.uncertain, &old)
        };
        let values: Vec<f64> = same.iter().map(|g| g.value).collect();
        set(t, key, v, &comment(f, &values));
    }
    if gdoc.is_some() {
        set(
            doc.as_table_mut(),
            "gauges",
            Value::from(gauges_file_name),
            "# shpb calibrate: the gauge channels, beside this file.\n",
        );
    }
    doc.remove("uncertainty");
    let mut text = format!("{header}{}", doc);
    if !text.ends_with('\n') {
        text.push('\n');
    }
    text.push_str(&uncertainty_table(c, gauges.is_none()));
    Ok(SetupTexts {
        setup: text,
        gauges: gdoc.map(|g| g.to_string()),
    })
}

/// The base set-up of `--bars` as text: (its name in messages, its text, its gauge file's text
/// when it names one). A built-in set-up's texts are the compiled-in ones; a file's gauge file is
/// read relative to it.
pub fn read_base(bars: &std::path::Path) -> Result<(String, String, Option<String>)> {
    crate::api::require_bars(bars)?;
    let builtin = bars.to_str().and_then(shpb_input::builtin::setup);
    let (name, text) = match builtin {
        Some(t) => (
            format!("built-in set-up `{}`", bars.display()),
            t.to_string(),
        ),
        None => (
            bars.display().to_string(),
            shpb_input::files::read_to_string(bars).map_err(|e| Error::io(bars, e))?,
        ),
    };
    let doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| Error::Parse {
            file: name.clone(),
            message: e.to_string(),
        })?;
    let gauges = match doc.get("gauges").and_then(Item::as_str) {
        None => None,
        Some(g) => Some(match builtin.and_then(|_| shpb_input::builtin::gauges(g)) {
            Some(t) => t.to_string(),
            None => {
                let p = bars.parent().unwrap_or(std::path::Path::new(".")).join(g);
                shpb_input::files::read_to_string(&p).map_err(|e| Error::io(&p, e))?
            }
        }),
    };
    Ok((name, text, gauges))
}

/// Sets a gauge channel's constant: a distance, or a strain factor (the channel becomes
/// `bridge = "linear"` with `strain_per_volt`, polarity 1, its bridge's other keys removed).
fn set_gauge(g: &mut DocumentMut, channel: &str, key: &str, f: &Fitted, file: &str) -> Result<()> {
    let channels = g
        .get_mut("channel")
        .and_then(Item::as_array_of_tables_mut)
        .ok_or_else(|| base_err(file, "gauges", "no [[channel]] in the gauge file or set-up"))?;
    let t = channels
        .iter_mut()
        .find(|t| t.get("name").and_then(Item::as_str) == Some(channel))
        .ok_or_else(|| base_err(file, "gauges", format!("no gauge channel `{channel}`")))?;
    let old = was(t, key);
    if key == "strain_per_volt" {
        let bridge = was(t, "bridge");
        for k in [
            "gauge_factor",
            "excitation_v",
            "amplifier_gain",
            "poisson_ratio",
        ] {
            t.remove(k);
        }
        let mut b = Value::from("linear");
        b.decor_mut().set_suffix(format!("   # {bridge}"));
        set(
            t,
            "bridge",
            b,
            "# shpb calibrate: a linear factor replaces the bridge (its gauge factor, excitation,\n\
             #   gain and Poisson's ratio removed); strain_per_volt carries the sign.\n",
        );
        set(
            t,
            "polarity",
            number(1.0, false, "the factor's sign is the polarity"),
            "",
        );
    }
    set(t, key, number(f.value, true, &old), &comment(f, &[f.value]));
    Ok(())
}

/// The `[uncertainty]` table (interfaces §2): fitted_on, shots, the relative or absolute 1-sigma
/// of each uncertain constant (p_loss absolute, the others relative), the scatter.
///
/// A gauge channel's constant (`gauges.<channel>.<key>`) can be uncertain only when the channels
/// are inline (`channels_inline`); with a separate gauge file its 1-sigma is written as a comment.
pub fn uncertainty_table(c: &Calibration, channels_inline: bool) -> String {
    let mut t = String::from(
        "\n# What the calibrated constants are uncertain by, and the shot-to-shot scatter the\n\
         # calibration shots show; written by `shpb calibrate` (1-sigma, normal; the\n\
         # correlations of constants one fit gave together, the others independent).\n\
         [uncertainty]\n",
    );
    t.push_str(&format!(
        "fitted_on = {}\nshots = {}\n",
        Value::from(c.fitted_on.as_str()),
        c.shots
    ));
    let uncertain: Vec<&Fitted> = c
        .constants
        .iter()
        .filter(|f| f.uncertain && f.sd.is_some())
        .collect();
    let absolute = |f: &Fitted| f.key == "gun.loss_pressure_pa";
    let rel: Vec<&&Fitted> = uncertain.iter().filter(|f| !absolute(f)).collect();
    let abs: Vec<&&Fitted> = uncertain.iter().filter(|f| absolute(f)).collect();
    if !rel.is_empty() {
        t.push_str("[uncertainty.relative_sd]\n");
        for f in rel {
            if !channels_inline && f.key.starts_with("gauges.") {
                t.push_str("# the gauge channels are in their own file, which [uncertainty] cannot reach:\n# ");
            }
            t.push_str(&format!(
                "\"{}\" = {:.3e}   # {}\n",
                f.key,
                f.relative_sd().unwrap_or(0.0),
                f.sd_from.name()
            ));
        }
    }
    if !abs.is_empty() {
        t.push_str("[uncertainty.sd]\n");
        for f in abs {
            t.push_str(&format!(
                "\"{}\" = {:.3e}   # {}, {}\n",
                f.key,
                f.sd.unwrap_or(0.0),
                f.unit,
                f.sd_from.name()
            ));
        }
    }
    // Correlations of pairs the table above states (a gauge key only with inline channels).
    let stated = |k: &str| {
        uncertain
            .iter()
            .any(|f| f.key == k && (channels_inline || !k.starts_with("gauges.")))
    };
    let mut rows: Vec<&str> = Vec::new();
    for r in &c.correlations {
        if stated(&r.a) && stated(&r.b) && !rows.contains(&r.a.as_str()) {
            rows.push(&r.a);
        }
    }
    for a in rows {
        t.push_str(&format!("[uncertainty.correlation.\"{a}\"]\n"));
        for r in c.correlations.iter().filter(|r| r.a == a && stated(&r.b)) {
            t.push_str(&format!("\"{}\" = {:.6}\n", r.b, r.r));
        }
    }
    if !c.scatter.is_empty() {
        t.push_str("[uncertainty.scatter]\n");
        for (k, v) in &c.scatter {
            let what = if k.ends_with("_s") {
                "absolute, s"
            } else {
                "relative"
            };
            t.push_str(&format!("{k} = {v:.3e}   # {what}\n"));
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::super::{Correlation, SdFrom};
    use super::*;

    fn fitted(key: &str, value: f64, sd: Option<f64>) -> Fitted {
        Fitted {
            key: key.into(),
            value,
            unit: "1",
            sd,
            sd_from: SdFrom::Covariance,
            fitted_on: "test shots".into(),
            uncertain: true,
        }
    }

    #[test]
    fn values_are_replaced_comments_kept_and_the_uncertainty_appended() {
        let setup = "# top comment\ngauges = \"g.toml\"\n[gun]\n# the line\nk_m2_per_s2_per_pa = 7e-4   # old\nloss_pressure_pa = 2e4\n[shaper]\ncalibrated_pressure_psi = [10.0, 15.0]\n";
        let gauges = "[[channel]]\nname = \"incident\"\ndistance_from_specimen_m = 0.6\nbridge = \"full-poisson\"\ngauge_factor = 2.1\npolarity = -1.0\n[[channel]]\nname = \"transmission\"\ndistance_from_specimen_m = 0.3\n";
        let c = Calibration {
            fitted_on: "five \"shots\"".into(),
            shots: 5,
            constants: vec![
                fitted("gun.k_m2_per_s2_per_pa", 7.1234567e-4, Some(3e-5)),
                fitted("gun.loss_pressure_pa", 21760.4, Some(3e3)),
                fitted("shaper.calibrated_pressure_psi", 10.0, None),
                fitted("shaper.calibrated_pressure_psi", 12.5, None),
                fitted(
                    "gauges.transmission.distance_from_specimen_m",
                    0.31,
                    Some(1e-3),
                ),
                fitted("gauges.incident.strain_per_volt", -1.5e-3, Some(1e-5)),
            ],
            correlations: vec![
                Correlation {
                    a: "gun.k_m2_per_s2_per_pa".into(),
                    b: "gun.loss_pressure_pa".into(),
                    r: 0.93,
                },
                Correlation {
                    a: "gun.k_m2_per_s2_per_pa".into(),
                    b: "gauges.transmission.distance_from_specimen_m".into(),
                    r: 0.1,
                },
            ],
            scatter: vec![("incident_peak_stress", 0.02)],
            ran: vec![],
        };
        let t = rewrite(
            setup,
            "base.toml",
            Some(gauges),
            "new-gauges.toml",
            &c,
            "# head\n",
        )
        .unwrap();
        let s = &t.setup;
        assert!(s.starts_with("# head\n# top comment\n"), "{s}");
        assert!(s.contains("# the line\n# shpb calibrate: 7.123e-4"), "{s}");
        let parsed: toml::Table = toml::from_str(s).unwrap();
        assert_eq!(
            parsed["gun"]["k_m2_per_s2_per_pa"].as_float(),
            Some(7.123e-4)
        );
        assert_eq!(parsed["gun"]["loss_pressure_pa"].as_float(), Some(21760.0));
        assert!(
            s.contains("k_m2_per_s2_per_pa = 7.123e-4   # was 7e-4"),
            "{s}"
        );
        assert_eq!(parsed["gauges"].as_str(), Some("new-gauges.toml"));
        let arr = parsed["shaper"]["calibrated_pressure_psi"]
            .as_array()
            .unwrap();
        assert_eq!(arr.len(), 2);
        let u = &parsed["uncertainty"];
        assert_eq!(u["shots"].as_integer(), Some(5));
        assert_eq!(u["fitted_on"].as_str(), Some("five \"shots\""));
        assert!(
            (u["relative_sd"]["gun.k_m2_per_s2_per_pa"]
                .as_float()
                .unwrap()
                - 3e-5 / 7.1234567e-4)
                .abs()
                < 1e-3
        );
        assert_eq!(u["sd"]["gun.loss_pressure_pa"].as_float(), Some(3e3));
        assert_eq!(u["scatter"]["incident_peak_stress"].as_float(), Some(0.02));
        // The gauge key is not in the table (its channels are in their own file), so neither is
        // its correlation.
        let r = u["correlation"]["gun.k_m2_per_s2_per_pa"]
            .as_table()
            .unwrap();
        assert_eq!(r["gun.loss_pressure_pa"].as_float(), Some(0.93));
        assert_eq!(r.len(), 1);
        let g: toml::Table = toml::from_str(t.gauges.as_ref().unwrap()).unwrap();
        let ch = g["channel"].as_array().unwrap();
        assert_eq!(ch[1]["distance_from_specimen_m"].as_float(), Some(0.31));
        assert_eq!(ch[0]["bridge"].as_str(), Some("linear"));
        assert_eq!(ch[0]["strain_per_volt"].as_float(), Some(-1.5e-3));
        assert!(ch[0].get("gauge_factor").is_none());
        assert_eq!(ch[0]["polarity"].as_float(), Some(1.0));
    }
}
