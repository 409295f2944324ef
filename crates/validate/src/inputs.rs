//! The report's list of adjustable inputs that are not in the paper, with value and reason,
//! read from the shipped files (`bars/authors.toml`, `bars/gauges-authors.toml`, `specimens/`).

use crate::Context;
use shpb_core::apparatus::Apparatus;
use shpb_core::contact::Region2Form;
use shpb_core::material::Material;
use shpb_core::scene::AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S;
use shpb_core::striker::{Gun, PSI_PA};
use shpb_input::Result;
use shpb_input::prelude::*;
use std::fmt::Write as _;

/// The markdown section "Adjustable inputs not in the paper".
pub fn section(ctx: &Context) -> Result<String> {
    let a = Apparatus::from_file(&ctx.path("bars/authors.toml"))?;
    let mut rows: Vec<[String; 4]> = Vec::new();
    let mut row = |name: &str, file: &str, value: String, reason: &str| {
        rows.push([name.into(), file.into(), value, reason.into()]);
    };
    let calibrated = "calibrated on the eight 2013-05-22 incident records (peak, rise, duration, \
                      energy of the pulse): validation/pulse/REPORT.md";
    match a.gun {
        Gun::Linear(g) => {
            row(
                "gas gun k in v² = k (p − p_loss)",
                "bars/authors.toml [gun]",
                format!("{:.4e} m²/s²/Pa", g.k_m2_per_s2_per_pa),
                calibrated,
            );
            row(
                "gas gun p_loss",
                "bars/authors.toml [gun]",
                format!(
                    "{:.0} Pa ({:.2} psi)",
                    g.loss_pressure_pa,
                    g.loss_pressure_pa / PSI_PA
                ),
                calibrated,
            );
        }
        Gun::Adiabatic(g) => {
            row(
                "gas gun (adiabatic): reservoir, barrel, friction",
                "bars/authors.toml [gun]",
                format!(
                    "{:.3e} m³, {:.3} m, {:.1} N",
                    g.reservoir_volume_m3, g.barrel_length_m, g.friction_n
                ),
                calibrated,
            );
        }
        Gun::None => {}
    }
    match a.shaper {
        Some(s) => {
            row(
                "copper shaper diameter, thickness",
                "bars/authors.toml [shaper]",
                format!(
                    "{:.3} mm, {:.4} mm",
                    s.diameter_m * 1e3,
                    s.thickness_m * 1e3
                ),
                calibrated,
            );
            row(
                "copper shaper elastic modulus",
                "bars/authors.toml [shaper]",
                format!("{:.3} GPa", s.youngs_modulus_pa / 1e9),
                "calibrated (as above); an effective modulus standing for the compliance of the \
                 disc's faces and contacts, not copper's 117 GPa, which cannot reproduce the \
                 records",
            );
            row(
                "copper shaper σ0, n, m",
                "bars/authors.toml [shaper]",
                format!("{:.2} GPa, {}, {}", s.sigma0_pa / 1e9, s.n, s.m),
                "Frew, Forrestal & Chen (2002) for annealed C11000, kept fixed in the calibration",
            );
        }
        None => row(
            "copper shaper",
            "bars/authors.toml",
            "none".into(),
            "no shaper in the set-up",
        ),
    }
    let m = &a.material;
    row(
        "bar material",
        "bars/authors.toml [material]",
        format!(
            "E {:.0} GPa, ν {}, ρ {:.0} kg/m³ (c0 {:.1} m/s)",
            m.youngs_modulus_pa / 1e9,
            m.poisson_ratio,
            m.density_kg_m3,
            m.wave_speed_m_s()
        ),
        "the authors' analysis script (maraging steel, c0 = 4865.5 m/s measured, ρ = E/c0²); the \
         paper names only the steel and the 19.05 mm diameter",
    );
    row(
        "bar lengths, striker, gauge distances",
        "bars/authors.toml, bars/gauges-authors.toml",
        format!(
            "incident {} m, transmission {} m, striker {} m; gauges {} m",
            a.incident.length_m,
            a.transmission.length_m,
            a.striker.length_m,
            a.gauges
                .channels
                .iter()
                .map(|c| format!("{} {}", c.name, c.distance_from_specimen_m))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        "the authors' script and set-up description (physics.md §6); the paper gives the 10 cm \
         striker",
    );
    if let Some(ch) = a.gauges.channels.first() {
        row(
            "gauge bridge factor",
            "bars/gauges-authors.toml",
            format!(
                "{} bridge, amplifier gain {} (half the strain of the authors' formula), GF {}, Vex {} V",
                ch.bridge.kind.name(),
                ch.amplifier_gain,
                ch.bridge.gauge_factor,
                ch.bridge.excitation_v
            ),
            "the reading that explains the authors' own reductions of 7 of the 8 records, the \
             consistency of the incident pulses and the gun's energy budget (header of \
             bars/gauges-authors.toml; validation/gauge-records/REPORT.md)",
        );
        let d = &ch.digitiser;
        row(
            "digitiser",
            "bars/gauges-authors.toml",
            format!(
                "{:.0} MHz, {} bits over ±{} V, noise {:.2e} V RMS",
                d.sample_rate_hz / 1e6,
                d.bits,
                d.range_v,
                d.noise_rms_v
            ),
            "estimated from the pre-trigger part of the 16 recorded traces (quantisation step and \
             noise)",
        );
    }
    for name in ["ss440c", "ss302", "al2017"] {
        let mat = Material::builtin(name).expect("built-in material");
        row(
            &format!("Poisson ratio of {name}"),
            &format!("specimens/{name}.toml"),
            format!("{}", mat.poisson_ratio),
            "not in the paper's Table I; typical handbook value (physics.md §4; the authors' DEM \
             script used 0.3 for all)",
        );
    }
    row(
        "sphere masses",
        "specimens/pair-6.35mm-*.toml",
        "full 6.35 mm spheres".into(),
        "the paper's spheres are truncated; full-sphere masses are a fair approximation \
         (physics.md §5)",
    );
    row(
        "transmission-bar impedance of the force-driven DEM",
        "scene key medium_impedance_kg_s (default)",
        format!("{AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S:.4e} kg/s"),
        "ρ c0 A with ρ = 8110 kg/m³ (not measured, physics.md §5), c0 = 4865.5 m/s, radius 9.525 mm",
    );
    row(
        "form of region II of the loading law",
        "scene key region2 (default)",
        match Region2Form::default() {
            Region2Form::Smooth => "smooth: F = δ(α + β ln δ) + γ(δ − δy)(δp − δ)".into(),
            Region2Form::Published => "published: F = δ(α + β ln δ)".into(),
        },
        "the published form has a 13–17 % slope jump at δy and starts above Hertz, which gives \
         restitution > 1 just past yield (case restitution); γ vanishes at δy and δp, so δy, Fy, \
         δp, Fp, α, β are the paper's; the Fig. 2 errors change by ≤ 0.05 percentage points",
    );
    row(
        "Johnson–Cook sign",
        "src/material.rs",
        "σy* = σy (1 + C ln(ε̇/ε̇0))".into(),
        "the paper prints a minus sign (a typo: the authors' code and Fig. 3 use the plus sign, \
         physics.md §2); C and ε̇0 are the paper's",
    );
    let mut md = String::new();
    let _ = writeln!(md, "## Adjustable inputs that are not in the paper\n");
    let _ = writeln!(
        md,
        "Read from the shipped files when the report was generated. Everything else (Table I \
         densities, moduli and yield stresses; the fits of Eq. 1; the Johnson–Cook C and ε̇0 of \
         Figs. 3 and 4; sphere diameters) is the paper's.\n"
    );
    let _ = writeln!(md, "| input | where | value | reason |");
    let _ = writeln!(md, "|---|---|---|---|");
    for r in rows {
        let _ = writeln!(md, "| {} | {} | {} | {} |", r[0], r[1], r[2], r[3]);
    }
    Ok(md)
}
