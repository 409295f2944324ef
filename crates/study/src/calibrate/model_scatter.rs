//! The shots' scatter about the calibrated model (docs/physics.md §10.6): when the shots of a
//! manifest name their virtual tests (`scene`), each is run on the calibrated set-up and its
//! incident peak and energy and its reflected and transmitted delays are compared with the
//! record's. What the calibration cannot fit (the model's misfit from shot to shot, its bias on a
//! delay, the shot-to-shot scatter itself) is then in the `[uncertainty.scatter]` a prediction
//! carries, rather than only the records' within-pressure scatter.
//!
//! For each output the 1-sigma is s · t₀.₉₅(ν)/z₀.₉₅ with s² = Σ r²/ν, ν = n − 1 (n − 2 for the
//! transmitted delay when [`super::specimen_arrivals`] fitted its mean), over the n shots
//! that have it, r = (measured − simulated)/simulated for the peak and energy (relative) and
//! measured − simulated for the delays (s): the bias is not removed (the band is centred on the
//! model), and the Student factor makes the normal band value ± 1.645 σ of a new shot the
//! t-interval a scatter estimated from n shots gives (n − 1 degrees of freedom: the residuals are
//! in-sample). The parameters' own uncertainty is propagated beside it (`band`), not in it.

use super::setup_file;
use super::{Calibration, Data, ShotData, incident_pulse};
use crate::uq::student_t_quantile;
use rayon::prelude::*;
use shpb_core::apparatus::Apparatus;
use shpb_core::reduce::{ReductionOptions, ReductionSetup};
use shpb_core::scene::SceneParams;
use shpb_core::uncertainty::SCATTER_OUTPUTS;
use shpb_input::{Error, Result};

/// One shot's measured and simulated outputs, in the order of [`SCATTER_OUTPUTS`].
#[derive(Debug, Clone)]
pub struct ShotResiduals {
    /// The shot's label.
    pub label: String,
    /// The record's values (None where it shows none).
    pub measured: [Option<f64>; 4],
    /// The virtual test's on the calibrated set-up.
    pub simulated: [Option<f64>; 4],
}

