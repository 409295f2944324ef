//! Specimen tables (`[specimen]` of a scene, `specimens/pair-*.toml`) validated into the core's
//! [`SpherePair`].

use crate::error::{Error, Result, Validator};
use crate::material::MaterialFile;
use serde::Deserialize;
use shpb_core::material::Material;
use shpb_core::specimen::{Sphere, SpherePair};
use std::path::Path;

/// One sphere as written in a pair file or a scene's `[specimen]` table.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    /// Built-in material name or path to a material `.toml`.
    pub material: String,
    /// Diameter, m (give this or `radius_m`).
    pub diameter_m: Option<f64>,
    /// Radius, m (give this or `diameter_m`).
    pub radius_m: Option<f64>,
    /// Mass, kg (default: the full sphere).
    pub mass_kg: Option<f64>,
}

/// A pair as written in `specimens/pair-*.toml`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairSpec {
    /// Incident-side sphere.
    pub sphere1: SphereSpec,
    /// Transmission-side sphere.
    pub sphere2: SphereSpec,
}

/// A scene's `[specimen]` table: either `pair = "name or file"` or explicit `sphere1`/`sphere2`.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SpecimenSpec {
    /// A built-in material name (the paper's 6.35 mm pair of it) or a path to a pair `.toml`.
    pub pair: Option<String>,
    /// Incident-side sphere.
    pub sphere1: Option<SphereSpec>,
    /// Transmission-side sphere.
    pub sphere2: Option<SphereSpec>,
}

impl SphereSpec {
    /// Validates this sphere; `v` reports keys under its table.
    pub fn build(&self, base_dir: &Path, v: &Validator) -> Result<Sphere> {
        let material = Material::resolve(&self.material, base_dir, v, "material")?;
        let radius_m = match (self.diameter_m, self.radius_m) {
            (Some(d), None) => v.positive("diameter_m", d, 10.0, "m")? / 2.0,
            (None, Some(r)) => v.positive("radius_m", r, 5.0, "m")?,
            _ => {
                return Err(v.error(
                    "diameter_m",
                    "give exactly one of `diameter_m` and `radius_m`",
                    "one positive length in m",
                ));
            }
        };
        let mut sphere = Sphere::full(material, radius_m);
        if let Some(m) = self.mass_kg {
            sphere.mass_kg = v.positive("mass_kg", m, 1e6, "kg")?;
        }
        Ok(sphere)
    }
}

impl PairSpec {
    /// Validates both spheres.
    pub fn build(&self, base_dir: &Path, v: &Validator) -> Result<SpherePair> {
        Ok(SpherePair {
            sphere1: self.sphere1.build(base_dir, &v.table("sphere1"))?,
            sphere2: self.sphere2.build(base_dir, &v.table("sphere2"))?,
        })
    }
}

/// Reads a pair file (`specimens/pair-*.toml`).
pub fn load_pair_file(path: &Path) -> Result<SpherePair> {
    let text = crate::provenance::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let file = path.display().to_string();
    let spec: PairSpec = toml::from_str(&text).map_err(|e| Error::Parse {
        file: file.clone(),
        message: e.to_string(),
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    spec.build(base, &Validator::new(file))
}

/// Resolves a specimen reference: a pair `.toml` path, or a built-in material name (paper pair).
pub fn resolve_pair(
    reference: &str,
    base_dir: &Path,
    v: &Validator,
    key: &str,
) -> Result<SpherePair> {
    if reference.ends_with(".toml") {
        let path = base_dir.join(reference);
        if !path.is_file() {
            return Err(v.error(
                key,
                format!("cannot read {}: no such file", path.display()),
                "a readable pair .toml file, relative to the scene file's directory",
            ));
        }
        return load_pair_file(&path);
    }
    Material::resolve(reference, base_dir, v, key).map(SpherePair::paper)
}

impl SpecimenSpec {
    /// Validates the specimen table of a scene.
    pub fn build(&self, base_dir: &Path, v: &Validator) -> Result<SpherePair> {
        match (&self.pair, &self.sphere1, &self.sphere2) {
            (Some(p), None, None) => resolve_pair(p, base_dir, v, "pair"),
            (None, Some(a), Some(b)) => Ok(SpherePair {
                sphere1: a.build(base_dir, &v.table("sphere1"))?,
                sphere2: b.build(base_dir, &v.table("sphere2"))?,
            }),
            _ => Err(v.error(
                "pair",
                "give either `pair` or both `sphere1` and `sphere2`",
                format!(
                    "pair = \"{}\" (or a pair .toml), or [specimen.sphere1] and [specimen.sphere2] tables",
                    crate::material::builtin_names()
                ),
            )),
        }
    }
}
