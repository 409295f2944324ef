//! PNG plots with plotters: force–displacement curves (as in the paper's Figs. 2–4).

use crate::atomic::write_atomically;
use plotters::prelude::*;
use shpb_core::reduce_cylinder::{CylinderReduction, WaveAnalysis};
use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_core::solver::SpecimenSeries;
use shpb_input::{Error, Result};
use std::path::Path;

/// One curve of a plot: label, x values, y values, and whether to draw it dashed (measured data).
pub struct Curve<'a> {
    /// Legend label.
    pub label: String,
    /// Abscissae.
    pub x: &'a [f64],
    /// Ordinates.
    pub y: &'a [f64],
    /// Draw as measured data (dashed, dark red) rather than a model line.
    pub measured: bool,
}

const PALETTE: [RGBColor; 5] = [
    RGBColor(230, 140, 20),
    RGBColor(0, 0, 0),
    RGBColor(30, 90, 200),
    RGBColor(40, 150, 60),
    RGBColor(150, 60, 170),
];

/// Title, axis labels and display scale factors of a plot.
pub struct Axes<'a> {
    /// Caption.
    pub title: &'a str,
    /// x-axis label with unit.
    pub x_label: &'a str,
    /// y-axis label with unit.
    pub y_label: &'a str,
    /// Factor applied to x values for display (e.g. 1e3 for m → mm).
    pub x_scale: f64,
    /// Factor applied to y values for display.
    pub y_scale: f64,
}

/// A drawing area of the bitmap backend.
type Area<'b> = DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>;

/// Converts a plotters error into the crate's error for `path`.
fn perr<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> Error + '_ {
    move |e| Error::Io {
        file: path.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// A tick label as a person writes it: at most six significant digits, no float noise
/// (`0.30000000000000004` → `0.3`), no trailing zeros, no `-0`.
pub fn tick(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_nan() { "NaN".into() } else { "0".into() };
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (5 - magnitude).clamp(0, 15) as usize;
    let text = format!("{v:.decimals$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    };
    if text == "-0" { "0".into() } else { text }
}

/// A value label with three significant digits (`12.3`, `0.0456`, `1230`).
pub fn three_digits(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return tick(v);
    }
    let unit = 10f64.powi(v.abs().log10().floor() as i32 - 2);
    tick((v / unit).round() * unit)
}

/// Data range of the scaled curves, padded so a flat curve still has an axis.
fn range(curves: &[Curve], axes: &Axes) -> (f64, f64, f64, f64) {
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for c in curves {
        for (&x, &y) in c.x.iter().zip(c.y) {
            xmax = xmax.max(x * axes.x_scale);
            ymax = ymax.max(y * axes.y_scale);
            xmin = xmin.min(x * axes.x_scale);
            ymin = ymin.min(y * axes.y_scale);
        }
    }
    if xmax <= xmin {
        xmax = xmin + 1.0;
    }
    if ymax <= ymin {
        ymax = ymin + 1.0;
    }
    (xmin, xmax * 1.03, ymin - 0.02 * (ymax - ymin), ymax * 1.08)
}

/// A shaded stretch of a panel's x axis (a window, a baseline, a span the verdict weighs), in
/// the curves' units (before the panel's `x_scale`).
pub struct Span {
    /// Legend label.
    pub label: String,
    /// Start and end, in the curves' x units.
    pub from_to: (f64, f64),
    /// Fill colour (drawn translucent).
    pub colour: RGBColor,
}

/// What a panel marks besides its curves: shaded x spans, dashed vertical lines (label, x in the
/// curves' units, colour) and a shaded horizontal band (label, low, high in the curves' y units).
#[derive(Default)]
pub struct Marks {
    /// Shaded x spans, drawn under the curves.
    pub spans: Vec<Span>,
    /// Dashed vertical lines.
    pub lines: Vec<(String, f64, RGBColor)>,
    /// A shaded horizontal band (e.g. a tolerance).
    pub band: Option<(String, f64, f64)>,
}

/// Draws line curves with axes and a legend into one panel.
fn draw_xy(area: &Area, path: &Path, axes: &Axes, curves: &[Curve]) -> Result<()> {
    draw_xy_marked(area, path, axes, curves, &Marks::default())
}

/// [`draw_xy`] with the spans, lines and band of `marks` under the curves.
fn draw_xy_marked(
    area: &Area,
    path: &Path,
    axes: &Axes,
    curves: &[Curve],
    marks: &Marks,
) -> Result<()> {
    let (xmin, xmax, ymin, ymax) = range(curves, axes);
    let (ymin, ymax) = match &marks.band {
        Some((_, lo, hi)) => (
            ymin.min(lo * axes.y_scale * 1.5),
            ymax.max(hi * axes.y_scale * 1.5),
        ),
        None => (ymin, ymax),
    };
    let mut chart = ChartBuilder::on(area)
        .caption(axes.title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(55)
        .y_label_area_size(75)
        .build_cartesian_2d(xmin..xmax, ymin..ymax)
        .map_err(perr(path))?;
    chart
        .configure_mesh()
        .x_desc(axes.x_label)
        .y_desc(axes.y_label)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 17))
        .draw()
        .map_err(perr(path))?;
    let clip = |x: f64| (x * axes.x_scale).clamp(xmin, xmax);
    for s in &marks.spans {
        let fill = s.colour.mix(0.2).filled();
        let colour = s.colour;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(clip(s.from_to.0), ymin), (clip(s.from_to.1), ymax)],
                fill,
            )))
            .map_err(perr(path))?
            .label(s.label.clone())
            .legend(move |(x, y)| {
                Rectangle::new([(x, y - 6), (x + 20, y + 6)], colour.mix(0.35).filled())
            });
    }
    if let Some((label, lo, hi)) = &marks.band {
        let green = RGBColor(40, 150, 60);
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(xmin, lo * axes.y_scale), (xmax, hi * axes.y_scale)],
                green.mix(0.25).filled(),
            )))
            .map_err(perr(path))?
            .label(label.clone())
            .legend(move |(x, y)| {
                Rectangle::new([(x, y - 6), (x + 20, y + 6)], green.mix(0.4).filled())
            });
    }
    for (label, x, colour) in &marks.lines {
        let colour = *colour;
        chart
            .draw_series(DashedLineSeries::new(
                [(clip(*x), ymin), (clip(*x), ymax)],
                6,
                4,
                colour.stroke_width(2),
            ))
            .map_err(perr(path))?
            .label(label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    for (i, c) in curves.iter().enumerate() {
        let pts: Vec<(f64, f64)> =
            c.x.iter()
                .zip(c.y)
                .map(|(&x, &y)| (x * axes.x_scale, y * axes.y_scale))
                .collect();
        let color = if c.measured {
            RGBColor(140, 20, 20)
        } else {
            PALETTE[i % PALETTE.len()]
        };
        let series = if c.measured {
            chart.draw_series(DashedLineSeries::new(pts, 8, 5, color.stroke_width(3)))
        } else {
            let runs = unreversed_runs(&pts, |p| chart.backend_coord(p));
            chart.draw_series(
                runs.into_iter()
                    .map(|run| PathElement::new(run, color.stroke_width(2))),
            )
        }
        .map_err(perr(path))?;
        series.label(c.label.clone()).legend(move |(x, y)| {
            PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
        });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 17))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(perr(path))?;
    Ok(())
}

