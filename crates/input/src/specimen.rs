//! Specimen tables (`[specimen]` of a scene, `specimens/pair-*.toml`) validated into the core's
//! [`SpherePair`].

use crate::error::{Error, Result, Validator};
use crate::material::MaterialFile;
use serde::Deserialize;
use shpb_core::material::Material;
use shpb_core::specimen::{Seating, Sphere, SphereChain, SpherePair};
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

/// A scene's `[specimen]` table: either `pair = "name or file"` or explicit `sphere1`/`sphere2`;
/// for a chain of spheres (`chain` and `shpb` scenes) also `count` identical spheres of
/// `material` and `diameter_m`, or one `[[specimen.sphere]]` table per sphere.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SpecimenSpec {
    /// A built-in material name (the paper's 6.35 mm pair of it) or a path to a pair `.toml`.
    pub pair: Option<String>,
    /// Incident-side sphere.
    pub sphere1: Option<SphereSpec>,
    /// Transmission-side sphere.
    pub sphere2: Option<SphereSpec>,
    /// Number of identical spheres of a chain (2 or more).
    pub count: Option<i64>,
    /// Material of the `count` spheres (a built-in name or a material `.toml`), or of a
    /// cylinder: such a name (its E, ν, ρ are used), or a table `{ density_kg_m3,
    /// youngs_modulus_pa, poisson_ratio }` as a set-up's `[material]` or an insert's `material`.
    pub material: Option<toml::Value>,
    /// `"spheres"` (default) or `"cylinder"` (`shpb` scenes: an elastic cylinder between the
    /// bars, docs/physics.md §6.9).
    pub shape: Option<String>,
    /// Length of a cylinder along the bar axis, m.
    pub length_m: Option<f64>,
    /// A tension specimen's gauge length, m: the same length as `length_m` under the name a
    /// tension-bar lab gives it (one of the two; docs/physics.md §6.13).
    pub gauge_length_m: Option<f64>,
    /// Diameter of the `count` spheres, m.
    pub diameter_m: Option<f64>,
    /// One table per sphere of a chain, sphere 1 first.
    pub sphere: Option<Vec<SphereSpec>>,
    /// `shpb` scenes: each contact open by this gap before the test, m (0 to 1 mm).
    pub gap_m: Option<f64>,
    /// `shpb` scenes: each contact pressed by this static force before the test, N (0 to 10 kN).
    pub preload_n: Option<f64>,
    /// A cylinder's flow model (docs/physics.md §6.12): `elastic`, `johnson-cook` or `table`
    /// (default: johnson-cook when the material has a `[johnson_cook]` table or the specimen
    /// gives one, else elastic).
    pub model: Option<String>,
    /// A cylinder's Johnson–Cook constants (replaces the material file's `[johnson_cook]`).
    pub johnson_cook: Option<toml::Value>,
    /// A cylinder's tabulated flow curve: true stress against equivalent plastic strain.
    pub flow_curve: Option<FlowCurveSpec>,
    /// A cylinder's Taylor–Quinney factor (fraction of plastic work turned into heat, 0 to 1).
    pub taylor_quinney: Option<f64>,
    /// A cylinder's initial temperature, K.
    pub initial_temperature_k: Option<f64>,
    /// A cylinder's radial inertia (Davies–Hunter), default false.
    pub radial_inertia: Option<bool>,
    /// Coulomb friction coefficient at a cylinder's faces (0 to 10, default 0).
    pub friction_coefficient: Option<f64>,
    /// The barrelling factor of that friction: `avitzur` (default) or `slab`.
    pub friction_model: Option<String>,
    /// Compressive true strain a flowing cylinder's grid is built to carry (0 to 2).
    pub design_true_strain: Option<f64>,
    /// Spheres: quasi-static yield stress σy of every sphere, Pa (paper Eq. 2), replacing the
    /// material file's (the paper's pairs are of one material).
    pub yield_stress_pa: Option<f64>,
    /// Spheres: Johnson–Cook rate constant C of every sphere (paper Eq. 2), replacing the
    /// material file's.
    pub jc_c: Option<f64>,
    /// Spheres: Johnson–Cook reference rate ε̇0 of every sphere, 1/s (paper Eq. 2), replacing the
    /// material file's.
    pub jc_reference_rate_per_s: Option<f64>,
}

