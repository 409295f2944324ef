//! A cylindrical specimen's `[specimen]` keys (`shape = "cylinder"`) validated into the core's
//! [`CylinderSpecimen`] (docs/physics.md §6.9, §6.12): material, geometry, flow model (`model`,
//! `johnson_cook`, `flow_curve`, `taylor_quinney`, `initial_temperature_k`), end friction
//! (`friction_coefficient`, `friction_model`), `radial_inertia` and the grid's
//! `design_true_strain`.

use crate::error::{Result, Validator};
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

/// Validates a cylindrical specimen (`shape = "cylinder"`, docs/physics.md §6.9, §6.12): its
/// geometry, material (a name, a file or a table) and flow keys; `v` reports keys under
/// `[specimen]`.
pub fn build(spec: &SpecimenSpec, base_dir: &Path, v: &Validator) -> Result<CylinderSpecimen> {
    spec.refuse_seating_keys(v)?;
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
    // The scene's own constants win over the material file's; each table's errors name where
    // it stands (`specimen.johnson_cook` or `specimen.material.johnson_cook`).
    let jc_table = spec
        .johnson_cook
        .as_ref()
        .map(|t| (t, v.clone()))
        .or(material_jc.as_ref().map(|t| (t, v.table("material"))));
    let model = match spec.model.as_deref() {
        Some(m) => m,
        None if jc_table.is_some() => "johnson-cook",
        None if spec.flow_curve.is_some() => "table",
        None => "elastic",
    };
    let flow = match model {
        "elastic" => FlowModel::Elastic,
        "johnson-cook" => {
            let Some((table, tv)) = jc_table else {
                return Err(v.error(
                    "johnson_cook",
                    "model = \"johnson-cook\" needs constants: the material has no [johnson_cook] table",
                    "a [specimen.johnson_cook] table { a_pa, b_pa, n, c, reference_rate_per_s, m, melt_temperature_k, specific_heat_j_kg_k }, or a material with one (ofhc-copper, al6061-t6, al7075-t6, ti6al4v, steel4340)",
                ));
            };
            FlowModel::JohnsonCook(johnson_cook_from_value(
                table,
                taylor_quinney,
                &tv,
                "johnson_cook",
            )?)
        }
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
