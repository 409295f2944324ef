//! Several records reduced in one command (`shpb reduce A.csv B.csv --summary S.csv --report
//! R.md`): one summary row per record, a Markdown report with one figure per record.

use crate::atomic::write_text_atomically;
use crate::plot::{
    Axes, Curve, Marks, Measure, Span, balance_residual, curve, marked_panels_figure,
    strain_rate_panel, stress_strain_panel, window_panels,
};
use plotters::style::RGBColor;
use shpb_core::reduce::{BarProperties, Reduction, WaveMetrics, verdict_reason, wave_metrics};
use shpb_core::reduce_cylinder::CylinderReduction;
use shpb_input::Result;
use std::fmt::Write as _;
use std::path::Path;

/// One record of a batch: its name and its reduction, or why it could not be reduced.
pub struct BatchRecord<'a> {
    /// The record as given on the command line.
    pub record: String,
    /// The reduction, or the error message.
    pub reduction: std::result::Result<&'a Reduction, String>,
    /// The incident and transmission bars (for the waves' stresses and energies).
    pub bars: Option<(BarProperties, BarProperties)>,
    /// The record's figure, as the report links it (relative to the report).
    pub figure: Option<String>,
    /// A cylinder's 1/2/3-wave reduction, when the record was reduced for a cylinder.
    pub cylinder: Option<&'a CylinderReduction>,
}

/// Metrics of the incident, reflected and transmitted waves at the faces of a reduction.
pub fn wave_table(
    r: &Reduction,
    bars: &(BarProperties, BarProperties),
) -> [Option<WaveMetrics>; 3] {
    [
        wave_metrics(&r.time_s, &r.incident_strain, &bars.0, true),
        wave_metrics(&r.time_s, &r.reflected_strain, &bars.0, false),
        wave_metrics(&r.time_s, &r.transmitted_strain, &bars.1, true),
    ]
}

/// Strain rate at the peak back force and its mean over the loading span (sphere specimens).
fn strain_rates(r: &Reduction) -> (f64, f64) {
    match &r.strain_rate_per_s {
        Some(rate) => {
            let (a, b) = r.quality.loading_span_s;
            let span: Vec<f64> = r
                .time_s
                .iter()
                .zip(rate)
                .filter(|(t, _)| (a..=b).contains(*t))
                .map(|(_, v)| *v)
                .collect();
            let mean = if span.is_empty() {
                f64::NAN
            } else {
                span.iter().sum::<f64>() / span.len() as f64
            };
            (rate[r.peak_index], mean)
        }
        None => (f64::NAN, f64::NAN),
    }
}

/// A CSV field: quoted when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A number for the CSV (empty when unknown).
fn num(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:e}"),
        _ => String::new(),
    }
}

/// Column names of the batch summary (SI units in the names).
pub const SUMMARY_COLUMNS: [&str; 41] = [
    "record",
    "status",
    "alignment",
    "peak_back_force_N",
    "peak_front_force_N",
    "displacement_at_peak_m",
    "strain_rate_at_peak_per_s",
    "mean_strain_rate_loading_per_s",
    "equilibrium_ratio_at_peak",
    "equilibrium_mean_loading",
    "equilibrium_max_loading",
    "equilibrium_verdict",
    "reflected_delay_s",
    "geometric_reflected_delay_s",
    "measured_reflected_delay_s",
    "transmitted_delay_s",
    "measured_transmitted_delay_s",
    "incident_peak_Pa",
    "incident_rise_s",
    "incident_duration_s",
    "incident_energy_J",
    "reflected_peak_Pa",
    "reflected_rise_s",
    "reflected_duration_s",
    "reflected_energy_J",
    "transmitted_peak_Pa",
    "transmitted_rise_s",
    "transmitted_duration_s",
    "transmitted_energy_J",
    "signal_to_noise_incident",
    "signal_to_noise_transmission",
    "pulse_overlap_s",
    "warnings",
    "balance_incident_path_m",
    "balance_transmission_path_m",
    "peak_stress_one_wave_Pa",
    "peak_stress_two_wave_Pa",
    "peak_stress_three_wave_Pa",
    "strain_at_peak_stress_three_wave",
    "mean_strain_rate_per_s",
    "verdict_reason",
];

