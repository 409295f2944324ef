//! `shpb reduce`: the lab's reduction of raw records or run files, one or a batch.

use super::common::{DEFAULT_BARS, finite, plan, report, require_bars, warn, write_all};
use shpb_core::reduce::{DispersionCorrection, Reduction, ReductionSetup};
use shpb_input::{Error, Result};
use shpb_output::batch::{BatchRecord, record_figure, write_report, write_summary};
use shpb_output::reduction::{write_reduction_csv_with, write_reduction_hdf5_with};
use shpb_study::api::{RecordOptions, Reduced, reduce_record_with};
use std::path::{Path, PathBuf};

/// The files `shpb reduce` may write.
pub struct Outputs<'a> {
    /// `-o`: the reduction as HDF5 (one record only).
    pub output: Option<&'a Path>,
    /// `--csv`: the reduction series as CSV (one record only).
    pub csv: Option<&'a Path>,
    /// `--summary`: one CSV row per record.
    pub summary: Option<&'a Path>,
    /// `--report`: Markdown report, with one figure per record beside it.
    pub report: Option<&'a Path>,
    /// `--plot`: the figure of the reduction (one record only).
    pub plot: Option<&'a Path>,
    /// Overwrite existing files.
    pub force: bool,
}

/// A file's name without its extension (`record` if it has none): figure names and titles.
fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "record".into())
}

/// The figure of record `k` of a report: `<report stem>-<record stem>.png` beside the report
/// (`-<k>` appended when two records share a stem).
fn figure_path(report: &Path, records: &[PathBuf], k: usize) -> PathBuf {
    let own = stem(&records[k]);
    let shared = records.iter().filter(|r| stem(r) == own).count() > 1;
    let name = if shared {
        format!("{}-{}-{}.png", stem(report), own, k + 1)
    } else {
        format!("{}-{}.png", stem(report), own)
    };
    report.with_file_name(name)
}

/// The command line that reproduces this reduction (stored in the outputs).
fn command_line(records: &[PathBuf], bars: &str, o: &Outputs, choices: &RecordOptions) -> String {
    let mut c = String::from("shpb reduce");
    // A record of channel files is named by its first file; its --channel flags give it.
    if choices.channels.is_none() {
        for r in records {
            c.push_str(&format!(" {}", r.display()));
        }
    }
    c.push_str(&format!(" --bars {bars}"));
    for (flag, p) in [
        ("-o", o.output),
        ("--csv", o.csv),
        ("--summary", o.summary),
        ("--report", o.report),
        ("--plot", o.plot),
    ] {
        if let Some(p) = p {
            c.push_str(&format!(" {flag} {}", p.display()));
        }
    }
    c.push_str(&choices.command_flags());
    if o.force {
        c.push_str(" --force");
    }
    c
}

