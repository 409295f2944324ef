//! `shpb incident`: the incident pulse a force–approach record implies.

use super::common::{finite, gun_shot, load_apparatus, report};
use shpb_input::csv::SignConvention;
use shpb_input::{Error, Result, Validator};
use std::path::Path;

/// `shpb incident`: the incident pulse a force–approach record implies (reduce::implied_incident).
pub fn incident(
    record: &Path,
    bars: &Path,
    pressure: Option<&str>,
    smoothing_us: f64,
) -> Result<()> {
    let apparatus = load_apparatus(bars)?;
    let smoothing_s = Validator::new("command line").in_range(
        "--smoothing-us",
        smoothing_us,
        0.0,
        1000.0,
        "µs",
    )? * 1e-6;
    // Every input is checked before anything is printed.
    let gun_velocity = match pressure {
        Some(text) => Some(gun_shot(&apparatus, text)?.1),
        None => None,
    };
    let table = shpb_input::csv::CsvTable::read(record)?;
    let time = table.time_column("time_s")?;
    // Compression positive, or refused naming the file and column (a record with compression
    // negative would otherwise imply a plausible-looking pulse of the wrong sign).
    let compression = |name: &str| {
        table.compression_column(
            name,
            SignConvention::CompressionPositive,
            "negate the column: shpb incident reads force_N and displacement_m compression positive",
        )
    };
    let displacement = compression("displacement_m")?;
    let force = compression("force_N")?;
    let bar = shpb_core::reduce::ReductionSetup::from_apparatus(&apparatus)?.incident_bar;
    let pulse = shpb_core::reduce::implied_incident(time, &displacement, &force, &bar, smoothing_s)
        .ok_or_else(|| Error::Input {
            file: table.file.clone(),
            key: "force_N".into(),
            problem: "the record implies no compressive incident pulse".into(),
            allowed: "a loading record: force and approach growing from the start".into(),
        })?;
    let c0 = bar.wave_speed_m_s;
    let rho_c = bar.youngs_modulus_pa / c0;
    let mut text = String::new();
    text.push_str(&format!(
        "record              {} ({} samples, {:.3} µs apart)",
        record.display(),
        time.len(),
        (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64 * 1e6
    ));
    text.push('\n');
    text.push_str(&format!(
        "incident peak       {:.1} MPa at {:.1} µs",
        pulse.peak_pa / 1e6,
        pulse.peak_time_s * 1e6
    ));
    text.push('\n');
    text.push_str(&format!(
        "plateau             {:.1} MPa (mean over the width at half peak)",
        pulse.mean_over_half_pa / 1e6
    ));
    text.push('\n');
    text.push_str(&format!(
        "width at half peak  {:.1} µs",
        pulse.duration_half_s * 1e6
    ));
    text.push('\n');
    text.push_str(&format!("impulse             {:.4} N s", pulse.impulse_n_s));
    text.push('\n');
    text.push_str(&format!("energy              {:.3} J", pulse.energy_j));
    text.push('\n');
    // An unshaped striker of the bar's impedance gives a square pulse: ρ c0 v / 2 for 2 L / c0.
    let length_m = 0.5 * c0 * pulse.duration_half_s;
    let velocity = 2.0 * pulse.mean_over_half_pa / rho_c;
    let mass = apparatus.material.density_kg_m3 * bar.area_m2 * length_m;
    text.push_str(&format!(
        "unshaped striker    {:.3} m at {:.2} m/s would give that plateau and width \
         (momentum {:.3} N s, energy {:.2} J)",
        length_m,
        velocity,
        mass * velocity,
        0.5 * mass * velocity * velocity
    ));
    text.push('\n');
    let mut striker_check = serde_json::Value::Null;
    if let Some(v0) = gun_velocity {
        let m = apparatus.striker_mass_kg();
        let most = shpb_core::striker::most_pulse_energy_j(m, v0, pulse.impulse_n_s);
        text.push_str(&format!(
            "set-up's striker    {:.3} m, {:.4} kg at {v0:.3} m/s: momentum {:.3} N s, energy {:.2} J",
            apparatus.striker.length_m,
            m,
            m * v0,
            0.5 * m * v0 * v0
        ));
        text.push('\n');
        text.push_str(&format!(
            "  giving this impulse it can put at most {most:.2} J into the bar: {}",
            if pulse.energy_j > most {
                "the record's pulse is NOT possible with this striker at this pressure"
            } else {
                "possible"
            }
        ));
        text.push('\n');
        striker_check = serde_json::json!({
            "length_m": apparatus.striker.length_m,
            "mass_kg": m,
            "velocity_m_s": v0,
            "most_pulse_energy_J": finite(most),
            "possible": pulse.energy_j <= most,
        });
    }
    report(&text, || {
        serde_json::json!({
            "record": record.display().to_string(),
            "samples": time.len(),
            "incident_peak_Pa": finite(pulse.peak_pa),
            "incident_peak_time_s": finite(pulse.peak_time_s),
            "plateau_Pa": finite(pulse.mean_over_half_pa),
            "width_at_half_peak_s": finite(pulse.duration_half_s),
            "impulse_N_s": finite(pulse.impulse_n_s),
            "energy_J": finite(pulse.energy_j),
            "unshaped_striker": {
                "length_m": finite(length_m),
                "velocity_m_s": finite(velocity),
            },
            "set_up_striker": striker_check,
        })
    })
}