/// A cylinder record's summary values (docs/physics.md §7.8, engineering, compression positive):
/// the 1-, 2- and 3-wave peak stresses, the 3-wave strain at its peak stress and the 1-wave mean
/// strain rate over the loading ([`CylinderReduction::mean_strain_rate_per_s`]); None for spheres.
fn cylinder_columns(c: Option<&CylinderReduction>) -> [Option<f64>; 5] {
    let Some(c) = c else {
        return [None; 5];
    };
    let peak = |a: &shpb_core::reduce_cylinder::WaveAnalysis| {
        a.stress_pa
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let k = shpb_core::numeric::argmax(&c.three_wave.stress_pa);
    [
        Some(peak(&c.one_wave)),
        Some(peak(&c.two_wave)),
        Some(peak(&c.three_wave)),
        c.three_wave.strain.get(k).copied(),
        Some(c.mean_strain_rate_per_s),
    ]
}

/// The summary CSV text: a header of [`SUMMARY_COLUMNS`], then one row per record.
pub fn summary_csv(records: &[BatchRecord]) -> String {
    let mut text = SUMMARY_COLUMNS.join(",");
    text.push('\n');
    for b in records {
        let mut row = vec![csv_field(&b.record)];
        match &b.reduction {
            Err(e) => {
                row.push(csv_field(&format!("error: {e}")));
                row.extend((2..SUMMARY_COLUMNS.len()).map(|_| String::new()));
            }
            Ok(r) => {
                let (rate_peak, rate_mean) = strain_rates(r);
                let a = &r.alignment;
                let q = &r.quality;
                row.push("ok".into());
                row.push(a.strategy.name().into());
                for v in [
                    r.peak_back_force_n,
                    r.peak_front_force_n,
                    r.displacement_at_peak_force_m,
                    rate_peak,
                    rate_mean,
                    r.equilibrium_ratio_at_peak,
                    q.equilibrium_mean,
                    q.equilibrium_max,
                ] {
                    row.push(num(Some(v)));
                }
                row.push(q.verdict.name().into());
                row.push(num(Some(r.windows.reflected_delay_s)));
                row.push(num(Some(a.geometric_reflected_delay_s)));
                row.push(num(a.measured_reflected_delay_s));
                row.push(num(Some(r.windows.transmitted_delay_s)));
                row.push(num(a.measured_transmitted_delay_s));
                let waves = b.bars.as_ref().map(|bars| wave_table(r, bars));
                for k in 0..3 {
                    let w = waves.as_ref().and_then(|w| w[k]);
                    row.push(num(w.map(|w| w.peak_stress_pa)));
                    row.push(num(w.map(|w| w.rise_10_90_s)));
                    row.push(num(w.map(|w| w.duration_10_s)));
                    row.push(num(w.map(|w| w.energy_j)));
                }
                row.push(num(Some(q.signal_to_noise.0)));
                row.push(num(Some(q.signal_to_noise.1)));
                row.push(num(Some(q.pulse_overlap_s)));
                row.push(csv_field(&r.warnings.join("; ")));
                row.push(num(a.balance_paths_m.map(|p| p.0)));
                row.push(num(a.balance_paths_m.map(|p| p.1)));
                row.extend(cylinder_columns(b.cylinder).map(num));
                row.push(csv_field(&verdict_reason(r)));
            }
        }
        text.push_str(&row.join(","));
        text.push('\n');
    }
    text
}

/// Writes the summary CSV atomically (no clobbering without `force`).
pub fn write_summary(path: &Path, force: bool, records: &[BatchRecord]) -> Result<()> {
    write_text_atomically(path, force, &summary_csv(records))
}

/// A number with `digits` decimals after scaling, or `—` when unknown.
fn cell(v: Option<f64>, scale: f64, digits: usize) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{:.digits$}", v * scale),
        _ => "—".into(),
    }
}

