//! `shpb list`: the built-in materials, the built-in set-ups and the scene kinds.

use super::common::print;
use shpb_core::material::Material;
use shpb_input::Result;
use shpb_input::prelude::*;
use std::fmt::Write as _;

/// `shpb list`: prints three sections, each one name and one description a line.
pub fn list() -> Result<()> {
    print(&text())
}

/// The text `shpb list` prints.
pub fn text() -> String {
    let mut out = String::new();
    let materials: Vec<(String, String)> = shpb_input::material::BUILTIN_MATERIALS
        .iter()
        .map(|(name, toml)| (name.to_string(), material_line(name, toml)))
        .collect();
    section(
        &mut out,
        "BUILT-IN MATERIALS (pair = \"NAME\" or material = \"NAME\" in scenes, shpb curve --specimen NAME):",
        &materials,
    );
    out.push('\n');
    let setups: Vec<(String, String)> = shpb_input::builtin::SETUPS
        .iter()
        .map(|(name, _, description)| (name.to_string(), description.to_string()))
        .collect();
    section(
        &mut out,
        "BUILT-IN SET-UPS (bars = \"NAME\" in scenes, --bars NAME):",
        &setups,
    );
    out.push('\n');
    let kinds: Vec<(String, String)> = shpb_input::kinds::names_and_help()
        .into_iter()
        .map(|(name, help)| (name.to_string(), help.to_string()))
        .collect();
    section(&mut out, "SCENE KINDS (kind = \"NAME\" in scenes):", &kinds);
    out
}

/// A heading and its `name  description` lines, names padded to one column.
fn section(out: &mut String, heading: &str, rows: &[(String, String)]) {
    let width = rows
        .iter()
        .map(|(n, _)| n.chars().count())
        .max()
        .unwrap_or(0);
    let _ = writeln!(out, "{heading}");
    for (name, description) in rows {
        let _ = writeln!(out, "  {name:<width$}  {description}");
    }
}

/// A built-in material's description (the `description` of its file) and properties.
fn material_line(name: &str, toml: &str) -> String {
    let properties = match Material::builtin(name) {
        Some(m) => properties(&m),
        None => "not readable".into(),
    };
    match description(toml) {
        Some(d) => format!("{d}: {properties}"),
        None => properties,
    }
}

/// Density, Young's modulus, yield stress and Johnson–Cook C of a material.
fn properties(m: &Material) -> String {
    // Four decimals at most, without the noise of the unit conversions (204e9 / 1e9).
    let g = |x: f64| (x * 1e4).round() / 1e4;
    format!(
        "ρ {} kg/m³, E {} GPa, σy {} MPa, C {}",
        g(m.density_kg_m3),
        g(m.youngs_modulus_pa / 1e9),
        g(m.yield_stress_pa / 1e6),
        g(m.rate.c)
    )
}

/// The `description = "…"` line of a material file, if it has one.
fn description(toml: &str) -> Option<&str> {
    toml.lines().find_map(|line| {
        let (key, value) = line.split_once('=')?;
        if key.trim() != "description" {
            return None;
        }
        let value = value.trim();
        value.strip_prefix('"')?.strip_suffix('"')
    })
}
