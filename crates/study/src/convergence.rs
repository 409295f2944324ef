//! Convergence studies: a scene run on a ladder of resolutions, each level's error against the
//! finest (and against a Richardson extrapolation where the observed order allows), its run
//! time, and the observed order of convergence (Roache, *Verification and Validation in
//! Computational Science and Engineering*, 1998: p = ln(e₂₁/e₃₂)/ln r for a refinement ratio r).

use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use std::path::Path;
use std::time::Instant;

/// The knob a ladder refines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Knob {
    /// Bar cell size of `pulse`/`shpb` scenes, m (the time step follows at Courant 1).
    CellSize,
    /// Time steps per contact duration of `collision` scenes.
    StepsPerContact,
    /// Time steps per contact period of `force-driven` scenes.
    StepsPerPeriod,
}

impl Knob {
    /// The scene key the knob sets.
    pub fn key(self) -> &'static str {
        match self {
            Knob::CellSize => "cell_size_m",
            Knob::StepsPerContact => "steps_per_contact",
            Knob::StepsPerPeriod => "steps_per_period",
        }
    }

    /// The ladder of values, coarsest first; each level refines the previous one by 2.
    pub fn ladder(self) -> Vec<f64> {
        match self {
            Knob::CellSize => (0..6).map(|k| 4e-3 / f64::powi(2.0, k)).collect(),
            _ => (0..7).map(|k| 125.0 * f64::powi(2.0, k)).collect(),
        }
    }

    /// The grid spacing h the value stands for (cell size, or 1/steps), for the order estimate.
    pub fn spacing(self, value: f64) -> f64 {
        match self {
            Knob::CellSize => value,
            _ => 1.0 / value,
        }
    }

    /// The knob a scene's kind refines, or an error naming the scene for kinds with none.
    pub fn for_scene(params: &Params) -> Result<Knob> {
        match &params.params {
            SceneParams::Pulse { .. } => Ok(Knob::CellSize),
            SceneParams::Collision(_) => Ok(Knob::StepsPerContact),
            SceneParams::ForceDriven { .. } => Ok(Knob::StepsPerPeriod),
            _ => Err(Error::Input {
                file: params.source.clone(),
                key: "kind".into(),
                problem: format!(
                    "a `{}` scene evaluates the law on its own points: no resolution to converge",
                    params.kind
                ),
                allowed: "collision, force-driven, pulse, shpb".into(),
            }),
        }
    }
}

/// The quantities compared between levels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metrics {
    /// Peak contact force (bar scenes without spheres: peak stress at the last gauge), N or Pa.
    pub peak: f64,
    /// Sphere approach at peak force, m (0 without spheres).
    pub displacement_at_peak_m: f64,
}

/// One level of a ladder.
#[derive(Debug, Clone, PartialEq)]
pub struct Level {
    /// Value of the knob.
    pub value: f64,
    /// Wall-clock run time, s.
    pub runtime_s: f64,
    /// The level's metrics.
    pub metrics: Metrics,
    /// Relative error of the peak against the finest level.
    pub peak_error: f64,
    /// Relative error of the displacement at peak against the finest level.
    pub displacement_error: f64,
    /// RMS difference of the signal (transmission-gauge strain, or contact force) against the
    /// finest level, relative to the finest level's largest |value|.
    pub signal_rms_error: f64,
}

impl Level {
    /// The level's table columns: value, run time, peak, its error, displacement at peak, its
    /// error, signal RMS error.
    pub fn columns(&self) -> [f64; 7] {
        [
            self.value,
            self.runtime_s,
            self.metrics.peak,
            self.peak_error,
            self.metrics.displacement_at_peak_m,
            self.displacement_error,
            self.signal_rms_error,
        ]
    }
}

/// Observed order of convergence of one quantity and its Richardson-extrapolated value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Order {
    /// Observed order p from the three finest levels (None: differences too small or not
    /// monotone to define it).
    pub order: Option<f64>,
    /// Richardson extrapolation f₁ + (f₁ − f₂)/(rᵖ − 1) from the two finest levels.
    pub extrapolated: Option<f64>,
}

