//! 90 % bands of a virtual test's summary from the set-up's stated uncertainty
//! (docs/physics.md §10.6): first-order (linearised) propagation by central differences, one run
//! at each of value ± 1 sd of every uncertain input, the outputs' shot-to-shot scatter added in
//! quadrature, band = value ± 1.645 σ ([`predict_with`]); [`monte_carlo`] draws the same inputs
//! for the check of that approximation (validation/bands/REPORT.md).
//!
//! The inputs are the set-up's `[uncertainty]` constants ([`shpb_core::uncertainty`]) and, when
//! the scene fires the set-up's gun, the gun's shot-to-shot scatter of the striker velocity
//! (`[gun] velocity_scatter`, [`VELOCITY_SCATTER`]). The band runs are summary-only: no x–t
//! snapshots, no files.

use crate::uq::{Rng, mean_sd, normal_quantile, percentile};
use rayon::prelude::*;
use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_core::uncertainty::Uncertainty;
use shpb_input::files::{InputFile, Provenance};
use shpb_input::{Error, Result};
use std::path::Path;

/// The summary values a run's bands are given for (docs/physics.md §10.6).
pub const BANDED: [&str; 7] = [
    "incident_peak_stress",
    "incident_energy",
    "reflected_delay",
    "transmitted_delay",
    "reduced_peak_back_force",
    "reduced_displacement_at_peak_force",
    "reduced_equilibrium_ratio_at_peak",
];

/// The standard normal quantile of 95 %: a 90 % two-sided band is value ± Z_90 σ.
pub const Z_90: f64 = 1.644_853_626_951_472_2;

/// The input name of the gun's shot-to-shot scatter: the striker velocity over its nominal
/// value (value 1, sd `velocity_scatter`).
pub const VELOCITY_SCATTER: &str = "gun.velocity_scatter";

/// One uncertain input of a scene's bands: a set-up key (or [`VELOCITY_SCATTER`]), its value and
/// its 1-sigma.
#[derive(Debug, Clone, PartialEq)]
pub struct BandInput {
    /// The dotted set-up key, or [`VELOCITY_SCATTER`].
    pub key: String,
    /// The nominal value (SI; 1 for the velocity scatter).
    pub value: f64,
    /// 1-sigma, same unit.
    pub sd: f64,
}

/// The band of one summary value.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// The summary key (`incident_peak_stress`).
    pub key: String,
    /// Unit of the summary value.
    pub unit: &'static str,
    /// The nominal run's value.
    pub value: f64,
    /// Its 1-sigma: every input's share and the scatter in quadrature.
    pub sd: f64,
    /// Each input's share, (y(x + sd) − y(x − sd))/2, in the order of [`Prediction::inputs`].
    pub shares: Vec<f64>,
    /// The output's stated shot-to-shot scatter, 1-sigma (0: none).
    pub scatter_sd: f64,
    /// value − 1.645 σ, value + 1.645 σ.
    pub band_90: [f64; 2],
}

/// What [`predict_with`] found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Prediction {
    /// The inputs, in the order of each band's shares.
    pub inputs: Vec<BandInput>,
    /// One band per [`BANDED`] value the nominal run and every band run have.
    pub bands: Vec<Band>,
    /// Band runs made (two per input).
    pub runs: usize,
    /// Why a value has no band (a band run failed or lacks it).
    pub warnings: Vec<String>,
}

/// The uncertain inputs of `params`: its set-up's `[uncertainty]` constants that the scene uses
/// (the gun's, `gun.*`, only when it fires the gun: a pressure; the shaper's, `shaper.*`, not in a
/// test a recorded wave drives, which has neither) and, when the scene fires the gun of a set-up
/// stating a velocity scatter, that scatter. Empty for a scene without bars.
pub fn inputs(params: &Params) -> Vec<BandInput> {
    let SceneParams::Pulse {
        apparatus,
        pressure_pa,
        options,
    } = &params.params
    else {
        return Vec::new();
    };
    let gun = pressure_pa.is_finite() && options.incident_drive.is_none();
    let driven = options.incident_drive.is_some();
    let mut v: Vec<BandInput> = apparatus
        .uncertainty
        .iter()
        .flat_map(|u| &u.inputs)
        .filter(|i| !(i.key.starts_with("gun.") && !gun || i.key.starts_with("shaper.") && driven))
        .map(|i| BandInput {
            key: i.key.clone(),
            value: i.value,
            sd: i.sd,
        })
        .collect();
    if let Some(s) = apparatus.gun_velocity_scatter
        && s > 0.0
        && gun
    {
        v.push(BandInput {
            key: VELOCITY_SCATTER.into(),
            value: 1.0,
            sd: s,
        });
    }
    v
}

