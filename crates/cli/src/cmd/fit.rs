//! `shpb fit`: the constants a record implies, with their uncertainty (shpb_study::fit;
//! docs/physics.md §11).

use super::common::{ProgressLine, finite, report, warn};
use shpb_input::Result;
use shpb_output::atomic::check_not_input;
use shpb_output::fit::FitReport;
use shpb_study::fit::spec::parse_flags;
use shpb_study::fit::{Problem, Settings};
use std::path::{Path, PathBuf};

/// The options of `shpb fit` besides the scene.
pub struct FitOptions<'a> {
    /// `--free KEY=MIN:MAX`, one or more.
    pub free: &'a [String],
    /// `--prior KEY=normal:MEAN:SD`.
    pub prior: &'a [String],
    /// `--record FILE`.
    pub record: &'a [PathBuf],
    /// `--residual`.
    pub residual: Option<&'a str>,
    /// `-o FIT.h5`.
    pub output: Option<&'a Path>,
    /// `--plot FILE.png`: the records with the best fit and the predictive band.
    pub plot: Option<&'a Path>,
    /// `--corner FILE.png`: marginal and pairwise posterior plots.
    pub corner: Option<&'a Path>,
    /// `--force`.
    pub force: bool,
    /// `--resume`: continue the checkpoint `<FIT.h5>.partial.h5` of a stopped fit.
    pub resume: bool,
    /// Sampler and fit settings.
    pub settings: Settings,
}

/// `shpb fit SCENE --free KEY=MIN:MAX … [--prior …] [--record FILE …] [-o FIT.h5] [--json]`.
pub fn fit(scene: &Path, o: &FitOptions) -> Result<()> {
    let (free, priors, residual) = parse_flags(o.free, o.prior, o.residual)?;
    let outputs = super::common::plan(
        o.force,
        &[
            (o.output, "-o", &["h5", "hdf5"]),
            (o.plot, "--plot", &["png"]),
            (o.corner, "--corner", &["png"]),
        ],
    )?;
    let mut inputs = vec![scene.to_path_buf()];
    inputs.extend(o.record.iter().cloned());
    for (path, flag) in [(o.output, "-o"), (o.plot, "--plot"), (o.corner, "--corner")] {
        if let Some(p) = path {
            check_not_input(p, flag, &inputs)?;
        }
    }
    let problem = Problem::new(scene, free, priors, residual, o.record)?;
    let mut line = ProgressLine::new(&format!("fit {}", scene.display()));
    let mut progress = |stage: &str, done: usize, total: usize| {
        // Least squares ≈ the first fifth of the time, the sampler the rest.
        let f = match stage {
            "least squares" => 0.2 * done as f64 / total.max(1) as f64,
            "posterior" => 0.2 + 0.75 * done as f64 / total.max(1) as f64,
            _ => 0.95,
        };
        line.update(f.min(1.0));
    };
    // With -o, the chain so far is kept every twentieth of the steps in `<FIT.h5>.partial.h5`,
    // which `--resume` continues (a stopped fit says so).
    let checkpoint = o.output.map(shpb_study::fit::checkpoint_path);
    let resume = match (&checkpoint, o.resume) {
        (None, true) => {
            return Err(shpb_study::api::input_err(
                "--resume",
                "given without -o",
                "--resume with the -o FIT.h5 of the stopped fit (its checkpoint is FIT.h5.partial.h5)",
            ));
        }
        (Some(c), true) if c.is_file() => {
            let r = shpb_output::fit::read_fit_hdf5(c)?;
            shpb_study::fit::check_resume(&problem, &o.settings, &r, c)?;
            Some(r)
        }
        (Some(c), true) => {
            return Err(shpb_study::api::input_err(
                "--resume",
                format!("no checkpoint {}", c.display()),
                "--resume after a fit with the same -o was stopped",
            ));
        }
        (Some(c), false) if c.is_file() && !o.force => {
            return Err(shpb_study::api::input_err(
                "-o",
                format!("a stopped fit left its checkpoint {}", c.display()),
                "--resume to continue it, or --force to start again",
            ));
        }
        _ => None,
    };
    if let Some(c) = checkpoint.clone() {
        crate::interrupt::set_message(move || {
            format!(
                "the chain so far is in {}; continue with: {}",
                c.display(),
                crate::interrupt::resume_command()
            )
        });
    }
    let started = std::time::Instant::now();
    let r = shpb_study::fit::fit_resumable(
        &problem,
        &o.settings,
        &super::common::command_line(),
        &mut progress,
        &|| true,
        resume.as_ref(),
        &mut |partial| match &checkpoint {
            Some(c) => shpb_output::fit::write_fit_hdf5(c, true, partial, None),
            None => Ok(()),
        },
    )?;
    crate::interrupt::clear_message();
    line.finish();
    let seconds = started.elapsed().as_secs_f64();
    for w in &r.warnings {
        warn(w);
    }
    super::common::write_all(&outputs, || {
        shpb_output::fit::write_fit_outputs(&r, o.output, o.plot, o.corner, o.force)
    })?;
    if let Some(c) = &checkpoint {
        // The fit is whole in its file: the checkpoint has served.
        let _ = std::fs::remove_file(c);
    }
    report(&text(&r, seconds), || {
        let mut j = shpb_output::fit::fit_json(&r);
        j["seconds"] = finite(seconds);
        j
    })
}

/// The result table: each parameter's best fit, median and 90 % interval; each record's noise
/// and how much of it lies inside its predictive band.
fn text(r: &FitReport, seconds: f64) -> String {
    let mut t = format!(
        "fit of {} ({} residual): {} walkers × {} steps ({} burn-in), acceptance {:.2}, {} runs in {:.1} s\n",
        r.scene, r.residual, r.walkers, r.steps, r.burn_in, r.acceptance, r.evaluations, seconds
    );
    t.push_str(&format!(
        "{:<34} {:>12} {:>12} {:>27} {:>6} {:>7}\n",
        "key", "best", "median", "90 % interval", "unit", "ESS"
    ));
    for p in &r.parameters {
        t.push_str(&format!(
            "{:<34} {:>12.5e} {:>12.5e} {:>12.5e} – {:<12.5e} {:>6} {:>7.0}\n",
            p.key, p.best, p.median, p.band_90[0], p.band_90[1], p.unit, p.ess
        ));
    }
    for rec in &r.records {
        t.push_str(&format!(
            "record {} ({} against {}): {} points, noise SD {:.3e} {}, correlated over {:.1} points, {:.0} % inside the 90 % predictive band\n",
            rec.name,
            rec.y_label,
            rec.x_label,
            rec.y.len(),
            rec.noise_sd,
            rec.y_unit,
            rec.noise_correlation,
            100.0 * rec.inside_band
        ));
    }
    t
}