/// A convergence study.
#[derive(Debug, Clone, PartialEq)]
pub struct Study {
    /// The scene file.
    pub scene: String,
    /// The refined knob.
    pub knob: Knob,
    /// Levels, coarsest first.
    pub levels: Vec<Level>,
    /// Order and extrapolation of the peak.
    pub peak_order: Order,
    /// Order and extrapolation of the displacement at peak.
    pub displacement_order: Order,
    /// Orders between successive triples of levels (peak), coarsest first.
    pub local_peak_orders: Vec<Option<f64>>,
    /// RMS difference of the signal between each level and the next finer one (relative to the
    /// finer level's largest |value|), coarsest first.
    pub successive_signal_rms: Vec<f64>,
    /// Orders log₂(d_i/d_{i+1}) of those successive differences (None where not decreasing).
    pub signal_orders: Vec<Option<f64>>,
}

/// Differences below this fraction of the value are round-off, not discretisation error.
const ROUND_OFF: f64 = 1e-12;

/// Observed order from three values on grids refined by `ratio` (coarsest first).
pub fn observed_order(coarse: f64, medium: f64, fine: f64, ratio: f64) -> Option<f64> {
    let (e21, e32) = (medium - coarse, fine - medium);
    let scale = fine.abs().max(f64::MIN_POSITIVE);
    if e21.abs() <= ROUND_OFF * scale || e32.abs() <= ROUND_OFF * scale || e21 * e32 <= 0.0 {
        return None;
    }
    Some((e21 / e32).abs().ln() / ratio.ln())
}

/// Richardson extrapolation of `fine` using `medium` on a grid `ratio` times coarser and order p.
pub fn richardson(medium: f64, fine: f64, ratio: f64, p: f64) -> f64 {
    fine + (fine - medium) / (ratio.powf(p) - 1.0)
}

/// Peak and displacement at peak of a run (sub-sample, [`interpolated_peak`]).
pub(crate) fn metrics(out: &RunOutput) -> Metrics {
    match &out.contact {
        Some(c) => {
            let (peak, displacement_at_peak_m) = interpolated_peak(&c.force_n, &c.displacement_m);
            Metrics {
                peak,
                displacement_at_peak_m,
            }
        }
        None => Metrics {
            peak: out
                .gauges
                .last()
                .map(|g| g.strain.iter().fold(0.0f64, |m, s| m.max(s.abs())))
                .unwrap_or(0.0),
            displacement_at_peak_m: 0.0,
        },
    }
}

/// Peak of `f` and the value of `g` there, between samples: the parabola through the largest
/// sample and its neighbours (uniform sampling) gives the peak's fractional index s ∈ [−½, ½];
/// `g` is read on the parabola through the same three indices. Picking the largest sample
/// instead would add a sampling error of O(Δt) to g, which hides the scheme's order.
pub fn interpolated_peak(f: &[f64], g: &[f64]) -> (f64, f64) {
    let k = shpb_core::numeric::argmax(f);
    if k == 0 || k + 1 >= f.len() {
        return (f[k], g[k]);
    }
    let (fm, f0, fp) = (f[k - 1], f[k], f[k + 1]);
    let curvature = fm - 2.0 * f0 + fp;
    if curvature >= 0.0 {
        return (f0, g[k]);
    }
    let s = (0.5 * (fm - fp) / curvature).clamp(-0.5, 0.5);
    let quad =
        |ym: f64, y0: f64, yp: f64| y0 + 0.5 * s * (yp - ym) + 0.5 * s * s * (yp - 2.0 * y0 + ym);
    (quad(fm, f0, fp), quad(g[k - 1], g[k], g[k + 1]))
}

/// The compared signal of a run (transmission-gauge strain, else the last gauge, else the
/// contact force): (time, values).
pub(crate) fn signal(out: &RunOutput) -> (Vec<f64>, Vec<f64>) {
    if let (Some(t), Some(g)) = (
        &out.time_s,
        out.gauges.iter().find(|g| g.name == "transmission"),
    ) {
        return (t.clone(), g.strain.clone());
    }
    if let (Some(t), Some(g)) = (&out.time_s, out.gauges.last()) {
        return (t.clone(), g.strain.clone());
    }
    match &out.contact {
        Some(c) => (
            c.time_s.clone().unwrap_or_else(|| c.displacement_m.clone()),
            c.force_n.clone(),
        ),
        None => (Vec::new(), Vec::new()),
    }
}

