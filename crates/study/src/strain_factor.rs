//! The strain factor of each gauge channel from paired records of the same shot: one file in
//! volts, one in strain or microstrain (as Yao et al. keep `raw_voltage.*` beside
//! `raw_microstrain.*` / `raw_strain.*`). Each channel's factor k (strain per volt at the
//! recorder, tension positive) is the least-squares slope of ε = k·V + b over every sample
//! (the intercept b absorbs a baseline offset between the two files), with its standard error
//! and the residual; a set-up takes it as `bridge = "linear"`, `strain_per_volt = k`.

use shpb_input::layout::LayoutRecord;
use shpb_input::{Error, Result};
use std::path::Path;

/// The least-squares strain factor of one channel (ε = k·V + b over the samples).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelFactor {
    /// k, strain per volt at the recorder (tension positive).
    pub strain_per_volt: f64,
    /// Standard error of k: √(s²/Σ(V − V̄)²), s² = Σ residual²/(n − 2).
    pub standard_error: f64,
    /// The intercept b, strain (a baseline offset between the two files).
    pub offset_strain: f64,
    /// Root-mean-square residual √(Σ residual²/n), strain.
    pub residual_rms_strain: f64,
    /// Samples fitted.
    pub samples: usize,
}

/// The strain factors of both channels of a shot ([`strain_factor`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StrainFactor {
    /// The record in volts, as named.
    pub volts_file: String,
    /// The record in strain, as named.
    pub strains_file: String,
    /// The incident channel's factor.
    pub incident: ChannelFactor,
    /// The transmission channel's factor.
    pub transmission: ChannelFactor,
}

/// The least-squares line ε = k·V + b through paired samples (module docs), or None for fewer
/// than three samples, different lengths, or volts without spread.
pub fn fit_channel(volts: &[f64], strains: &[f64]) -> Option<ChannelFactor> {
    let n = volts.len();
    if n < 3 || strains.len() != n {
        return None;
    }
    let ones = vec![1.0; n];
    let beta = shpb_core::numeric::least_squares(&[volts, &ones], strains)?;
    let (k, b) = (beta[0], beta[1]);
    let rss: f64 = volts
        .iter()
        .zip(strains)
        .map(|(v, e)| (e - k * v - b).powi(2))
        .sum();
    let mean = volts.iter().sum::<f64>() / n as f64;
    let sxx: f64 = volts.iter().map(|v| (v - mean).powi(2)).sum();
    Some(ChannelFactor {
        strain_per_volt: k,
        standard_error: (rss / (n - 2) as f64 / sxx).sqrt(),
        offset_strain: b,
        residual_rms_strain: (rss / n as f64).sqrt(),
        samples: n,
    })
}