/// The Markdown report: the command, a table of every record, then a section per record with
/// its figure, windows, pulse metrics, quality checks and warnings.
pub fn report_markdown(command: &str, records: &[BatchRecord]) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Reduction of {} records\n", records.len());
    let _ = writeln!(md, "Generated by `{command}`.\n");
    // A tension batch (every reduced record in tension) says so; a mixed one names both.
    let reduced: Vec<&Reduction> = records
        .iter()
        .filter_map(|b| b.reduction.as_ref().ok().copied())
        .collect();
    let tension = reduced.iter().filter(|r| r.tension).count();
    md.push_str(if tension == 0 {
        "Forces are compression positive; "
    } else if tension == reduced.len() {
        "A tension test (split Hopkinson tension bar): forces and stresses are tension positive, \
         δ the elongation; "
    } else {
        "Records reduced in compression have forces compression positive, those in tension \
         (marked in their sections) tension positive; "
    });
    md.push_str(
        "δ is the sphere approach; the equilibrium ratio is \
         |F_front − F_back| / F_3wave, judged over the loading span (25 % of the 3-wave peak to \
         the peak) against 0.05 (Ravichandran & Subhash 1994): *equilibrium* if every sample \
         passes, *marginal* if the mean does, else *not in equilibrium*.\n\n",
    );
    md.push_str(
        "Each record's figure shows, top, the incident and transmission gauges' records \
         (smoothed and debiased, on the record's clock) with the baseline span and the windows \
         the reduction cut (dashed: the geometric start, where the alignment moved a window); \
         then the waves at the faces and the face forces with the loading span; then the \
         balance residual (F_front − F_back)/F_3wave with the ±0.05 equilibrium band and the \
         loading span the verdict judges, and what the specimen makes of the waves. Under each \
         figure one sentence says which alignment placed the windows and why the verdict \
         follows (also the summary's `verdict_reason` column).\n\n",
    );
    md.push_str(
        "| record | peak back force (kN) | peak front force (kN) | δ at peak (µm) | strain rate at peak (1/s) | equilibrium at peak | mean / max over loading | verdict | alignment |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for b in records {
        match &b.reduction {
            Err(e) => {
                let _ = writeln!(
                    md,
                    "| {} | error: {} | | | | | | | |",
                    file_name(&b.record),
                    e
                );
            }
            Ok(r) => {
                let (rate, _) = strain_rates(r);
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {} | {} / {} | {} | {} |",
                    file_name(&b.record),
                    cell(Some(r.peak_back_force_n), 1e-3, 2),
                    cell(Some(r.peak_front_force_n), 1e-3, 2),
                    cell(Some(r.displacement_at_peak_force_m), 1e6, 1),
                    cell(Some(rate), 1.0, 0),
                    cell(Some(r.equilibrium_ratio_at_peak), 1.0, 3),
                    cell(Some(r.quality.equilibrium_mean), 1.0, 3),
                    cell(Some(r.quality.equilibrium_max), 1.0, 3),
                    r.quality.verdict.name(),
                    r.alignment.strategy.name()
                );
            }
        }
    }
    for b in records {
        let _ = writeln!(md, "\n## {}\n", b.record);
        let r = match &b.reduction {
            Err(e) => {
                let _ = writeln!(md, "Not reduced: {e}");
                continue;
            }
            Ok(r) => r,
        };
        if let Some(f) = &b.figure {
            let _ = writeln!(md, "![{}]({})\n", b.record, f);
        }
        let _ = writeln!(md, "**Verdict.** {}\n", capitalised(&verdict_reason(r)));
        let a = &r.alignment;
        let us = |v: Option<f64>| cell(v, 1e6, 2);
        let _ = writeln!(
            md,
            "Windows ({} alignment): incident foot at {} µs on the record clock; reflected +{} µs \
             (geometric {}, record's foot {}); transmitted +{} µs (geometric {}, record's foot \
             {}); {} µs long.{}\n",
            a.strategy.name(),
            us(Some(r.windows.incident_start_s)),
            us(Some(r.windows.reflected_delay_s)),
            us(Some(a.geometric_reflected_delay_s)),
            us(a.measured_reflected_delay_s),
            us(Some(r.windows.transmitted_delay_s)),
            us(Some(a.geometric_transmitted_delay_s)),
            us(a.measured_transmitted_delay_s),
            cell(Some(r.windows.duration_s), 1e6, 1),
            match a.balance_shift_s {
                Some((sr, st)) => format!(
                    " Balance search (±{} µs): reflected shifted {} µs, transmitted {} µs{}{}.",
                    cell(Some(a.balance_bound_s), 1e6, 1),
                    us(Some(sr)),
                    us(Some(st)),
                    if a.at_bound { ", at the bound" } else { "" },
                    a.balance_paths_m.map_or(String::new(), |(pi, pt)| format!(
                        "; as gauge paths, incident {pi:.4} m and transmission {pt:.4} m"
                    ))
                ),
                None => String::new(),
            }
        );
        if let Some(bars) = &b.bars {
            md.push_str(
                "| wave (at the face) | peak (MPa) | rise 10–90 % (µs) | duration at 10 % (µs) | energy (J) |\n\
                 |---|---|---|---|---|\n",
            );
            for (name, w) in ["incident", "reflected", "transmitted"]
                .iter()
                .zip(wave_table(r, bars))
            {
                let _ = writeln!(
                    md,
                    "| {name} | {} | {} | {} | {} |",
                    cell(w.map(|w| w.peak_stress_pa), 1e-6, 1),
                    cell(w.map(|w| w.rise_10_90_s), 1e6, 1),
                    cell(w.map(|w| w.duration_10_s), 1e6, 1),
                    cell(w.map(|w| w.energy_j), 1.0, 3)
                );
            }
            md.push('\n');
        }
        if b.cylinder.is_some() {
            let [one, two, three, strain, rate] = cylinder_columns(b.cylinder);
            let _ = writeln!(
                md,
                "Cylinder (engineering, {}): peak stress {} MPa (1-wave), {} \
                 MPa (2-wave), {} MPa (3-wave); 3-wave strain at its peak stress {}; mean strain \
                 rate {} 1/s.\n",
                if b.reduction.as_ref().is_ok_and(|r| r.tension) {
                    "tension positive"
                } else {
                    "compression positive"
                },
                cell(one, 1e-6, 1),
                cell(two, 1e-6, 1),
                cell(three, 1e-6, 1),
                cell(strain, 1.0, 4),
                cell(rate, 1.0, 0)
            );
        }
        let q = &r.quality;
        let _ = writeln!(
            md,
            "Quality: equilibrium over the loading ({}–{} µs) mean {}, max {}: **{}**; incident \
             pulse {} µs at its gauge, overlap with the reflected one {} µs; signal/noise {} \
             (incident), {} (transmission).\n",
            cell(Some(q.loading_span_s.0), 1e6, 1),
            cell(Some(q.loading_span_s.1), 1e6, 1),
            cell(Some(q.equilibrium_mean), 1.0, 3),
            cell(Some(q.equilibrium_max), 1.0, 3),
            q.verdict.name(),
            cell(Some(q.incident_duration_s), 1e6, 1),
            cell(Some(q.pulse_overlap_s), 1e6, 1),
            cell(Some(q.signal_to_noise.0), 1.0, 0),
            cell(Some(q.signal_to_noise.1), 1.0, 0)
        );
        for w in &r.warnings {
            let _ = writeln!(md, "- warning: {w}");
        }
    }
    md
}

