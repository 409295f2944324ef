//! What `shpb fit` found, as plain data ([`FitReport`]), and its outputs: the fit file (HDF5,
//! [`write_fit_hdf5`], read back by [`read_fit_hdf5`] to resume a fit or from Python), the
//! `--json` object ([`fit_json`]), the corner plot of the posterior ([`corner_figure`]) and the
//! records with the posterior-predictive band ([`records_figure`]). The statistics themselves
//! (least squares, ensemble sampler, noise model) are docs/physics.md §12.
//!
//! Layout of the fit file (every number in SI units, `units` attributes on the datasets):
//! - `/` attribute `shpb_version`.
//! - `/fit` attributes `scene`, `residual`, `command_line` (strings), `walkers`, `steps`,
//!   `burn_in`, `evaluations` (unsigned integers), `acceptance`, `best_cost` (floats) and
//!   `warnings` (one per line, empty for none).
//! - `/fit/parameters/<key>` one group per free parameter (`<key>` the scene key,
//!   `specimen.yield_stress_pa`), attributes `unit`, `min`, `max` (the `--free` bounds),
//!   `prior_mean` and `prior_sd` (only for a `--prior normal:MEAN:SD`), `value` (the least-squares
//!   best fit), `median`, `band_90_low`, `band_90_high` (5 % and 95 % posterior quantiles),
//!   `tau_steps` (integrated autocorrelation time, sampler steps) and `ess` (effective sample size).
//! - `/fit/chain` `[steps, walkers, parameters]`: every position of every walker, with the
//!   attributes `parameters` (the keys, in the order of the last axis) and `units` (theirs).
//! - `/fit/log_prob` `[steps, walkers]`: the log posterior of each position (natural log).
//! - `/fit/samples` `[n, parameters]`: the chain after the burn-in, n = (steps − burn_in) ×
//!   walkers, step by step (attributes `parameters` and `units` as on `/fit/chain`).
//! - `/fit/correlations` `[parameters, parameters]`: the posterior Pearson correlations.
//! - `/fit/records/<i>` one group per record (i = 0, 1, …), attributes `name`, `x_label`,
//!   `x_unit`, `y_label`, `y_unit`, `noise_sd` (y units), `noise_correlation` (points),
//!   `noise_calibration` (factor on the noise's variance from simulated records, 1: none) and
//!   `inside_band` (fraction); datasets `x`, `y` (the record), `best` (the model at the best
//!   fit), `band_low`, `band_high` (the 90 % posterior-predictive band, empty when none).
//! - `/provenance` as a run file has it ([`crate::provenance`]), when given.

use crate::atomic::write_atomically;
use crate::h5::{h5err, string_attr, vlu, write_dataset};
use crate::plot::{BandedPanel, CornerVariable, band_panels_figure, corner_plot};
use hdf5::types::VarLenUnicode;
use serde_json::{Value, json};
use shpb_input::{Error, Result};
use std::path::Path;

/// One free parameter of a fit (docs/physics.md §12.1).
#[derive(Debug, Clone, PartialEq)]
pub struct FitParameter {
    /// Scene key, e.g. `specimen.yield_stress_pa`.
    pub key: String,
    /// SI unit, `Pa`, `1` ...
    pub unit: String,
    /// Lower `--free` bound (uniform prior support).
    pub min: f64,
    /// Upper `--free` bound.
    pub max: f64,
    /// `--prior normal:MEAN:SD`: mean and standard deviation.
    pub prior_normal: Option<(f64, f64)>,
    /// Least-squares best fit.
    pub best: f64,
    /// Posterior median.
    pub median: f64,
    /// 5 % and 95 % posterior quantiles.
    pub band_90: [f64; 2],
    /// Integrated autocorrelation time, sampler steps.
    pub tau_steps: f64,
    /// Effective sample size.
    pub ess: f64,
}

/// One record a fit was made to, with the model's best and posterior-predictive band on it.
#[derive(Debug, Clone, PartialEq)]
pub struct FitRecord {
    /// File name or `scene`.
    pub name: String,
    /// Abscissa's name, e.g. `time`, `strain`.
    pub x_label: String,
    /// Abscissa's SI unit, e.g. `s`, `1`.
    pub x_unit: String,
    /// Ordinate's name, e.g. `force`.
    pub y_label: String,
    /// Ordinate's SI unit, e.g. `N`.
    pub y_unit: String,
    /// The record's abscissae (the residual points).
    pub x: Vec<f64>,
    /// The record's ordinates.
    pub y: Vec<f64>,
    /// The model at the best fit, on `x`.
    pub best: Vec<f64>,
    /// Lower edge of the 90 % posterior-predictive band on `x` (model spread + noise), may be
    /// empty.
    pub band_low: Vec<f64>,
    /// Upper edge of the band, may be empty.
    pub band_high: Vec<f64>,
    /// Noise model: standard deviation of one point, y units.
    pub noise_sd: f64,
    /// Noise model: correlation length, points.
    pub noise_correlation: f64,
    /// Noise model: factor on its variance σ²τ from simulated records (1: none).
    pub noise_calibration: f64,
    /// Fraction of points inside the band.
    pub inside_band: f64,
}

