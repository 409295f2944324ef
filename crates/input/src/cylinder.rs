//! A cylindrical specimen's `[specimen]` keys (`shape = "cylinder"`) validated into the core's
//! [`CylinderSpecimen`] (docs/physics.md §6.9, §6.12): material, geometry, flow model (`model`,
//! `johnson_cook`, `flow_curve`, `taylor_quinney`, `initial_temperature_k`), end friction
//! (`friction_coefficient`, `friction_model`), `radial_inertia` and the grid's
//! `design_true_strain`.

use crate::error::{Error, Result, Validator};
use crate::material::{DEFAULT_TAYLOR_QUINNEY, johnson_cook_from_value, resolve_with_johnson_cook};
use crate::specimen::{CYLINDER_FORM, SpecimenSpec};
use shpb_core::bar::BarMaterial;
use shpb_core::flow::{FlowModel, FlowTable, Friction, FrictionModel};
use shpb_core::specimen::{CylinderSpecimen, DEFAULT_DESIGN_TRUE_STRAIN};
use std::path::Path;

/// Temperature of a specimen without thermal constants, K.
const ROOM_TEMPERATURE_K: f64 = 293.0;

/// The flow models a cylinder may name with `model`.
const MODELS: &str = "elastic, johnson-cook, table";

/// The Johnson–Cook constants a `[specimen.johnson_cook]` table must give to stand alone.
const JOHNSON_COOK_REQUIRED: [&str; 3] = ["a_pa", "b_pa", "n"];

/// What a cylinder's Johnson–Cook constants may be given as, for messages.
const JOHNSON_COOK_FORM: &str = "a [specimen.johnson_cook] table { a_pa, b_pa, n, c, reference_rate_per_s, m, melt_temperature_k, specific_heat_j_kg_k } (a table without a_pa, b_pa and n is merged over the material's), or a material with one (ofhc-copper, al6061-t6, al7075-t6, ti6al4v, steel4340)";

/// A cylinder's Johnson–Cook law (docs/physics.md §6.12) from the scene's `[specimen.johnson_cook]`
/// table `scene` and the material's `[johnson_cook]` table `material`. A scene table with `a_pa`,
/// `b_pa` and `n` stands alone (it replaces the material's); one without them is merged over the
/// material's, key by key (`--set specimen.johnson_cook.b_pa=300e6` changes B only), and refused
/// naming the missing constants when the material has none. Each error names where its constant
/// stands: `specimen.johnson_cook.<key>` if the scene gave it, else
/// `specimen.material.johnson_cook.<key>`.
fn johnson_cook(
    scene: Option<&toml::Value>,
    material: Option<&toml::Value>,
    taylor_quinney: f64,
    v: &Validator,
) -> Result<shpb_core::flow::JohnsonCook> {
    let from = |table: &toml::Value, v: &Validator| {
        johnson_cook_from_value(table, taylor_quinney, v, "johnson_cook")
    };
    let given = match (scene, material) {
        (None, None) => {
            return Err(v.error(
                "johnson_cook",
                "model = \"johnson-cook\" needs constants: the material has no [johnson_cook] table",
                JOHNSON_COOK_FORM,
            ));
        }
        (None, Some(table)) => return from(table, &v.table("material")),
        (Some(toml::Value::Table(given)), _)
            if !JOHNSON_COOK_REQUIRED.iter().all(|k| given.contains_key(*k)) =>
        {
            given
        }
        // A complete table (or a value that is not a table, refused by the reader) stands alone.
        (Some(table), _) => return from(table, v),
    };
    let Some(toml::Value::Table(base)) = material else {
        let missing: Vec<&str> = JOHNSON_COOK_REQUIRED
            .into_iter()
            .filter(|k| !given.contains_key(*k))
            .collect();
        let why = match material {
            None => "the material has no [johnson_cook] table to merge it over",
            Some(_) => "the material's johnson_cook is not a table to merge it over",
        };
        return Err(v.error(
            "johnson_cook",
            format!("missing {}: {why}", missing.join(", ")),
            JOHNSON_COOK_FORM,
        ));
    };
    let mut merged = base.clone();
    merged.extend(given.iter().map(|(k, x)| (k.clone(), x.clone())));
    let merged = toml::Value::Table(merged);
    from(&merged, v).or_else(|e| match &e {
        // A constant the scene did not give is the material's: named where it stands.
        Error::Input { key, .. }
            if base
                .keys()
                .any(|k| !given.contains_key(k) && *key == v.key(&format!("johnson_cook.{k}"))) =>
        {
            from(&merged, &v.table("material"))
        }
        _ => Err(e),
    })
}