/// The set-up's `[uncertainty]` of a bar scene, if it states one.
pub fn uncertainty(params: &Params) -> Option<&Uncertainty> {
    match &params.params {
        SceneParams::Pulse { apparatus, .. } => apparatus.uncertainty.as_ref(),
        _ => None,
    }
}

/// A scene moved to `values` (set-up keys at new values; [`VELOCITY_SCATTER`] scales the
/// striker velocity): what the band and Monte-Carlo runs call.
pub type Perturb<'a> = dyn Fn(&[(String, f64)]) -> Result<Params> + Sync + 'a;

/// Scales the striker velocity of a bar scene by `factor` (the gun's shot-to-shot scatter).
fn scale_velocity(params: &mut Params, factor: f64) {
    if let SceneParams::Pulse { options, .. } = &mut params.params {
        options.striker_velocity_m_s *= factor;
    }
}

/// The scene of `params`, loaded with `provenance` (what `api::load_scene` returned), moved to
/// `values`: the set-up's text among the stored inputs gets each key's new value
/// (`shpb_input::uncertainty::with_value`) and the scene is read again from the inputs
/// (`files::replay`), so that every quantity the loader derives from the set-up (the gun's
/// striker velocity, the shaper's faces) follows; then [`VELOCITY_SCATTER`] scales the striker
/// velocity.
pub fn reload(
    params: &Params,
    provenance: &Provenance,
    values: &[(String, f64)],
) -> Result<Params> {
    let SceneParams::Pulse { apparatus, .. } = &params.params else {
        return Ok(params.clone());
    };
    let name = shpb_input::uncertainty::input_name(&apparatus.source);
    let mut inputs: Vec<InputFile> = provenance.inputs.clone();
    let mut velocity = 1.0;
    let set_up: Vec<&(String, f64)> = values
        .iter()
        .filter(|(k, _)| k != VELOCITY_SCATTER)
        .collect();
    for (k, x) in values {
        if k == VELOCITY_SCATTER {
            velocity *= x;
        }
    }
    if !set_up.is_empty() {
        let file = inputs
            .iter_mut()
            .find(|f| f.name == name)
            .ok_or_else(|| Error::Input {
                file: apparatus.source.clone(),
                key: "uncertainty".into(),
                problem: "the set-up's text is not among the inputs the scene read".into(),
                allowed: "a scene loaded through shpb_study::api::load_scene".into(),
            })?;
        let mut text = file.text.clone();
        for (k, x) in set_up {
            text = shpb_input::uncertainty::with_value(&text, &apparatus.source, k, *x)?;
        }
        file.text = text;
    }
    let fidelity: Vec<(String, shpb_input::scene::Value)> = provenance
        .fidelity_override
        .iter()
        .map(|f| {
            (
                "fidelity".to_string(),
                shpb_input::scene::Value::String(f.clone()),
            )
        })
        .collect();
    let mut moved = shpb_input::files::replay(&inputs, || {
        use shpb_input::prelude::*;
        Params::from_file_overridden(Path::new(&provenance.scene_file), &fidelity)
    })?;
    scale_velocity(&mut moved, velocity);
    Ok(moved)
}

/// The correlation matrix (row-major) of `inputs` as `u` states it (1 on the diagonal, a pair
/// not listed and the gun's velocity scatter independent).
pub fn correlation_matrix(inputs: &[BandInput], u: Option<&Uncertainty>) -> Vec<f64> {
    let keys: Vec<&str> = inputs.iter().map(|i| i.key.as_str()).collect();
    shpb_core::uncertainty::correlation_matrix(u.map_or(&[][..], |u| &u.correlations), &keys)
}

