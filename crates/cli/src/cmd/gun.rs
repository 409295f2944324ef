//! `shpb gun`: the striker velocity the gas gun gives at a pressure.

use super::common::{gun_shot, load_apparatus, say};
use shpb_core::striker::{ATMOSPHERE_PA, Gun, PSI_PA};
use shpb_input::Result;
use std::path::Path;

/// `shpb gun --pressure P [--bars SET-UP]`: pressure, the gas's work, striker velocity, energy and
/// momentum, the elastic bar stress and length of an unshaped pulse, and the same gun firing
/// strikers of half and twice the length (½ m v² = W(p), docs/physics.md §6.4).
pub fn gun(pressure: &str, bars: &Path) -> Result<()> {
    let apparatus = load_apparatus(bars)?;
    let (p, v) = gun_shot(&apparatus, pressure)?;
    let m = apparatus.striker_mass_kg();
    let area = apparatus.striker.area_m2();
    let e = 0.5 * m * v * v;
    let c0 = apparatus.material.wave_speed_m_s();
    let z = apparatus.material.density_kg_m3 * c0;
    say(&format!(
        "pressure            {:.4} psi = {:.1} kPa (gauge)",
        p / PSI_PA,
        p / 1e3
    ))?;
    say(&format!(
        "gas work W(p)       {:.4} J on any striker (½ m v² = W, docs/physics.md §6.4)",
        apparatus.gun.kinetic_energy_j(p, area)
    ))?;
    say(&format!(
        "striker             {:.3} m, {m:.4} kg",
        apparatus.striker.length_m
    ))?;
    say(&format!("striker velocity    {v:.4} m/s"))?;
    say(&format!("striker energy      {e:.4} J"))?;
    say(&format!("striker momentum    {:.4} N s", m * v))?;
    say(&format!(
        "elastic bar stress  {:.2} MPa for {:.1} µs (ρ c0 v / 2 for 2 L / c0, without shaper)",
        0.5 * z * v / 1e6,
        2.0 * apparatus.striker.length_m / c0 * 1e6
    ))?;
    for factor in [0.5, 2.0] {
        let vf = apparatus
            .gun
            .striker_velocity_m_s(p, factor * m, area)
            .map_err(shpb_input::Validator::new("command line").core("--pressure"))?;
        say(&format!(
            "  a {:.3} m striker  {vf:.4} m/s, {:.4} J, {:.4} N s",
            factor * apparatus.striker.length_m,
            0.5 * factor * m * vf * vf,
            factor * m * vf
        ))?;
    }
    match apparatus.gun {
        Gun::Linear(g) => {
            say(&format!(
                "gun                 calibration line v² = k (m_ref/m)(p − p_loss): k {:.4e} m²/s²/Pa, \
                 p_loss {:.2} kPa, m_ref {:.4} kg",
                g.k_m2_per_s2_per_pa,
                g.loss_pressure_pa / 1e3,
                g.calibration_mass_kg
            ))?;
            if let Some(a) = g.equivalent_adiabatic(area, 1.4, ATMOSPHERE_PA) {
                say(&format!(
                    "  as a frictionless adiabatic gun (γ 1.4): reservoir V0 {:.3e} m³, barrel \
                     {:.3} m ({:.3e} m³ swept)",
                    a.reservoir_volume_m3,
                    a.barrel_length_m,
                    a.barrel_length_m * area
                ))?;
            }
        }
        Gun::Adiabatic(g) => {
            say(&format!(
                "gun                 adiabatic (γ {}): reservoir V0 {:.3e} m³, barrel {:.3} m, \
                 friction {:.1} N",
                g.gamma, g.reservoir_volume_m3, g.barrel_length_m, g.friction_n
            ))?;
        }
        Gun::None => {}
    }
    Ok(())
}
