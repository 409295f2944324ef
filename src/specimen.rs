//! The specimen: two (possibly dissimilar) spheres and their effective contact properties
//! (paper Sec. II: E*, r; physics.md §1).

use crate::error::{Error, Result, Validator};
use crate::material::{JohnsonCook, Material};
use serde::Deserialize;
use std::path::Path;

/// One sphere of the specimen.
#[derive(Debug, Clone, PartialEq)]
pub struct Sphere {
    /// Its material.
    pub material: Material,
    /// Radius of curvature at the contact, m.
    pub radius_m: f64,
    /// Mass, kg (default: the full sphere, a fair approximation for the truncated ones, physics.md §5).
    pub mass_kg: f64,
}

impl Sphere {
    /// A full sphere of `material` with radius `radius_m`.
    pub fn full(material: Material, radius_m: f64) -> Sphere {
        let mass_kg = material.density_kg_m3 * 4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3);
        Sphere {
            material,
            radius_m,
            mass_kg,
        }
    }
}

/// Effective properties of a pair as used by the contact law (paper Sec. II; authors' code for
/// dissimilar spheres: the yield stress and rate hardening of the weaker sphere).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactProperties {
    /// Effective modulus E* = [(1−ν1²)/E1 + (1−ν2²)/E2]⁻¹, Pa.
    pub e_star_pa: f64,
    /// Effective radius r = (1/r1 + 1/r2)⁻¹, m.
    pub radius_m: f64,
    /// r1 + r2, the length in the global strain rate of paper Eq. 3, m.
    pub sum_of_radii_m: f64,
    /// Quasi-static yield stress min(σy1, σy2), Pa.
    pub yield_stress_pa: f64,
    /// Rate hardening of the sphere with the smaller yield stress (paper Eq. 2).
    pub rate: JohnsonCook,
}

/// Two spheres in contact: sphere 1 is on the incident side, sphere 2 on the transmission side.
#[derive(Debug, Clone, PartialEq)]
pub struct SpherePair {
    /// Incident-side sphere.
    pub sphere1: Sphere,
    /// Transmission-side sphere.
    pub sphere2: Sphere,
}

impl SpherePair {
    /// The paper's specimen: two full spheres of `material`, 6.35 mm in diameter.
    pub fn paper(material: Material) -> SpherePair {
        let s = Sphere::full(material, 6.35e-3 / 2.0);
        SpherePair {
            sphere1: s.clone(),
            sphere2: s,
        }
    }

    /// Effective contact properties of the pair (physics.md §1).
    pub fn contact_properties(&self) -> ContactProperties {
        let (a, b) = (&self.sphere1, &self.sphere2);
        let e_star_pa = 1.0
            / (1.0 / a.material.plane_strain_modulus_pa()
                + 1.0 / b.material.plane_strain_modulus_pa());
        let radius_m = 1.0 / (1.0 / a.radius_m + 1.0 / b.radius_m);
        let weaker = if a.material.yield_stress_pa <= b.material.yield_stress_pa {
            a
        } else {
            b
        };
        ContactProperties {
            e_star_pa,
            radius_m,
            sum_of_radii_m: a.radius_m + b.radius_m,
            yield_stress_pa: weaker.material.yield_stress_pa,
            rate: weaker.material.rate,
        }
    }

    /// Reduced mass m1 m2 / (m1 + m2), kg.
    pub fn reduced_mass_kg(&self) -> f64 {
        let (m1, m2) = (self.sphere1.mass_kg, self.sphere2.mass_kg);
        m1 * m2 / (m1 + m2)
    }
}

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
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
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