/// `shpb reduce RECORD... [--bars SET-UP] [--specimen S.toml] [-o OUT.h5] [--csv OUT.csv]
/// [--plot OUT.png] [--summary S.csv] [--report R.md] [--align geometric|foot|balance] [--smooth SECONDS] [window overrides]
/// [--force]`: reduces raw records (the authors' CSV) or HDF5 files of `shpb run` (recognised by
/// their signature) with the set-up's bars and gauges, writes `/reduction/*` (HDF5) and/or CSV
/// for one record, a summary and a report for any number, and prints a summary of each. A
/// record that cannot be reduced stops a single reduction; in a batch it gets an error row and
/// the command fails after writing the others.
pub fn reduce_command(
    records: &[PathBuf],
    bars_flag: Option<&Path>,
    o: Outputs,
    choices: &RecordOptions,
) -> Result<()> {
    let bars = bars_flag.unwrap_or(Path::new(DEFAULT_BARS));
    require_bars(bars)?;
    if records.len() > 1 && (o.output.is_some() || o.csv.is_some() || o.plot.is_some()) {
        let flag = if o.output.is_some() {
            "--output"
        } else if o.csv.is_some() {
            "--csv"
        } else {
            "--plot"
        };
        return Err(Error::Input {
            file: "command line".into(),
            key: flag.into(),
            problem: format!("{} records were given, but {flag} holds one reduction", records.len()),
            allowed: "one record with -o/--csv/--plot, or several with --summary FILE.csv and/or --report FILE.md".into(),
        });
    }
    let mut inputs: Vec<PathBuf> = records.to_vec();
    if let Some(set) = &choices.channels {
        inputs.extend(set.files.iter().map(|(_, p)| p.clone()));
    }
    inputs.push(bars.to_path_buf());
    if let Some(s) = &choices.specimen {
        inputs.push(PathBuf::from(&s.source));
    }
    let figures: Vec<PathBuf> = match o.report {
        Some(rep) => (0..records.len())
            .map(|k| figure_path(rep, records, k))
            .collect(),
        None => Vec::new(),
    };
    let mut outputs: Vec<(Option<&Path>, &str, &[&str])> = vec![
        (o.output, "--output", &["h5", "hdf5"][..]),
        (o.csv, "--csv", &["csv"][..]),
        (o.summary, "--summary", &["csv"][..]),
        (o.report, "--report", &["md"][..]),
        (o.plot, "--plot", &["png"][..]),
    ];
    outputs.extend(
        figures
            .iter()
            .map(|f| (Some(f.as_path()), "--report (figure)", &["png"][..])),
    );
    let out_plan = plan(o.force, &outputs)?;
    out_plan.not_inputs(&inputs)?;
    let data_on_stdout = out_plan.to_stdout();

    let mut reduced: Vec<Result<Reduced>> = records
        .iter()
        .map(|r| reduce_record_with(r, bars_flag, choices))
        .collect();
    if records.len() == 1 && reduced[0].is_err() {
        return reduced.pop().expect("one record").map(|_| ());
    }
    let set_up_name = bars_flag.map_or_else(
        || match &reduced[0] {
            Ok(r) => r.apparatus.source.clone(),
            Err(_) => DEFAULT_BARS.to_string(),
        },
        |b| b.display().to_string(),
    );
    let command = command_line(records, &set_up_name, &o, choices);
    write_all(&out_plan, || {
        if let Ok(r) = &reduced[0]
            && records.len() == 1
        {
            if let Some(out) = o.output {
                write_reduction_hdf5_with(
                    out,
                    o.force,
                    &command,
                    &r.reduction,
                    r.cylinder.as_ref(),
                )?;
            }
            if let Some(c) = o.csv {
                write_reduction_csv_with(c, o.force, &r.reduction, r.cylinder.as_ref())?;
            }
            if let Some(p) = o.plot {
                record_figure(
                    p,
                    o.force,
                    &stem(&records[0]),
                    &r.reduction,
                    r.cylinder.as_ref(),
                )?;
            }
        }
        let mut batch = Vec::new();
        for (k, (record, result)) in records.iter().zip(&reduced).enumerate() {
            let figure = match (result, figures.get(k)) {
                (Ok(r), Some(path)) => {
                    record_figure(
                        path,
                        o.force,
                        &stem(record),
                        &r.reduction,
                        r.cylinder.as_ref(),
                    )?;
                    path.file_name().map(|n| n.to_string_lossy().into_owned())
                }
                _ => None,
            };
            batch.push(BatchRecord {
                record: record.display().to_string(),
                reduction: result
                    .as_ref()
                    .map(|r| &r.reduction)
                    .map_err(|e| e.to_string()),
                bars: match result {
                    Ok(r) => ReductionSetup::from_apparatus(&r.apparatus)
                        .ok()
                        .map(|s| (s.incident_bar, s.transmission_bar)),
                    Err(_) => None,
                },
                figure,
                cylinder: result.as_ref().ok().and_then(|r| r.cylinder.as_ref()),
            });
        }
        if let Some(s) = o.summary {
            write_summary(s, o.force, &batch)?;
        }
        if let Some(rep) = o.report {
            write_report(rep, o.force, &command, &batch)?;
        }
        Ok(())
    })?;
    for (record, result) in records.iter().zip(&reduced) {
        if let Ok(r) = result {
            for w in &r.reduction.warnings {
                if records.len() > 1 {
                    warn(&format!("{}: {w}", record.display()));
                } else {
                    warn(w);
                }
            }
        }
    }
    let failed: Vec<&Error> = reduced.iter().filter_map(|r| r.as_ref().err()).collect();
    if !data_on_stdout {
        let text: String = records
            .iter()
            .zip(&reduced)
            .map(|(record, result)| match result {
                Ok(r) => summary_text(record, r),
                Err(e) => format!("record: {}: not reduced: {e}\n", record.display()),
            })
            .collect::<Vec<_>>()
            .join("\n");
        report(&text, || {
            let items: Vec<serde_json::Value> = records
                .iter()
                .zip(&reduced)
                .map(|(record, result)| match result {
                    Ok(r) => summary_json(record, r),
                    Err(e) => serde_json::json!({
                        "record": record.display().to_string(),
                        "error": e.to_string(),
                    }),
                })
                .collect();
            if items.len() == 1 {
                items.into_iter().next().expect("one record")
            } else {
                serde_json::Value::Array(items)
            }
        })?;
    }
    match failed.first() {
        Some(e) if records.len() > 1 => Err(Error::Input {
            file: "command line".into(),
            key: "RECORD".into(),
            problem: format!(
                "{} of {} records could not be reduced (the first: {e})",
                failed.len(),
                records.len()
            ),
            allowed: "records the set-up can reduce (see the summary's status column)".into(),
        }),
        _ => Ok(()),
    }
}

