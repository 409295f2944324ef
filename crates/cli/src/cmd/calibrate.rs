//! `shpb calibrate`: a set-up's constants fitted to a lab's own shots (shpb_study::calibrate).

use super::common::{quiet_mode, report, warn};
use shpb_core::apparatus::Apparatus;
use shpb_core::gauge::GaugeSetup;
use shpb_input::prelude::*;
use shpb_input::shots::ShotManifest;
use shpb_input::{Error, Result};
use shpb_output::atomic::{check_not_input, check_output_path, write_text_atomically};
use shpb_study::calibrate::{
    Calibration, Data, Fitted, SdFrom, calibrate as run_calibrations, model_scatter, setup_file,
};
use std::path::{Path, PathBuf};

/// The gauge file written beside `output`: `<stem>-gauges.toml`.
pub fn gauges_path(output: &Path) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or("setup".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}-gauges.toml"))
}

/// `shpb calibrate SHOTS.toml --bars BASE -o SETUP.toml [--force]`: runs every calibration whose
/// data the shots carry (shpb_study::calibrate::CALIBRATIONS), prints each constant with its
/// 1-sigma and what it was fitted on, and writes the base set-up with the calibrated values
/// replaced, the `[uncertainty]` table appended, and its gauge file beside it
/// (`SETUP-gauges.toml`). Progress of long fits goes to stderr.
///
/// The strain factor from paired volt and strain files (`--paired VOLTS STRAINS`,
/// shpb_study::strain_factor) is a calibration of its own: it joins the constants here, as a
/// `gauges.<channel>.strain_per_volt` [`shpb_study::calibrate::Fitted`], before the set-up is
/// written.
pub fn calibrate(
    shots: Option<&Path>,
    paired: Option<(&Path, &Path)>,
    bars: &Path,
    output: &Path,
    force: bool,
) -> Result<()> {
    if shpb_output::atomic::is_stdout(output) {
        return Err(shpb_study::api::input_err(
            "-o",
            "the set-up cannot go to stdout: its gauge file is written beside it",
            "a .toml file path",
        ));
    }
    if output.file_name().is_some_and(|n| n.to_str().is_none()) {
        return Err(shpb_study::api::input_err(
            "-o",
            format!(
                "{} is not valid UTF-8: the set-up names its gauge file inside it, in TOML",
                output.display()
            ),
            "a .toml file name in UTF-8",
        ));
    }
    check_output_path(output, force, "-o", &["toml"][..])?;
    let gauges_out = gauges_path(output);
    if shots.is_none() && paired.is_none() {
        return Err(shpb_study::api::input_err(
            "SHOTS",
            "nothing to calibrate on",
            "a shots manifest, --paired VOLTS STRAINS, or both",
        ));
    }
    if let Some(shots) = shots
        && !shots.is_file()
    {
        return Err(shpb_study::api::input_err(
            "SHOTS",
            format!(
                "cannot read {}: {}",
                shots.display(),
                shpb_input::files::not_a_file(shots)
            ),
            "a shots manifest .toml ([[shot]] tables with file and pressure or \
             striker_velocity_m_s)",
        ));
    }
    let (base_name, base_text, base_gauges) = setup_file::read_base(bars)?;
    let manifest = shots.map(ShotManifest::from_file).transpose()?;
    let outputs = super::common::plan(
        force,
        &[
            (Some(output), "-o", &["toml"]),
            (
                base_gauges.is_some().then_some(gauges_out.as_path()),
                "-o (its gauge file)",
                &["toml"],
            ),
        ],
    )?;
    let mut inputs: Vec<PathBuf> = vec![bars.to_path_buf()];
    inputs.extend(shots.map(Path::to_path_buf));
    if let Some(m) = &manifest {
        inputs.extend(m.shots.iter().map(|s| s.file.clone()));
        inputs.extend(m.shots.iter().filter_map(|s| s.scene.clone()));
    }
    if let Some((v, s)) = paired {
        inputs.extend([v.to_path_buf(), s.to_path_buf()]);
    }
    outputs.not_inputs(&inputs)?;
    check_not_input(&gauges_out, "-o", &inputs)?;

    let base = shpb_study::api::load_apparatus(bars)?;
    let mut c = match &manifest {
        Some(manifest) => {
            let data = Data::read(base, manifest)?;
            let show = !quiet_mode();
            let mut progress = |line: &str| {
                if show {
                    eprintln!("calibrate: {line}");
                }
            };
            let mut c = run_calibrations(&data, &mut progress)?;
            if let Some(m) = model_scatter::about_model(&data, &c)? {
                for s in &m.shots {
                    progress(&format!(
                        "scatter about the model: {}: measured/simulated peak {}, energy {}, \
                         reflected delay {}, transmitted delay {}",
                        s.label,
                        ratio(s.measured[0], s.simulated[0]),
                        ratio(s.measured[1], s.simulated[1]),
                        difference_us(s.measured[2], s.simulated[2]),
                        difference_us(s.measured[3], s.simulated[3]),
                    ));
                }
                c.scatter = m.scatter;
            }
            c
        }
        None => Calibration {
            fitted_on: String::new(),
            shots: 0,
            constants: Vec::new(),
            correlations: Vec::new(),
            scatter: Vec::new(),
            ran: Vec::new(),
        },
    };
    if let Some((volts, strains)) = paired {
        paired_factor(&mut c, volts, strains)?;
    }
    let shots = shots.unwrap_or(Path::new("--paired"));

    let gauges_name = gauges_out
        .file_name()
        .map_or("setup-gauges.toml".into(), |n| {
            n.to_string_lossy().into_owned()
        });
    let header = format!(
        "# Set-up calibrated by `shpb calibrate {} --bars {}` on {} shots ({}).\n\
         # The base set-up's text, each calibrated value replaced (a `# shpb calibrate:` comment\n\
         # above it says what it was fitted on; the old value follows it); [uncertainty] at the end.\n\n",
        shots.display(),
        bars.display(),
        c.shots,
        c.fitted_on
    );
    let texts = setup_file::rewrite(
        &base_text,
        &base_name,
        base_gauges.as_deref(),
        &gauges_name,
        &c,
        &header,
    )?;
    check_loads(&texts, &gauges_name);
    super::common::write_all(&outputs, || {
        if let Some(g) = &texts.gauges {
            write_text_atomically(&gauges_out, force, g)?;
        }
        write_text_atomically(output, force, &texts.setup)
    })?;
    let gauges_written = texts.gauges.as_ref().map(|_| gauges_out.as_path());
    report(&text(&c), || json(&c, output, gauges_written))
}

