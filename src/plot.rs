//! PNG plots with plotters: force–displacement curves (as in the paper's Figs. 2–4).

use crate::error::{Error, Result};
use crate::io::write_atomically;
use plotters::prelude::*;
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

/// Draws curves into a PNG (written atomically), scaled as `axes` says.
pub fn xy_plot(path: &Path, force: bool, axes: &Axes, curves: &[Curve]) -> Result<()> {
    let (title, x_label, y_label, x_scale, y_scale) = (
        axes.title,
        axes.x_label,
        axes.y_label,
        axes.x_scale,
        axes.y_scale,
    );
    let (mut xmax, mut ymax) = (0.0f64, 0.0f64);
    let (mut xmin, mut ymin) = (0.0f64, 0.0f64);
    for c in curves {
        for (&x, &y) in c.x.iter().zip(c.y) {
            xmax = xmax.max(x * x_scale);
            ymax = ymax.max(y * y_scale);
            xmin = xmin.min(x * x_scale);
            ymin = ymin.min(y * y_scale);
        }
    }
    if xmax <= xmin {
        xmax = xmin + 1.0;
    }
    if ymax <= ymin {
        ymax = ymin + 1.0;
    }
    let perr = |e: String| Error::Io {
        file: path.display().to_string(),
        source: std::io::Error::other(e),
    };
    write_atomically(path, force, |tmp| {
        let root = BitMapBackend::new(tmp, (1000, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| perr(e.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 26))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(75)
            .build_cartesian_2d(xmin..xmax * 1.03, ymin..ymax * 1.08)
            .map_err(|e| perr(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 18))
            .draw()
            .map_err(|e| perr(e.to_string()))?;
        for (i, c) in curves.iter().enumerate() {
            let pts: Vec<(f64, f64)> =
                c.x.iter()
                    .zip(c.y)
                    .map(|(&x, &y)| (x * x_scale, y * y_scale))
                    .collect();
            let color = if c.measured {
                RGBColor(140, 20, 20)
            } else {
                PALETTE[i % PALETTE.len()]
            };
            let series = if c.measured {
                chart.draw_series(DashedLineSeries::new(pts, 8, 5, color.stroke_width(3)))
            } else {
                chart.draw_series(LineSeries::new(pts, color.stroke_width(2)))
            }
            .map_err(|e| perr(e.to_string()))?;
            series.label(c.label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
            });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 18))
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(|e| perr(e.to_string()))?;
        root.present().map_err(|e| perr(e.to_string()))
    })
}
