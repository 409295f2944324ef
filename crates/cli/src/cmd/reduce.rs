//! `shpb reduce`: the lab's reduction of a raw record or of a run file.

use super::common::{
    DEFAULT_BARS, finite, input_err, load_apparatus, report, require_bars, stdout_once, warn, wrote,
};
use shpb_core::apparatus::Apparatus;
use shpb_core::reduce::{PAPER_SPHERE_RADII_M, ReductionOptions, ReductionSetup, reduce_named};
use shpb_core::scene::{Params, SceneParams};
use shpb_input::Result;
use shpb_input::gauges::reduce_record_file;
use shpb_input::prelude::*;
use shpb_output::atomic::{check_extension, check_not_input, check_output_flag};
use shpb_output::reduction::{
    is_hdf5, read_hdf5_strains, write_reduction_csv, write_reduction_hdf5,
};
use std::path::Path;

/// `shpb reduce RECORD --bars SET-UP [-o OUT.h5] [--csv OUT.csv] [--no-dispersion] [--force]`:
/// reduces a raw record (the authors' CSV) or an HDF5 file of `shpb run` (recognised by its
/// signature) with the set-up's bars and gauges (`bars`: a built-in set-up name or a set-up
/// file), writes `/reduction/*` (HDF5) and/or CSV, and prints a summary. The strain rate uses
/// the paper's spheres (r1 + r2 = 6.35 mm).
pub fn reduce_command(
    record: &Path,
    bars_flag: Option<&Path>,
    output: Option<&Path>,
    csv: Option<&Path>,
    force: bool,
    no_dispersion: bool,
) -> Result<()> {
    let bars = bars_flag.unwrap_or(Path::new(DEFAULT_BARS));
    require_bars(bars)?;
    let outputs = [
        (output, "--output", &["h5", "hdf5"][..]),
        (csv, "--csv", &["csv"][..]),
    ];
    for (p, flag, extensions) in outputs {
        if let Some(p) = p {
            check_output_flag(p, force, flag)?;
            check_extension(p, flag, extensions)?;
            check_not_input(p, flag, &[record.to_path_buf(), bars.to_path_buf()])?;
        }
    }
    if !record.is_file() {
        return Err(input_err(
            "command line",
            "RECORD",
            format!("cannot read {}: no such file", record.display()),
            "a raw gauge record (.csv: time_s,incident_V,transmission_V) or an HDF5 file of `shpb run`",
        ));
    }
    let data_on_stdout = stdout_once(&[output, csv])?;
    let hdf5_input = is_hdf5(record)?;
    let run = if hdf5_input { run_setup(record)? } else { None };
    let (apparatus, radii) = match run {
        Some((run_apparatus, radii)) => {
            if let Some(flag) = bars_flag {
                let given = load_apparatus(flag)?;
                if ReductionSetup::from_apparatus(&given)?
                    != ReductionSetup::from_apparatus(&run_apparatus)?
                {
                    return Err(input_err(
                        "command line",
                        "--bars",
                        format!(
                            "{} was simulated with the set-up {} ({}); --bars {} differs ({})",
                            record.display(),
                            run_apparatus.source,
                            describe(&run_apparatus),
                            flag.display(),
                            describe(&given)
                        ),
                        "no --bars (the run file's own set-up is used), or a set-up with the same bars and gauge distances",
                    ));
                }
            }
            (run_apparatus, radii)
        }
        None => (load_apparatus(bars)?, PAPER_SPHERE_RADII_M),
    };
    let options = ReductionOptions {
        dispersion_correction: !no_dispersion,
        specimen_radii_m: Some(radii),
        ..ReductionOptions::default()
    };
    let r = if hdf5_input {
        let input = read_hdf5_strains(record)?;
        reduce_named(
            &input,
            &ReductionSetup::from_apparatus(&apparatus)?,
            &options,
            &record.display().to_string(),
        )?
    } else {
        reduce_record_file(record, &apparatus, &options)?
    };
    let mut scene = format!(
        "shpb reduce {} --bars {}",
        record.display(),
        bars_flag.map_or(apparatus.source.clone(), |b| b.display().to_string())
    );
    if let Some(o) = output {
        scene.push_str(&format!(" -o {}", o.display()));
    }
    if let Some(c) = csv {
        scene.push_str(&format!(" --csv {}", c.display()));
    }
    if no_dispersion {
        scene.push_str(" --no-dispersion");
    }
    if force {
        scene.push_str(" --force");
    }
    if let Some(o) = output {
        write_reduction_hdf5(o, force, &scene, &r)?;
        wrote(o);
    }
    if let Some(c) = csv {
        write_reduction_csv(c, force, &r)?;
        wrote(c);
    }
    for w in &r.warnings {
        warn(w);
    }
    if data_on_stdout {
        return Ok(());
    }
    let bridges: Vec<String> = ["incident", "transmission"]
        .iter()
        .filter_map(|n| apparatus.gauges.channel(n))
        .map(|c| {
            format!(
                "{} {} gain {}",
                c.name,
                c.bridge.kind.name(),
                c.amplifier_gain
            )
        })
        .collect();
    let text = format!(
        "record: {} ({}); bridges: {}\n\
         windows: incident from {:.2} µs, reflected +{:.2} µs, transmitted +{:.2} µs, {:.1} µs long; dispersion correction {}\n\
         peak back force {:.1} N at t = {:.2} µs; displacement at peak force {:.2} µm; equilibrium ratio at peak {:.3}\n",
        record.display(),
        if hdf5_input {
            "HDF5 gauge strains"
        } else {
            "raw gauge voltages"
        },
        bridges.join(", "),
        r.windows.incident_start_s * 1e6,
        r.windows.reflected_delay_s * 1e6,
        r.windows.transmitted_delay_s * 1e6,
        r.windows.duration_s * 1e6,
        if r.dispersion_corrected { "on" } else { "off" },
        r.peak_back_force_n,
        r.peak_back_force_time_s * 1e6,
        r.displacement_at_peak_force_m * 1e6,
        r.equilibrium_ratio_at_peak
    );
    report(&text, || {
        serde_json::json!({
            "record": record.display().to_string(),
            "set_up": apparatus.source,
            "input": if hdf5_input { "hdf5 gauge strains" } else { "raw gauge voltages" },
            "windows_s": {
                "incident_start": finite(r.windows.incident_start_s),
                "reflected_delay": finite(r.windows.reflected_delay_s),
                "transmitted_delay": finite(r.windows.transmitted_delay_s),
                "duration": finite(r.windows.duration_s),
            },
            "dispersion_corrected": r.dispersion_corrected,
            "peak_back_force_N": finite(r.peak_back_force_n),
            "peak_back_force_time_s": finite(r.peak_back_force_time_s),
            "displacement_at_peak_force_m": finite(r.displacement_at_peak_force_m),
            "equilibrium_ratio_at_peak": finite(r.equilibrium_ratio_at_peak),
            "warnings": r.warnings,
        })
    })
}