/// Everything a fit found.
#[derive(Debug, Clone, PartialEq)]
pub struct FitReport {
    /// The scene text.
    pub scene: String,
    /// The residual chosen (`force-time`, …).
    pub residual: String,
    /// The command line of the fit.
    pub command_line: String,
    /// The free parameters, in the order of the chain's last axis.
    pub parameters: Vec<FitParameter>,
    /// Walkers of the ensemble sampler.
    pub walkers: usize,
    /// Sampler steps made (all kept in `chain`).
    pub steps: usize,
    /// Steps dropped as burn-in before the posterior statistics.
    pub burn_in: usize,
    /// Steps × walkers × parameters, step-major (all steps).
    pub chain: Vec<f64>,
    /// Steps × walkers: the log posterior of each position.
    pub log_prob: Vec<f64>,
    /// Posterior Pearson matrix (after burn-in), parameters × parameters.
    pub correlations: Vec<Vec<f64>>,
    /// Fraction of the sampler's proposals accepted.
    pub acceptance: f64,
    /// Forward runs made.
    pub evaluations: usize,
    /// Least-squares cost at the best fit.
    pub best_cost: f64,
    /// The records fitted.
    pub records: Vec<FitRecord>,
    /// What the fit warned about.
    pub warnings: Vec<String>,
}

impl FitReport {
    /// The posterior samples: the chain after the burn-in, `[n, parameters]` row-major with
    /// n = (steps − burn_in) × walkers, step by step (empty when the burn-in takes every step).
    pub fn samples(&self) -> &[f64] {
        let row = self.walkers * self.parameters.len();
        let start = (self.burn_in.min(self.steps) * row).min(self.chain.len());
        &self.chain[start..]
    }

    /// The samples of parameter `k` (after the burn-in), one per walker and step.
    pub fn samples_of(&self, k: usize) -> Vec<f64> {
        let p = self.parameters.len();
        self.samples()
            .iter()
            .skip(k)
            .step_by(p.max(1))
            .copied()
            .collect()
    }

    /// The first inconsistency between the report's sizes (chain, log_prob, correlations,
    /// records, burn-in, keys), if any.
    fn inconsistency(&self) -> Option<String> {
        let p = self.parameters.len();
        let (s, w) = (self.steps, self.walkers);
        if self.chain.len() != s * w * p {
            return Some(format!(
                "chain has {} values, not steps × walkers × parameters = {s} × {w} × {p}",
                self.chain.len()
            ));
        }
        if self.log_prob.len() != s * w {
            return Some(format!(
                "log_prob has {} values, not steps × walkers = {s} × {w}",
                self.log_prob.len()
            ));
        }
        if self.burn_in > s {
            return Some(format!("burn_in {} exceeds the {s} steps", self.burn_in));
        }
        if self.correlations.len() != p || self.correlations.iter().any(|r| r.len() != p) {
            return Some(format!("correlations is not {p} × {p}"));
        }
        if let Some(k) = self
            .parameters
            .iter()
            .find(|k| k.key.is_empty() || k.key.contains('/') || k.key == "." || k.key == "..")
        {
            return Some(format!(
                "parameter key `{}` cannot name an HDF5 group (empty, `.`, `..` or with `/`)",
                k.key
            ));
        }
        for (i, a) in self.parameters.iter().enumerate() {
            if self.parameters[..i].iter().any(|b| b.key == a.key) {
                return Some(format!("parameter key `{}` appears twice", a.key));
            }
        }
        self.records.iter().find_map(|r| {
            let n = r.x.len();
            let band = r.band_low.len() == r.band_high.len()
                && (r.band_low.is_empty() || r.band_low.len() == n);
            (r.y.len() != n || r.best.len() != n || !band).then(|| {
                format!(
                    "record `{}`: x, y, best ({n}, {}, {}) and band ({}, {}) differ in length",
                    r.name,
                    r.y.len(),
                    r.best.len(),
                    r.band_low.len(),
                    r.band_high.len()
                )
            })
        })
    }
}

/// The parameters' keys.
fn keys(r: &FitReport) -> Vec<VarLenUnicode> {
    r.parameters.iter().map(|k| vlu(&k.key)).collect()
}