/// The strain factor of each channel from a record in volts and one in strain of the same shot,
/// each read by [`shpb_input::sheet::read_record`] without a layout (columns named with their
/// units); their time axes must agree sample by sample (within 1 % of a step).
pub fn strain_factor(volts: &Path, strains: &Path) -> Result<StrainFactor> {
    let refuse = |file: &Path, problem: &str, allowed: &str| Error::Input {
        file: file.display().to_string(),
        key: "record".into(),
        problem: problem.to_string(),
        allowed: allowed.to_string(),
    };
    let LayoutRecord::Voltages(v) = shpb_input::sheet::read_record(volts, None)? else {
        return Err(refuse(
            volts,
            "holds strains, not volts",
            "the shot's record in V or mV first, then its record in strain",
        ));
    };
    let LayoutRecord::Strains(e) = shpb_input::sheet::read_record(strains, None)? else {
        return Err(refuse(
            strains,
            "holds volts, not strains",
            "the shot's record in strain or microstrain second",
        ));
    };
    // Both records checked for plausibility (a clipped or dead channel would bias the fit, a
    // strain record in µε under a strain header would scale it by 10⁶).
    {
        use shpb_core::reduce::plausibility::{Channel, check_channels};
        let baseline_samples = shpb_core::reduce::ReductionOptions::default().baseline_samples;
        let channel = |name, time_s, strain, volts| Channel {
            name,
            time_s,
            strain,
            volts,
            youngs_modulus_pa: None,
            baseline_samples,
            smoothing_window_s: shpb_core::reduce::DEFAULT_SMOOTHING_S,
            pulse_due_s: None,
        };
        check_channels(
            &[
                channel("incident", &v.time_s, &v.incident_v, true),
                channel("transmission", &v.time_s, &v.transmission_v, true),
            ],
            &volts.display().to_string(),
        )?;
        check_channels(
            &[
                channel("incident", &e.time_s, &e.incident_strain, false),
                channel("transmission", &e.time_s, &e.transmission_strain, false),
            ],
            &strains.display().to_string(),
        )?;
    }
    let n = v.time_s.len();
    let step = (v.time_s[n - 1] - v.time_s[0]) / (n - 1) as f64;
    if e.time_s.len() != n
        || v.time_s
            .iter()
            .zip(&e.time_s)
            .any(|(a, b)| (a - b).abs() > 0.01 * step)
    {
        return Err(refuse(
            strains,
            &format!(
                "its {} samples are not at the times of the {n} samples of {}",
                e.time_s.len(),
                volts.display()
            ),
            "two records of the same shot, sample by sample",
        ));
    }
    let fit = |volts_v: &[f64], strain: &[f64], name: &str| {
        fit_channel(volts_v, strain).ok_or_else(|| {
            refuse(
                volts,
                &format!("the {name} channel's volts do not vary"),
                "a shot's record (pulses on both channels)",
            )
        })
    };
    Ok(StrainFactor {
        volts_file: volts.display().to_string(),
        strains_file: strains.display().to_string(),
        incident: fit(&v.incident_v, &e.incident_strain, "incident")?,
        transmission: fit(&v.transmission_v, &e.transmission_strain, "transmission")?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slope_its_error_and_the_residual_of_a_known_line() {
        // ε = 4.96e-4·V − 2e-6 plus alternating ±1e-7 noise, over a ramp of volts.
        let volts: Vec<f64> = (0..2001).map(|i| -1.0 + i as f64 * 1e-3).collect();
        let noise = |i: usize| if i.is_multiple_of(2) { 1e-7 } else { -1e-7 };
        let strains: Vec<f64> = volts
            .iter()
            .enumerate()
            .map(|(i, v)| 4.96e-4 * v - 2e-6 + noise(i))
            .collect();
        let f = fit_channel(&volts, &strains).unwrap();
        // The ±1e-7 pattern is nearly orthogonal to the ramp: k and b within its size / spread.
        assert!((f.strain_per_volt - 4.96e-4).abs() < 1e-9, "{f:?}");
        assert!((f.offset_strain + 2e-6).abs() < 1e-9, "{f:?}");
        // The residual is the noise: RMS 1e-7.
        assert!((f.residual_rms_strain - 1e-7).abs() < 1e-9, "{f:?}");
        // Standard error √(s²/Sxx) with s ≈ 1e-7, Sxx = Σ(V − V̄)² = 2001·(2001² − 1)/12·1e-6.
        let sxx = 2001.0 * (2001.0f64.powi(2) - 1.0) / 12.0 * 1e-6;
        let expected = 1e-7 * (2001.0 / 1999.0f64).sqrt() / sxx.sqrt();
        assert!(
            (f.standard_error / expected - 1.0).abs() < 1e-3,
            "{} vs {expected}",
            f.standard_error
        );
        assert_eq!(f.samples, 2001);
        assert!(fit_channel(&[1.0, 1.0, 1.0], &[0.0, 1.0, 2.0]).is_none());
        assert!(fit_channel(&[1.0, 2.0], &[0.0, 1.0]).is_none());
    }
}