/// The set-up and sphere radii a run file was simulated with, from the scene and inputs stored
/// in its `/provenance` (None for a file without a stored bar scene, e.g. `shpb strain`'s).
fn run_setup(record: &Path) -> Result<Option<(Apparatus, (f64, f64))>> {
    let Ok(stored) = shpb_output::provenance::read_provenance(record) else {
        return Ok(None);
    };
    if stored.scene_file.is_empty() {
        return Ok(None);
    }
    let params = shpb_input::files::replay(&stored.inputs, || {
        Params::from_file_with(Path::new(&stored.scene_file), None)
    })?;
    Ok(match params.params {
        SceneParams::Pulse { apparatus, .. } => Some((
            *apparatus,
            (params.pair.sphere1.radius_m, params.pair.sphere2.radius_m),
        )),
        _ => None,
    })
}

/// The bar diameters and gauge distances of a set-up, for messages.
fn describe(a: &Apparatus) -> String {
    let gauge = |n: &str| {
        a.gauges.channel(n).map_or("none".to_string(), |c| {
            format!("{} m", c.distance_from_specimen_m)
        })
    };
    format!(
        "bars {} / {} mm, gauges at {} / {}",
        a.incident.diameter_m * 1e3,
        a.transmission.diameter_m * 1e3,
        gauge("incident"),
        gauge("transmission")
    )
}