/// Writes a 1-D string array attribute.
fn strings_attr(
    loc: &hdf5::Location,
    name: &str,
    values: &[VarLenUnicode],
    file: &Path,
) -> Result<()> {
    loc.new_attr_builder()
        .with_data(values)
        .create(name)
        .map(|_| ())
        .map_err(h5err(file))
}

/// Writes a scalar attribute of a number type.
fn number_attr<T: hdf5::H5Type>(
    loc: &hdf5::Location,
    name: &str,
    value: T,
    file: &Path,
) -> Result<()> {
    loc.new_attr::<T>()
        .shape(())
        .create(name)
        .and_then(|a| a.write_scalar(&value))
        .map_err(h5err(file))
}

/// Writes an f64 dataset of shape `shape` (row-major `data`) with its `units` or, for a dataset
/// whose last axis runs over the parameters, their keys (`parameters`) and units (`units`).
fn write_array(
    g: &hdf5::Group,
    name: &str,
    shape: &[usize],
    data: &[f64],
    units: &str,
    columns: Option<(&[VarLenUnicode], &[VarLenUnicode])>,
    file: &Path,
) -> Result<()> {
    let array = ndarray::ArrayD::from_shape_vec(shape, data.to_vec()).map_err(|e| Error::Hdf5 {
        file: file.display().to_string(),
        message: format!("{name}: {e}"),
    })?;
    let ds = g
        .new_dataset_builder()
        .with_data(&array)
        .create(name)
        .map_err(h5err(file))?;
    match columns {
        Some((keys, units)) => {
            strings_attr(&ds, "parameters", keys, file)?;
            strings_attr(&ds, "units", units, file)
        }
        None => string_attr(&ds, "units", units, file),
    }
}

/// Writes the fit file of `r` to `path` in the layout of this module (with `/provenance` when
/// given), atomically, refusing to replace an existing file unless `force`. A report whose sizes
/// disagree (chain against steps × walkers × parameters, …) is refused before anything is written.
pub fn write_fit_hdf5(
    path: &Path,
    force: bool,
    r: &FitReport,
    provenance: Option<&shpb_input::files::Provenance>,
) -> Result<()> {
    if let Some(problem) = r.inconsistency() {
        return Err(Error::Hdf5 {
            file: path.display().to_string(),
            message: format!("fit report not written: {problem}"),
        });
    }
    let p = r.parameters.len();
    write_atomically(path, force, |tmp| {
        let f = crate::h5::create(tmp).map_err(h5err(path))?;
        string_attr(&f, "shpb_version", env!("CARGO_PKG_VERSION"), path)?;
        let g = f.create_group("fit").map_err(h5err(path))?;
        string_attr(&g, "scene", &r.scene, path)?;
        string_attr(&g, "residual", &r.residual, path)?;
        string_attr(&g, "command_line", &r.command_line, path)?;
        for (name, v) in [
            ("walkers", r.walkers),
            ("steps", r.steps),
            ("burn_in", r.burn_in),
            ("evaluations", r.evaluations),
        ] {
            number_attr(&g, name, v as u64, path)?;
        }
        number_attr(&g, "acceptance", r.acceptance, path)?;
        number_attr(&g, "best_cost", r.best_cost, path)?;
        string_attr(&g, "warnings", &r.warnings.join("\n"), path)?;
        let params = g.create_group("parameters").map_err(h5err(path))?;
        for k in &r.parameters {
            let pg = params.create_group(&k.key).map_err(h5err(path))?;
            string_attr(&pg, "unit", &k.unit, path)?;
            let mut numbers = vec![("min", k.min), ("max", k.max)];
            if let Some((mean, sd)) = k.prior_normal {
                numbers.extend([("prior_mean", mean), ("prior_sd", sd)]);
            }
            numbers.extend([
                ("value", k.best),
                ("median", k.median),
                ("band_90_low", k.band_90[0]),
                ("band_90_high", k.band_90[1]),
                ("tau_steps", k.tau_steps),
                ("ess", k.ess),
            ]);
            for (name, v) in numbers {
                number_attr(&pg, name, v, path)?;
            }
        }
        let (keys, units) = (
            keys(r),
            r.parameters
                .iter()
                .map(|k| vlu(&k.unit))
                .collect::<Vec<_>>(),
        );
        let columns = Some((keys.as_slice(), units.as_slice()));
        write_array(
            &g,
            "chain",
            &[r.steps, r.walkers, p],
            &r.chain,
            "",
            columns,
            path,
        )?;
        write_array(
            &g,
            "log_prob",
            &[r.steps, r.walkers],
            &r.log_prob,
            "1",
            None,
            path,
        )?;
        let samples = r.samples();
        let n = if p * r.walkers == 0 {
            0
        } else {
            samples.len() / p
        };
        write_array(&g, "samples", &[n, p], samples, "", columns, path)?;
        let flat: Vec<f64> = r.correlations.iter().flatten().copied().collect();
        write_array(&g, "correlations", &[p, p], &flat, "1", None, path)?;
        let records = g.create_group("records").map_err(h5err(path))?;
        for (i, rec) in r.records.iter().enumerate() {
            let rg = records.create_group(&i.to_string()).map_err(h5err(path))?;
            for (name, text) in [
                ("name", &rec.name),
                ("x_label", &rec.x_label),
                ("x_unit", &rec.x_unit),
                ("y_label", &rec.y_label),
                ("y_unit", &rec.y_unit),
            ] {
                string_attr(&rg, name, text, path)?;
            }
            for (name, v) in [
                ("noise_sd", rec.noise_sd),
                ("noise_correlation", rec.noise_correlation),
                ("noise_calibration", rec.noise_calibration),
                ("inside_band", rec.inside_band),
            ] {
                number_attr(&rg, name, v, path)?;
            }
            write_dataset(&rg, "x", &rec.x, &rec.x_unit, path)?;
            for (name, data) in [
                ("y", &rec.y),
                ("best", &rec.best),
                ("band_low", &rec.band_low),
                ("band_high", &rec.band_high),
            ] {
                write_dataset(&rg, name, data, &rec.y_unit, path)?;
            }
        }
        if let Some(prov) = provenance {
            crate::provenance::write_provenance(&f, prov, path)?;
        }
        f.close().map_err(h5err(path))
    })
}

