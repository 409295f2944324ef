//! Material files (`specimens/*.toml`) and the built-in materials, validated into the core's
//! [`Material`].

use crate::error::{Error, Result, Validator};
use serde::Deserialize;
use shpb_core::material::{JohnsonCook, Material};
use std::path::Path;

/// The on-disk form of a material file in `specimens/` (validated into [`Material`]).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialToml {
    name: String,
    #[serde(default)]
    #[allow(dead_code)]
    description: Option<String>,
    density_kg_m3: f64,
    youngs_modulus_pa: f64,
    poisson_ratio: f64,
    yield_stress_pa: f64,
    #[serde(default)]
    jc_c: f64,
    #[serde(default = "default_reference_rate")]
    jc_reference_rate_per_s: f64,
    /// The flow stress of a cylinder of this material (docs/physics.md §6.12); spheres ignore it.
    johnson_cook: Option<toml::Value>,
}

/// A `[johnson_cook]` table (a material file's, or a cylinder's `[specimen.johnson_cook]`):
/// σ_f = (A + B ε̄pⁿ)(1 + C ln max(ε̇p/ε̇0, 1))(1 − T*ᵐ), docs/physics.md §6.12; the thermal term
/// when `m`, `melt_temperature_k` and `specific_heat_j_kg_k` are given.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JohnsonCookToml {
    a_pa: f64,
    b_pa: f64,
    n: f64,
    #[serde(default)]
    c: f64,
    #[serde(default = "default_jc_flow_rate")]
    reference_rate_per_s: f64,
    m: Option<f64>,
    #[serde(default = "default_room_temperature")]
    room_temperature_k: f64,
    melt_temperature_k: Option<f64>,
    specific_heat_j_kg_k: Option<f64>,
    /// Where the constants come from (kept in the file; not used by the model).
    #[allow(dead_code)]
    source: Option<String>,
}

fn default_jc_flow_rate() -> f64 {
    1.0
}

fn default_room_temperature() -> f64 {
    293.0
}

/// Taylor–Quinney factor β, the fraction of plastic work turned into heat, unless a scene sets
/// `taylor_quinney` (docs/physics.md §6.12; Taylor & Quinney, Proc. R. Soc. A 143, 307 (1934)).
pub const DEFAULT_TAYLOR_QUINNEY: f64 = 0.9;

/// Reads a `[johnson_cook]` table `value` (under `key` of `v`) into the core's law, with the
/// Taylor–Quinney factor `taylor_quinney` for its heating.
pub fn johnson_cook_from_value(
    value: &toml::Value,
    taylor_quinney: f64,
    v: &Validator,
    key: &str,
) -> Result<shpb_core::flow::JohnsonCook> {
    let raw: JohnsonCookToml = value.clone().try_into().map_err(|e: toml::de::Error| {
        v.error(
            key,
            e.message().to_string(),
            "a table { a_pa, b_pa, n, c, reference_rate_per_s, m, room_temperature_k, melt_temperature_k, specific_heat_j_kg_k }",
        )
    })?;
    let tv = v.table(key);
    let thermal = match (raw.m, raw.melt_temperature_k, raw.specific_heat_j_kg_k) {
        (None, None, None) => None,
        (Some(m), Some(melt), Some(cp)) => Some(shpb_core::flow::ThermalSoftening {
            m,
            room_temperature_k: raw.room_temperature_k,
            melt_temperature_k: melt,
            specific_heat_j_kg_k: cp,
            taylor_quinney,
        }),
        _ => {
            return Err(tv.error(
                "m",
                "thermal softening needs m, melt_temperature_k and specific_heat_j_kg_k together",
                "all three, or none (no thermal softening)",
            ));
        }
    };
    shpb_core::flow::JohnsonCook::new(
        key,
        shpb_core::flow::JohnsonCook {
            a_pa: raw.a_pa,
            b_pa: raw.b_pa,
            n: raw.n,
            c: raw.c,
            reference_rate_per_s: raw.reference_rate_per_s,
            thermal,
        },
    )
    .map_err(tv.core_named())
}

fn default_reference_rate() -> f64 {
    1e-3
}

/// The materials shipped in `specimens/`, compiled into the binary so it runs from any directory.
pub const BUILTIN_MATERIALS: &[(&str, &str)] = &[
    ("ss440c", include_str!("../../../specimens/ss440c.toml")),
    ("ss302", include_str!("../../../specimens/ss302.toml")),
    ("al2017", include_str!("../../../specimens/al2017.toml")),
    (
        "ofhc-copper",
        include_str!("../../../specimens/ofhc-copper.toml"),
    ),
    (
        "al6061-t6",
        include_str!("../../../specimens/al6061-t6.toml"),
    ),
    (
        "al7075-t6",
        include_str!("../../../specimens/al7075-t6.toml"),
    ),
    ("ti6al4v", include_str!("../../../specimens/ti6al4v.toml")),
    (
        "steel4340",
        include_str!("../../../specimens/steel4340.toml"),
    ),
];

/// Reading and resolving materials: built-in names or `.toml` files.
pub trait MaterialFile: Sized {
    /// Parses and validates a material from TOML text; `file` names the source in errors.
    fn from_toml(text: &str, file: &str) -> Result<Self>;
    /// A built-in material by name (`ss440c`, `ss302`, `al2017`).
    fn builtin(name: &str) -> Option<Self>;
    /// Resolves a material reference: a path to a `.toml` file (relative to `base_dir`) or a built-in name.
    fn resolve(reference: &str, base_dir: &Path, v: &Validator, key: &str) -> Result<Self>;
}