/// The strain factor of each channel from a shot's paired volt and strain records
/// (shpb_study::strain_factor: least squares ε = k·V + b), joined to the calibration as
/// `gauges.<channel>.strain_per_volt` with its standard error.
fn paired_factor(c: &mut Calibration, volts: &Path, strains: &Path) -> Result<()> {
    let f = shpb_study::strain_factor::strain_factor(volts, strains)?;
    let on = format!(
        "paired records {} (V) and {} (strain), least squares over {} samples",
        volts.display(),
        strains.display(),
        f.incident.samples
    );
    for (channel, k) in [("incident", &f.incident), ("transmission", &f.transmission)] {
        // The set-up states k to 4 significant digits: its rounding error (uniform within half
        // a unit u of the 4th digit, sd = u / (2√3)) bounds the 1-sigma from below.
        let unit = 10f64.powf(k.strain_per_volt.abs().log10().floor() - 3.0);
        let rounding = unit / (2.0 * 3f64.sqrt());
        c.constants.push(Fitted {
            key: format!("gauges.{channel}.strain_per_volt"),
            value: k.strain_per_volt,
            unit: "1/V",
            sd: Some(k.standard_error.max(rounding)),
            sd_from: SdFrom::Covariance,
            fitted_on: format!("{on}; residual {:.3e} RMS", k.residual_rms_strain),
            uncertain: true,
        });
    }
    if c.fitted_on.is_empty() {
        c.fitted_on = on;
    } else {
        c.fitted_on = format!("{}; {on}", c.fitted_on);
    }
    c.shots = c.shots.max(1);
    c.ran.push(("paired-strain-factor", None));
    Ok(())
}