/// A tabulated flow curve (`[specimen.flow_curve]`): true stress at equivalent plastic strains.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowCurveSpec {
    /// Equivalent plastic strains, strictly increasing from 0.
    pub plastic_strain: Vec<f64>,
    /// True flow stress at each, Pa.
    pub stress_pa: Vec<f64>,
}

/// Largest seating gap a scene may give, m: beyond it the spheres are not seated but loose.
pub const MAX_GAP_M: f64 = 1e-3;

/// Largest seating preload a scene may give, N.
pub const MAX_PRELOAD_N: f64 = 1e4;

/// What a cylindrical specimen is given as, for messages.
pub const CYLINDER_FORM: &str = "shape = \"cylinder\" with length_m (or a tension specimen's gauge_length_m) and diameter_m (each greater than 0, at most 0.1 m) and material (a built-in name such as \"al2017\", a material .toml, or a table { density_kg_m3, youngs_modulus_pa, poisson_ratio })";

/// Most spheres a chain may have.
pub const MAX_CHAIN_SPHERES: i64 = 100_000;

/// What a chain specimen may be given as, for messages.
pub const CHAIN_FORMS: &str = "count = N (2 to 100000) with material and diameter_m, or one [[specimen.sphere]] table per sphere (2 or more, each with material and diameter_m), or pair = \"ss440c\" / [specimen.sphere1] and [specimen.sphere2] for two";

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
    let text = crate::files::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let file = path.display().to_string();
    let spec: PairSpec = toml::from_str(&text).map_err(|e| Error::Parse {
        file: file.clone(),
        message: e.to_string(),
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    spec.build(base, &Validator::new(file))
}

/// Resolves a specimen reference: a pair `.toml` path, or a built-in material name or material
/// `.toml` file (the paper's 6.35 mm pair of it).
pub fn resolve_pair(
    reference: &str,
    base_dir: &Path,
    v: &Validator,
    key: &str,
) -> Result<SpherePair> {
    if reference.ends_with(".toml") {
        let path = base_dir.join(reference);
        if !crate::files::is_file(&path) {
            return Err(v.error(
                key,
                format!(
                    "cannot read {}: {}",
                    path.display(),
                    crate::files::not_a_file(&path)
                ),
                "a readable pair or material .toml file, relative to the scene file's directory",
            ));
        }
        // A material file (no [sphere1]/[sphere2] table) is the paper's 6.35 mm pair of it, as
        // a built-in name is (issue 42: `curve --specimen ss440c.toml` was refused with a TOML
        // error although its help offers material files).
        let text = crate::files::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        let is_pair = match text.parse::<toml::Table>() {
            Ok(t) => t.contains_key("sphere1") || t.contains_key("sphere2"),
            Err(_) => true,
        };
        if is_pair {
            return load_pair_file(&path);
        }
    }
    Material::resolve(reference, base_dir, v, key).map(SpherePair::paper)
}

impl SpecimenSpec {
    /// Replaces the material constants of every sphere in `spheres` by the ones this table gives
    /// (`yield_stress_pa`, `jc_c`, `jc_reference_rate_per_s`: σy, C and ε̇0 of paper Eq. 2), each
    /// checked as a material file's: the paper's pairs are of one material, so one value holds
    /// for all.
    fn apply_sphere_flow_keys<'a>(
        &self,
        spheres: impl IntoIterator<Item = &'a mut Sphere>,
        v: &Validator,
    ) -> Result<()> {
        let check = |key: &str, value: Option<f64>| {
            value
                .map(|x| crate::material::sphere_flow_constant(v, key, x))
                .transpose()
        };
        let yield_stress = check("yield_stress_pa", self.yield_stress_pa)?;
        let c = check("jc_c", self.jc_c)?;
        let reference_rate = check("jc_reference_rate_per_s", self.jc_reference_rate_per_s)?;
        for sphere in spheres {
            let m = &mut sphere.material;
            m.yield_stress_pa = yield_stress.unwrap_or(m.yield_stress_pa);
            m.rate.c = c.unwrap_or(m.rate.c);
            m.rate.reference_rate_per_s = reference_rate.unwrap_or(m.rate.reference_rate_per_s);
        }
        Ok(())
    }

    /// Refuses a sphere's flow constants for a cylinder, naming the cylinder's own key.
    pub(crate) fn refuse_sphere_flow_keys(&self, v: &Validator) -> Result<()> {
        for (key, given, instead) in [
            ("yield_stress_pa", self.yield_stress_pa.is_some(), "a_pa"),
            ("jc_c", self.jc_c.is_some(), "c"),
            (
                "jc_reference_rate_per_s",
                self.jc_reference_rate_per_s.is_some(),
                "reference_rate_per_s",
            ),
        ] {
            if given {
                return Err(v.error(
                    key,
                    format!(
                        "`{key}` is a sphere's material constant (paper Eq. 2); a cylinder flows by its Johnson–Cook constants"
                    ),
                    format!(
                        "specimen.johnson_cook.{instead} (a cylinder's [specimen.johnson_cook] table, merged over the material's)"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// How the spheres sit between the bars (`gap_m` or `preload_n`, `shpb` scenes;
    /// docs/physics.md §6.11): touching without either (or with a zero one).
    pub fn build_seating(&self, v: &Validator) -> Result<Seating> {
        let gap = self
            .gap_m
            .map(|g| v.in_range("gap_m", g, 0.0, MAX_GAP_M, "m"))
            .transpose()?
            .unwrap_or(0.0);
        let preload = self
            .preload_n
            .map(|f| v.in_range("preload_n", f, 0.0, MAX_PRELOAD_N, "N"))
            .transpose()?
            .unwrap_or(0.0);
        match (gap > 0.0, preload > 0.0) {
            (true, true) => Err(v.error(
                "preload_n",
                "a contact cannot be both open by a gap and pressed by a preload",
                "either gap_m or preload_n",
            )),
            (true, false) => Ok(Seating::Gap { gap_m: gap }),
            (false, true) => Ok(Seating::Preload { force_n: preload }),
            (false, false) => Ok(Seating::Touching),
        }
    }

    /// The table without its seating keys (the `shpb` parser reads those with
    /// [`SpecimenSpec::build_seating`] and the spheres from the rest).
    pub fn spheres_only(&self) -> SpecimenSpec {
        SpecimenSpec {
            gap_m: None,
            preload_n: None,
            ..self.clone()
        }
    }

    /// Refuses the seating keys where no bars hold the specimen (every scene kind but `shpb`,
    /// and a cylinder, which sits on butt joints).
    pub(crate) fn refuse_seating_keys(&self, v: &Validator) -> Result<()> {
        for (key, given) in [
            ("gap_m", self.gap_m.is_some()),
            ("preload_n", self.preload_n.is_some()),
        ] {
            if given {
                return Err(v.error(
                    key,
                    format!("`{key}` is how spheres sit between the bars of a test"),
                    "kind = \"shpb\" with a specimen of spheres",
                ));
            }
        }
        Ok(())
    }

    /// Whether the table asks for a cylinder (`shape = "cylinder"`); an unknown `shape` is an
    /// error naming the allowed ones.
    pub fn is_cylinder(&self, v: &Validator) -> Result<bool> {
        match self.shape.as_deref() {
            None | Some("spheres") => Ok(false),
            Some("cylinder") => Ok(true),
            Some(other) => Err(v.error(
                "shape",
                format!("unknown shape `{other}`"),
                "spheres (default), cylinder",
            )),
        }
    }

    /// Refuses the cylinder's keys in a sphere specimen.
    fn refuse_cylinder_keys(&self, v: &Validator) -> Result<()> {
        if self.is_cylinder(v)? {
            return Err(v.error(
                "shape",
                "a cylindrical specimen needs kind = \"shpb\"",
                "shape = \"spheres\" (or no shape) in this scene kind",
            ));
        }
        for (key, given) in [
            ("length_m", self.length_m.is_some()),
            ("gauge_length_m", self.gauge_length_m.is_some()),
            ("model", self.model.is_some()),
            ("johnson_cook", self.johnson_cook.is_some()),
            ("flow_curve", self.flow_curve.is_some()),
            ("taylor_quinney", self.taylor_quinney.is_some()),
            (
                "initial_temperature_k",
                self.initial_temperature_k.is_some(),
            ),
            ("radial_inertia", self.radial_inertia.is_some()),
            ("friction_coefficient", self.friction_coefficient.is_some()),
            ("friction_model", self.friction_model.is_some()),
            ("design_true_strain", self.design_true_strain.is_some()),
        ] {
            if given {
                return Err(v.error(
                    key,
                    format!("`{key}` belongs to a cylinder"),
                    "shape = \"cylinder\" (kind = \"shpb\") for a cylindrical specimen",
                ));
            }
        }
        Ok(())
    }

    /// The sphere material's name or file, if given (a table is a cylinder's).
    fn material_name(&self, v: &Validator) -> Result<Option<String>> {
        match &self.material {
            None => Ok(None),
            Some(toml::Value::String(s)) => Ok(Some(s.clone())),
            Some(_) => Err(v.error(
                "material",
                "a sphere's material is a name, not a table",
                "a built-in material name or a material .toml file",
            )),
        }
    }

    /// Whether the table gives a chain (`count`, `material`, `diameter_m` or `sphere`) rather
    /// than a pair.
    pub fn is_chain_form(&self) -> bool {
        self.count.is_some()
            || self.material.is_some()
            || self.diameter_m.is_some()
            || self.sphere.is_some()
    }

    /// Validates the specimen of a chain (`chain` and `shpb` scenes): any of [`CHAIN_FORMS`].
    pub fn build_chain(&self, base_dir: &Path, v: &Validator) -> Result<SphereChain> {
        self.refuse_cylinder_keys(v)?;
        self.refuse_seating_keys(v)?;
        if !self.is_chain_form() {
            return self.build(base_dir, v).map(|p| SphereChain::from_pair(&p));
        }
        for (key, given) in [
            ("pair", self.pair.is_some()),
            ("sphere1", self.sphere1.is_some()),
            ("sphere2", self.sphere2.is_some()),
        ] {
            if given {
                return Err(v.error(
                    key,
                    format!("`{key}` cannot be combined with count/material/diameter_m/sphere"),
                    CHAIN_FORMS,
                ));
            }
        }
        match (self.count, &self.sphere) {
            (Some(_), Some(_)) => Err(v.error(
                "count",
                "give either `count` (with material and diameter_m) or [[specimen.sphere]] tables, not both",
                CHAIN_FORMS,
            )),
            (Some(n), None) => {
                if !(2..=MAX_CHAIN_SPHERES).contains(&n) {
                    return Err(v.error(
                        "count",
                        format!("{n} is out of range"),
                        format!("2 to {MAX_CHAIN_SPHERES}"),
                    ));
                }
                let (Some(material), Some(d)) = (self.material_name(v)?, self.diameter_m) else {
                    return Err(v.error(
                        if self.material.is_none() { "material" } else { "diameter_m" },
                        "missing: `count` spheres need a material and a diameter_m",
                        CHAIN_FORMS,
                    ));
                };
                let sphere = SphereSpec {
                    material,
                    diameter_m: Some(d),
                    radius_m: None,
                    mass_kg: None,
                }
                .build(base_dir, v)?;
                let mut spheres = vec![sphere; n as usize];
                self.apply_sphere_flow_keys(&mut spheres, v)?;
                Ok(SphereChain { spheres })
            }
            (None, Some(list)) => {
                if let Some(key) = [
                    ("material", self.material.is_some()),
                    ("diameter_m", self.diameter_m.is_some()),
                ]
                .iter()
                .find_map(|(k, g)| g.then_some(*k))
                {
                    return Err(v.error(
                        key,
                        format!("`{key}` belongs in each [[specimen.sphere]] table (or use count)"),
                        CHAIN_FORMS,
                    ));
                }
                if list.len() < 2 || list.len() as i64 > MAX_CHAIN_SPHERES {
                    return Err(v.error(
                        "sphere",
                        format!("{} sphere table(s)", list.len()),
                        format!("2 to {MAX_CHAIN_SPHERES} [[specimen.sphere]] tables"),
                    ));
                }
                let mut spheres = list
                    .iter()
                    .enumerate()
                    .map(|(k, s)| s.build(base_dir, &v.table(&format!("sphere[{}]", k + 1))))
                    .collect::<Result<Vec<_>>>()?;
                self.apply_sphere_flow_keys(&mut spheres, v)?;
                Ok(SphereChain { spheres })
            }
            (None, None) => Err(v.error(
                "count",
                "missing: `material` and `diameter_m` need a `count`",
                CHAIN_FORMS,
            )),
        }
    }

    /// Validates the specimen table of a scene.
    pub fn build(&self, base_dir: &Path, v: &Validator) -> Result<SpherePair> {
        self.refuse_cylinder_keys(v)?;
        self.refuse_seating_keys(v)?;
        if self.is_chain_form() {
            return Err(v.error(
                "count",
                "a chain specimen (count, material, diameter_m, [[specimen.sphere]]) needs kind = \"chain\" or \"shpb\"",
                "pair = \"ss440c\" (or a pair .toml), or [specimen.sphere1] and [specimen.sphere2] tables",
            ));
        }
        let mut pair = match (&self.pair, &self.sphere1, &self.sphere2) {
            (Some(p), None, None) => resolve_pair(p, base_dir, v, "pair")?,
            (None, Some(a), Some(b)) => SpherePair {
                sphere1: a.build(base_dir, &v.table("sphere1"))?,
                sphere2: b.build(base_dir, &v.table("sphere2"))?,
            },
            _ => {
                return Err(v.error(
                "pair",
                "give either `pair` or both `sphere1` and `sphere2`",
                format!(
                    "pair = \"{}\" (or a pair .toml), or [specimen.sphere1] and [specimen.sphere2] tables",
                    crate::material::builtin_names()
                ),
                ));
            }
        };
        self.apply_sphere_flow_keys([&mut pair.sphere1, &mut pair.sphere2], v)?;
        Ok(pair)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneFile;
    use shpb_core::scene::Params;
    use std::path::PathBuf;

    /// The `[specimen]` table `text` built as a scene's pair (`chain` false) or chain.
    fn spheres(text: &str, chain: bool) -> Result<Vec<Sphere>> {
        let spec: SpecimenSpec = toml::from_str(text).expect("a [specimen] table");
        let v = Validator::new("scene.toml").table("specimen");
        if chain {
            spec.build_chain(Path::new("."), &v).map(|c| c.spheres)
        } else {
            spec.build(Path::new("."), &v)
                .map(|p| vec![p.sphere1, p.sphere2])
        }
    }

    fn builtin(name: &str) -> Material {
        Material::builtin(name).expect("a built-in material")
    }

    /// `m` with σy, C and ε̇0 replaced: what the scene keys make of a material.
    fn with_flow(m: Material, yield_stress_pa: f64, c: f64, rate: f64) -> Material {
        Material {
            yield_stress_pa,
            rate: shpb_core::material::JohnsonCook {
                c,
                reference_rate_per_s: rate,
            },
            ..m
        }
    }

    const KEYS: &str = "yield_stress_pa = 1700e6\njc_c = 0.05\njc_reference_rate_per_s = 1.0\n";

    #[test]
    fn flow_keys_replace_every_spheres_constants_and_nothing_else() {
        let ss440c = with_flow(builtin("ss440c"), 1700e6, 0.05, 1.0);
        // pair = name, and a chain of `count` spheres.
        for (text, chain, n) in [
            (format!("pair = \"ss440c\"\n{KEYS}"), false, 2),
            (format!("pair = \"ss440c\"\n{KEYS}"), true, 2),
            (
                format!("count = 5\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3\n{KEYS}"),
                true,
                5,
            ),
        ] {
            let got = spheres(&text, chain).unwrap();
            assert_eq!(got.len(), n, "{text}");
            for s in &got {
                assert_eq!(s.material, ss440c, "{text}");
                assert_eq!(s.radius_m, 6.35e-3 / 2.0);
            }
        }
        // sphere1/sphere2 and [[specimen.sphere]] tables of two materials: both take the keys,
        // each keeps its own elastic constants and density.
        let two = "[sphere1]\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3\n\
                   [sphere2]\nmaterial = \"al2017\"\ndiameter_m = 10e-3\n";
        let list = "[[sphere]]\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3\n\
                    [[sphere]]\nmaterial = \"al2017\"\ndiameter_m = 10e-3\n";
        for (text, chain) in [(two, false), (two, true), (list, true)] {
            let got = spheres(&format!("{KEYS}{text}"), chain).unwrap();
            assert_eq!(got[0].material, ss440c);
            assert_eq!(
                got[1].material,
                with_flow(builtin("al2017"), 1700e6, 0.05, 1.0)
            );
        }
        // One key alone changes only its constant.
        let got = spheres("pair = \"ss440c\"\njc_c = 0.0\n", false).unwrap();
        let own = builtin("ss440c");
        assert_eq!(
            got[1].material,
            with_flow(own.clone(), own.yield_stress_pa, 0.0, 1e-3)
        );
        // Without the keys: the material's own constants.
        let got = spheres("pair = \"ss440c\"\n", false).unwrap();
        assert_eq!(got[0].material, own);
    }

    #[test]
    fn flow_keys_are_checked_as_the_material_files_are() {
        // The same value refused in a material file and in a scene's [specimen] table: the same
        // problem and allowed range, under the key where each stands.
        let material = include_str!("../../../specimens/ss440c.toml");
        for (key, bad) in [
            ("yield_stress_pa", "-1.0"),
            ("yield_stress_pa", "0.0"),
            ("jc_c", "1.5"),
            ("jc_c", "-0.01"),
            ("jc_reference_rate_per_s", "0.0"),
            ("jc_reference_rate_per_s", "2e9"),
            ("yield_stress_pa", "nan"),
        ] {
            let file_text: String = material
                .lines()
                .map(|l| {
                    if l.starts_with(&format!("{key} ")) {
                        format!("{key} = {bad}")
                    } else {
                        l.to_string()
                    }
                })
                .collect::<Vec<_>>()
                .join("\n");
            let Err(Error::Input {
                key: file_key,
                problem: file_problem,
                allowed: file_allowed,
                ..
            }) = Material::from_toml(&file_text, "m.toml")
            else {
                panic!("{key} = {bad} accepted in a material file");
            };
            assert_eq!(file_key, key);
            for chain in [false, true] {
                let e = spheres(&format!("pair = \"ss440c\"\n{key} = {bad}\n"), chain).unwrap_err();
                let Error::Input {
                    file,
                    key: k,
                    problem,
                    allowed,
                } = &e
                else {
                    panic!("{e}");
                };
                assert_eq!(file, "scene.toml");
                assert_eq!(k, &format!("specimen.{key}"));
                assert_eq!((problem, allowed), (&file_problem, &file_allowed), "{e}");
            }
        }
    }

    fn scene(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes")
            .join(name)
    }

    /// The spheres of a repository scene read with `--set` overrides, as `shpb run --set` reads it.
    fn scene_spheres(name: &str, set: &[(&str, f64)]) -> Result<Vec<Sphere>> {
        let overrides: Vec<(String, toml::Value)> = set
            .iter()
            .map(|(k, x)| (k.to_string(), toml::Value::Float(*x)))
            .collect();
        let p = Params::from_file_overridden(&scene(name), &overrides)?;
        Ok(p.specimen
            .as_ref()
            .and_then(|s| s.spheres())
            .expect("a sphere scene")
            .chain
            .spheres
            .clone())
    }

    #[test]
    fn set_reaches_the_spheres_of_every_scene_kind() {
        let set = [
            ("specimen.yield_stress_pa", 1700e6),
            ("specimen.jc_c", 0.05),
            ("specimen.jc_reference_rate_per_s", 1.0),
        ];
        for name in [
            "quasistatic-fig2.toml",
            "constant-rate-ss440c-1e4.toml",
            "collision-ss440c-5ms.toml",
            "collision-dissimilar.toml",
            "force-driven-ss440c-10psi.toml",
            "chain-ss440c-10.toml",
            "shpb-ss440c-10psi.toml",
            "shpb-ss440c-seated-gap.toml",
        ] {
            let own = scene_spheres(name, &[]).unwrap();
            let got = scene_spheres(name, &set).unwrap();
            assert_eq!(got.len(), own.len(), "{name}");
            for (g, o) in got.iter().zip(&own) {
                let expected = with_flow(o.material.clone(), 1700e6, 0.05, 1.0);
                assert_eq!(g.material, expected, "{name}");
                assert_eq!((g.radius_m, g.mass_kg), (o.radius_m, o.mass_kg), "{name}");
            }
        }
        // Out of range on the command line: the scene file and the key named.
        let e = scene_spheres("force-driven-ss440c-10psi.toml", &[("specimen.jc_c", 2.0)])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("force-driven-ss440c-10psi.toml") && e.contains("`specimen.jc_c`"),
            "{e}"
        );
    }
}