/// What [`about_model`] found.
#[derive(Debug, Clone)]
pub struct ModelScatter {
    /// `[uncertainty.scatter]` keys and their 1-sigma (relative or s).
    pub scatter: Vec<(&'static str, f64)>,
    /// Each shot's values.
    pub shots: Vec<ShotResiduals>,
}

/// A record's measured outputs, in the order of [`SCATTER_OUTPUTS`]: the incident peak as the
/// calibration reads it (largest −E ε of [`incident_pulse`], unsmoothed), the incident energy by
/// the run summary's rule (E A c0 ∫ε² dt of the incident wave of `shpb reduce`'s reduction of the
/// record), the reflected and transmitted delays `shpb reduce` measures (feet after the incident
/// foot), the rules a run's `incident_peak_stress`, `incident_energy`, `reflected_delay` and
/// `transmitted_delay` follow.
pub fn measured(a: &Apparatus, s: &ShotData) -> Result<[Option<f64>; 4]> {
    let (_, y) = incident_pulse(a, s);
    let peak = y.iter().copied().reduce(f64::max);
    let setup = ReductionSetup::from_apparatus(a)?;
    let r = shpb_core::reduce::reduce(&s.input, &setup, &ReductionOptions::default())?;
    let energy =
        shpb_core::reduce::wave_metrics(&r.time_s, &r.incident_strain, &setup.incident_bar, true)
            .map(|m| m.energy_j);
    Ok([
        peak,
        energy,
        s.arrivals.reflected_delay_s,
        s.arrivals.transmitted_delay_s,
    ])
}

/// The base set-up's texts, as `shpb calibrate` read them ([`setup_file::read_base`]): name,
/// text and the gauge file's text.
pub type BaseTexts = (String, String, Option<String>);

/// Every shot of `data` that names its virtual test, run on the set-up calibrated with `c`'s
/// constants ([`setup_file::rewrite`] of the base texts, written to a temporary directory, each
/// scene's `bars` replaced by it; summary-only runs in parallel), beside [`measured`].
pub fn simulate(data: &Data, c: &Calibration) -> Result<Vec<ShotResiduals>> {
    let shots: Vec<&ShotData> = data
        .shots
        .iter()
        .filter(|s| s.shot.scene.is_some())
        .collect();
    if shots.is_empty() {
        return Ok(Vec::new());
    }
    let base = data.base_texts.as_ref().ok_or_else(|| Error::Input {
        file: data.base.source.clone(),
        key: "scene".into(),
        problem: "the base set-up's file cannot be read again for the shots' virtual tests".into(),
        allowed: "a base set-up file that stays readable, or shots without `scene`".into(),
    })?;
    let dir = tempfile::tempdir().map_err(|e| Error::io(std::path::Path::new("."), e))?;
    let gauges_name = "calibrated-gauges.toml";
    let texts = setup_file::rewrite(&base.1, &base.0, base.2.as_deref(), gauges_name, c, "")?;
    let setup = dir.path().join("calibrated.toml");
    std::fs::write(&setup, &texts.setup).map_err(|e| Error::io(&setup, e))?;
    if let Some(g) = &texts.gauges {
        let p = dir.path().join(gauges_name);
        std::fs::write(&p, g).map_err(|e| Error::io(&p, e))?;
    }
    let bars = shpb_input::scene::Value::String(setup.display().to_string());
    shots
        .par_iter()
        .map(|s| {
            let scene = s.shot.scene.as_deref().expect("filtered on scene");
            let (params, _) = crate::api::load_scene(
                crate::api::Scene::File(scene),
                None,
                &[("bars".to_string(), bars.clone())],
                String::new(),
            )?;
            if !matches!(params.params, SceneParams::Pulse { .. }) {
                return Err(not_a_bar_test(scene));
            }
            let out = params.summary_only().run()?;
            Ok(ShotResiduals {
                label: s.shot.label.clone(),
                measured: measured(&data.base, s)?,
                simulated: SCATTER_OUTPUTS.map(|(_, key, _)| out.summary_value(key)),
            })
        })
        .collect()
}

/// The residual of output `i` ([`SCATTER_OUTPUTS`] order) of one shot: relative to the
/// simulated value for the peak and energy, measured − simulated (s) for the delays.
pub fn residual(s: &ShotResiduals, i: usize) -> Option<f64> {
    let (m, y) = (s.measured[i]?, s.simulated[i]?);
    let r = if SCATTER_OUTPUTS[i].2 {
        (m - y) / y
    } else {
        m - y
    };
    r.is_finite().then_some(r)
}

/// The shots' scatter about the model calibrated with `c`, when shots of `data` name their
/// virtual test ([`simulate`]); None when none does. An output shown by too few shots gets no
/// scatter; the transmitted delay loses one more degree of freedom when
/// [`super::specimen_arrivals`] fitted its mean away.
pub fn about_model(data: &Data, c: &Calibration) -> Result<Option<ModelScatter>> {
    let shots = simulate(data, c)?;
    if shots.is_empty() {
        return Ok(None);
    }
    let dated = c
        .ran
        .iter()
        .any(|(n, skipped)| *n == super::specimen_arrivals::NAME && skipped.is_none());
    let mut scatter = Vec::new();
    for (i, (key, _, _)) in SCATTER_OUTPUTS.iter().enumerate() {
        let r: Vec<f64> = shots.iter().filter_map(|s| residual(s, i)).collect();
        let fitted = usize::from(dated && *key == "transmitted_delay_s");
        if let Some(sd) = predictive_sd(&r, fitted) {
            scatter.push((*key, sd));
        }
    }
    Ok(Some(ModelScatter { scatter, shots }))
}

/// The 1-sigma of a new shot about the model from in-sample residuals `r` (module docs), of
/// which `fitted` constants were fitted to remove a part: √(Σ r²/ν) · t₀.₉₅(ν)/z₀.₉₅ with
/// ν = n − 1 − `fitted`; None without a degree of freedom or with all residuals zero.
pub fn predictive_sd(r: &[f64], fitted: usize) -> Option<f64> {
    let n = r.len();
    if n < 2 + fitted {
        return None;
    }
    let dof = (n - 1 - fitted) as f64;
    let s = (r.iter().map(|x| x * x).sum::<f64>() / dof).sqrt();
    (s > 0.0).then(|| s * student_t_quantile(0.95, dof) / crate::band::Z_90)
}

/// The error of a shot whose `scene` is not a test with bars.
fn not_a_bar_test(scene: &std::path::Path) -> Error {
    Error::Input {
        file: scene.display().to_string(),
        key: "kind".into(),
        problem: "not a test with bars".into(),
        allowed: "a full virtual test of the shot (a scene with `bars`)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_predictive_sd_is_the_t_interval_of_the_residuals() {
        // Residuals ±1 (n = 4): s = √(4/3); t₀.₉₅(3) = 2.3534 over z = 1.6449.
        let sd = predictive_sd(&[1.0, -1.0, 1.0, -1.0], 0).unwrap();
        assert!((sd - (4.0f64 / 3.0).sqrt() * 2.353363 / 1.644854).abs() < 2e-3);
        // One constant fitted to them: ν = 2, s = √2, t₀.₉₅(2) = 2.919986.
        let sd = predictive_sd(&[1.0, -1.0, 1.0, -1.0], 1).unwrap();
        assert!((sd - 2f64.sqrt() * 2.919986 / 1.644854).abs() < 2e-3);
        assert_eq!(predictive_sd(&[0.5], 0), None);
        assert_eq!(predictive_sd(&[0.5, 0.2], 1), None);
        assert_eq!(predictive_sd(&[0.0, 0.0], 0), None);
    }
}