/// The printed summary of one reduction.
fn summary_text(record: &Path, reduced: &Reduced) -> String {
    let Reduced {
        reduction: r,
        apparatus,
        hdf5_input,
        cylinder,
        specimen,
    } = reduced;
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
    let a = &r.alignment;
    let q = &r.quality;
    let us = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{:.2}", v * 1e6));
    let mut text = format!(
        "record: {} ({}); bridges: {}\n\
         windows ({} alignment): incident from {:.2} µs, reflected +{:.2} µs (geometric {}, record's foot {}), transmitted +{:.2} µs (geometric {}, record's foot {}), {:.1} µs long; dispersion correction {}; filter {}\n\
         peak back force {:.1} N at t = {:.2} µs; displacement at peak force {:.2} µm; equilibrium ratio at peak {:.3}\n\
         equilibrium over the loading ({:.1}–{:.1} µs): mean {:.3}, max {:.3}: {}; signal/noise {:.0} (incident), {:.0} (transmission)\n",
        record.display(),
        if *hdf5_input {
            "HDF5 gauge strains"
        } else {
            "raw gauge voltages"
        },
        bridges.join(", "),
        a.strategy.name(),
        r.windows.incident_start_s * 1e6,
        r.windows.reflected_delay_s * 1e6,
        us(Some(a.geometric_reflected_delay_s)),
        us(a.measured_reflected_delay_s),
        r.windows.transmitted_delay_s * 1e6,
        us(Some(a.geometric_transmitted_delay_s)),
        us(a.measured_transmitted_delay_s),
        r.windows.duration_s * 1e6,
        dispersion_summary(r),
        r.filter.describe(),
        r.peak_back_force_n,
        r.peak_back_force_time_s * 1e6,
        r.displacement_at_peak_force_m * 1e6,
        r.equilibrium_ratio_at_peak,
        q.loading_span_s.0 * 1e6,
        q.loading_span_s.1 * 1e6,
        q.equilibrium_mean,
        q.equilibrium_max,
        q.verdict.name(),
        q.signal_to_noise.0,
        q.signal_to_noise.1,
    );
    if let (Some((sr, st)), Some((pi, pt))) = (a.balance_shift_s, a.balance_paths_m) {
        // The set-up's paths as the reduction reads them (inserts included).
        let stated = ReductionSetup::from_apparatus(apparatus).ok();
        text.push_str(&format!(
            "balance: reflected shifted {:+.2} µs, transmitted {:+.2} µs{}: as gauge paths (gauge to face, on the bars' c0), incident {:.4} m and transmission {:.4} m against the set-up's {:.4} m and {:.4} m\n",
            sr * 1e6,
            st * 1e6,
            if a.at_bound { " (at the bound)" } else { "" },
            pi,
            pt,
            stated.as_ref().map_or(f64::NAN, |s| s.incident_gauge_m),
            stated.as_ref().map_or(f64::NAN, |s| s.transmission_gauge_m),
        ));
    }
    if let Some(s) = &r.separation {
        let mm = |d: (f64, Option<f64>)| match d.1 {
            Some(d2) => format!("{:.1} and {:.1} mm", d.0 * 1e3, d2 * 1e3),
            None => format!("{:.1} mm", d.0 * 1e3),
        };
        text.push_str(&format!(
            "wave separation {}: incident gauges {}, transmission gauges {}, {}; {} terms of the series (the noise gain at its singular frequencies)\n",
            s.method.name(),
            mm(s.incident_gauges_m),
            mm(s.transmission_gauges_m),
            if s.exact_mode { "exact first mode" } else { "at c0" },
            s.series_terms
        ));
    }
    if let (Some((r1, r2)), Some(rate)) = (specimen.radii_m(), &r.strain_rate_per_s) {
        text.push_str(&format!(
            "spheres, r1 + r2 = {:.3} mm: peak strain rate δ̇/(r1 + r2) {:.0} 1/s\n",
            (r1 + r2) * 1e3,
            rate.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        ));
    }
    if let Some(c) = cylinder {
        text.push_str(&format!(
            "cylinder {:.3} mm × {:.3} mm (1-wave, {} positive): peak stress {:.2} MPa at t = {:.2} µs; strain at peak {:.4e}; mean strain rate {:.1} 1/s\n",
            c.geometry.length_m * 1e3,
            c.geometry.diameter_m * 1e3,
            if c.tension { "tension" } else { "compression" },
            c.peak_stress_pa * 1e-6,
            c.peak_time_s * 1e6,
            c.strain_at_peak,
            c.mean_strain_rate_per_s
        ));
    }
    text.push_str(&format!(
        "verdict: {}\n",
        shpb_core::reduce::verdict_reason(r)
    ));
    text
}