/// Writes the Markdown report atomically (no clobbering without `force`).
pub fn write_report(
    path: &Path,
    force: bool,
    command: &str,
    records: &[BatchRecord],
) -> Result<()> {
    write_text_atomically(path, force, &report_markdown(command, records))
}

/// The two panels of the waves at the faces and the 1/2/3-wave forces, the forces with the
/// loading span the equilibrium verdict judges.
fn face_panels<'a>(
    waves_title: &'a str,
    r: &'a Reduction,
) -> Vec<(Axes<'a>, Vec<Curve<'a>>, Marks)> {
    vec![
        (
            Axes {
                title: waves_title,
                x_label: "time at the faces (µs)",
                // A tension reduction reads the strains turned (docs/physics.md §7.8.1).
                y_label: if r.tension {
                    "bar strain (µε), gauges' sign turned (tension test)"
                } else {
                    "bar strain (µε), tension positive"
                },
                x_scale: 1e6,
                y_scale: 1e6,
            },
            vec![
                curve("incident", &r.time_s, &r.incident_strain),
                curve("reflected", &r.time_s, &r.reflected_strain),
                curve("transmitted", &r.time_s, &r.transmitted_strain),
            ],
            Marks::default(),
        ),
        (
            Axes {
                title: "face forces",
                x_label: "time at the faces (µs)",
                y_label: if r.tension {
                    "force, tension positive (kN)"
                } else {
                    "force, compression positive (kN)"
                },
                x_scale: 1e6,
                y_scale: 1e-3,
            },
            vec![
                curve("front (2-wave)", &r.time_s, &r.force_front_n),
                curve("back (1-wave)", &r.time_s, &r.force_back_n),
                curve("3-wave", &r.time_s, &r.force_3wave_n),
            ],
            Marks {
                spans: vec![Span {
                    label: "loading span (verdict)".into(),
                    from_to: r.quality.loading_span_s,
                    colour: RGBColor(150, 60, 170),
                }],
                ..Marks::default()
            },
        ),
    ]
}

