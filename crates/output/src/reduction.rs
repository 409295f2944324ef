//! The lab's reduction written out (`/reduction/*` in HDF5, or CSV), and the gauge strains of a
//! run file read back for `shpb reduce`.

use crate::atomic::{write_atomically, write_text_atomically};
use crate::h5::{h5err, string_attr, write_dataset};
use shpb_core::reduce::{Reduction, ReductionInput};
use shpb_core::reduce_cylinder::{CylinderReduction, WaveAnalysis};
use shpb_input::{Error, Result};
use std::path::Path;

/// Reads `/time` and `/gauges/{incident,transmission}/strain` of an HDF5 file written by
/// `shpb run`.
pub fn read_hdf5_strains(path: &Path) -> Result<ReductionInput> {
    let f = crate::h5::open(path).map_err(h5err(path))?;
    let read = |name: &str| -> Result<Vec<f64>> {
        let ds = f.dataset(name).map_err(|e| {
            Error::Input {
                file: path.display().to_string(),
                key: name.to_string(),
                problem: format!("cannot read it ({e})"),
                allowed: "an HDF5 file written by `shpb run` of a bar scene (/time, /gauges/incident/strain, /gauges/transmission/strain)".into(),
            }
        })?;
        ds.read_raw::<f64>().map_err(h5err(path))
    };
    Ok(ReductionInput {
        time_s: read("time")?,
        incident_strain: read("gauges/incident/strain")?,
        transmission_strain: read("gauges/transmission/strain")?,
    })
}

/// One dataset of an HDF5 file (e.g. `gauges/incident_2/strain`), None when it has none.
pub fn read_hdf5_series(path: &Path, name: &str) -> Result<Option<Vec<f64>>> {
    let f = crate::h5::open(path).map_err(h5err(path))?;
    Ok(match f.dataset(name) {
        Ok(ds) => Some(ds.read_raw::<f64>().map_err(h5err(path))?),
        Err(_) => None,
    })
}

/// `/time` and `/gauges/{incident,transmission}/voltage` of a run file (the digitised bridge
/// outputs, V), or None when the file has no such datasets.
pub fn read_hdf5_voltages(path: &Path) -> Result<Option<shpb_core::gauge::RawRecord>> {
    let f = crate::h5::open(path).map_err(h5err(path))?;
    let read = |name: &str| -> Option<Vec<f64>> { f.dataset(name).ok()?.read_raw::<f64>().ok() };
    Ok(
        match (
            read("time"),
            read("gauges/incident/voltage"),
            read("gauges/transmission/voltage"),
        ) {
            (Some(time_s), Some(incident_v), Some(transmission_v)) => {
                Some(shpb_core::gauge::RawRecord {
                    time_s,
                    incident_v,
                    transmission_v,
                })
            }
            _ => None,
        },
    )
}

/// Whether `path` starts with the HDF5 signature.
pub fn is_hdf5(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut sig = [0u8; 8];
    let n = f.read(&mut sig).map_err(|e| Error::io(path, e))?;
    Ok(n == 8 && sig == *b"\x89HDF\r\n\x1a\n")
}

/// The `/reduction` datasets: (name, data, units, CSV column).
pub fn reduction_columns(r: &Reduction) -> Vec<(&'static str, &[f64], &'static str, &'static str)> {
    let mut cols = vec![
        ("time", r.time_s.as_slice(), "s", "time_s"),
        (
            "displacement",
            r.displacement_m.as_slice(),
            "m",
            "displacement_m",
        ),
        (
            "force_front",
            r.force_front_n.as_slice(),
            "N",
            "force_front_N",
        ),
        ("force_back", r.force_back_n.as_slice(), "N", "force_back_N"),
        (
            "force_3wave",
            r.force_3wave_n.as_slice(),
            "N",
            "force_3wave_N",
        ),
        (
            "approach_velocity",
            r.approach_velocity_m_s.as_slice(),
            "m/s",
            "approach_velocity_m_s",
        ),
    ];
    if let Some(s) = &r.strain_rate_per_s {
        cols.push(("strain_rate", s.as_slice(), "1/s", "strain_rate_per_s"));
    }
    cols.push((
        "equilibrium_ratio",
        r.equilibrium_ratio.as_slice(),
        "1",
        "equilibrium_ratio",
    ));
    cols
}