/// Warns when the written set-up would not load as a set-up (a calibrated value out of its key's
/// range, or an uncertainty its key cannot carry).
fn check_loads(texts: &setup_file::SetupTexts, gauges_name: &str) {
    let gauges = |g: &str| -> Result<GaugeSetup> {
        match &texts.gauges {
            Some(t) if g == gauges_name => GaugeSetup::from_toml(t, g),
            _ => Err(Error::Input {
                file: "calibrated set-up".into(),
                key: "gauges".into(),
                problem: format!("unexpected gauge file {g}"),
                allowed: gauges_name.into(),
            }),
        }
    };
    if let Err(e) = Apparatus::from_toml(&texts.setup, "calibrated set-up", &gauges) {
        warn(&format!("the calibrated set-up does not load: {e}"));
    }
}

/// measured/simulated, or `—`.
fn ratio(m: Option<f64>, y: Option<f64>) -> String {
    match (m, y) {
        (Some(m), Some(y)) => format!("{:.3}", m / y),
        _ => "—".into(),
    }
}

/// measured − simulated in µs, or `—`.
fn difference_us(m: Option<f64>, y: Option<f64>) -> String {
    match (m, y) {
        (Some(m), Some(y)) => format!("{:+.1} us", (m - y) * 1e6),
        _ => "—".into(),
    }
}

/// A number with 4 significant digits.
fn g4(x: f64) -> String {
    format!("{x:.4e}")
}

/// The printed result.
fn text(c: &Calibration) -> String {
    let mut t = format!("calibrated on {} shots: {}\n", c.shots, c.fitted_on);
    for f in &c.constants {
        let sd = match (f.sd, f.relative_sd()) {
            (Some(sd), Some(r)) => format!(
                " ± {} {} ({:.2} %, {})",
                g4(sd),
                f.unit,
                100.0 * r,
                f.sd_from.name()
            ),
            _ => String::new(),
        };
        t.push_str(&format!("  {:<46} {} {}{sd}\n", f.key, g4(f.value), f.unit));
        t.push_str(&format!("      fitted on: {}\n", f.fitted_on));
    }
    if !c.correlations.is_empty() {
        t.push_str("correlations of constants fitted together:\n");
        for r in &c.correlations {
            t.push_str(&format!("  {} ~ {}: {:+.3}\n", r.a, r.b, r.r));
        }
    }
    if !c.scatter.is_empty() {
        t.push_str("shot-to-shot scatter (1-sigma):\n");
        for (k, v) in &c.scatter {
            t.push_str(&format!("  {k:<46} {}\n", g4(*v)));
        }
    }
    for (name, why) in &c.ran {
        if let Some(why) = why {
            t.push_str(&format!("not calibrated: {name}: {why}\n"));
        }
    }
    t
}

/// The `--json` result.
fn json(c: &Calibration, setup: &Path, gauges: Option<&Path>) -> serde_json::Value {
    let constants: Vec<serde_json::Value> = c
        .constants
        .iter()
        .map(|f| {
            serde_json::json!({
                "key": f.key,
                "value": f.value,
                "unit": f.unit,
                "sd": f.sd,
                "relative_sd": f.relative_sd(),
                "sd_from": f.sd_from.name(),
                "fitted_on": f.fitted_on,
            })
        })
        .collect();
    let scatter: serde_json::Map<String, serde_json::Value> = c
        .scatter
        .iter()
        .map(|(k, v)| (k.to_string(), serde_json::json!(v)))
        .collect();
    let correlations: Vec<serde_json::Value> = c
        .correlations
        .iter()
        .map(|r| serde_json::json!({"a": r.a, "b": r.b, "r": r.r}))
        .collect();
    let skipped: serde_json::Map<String, serde_json::Value> = c
        .ran
        .iter()
        .filter_map(|(n, w)| w.as_ref().map(|w| (n.to_string(), serde_json::json!(w))))
        .collect();
    serde_json::json!({
        "fitted_on": c.fitted_on,
        "shots": c.shots,
        "constants": constants,
        "correlations": correlations,
        "scatter": scatter,
        "not_calibrated": skipped,
        "setup": setup.display().to_string(),
        "gauges": gauges.map(|g| g.display().to_string()),
    })
}