impl MaterialFile for Material {
    /// Parses and validates a material from TOML text; `file` names the source in errors.
    fn from_toml(text: &str, file: &str) -> Result<Material> {
        parse(text, file).map(|(m, _)| m)
    }

    /// A built-in material by name (`ss440c`, `ss302`, `al2017`).
    fn builtin(name: &str) -> Option<Material> {
        BUILTIN_MATERIALS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(n, text)| {
                let text = crate::files::builtin(&format!("specimens/{n}.toml"), text);
                Material::from_toml(text, &format!("specimens/{n}.toml"))
                    .expect("built-in material files are valid")
            })
    }

    /// Resolves a material reference: a path to a `.toml` file (relative to `base_dir`) or a built-in name.
    fn resolve(reference: &str, base_dir: &Path, v: &Validator, key: &str) -> Result<Material> {
        resolve_with_johnson_cook(reference, base_dir, v, key).map(|(m, _)| m)
    }
}

/// Parses and validates a material file's text (`file` names it in errors): the material and
/// its `[johnson_cook]` table, if any (a cylinder's flow, docs/physics.md §6.12).
fn parse(text: &str, file: &str) -> Result<(Material, Option<toml::Value>)> {
    let raw: MaterialToml = toml::from_str(text).map_err(|e| Error::Parse {
        file: file.to_string(),
        message: e.to_string(),
    })?;
    let v = Validator::new(file);
    let m = Material {
        name: raw.name,
        density_kg_m3: v.positive("density_kg_m3", raw.density_kg_m3, 1e5, "kg/m³")?,
        youngs_modulus_pa: v.positive("youngs_modulus_pa", raw.youngs_modulus_pa, 1e13, "Pa")?,
        poisson_ratio: v.in_range("poisson_ratio", raw.poisson_ratio, -0.99, 0.4999, "")?,
        yield_stress_pa: sphere_flow_constant(&v, "yield_stress_pa", raw.yield_stress_pa)?,
        rate: JohnsonCook {
            c: sphere_flow_constant(&v, "jc_c", raw.jc_c)?,
            reference_rate_per_s: sphere_flow_constant(
                &v,
                "jc_reference_rate_per_s",
                raw.jc_reference_rate_per_s,
            )?,
        },
    };
    Ok((m, raw.johnson_cook))
}

/// Checks one of a sphere's flow constants (`yield_stress_pa`, `jc_c`, `jc_reference_rate_per_s`:
/// σy, C and ε̇0 of paper Eq. 2) against its range,
/// reported for `key` of `v`: σy > 0 (at most 1e20 Pa), 0 ≤ C ≤ 1, 0 < ε̇0 ≤ 1e9 1/s. The one
/// check of these keys, in a material file and in a scene's `[specimen]` table.
pub(crate) fn sphere_flow_constant(v: &Validator, key: &str, value: f64) -> Result<f64> {
    match key {
        "yield_stress_pa" => v.positive(key, value, 1e20, "Pa"),
        "jc_c" => v.in_range(key, value, 0.0, 1.0, ""),
        "jc_reference_rate_per_s" => v.positive(key, value, 1e9, "1/s"),
        other => unreachable!("`{other}` is not a sphere flow constant"),
    }
}

/// A material reference (as [`MaterialFile::resolve`] reads it) with its `[johnson_cook]` table,
/// if it has one: the file is read and parsed once.
pub fn resolve_with_johnson_cook(
    reference: &str,
    base_dir: &Path,
    v: &Validator,
    key: &str,
) -> Result<(Material, Option<toml::Value>)> {
    match material_source(reference, base_dir, v, key)? {
        Some((text, file)) => parse(&text, &file),
        None if base_dir.join(reference).is_dir() => Err(v.error(
            key,
            format!(
                "{} is a directory, not a material file",
                base_dir.join(reference).display()
            ),
            format!("{} or a path to a material .toml file", builtin_names()),
        )),
        None => Err(v.error(
            key,
            format!("unknown material `{reference}`"),
            format!("{} or a path to a material .toml file", builtin_names()),
        )),
    }
}

/// The text and name of a material reference: a `.toml` file relative to `base_dir` (read through
/// `files`, so a run records it), or a built-in material; None for neither.
fn material_source(
    reference: &str,
    base_dir: &Path,
    v: &Validator,
    key: &str,
) -> Result<Option<(String, String)>> {
    if reference.ends_with(".toml") {
        let path = base_dir.join(reference);
        let text = crate::files::read_to_string(&path).map_err(|e| {
            v.error(
                key,
                format!("cannot read {}: {e}", path.display()),
                "a readable material .toml file, relative to the scene file's directory",
            )
        })?;
        return Ok(Some((text, path.display().to_string())));
    }
    Ok(BUILTIN_MATERIALS
        .iter()
        .find(|(n, _)| *n == reference)
        .map(|(n, text)| {
            let file = format!("specimens/{n}.toml");
            (crate::files::builtin(&file, text).to_string(), file)
        }))
}

/// The built-in material names joined for error messages.
pub fn builtin_names() -> String {
    BUILTIN_MATERIALS
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}
