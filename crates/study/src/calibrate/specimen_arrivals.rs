//! The transmission gauge's effective distance from specimen shots (docs/physics.md §7.6): when
//! no shot has the bars pressed together, the transmitted foot includes the specimen's transit,
//! which only the shot's virtual test knows. Each shot naming its test (`scene`) is run on the
//! set-up calibrated so far ([`super::model_scatter::simulate`]); the simulated transmitted delay
//! moves one for one with d_T/c0, so d_T = d_T,0 + c0 · mean(measured − simulated transmitted
//! delay), with 1-sigma c0 · sd/√n (standard error of the mean over the n shots). Like the other
//! effective distances it absorbs any offset between the feet of the recorded and the simulated
//! pulse shapes; it runs after the gun and the shaper, whose pulse shape it dates.

use super::model_scatter::{residual, simulate};
use super::{Calibration, Calibrator, Data, Fitted, SdFrom, mean, sample_sd};
use shpb_input::Result;

/// The calibration's name (`calibrate = ["specimen-arrivals"]`).
pub const NAME: &str = "specimen-arrivals";

/// Key of the constant it fits.
const KEY: &str = "gauges.transmission.distance_from_specimen_m";

/// Index of the transmitted delay in `SCATTER_OUTPUTS`.
const TRANSMITTED: usize = 3;

/// The specimen-arrival calibration (registered in [`super::CALIBRATIONS`]).
pub struct SpecimenArrivals;

impl Calibrator for SpecimenArrivals {
    fn name(&self) -> &'static str {
        NAME
    }

    fn skip_reason(&self, data: &Data, earlier: &[Fitted]) -> Option<String> {
        if earlier.iter().any(|f| f.key == KEY) {
            return Some("the transmission gauge was dated by shots with the bars together".into());
        }
        let n = data
            .shots
            .iter()
            .filter(|s| {
                s.shot.scene.is_some()
                    && !s.shot.bars_together
                    && s.arrivals.transmitted_delay_s.is_some()
            })
            .count();
        if n < 2 {
            return Some(
                "needs two or more specimen shots that name their virtual test (`scene`) and show \
                 a transmitted pulse"
                    .into(),
            );
        }
        data.base_texts
            .is_none()
            .then(|| "the base set-up's file cannot be read again for the virtual tests".into())
    }

    fn fit(
        &self,
        data: &Data,
        earlier: &[Fitted],
        progress: &mut dyn FnMut(&str),
    ) -> Result<super::Fit> {
        let so_far = Calibration {
            fitted_on: data.fitted_on.clone(),
            shots: data.shots.len(),
            constants: earlier.to_vec(),
            correlations: Vec::new(),
            scatter: Vec::new(),
            ran: Vec::new(),
        };
        let sims = simulate(data, &so_far)?;
        let (r, labels): (Vec<f64>, Vec<&str>) = sims
            .iter()
            .zip(data.shots.iter().filter(|s| s.shot.scene.is_some()))
            .filter(|(_, s)| !s.shot.bars_together)
            .filter_map(|(x, s)| residual(x, TRANSMITTED).map(|r| (r, s.shot.label.as_str())))
            .unzip();
        let a = &data.base;
        let density = earlier
            .iter()
            .find(|f| f.key == "material.density_kg_m3")
            .map_or(a.material.density_kg_m3, |f| f.value);
        let c0 = (a.material.youngs_modulus_pa / density).sqrt();
        let d0 = a
            .gauges
            .channel("transmission")
            .map_or(0.0, |c| c.distance_from_specimen_m);
        let (b, n) = (mean(&r), r.len());
        let sd = sample_sd(&r).map(|s| c0 * s / (n as f64).sqrt());
        let d = d0 + c0 * b;
        progress(&format!(
            "{NAME}: transmitted pulses {:+.2} us against the virtual tests on {n} shots: \
             d_T = {d:.4} m (was {d0} m)",
            b * 1e6
        ));
        Ok(vec![Fitted {
            key: KEY.into(),
            value: d,
            unit: "m",
            sd,
            sd_from: SdFrom::Scatter,
            fitted_on: format!(
                "transmitted foot {:+.2} us against each shot's virtual test on the set-up \
                 calibrated so far (was {d0} m, c0 = {c0:.1} m/s), on {}",
                b * 1e6,
                labels.join(", ")
            ),
            uncertain: true,
        }]
        .into())
    }
}