/// The JSON object of one reduction (`--json`).
fn summary_json(record: &Path, reduced: &Reduced) -> serde_json::Value {
    let r: &Reduction = &reduced.reduction;
    let a = &r.alignment;
    let q = &r.quality;
    let opt = |v: Option<f64>| v.map_or(serde_json::Value::Null, finite);
    let mut json = serde_json::json!({
        "record": record.display().to_string(),
        "set_up": reduced.apparatus.source,
        "input": if reduced.hdf5_input { "hdf5 gauge strains" } else { "raw gauge voltages" },
        "windows_s": {
            "incident_start": finite(r.windows.incident_start_s),
            "reflected_delay": finite(r.windows.reflected_delay_s),
            "transmitted_delay": finite(r.windows.transmitted_delay_s),
            "duration": finite(r.windows.duration_s),
        },
        "alignment": {
            "strategy": a.strategy.name(),
            "geometric_reflected_delay_s": finite(a.geometric_reflected_delay_s),
            "geometric_transmitted_delay_s": finite(a.geometric_transmitted_delay_s),
            "measured_reflected_delay_s": opt(a.measured_reflected_delay_s),
            "measured_transmitted_delay_s": opt(a.measured_transmitted_delay_s),
            "balance_shift_reflected_s": opt(a.balance_shift_s.map(|s| s.0)),
            "balance_shift_transmitted_s": opt(a.balance_shift_s.map(|s| s.1)),
            "balance_incident_path_m": opt(a.balance_paths_m.map(|p| p.0)),
            "balance_transmission_path_m": opt(a.balance_paths_m.map(|p| p.1)),
            "at_bound": a.at_bound,
        },
        "quality": {
            "loading_span_s": [finite(q.loading_span_s.0), finite(q.loading_span_s.1)],
            "equilibrium_mean": finite(q.equilibrium_mean),
            "equilibrium_max": finite(q.equilibrium_max),
            "equilibrium_verdict": q.verdict.name(),
            "incident_duration_s": finite(q.incident_duration_s),
            "pulse_overlap_s": finite(q.pulse_overlap_s),
            "signal_to_noise": [finite(q.signal_to_noise.0), finite(q.signal_to_noise.1)],
        },
        "dispersion_corrected": r.dispersion_corrected,
        "dispersion": r.dispersion.name(),
        "tyas_pope": r.tyas_pope,
        "loading": if r.tension { "tension" } else { "compression" },
        "filter": filter_json(&r.filter),
        "baseline": r.baseline.name(),
        "peak_back_force_N": finite(r.peak_back_force_n),
        "peak_back_force_time_s": finite(r.peak_back_force_time_s),
        "displacement_at_peak_force_m": finite(r.displacement_at_peak_force_m),
        "equilibrium_ratio_at_peak": finite(r.equilibrium_ratio_at_peak),
        "warnings": r.warnings,
        "verdict_reason": shpb_core::reduce::verdict_reason(r),
    });
    if let (Some((r1, r2)), Some(rate)) = (reduced.specimen.radii_m(), &r.strain_rate_per_s) {
        json["spheres"] = serde_json::json!({
            "radii_sum_m": finite(r1 + r2),
            "peak_strain_rate_per_s": finite(rate.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
        });
    }
    json["wave_separation"] = match &r.separation {
        Some(s) => serde_json::json!({
            "method": s.method.name(),
            "incident_gauges_m": [finite(s.incident_gauges_m.0), opt(s.incident_gauges_m.1)],
            "transmission_gauges_m": [finite(s.transmission_gauges_m.0), opt(s.transmission_gauges_m.1)],
            "exact_mode": s.exact_mode,
            "series_terms": s.series_terms,
        }),
        None => serde_json::json!({ "method": "none" }),
    };
    if let Some(c) = &reduced.cylinder {
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
}

/// The filter a reduction applied, with its parameters (`--json`; docs/physics.md §7.12).
fn filter_json(f: &shpb_core::reduce::Filter) -> serde_json::Value {
    use shpb_core::reduce::Filter;
    let opt = |v: Option<f64>| v.map_or(serde_json::Value::Null, finite);
    let mut json = serde_json::json!({ "name": f.name(), "description": f.describe() });
    match *f {
        Filter::None => {}
        Filter::MovingAverage { width_s } => json["width_s"] = opt(width_s),
        Filter::Butterworth { order, cutoff_hz } => {
            json["order"] = order.into();
            json["cutoff_hz"] = opt(cutoff_hz);
            json["zero_phase"] = "forward-backward".into();
        }
        Filter::SavitzkyGolay { window_s, order } => {
            json["window_s"] = finite(window_s);
            json["order"] = order.into();
        }
    }
    json
}

/// The summary's word for the correction used: `off`, `bancroft`, `pochhammer-chree`, with
/// `+ tyas-pope` when the amplitude factors were applied.
fn dispersion_summary(r: &Reduction) -> String {
    match (r.dispersion, r.tyas_pope) {
        (DispersionCorrection::None, _) => "off".to_string(),
        (d, false) => d.name().to_string(),
        (d, true) => format!("{} + tyas-pope", d.name()),
    }
}
