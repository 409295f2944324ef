//! `shpb gun`: the striker velocity the gas gun gives at a pressure.

use super::common::{gun_shot, load_apparatus, say};
use shpb_input::Result;
use std::path::Path;

/// `shpb gun --pressure P [--bars SET-UP]`: pressure, striker velocity and energy, and the
/// elastic bar stress of an unshaped impact.
pub fn gun(pressure: &str, bars: &Path) -> Result<()> {
    let apparatus = load_apparatus(bars)?;
    let (p, v) = gun_shot(&apparatus, pressure)?;
    let e = 0.5 * apparatus.striker_mass_kg() * v * v;
    let z = apparatus.material.density_kg_m3 * apparatus.material.wave_speed_m_s();
    say(&format!(
        "pressure            {:.4} psi = {:.1} kPa (gauge)",
        p / shpb_core::striker::PSI_PA,
        p / 1e3
    ))?;
    say(&format!("striker velocity    {v:.4} m/s"))?;
    say(&format!(
        "striker energy      {e:.4} J (mass {:.4} kg)",
        apparatus.striker_mass_kg()
    ))?;
    say(&format!(
        "elastic bar stress  {:.2} MPa (ρ c0 v / 2, without shaper)",
        0.5 * z * v / 1e6
    ))?;
    Ok(())
}
