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
    let (gun_pressure, gun_velocity) = match pressure {
        Some(text) => {
            let (p, v) = gun_shot(&apparatus, text)?;
            (Some(p), Some(v))
        }
        None => (None, None),
    };
    let table = shpb_input::csv::CsvTable::read(record)?;
    let time = table.time_column("time_s")?;
    table.check_time_span("time_s", time)?;
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
    // A `shpb reduce --csv` table has the 3-wave force: with it, σI = F3/A + ρ c0 δ̇/2 is exactly
    // the incident pulse the gauges measured, with no equilibrium assumed (physics.md §7.4).
    let force = if table.optional_column("force_N").is_none()
        && table.optional_column("force_3wave_N").is_some()
    {
        compression("force_3wave_N")?
    } else {
        compression("force_N")?
    };
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
    // Which striker: the shape, free of amplitude and gun (striker::pulse_shape, physics.md §6.4).
    let shape = shpb_core::striker::pulse_shape(time, &pulse.stress_pa);
    let verdict = shape
        .as_ref()
        .map(shpb_core::striker::StrikerVerdict::from_shape);
    if let (Some(sh), Some(vd)) = (&shape, verdict) {
        text.push_str(&format!(
            "record starts at    {:.0} % of the peak (the rise needs < 10 %)\n\
             rise 10-90 %        {:.1} µs = {:.2} of the width at half peak (unshaped below {}, \
             shaped above {})",
            100.0 * sh.start_fraction,
            sh.rise_s * 1e6,
            sh.rise_fraction(),
            shpb_core::striker::UNSHAPED_MAX_RISE_FRACTION,
            shpb_core::striker::SHAPED_MIN_RISE_FRACTION
        ));
        text.push('\n');
        text.push_str(&format!(
            "width at 10 %       {:.1} µs; effective duration (∫σ)²/∫σ² {:.1} µs = {:.2} × width \
             at half peak (rectangle 1, triangle 1.5)",
            sh.width_10_s * 1e6,
            sh.effective_duration_s * 1e6,
            sh.squareness()
        ));
        text.push('\n');
        text.push_str(&format!(
            "striker verdict     {} ({})",
            vd.name(),
            match vd {
                shpb_core::striker::StrikerVerdict::Unshaped => "steep rise and plateau: a striker on the bar, no shaper",
                shpb_core::striker::StrikerVerdict::Shaped => "ramped rise: a pulse shaper",
                shpb_core::striker::StrikerVerdict::Inconclusive => "between the thresholds",
                shpb_core::striker::StrikerVerdict::EdgeMissing => "the record starts after the pulse's foot: rise unmeasurable; see momentum and energy",
            }
        ));
        text.push('\n');
    }
    let mut striker_check = serde_json::Value::Null;
    let mut long_check = serde_json::Value::Null;
    let mut energy_verdict = None;
    let mut energy_fraction = None;
    if let (Some(v0), Some(p)) = (gun_velocity, gun_pressure) {
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
        // The gas's work W(p) goes whole into the bar only from an unshaped striker that stops; a
        // copper shaper dissipates part of it (physics.md §6.4).
        let work = apparatus.gun.kinetic_energy_j(p, bar.area_m2);
        let fraction = pulse.energy_j / work;
        let ev = shpb_core::striker::StrikerVerdict::from_energy_fraction(fraction);
        text.push_str(&format!(
            "energy / gas work   {:.2} of W = {work:.2} J (unshaped above {}, shaped below {}): {}",
            fraction,
            shpb_core::striker::UNSHAPED_MIN_ENERGY_FRACTION,
            shpb_core::striker::SHAPED_MAX_ENERGY_FRACTION,
            ev.name()
        ));
        text.push('\n');
        energy_verdict = Some(ev);
        energy_fraction = Some(fraction);
        // The same gun firing the unshaped striker the width implies: it gets the gas's work W(p)
        // (½ m v² = W, striker.rs) and, stopping, gives its momentum √(2 m W) and all of W.
        if let Ok(v_long) = apparatus.gun.striker_velocity_m_s(p, mass, bar.area_m2) {
            let (i_long, e_long) = (mass * v_long, 0.5 * mass * v_long * v_long);
            text.push_str(&format!(
                "gun's {:.3} m striker {v_long:.3} m/s, unshaped: momentum {i_long:.3} N s, energy \
                 {e_long:.2} J; the record's are {:+.1} %, {:+.1} % of those",
                length_m,
                100.0 * (pulse.impulse_n_s / i_long - 1.0),
                100.0 * (pulse.energy_j / e_long - 1.0)
            ));
            text.push('\n');
            long_check = serde_json::json!({
                "length_m": finite(length_m),
                "velocity_m_s": finite(v_long),
                "impulse_N_s": finite(i_long),
                "energy_J": finite(e_long),
            });
        }
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
            "shape": shape.map(|sh| serde_json::json!({
                "rise_10_90_s": finite(sh.rise_s),
                "width_10_s": finite(sh.width_10_s),
                "effective_duration_s": finite(sh.effective_duration_s),
                "rise_fraction": finite(sh.rise_fraction()),
                "squareness": finite(sh.squareness()),
                "start_fraction": finite(sh.start_fraction),
            })),
            "striker_verdict": verdict.map(|v| v.name()),
            "energy_fraction_of_gun_work": energy_fraction.map(finite),
            "energy_verdict": energy_verdict.map(|v| v.name()),
            "gun_unshaped_striker": long_check,
        })
    })
}
