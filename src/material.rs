//! Sphere materials (paper Table I) with Johnson–Cook rate hardening (paper Eq. 2, plus sign).

use crate::error::{Error, Result, Validator};
use serde::Deserialize;
use std::path::Path;

/// Johnson–Cook rate hardening of the yield stress, `σy* = σy (1 + C ln(ε̇/ε̇0))` (paper Eq. 2 with
/// the sign corrected as in the authors' code, physics.md §2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JohnsonCook {
    /// Dimensionless rate sensitivity C.
    pub c: f64,
    /// Reference (quasi-static) strain rate ε̇0 at which σy was measured, 1/s.
    pub reference_rate_per_s: f64,
}

impl JohnsonCook {
    /// No rate dependence (C = 0).
    pub const NONE: JohnsonCook = JohnsonCook {
        c: 0.0,
        reference_rate_per_s: 1e-3,
    };

    /// Dynamic yield stress at strain rate `rate_per_s`; equals `sigma_y_pa` for ε̇ ≤ ε̇0 (physics.md §2).
    pub fn dynamic_yield_stress(&self, sigma_y_pa: f64, rate_per_s: f64) -> f64 {
        if rate_per_s > self.reference_rate_per_s && self.c != 0.0 {
            sigma_y_pa * (1.0 + self.c * (rate_per_s / self.reference_rate_per_s).ln())
        } else {
            sigma_y_pa
        }
    }
}

/// An isotropic elastic–perfectly-plastic sphere material with rate hardening (paper Table I).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Short name, e.g. `ss440c`.
    pub name: String,
    /// Mass density, kg/m³.
    pub density_kg_m3: f64,
    /// Young's modulus, Pa.
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio (not given in the paper; physics.md §4 defaults).
    pub poisson_ratio: f64,
    /// Quasi-static yield stress σy, Pa.
    pub yield_stress_pa: f64,
    /// Johnson–Cook rate hardening (paper Eq. 2).
    pub rate: JohnsonCook,
}

/// The on-disk form of a material file in `specimens/` (validated into [`Material`]).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialFile {
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
    ("ss440c", include_str!("../specimens/ss440c.toml")),
    ("ss302", include_str!("../specimens/ss302.toml")),
    ("al2017", include_str!("../specimens/al2017.toml")),
];

impl Material {
    /// Parses and validates a material from TOML text; `file` names the source in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Material> {
        let raw: MaterialFile = toml::from_str(text).map_err(|e| Error::Parse {
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
    pub fn builtin(name: &str) -> Option<Material> {
        BUILTIN_MATERIALS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(n, text)| {
                Material::from_toml(text, &format!("specimens/{n}.toml"))
                    .expect("built-in material files are valid")
            })
    }

    /// Resolves a material reference: a path to a `.toml` file (relative to `base_dir`) or a built-in name.
    pub fn resolve(reference: &str, base_dir: &Path, v: &Validator, key: &str) -> Result<Material> {
        if reference.ends_with(".toml") {
            let path = base_dir.join(reference);
            let text = std::fs::read_to_string(&path).map_err(|e| {
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

    /// Plane-strain modulus E/(1−ν²), Pa (one sphere's share of E*, physics.md §1).
    pub fn plane_strain_modulus_pa(&self) -> f64 {
        self.youngs_modulus_pa / (1.0 - self.poisson_ratio * self.poisson_ratio)
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
