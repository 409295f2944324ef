//! `shpb strain`: a raw gauge record converted to bar strain with the set-up's gauge channels.

use super::common::{load_apparatus, say};
use shpb_core::run::RunOutput;
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use shpb_output::io::check_output;
use std::path::Path;

/// `shpb strain RECORD [--bars SET-UP] [-o OUT.h5] [--csv OUT.csv] [--force]`.
pub fn strain(
    record: &Path,
    bars: &Path,
    output: Option<&Path>,
    csv: Option<&Path>,
    force: bool,
) -> Result<()> {
    for p in [output, csv].into_iter().flatten() {
        check_output(p, force)?;
    }
    let apparatus = load_apparatus(bars)?;
    let rec = shpb_core::gauge::RawRecord::read(record)?;
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
    };
    let text = format!(
        "record = \"{}\"\nbars = \"{}\"\n",
        record.display(),
        bars.display()
    );
    if let Some(p) = output {
        shpb_output::io::write_hdf5(p, force, &text, &out)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = csv {
        shpb_output::io::write_csv(p, force, &out)?;
        eprintln!("wrote {}", p.display());
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