/// Scalar results of a reduction, as `/summary` attributes: (key, value, unit).
pub fn summary_items(r: &Reduction) -> Vec<(&'static str, f64, &'static str)> {
    let mut v = vec![
        ("peak_back_force", r.peak_back_force_n, "N"),
        ("peak_back_force_time", r.peak_back_force_time_s, "s"),
        (
            "displacement_at_peak_force",
            r.displacement_at_peak_force_m,
            "m",
        ),
        (
            "equilibrium_ratio_at_peak",
            r.equilibrium_ratio_at_peak,
            "1",
        ),
        ("peak_front_force", r.peak_front_force_n, "N"),
        ("max_displacement", r.max_displacement_m, "m"),
        ("face_time_offset", r.face_time_offset_s, "s"),
        ("incident_start", r.windows.incident_start_s, "s"),
        ("reflected_delay", r.windows.reflected_delay_s, "s"),
        ("transmitted_delay", r.windows.transmitted_delay_s, "s"),
        ("window_duration", r.windows.duration_s, "s"),
        (
            "dispersion_corrected",
            if r.dispersion_corrected { 1.0 } else { 0.0 },
            "1",
        ),
    ];
    if let Some(m) = r.measured_reflected_delay_s {
        v.push(("measured_reflected_delay", m, "s"));
    }
    let a = &r.alignment;
    v.push((
        "geometric_reflected_delay",
        a.geometric_reflected_delay_s,
        "s",
    ));
    v.push((
        "geometric_transmitted_delay",
        a.geometric_transmitted_delay_s,
        "s",
    ));
    if let Some(m) = a.measured_transmitted_delay_s {
        v.push(("measured_transmitted_delay", m, "s"));
    }
    if let Some((sr, st)) = a.balance_shift_s {
        v.push(("balance_shift_reflected", sr, "s"));
        v.push(("balance_shift_transmitted", st, "s"));
    }
    if let Some((pi, pt)) = a.balance_paths_m {
        v.push(("balance_incident_path", pi, "m"));
        v.push(("balance_transmission_path", pt, "m"));
    }
    if let Some(s) = &r.separation {
        v.push((
            "wave_separation_gauges_per_bar",
            if s.incident_gauges_m.1.is_some() {
                2.0
            } else {
                1.0
            },
            "1",
        ));
        v.push(("wave_separation_series_terms", s.series_terms as f64, "1"));
    }
    let q = &r.quality;
    v.extend([
        ("equilibrium_mean_loading", q.equilibrium_mean, "1"),
        ("equilibrium_max_loading", q.equilibrium_max, "1"),
        ("loading_start", q.loading_span_s.0, "s"),
        ("loading_end", q.loading_span_s.1, "s"),
        ("incident_duration", q.incident_duration_s, "s"),
        ("pulse_overlap", q.pulse_overlap_s, "s"),
        ("noise_incident_strain", q.noise_strain.0, "1"),
        ("noise_transmission_strain", q.noise_strain.1, "1"),
        ("signal_to_noise_incident", q.signal_to_noise.0, "1"),
        ("signal_to_noise_transmission", q.signal_to_noise.1, "1"),
    ]);
    v
}

/// Writes a reduction to HDF5 atomically: root attributes `shpb_version` and `scene` (the
/// command line), `/reduction/<series>` with `units` attributes, `/summary` scalar attributes
/// with a `units` list.
pub fn write_reduction_hdf5(path: &Path, force: bool, scene: &str, r: &Reduction) -> Result<()> {
    write_reduction_hdf5_with(path, force, scene, r, None)
}