/// Reads a fit file written by [`write_fit_hdf5`] back into the report it was written from
/// (`/fit/samples` is derived from the chain and not read; `/provenance` is read by
/// [`crate::provenance::read_provenance`]).
pub fn read_fit_hdf5(path: &Path) -> Result<FitReport> {
    let bad = |key: &str, problem: String| Error::Input {
        file: path.display().to_string(),
        key: key.to_string(),
        problem,
        allowed: "a fit file written by `shpb fit -o`".into(),
    };
    let f = crate::h5::open(path).map_err(|e| bad("file", format!("cannot open as HDF5: {e}")))?;
    let g = f
        .group("fit")
        .map_err(|_| bad("/fit", "no /fit group: not a fit file".into()))?;
    let text = |loc: &hdf5::Location, at: &str, name: &str| -> Result<String> {
        loc.attr(name)
            .and_then(|a| a.read_scalar::<VarLenUnicode>())
            .map(|s| s.as_str().to_string())
            .map_err(|e| bad(&format!("{at} attribute {name}"), e.to_string()))
    };
    let number = |loc: &hdf5::Location, at: &str, name: &str| -> Result<f64> {
        loc.attr(name)
            .and_then(|a| a.read_scalar::<f64>())
            .map_err(|e| bad(&format!("{at} attribute {name}"), e.to_string()))
    };
    let count = |name: &str| -> Result<usize> {
        g.attr(name)
            .and_then(|a| a.read_scalar::<u64>())
            .map(|v| v as usize)
            .map_err(|e| bad(&format!("/fit attribute {name}"), e.to_string()))
    };
    let data = |loc: &hdf5::Group, at: &str, name: &str| -> Result<Vec<f64>> {
        loc.dataset(name)
            .and_then(|d| d.read_raw::<f64>())
            .map_err(|e| bad(&format!("{at}/{name}"), e.to_string()))
    };
    let chain_ds = g
        .dataset("chain")
        .map_err(|e| bad("/fit/chain", e.to_string()))?;
    let order: Vec<String> = chain_ds
        .attr("parameters")
        .and_then(|a| a.read_raw::<VarLenUnicode>())
        .map(|v| v.iter().map(|s| s.as_str().to_string()).collect())
        .map_err(|e| bad("/fit/chain attribute parameters", e.to_string()))?;
    let params = g
        .group("parameters")
        .map_err(|e| bad("/fit/parameters", e.to_string()))?;
    let parameters = order
        .iter()
        .map(|key| {
            let at = format!("/fit/parameters/{key}");
            let pg = params.group(key).map_err(|e| bad(&at, e.to_string()))?;
            let n = |name: &str| number(&pg, &at, name);
            let prior_normal = if pg.attr("prior_mean").is_ok() {
                Some((n("prior_mean")?, n("prior_sd")?))
            } else {
                None
            };
            Ok(FitParameter {
                key: key.clone(),
                unit: text(&pg, &at, "unit")?,
                min: n("min")?,
                max: n("max")?,
                prior_normal,
                best: n("value")?,
                median: n("median")?,
                band_90: [n("band_90_low")?, n("band_90_high")?],
                tau_steps: n("tau_steps")?,
                ess: n("ess")?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let p = parameters.len();
    let flat = data(&g, "/fit", "correlations")?;
    let correlations = if p == 0 {
        Vec::new()
    } else {
        flat.chunks(p).map(<[f64]>::to_vec).collect()
    };
    let records_group = g
        .group("records")
        .map_err(|e| bad("/fit/records", e.to_string()))?;
    let mut names = records_group
        .member_names()
        .map_err(|e| bad("/fit/records", e.to_string()))?;
    names.sort_by_key(|n| n.parse::<usize>().unwrap_or(usize::MAX));
    let records = names
        .iter()
        .map(|i| {
            let at = format!("/fit/records/{i}");
            let rg = records_group
                .group(i)
                .map_err(|e| bad(&at, e.to_string()))?;
            let t = |name: &str| text(&rg, &at, name);
            let n = |name: &str| number(&rg, &at, name);
            let d = |name: &str| data(&rg, &at, name);
            Ok(FitRecord {
                name: t("name")?,
                x_label: t("x_label")?,
                x_unit: t("x_unit")?,
                y_label: t("y_label")?,
                y_unit: t("y_unit")?,
                x: d("x")?,
                y: d("y")?,
                best: d("best")?,
                band_low: d("band_low")?,
                band_high: d("band_high")?,
                noise_sd: n("noise_sd")?,
                noise_correlation: n("noise_correlation")?,
                // Files written before the calibration existed have none.
                noise_calibration: n("noise_calibration").unwrap_or(1.0),
                inside_band: n("inside_band")?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let warnings = text(&g, "/fit", "warnings")?;
    let report = FitReport {
        scene: text(&g, "/fit", "scene")?,
        residual: text(&g, "/fit", "residual")?,
        command_line: text(&g, "/fit", "command_line")?,
        parameters,
        walkers: count("walkers")?,
        steps: count("steps")?,
        burn_in: count("burn_in")?,
        chain: chain_ds
            .read_raw::<f64>()
            .map_err(|e| bad("/fit/chain", e.to_string()))?,
        log_prob: data(&g, "/fit", "log_prob")?,
        correlations,
        acceptance: number(&g, "/fit", "acceptance")?,
        evaluations: count("evaluations")?,
        best_cost: number(&g, "/fit", "best_cost")?,
        records,
        warnings: warnings.lines().map(str::to_string).collect(),
    };
    match report.inconsistency() {
        Some(problem) => Err(bad("/fit", problem)),
        None => Ok(report),
    }
}

/// The `--json` object of `shpb fit` (issue 44): `parameters` keyed by scene key, each with
/// `value` (the best fit), `unit` and `band_90` `[low, high]`, and `median`, `min`, `max`,
/// `prior_normal` (`[mean, sd]` or null), `tau_steps`, `ess`; the sampler's `walkers`, `steps`,
/// `burn_in`, `acceptance`, `evaluations`, `best_cost`; `correlations` (`{key: {key: r}}`);
/// `records` (name, axes, noise model, `inside_band`, `points`); `warnings`. Non-finite numbers
/// are null.
pub fn fit_json(r: &FitReport) -> Value {
    let parameters: serde_json::Map<String, Value> = r
        .parameters
        .iter()
        .map(|k| {
            (
                k.key.clone(),
                json!({
                    "value": k.best,
                    "unit": k.unit,
                    "band_90": k.band_90,
                    "median": k.median,
                    "min": k.min,
                    "max": k.max,
                    "prior_normal": k.prior_normal.map(|(m, s)| [m, s]),
                    "tau_steps": k.tau_steps,
                    "ess": k.ess,
                }),
            )
        })
        .collect();
    let correlations: serde_json::Map<String, Value> = r
        .parameters
        .iter()
        .zip(&r.correlations)
        .map(|(a, row)| {
            let row: serde_json::Map<String, Value> = r
                .parameters
                .iter()
                .zip(row)
                .map(|(b, &c)| (b.key.clone(), json!(c)))
                .collect();
            (a.key.clone(), Value::Object(row))
        })
        .collect();
    let records: Vec<Value> = r
        .records
        .iter()
        .map(|rec| {
            json!({
                "name": rec.name,
                "x": {"label": rec.x_label, "unit": rec.x_unit},
                "y": {"label": rec.y_label, "unit": rec.y_unit},
                "noise_sd": rec.noise_sd,
                "noise_correlation": rec.noise_correlation,
                "noise_calibration": rec.noise_calibration,
                "inside_band": rec.inside_band,
                "points": rec.x.len(),
            })
        })
        .collect();
    json!({
        "scene": r.scene,
        "residual": r.residual,
        "command_line": r.command_line,
        "parameters": parameters,
        "walkers": r.walkers,
        "steps": r.steps,
        "burn_in": r.burn_in,
        "acceptance": r.acceptance,
        "evaluations": r.evaluations,
        "best_cost": r.best_cost,
        "correlations": correlations,
        "records": records,
        "warnings": r.warnings,
    })
}

/// The most samples a corner plot draws in each scatter (thinned evenly beyond).
const CORNER_POINTS: usize = 5000;

/// The corner plot of a fit's posterior (PNG, atomic, no clobbering without `force`): each
/// parameter's marginal histogram after the burn-in on the diagonal, its best fit dashed and its
/// 90 % band shaded; the pairwise scatter of the samples below (at most 5000 points, best fit a
/// cross); the posterior correlations above.
pub fn corner_figure(path: &Path, force: bool, r: &FitReport) -> Result<()> {
    let columns: Vec<Vec<f64>> = (0..r.parameters.len()).map(|k| r.samples_of(k)).collect();
    let variables: Vec<CornerVariable> = r
        .parameters
        .iter()
        .zip(&columns)
        .map(|(k, samples)| CornerVariable {
            name: k.key.clone(),
            unit: k.unit.clone(),
            samples,
            best: Some(k.best),
            band: Some((k.band_90[0], k.band_90[1])),
        })
        .collect();
    let title = format!(
        "posterior: {} samples ({} walkers, steps {} to {})",
        columns.first().map_or(0, Vec::len),
        r.walkers,
        r.burn_in + 1,
        r.steps
    );
    corner_plot(
        path,
        force,
        &title,
        &variables,
        Some(&r.correlations),
        CORNER_POINTS,
    )
}

/// The records of a fit (PNG, atomic, no clobbering without `force`): one panel per record with
/// its points, the model at the best fit and the 90 % posterior-predictive band shaded, titled
/// with the record's name and the fraction of its points inside the band.
pub fn records_figure(path: &Path, force: bool, r: &FitReport) -> Result<()> {
    let panels: Vec<BandedPanel> = r
        .records
        .iter()
        .map(|rec| BandedPanel {
            title: if rec.band_low.is_empty() {
                format!("{}: best fit (no band)", rec.name)
            } else {
                format!(
                    "{}: {} % of points inside the 90 % band",
                    rec.name,
                    crate::plot::three_digits(100.0 * rec.inside_band)
                )
            },
            x_name_unit: (&rec.x_label, &rec.x_unit),
            y_name_unit: (&rec.y_label, &rec.y_unit),
            x: &rec.x,
            points: ("record".into(), &rec.y),
            line: ("best fit".into(), &rec.best),
            band: (
                "90 % posterior-predictive band".into(),
                &rec.band_low,
                &rec.band_high,
            ),
        })
        .collect();
    band_panels_figure(path, force, panels.len().clamp(1, 2), &panels)
}

/// The outputs of a fit, each when asked: `output` the fit file ([`write_fit_hdf5`]), `plot`
/// the records with the best fit and band ([`records_figure`]), `corner` the marginal and
/// pairwise posterior plots ([`corner_figure`]); refused if a file exists, unless `force`.
pub fn write_fit_outputs(
    r: &FitReport,
    output: Option<&Path>,
    plot: Option<&Path>,
    corner: Option<&Path>,
    force: bool,
) -> Result<()> {
    if let Some(p) = output {
        write_fit_hdf5(p, force, r, None)?;
    }
    if let Some(p) = plot {
        records_figure(p, force, r)?;
    }
    if let Some(p) = corner {
        corner_figure(p, force, r)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small report: 2 parameters, 3 walkers × 10 steps, 1 record of 40 points.
    fn report() -> FitReport {
        let (steps, walkers) = (10usize, 3usize);
        let mut chain = Vec::new();
        let mut log_prob = Vec::new();
        for s in 0..steps {
            for w in 0..walkers {
                let u = ((s * walkers + w) as f64 * 0.618_033_988_7).fract() - 0.5;
                chain.push(1.9e9 + 2e7 * u);
                chain.push(0.035 + 0.004 * u * u);
                log_prob.push(-0.5 * (u * 4.0).powi(2) - 3.0);
            }
        }
        let x: Vec<f64> = (0..40).map(|i| i as f64 * 1e-6).collect();
        let best: Vec<f64> = x.iter().map(|t| 1e4 * (t * 1e5).sin()).collect();
        let y: Vec<f64> = best
            .iter()
            .enumerate()
            .map(|(i, b)| b + 150.0 * ((i as f64 * 2.3).sin()))
            .collect();
        FitReport {
            scene: "kind = \"shpb\"\n".into(),
            residual: "force-time".into(),
            command_line: "shpb fit scene.toml --free specimen.yield_stress_pa=1e9:3e9".into(),
            parameters: vec![
                FitParameter {
                    key: "specimen.yield_stress_pa".into(),
                    unit: "Pa".into(),
                    min: 1e9,
                    max: 3e9,
                    prior_normal: None,
                    best: 1.9e9,
                    median: 1.901e9,
                    band_90: [1.89e9, 1.91e9],
                    tau_steps: 2.5,
                    ess: 12.0,
                },
                FitParameter {
                    key: "specimen.jc_c".into(),
                    unit: "1".into(),
                    min: 0.0,
                    max: 0.1,
                    prior_normal: Some((0.035, 0.01)),
                    best: 0.035,
                    median: 0.0355,
                    band_90: [0.035, 0.036],
                    tau_steps: 3.0,
                    ess: 10.0,
                },
            ],
            walkers,
            steps,
            burn_in: 4,
            chain,
            log_prob,
            correlations: vec![vec![1.0, 0.2], vec![0.2, 1.0]],
            acceptance: 0.41,
            evaluations: 123,
            best_cost: 4.5,
            records: vec![FitRecord {
                name: "2013-05-22_sample1_ss440c.csv".into(),
                x_label: "time".into(),
                x_unit: "s".into(),
                y_label: "force".into(),
                y_unit: "N".into(),
                band_low: best.iter().map(|b| b - 300.0).collect(),
                band_high: best.iter().map(|b| b + 300.0).collect(),
                x,
                y,
                best,
                noise_sd: 150.0,
                noise_correlation: 1.5,
                noise_calibration: 1.7,
                inside_band: 0.95,
            }],
            warnings: vec!["first warning".into(), "second warning".into()],
        }
    }

    #[test]
    fn a_fit_file_reads_back_as_the_report_it_was_written_from() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fit.h5");
        let r = report();
        let provenance = shpb_input::files::Provenance {
            scene_file: "scene.toml".into(),
            fidelity_override: None,
            command_line: r.command_line.clone(),
            inputs: vec![shpb_input::files::InputFile {
                name: "scene.toml".into(),
                text: r.scene.clone(),
            }],
        };
        write_fit_hdf5(&path, false, &r, Some(&provenance)).unwrap();
        assert_eq!(read_fit_hdf5(&path).unwrap(), r);
        assert_eq!(
            crate::provenance::read_provenance(&path).unwrap(),
            provenance
        );
        // The samples are the chain's last 6 steps: 6 × 3 rows of 2, the first row step 4's.
        let f = hdf5::File::open(&path).unwrap();
        let samples = f.dataset("fit/samples").unwrap();
        assert_eq!(samples.shape(), vec![18, 2]);
        assert_eq!(samples.read_raw::<f64>().unwrap(), r.chain[4 * 3 * 2..]);
        assert_eq!(f.dataset("fit/chain").unwrap().shape(), vec![10, 3, 2]);
        let jc = f.group("fit/parameters/specimen.jc_c").unwrap();
        assert_eq!(
            jc.attr("prior_sd").unwrap().read_scalar::<f64>().unwrap(),
            0.01
        );
        let ys = f.group("fit/parameters/specimen.yield_stress_pa").unwrap();
        assert!(
            ys.attr("prior_mean").is_err(),
            "no prior given, none written"
        );
        // Without --force an existing file is kept; with it, replaced.
        let mut other = r.clone();
        other.best_cost = 1.0;
        assert!(matches!(
            write_fit_hdf5(&path, false, &other, None),
            Err(Error::OutputExists(_))
        ));
        write_fit_hdf5(&path, true, &other, None).unwrap();
        assert_eq!(read_fit_hdf5(&path).unwrap().best_cost, 1.0);
    }

    #[test]
    fn a_least_squares_only_fit_without_warnings_or_band_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fit.h5");
        let mut r = report();
        (r.steps, r.burn_in) = (0, 0);
        r.chain.clear();
        r.log_prob.clear();
        r.warnings.clear();
        r.records[0].band_low.clear();
        r.records[0].band_high.clear();
        write_fit_hdf5(&path, false, &r, None).unwrap();
        assert_eq!(read_fit_hdf5(&path).unwrap(), r);
    }

    #[test]
    fn a_report_whose_sizes_disagree_is_refused_before_writing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fit.h5");
        let mut r = report();
        r.chain.pop();
        let e = write_fit_hdf5(&path, false, &r, None).unwrap_err();
        assert!(
            e.to_string().contains("steps × walkers × parameters"),
            "{e}"
        );
        assert!(!path.exists());
        let mut r = report();
        r.parameters[1].key = "a/b".into();
        assert!(write_fit_hdf5(&path, false, &r, None).is_err());
        assert!(!path.exists());
    }

    #[test]
    fn the_json_gives_each_parameter_its_value_unit_and_band() {
        let mut r = report();
        r.parameters[1].band_90[1] = f64::NAN;
        r.parameters[0].ess = f64::INFINITY;
        let j = fit_json(&r);
        let params = j["parameters"].as_object().unwrap();
        assert_eq!(params.len(), 2);
        for (key, p) in params {
            assert!(p["value"].is_number(), "{key}");
            assert!(p["unit"].is_string(), "{key}");
            let band = p["band_90"].as_array().unwrap();
            assert_eq!(band.len(), 2, "{key}");
        }
        let ys = &j["parameters"]["specimen.yield_stress_pa"];
        assert_eq!(ys["value"], 1.9e9);
        assert_eq!(ys["unit"], "Pa");
        assert_eq!(ys["band_90"], json!([1.89e9, 1.91e9]));
        assert!(ys["ess"].is_null(), "infinity is null");
        assert!(ys["prior_normal"].is_null());
        let c = &j["parameters"]["specimen.jc_c"];
        assert_eq!(c["band_90"][0], 0.035);
        assert!(c["band_90"][1].is_null(), "NaN is null");
        assert_eq!(c["prior_normal"], json!([0.035, 0.01]));
        for key in [
            "scene",
            "residual",
            "walkers",
            "steps",
            "burn_in",
            "acceptance",
            "evaluations",
            "best_cost",
            "records",
            "warnings",
        ] {
            assert!(!j[key].is_null(), "{key}");
        }
        assert_eq!(j["walkers"], 3);
        assert_eq!(j["records"][0]["points"], 40);
        assert_eq!(j["records"][0]["inside_band"], 0.95);
        assert_eq!(
            j["correlations"]["specimen.jc_c"]["specimen.yield_stress_pa"],
            0.2
        );
        assert_eq!(j["warnings"], json!(["first warning", "second warning"]));
    }

    /// Whether `path` holds a PNG (its eight-byte signature) of a sensible size.
    fn is_png(path: &Path) -> bool {
        let bytes = std::fs::read(path).unwrap();
        bytes.starts_with(b"\x89PNG\r\n\x1a\n") && bytes.len() > 1000
    }

    /// How many pixels of the PNG at `path` are within 6 of `colour` in each channel.
    fn pixels_of(path: &Path, colour: [u8; 3]) -> usize {
        let img = image::open(path).unwrap().to_rgb8();
        img.pixels()
            .filter(|p| (0..3).all(|c| p.0[c].abs_diff(colour[c]) <= 6))
            .count()
    }

    #[test]
    fn the_figures_draw_histograms_scatters_points_line_and_band() {
        let dir = tempfile::tempdir().unwrap();
        let r = report();
        let corner = dir.path().join("corner.png");
        corner_figure(&corner, false, &r).unwrap();
        // Histogram bars (blue at 0.6 on white), the best fit's dashed line and crosses (red).
        assert!(pixels_of(&corner, [120, 156, 222]) > 500, "histograms");
        assert!(pixels_of(&corner, [200, 30, 30]) > 50, "best fit marks");
        let records = dir.path().join("records.png");
        records_figure(&records, false, &r).unwrap();
        // The band (blue at 0.25 on white) is a fill a reader tells from the black line; the
        // record's points are dark red.
        let band = pixels_of(&records, [199, 214, 241]);
        assert!(band > 2000, "band fill: {band} pixels");
        assert!(pixels_of(&records, [170, 20, 20]) > 100, "points");
        // One parameter, a band the sampler could not give (NaN): still a figure.
        let mut one = r.clone();
        one.parameters[0].band_90 = [f64::NAN, f64::NAN];
        one.parameters.truncate(1);
        one.chain = r.samples_of(0);
        one.chain.splice(0..0, vec![1.9e9; 4 * 3]);
        one.correlations = vec![vec![1.0]];
        corner_figure(&dir.path().join("one.png"), false, &one).unwrap();
        let mut bare = r.clone();
        bare.records[0].band_low.clear();
        bare.records[0].band_high.clear();
        records_figure(&records, true, &bare).unwrap();
        assert_eq!(pixels_of(&records, [199, 214, 241]), 0, "no band drawn");
    }

    #[test]
    fn the_figures_are_pngs_that_refuse_to_clobber() {
        let dir = tempfile::tempdir().unwrap();
        let r = report();
        type Figure = fn(&Path, bool, &FitReport) -> Result<()>;
        let writers: [(&str, Figure); 2] = [
            ("corner.png", corner_figure),
            ("records.png", records_figure),
        ];
        for (name, write) in writers {
            let path = dir.path().join(name);
            write(&path, false, &r).unwrap();
            assert!(is_png(&path), "{name}");
            let before = std::fs::read(&path).unwrap();
            assert!(
                matches!(write(&path, false, &r), Err(Error::OutputExists(_))),
                "{name}"
            );
            assert_eq!(std::fs::read(&path).unwrap(), before, "{name} kept");
            write(&path, true, &r).unwrap();
            assert!(is_png(&path), "{name}");
        }
    }
}
