//! Wave speed and effective gauge distances from pulse arrivals (docs/physics.md §7.6): on each
//! shot, with the feet `shpb reduce` measures its delays by,
//! - the incident bar's far-end reflection comes 2 L_I/c0 after the incident foot → c0 (L_I from
//!   the base set-up); written as the density ρ = E/c0² (E kept: it sets the stress of a strain);
//! - the reflected foot comes 2 d_I/c0 after it → the incident gauge's distance d_I;
//! - on shots with the bars pressed together (`bars_together`), the transmitted foot comes
//!   d_I/c0 + d_T/c0 after it → the transmission gauge's distance d_T.
//!
//! Each is the mean over the shots that show it; its 1-sigma is the standard error of that mean
//! from the shots' scatter (one shot: a sample step over √12 per foot), with c0's carried into the
//! distances. The distances are effective: they absorb any offset between the feet of pulses of
//! different shapes.

use super::{Calibrator, Data, Fitted, SdFrom, ShotData, mean, sample_sd};
use shpb_input::Result;

/// The arrival calibration (registered in [`super::CALIBRATIONS`]).
pub struct ArrivalFit;

/// The per-shot values of one arrival, their mean and its 1-sigma.
struct Estimate {
    mean: f64,
    sd: f64,
    from: SdFrom,
    n: usize,
}

/// Mean and 1-sigma of per-shot values: the standard error of the mean from their scatter, or
/// for a single shot `resolution` (the sampling's).
fn estimate(values: &[f64], resolution: f64) -> Option<Estimate> {
    if values.is_empty() {
        return None;
    }
    let n = values.len();
    let (sd, from) = match sample_sd(values) {
        // The scatter of a few shots can come out below the sampling's resolution.
        Some(s) => (
            (s / (n as f64).sqrt()).max(resolution / (n as f64).sqrt()),
            SdFrom::Scatter,
        ),
        None => (resolution, SdFrom::Resolution),
    };
    Some(Estimate {
        mean: mean(values),
        sd,
        from,
        n,
    })
}

/// The delays of `pick` on the shots that show one (and pass `keep`), with the shots.
fn delays(
    data: &Data,
    pick: impl Fn(&ShotData) -> Option<f64>,
    keep: impl Fn(&ShotData) -> bool,
) -> (Vec<f64>, Vec<&ShotData>) {
    data.shots
        .iter()
        .filter(|s| keep(s))
        .filter_map(|s| pick(s).map(|d| (d, s)))
        .unzip()
}

impl Calibrator for ArrivalFit {
    fn name(&self) -> &'static str {
        "arrivals"
    }

    fn skip_reason(&self, data: &Data, _: &[Fitted]) -> Option<String> {
        let any = data.shots.iter().any(|s| {
            let a = &s.arrivals;
            a.reflected_delay_s.is_some()
                || a.incident_echo_delay_s.is_some()
                || (s.shot.bars_together && a.transmitted_delay_s.is_some())
        });
        (!any).then(|| {
            "no shot shows a reflected pulse, the incident bar's far-end reflection or (bars \
             together) a transmitted pulse"
                .into()
        })
    }

    fn fit(&self, data: &Data, _: &[Fitted], progress: &mut dyn FnMut(&str)) -> Result<super::Fit> {
        let a = &data.base;
        let dt = data
            .shots
            .iter()
            .map(|s| s.arrivals.dt_s)
            .fold(0.0, f64::max);
        // Two feet per delay, each uncertain by a uniform sample step.
        let resolution = dt * (2.0f64 / 12.0).sqrt();
        let length = a.incident.length_m;
        let mut out = Vec::new();

        let (echo, echo_shots) = delays(data, |s| s.arrivals.incident_echo_delay_s, |_| true);
        let base_c = a.material.wave_speed_m_s();
        let (c, sd_c) = match estimate(&echo, resolution) {
            Some(e) => {
                let c = 2.0 * length / e.mean;
                let sd_c = c * e.sd / e.mean;
                let rho = a.material.youngs_modulus_pa / (c * c);
                progress(&format!(
                    "arrivals: c0 = {c:.1} ± {sd_c:.1} m/s from the far-end reflection on {} shots",
                    e.n
                ));
                out.push(Fitted {
                    key: "material.density_kg_m3".into(),
                    value: rho,
                    unit: "kg/m^3",
                    sd: Some(2.0 * rho * sd_c / c),
                    sd_from: e.from,
                    fitted_on: format!(
                        "rho = E/c0^2 with c0 = {c:.1} +- {sd_c:.1} m/s (was {base_c:.1}) from \
                         the incident bar's far-end reflection, 2 L_I/c0 after the incident \
                         foot (L_I = {length} m), on {}",
                        data.on(echo_shots)
                    ),
                    uncertain: true,
                });
                (c, sd_c)
            }
            None => (base_c, 0.0),
        };

        let channel = |name: &str| {
            a.gauges
                .channel(name)
                .map_or(0.0, |ch| ch.distance_from_specimen_m)
        };
        let (refl, refl_shots) = delays(data, |s| s.arrivals.reflected_delay_s, |_| true);
        let d_i = match estimate(&refl, resolution) {
            Some(e) => {
                let d = 0.5 * c * e.mean;
                let sd = ((0.5 * c * e.sd).powi(2) + (0.5 * e.mean * sd_c).powi(2)).sqrt();
                out.push(Fitted {
                    key: "gauges.incident.distance_from_specimen_m".into(),
                    value: d,
                    unit: "m",
                    sd: Some(sd),
                    sd_from: e.from,
                    fitted_on: format!(
                        "reflected foot 2 d_I/c0 = {:.2} us after the incident foot (was {} m), \
                         on {}",
                        e.mean * 1e6,
                        channel("incident"),
                        data.on(refl_shots)
                    ),
                    uncertain: true,
                });
                Some((d, sd))
            }
            None => None,
        };

        let (trans, trans_shots) = delays(
            data,
            |s| s.arrivals.transmitted_delay_s,
            |s| s.shot.bars_together,
        );
        if let Some(e) = estimate(&trans, resolution) {
            let (di, sd_di) = d_i.unwrap_or((channel("incident"), 0.0));
            let d = c * e.mean - di;
            let sd = ((c * e.sd).powi(2) + (e.mean * sd_c).powi(2) + sd_di.powi(2)).sqrt();
            out.push(Fitted {
                key: "gauges.transmission.distance_from_specimen_m".into(),
                value: d,
                unit: "m",
                sd: Some(sd),
                sd_from: e.from,
                fitted_on: format!(
                    "transmitted foot (d_I + d_T)/c0 = {:.2} us after the incident foot, bars \
                     together (was {} m), on {}",
                    e.mean * 1e6,
                    channel("transmission"),
                    data.on(trans_shots)
                ),
                uncertain: true,
            });
        }
        Ok(out.into())
    }
}