fn relative(x: f64, reference: f64) -> f64 {
    if reference == 0.0 {
        0.0
    } else {
        (x - reference).abs() / reference.abs()
    }
}

/// RMS of (y − y_ref) on the reference's times over the common time span, relative to max |y_ref|.
pub fn rms_difference(t: &[f64], y: &[f64], t_ref: &[f64], y_ref: &[f64]) -> f64 {
    if t.len() < 2 || t_ref.is_empty() {
        return 0.0;
    }
    let end = t[t.len() - 1].min(t_ref[t_ref.len() - 1]);
    let keep: Vec<usize> = (0..t_ref.len()).filter(|&i| t_ref[i] <= end).collect();
    let at: Vec<f64> = keep.iter().map(|&i| t_ref[i]).collect();
    let y_at = shpb_core::numeric::resample(t, y, &at);
    let scale = y_ref.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 || keep.is_empty() {
        return 0.0;
    }
    let ss: f64 = keep
        .iter()
        .zip(&y_at)
        .map(|(&i, v)| (v - y_ref[i]).powi(2))
        .sum();
    (ss / keep.len() as f64).sqrt() / scale
}

/// Runs the scene at every level of its knob's ladder (`progress` is called before each run
/// with the level's index and value) and compares the levels with the finest.
pub fn study(path: &Path, mut progress: impl FnMut(usize, f64)) -> Result<Study> {
    let base = Params::from_file(path)?;
    let knob = Knob::for_scene(&base)?;
    let mut runs = Vec::new();
    for (i, value) in knob.ladder().into_iter().enumerate() {
        progress(i, value);
        let set = [(
            knob.key().to_string(),
            shpb_input::scene::Value::Float(value),
        )];
        let params = Params::from_file_overridden(path, &set)?;
        let start = Instant::now();
        let out = params.run()?;
        let runtime_s = start.elapsed().as_secs_f64();
        runs.push((value, runtime_s, metrics(&out), signal(&out)));
    }
    let (_, _, finest, (t_ref, y_ref)) = runs.last().expect("ladders are not empty").clone();
    let levels = runs
        .iter()
        .map(|(value, runtime_s, m, (t, y))| Level {
            value: *value,
            runtime_s: *runtime_s,
            metrics: *m,
            peak_error: relative(m.peak, finest.peak),
            displacement_error: relative(m.displacement_at_peak_m, finest.displacement_at_peak_m),
            signal_rms_error: rms_difference(t, y, &t_ref, &y_ref),
        })
        .collect::<Vec<_>>();
    let order_of = |get: fn(&Metrics) -> f64| -> Order {
        let n = levels.len();
        let (c, m, f) = (
            get(&levels[n - 3].metrics),
            get(&levels[n - 2].metrics),
            get(&levels[n - 1].metrics),
        );
        let order = observed_order(c, m, f, 2.0);
        Order {
            order,
            extrapolated: order.map(|p| richardson(m, f, 2.0, p)),
        }
    };
    let local_peak_orders = levels
        .windows(3)
        .map(|w| observed_order(w[0].metrics.peak, w[1].metrics.peak, w[2].metrics.peak, 2.0))
        .collect();
    let successive_signal_rms: Vec<f64> = runs
        .windows(2)
        .map(|w| rms_difference(&w[0].3.0, &w[0].3.1, &w[1].3.0, &w[1].3.1))
        .collect();
    let signal_orders = successive_signal_rms
        .windows(2)
        .map(|d| (d[1] > 0.0 && d[0] > d[1]).then(|| (d[0] / d[1]).log2()))
        .collect();
    Ok(Study {
        scene: path.display().to_string(),
        successive_signal_rms,
        signal_orders,
        knob,
        peak_order: order_of(|m| m.peak),
        displacement_order: order_of(|m| m.displacement_at_peak_m),
        local_peak_orders,
        levels,
    })
}

