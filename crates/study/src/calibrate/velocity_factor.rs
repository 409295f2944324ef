//! The incident gauge's strain factor from measured striker velocities (docs/physics.md §6.3): a
//! striker of the bars' material and section A_s hitting the bar (section A_b) without a shaper
//! sends a plateau of strain ε = v A_s / ((A_s + A_b) c0), v/(2c0) for equal sections. On each
//! shot the plateau's voltage (the mean over the middle half of the span above half the peak,
//! read through the base channel and turned back into volts) gives the factor
//! `strain_per_volt` = −ε/V (tension positive); the value is the mean over the shots, its 1-sigma
//! the standard error of that mean from their scatter. Written as a linear channel
//! (`bridge = "linear"`, `strain_per_volt`).
//!
//! The factor from paired volt and strain files (`--paired VOLTS STRAINS`) is the other route,
//! `crate::strain_factor` (helper RECORDS), wired in by the command.

use super::{Calibrator, Data, Fitted, SdFrom, mean, sample_sd};
use shpb_input::{Error, Result};

/// The velocity strain-factor calibration (registered in [`super::CALIBRATIONS`]).
pub struct VelocityFactor;

/// Mean of the middle half of the span where `y` (compression positive) stays above half its
/// peak: the plateau of an unshaped incident pulse; None without a pulse.
pub fn plateau(y: &[f64]) -> Option<f64> {
    let peak = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if peak.is_nan() || peak <= 0.0 {
        return None;
    }
    let first = y.iter().position(|&v| v >= 0.5 * peak)?;
    let last = first
        + y[first..]
            .iter()
            .position(|&v| v < 0.5 * peak)
            .unwrap_or(y.len() - first)
        - 1;
    let span = last - first;
    let (a, b) = (first + span / 4, last - span / 4);
    (b > a).then(|| mean(&y[a..=b]))
}

/// Plateau strain of a striker of section `striker_m2` hitting a bar of section `bar_m2`, both
/// of wave speed `c0`, at `v` (compression positive): v A_s/((A_s + A_b) c0).
pub fn plateau_strain(v: f64, striker_m2: f64, bar_m2: f64, c0: f64) -> f64 {
    v * striker_m2 / ((striker_m2 + bar_m2) * c0)
}

impl Calibrator for VelocityFactor {
    fn name(&self) -> &'static str {
        "strain-factor"
    }

    fn skip_reason(&self, data: &Data, _: &[Fitted]) -> Option<String> {
        if data.base.shaper.is_some() {
            return Some(
                "the base set-up has a pulse shaper: the plateau v/(2c0) holds without one".into(),
            );
        }
        (!data.shots.iter().any(|s| s.shot.velocity_m_s.is_some()))
            .then(|| "no shot gives striker_velocity_m_s".into())
    }

    fn fit(&self, data: &Data, _: &[Fitted], progress: &mut dyn FnMut(&str)) -> Result<super::Fit> {
        let a = &data.base;
        let ch = a.gauges.channel("incident").ok_or_else(|| Error::Input {
            file: a.source.clone(),
            key: "gauges".into(),
            problem: "no `incident` channel".into(),
            allowed: "a gauge set-up with an incident channel".into(),
        })?;
        let c0 = a.material.wave_speed_m_s();
        let e = a.material.youngs_modulus_pa;
        let mut factors = Vec::new();
        let mut ratios = Vec::new();
        let mut used = Vec::new();
        for s in &data.shots {
            let Some(v) = s.shot.velocity_m_s else {
                continue;
            };
            let (_, stress) = super::incident_pulse(a, s);
            let Some(read_pa) = plateau(&stress) else {
                return Err(Error::Input {
                    file: s.shot.file.display().to_string(),
                    key: "incident_V".into(),
                    problem: "no incident pulse with a plateau".into(),
                    allowed: "an incident record of an unshaped shot".into(),
                });
            };
            let read = read_pa / e;
            let truth = plateau_strain(v, a.striker.area_m2(), a.incident.area_m2(), c0);
            let volts = ch.voltage_from_strain(-read);
            factors.push(-truth / volts);
            ratios.push(truth / read);
            used.push(s);
        }
        let f = mean(&factors);
        let (sd, from) = match sample_sd(&factors) {
            Some(sd) => (Some(sd / (factors.len() as f64).sqrt()), SdFrom::Scatter),
            None => (None, SdFrom::Scatter),
        };
        progress(&format!(
            "strain-factor: {f:.4e} strain/V from {} shots ({:.3}x the base channel's reading)",
            factors.len(),
            mean(&ratios)
        ));
        Ok(vec![Fitted {
            key: "gauges.incident.strain_per_volt".into(),
            value: f,
            unit: "1/V",
            sd,
            sd_from: from,
            fitted_on: format!(
                "incident plateau = v A_s/((A_s + A_b) c0) (v/(2c0) for equal sections) at the \
                 measured striker velocities, {:.3}x the base channel's reading, on {}",
                mean(&ratios),
                data.on(used)
            ),
            uncertain: true,
        }]
        .into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plateau_of_a_trapezoid_is_its_top() {
        let y: Vec<f64> = (0..400)
            .map(|k| match k {
                0..100 => 0.0,
                100..120 => (k - 100) as f64 / 20.0,
                120..300 => 1.0,
                300..320 => (320 - k) as f64 / 20.0,
                _ => 0.0,
            })
            .collect();
        assert!((plateau(&y).unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(plateau(&[0.0, -1.0]), None);
        // Equal sections: v/(2 c0).
        assert!((plateau_strain(5.0, 2.0, 2.0, 5000.0) - 5e-4).abs() < 1e-15);
    }
}