/// σ² of the inputs' shares s (docs/physics.md §10.6): Σ_ij s_i s_j r_ij, r the stated
/// correlations (Σ s_i² when none is stated).
pub fn correlated_variance(inputs: &[BandInput], shares: &[f64], u: Option<&Uncertainty>) -> f64 {
    let n = shares.len();
    let r = correlation_matrix(&inputs[..n], u);
    let mut v = 0.0;
    for i in 0..n {
        for j in 0..n {
            v += shares[i] * shares[j] * r[i * n + j];
        }
    }
    v.max(0.0)
}

/// The bands of `nominal`'s [`BANDED`] values (a run of the scene `perturb` moves) for `inputs` and the outputs'
/// `scatter` (docs/physics.md §10.6): for each input i, runs at x_i ± sd_i (the others at their
/// values) give its share s_i = (y₊ − y₋)/2; σ² = Σ_ij s_i s_j r_ij + scatter² (r the stated
/// correlations of `scatter`'s set-up, else independent); band = y ± 1.645 σ. The
/// 2n runs are summary-only (no snapshots) and run in parallel (rayon's pool). A value some run
/// lacks (a pulse whose foot it cannot find) gets no band and a warning; a band run that fails
/// leaves every band out, with the error as a warning.
pub fn predict_with(
    nominal: &RunOutput,
    inputs: &[BandInput],
    scatter: Option<&Uncertainty>,
    perturb: &Perturb,
) -> Prediction {
    let mut prediction = Prediction {
        inputs: inputs.to_vec(),
        runs: 2 * inputs.len(),
        ..Default::default()
    };
    let jobs: Vec<(usize, f64)> = (0..inputs.len())
        .flat_map(|i| [(i, -1.0), (i, 1.0)])
        .collect();
    let runs: Vec<Result<RunOutput>> = jobs
        .par_iter()
        .map(|&(i, sign)| {
            let input = &inputs[i];
            let moved = perturb(&[(input.key.clone(), input.value + sign * input.sd)])?;
            Ok(moved.summary_only().run()?)
        })
        .collect();
    let mut outs = Vec::with_capacity(runs.len());
    for (r, &(i, sign)) in runs.into_iter().zip(&jobs) {
        match r {
            Ok(o) => outs.push(o),
            Err(e) => {
                let input = &inputs[i];
                prediction.warnings.push(format!(
                    "no 90 % bands: the band run with {} = {:e} failed: {e}",
                    input.key,
                    input.value + sign * input.sd
                ));
                return prediction;
            }
        }
    }
    for key in BANDED {
        let Some(item) = nominal.summary.iter().find(|s| s.key == key) else {
            continue;
        };
        let mut shares = Vec::with_capacity(inputs.len());
        for (i, input) in inputs.iter().enumerate() {
            match (
                outs[2 * i].summary_value(key),
                outs[2 * i + 1].summary_value(key),
            ) {
                (Some(lo), Some(hi)) if lo.is_finite() && hi.is_finite() => {
                    shares.push(0.5 * (hi - lo))
                }
                _ => {
                    prediction.warnings.push(format!(
                        "no 90 % band for {key}: a band run with {} moved by one sd has none",
                        input.key
                    ));
                    break;
                }
            }
        }
        if shares.len() < inputs.len() || !item.value.is_finite() {
            continue;
        }
        let scatter_sd = scatter
            .and_then(|u| u.scatter_of(key))
            .map_or(0.0, |s| s.sd_at(item.value));
        let sd = (correlated_variance(inputs, &shares, scatter) + scatter_sd * scatter_sd).sqrt();
        prediction.bands.push(Band {
            key: key.to_string(),
            unit: item.unit,
            value: item.value,
            sd,
            shares,
            scatter_sd,
            band_90: [item.value - Z_90 * sd, item.value + Z_90 * sd],
        });
    }
    prediction
}

/// [`predict_with`] for a scene loaded by `api::load_scene` (`provenance` its inputs): the
/// set-up's own `[uncertainty]` and gun scatter ([`inputs`]), the scene moved by [`reload`].
/// None when the set-up states no uncertainty (nor a gun scatter the scene uses).
pub fn predict(
    params: &Params,
    nominal: &RunOutput,
    provenance: &Provenance,
) -> Option<Prediction> {
    let inputs = inputs(params);
    let u = uncertainty(params);
    if inputs.is_empty() && u.is_none_or(|u| u.scatter.is_empty()) {
        return None;
    }
    Some(predict_with(nominal, &inputs, u, &|values| {
        reload(params, provenance, values)
    }))
}