/// The force–approach panel of spheres.
fn force_approach_panel(r: &Reduction) -> (Axes<'_>, Vec<Curve<'_>>, Marks) {
    (
        Axes {
            title: "force against sphere approach",
            x_label: "sphere approach δ (µm)",
            y_label: "force (kN)",
            x_scale: 1e6,
            y_scale: 1e-3,
        },
        vec![
            curve("back", &r.displacement_m, &r.force_back_n),
            curve("front", &r.displacement_m, &r.force_front_n),
        ],
        Marks::default(),
    )
}

/// The figure of one reduction, of `shpb reduce --plot` and of each record of `--report`
/// (atomic; an existing file is kept unless `force`), two panels across: the windows on the
/// incident and transmission gauges' records with their baseline span
/// ([`window_panels`]), the three waves at the faces and the 1/2/3-wave forces, the balance
/// residual (F_front − F_back)/F_3wave with the ±0.05 band and the loading span the verdict
/// judges, then what the specimen makes of the waves (docs/physics.md §7.3, §7.6–§7.8). Spheres:
/// force against approach and, when their radii are known, the global strain rate δ̇/Σrᵢ; a
/// cylinder: its 1/2/3-wave engineering stress against strain and strain rate against time,
/// compression positive.
pub fn record_figure(
    path: &Path,
    force: bool,
    title: &str,
    r: &Reduction,
    cylinder: Option<&CylinderReduction>,
) -> Result<()> {
    let residual = balance_residual(r);
    let waves_title = format!("{title}: waves at the faces");
    let mut windows = window_panels(r, &residual).into_iter();
    let mut panels = Vec::new();
    panels.extend(windows.by_ref().take(2));
    panels.extend(face_panels(&waves_title, r));
    panels.extend(windows);
    let plain = |(axes, curves)| (axes, curves, Marks::default());
    match cylinder {
        Some(c) => {
            let analyses = [
                ("1-wave", &c.one_wave),
                ("2-wave", &c.two_wave),
                ("3-wave", &c.three_wave),
            ];
            panels.push(plain(stress_strain_panel(
                Measure::Engineering,
                c.tension,
                analyses
                    .iter()
                    .map(|(name, a)| curve(name, &a.strain, &a.stress_pa))
                    .collect(),
            )));
            panels.push(plain(strain_rate_panel(
                Measure::Engineering,
                c.tension,
                analyses
                    .iter()
                    .map(|(name, a)| curve(name, &r.time_s, &a.strain_rate_per_s))
                    .collect(),
            )));
        }
        None => {
            panels.push(force_approach_panel(r));
            if let Some(rate) = &r.strain_rate_per_s {
                panels.push((
                    Axes {
                        title: "global strain rate δ̇/Σrᵢ",
                        x_label: "time at the faces (µs)",
                        y_label: "strain rate (1/s)",
                        x_scale: 1e6,
                        y_scale: 1.0,
                    },
                    vec![curve("strain rate", &r.time_s, rate)],
                    Marks::default(),
                ));
            }
        }
    }
    marked_panels_figure(path, force, 2, &panels)
}

/// `s` with its first letter upper-case (a sentence's start).
fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map_or_else(String::new, |f| f.to_uppercase().chain(c).collect())
}

/// The last component of a record's path (the table's record column).
fn file_name(record: &str) -> String {
    Path::new(record)
        .file_name()
        .map_or_else(|| record.to_string(), |n| n.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_with_commas_or_quotes_are_quoted() {
        assert_eq!(csv_field("a.csv"), "a.csv");
        assert_eq!(csv_field("a,b.csv"), "\"a,b.csv\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
    }

    #[test]
    fn a_failed_record_keeps_its_row_with_every_column() {
        let rows = [BatchRecord {
            record: "bad.csv".into(),
            reduction: Err("no incident pulse".into()),
            bars: None,
            figure: None,
            cylinder: None,
        }];
        let text = summary_csv(&rows);
        let line = text.lines().nth(1).unwrap();
        assert!(line.starts_with("bad.csv,error: no incident pulse,"));
        assert_eq!(line.split(',').count(), SUMMARY_COLUMNS.len());
    }
}
