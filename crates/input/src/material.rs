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
}

fn default_reference_rate() -> f64 {
    1e-3
}

/// The materials shipped in `specimens/`, compiled into the binary so it runs from any directory.
pub const BUILTIN_MATERIALS: &[(&str, &str)] = &[
    ("ss440c", include_str!("../../../specimens/ss440c.toml")),
    ("ss302", include_str!("../../../specimens/ss302.toml")),
    ("al2017", include_str!("../../../specimens/al2017.toml")),
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
        let raw: MaterialToml = toml::from_str(text).map_err(|e| Error::Parse {
            file: file.to_string(),
            message: e.to_string(),
        })?;
        let v = Validator::new(file);
        let m = Material {
            name: raw.name,
            density_kg_m3: v.positive("density_kg_m3", raw.density_kg_m3, 1e5, "kg/m³")?,
            youngs_modulus_pa: v.positive(
                "youngs_modulus_pa",
                raw.youngs_modulus_pa,
                1e13,
                "Pa",
            )?,
            poisson_ratio: v.in_range("poisson_ratio", raw.poisson_ratio, -0.99, 0.4999, "")?,
            yield_stress_pa: v.positive("yield_stress_pa", raw.yield_stress_pa, 1e20, "Pa")?,
            rate: JohnsonCook {
                c: v.in_range("jc_c", raw.jc_c, 0.0, 1.0, "")?,
                reference_rate_per_s: v.positive(
                    "jc_reference_rate_per_s",
                    raw.jc_reference_rate_per_s,
                    1e9,
                    "1/s",
                )?,
            },
        };
        Ok(m)
    }

    /// A built-in material by name (`ss440c`, `ss302`, `al2017`).
    fn builtin(name: &str) -> Option<Material> {
        BUILTIN_MATERIALS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(n, text)| {
                Material::from_toml(text, &format!("specimens/{n}.toml"))
                    .expect("built-in material files are valid")
            })
    }

    /// Resolves a material reference: a path to a `.toml` file (relative to `base_dir`) or a built-in name.
    fn resolve(reference: &str, base_dir: &Path, v: &Validator, key: &str) -> Result<Material> {
        if reference.ends_with(".toml") {
            let path = base_dir.join(reference);
            let text = crate::provenance::read_to_string(&path).map_err(|e| {
                v.error(
                    key,
                    format!("cannot read {}: {e}", path.display()),
                    "a readable material .toml file, relative to the scene file's directory",
                )
            })?;
            return Material::from_toml(&text, &path.display().to_string());
        }
        Material::builtin(reference).ok_or_else(|| {
            v.error(
                key,
                format!("unknown material `{reference}`"),
                format!("{} or a path to a material .toml file", builtin_names()),
            )
        })
    }
}

/// The built-in material names joined for error messages.
pub fn builtin_names() -> String {
    BUILTIN_MATERIALS
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}
