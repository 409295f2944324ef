//! `shpb reduce`: the lab's reduction of a raw record or of a run file.

use super::common::{DEFAULT_BARS, finite, report, require_bars, stdout_once, warn, wrote};
use shpb_input::Result;
use shpb_output::atomic::{check_not_input, check_output_path};
use shpb_output::reduction::{write_reduction_csv_with, write_reduction_hdf5_with};
use std::path::Path;

/// `shpb reduce RECORD --bars SET-UP [-o OUT.h5] [--csv OUT.csv] [--no-dispersion] [--force]`:
/// reduces a raw record (the authors' CSV) or an HDF5 file of `shpb run` (recognised by its
/// signature) with the set-up's bars and gauges (`bars`: a built-in set-up name or a set-up
/// file), writes `/reduction/*` (HDF5) and/or CSV, and prints a summary. The strain rate uses
/// the paper's spheres (r1 + r2 = 6.35 mm). With `specimen` = (length, diameter) of a cylinder
/// (both or neither), also its 1/2/3-wave stress and strain (docs/physics.md §7.6).
pub fn reduce_command(
    record: &Path,
    bars_flag: Option<&Path>,
    output: Option<&Path>,
    csv: Option<&Path>,
    force: bool,
    no_dispersion: bool,
    specimen: (Option<f64>, Option<f64>),
) -> Result<()> {
    let bars = bars_flag.unwrap_or(Path::new(DEFAULT_BARS));
    require_bars(bars)?;
    let geometry = shpb_study::api::cylinder_geometry(
        specimen.0,
        specimen.1,
        ("--specimen-length", "--specimen-diameter"),
    )?;
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
    let data_on_stdout = stdout_once(&[output, csv])?;
    let shpb_study::api::Reduced {
        reduction: r,
        apparatus,
        hdf5_input,
        cylinder,
    } = shpb_study::api::reduce_record(record, bars_flag, no_dispersion, geometry)?;
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
    if let Some(g) = &geometry {
        scene.push_str(&format!(
            " --specimen-length {} --specimen-diameter {}",
            g.length_m, g.diameter_m
        ));
    }
    if force {
        scene.push_str(" --force");
    }
    if let Some(o) = output {
        write_reduction_hdf5_with(o, force, &scene, &r, cylinder.as_ref())?;
        wrote(o);
    }
    if let Some(c) = csv {
        write_reduction_csv_with(c, force, &r, cylinder.as_ref())?;
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
    let mut text = format!(
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
    if let Some(c) = &cylinder {
        text.push_str(&format!(
            "cylinder {:.3} mm × {:.3} mm (1-wave, compression positive): peak stress {:.2} MPa at t = {:.2} µs; strain at peak {:.4e}; mean strain rate {:.1} 1/s\n",
            c.geometry.length_m * 1e3,
            c.geometry.diameter_m * 1e3,
            c.peak_stress_pa * 1e-6,
            c.peak_time_s * 1e6,
            c.strain_at_peak,
            c.mean_strain_rate_per_s
        ));
    }
    report(&text, || {
        let mut json = serde_json::json!({
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
        });
        if let Some(c) = &cylinder {
            json["cylinder"] = serde_json::json!({
                "length_m": finite(c.geometry.length_m),
                "diameter_m": finite(c.geometry.diameter_m),
                "peak_stress_Pa": finite(c.peak_stress_pa),
                "peak_stress_time_s": finite(c.peak_time_s),
                "strain_at_peak_stress": finite(c.strain_at_peak),
                "mean_strain_rate_per_s": finite(c.mean_strain_rate_per_s),
            });
        }
        json
    })
}