/// The analyses of a cylinder's reduction: (group name, analysis) for `/reduction/cylinder`.
pub fn cylinder_analyses(c: &CylinderReduction) -> [(&'static str, &WaveAnalysis); 3] {
    [
        ("one_wave", &c.one_wave),
        ("two_wave", &c.two_wave),
        ("three_wave", &c.three_wave),
    ]
}

/// The series of one analysis: (name, data, units, CSV column suffix) (docs/physics.md §7.8).
pub fn analysis_columns(
    a: &WaveAnalysis,
) -> [(&'static str, &[f64], &'static str, &'static str); 5] {
    [
        ("stress", &a.stress_pa, "Pa", "stress_Pa"),
        ("strain", &a.strain, "1", "strain"),
        (
            "strain_rate",
            &a.strain_rate_per_s,
            "1/s",
            "strain_rate_per_s",
        ),
        ("true_stress", &a.true_stress_pa, "Pa", "true_stress_Pa"),
        ("true_strain", &a.true_strain, "1", "true_strain"),
    ]
}

/// Writes `cylinder/` under the reduction group `g`: the geometry as attributes and
/// `<analysis>/<series>` of [`cylinder_analyses`] (compression positive, docs/physics.md §7.8;
/// tension positive for a tension test, §7.8.1).
pub fn write_cylinder_group(g: &hdf5::Group, c: &CylinderReduction, path: &Path) -> Result<()> {
    let cg = g.create_group("cylinder").map_err(h5err(path))?;
    for (key, value) in [
        ("length_m", c.geometry.length_m),
        ("diameter_m", c.geometry.diameter_m),
    ] {
        cg.new_attr::<f64>()
            .shape(())
            .create(key)
            .and_then(|a| a.write_scalar(&value))
            .map_err(h5err(path))?;
    }
    string_attr(
        &cg,
        "sign",
        if c.tension {
            "tension positive (stress, strain, strain rate): a tension test; docs/physics.md §7.8.1"
        } else {
            "compression positive (stress, strain, strain rate); docs/physics.md §7.8"
        },
        path,
    )?;
    for (group, a) in cylinder_analyses(c) {
        let ag = cg.create_group(group).map_err(h5err(path))?;
        for (name, data, units, _) in analysis_columns(a) {
            write_dataset(&ag, name, data, units, path)?;
        }
    }
    Ok(())
}

/// Scalar results of a cylinder's reduction, as `/summary` attributes: (key, value, unit).
pub fn cylinder_summary_items(c: &CylinderReduction) -> Vec<(&'static str, f64, &'static str)> {
    vec![
        ("specimen_length", c.geometry.length_m, "m"),
        ("specimen_diameter", c.geometry.diameter_m, "m"),
        ("peak_stress", c.peak_stress_pa, "Pa"),
        ("peak_stress_time", c.peak_time_s, "s"),
        ("strain_at_peak_stress", c.strain_at_peak, "1"),
        ("mean_strain_rate", c.mean_strain_rate_per_s, "1/s"),
    ]
}

/// [`write_reduction_hdf5`] with a cylinder's analyses under `/reduction/cylinder/<analysis>/
/// {stress, strain, strain_rate, true_stress, true_strain}` (`units` attributes; the group has
/// `length_m`, `diameter_m` and `sign` attributes) and its scalars in `/summary`.
pub fn write_reduction_hdf5_with(
    path: &Path,
    force: bool,
    scene: &str,
    r: &Reduction,
    cylinder: Option<&CylinderReduction>,
) -> Result<()> {
    write_atomically(path, force, |tmp| {
        let f = crate::h5::create(tmp).map_err(h5err(path))?;
        string_attr(&f, "shpb_version", env!("CARGO_PKG_VERSION"), path)?;
        string_attr(&f, "scene", scene, path)?;
        let g = f.create_group("reduction").map_err(h5err(path))?;
        for (name, data, units, _) in reduction_columns(r) {
            write_dataset(&g, name, data, units, path)?;
        }
        let mut items = summary_items(r);
        if let Some(c) = cylinder {
            write_cylinder_group(&g, c, path)?;
            items.extend(cylinder_summary_items(c));
        }
        let s = f.create_group("summary").map_err(h5err(path))?;
        for (key, value, _) in &items {
            s.new_attr::<f64>()
                .shape(())
                .create(*key)
                .and_then(|a| a.write_scalar(value))
                .map_err(h5err(path))?;
        }
        let units = items
            .iter()
            .map(|(k, _, u)| format!("{k}={u}"))
            .collect::<Vec<_>>()
            .join(", ");
        string_attr(&s, "units", &units, path)?;
        string_attr(&s, "warnings", &r.warnings.join("\n"), path)?;
        string_attr(&s, "alignment", r.alignment.strategy.name(), path)?;
        string_attr(&s, "equilibrium_verdict", r.quality.verdict.name(), path)?;
        string_attr(
            &s,
            "verdict_reason",
            &shpb_core::reduce::verdict_reason(r),
            path,
        )?;
        string_attr(&s, "filter", &r.filter.describe(), path)?;
        string_attr(&s, "baseline", r.baseline.name(), path)?;
        f.close().map_err(h5err(path))
    })
}

/// Writes the reduction series as CSV (one header line, units in the column names).
pub fn write_reduction_csv(path: &Path, force: bool, r: &Reduction) -> Result<()> {
    write_reduction_csv_with(path, force, r, None)
}

/// [`write_reduction_csv`] with a cylinder's columns after the reduction's:
/// `<analysis>_<series>` (e.g. `one_wave_stress_Pa`, `three_wave_true_strain`).
pub fn write_reduction_csv_with(
    path: &Path,
    force: bool,
    r: &Reduction,
    cylinder: Option<&CylinderReduction>,
) -> Result<()> {
    let mut cols: Vec<(String, &[f64])> = reduction_columns(r)
        .into_iter()
        .map(|c| (c.3.to_string(), c.1))
        .collect();
    if let Some(c) = cylinder {
        for (group, a) in cylinder_analyses(c) {
            for (_, data, _, column) in analysis_columns(a) {
                cols.push((format!("{group}_{column}"), data));
            }
        }
    }
    let mut text = cols
        .iter()
        .map(|c| c.0.as_str())
        .collect::<Vec<_>>()
        .join(",");
    text.push('\n');
    for i in 0..r.time_s.len() {
        let row: Vec<String> = cols.iter().map(|c| format!("{:e}", c.1[i])).collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    write_text_atomically(path, force, &text)
}
