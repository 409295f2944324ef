//! Multi-panel PNG figures of the validation report: model lines over reference data (dashed or
//! markers), as in the paper's Figs. 2–4.

use plotters::prelude::*;
use shpb_input::{Error, Result};
use shpb_output::io::write_atomically;
use std::path::Path;

/// How a series is drawn; the number picks a colour of the palette (0 is the paper's dark red of
/// reference data, 1 its orange of model curves).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Solid line (model).
    Line(usize),
    /// Dashed line (reference data: FEM or measurement).
    Dashed(usize),
    /// Filled circles (discrete reference points).
    Points(usize),
}

/// One curve of a panel, in SI units (the panel scales it for display).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
    /// How it is drawn.
    pub style: Style,
}

impl Series {
    /// A series from label, data and style.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, style: Style) -> Series {
        Series {
            label: label.into(),
            x,
            y,
            style,
        }
    }
}

/// One panel: title, axis labels with units, display scale factors and its series.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Panel title.
    pub title: String,
    /// x-axis label (with the displayed unit).
    pub x_label: String,
    /// y-axis label (with the displayed unit).
    pub y_label: String,
    /// Factor from SI x values to displayed ones (e.g. 1e6 for m → µm).
    pub x_scale: f64,
    /// Factor from SI y values to displayed ones.
    pub y_scale: f64,
    /// The curves.
    pub series: Vec<Series>,
}

/// Where the legend sits in every panel of a figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Legend {
    /// Upper left corner.
    UpperLeft,
    /// Upper right corner.
    UpperRight,
    /// Lower right corner.
    LowerRight,
}

/// A figure: panels in a grid of `columns` columns, written to one PNG.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Legend position in every panel.
    pub legend: Legend,
    /// Caption (shown under the image in the report).
    pub caption: String,
    /// Panels per row.
    pub columns: usize,
    /// The panels, row by row.
    pub panels: Vec<Panel>,
}

/// Colours: dark red (reference), orange (model), black, blue, green, purple, brown, teal.
const PALETTE: [RGBColor; 8] = [
    RGBColor(140, 20, 20),
    RGBColor(230, 140, 20),
    RGBColor(0, 0, 0),
    RGBColor(30, 90, 200),
    RGBColor(40, 150, 60),
    RGBColor(150, 60, 170),
    RGBColor(140, 90, 40),
    RGBColor(0, 150, 150),
];

/// Pixel size of one panel.
const PANEL_PX: (u32, u32) = (760, 540);

type Area<'b> = DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>;

/// Converts a plotters error into the crate's error for `path`.
fn perr<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> Error + '_ {
    move |e| Error::Io {
        file: path.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// Displayed data range of a panel, padded; a flat or empty panel still gets an axis.
fn range(p: &Panel) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for s in &p.series {
        for (&x, &y) in s.x.iter().zip(&s.y) {
            let (x, y) = (x * p.x_scale, y * p.y_scale);
            if x.is_finite() && y.is_finite() {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    if !x0.is_finite() {
        return (0.0, 1.0, 0.0, 1.0);
    }
    let pad = |lo: f64, hi: f64, below: f64, above: f64| {
        let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
        (lo - below * span, hi + above * span)
    };
    let (x0, x1) = pad(x0, x1, 0.0, 0.02);
    let (y0, y1) = pad(y0, y1, 0.03, 0.12);
    (x0, x1, y0, y1)
}

/// Draws one panel into its area.
fn draw_panel(area: &Area, path: &Path, p: &Panel, legend: Legend) -> Result<()> {
    let (x0, x1, y0, y1) = range(p);
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(perr(path))?;
    chart
        .configure_mesh()
        .x_desc(p.x_label.as_str())
        .y_desc(p.y_label.as_str())
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(perr(path))?;
    for s in &p.series {
        let pts: Vec<(f64, f64)> =
            s.x.iter()
                .zip(&s.y)
                .map(|(&x, &y)| (x * p.x_scale, y * p.y_scale))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
        let label = s.label.clone();
        match s.style {
            Style::Line(c) => {
                let colour = PALETTE[c % PALETTE.len()];
                chart
                    .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                    .map_err(perr(path))?
                    .label(label)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(3))
                    });
            }
            Style::Dashed(c) => {
                let colour = PALETTE[c % PALETTE.len()];
                chart
                    .draw_series(DashedLineSeries::new(pts, 7, 5, colour.stroke_width(2)))
                    .map_err(perr(path))?
                    .label(label)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 8, y)], colour.stroke_width(3))
                    });
            }
            Style::Points(c) => {
                let colour = PALETTE[c % PALETTE.len()];
                chart
                    .draw_series(pts.into_iter().map(|q| Circle::new(q, 4, colour.filled())))
                    .map_err(perr(path))?
                    .label(label)
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled()));
            }
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(match legend {
            Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
            Legend::UpperRight => SeriesLabelPosition::UpperRight,
            Legend::LowerRight => SeriesLabelPosition::LowerRight,
        })
        .draw()
        .map_err(perr(path))?;
    Ok(())
}

/// Draws a figure into a PNG at `path` (written atomically; an existing file needs `force`).
pub fn draw(path: &Path, force: bool, fig: &Figure) -> Result<()> {
    let columns = fig.columns.max(1);
    let rows = fig.panels.len().div_ceil(columns).max(1);
    let size = (PANEL_PX.0 * columns as u32, PANEL_PX.1 * rows as u32);
    write_atomically(path, force, |tmp| {
        let root = BitMapBackend::new(tmp, size).into_drawing_area();
        root.fill(&WHITE).map_err(perr(path))?;
        let areas = root.split_evenly((rows, columns));
        for (area, panel) in areas.iter().zip(&fig.panels) {
            draw_panel(area, path, panel, fig.legend)?;
        }
        root.present().map_err(perr(path))
    })
}