/// Validates a cylindrical specimen (`shape = "cylinder"`, docs/physics.md §6.9, §6.12): its
/// geometry, material (a name, a file or a table) and flow keys; `v` reports keys under
/// `[specimen]`.
pub fn build(spec: &SpecimenSpec, base_dir: &Path, v: &Validator) -> Result<CylinderSpecimen> {
    spec.refuse_seating_keys(v)?;
    spec.refuse_sphere_flow_keys(v)?;
    for (key, given) in [
        ("pair", spec.pair.is_some()),
        ("sphere1", spec.sphere1.is_some()),
        ("sphere2", spec.sphere2.is_some()),
        ("count", spec.count.is_some()),
        ("sphere", spec.sphere.is_some()),
    ] {
        if given {
            return Err(v.error(
                key,
                format!("`{key}` describes spheres, not a cylinder"),
                CYLINDER_FORM,
            ));
        }
    }
    // A tension specimen's gauge length is its length under the lab's name (one of the two).
    if let (Some(_), Some(_)) = (spec.length_m, spec.gauge_length_m) {
        return Err(v.error(
            "gauge_length_m",
            "given with length_m: both name the specimen's length",
            "one of length_m or gauge_length_m (the same length, m)",
        ));
    }
    let length_key = if spec.gauge_length_m.is_some() {
        "gauge_length_m"
    } else {
        "length_m"
    };
    let (Some(length), Some(diameter), Some(material)) = (
        spec.length_m.or(spec.gauge_length_m),
        spec.diameter_m,
        &spec.material,
    ) else {
        let key = match (spec.length_m.or(spec.gauge_length_m), spec.diameter_m) {
            (None, _) => "length_m",
            (_, None) => "diameter_m",
            _ => "material",
        };
        return Err(v.error(key, "missing", CYLINDER_FORM));
    };
    let (elastic, material_jc) = match material {
        toml::Value::String(name) => {
            let (m, jc) = resolve_with_johnson_cook(name, base_dir, v, "material")?;
            let elastic = BarMaterial {
                density_kg_m3: m.density_kg_m3,
                youngs_modulus_pa: m.youngs_modulus_pa,
                poisson_ratio: m.poisson_ratio,
            };
            (elastic, jc)
        }
        table @ toml::Value::Table(_) => (crate::setup::bar_material_value(table, v)?, None),
        other => {
            return Err(v.error(
                "material",
                format!("a value of type {} is not a material", other.type_str()),
                CYLINDER_FORM,
            ));
        }
    };
    let taylor_quinney = match spec.taylor_quinney {
        Some(b) => v.in_range("taylor_quinney", b, 0.0, 1.0, "")?,
        None => DEFAULT_TAYLOR_QUINNEY,
    };
    let model = match spec.model.as_deref() {
        Some(m) => m,
        None if spec.johnson_cook.is_some() || material_jc.is_some() => "johnson-cook",
        None if spec.flow_curve.is_some() => "table",
        None => "elastic",
    };
    let flow = match model {
        "elastic" => FlowModel::Elastic,
        "johnson-cook" => FlowModel::JohnsonCook(johnson_cook(
            spec.johnson_cook.as_ref(),
            material_jc.as_ref(),
            taylor_quinney,
            v,
        )?),
        "table" => {
            let Some(curve) = &spec.flow_curve else {
                return Err(v.error(
                    "flow_curve",
                    "model = \"table\" needs a flow curve",
                    "[specimen.flow_curve] with plastic_strain = [0.0, …] and stress_pa = [σy, …]",
                ));
            };
            FlowModel::Tabulated(
                FlowTable::new(
                    "flow_curve",
                    curve.plastic_strain.clone(),
                    curve.stress_pa.clone(),
                )
                .map_err(v.table("flow_curve").core_named())?,
            )
        }
        other => {
            return Err(v.error("model", format!("unknown model `{other}`"), MODELS));
        }
    };
    let flows = !matches!(flow, FlowModel::Elastic);
    let initial_temperature_k = match spec.initial_temperature_k {
        Some(t) => v.positive("initial_temperature_k", t, 1e4, "K")?,
        None => flow
            .thermal()
            .map_or(ROOM_TEMPERATURE_K, |t| t.room_temperature_k),
    };
    let friction = match spec.friction_coefficient {
        None => None,
        Some(mu) => {
            let mu = v.in_range("friction_coefficient", mu, 0.0, 10.0, "")?;
            let model = match spec.friction_model.as_deref() {
                None | Some("avitzur") => FrictionModel::Avitzur,
                Some("slab") => FrictionModel::Slab,
                Some(other) => {
                    return Err(v.error(
                        "friction_model",
                        format!("unknown friction model `{other}`"),
                        "avitzur (default), slab",
                    ));
                }
            };
            (mu > 0.0).then_some(Friction {
                coefficient: mu,
                model,
            })
        }
    };
    if spec.friction_model.is_some() && spec.friction_coefficient.is_none() {
        return Err(v.error(
            "friction_model",
            "given without friction_coefficient",
            "friction_coefficient = μ (0 to 10) with it",
        ));
    }
    let design_true_strain = match spec.design_true_strain {
        Some(e) => v.in_range("design_true_strain", e, 0.0, 2.0, "")?,
        None if flows => DEFAULT_DESIGN_TRUE_STRAIN,
        None => 0.0,
    };
    let c = CylinderSpecimen {
        material: elastic,
        length_m: v.positive(length_key, length, 0.1, "m")?,
        diameter_m: v.positive("diameter_m", diameter, 0.1, "m")?,
        flow,
        radial_inertia: spec.radial_inertia.unwrap_or(false),
        friction,
        initial_temperature_k,
        design_true_strain,
    };
    c.validate().map_err(v.core_named())?;
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;
    use crate::scene::SceneFile;
    use shpb_core::flow::{JohnsonCook, ThermalSoftening};
    use shpb_core::scene::Params;

    const COPPER: &str = "shape = \"cylinder\"\nlength_m = 6e-3\ndiameter_m = 6e-3\n";

    fn cylinder(text: &str) -> Result<CylinderSpecimen> {
        let spec: SpecimenSpec = toml::from_str(text).expect("a [specimen] table");
        build(
            &spec,
            Path::new("."),
            &Validator::new("scene.toml").table("specimen"),
        )
    }

    fn law(c: &CylinderSpecimen) -> JohnsonCook {
        match &c.flow {
            FlowModel::JohnsonCook(jc) => *jc,
            other => panic!("not Johnson–Cook: {other:?}"),
        }
    }

    /// specimens/ofhc-copper.toml's [johnson_cook] (Johnson & Cook 1983, Table 1) with the
    /// default Taylor–Quinney factor.
    fn ofhc_copper() -> JohnsonCook {
        JohnsonCook {
            a_pa: 90e6,
            b_pa: 292e6,
            n: 0.31,
            c: 0.025,
            reference_rate_per_s: 1.0,
            thermal: Some(ThermalSoftening {
                m: 1.09,
                room_temperature_k: 298.0,
                melt_temperature_k: 1356.0,
                specific_heat_j_kg_k: 383.0,
                taylor_quinney: DEFAULT_TAYLOR_QUINNEY,
            }),
        }
    }

    fn input_error(e: Error) -> (String, String, String) {
        match e {
            Error::Input {
                key,
                problem,
                allowed,
                ..
            } => (key, problem, allowed),
            other => panic!("{other}"),
        }
    }

    #[test]
    fn a_partial_johnson_cook_table_is_merged_over_the_materials() {
        let copper = format!("{COPPER}material = \"ofhc-copper\"\n");
        assert_eq!(law(&cylinder(&copper).unwrap()), ofhc_copper());
        for (keys, expect) in [
            (
                "b_pa = 300e6",
                JohnsonCook {
                    b_pa: 300e6,
                    ..ofhc_copper()
                },
            ),
            (
                "a_pa = 80e6\nn = 0.4\nc = 0.03",
                JohnsonCook {
                    a_pa: 80e6,
                    n: 0.4,
                    c: 0.03,
                    ..ofhc_copper()
                },
            ),
            (
                "m = 1.2\nreference_rate_per_s = 1e-3",
                JohnsonCook {
                    reference_rate_per_s: 1e-3,
                    thermal: ofhc_copper()
                        .thermal
                        .map(|t| ThermalSoftening { m: 1.2, ..t }),
                    ..ofhc_copper()
                },
            ),
        ] {
            let text = format!("{copper}[johnson_cook]\n{keys}\n");
            assert_eq!(law(&cylinder(&text).unwrap()), expect, "{keys}");
        }
    }

    #[test]
    fn a_complete_johnson_cook_table_still_replaces_the_materials() {
        // a_pa, b_pa and n stand alone, as before tables were merged: no C, no thermal term.
        let text = format!(
            "{COPPER}material = \"ofhc-copper\"\n[johnson_cook]\na_pa = 100e6\nb_pa = 200e6\nn = 0.5\n"
        );
        let expect = JohnsonCook {
            a_pa: 100e6,
            b_pa: 200e6,
            n: 0.5,
            c: 0.0,
            reference_rate_per_s: 1.0,
            thermal: None,
        };
        assert_eq!(law(&cylinder(&text).unwrap()), expect);
        // A material without constants takes a complete table.
        let text = format!(
            "{COPPER}material = \"al2017\"\n[johnson_cook]\na_pa = 100e6\nb_pa = 200e6\nn = 0.5\n"
        );
        assert_eq!(law(&cylinder(&text).unwrap()), expect);
    }

    #[test]
    fn a_partial_table_without_material_constants_is_refused_naming_the_missing_keys() {
        for material in [
            "material = \"al2017\"",
            "material = { density_kg_m3 = 8960.0, youngs_modulus_pa = 124e9, poisson_ratio = 0.34 }",
        ] {
            let text = format!("{COPPER}{material}\n[johnson_cook]\nb_pa = 300e6\n");
            let (key, problem, allowed) = input_error(cylinder(&text).unwrap_err());
            assert_eq!(key, "specimen.johnson_cook");
            assert!(problem.contains("missing a_pa, n"), "{problem}");
            assert!(allowed.contains("merged over the material's"), "{allowed}");
        }
    }

    #[test]
    fn merged_constants_out_of_range_are_named_where_they_stand() {
        let copper = format!("{COPPER}material = \"ofhc-copper\"\n");
        // The scene's constant: its key under [specimen.johnson_cook].
        let (key, _, allowed) =
            input_error(cylinder(&format!("{copper}[johnson_cook]\nb_pa = -1.0\n")).unwrap_err());
        assert_eq!(key, "specimen.johnson_cook.b_pa");
        assert!(allowed.contains("Pa"), "{allowed}");
        let (key, _, _) =
            input_error(cylinder(&format!("{copper}[johnson_cook]\nc = 11.0\n")).unwrap_err());
        assert_eq!(key, "specimen.johnson_cook.c");
        // B > 0 with the scene's n = 0: the scene's key.
        let (key, _, _) =
            input_error(cylinder(&format!("{copper}[johnson_cook]\nn = 0.0\n")).unwrap_err());
        assert_eq!(key, "specimen.johnson_cook.n");
        // An unknown key in the scene's table: the scene's table named.
        let (key, problem, _) =
            input_error(cylinder(&format!("{copper}[johnson_cook]\nbee = 1.0\n")).unwrap_err());
        assert_eq!(key, "specimen.johnson_cook");
        assert!(problem.contains("bee"), "{problem}");
    }

    #[test]
    fn a_materials_constant_out_of_range_is_named_in_the_material() {
        // A material file whose B is out of range, the scene giving only A: the bad constant
        // is the material's, named under specimen.material; B given by the scene mends it.
        let dir = tempfile::tempdir().unwrap();
        let copper = include_str!("../../../specimens/ofhc-copper.toml")
            .replace("b_pa = 292e6", "b_pa = -292e6");
        std::fs::write(dir.path().join("cu.toml"), copper).unwrap();
        let spec = |keys: &str| -> Result<CylinderSpecimen> {
            let text = format!("{COPPER}material = \"cu.toml\"\n[johnson_cook]\n{keys}\n");
            let spec: SpecimenSpec = toml::from_str(&text).unwrap();
            build(
                &spec,
                dir.path(),
                &Validator::new("scene.toml").table("specimen"),
            )
        };
        let (key, _, _) = input_error(spec("a_pa = 80e6").unwrap_err());
        assert_eq!(key, "specimen.material.johnson_cook.b_pa");
        let (key, _, _) = input_error(spec("b_pa = -1.0").unwrap_err());
        assert_eq!(key, "specimen.johnson_cook.b_pa");
        let mended = spec("b_pa = 300e6").unwrap();
        assert_eq!(
            law(&mended),
            JohnsonCook {
                b_pa: 300e6,
                ..ofhc_copper()
            }
        );
    }

    #[test]
    fn a_spheres_flow_constants_are_refused_for_a_cylinder() {
        for (key, instead) in [
            ("yield_stress_pa", "johnson_cook.a_pa"),
            ("jc_c", "johnson_cook.c"),
            (
                "jc_reference_rate_per_s",
                "johnson_cook.reference_rate_per_s",
            ),
        ] {
            let text = format!("{COPPER}material = \"ofhc-copper\"\n{key} = 1.0\n");
            let (k, _, allowed) = input_error(cylinder(&text).unwrap_err());
            assert_eq!(k, format!("specimen.{key}"));
            assert!(allowed.contains(instead), "{allowed}");
        }
    }

    #[test]
    fn set_reaches_the_johnson_cook_constants_of_the_cylinder_scenes() {
        let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        for name in ["shpb-cylinder-copper.toml", "shtb-cylinder-copper.toml"] {
            let read = |set: &[(&str, f64)]| {
                let overrides: Vec<(String, toml::Value)> = set
                    .iter()
                    .map(|(k, x)| (k.to_string(), toml::Value::Float(*x)))
                    .collect();
                Params::from_file_overridden(&scenes.join(name), &overrides).map(|p| {
                    p.specimen
                        .as_ref()
                        .and_then(|s| s.cylinder())
                        .cloned()
                        .expect("a cylinder scene")
                })
            };
            assert_eq!(law(&read(&[]).unwrap()), ofhc_copper(), "{name}");
            let got = read(&[
                ("specimen.johnson_cook.b_pa", 300e6),
                ("specimen.johnson_cook.n", 0.35),
            ])
            .unwrap();
            let expect = JohnsonCook {
                b_pa: 300e6,
                n: 0.35,
                ..ofhc_copper()
            };
            assert_eq!(law(&got), expect, "{name}");
            let e = read(&[("specimen.yield_stress_pa", 1e8)])
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(name) && e.contains("`specimen.yield_stress_pa`"),
                "{e}"
            );
        }
    }
}