/// Writes each band into its summary item's `band_90`, and the prediction's warnings after the
/// run's.
pub fn apply(out: &mut RunOutput, prediction: &Prediction) {
    for b in &prediction.bands {
        if let Some(item) = out.summary.iter_mut().find(|s| s.key == b.key) {
            item.band_90 = Some(b.band_90);
        }
    }
    out.warnings.extend(prediction.warnings.iter().cloned());
}

/// A Monte-Carlo ensemble of the same inputs: `n` runs with every input drawn at once, normal
/// with the correlations `u` states (seeded [`Rng`], Φ⁻¹ of uniforms, through the Cholesky
/// factor of the correlation matrix; independent when none is stated), each value's sample
/// values per [`BANDED`] key (the keys every run has). What the linear bands are checked
/// against (validation/bands/REPORT.md).
pub fn monte_carlo(
    inputs: &[BandInput],
    u: Option<&Uncertainty>,
    n: usize,
    seed: u64,
    perturb: &Perturb,
) -> Result<Vec<(String, Vec<f64>)>> {
    let mut rng = Rng::new(seed);
    let m = inputs.len();
    let r = nalgebra::DMatrix::from_row_slice(m, m, &correlation_matrix(inputs, u));
    // A semi-definite matrix (r = ±1) gets a tiny diagonal so that Cholesky exists.
    let l = r
        .clone()
        .cholesky()
        .or_else(|| (r + nalgebra::DMatrix::identity(m, m) * 1e-12).cholesky())
        .map(|c| c.l())
        .ok_or_else(|| Error::Input {
            file: "[uncertainty]".into(),
            key: "correlation".into(),
            problem: "the correlation matrix is not positive semi-definite".into(),
            allowed: "the correlations of one covariance matrix".into(),
        })?;
    let draws: Vec<Vec<(String, f64)>> = (0..n)
        .map(|_| {
            let z: Vec<f64> = (0..m).map(|_| normal_quantile(rng.uniform())).collect();
            inputs
                .iter()
                .enumerate()
                .map(|(i, input)| {
                    let zi: f64 = (0..=i).map(|j| l[(i, j)] * z[j]).sum();
                    (input.key.clone(), input.value + input.sd * zi)
                })
                .collect()
        })
        .collect();
    let outs: Vec<RunOutput> = draws
        .par_iter()
        .map(|values| Ok(perturb(values)?.summary_only().run()?))
        .collect::<Result<_>>()?;
    Ok(BANDED
        .iter()
        .filter_map(|key| {
            let y: Option<Vec<f64>> = outs.iter().map(|o| o.summary_value(key)).collect();
            y.map(|y| (key.to_string(), y))
        })
        .collect())
}

/// Mean, sd and the 5th and 95th percentiles of a Monte-Carlo sample.
pub fn sample_stats(y: &[f64]) -> (f64, f64, f64, f64) {
    let (mean, sd) = mean_sd(y);
    let mut sorted = y.to_vec();
    sorted.sort_by(f64::total_cmp);
    (
        mean,
        sd,
        percentile(&sorted, 0.05),
        percentile(&sorted, 0.95),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn correlated_shares_add_by_their_correlation() {
        use shpb_core::uncertainty::Correlation;
        let inputs: Vec<BandInput> = ["k", "p", "d"]
            .iter()
            .map(|k| BandInput {
                key: k.to_string(),
                value: 1.0,
                sd: 0.1,
            })
            .collect();
        let u = Uncertainty {
            fitted_on: "x".into(),
            shots: 2,
            inputs: vec![],
            correlations: vec![Correlation {
                a: "p".into(),
                b: "k".into(),
                r: 0.8,
            }],
            scatter: vec![],
        };
        // Var(a k + b p + c d) = a² + b² + c² + 2ab r_kp for unit shares' sds.
        let s = [3.0, -2.0, 1.0];
        let v = correlated_variance(&inputs, &s, Some(&u));
        assert!((v - (9.0 + 4.0 + 1.0 + 2.0 * 3.0 * -2.0 * 0.8)).abs() < 1e-12);
        assert!((correlated_variance(&inputs, &s, None) - 14.0).abs() < 1e-12);
    }

    #[test]
    fn z_90_is_the_95th_percentile_of_the_normal() {
        assert!((normal_quantile(0.95) - Z_90).abs() < 1e-8);
    }
}
