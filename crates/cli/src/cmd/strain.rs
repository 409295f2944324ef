//! `shpb strain`: a raw gauge record converted to bar strain with the set-up's gauge channels.

use super::common::{load_apparatus, say};
use shpb_core::run::RunOutput;
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use shpb_output::atomic::{check_not_input, check_output_path};
use std::path::Path;

/// `shpb strain RECORD [--bars SET-UP] [-o OUT.h5] [--csv OUT.csv] [--force]`.
pub fn strain(
    record: &Path,
    bars: &Path,
    output: Option<&Path>,
    csv: Option<&Path>,
    force: bool,
) -> Result<()> {
    let outputs = [
        (output, "--output", &["h5", "hdf5"][..]),
        (csv, "--csv", &["csv"][..]),
    ];
    for (p, flag, extensions) in outputs {
        if let Some(p) = p {
            check_output_path(p, force, flag, extensions)?;
            check_not_input(p, flag, &[record.to_path_buf(), bars.to_path_buf()])?;
        }
    }
    let (read, inputs) = shpb_input::files::capture(|| -> Result<_> {
        Ok((
            load_apparatus(bars)?,
            shpb_core::gauge::RawRecord::read(record)?,
        ))
    });
    let (apparatus, rec) = read?;
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
    };
    let text = format!(
        "record = \"{}\"\nbars = \"{}\"\n",
        record.display(),
        bars.display()
    );
    if let Some(p) = output {
        let provenance = shpb_input::files::Provenance {
            scene_file: String::new(),
            fidelity_override: None,
            command_line: std::env::args().collect::<Vec<_>>().join(" "),
            inputs: inputs.clone(),
        };
        shpb_output::io::write_hdf5(p, force, &text, Some(&provenance), &out)?;
        super::common::wrote(p);
    }
    if let Some(p) = csv {
        shpb_output::io::write_csv(p, force, &out)?;
        super::common::wrote(p);
    }
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