/// A polyline cut where it turns back by more than a right angle (on the bitmap, `pixel` of each
/// point), each piece starting where the last ends. Plotters joins the segments of a wide line
/// with miters that grow without bound as a turn nears a reversal, so a curve that doubles back
/// (a stress–strain curve unloading at constant strain, a pulse's sharp edge) would shoot a
/// spike off the panel.
fn unreversed_runs(
    points: &[(f64, f64)],
    pixel: impl Fn(&(f64, f64)) -> (i32, i32),
) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut run: Vec<(f64, f64)> = Vec::new();
    let mut last: Option<(i32, i32)> = None;
    let mut heading: Option<(i64, i64)> = None;
    for p in points {
        let px = pixel(p);
        if let Some(q) = last {
            if q == px {
                continue;
            }
            let d = (i64::from(px.0 - q.0), i64::from(px.1 - q.1));
            if heading.is_some_and(|h| h.0 * d.0 + h.1 * d.1 < 0) {
                let start = run[run.len() - 1];
                runs.push(std::mem::replace(&mut run, vec![start]));
            }
            heading = Some(d);
        }
        run.push(*p);
        last = Some(px);
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

/// Draws curves into a PNG (written atomically), scaled as `axes` says.
pub fn xy_plot(path: &Path, force: bool, axes: &Axes, curves: &[Curve]) -> Result<()> {
    write_atomically(path, force, |tmp| {
        let root = BitMapBackend::new(tmp, (1000, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        draw_xy(&root, path, axes, curves)?;
        root.present().map_err(perr(path))
    })
}

/// A stress field over position and time (a Lagrange x–t diagram): rows of `stress_pa` at
/// `time_s`, columns at `x_m` (positions along the apparatus).
pub struct Field<'a> {
    /// Positions, m.
    pub x_m: &'a [f64],
    /// Times, s.
    pub time_s: &'a [f64],
    /// Stress rows, Pa (tension positive).
    pub stress_pa: &'a [Vec<f64>],
}

/// Diverging colour: compression blue, tension red, zero white.
fn stress_colour(s: f64, scale: f64) -> RGBColor {
    let a = (s / scale).clamp(-1.0, 1.0);
    let fade = |v: f64| (255.0 * (1.0 - v.abs())) as u8;
    if a < 0.0 {
        RGBColor(fade(a), fade(a), 255)
    } else {
        RGBColor(255, fade(a), fade(a))
    }
}

/// A vertical colour bar from `lo` to `hi` labelled `label`, coloured by `colour` (one helper
/// for the stress bar of the bar x–t diagram and the force bar of the chain picture).
fn draw_scale_bar(
    area: &Area,
    path: &Path,
    label: &str,
    (lo, hi): (f64, f64),
    colour: impl Fn(f64) -> RGBColor,
) -> Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin_top(45)
        .margin_bottom(65)
        .margin_right(10)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(perr(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_labels(7)
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(perr(path))?;
    let steps = 100;
    for k in 0..steps {
        let (a, b) = (
            lo + (hi - lo) * k as f64 / steps as f64,
            lo + (hi - lo) * (k + 1) as f64 / steps as f64,
        );
        chart
            .plotting_area()
            .draw(&Rectangle::new(
                [(0.0, a), (1.0, b)],
                colour(0.5 * (a + b)).filled(),
            ))
            .map_err(perr(path))?;
    }
    Ok(())
}

/// Draws x–t fields (several bars side by side) as coloured cells, with a colour bar.
fn draw_field(area: &Area, path: &Path, title: &str, fields: &[Field]) -> Result<()> {
    let (mut xmin, mut xmax, mut tmax) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    let mut magnitudes: Vec<f64> = Vec::new();
    for f in fields {
        for &x in f.x_m {
            xmin = xmin.min(x);
            xmax = xmax.max(x);
        }
        tmax = f.time_s.iter().cloned().fold(tmax, f64::max);
        magnitudes.extend(f.stress_pa.iter().flatten().map(|v| v.abs()));
    }
    // Full colour at the 99.5th percentile, so one hot spot does not wash out the waves.
    magnitudes.sort_by(|a, b| a.total_cmp(b));
    let smax = magnitudes
        .get(magnitudes.len() * 995 / 1000)
        .copied()
        .unwrap_or(1.0);
    if !xmin.is_finite() || xmax <= xmin || tmax <= 0.0 {
        return Ok(());
    }
    let smax = smax.max(1.0);
    let (area, bar_area) = area.split_horizontally(area.dim_in_pixel().0.saturating_sub(130));
    let mut chart = ChartBuilder::on(&area)
        .caption(
            format!("{title} (blue: compression, red: tension)"),
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(75)
        .build_cartesian_2d(xmin * 1e3..xmax * 1e3, 0.0..tmax * 1e6)
        .map_err(perr(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("position along the bars (mm, 0 = specimen)")
        .y_desc("time (µs)")
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 16))
        .draw()
        .map_err(perr(path))?;
    let full_mpa = smax / 1e6;
    draw_scale_bar(
        &bar_area,
        path,
        "stress (MPa)",
        (-full_mpa, full_mpa),
        |v| stress_colour(v, full_mpa),
    )?;
    for f in fields {
        for (k, row) in f.stress_pa.iter().enumerate() {
            let t0 = if k == 0 { 0.0 } else { f.time_s[k - 1] };
            let t1 = f.time_s[k];
            for j in 0..f.x_m.len().saturating_sub(1) {
                let s = 0.5 * (row[j] + row[j + 1]);
                let rect = Rectangle::new(
                    [(f.x_m[j] * 1e3, t0 * 1e6), (f.x_m[j + 1] * 1e3, t1 * 1e6)],
                    stress_colour(s, smax).filled(),
                );
                chart.plotting_area().draw(&rect).map_err(perr(path))?;
            }
        }
    }
    Ok(())
}

/// The figure of a full virtual test: a row of x–y panels (gauge signals, then what the
/// specimen did: force–approach for spheres, stress–strain and strain rate for a cylinder),
/// 800 × 620 pixels each, above the x–t diagram of the bars' stress across the whole width.
pub fn test_figure(
    path: &Path,
    force: bool,
    panels: &[(Axes, Vec<Curve>)],
    fields: &[Field],
) -> Result<()> {
    let columns = panels.len().max(1);
    write_atomically(path, force, |tmp| {
        let root = BitMapBackend::new(tmp, (800 * columns as u32, 1300)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        let (top, bottom) = root.split_vertically(620);
        for (area, (axes, curves)) in top.split_evenly((1, columns)).iter().zip(panels) {
            draw_xy(area, path, axes, curves)?;
        }
        draw_field(
            &bottom,
            path,
            "x–t (Lagrange) diagram of the bar stress",
            fields,
        )?;
        root.present().map_err(perr(path))
    })
}

/// A grid of x–y panels with their [`Marks`] (`columns` across, row by row), 800 × 600 pixels
/// each, in one PNG.
pub fn marked_panels_figure(
    path: &Path,
    force: bool,
    columns: usize,
    panels: &[(Axes, Vec<Curve>, Marks)],
) -> Result<()> {
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns).max(1);
    write_atomically(path, force, |tmp| {
        let root =
            BitMapBackend::new(tmp, (800 * columns as u32, 600 * rows as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        for (area, (axes, curves, marks)) in root.split_evenly((rows, columns)).iter().zip(panels) {
            draw_xy_marked(area, path, axes, curves, marks)?;
        }
        root.present().map_err(perr(path))
    })
}

/// A grid of x–y panels (`columns` across, row by row), 800 × 600 pixels each, in one PNG.
pub fn panels_figure(
    path: &Path,
    force: bool,
    columns: usize,
    panels: &[(Axes, Vec<Curve>)],
) -> Result<()> {
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns).max(1);
    write_atomically(path, force, |tmp| {
        let root =
            BitMapBackend::new(tmp, (800 * columns as u32, 600 * rows as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        for (area, (axes, curves)) in root.split_evenly((rows, columns)).iter().zip(panels) {
            draw_xy(area, path, axes, curves)?;
        }
        root.present().map_err(perr(path))
    })
}

/// Sequential colour (white → dark blue) of `v` within [lo, hi].
fn level_colour(v: f64, lo: f64, hi: f64) -> RGBColor {
    let a = if hi > lo {
        ((v - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.5
    };
    RGBColor(
        (255.0 - 225.0 * a) as u8,
        (255.0 - 165.0 * a) as u8,
        (255.0 - 55.0 * a) as u8,
    )
}

/// One quantity of a two-parameter study as a heat map: cell (i, j) at (x_i, y_j), value
/// `z[i][j]` (NaN cells left blank); the caption gives the colour range.
fn draw_heat_map(
    area: &Area,
    path: &Path,
    labels: (&str, &str, &str),
    x: &[f64],
    y: &[f64],
    z: &[Vec<f64>],
) -> Result<()> {
    let edges = |v: &[f64]| -> Vec<f64> {
        let n = v.len();
        let step = |i: usize| {
            if n > 1 {
                (v[i.min(n - 1)] - v[i.saturating_sub(1).min(n - 2)]).abs()
            } else {
                1.0
            }
        };
        let mut e = vec![v[0] - 0.5 * step(1)];
        for i in 1..n {
            e.push(0.5 * (v[i - 1] + v[i]));
        }
        e.push(v[n - 1] + 0.5 * step(n - 1));
        e
    };
    let (xe, ye) = (edges(x), edges(y));
    let finite: Vec<f64> = z
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (x0, x1) = (xe[0].min(xe[xe.len() - 1]), xe[0].max(xe[xe.len() - 1]));
    let (y0, y1) = (ye[0].min(ye[ye.len() - 1]), ye[0].max(ye[ye.len() - 1]));
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!(
                "{} (white {} → blue {})",
                labels.2,
                three_digits(lo),
                three_digits(hi)
            ),
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(perr(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(labels.0)
        .y_desc(labels.1)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 16))
        .draw()
        .map_err(perr(path))?;
    for i in 0..x.len() {
        for j in 0..y.len() {
            let v = z[i][j];
            if !v.is_finite() {
                continue;
            }
            let rect = Rectangle::new(
                [(xe[i], ye[j]), (xe[i + 1], ye[j + 1])],
                level_colour(v, lo, hi).filled(),
            );
            chart.plotting_area().draw(&rect).map_err(perr(path))?;
            chart
                .plotting_area()
                .draw(&Text::new(
                    three_digits(v),
                    (0.5 * (xe[i] + xe[i + 1]), 0.5 * (ye[j] + ye[j + 1])),
                    ("sans-serif", 12),
                ))
                .map_err(perr(path))?;
        }
    }
    Ok(())
}

/// The summary plot of a study with one or two swept parameters: peak force and peak strain
/// rate against the parameter (lines) or over the two parameters (heat maps). `x` and `y` hold
/// the numeric values of the swept parameters with their axis labels; `force[i][j]` and
/// `rate[i][j]` the results (j = 0 only for one parameter).
pub fn sweep_figure(
    path: &Path,
    force: bool,
    x: (&str, &[f64]),
    y: Option<(&str, &[f64])>,
    force_n: &[Vec<f64>],
    rate_per_s: &[Vec<f64>],
) -> Result<()> {
    write_atomically(path, force, |tmp| {
        let root = BitMapBackend::new(tmp, (1600, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        let (left, right) = root.split_horizontally(800);
        match y {
            None => {
                let f: Vec<f64> = force_n.iter().map(|r| r[0]).collect();
                let r: Vec<f64> = rate_per_s.iter().map(|r| r[0]).collect();
                for (area, title, ylab, data, scale) in [
                    (&left, "peak contact force", "force (kN)", &f, 1e-3),
                    (
                        &right,
                        "peak strain rate (reduced)",
                        "strain rate (1/s)",
                        &r,
                        1.0,
                    ),
                ] {
                    let axes = Axes {
                        title,
                        x_label: x.0,
                        y_label: ylab,
                        x_scale: 1.0,
                        y_scale: scale,
                    };
                    let curves = [Curve {
                        label: title.to_string(),
                        x: x.1,
                        y: data,
                        measured: false,
                    }];
                    draw_xy(area, path, &axes, &curves)?;
                }
            }
            Some((ylab, yv)) => {
                let kn: Vec<Vec<f64>> = force_n
                    .iter()
                    .map(|r| r.iter().map(|v| v * 1e-3).collect())
                    .collect();
                draw_heat_map(
                    &left,
                    path,
                    (x.0, ylab, "peak contact force (kN)"),
                    x.1,
                    yv,
                    &kn,
                )?;
                draw_heat_map(
                    &right,
                    path,
                    (x.0, ylab, "peak strain rate (1/s)"),
                    x.1,
                    yv,
                    rate_per_s,
                )?;
            }
        }
        root.present().map_err(perr(path))
    })
}

/// One panel of [`band_figure`]: a quantity's 5, 50 and 95 % percentiles against time (or
/// another abscissa).
pub struct BandPanel<'a> {
    /// Caption.
    pub title: &'a str,
    /// y-axis label with unit.
    pub y_label: &'a str,
    /// Factor applied to the values for display.
    pub y_scale: f64,
    /// x-axis label with unit.
    pub x_label: &'a str,
    /// Factor applied to the abscissae for display.
    pub x_scale: f64,
    /// Abscissae (time in s, an approach in m).
    pub x: &'a [f64],
    /// The 5, 50 and 95 % percentiles at each time.
    pub p5_p50_p95: [&'a [f64]; 3],
}

/// The bands of a study (`shpb study --plot`): one panel per quantity, its median as a line and
/// its 5 % and 95 % percentiles dashed.
pub fn band_figure(path: &Path, force: bool, panels: &[BandPanel]) -> Result<()> {
    write_atomically(path, force, |tmp| {
        let width = 800 * panels.len().max(1) as u32;
        let root = BitMapBackend::new(tmp, (width, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        let areas = root.split_evenly((1, panels.len().max(1)));
        for (area, p) in areas.iter().zip(panels) {
            let axes = Axes {
                title: p.title,
                x_label: p.x_label,
                y_label: p.y_label,
                x_scale: p.x_scale,
                y_scale: p.y_scale,
            };
            let curves: Vec<Curve> = ["5 %", "median", "95 %"]
                .iter()
                .zip(p.p5_p50_p95)
                .map(|(label, y)| Curve {
                    label: label.to_string(),
                    x: p.x,
                    y,
                    measured: *label != "median",
                })
                .collect();
            draw_xy(area, path, &axes, &curves)?;
        }
        root.present().map_err(perr(path))
    })
}

/// Draws a run: force against displacement for sphere scenes (with the measured curve for
/// force-driven ones), gauge signals as bar stress against time for bar scenes.
pub fn plot_run(path: &Path, force: bool, params: &Params, out: &RunOutput) -> Result<()> {
    let name = Path::new(&params.source)
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let title = format!("{} — {}", params.kind, name);
    if let Some(chain) = &out.chain {
        return chain_figure(path, force, &title, chain);
    }
    if let SceneParams::Pulse {
        apparatus, options, ..
    } = &params.params
    {
        if let Some(contact) = &out.contact {
            let panel = force_approach_panel(contact, out.reduction.as_ref());
            return plot_test(path, force, &title, apparatus, out, vec![panel]);
        }
        if let Some(specimen) = &out.specimen {
            let cylinder = out.cylinder_reduction.as_ref();
            let tension = options.loading.is_tension();
            let reduced_rate =
                cylinder.map_or_else(Vec::new, |c| true_strain_rate(&c.one_wave, tension));
            let panels = cylinder_test_panels(specimen, cylinder, &reduced_rate, tension);
            return plot_test(path, force, &title, apparatus, out, panels);
        }
    }
    if let Some(contact) = &out.contact {
        let mut curves = vec![Curve {
            label: match params.contact_law() {
                Some(law) => format!("shpb ({})", law.name()),
                None => "shpb".to_string(),
            },
            x: &contact.displacement_m,
            y: &contact.force_n,
            measured: false,
        }];
        let shifted: Vec<f64>;
        if let SceneParams::ForceDriven {
            setup,
            measured_displacement_m: Some(d),
        } = &params.params
        {
            shifted = d.iter().map(|x| x - d[0]).collect();
            curves.push(Curve {
                label: "measured (authors' SHPB, offset δ(0) removed)".into(),
                x: &shifted,
                y: &setup.drive.force_n,
                measured: true,
            });
        }
        let axes = Axes {
            title: &title,
            x_label: "sphere approach δ (mm)",
            y_label: "force F (kN)",
            x_scale: 1e3,
            y_scale: 1e-3,
        };
        return xy_plot(path, force, &axes, &curves);
    }
    let e = match &params.params {
        SceneParams::Pulse { apparatus, .. } => apparatus.material.youngs_modulus_pa,
        _ => 1.0,
    };
    let stresses = gauge_stresses(out, e);
    let curves = gauge_curves(out, &stresses);
    let axes = Axes {
        title: &title,
        x_label: "time after impact (µs)",
        y_label: "bar stress at the gauge, compression positive (MPa)",
        x_scale: 1e6,
        y_scale: 1e-6,
    };
    xy_plot(path, force, &axes, &curves)
}

/// Bar stress at each gauge, compression positive (−E ε), Pa.
fn gauge_stresses(out: &RunOutput, e_pa: f64) -> Vec<Vec<f64>> {
    out.gauges
        .iter()
        .map(|g| g.strain.iter().map(|s| -e_pa * s).collect())
        .collect()
}

/// One curve per gauge against the run's time axis.
fn gauge_curves<'a>(out: &'a RunOutput, stresses: &'a [Vec<f64>]) -> Vec<Curve<'a>> {
    let t = out.time_s.as_deref().unwrap_or(&[]);
    out.gauges
        .iter()
        .zip(stresses)
        .map(|(g, s)| Curve {
            label: format!("{} gauge", g.name),
            x: t,
            y: s,
            measured: false,
        })
        .collect()
}

/// The figure of a full virtual test ([`test_figure`]): the gauge signals, then `specimen`'s
/// panels, above the x–t diagram of the bars.
fn plot_test<'a>(
    path: &Path,
    force: bool,
    title: &str,
    apparatus: &shpb_core::apparatus::Apparatus,
    out: &'a RunOutput,
    specimen: Vec<(Axes<'a>, Vec<Curve<'a>>)>,
) -> Result<()> {
    let e = apparatus.material.youngs_modulus_pa;
    let stresses = gauge_stresses(out, e);
    // The incident peak's 90 % band (docs/physics.md §10.6), when the run has one: a box over
    // the peak's ± 15 µs from low to high, its numbers in the legend.
    let band = incident_peak_band(out, &stresses);
    let gauge_title = format!("{title}: gauge signals");
    let gauge_axes = Axes {
        title: &gauge_title,
        x_label: "time after impact (µs)",
        y_label: "bar stress, compression positive (MPa)",
        x_scale: 1e6,
        y_scale: 1e-6,
    };
    let mut gauge_panel = gauge_curves(out, &stresses);
    if let Some((x, y, [lo, hi])) = &band {
        let label = format!(
            "incident peak, 90 % band {:.1}-{:.1} MPa",
            lo * 1e-6,
            hi * 1e-6
        );
        gauge_panel.push(curve(&label, x, y));
    }
    let mut panels = vec![(gauge_axes, gauge_panel)];
    panels.extend(specimen);
    // Positions along the apparatus with the specimen at 0: striker and incident bar to the left.
    let (li, ls) = (apparatus.incident.length_m, apparatus.striker.length_m);
    let shifted: Vec<Vec<f64>> = out
        .bars
        .iter()
        .map(|b| {
            let offset = match b.name.as_str() {
                "striker" => -li - ls,
                "incident" => -li,
                _ => 0.0,
            };
            b.x_m.iter().map(|x| x + offset).collect()
        })
        .collect();
    let fields: Vec<crate::plot::Field> = out
        .bars
        .iter()
        .zip(&shifted)
        .map(|(b, x)| crate::plot::Field {
            x_m: x,
            time_s: &b.time_s,
            stress_pa: &b.stress_pa,
        })
        .collect();
    test_figure(path, force, &panels, &fields)
}

/// The box a run's incident peak band draws on the gauge panel: (times, stresses) of its outline,
/// ± 15 µs about the incident gauge's peak from the band's low to its high, and the band; None
/// without a band or an incident gauge.
#[allow(clippy::type_complexity)]
fn incident_peak_band(
    out: &RunOutput,
    stresses: &[Vec<f64>],
) -> Option<(Vec<f64>, Vec<f64>, [f64; 2])> {
    let band = out
        .summary
        .iter()
        .find(|i| i.key == "incident_peak_stress")?
        .band_90?;
    let k = out.gauges.iter().position(|g| g.name == "incident")?;
    let t = out.time_s.as_deref()?;
    let s = &stresses[k];
    let peak = (0..s.len().min(t.len())).max_by(|&a, &b| s[a].total_cmp(&s[b]))?;
    let (t0, t1) = (t[peak] - 15e-6, t[peak] + 15e-6);
    let [lo, hi] = band;
    Some((vec![t0, t1, t1, t0, t0], vec![lo, lo, hi, hi, lo], band))
}

/// Force against sphere approach: the true contact force and, when the run reduced its gauges,
/// the back force reduced from them (dashed).
fn force_approach_panel<'a>(
    contact: &'a shpb_core::solver::ContactSeries,
    reduction: Option<&'a shpb_core::reduce::Reduction>,
) -> (Axes<'a>, Vec<Curve<'a>>) {
    let mut curves = vec![curve(
        "true contact (simulation)",
        &contact.displacement_m,
        &contact.force_n,
    )];
    if let Some(r) = reduction {
        curves.push(Curve {
            measured: true,
            ..curve(
                "reduced from the gauges (back force)",
                &r.displacement_m,
                &r.force_back_n,
            )
        });
    }
    let axes = Axes {
        title: "force against sphere approach",
        x_label: "sphere approach δ (mm)",
        y_label: "force F (kN)",
        x_scale: 1e3,
        y_scale: 1e-3,
    };
    (axes, curves)
}

/// Which stress and strain a cylinder's panels show: engineering (as the lab reduces them) or
/// true (constant volume, docs/physics.md §7.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Measure {
    /// Engineering stress, strain and strain rate.
    Engineering,
    /// True stress, strain and strain rate.
    True,
}

/// A cylinder's stress–strain panel: `curves` of stress (Pa) against strain, drawn in MPa
/// against %, compression positive (tension positive for a tension test, `tension`,
/// docs/physics.md §7.8.1).
pub(crate) fn stress_strain_panel(
    measure: Measure,
    tension: bool,
    curves: Vec<Curve<'_>>,
) -> (Axes<'_>, Vec<Curve<'_>>) {
    let (title, x_label, y_label) = match (measure, tension) {
        (Measure::Engineering, false) => (
            "cylinder: engineering stress against strain",
            "engineering strain (%), compression positive",
            "engineering stress (MPa), compression positive",
        ),
        (Measure::Engineering, true) => (
            "cylinder: engineering stress against strain",
            "engineering strain (%), tension positive",
            "engineering stress (MPa), tension positive",
        ),
        (Measure::True, false) => (
            "cylinder: true stress against true strain",
            "true strain (%), compression positive",
            "true stress (MPa), compression positive",
        ),
        (Measure::True, true) => (
            "cylinder: true stress against true strain",
            "true strain (%), tension positive",
            "true stress (MPa), tension positive",
        ),
    };
    let axes = Axes {
        title,
        x_label,
        y_label,
        x_scale: 1e2,
        y_scale: 1e-6,
    };
    (axes, curves)
}

/// A cylinder's strain-rate panel, compression positive (tension positive for a tension test):
/// the engineering rate against the time at the faces (µs; `curves` against the reduction's
/// time in s), or the true rate against the true strain (%; `curves` against the true strain,
/// which needs no common clock between the specimen and the reduction).
pub(crate) fn strain_rate_panel(
    measure: Measure,
    tension: bool,
    curves: Vec<Curve<'_>>,
) -> (Axes<'_>, Vec<Curve<'_>>) {
    let axes = match (measure, tension) {
        (Measure::Engineering, false) => Axes {
            title: "cylinder: engineering strain rate",
            x_label: "time at the faces (µs)",
            y_label: "strain rate (1/s), compression positive",
            x_scale: 1e6,
            y_scale: 1.0,
        },
        (Measure::Engineering, true) => Axes {
            title: "cylinder: engineering strain rate",
            x_label: "time at the faces (µs)",
            y_label: "strain rate (1/s), tension positive",
            x_scale: 1e6,
            y_scale: 1.0,
        },
        (Measure::True, false) => Axes {
            title: "cylinder: true strain rate against true strain",
            x_label: "true strain (%), compression positive",
            y_label: "true strain rate (1/s), compression positive",
            x_scale: 1e2,
            y_scale: 1.0,
        },
        (Measure::True, true) => Axes {
            title: "cylinder: true strain rate against true strain",
            x_label: "true strain (%), tension positive",
            y_label: "true strain rate (1/s), tension positive",
            x_scale: 1e2,
            y_scale: 1.0,
        },
    };
    (axes, curves)
}

/// The true strain rate of a reduced analysis, d/dt[−ln(1 − ε)] = ε̇/(1 − ε), 1/s; in tension
/// (`tension`, docs/physics.md §7.8.1) d/dt[ln(1 + ε)] = ε̇/(1 + ε).
pub(crate) fn true_strain_rate(a: &WaveAnalysis, tension: bool) -> Vec<f64> {
    a.strain_rate_per_s
        .iter()
        .zip(&a.strain)
        .map(|(rate, e)| {
            if tension {
                rate / (1.0 + e)
            } else {
                rate / (1.0 - e)
            }
        })
        .collect()
}

/// A cylinder test's own panels: true stress against true strain, the specimen's (simulation)
/// beside the lab's 1-wave (dashed) and 3-wave reductions, and the true strain rate against the
/// true strain, the specimen's beside the 1-wave one (`reduced_rate`, from [`true_strain_rate`]).
fn cylinder_test_panels<'a>(
    s: &'a SpecimenSeries,
    c: Option<&'a CylinderReduction>,
    reduced_rate: &'a [f64],
    tension: bool,
) -> Vec<(Axes<'a>, Vec<Curve<'a>>)> {
    let own = "true (specimen, simulation)";
    let mut stress = vec![curve(own, &s.true_strain, &s.face_stress_pa)];
    let mut rate = vec![curve(own, &s.true_strain, &s.true_strain_rate_per_s)];
    if let Some(c) = c {
        let (one, three) = (&c.one_wave, &c.three_wave);
        stress.push(Curve {
            measured: true,
            ..curve(
                "1-wave reduction of the gauges",
                &one.true_strain,
                &one.true_stress_pa,
            )
        });
        stress.push(curve(
            "3-wave reduction of the gauges",
            &three.true_strain,
            &three.true_stress_pa,
        ));
        rate.push(Curve {
            measured: true,
            ..curve(
                "1-wave reduction of the gauges",
                &one.true_strain,
                reduced_rate,
            )
        });
    }
    vec![
        stress_strain_panel(Measure::True, tension, stress),
        strain_rate_panel(Measure::True, tension, rate),
    ]
}

/// A model-line curve (solid, in the palette's colour of its place).
pub(crate) fn curve<'a>(label: &str, x: &'a [f64], y: &'a [f64]) -> Curve<'a> {
    Curve {
        label: label.into(),
        x,
        y,
        measured: false,
    }
}

/// Rows of the x–t picture of a chain at most: longer series are binned in time, each cell
/// showing the largest force of its bin (so no peak is lost).
const CHAIN_PICTURE_ROWS: usize = 600;

/// The figure of a chain run: the x–t picture of the contact forces along the chain (contact
/// index against time, colour = force, with its colour bar) and the velocities of the first,
/// middle and last spheres.
pub fn chain_figure(
    path: &Path,
    force: bool,
    title: &str,
    chain: &shpb_core::run::ChainSeries,
) -> Result<()> {
    let t = &chain.time_s;
    let nt = t.len();
    let nc = chain.contact_force_n.len();
    let bin = nt.div_ceil(CHAIN_PICTURE_ROWS).max(1);
    let fmax = chain
        .contact_force_n
        .iter()
        .flatten()
        .fold(0.0f64, |a, &f| a.max(f))
        .max(1e-9);
    let tmax = t.last().copied().unwrap_or(0.0).max(1e-12);
    write_atomically(path, force, |tmp| {
        let root = BitMapBackend::new(tmp, (1700, 800)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        let (left, right) = root.split_horizontally(1000);
        let (field, bar) = left.split_horizontally(870);
        let mut c = ChartBuilder::on(&field)
            .caption(
                format!("{title}: contact forces along the chain"),
                ("sans-serif", 20),
            )
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(75)
            .build_cartesian_2d(0.5..nc as f64 + 0.5, 0.0..tmax * 1e6)
            .map_err(perr(path))?;
        c.configure_mesh()
            .disable_mesh()
            .x_desc("contact k (between spheres k and k + 1)")
            .y_desc("time (µs)")
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .label_style(("sans-serif", 16))
            .draw()
            .map_err(perr(path))?;
        let kn = fmax * 1e-3;
        draw_scale_bar(&bar, path, "contact force (kN)", (0.0, kn), |v| {
            level_colour(v, 0.0, kn)
        })?;
        for (k, row) in chain.contact_force_n.iter().enumerate() {
            let mut i = 0;
            while i < nt {
                let j = (i + bin).min(nt);
                let f = row[i..j].iter().fold(0.0f64, |a, &f| a.max(f));
                let t0 = if i == 0 { 0.0 } else { t[i - 1] };
                let x = (k + 1) as f64;
                c.plotting_area()
                    .draw(&Rectangle::new(
                        [(x - 0.5, t0 * 1e6), (x + 0.5, t[j - 1] * 1e6)],
                        level_colour(f * 1e-3, 0.0, fmax * 1e-3).filled(),
                    ))
                    .map_err(perr(path))?;
                i = j;
            }
        }
        let n = chain.velocity_m_s.len();
        let mut picks = vec![0, n / 2, n - 1];
        picks.dedup();
        let curves: Vec<Curve> = picks
            .iter()
            .map(|&k| Curve {
                label: format!("sphere {}", k + 1),
                x: t,
                y: &chain.velocity_m_s[k],
                measured: false,
            })
            .collect();
        let axes = Axes {
            title: "sphere velocities",
            x_label: "time (µs)",
            y_label: "velocity (m/s)",
            x_scale: 1e6,
            y_scale: 1.0,
        };
        draw_xy(&right, path, &axes, &curves)?;
        root.present().map_err(perr(path))
    })
}

/// One line of a [`loglog_plot`]: points (x, y > 0) and an RGB colour.
#[derive(Debug, Clone)]
pub struct LogLine<'a> {
    /// Legend label.
    pub label: &'a str,
    /// The points.
    pub points: Vec<(f64, f64)>,
    /// Colour.
    pub rgb: (u8, u8, u8),
}

/// Draws lines with markers on log–log axes (e.g. error against run time).
pub fn loglog_plot(
    path: &Path,
    force: bool,
    title: &str,
    (x_label, y_label): (&str, &str),
    lines: &[LogLine],
) -> Result<()> {
    use plotters::prelude::*;
    let perr = |e: &dyn std::fmt::Display| Error::Io {
        file: path.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    };
    let all: Vec<(f64, f64)> = lines.iter().flat_map(|l| l.points.clone()).collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in &all {
        (x0, x1, y0, y1) = (x0.min(*x), x1.max(*x), y0.min(*y), y1.max(*y));
    }
    if all.is_empty() {
        (x0, x1, y0, y1) = (1e-3, 1.0, 1e-9, 1.0);
    }
    write_atomically(path, force, |tmp| {
        let root = BitMapBackend::new(tmp, (1000, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| perr(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(85)
            .build_cartesian_2d(
                ((x0 / 1.5)..(x1 * 1.5)).log_scale(),
                ((y0 / 3.0)..(y1 * 3.0)).log_scale(),
            )
            .map_err(|e| perr(&e))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .label_style(("sans-serif", 17))
            .draw()
            .map_err(|e| perr(&e))?;
        for line in lines {
            let color = RGBColor(line.rgb.0, line.rgb.1, line.rgb.2);
            chart
                .draw_series(LineSeries::new(line.points.clone(), color.stroke_width(2)))
                .map_err(|e| perr(&e))?
                .label(line.label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
                });
            chart
                .draw_series(
                    line.points
                        .iter()
                        .map(|q| Circle::new(*q, 4, color.filled())),
                )
                .map_err(|e| perr(&e))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 17))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| perr(&e))?;
        root.present().map_err(|e| perr(&e))
    })
}

/// The balance residual a reduction's verdict weighs, signed: (F_front − F_back) / F_3wave with
/// the equilibrium ratio's floor (docs/physics.md §7.7), shown within ±1.
pub fn balance_residual(r: &shpb_core::reduce::Reduction) -> Vec<f64> {
    r.equilibrium_ratio
        .iter()
        .zip(r.force_front_n.iter().zip(&r.force_back_n))
        .map(|(q, (f, b))| (q * (f - b).signum()).clamp(-1.0, 1.0))
        .collect()
}

/// Colours of the windows on the records: baseline, incident, reflected, transmitted, loading.
const WINDOW_COLOURS: [RGBColor; 5] = [
    RGBColor(120, 120, 120),
    RGBColor(230, 140, 20),
    RGBColor(30, 90, 200),
    RGBColor(40, 150, 60),
    RGBColor(150, 60, 170),
];

/// The panels that let a person check a reduction's windows (docs/physics.md §7.3, §7.6–§7.7):
/// the incident gauge's record with the baseline span and the incident and reflected windows,
/// the transmission gauge's with the baseline span and the transmitted window (the geometric
/// starts dashed where the alignment moved a window), and the balance residual
/// (`residual`, from [`balance_residual`]) with the ±0.05 equilibrium band and the loading span
/// the verdict judges.
pub fn window_panels<'a>(
    r: &'a shpb_core::reduce::Reduction,
    residual: &'a [f64],
) -> Vec<(Axes<'static>, Vec<Curve<'a>>, Marks)> {
    let rec = &r.record;
    let w = &r.windows;
    let t0 = rec.time_s.first().copied().unwrap_or(0.0);
    let dt = if rec.time_s.len() > 1 {
        rec.time_s[1] - t0
    } else {
        1.0
    };
    let ts = w.incident_start_s;
    let span = |delay: f64| (ts + delay, ts + delay + w.duration_s);
    // The records from their start (the baseline) to a tenth of the shown time past the last
    // window's end.
    let last_end = ts + w.reflected_delay_s.max(w.transmitted_delay_s) + w.duration_s;
    let shown_end = last_end + 0.1 * (last_end - t0);
    let n = rec
        .time_s
        .iter()
        .take_while(|&&t| t <= shown_end)
        .count()
        .max(2)
        .min(rec.time_s.len());
    let baseline = || Span {
        label: format!("baseline ({} samples)", w.baseline_samples),
        from_to: (t0, t0 + w.baseline_samples.saturating_sub(1) as f64 * dt),
        colour: WINDOW_COLOURS[0],
    };
    let window = |label: &str, delay: f64, colour: RGBColor| Span {
        label: format!("{label} window"),
        from_to: span(delay),
        colour,
    };
    let geometric_line = |label: &str, used: f64, geometric: f64| {
        ((used - geometric).abs() > 0.5 * dt).then(|| {
            (
                format!("geometric {label} start"),
                ts + geometric,
                RGBColor(0, 0, 0),
            )
        })
    };
    let record_axes = |title: &'static str| Axes {
        title,
        x_label: "time on the record's clock (µs)",
        y_label: "gauge strain (µε), tension positive",
        x_scale: 1e6,
        y_scale: 1e6,
    };
    let loading = Span {
        label: "loading span (verdict)".into(),
        from_to: r.quality.loading_span_s,
        colour: WINDOW_COLOURS[4],
    };
    vec![
        (
            record_axes("incident gauge: baseline, incident and reflected windows"),
            vec![curve(
                "incident gauge",
                &rec.time_s[..n],
                &rec.incident_strain[..n],
            )],
            Marks {
                spans: vec![
                    baseline(),
                    window("incident", 0.0, WINDOW_COLOURS[1]),
                    window("reflected", w.reflected_delay_s, WINDOW_COLOURS[2]),
                ],
                lines: geometric_line(
                    "reflected",
                    w.reflected_delay_s,
                    r.alignment.geometric_reflected_delay_s,
                )
                .into_iter()
                .collect(),
                band: None,
            },
        ),
        (
            record_axes("transmission gauge: baseline and transmitted window"),
            vec![curve(
                "transmission gauge",
                &rec.time_s[..n],
                &rec.transmission_strain[..n],
            )],
            Marks {
                spans: vec![
                    baseline(),
                    window("transmitted", w.transmitted_delay_s, WINDOW_COLOURS[3]),
                ],
                lines: geometric_line(
                    "transmitted",
                    w.transmitted_delay_s,
                    r.alignment.geometric_transmitted_delay_s,
                )
                .into_iter()
                .collect(),
                band: None,
            },
        ),
        (
            Axes {
                title: "balance residual (F_front − F_back) / F_3wave (within ±1)",
                x_label: "time at the faces (µs)",
                y_label: "residual",
                x_scale: 1e6,
                y_scale: 1.0,
            },
            vec![curve("residual", &r.time_s, residual)],
            Marks {
                spans: vec![loading],
                lines: Vec::new(),
                band: Some((
                    format!(
                        "equilibrium band ±{}",
                        shpb_core::reduce::quality::EQUILIBRIUM_TOLERANCE
                    ),
                    -shpb_core::reduce::quality::EQUILIBRIUM_TOLERANCE,
                    shpb_core::reduce::quality::EQUILIBRIUM_TOLERANCE,
                )),
            },
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_read_as_a_person_writes_them() {
        assert_eq!(tick(0.1 + 0.2), "0.3");
        assert_eq!(tick(-0.0), "0");
        assert_eq!(tick(250.0), "250");
        assert_eq!(tick(1.5e-7), "0.00000015");
        assert_eq!(tick(123456.0), "123456");
        assert_eq!(three_digits(12.3456), "12.3");
        assert_eq!(three_digits(0.045678), "0.0457");
        assert_eq!(three_digits(1234.5), "1230");
        assert_eq!(three_digits(-7.0), "-7");
    }

    #[test]
    fn a_polyline_is_cut_where_it_turns_back() {
        let px = |p: &(f64, f64)| (p.0 as i32, p.1 as i32);
        // Up, a right-angle turn (kept), a repeated pixel (skipped), then back down.
        let pts = [
            (0.0, 0.0),
            (10.0, 0.0),
            (10.0, 10.0),
            (10.2, 10.4),
            (9.0, 0.0),
        ];
        let runs = unreversed_runs(&pts, px);
        assert_eq!(
            runs,
            vec![
                vec![(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)],
                vec![(10.0, 10.0), (9.0, 0.0)]
            ]
        );
        assert_eq!(unreversed_runs(&[], px), Vec::<Vec<(f64, f64)>>::new());
    }

    #[test]
    fn the_x_t_diagram_has_a_colour_bar_from_compression_to_tension() {
        let dir = tempfile::TempDir::new().unwrap();
        let path = dir.path().join("xt.png");
        let x: Vec<f64> = (0..50).map(|i| i as f64 * 0.01).collect();
        let t: Vec<f64> = (1..=40).map(|k| k as f64 * 1e-6).collect();
        let rows: Vec<Vec<f64>> = t
            .iter()
            .map(|&tk| {
                x.iter()
                    .map(|&xi| 1e8 * ((xi - 3e4 * tk) * 20.0).sin())
                    .collect()
            })
            .collect();
        let field = Field {
            x_m: &x,
            time_s: &t,
            stress_pa: &rows,
        };
        let panel = || {
            let axes = Axes {
                title: "t",
                x_label: "x",
                y_label: "y",
                x_scale: 1.0,
                y_scale: 1.0,
            };
            (axes, vec![curve("c", &x, &x)])
        };
        let panels = [panel(), panel()];
        test_figure(&path, false, &panels, &[field]).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        // The colour bar sits in the last 130 px of the bottom panel: its column holds
        // saturated blue (compression) and saturated red (tension).
        let (w, h) = img.dimensions();
        let column: Vec<[u8; 3]> = (620..h).map(|y| img.get_pixel(w - 60, y).0).collect();
        assert!(column.iter().any(|p| p[2] == 255 && p[0] < 40), "no blue");
        assert!(column.iter().any(|p| p[0] == 255 && p[2] < 40), "no red");
    }
}

/// The display scale and unit text of an axis in engineering notation (a power of 1000): an SI
/// prefix for the units that take one (`1.9e9 Pa` → × 1e-9, `GPa`); for the others the numbers
/// as they are from 0.01 to 10⁴ (`0.035`, `250 m/s`), the power written out beyond
/// (`0.00035 1/s` → × 1e6, `×1e-6 1/s`); `max_abs` is the largest magnitude shown.
pub fn engineering_axis(max_abs: f64, unit: &str) -> (f64, String) {
    let unit = if unit == "1" { "" } else { unit };
    let power = if max_abs.is_finite() && max_abs > 0.0 {
        ((max_abs.log10() / 3.0).floor() as i32 * 3).clamp(-15, 12)
    } else {
        0
    };
    let prefix = match power {
        -15 => "f",
        -12 => "p",
        -9 => "n",
        -6 => "µ",
        -3 => "m",
        3 => "k",
        6 => "M",
        9 => "G",
        12 => "T",
        _ => "",
    };
    if matches!(unit, "s" | "m" | "Pa" | "N" | "J" | "V" | "Hz") {
        (10f64.powi(-power), format!("{prefix}{unit}"))
    } else if (1e-2..1e4).contains(&max_abs) || power == 0 {
        (1.0, unit.to_string())
    } else {
        let text = format!("×1e{power} {unit}").trim_end().to_string();
        (10f64.powi(-power), text)
    }
}

/// An axis label `name (unit)`, or `name` alone without a unit.
fn with_unit(name: &str, unit: &str) -> String {
    if unit.is_empty() {
        name.to_string()
    } else {
        format!("{name} ({unit})")
    }
}

/// The smallest and largest finite value of `values` (None when there is none), widened by
/// `pad` of the span on each side (a flat set gets a span of its own).
fn finite_range(values: impl IntoIterator<Item = f64>, pad: f64) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        return None;
    }
    let span = if hi > lo {
        hi - lo
    } else if lo != 0.0 {
        lo.abs()
    } else {
        1.0
    };
    Some((lo - pad * span, hi + pad * span))
}

/// One variable of a [`corner_plot`]: its name and unit, its samples (one per draw, the same
/// number for every variable) and what to mark on it.
pub struct CornerVariable<'a> {
    /// Axis name (without the unit).
    pub name: String,
    /// SI unit (`Pa`, `1`).
    pub unit: String,
    /// The samples, one per draw.
    pub samples: &'a [f64],
    /// A value marked by a line on the histogram and a cross on the scatters (a best fit).
    pub best: Option<f64>,
    /// An interval shaded on the histogram (a 90 % band).
    pub band: Option<(f64, f64)>,
}

/// The colours of a corner plot: histogram, band, best value, scatter points.
const CORNER_COLOURS: [RGBColor; 4] = [
    RGBColor(30, 90, 200),
    RGBColor(40, 150, 60),
    RGBColor(200, 30, 30),
    RGBColor(20, 20, 20),
];

/// A corner plot (Foreman-Mackey, JOSS 1, 24 (2016)) of samples of several variables: each
/// variable's histogram on the diagonal (its band shaded, its best value a dashed line), the
/// pairwise scatter below it (at most `max_points` points, thinned evenly, the best values a
/// cross) and, above it, the correlation `correlations[i][j]` when given. Axes in engineering
/// notation ([`engineering_axis`]); 400 × 400 pixels a cell (800 for one variable); PNG written
/// atomically. Non-finite samples and marks are left out.
pub fn corner_plot(
    path: &Path,
    force: bool,
    title: &str,
    variables: &[CornerVariable],
    correlations: Option<&[Vec<f64>]>,
    max_points: usize,
) -> Result<()> {
    let p = variables.len().max(1);
    // 400 pixels a cell, 800 across at least (room for the title).
    let cell = (800 / p as u32).max(400);
    // Each variable's display range, scale and label.
    let axes: Vec<((f64, f64), f64, String)> = variables
        .iter()
        .map(|v| {
            let marked = v
                .best
                .into_iter()
                .chain(v.band.into_iter().flat_map(|(a, b)| [a, b]));
            let (lo, hi) =
                finite_range(v.samples.iter().copied().chain(marked), 0.05).unwrap_or((0.0, 1.0));
            let (scale, unit) = engineering_axis(lo.abs().max(hi.abs()), &v.unit);
            ((lo * scale, hi * scale), scale, with_unit(&v.name, &unit))
        })
        .collect();
    let stride = variables
        .first()
        .map_or(1, |v| v.samples.len().div_ceil(max_points.max(1)).max(1));
    write_atomically(path, force, |tmp| {
        let root =
            BitMapBackend::new(tmp, (cell * p as u32, cell * p as u32 + 40)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        let body = root.titled(title, ("sans-serif", 24)).map_err(perr(path))?;
        let cells = body.split_evenly((p, p));
        for (i, vi) in variables.iter().enumerate() {
            for (j, vj) in variables.iter().enumerate() {
                let area = &cells[i * p + j];
                if j > i {
                    if let Some(r) = correlations.and_then(|c| c.get(i)?.get(j).copied()) {
                        let text = format!("correlation {}", tick((r * 100.0).round() / 100.0));
                        let middle = cell as i32 / 2;
                        area.draw(&Text::new(text, (middle - 90, middle), ("sans-serif", 22)))
                            .map_err(perr(path))?;
                    }
                } else if i == j {
                    corner_histogram(area, path, vi, &axes[i])?;
                } else {
                    corner_scatter(area, path, (vj, &axes[j]), (vi, &axes[i]), stride)?;
                }
            }
        }
        root.present().map_err(perr(path))
    })
}

/// The diagonal cell of a [`corner_plot`]: the histogram of one variable's samples (√n bins,
/// 10 to 40), its band shaded and its best value dashed, captioned with both.
fn corner_histogram(
    area: &Area,
    path: &Path,
    v: &CornerVariable,
    axis: &((f64, f64), f64, String),
) -> Result<()> {
    let ((lo, hi), scale, label) = axis;
    let values: Vec<f64> = v
        .samples
        .iter()
        .map(|s| s * scale)
        .filter(|s| s.is_finite())
        .collect();
    let bins = ((values.len() as f64).sqrt() as usize).clamp(10, 40);
    let width = (hi - lo) / bins as f64;
    let mut counts = vec![0usize; bins];
    for s in &values {
        let k = ((s - lo) / width).floor();
        if k >= 0.0 && (k as usize) < bins {
            counts[k as usize] += 1;
        }
    }
    let top = counts.iter().copied().max().unwrap_or(0).max(1) as f64 * 1.1;
    let unit = if v.unit == "1" { "" } else { v.unit.as_str() };
    let si = |x: f64| shpb_core::error::format_si(x, unit);
    let mut caption = match v.best.filter(|b| b.is_finite()) {
        Some(b) => format!("best {}", si(b)),
        None => String::new(),
    };
    if let Some((a, b)) = v.band.filter(|(a, b)| a.is_finite() && b.is_finite()) {
        caption = format!("{caption}, 90 %: {} to {}", si(a), si(b));
    }
    if values.is_empty() {
        caption = format!("{caption} (no samples)");
    }
    let mut chart = ChartBuilder::on(area)
        .caption(caption.trim_start_matches(", "), ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(50)
        .y_label_area_size(60)
        .build_cartesian_2d(*lo..*hi, 0.0..top)
        .map_err(perr(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(label.as_str())
        .y_desc("samples")
        .x_labels(5)
        .x_label_formatter(&|x| tick(*x))
        .y_label_formatter(&|y| tick(*y))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(perr(path))?;
    let [blue, green, red, _] = CORNER_COLOURS;
    if let Some((a, b)) = v.band.filter(|(a, b)| a.is_finite() && b.is_finite()) {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(a * scale, 0.0), (b * scale, top)],
                green.mix(0.2).filled(),
            )))
            .map_err(perr(path))?;
    }
    chart
        .draw_series(counts.iter().enumerate().map(|(k, &c)| {
            let x0 = lo + k as f64 * width;
            Rectangle::new([(x0, 0.0), (x0 + width, c as f64)], blue.mix(0.6).filled())
        }))
        .map_err(perr(path))?;
    if let Some(b) = v.best.filter(|b| b.is_finite()) {
        chart
            .draw_series(DashedLineSeries::new(
                [(b * scale, 0.0), (b * scale, top)],
                6,
                4,
                red.stroke_width(2),
            ))
            .map_err(perr(path))?;
    }
    Ok(())
}

/// A cell below the diagonal of a [`corner_plot`]: the samples of `y` against those of `x`
/// (every `stride`-th), the best values a cross.
fn corner_scatter(
    area: &Area,
    path: &Path,
    (x, x_axis): (&CornerVariable, &((f64, f64), f64, String)),
    (y, y_axis): (&CornerVariable, &((f64, f64), f64, String)),
    stride: usize,
) -> Result<()> {
    let (((x0, x1), xs, xl), ((y0, y1), ys, yl)) = (x_axis, y_axis);
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(50)
        .y_label_area_size(60)
        .build_cartesian_2d(*x0..*x1, *y0..*y1)
        .map_err(perr(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(xl.as_str())
        .y_desc(yl.as_str())
        .x_labels(5)
        .y_labels(5)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(perr(path))?;
    let [_, _, red, ink] = CORNER_COLOURS;
    chart
        .draw_series(
            x.samples
                .iter()
                .zip(y.samples)
                .step_by(stride)
                .map(|(a, b)| (a * xs, b * ys))
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .map(|p| Circle::new(p, 1, ink.mix(0.35).filled())),
        )
        .map_err(perr(path))?;
    if let (Some(a), Some(b)) = (x.best, y.best)
        && a.is_finite()
        && b.is_finite()
    {
        chart
            .draw_series(std::iter::once(Cross::new(
                (a * xs, b * ys),
                8,
                red.stroke_width(3),
            )))
            .map_err(perr(path))?;
    }
    Ok(())
}

/// One panel of [`band_panels_figure`]: measured points, a model's line and a shaded band
/// around it (all on the same abscissae), in SI units with their names and units.
pub struct BandedPanel<'a> {
    /// Caption.
    pub title: String,
    /// x-axis name and SI unit.
    pub x_name_unit: (&'a str, &'a str),
    /// y-axis name and SI unit.
    pub y_name_unit: (&'a str, &'a str),
    /// Abscissae.
    pub x: &'a [f64],
    /// The measured points: legend label and ordinates.
    pub points: (String, &'a [f64]),
    /// The model's line: legend label and ordinates.
    pub line: (String, &'a [f64]),
    /// The band: legend label, lower and upper edges (empty edges: no band).
    pub band: (String, &'a [f64], &'a [f64]),
}

/// The most points of a [`BandedPanel`] drawn (thinned evenly beyond).
const BANDED_POINTS: usize = 3000;

/// Panels of measured points with a model's line over its shaded band (a posterior-predictive
/// band: translucent blue with darker edges, under the points, the line black on top), `columns`
/// across, 800 × 600 pixels each, axes in engineering notation; PNG written atomically.
pub fn band_panels_figure(
    path: &Path,
    force: bool,
    columns: usize,
    panels: &[BandedPanel],
) -> Result<()> {
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns).max(1);
    write_atomically(path, force, |tmp| {
        let root =
            BitMapBackend::new(tmp, (800 * columns as u32, 600 * rows as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        for (area, panel) in root.split_evenly((rows, columns)).iter().zip(panels) {
            draw_banded(area, path, panel)?;
        }
        root.present().map_err(perr(path))
    })
}

/// Draws one [`BandedPanel`].
fn draw_banded(area: &Area, path: &Path, p: &BandedPanel) -> Result<()> {
    let has_band =
        !p.band.1.is_empty() && p.band.1.len() == p.x.len() && p.band.2.len() == p.x.len();
    let ys = || {
        p.points
            .1
            .iter()
            .chain(p.line.1)
            .chain(if has_band { p.band.1 } else { &[] })
            .chain(if has_band { p.band.2 } else { &[] })
            .copied()
    };
    let (x0, x1) = finite_range(p.x.iter().copied(), 0.02).unwrap_or((0.0, 1.0));
    let (y0, y1) = finite_range(ys(), 0.05).unwrap_or((0.0, 1.0));
    let (xs, xu) = engineering_axis(x0.abs().max(x1.abs()), p.x_name_unit.1);
    let (ys_, yu) = engineering_axis(y0.abs().max(y1.abs()), p.y_name_unit.1);
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(55)
        .y_label_area_size(75)
        .build_cartesian_2d(x0 * xs..x1 * xs, y0 * ys_..y1 * ys_)
        .map_err(perr(path))?;
    chart
        .configure_mesh()
        .x_desc(with_unit(p.x_name_unit.0, &xu))
        .y_desc(with_unit(p.y_name_unit.0, &yu))
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 17))
        .draw()
        .map_err(perr(path))?;
    let blue = RGBColor(30, 90, 200);
    let red = RGBColor(170, 20, 20);
    if has_band {
        // One polygon per run of finite edges: along the lower edge, back along the upper.
        let finite =
            |k: usize| p.x[k].is_finite() && p.band.1[k].is_finite() && p.band.2[k].is_finite();
        let mut runs: Vec<Vec<usize>> = Vec::new();
        for k in 0..p.x.len() {
            match (finite(k), runs.last_mut()) {
                (true, Some(run)) if run.last() == Some(&(k.wrapping_sub(1))) => run.push(k),
                (true, _) => runs.push(vec![k]),
                (false, _) => {}
            }
        }
        let label = p.band.0.clone();
        let mut first = true;
        for run in &runs {
            let mut poly: Vec<(f64, f64)> = run
                .iter()
                .map(|&k| (p.x[k] * xs, p.band.1[k] * ys_))
                .collect();
            poly.extend(run.iter().rev().map(|&k| (p.x[k] * xs, p.band.2[k] * ys_)));
            let drawn = chart
                .draw_series(std::iter::once(Polygon::new(poly, blue.mix(0.25).filled())))
                .map_err(perr(path))?;
            if std::mem::take(&mut first) {
                drawn.label(label.clone()).legend(move |(x, y)| {
                    Rectangle::new([(x, y - 6), (x + 20, y + 6)], blue.mix(0.35).filled())
                });
            }
            for edge in [p.band.1, p.band.2] {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        run.iter()
                            .map(|&k| (p.x[k] * xs, edge[k] * ys_))
                            .collect::<Vec<_>>(),
                        blue.mix(0.7).stroke_width(1),
                    )))
                    .map_err(perr(path))?;
            }
        }
    }
    let stride = p.x.len().div_ceil(BANDED_POINTS).max(1);
    chart
        .draw_series(
            p.x.iter()
                .zip(p.points.1)
                .step_by(stride)
                .map(|(x, y)| (x * xs, y * ys_))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|q| Circle::new(q, 2, red.filled())),
        )
        .map_err(perr(path))?
        .label(p.points.0.clone())
        .legend(move |(x, y)| Circle::new((x + 10, y), 3, red.filled()));
    let line: Vec<(f64, f64)> =
        p.x.iter()
            .zip(p.line.1)
            .map(|(x, y)| (x * xs, y * ys_))
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect();
    let runs = unreversed_runs(&line, |q| chart.backend_coord(q));
    chart
        .draw_series(
            runs.into_iter()
                .map(|run| PathElement::new(run, BLACK.stroke_width(2))),
        )
        .map_err(perr(path))?
        .label(p.line.0.clone())
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(3)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 17))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(perr(path))?;
    Ok(())
}

#[cfg(test)]
mod engineering_tests {
    use super::*;

    #[test]
    fn engineering_axes_use_powers_of_a_thousand() {
        assert_eq!(engineering_axis(1.93e9, "Pa"), (1e-9, "GPa".to_string()));
        assert_eq!(engineering_axis(45e-6, "s"), (1e6, "µs".to_string()));
        assert_eq!(engineering_axis(0.045, "1"), (1.0, String::new()));
        assert_eq!(engineering_axis(0.0045, "1"), (1e3, "×1e-3".to_string()));
        assert_eq!(engineering_axis(2e4, "1/s"), (1e-3, "×1e3 1/s".to_string()));
        assert_eq!(engineering_axis(5.3, "m/s"), (1.0, "m/s".to_string()));
        assert_eq!(engineering_axis(0.0, "N"), (1.0, "N".to_string()));
        assert_eq!(with_unit("strain", ""), "strain");
    }
}
