//! `shpb strain`: a raw gauge record converted to bar strain with the set-up's gauge channels.

use super::common::{plan, say, write_all};
use shpb_core::run::RunOutput;
use shpb_input::{Error, Result};
use std::path::Path;

/// How `shpb strain` reads the record.
pub struct StrainOptions<'a> {
    /// A layout for a text record that is not the authors' CSV (`--layout`).
    pub layout: Option<&'a Path>,
    /// Samples at the start of each channel whose mean is removed (`--baseline-samples`; 0: off).
    pub baseline_samples: usize,
}

/// `shpb strain RECORD [--bars SET-UP] [--layout FILE] [--baseline-samples N] [-o OUT.h5]
/// [--csv OUT.csv] [--force]`: the record's bridge voltages, each channel's pre-trigger baseline
/// removed as `shpb reduce` removes it, converted to bar strain through the set-up's channels.
pub fn strain(
    record: &Path,
    bars: &Path,
    read_as: StrainOptions,
    output: Option<&Path>,
    csv: Option<&Path>,
    force: bool,
) -> Result<()> {
    let outputs = plan(
        force,
        &[
            (output, "--output", &["h5", "hdf5"][..]),
            (csv, "--csv", &["csv"][..]),
        ],
    )?;
    let mut inputs_given = vec![record.to_path_buf(), bars.to_path_buf()];
    inputs_given.extend(read_as.layout.map(Path::to_path_buf));
    outputs.not_inputs(&inputs_given)?;
    let (read, inputs) = shpb_input::files::capture(|| -> Result<_> {
        // A set-up, or a lab's input deck (its bridges and gains; `load_record_apparatus`).
        let (apparatus, _) = shpb_study::api::load_record_apparatus(bars)?;
        let layout = read_as
            .layout
            .map(shpb_input::layout::RecordLayout::from_file)
            .transpose()?;
        let rec = match shpb_input::sheet::read_record(record, layout.as_ref())? {
            shpb_input::layout::LayoutRecord::Voltages(r) => r,
            shpb_input::layout::LayoutRecord::Strains(_) => {
                return Err(Error::Input {
                    file: layout.map_or(record.display().to_string(), |l| l.source),
                    key: "incident.unit".into(),
                    problem: "the record holds bar strains; `shpb strain` converts bridge \
                              voltages"
                        .into(),
                    allowed: "a record or layout with V or mV channels (strain records go to \
                              `shpb reduce` directly)"
                        .into(),
                });
            }
        };
        Ok((apparatus, rec))
    });
    let (apparatus, mut rec) = read?;
    // Issue 42: a baseline longer than the record was cut to half of it without a word.
    let half = rec.time_s.len() / 2;
    if read_as.baseline_samples > half {
        return Err(Error::Input {
            file: record.display().to_string(),
            key: "--baseline-samples".into(),
            problem: format!(
                "{} samples (900 unless given) is more than half of the record's {} samples: \
                 the baseline would take in the pulse",
                read_as.baseline_samples,
                rec.time_s.len()
            ),
            allowed: format!("0 to {half} samples for this record"),
        });
    }
    for (name, volts) in [
        ("incident", &rec.incident_v),
        ("transmission", &rec.transmission_v),
    ] {
        if let Some(ch) = apparatus.gauges.channel(name) {
            shpb_core::reduce::beyond_digitiser_range(ch, volts, &apparatus.source)?;
        }
    }
    let n = read_as.baseline_samples;
    rec.incident_v = shpb_core::gauge::remove_baseline(&rec.incident_v, n);
    rec.transmission_v = shpb_core::gauge::remove_baseline(&rec.transmission_v, n);
    let mut gauges = Vec::new();
    for (name, volts) in [
        ("incident", &rec.incident_v),
        ("transmission", &rec.transmission_v),
    ] {
        let ch = apparatus.gauges.channel(name).ok_or_else(|| Error::Input {
            file: apparatus.source.clone(),
            key: "gauges".into(),
            problem: format!("no `{name}` channel in the gauge set-up"),
            allowed: "channels named incident and transmission".into(),
        })?;
        gauges.push(shpb_core::run::GaugeTrace {
            name: name.to_string(),
            strain: ch.strains_from_voltages(volts),
            voltage_v: volts.clone(),
        });
    }
    // The converted record checked for plausibility as far as a conversion needs: its time
    // unit, its scale against the bars' elastic limit, a clipped pulse (a record need not hold
    // whole pulses to be converted).
    let channel = |k: usize| shpb_core::reduce::plausibility::Channel {
        name: if k == 0 { "incident" } else { "transmission" },
        time_s: &rec.time_s,
        strain: &gauges[k].strain,
        volts: false,
        youngs_modulus_pa: Some(apparatus.material.youngs_modulus_pa),
        baseline_samples: n,
        smoothing_window_s: shpb_core::reduce::DEFAULT_SMOOTHING_S,
        pulse_due_s: None,
    };
    shpb_core::reduce::plausibility::check_channels_named(
        &[channel(0), channel(1)],
        &record.display().to_string(),
        &["time-span", "clipped", "elastic-limit"],
    )?;
    let out = RunOutput {
        contact: None,
        time_s: Some(rec.time_s.clone()),
        gauges,
        energy: Vec::new(),
        bars: Vec::new(),
        summary: Vec::new(),
        reduction: None,
        warnings: Vec::new(),
        chain: None,
        drive: None,
        specimen: None,
        cylinder_reduction: None,
    };
    let text = format!(
        "record = \"{}\"\nbars = \"{}\"\nbaseline_samples = {n}\n",
        record.display(),
        bars.display()
    );
    write_all(&outputs, || {
        if let Some(p) = output {
            let provenance = shpb_input::files::Provenance {
                scene_file: String::new(),
                fidelity_override: None,
                command_line: super::common::command_line(),
                inputs: inputs.clone(),
            };
            shpb_output::io::write_hdf5(p, force, &text, Some(&provenance), &out)?;
        }
        if let Some(p) = csv {
            shpb_output::io::write_csv(p, force, &out)?;
        }
        Ok(())
    })?;
    if output.is_none() && csv.is_none() {
        let peak = |s: &[f64]| s.iter().cloned().fold(0.0, f64::min);
        say(&format!(
            "{} samples; most compressive strain: incident {:.4e}, transmission {:.4e}",
            rec.time_s.len(),
            peak(&out.gauges[0].strain),
            peak(&out.gauges[1].strain)
        ))?;
    }
    Ok(())
}