fn fmt_order(o: Option<f64>) -> String {
    o.map(|p| format!("{p:.2}")).unwrap_or_else(|| "—".into())
}

/// The study as a printable table (one row per level) with the observed orders below it.
pub fn table_text(s: &Study) -> String {
    let mut t = format!(
        "convergence of {} in {} (refinement ratio 2; errors relative to the finest level)\n",
        s.scene,
        s.knob.key()
    );
    t.push_str(&format!(
        "{:>14} {:>11} {:>16} {:>11} {:>16} {:>11} {:>11}\n",
        s.knob.key(),
        "runtime_s",
        "peak",
        "peak_err",
        "disp_at_peak_m",
        "disp_err",
        "signal_rms"
    ));
    for l in &s.levels {
        let [value, runtime, peak, peak_err, disp, disp_err, rms] = l.columns();
        t.push_str(&format!(
            "{value:>14.4e} {runtime:>11.4} {peak:>16.9e} {peak_err:>11.2e} {disp:>16.9e} {disp_err:>11.2e} {rms:>11.2e}\n"
        ));
    }
    let ex = |o: &Order| {
        o.extrapolated
            .map(|v| format!("{v:.9e}"))
            .unwrap_or_else(|| "—".into())
    };
    t.push_str(&format!(
        "observed order (three finest levels): peak {}, displacement at peak {}\n",
        fmt_order(s.peak_order.order),
        fmt_order(s.displacement_order.order)
    ));
    t.push_str(&format!(
        "Richardson extrapolation: peak {}, displacement at peak {}\n",
        ex(&s.peak_order),
        ex(&s.displacement_order)
    ));
    let list = |v: &[Option<f64>]| {
        v.iter()
            .map(|o| fmt_order(*o))
            .collect::<Vec<_>>()
            .join(", ")
    };
    t.push_str(&format!(
        "local orders of the peak (successive triples, coarsest first): {}\n",
        list(&s.local_peak_orders)
    ));
    t.push_str(&format!(
        "signal RMS difference between successive levels: {}\n",
        s.successive_signal_rms
            .iter()
            .map(|d| format!("{d:.2e}"))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    t.push_str(&format!(
        "observed orders of the signal (successive differences, coarsest first): {}",
        list(&s.signal_orders)
    ));
    t
}

/// Writes the levels as CSV (atomically; refuses to overwrite without `force`).
pub fn write_csv(path: &Path, force: bool, s: &Study) -> Result<()> {
    let mut text = format!(
        "{},runtime_s,peak,peak_error,displacement_at_peak_m,displacement_error,signal_rms_error\n",
        s.knob.key()
    );
    for l in &s.levels {
        let row: Vec<String> = l.columns().iter().map(|v| format!("{v:e}")).collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    shpb_output::io::write_text_atomically(path, force, &text)
}

/// Draws relative error against run time on log–log axes (levels with zero error left out).
pub fn plot(path: &Path, force: bool, s: &Study) -> Result<()> {
    type Get = fn(&Level) -> f64;
    let series: [(&str, Get, (u8, u8, u8)); 3] = [
        ("peak force", |l| l.peak_error, (230, 140, 20)),
        (
            "displacement at peak",
            |l| l.displacement_error,
            (30, 90, 200),
        ),
        ("gauge signal RMS", |l| l.signal_rms_error, (40, 150, 60)),
    ];
    let pts = |get: Get| -> Vec<(f64, f64)> {
        s.levels
            .iter()
            .map(|l| (l.runtime_s.max(1e-6), get(l)))
            .filter(|(_, e)| *e > 0.0)
            .collect()
    };
    let lines: Vec<shpb_output::plot::LogLine> = series
        .iter()
        .map(|(label, get, rgb)| shpb_output::plot::LogLine {
            label,
            points: pts(*get),
            rgb: *rgb,
        })
        .collect();
    let title = format!("convergence: {} (refining {})", s.scene, s.knob.key());
    shpb_output::plot::loglog_plot(
        path,
        force,
        &title,
        ("run time (s)", "relative error against the finest level"),
        &lines,
    )
}
