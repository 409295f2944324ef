//! `kind = "collision"`: two free spheres with initial velocities (restitution, contact time, peak
//! force, energy dissipated).

use super::{
    Key, LAW, OUTPUT_EVERY, Parsed, REGION2, SPECIMEN, SceneKind, UNLOADING, check_every, one,
};
use crate::error::{Result, Validator};
use crate::toml_file::parse_as;
use shpb_core::fidelity::Fidelity;
use shpb_core::scene::SceneParams;
use shpb_core::solver::{self, CollisionSetup};
use std::path::Path;

/// The registry entry.
pub(super) const KIND: SceneKind = SceneKind {
    name: "collision",
    help: "two free spheres with initial velocities: restitution, contact time, peak force, dissipation",
    keys: &[
        SPECIMEN,
        LAW,
        REGION2,
        UNLOADING,
        Key {
            key: "velocity1_m_s",
            unit: "m/s",
            default: "required",
            meaning: "initial velocity of sphere 1 (toward sphere 2), -1e4 to 1e4 and greater than velocity2_m_s",
        },
        Key {
            key: "velocity2_m_s",
            unit: "m/s",
            default: "0",
            meaning: "initial velocity of sphere 2, -1e4 to 1e4",
        },
        Key {
            key: "time_step_s",
            unit: "s",
            default: "Hertz contact time / steps_per_contact",
            meaning: "time step; at most the stability limit 1/ω of the contact",
        },
        Key {
            key: "steps_per_contact",
            unit: "",
            default: "fidelity: 200, 2000, 20000",
            meaning: "time steps per Hertz contact time, 20 to 1e8",
        },
        OUTPUT_EVERY,
    ],
    example: "kind = \"collision\"\nvelocity1_m_s = 5.0\nspecimen = { pair = \"ss440c\" }\n",
    example_dir: None,
    parse,
};

super::sphere_scene_file! {
    struct CollisionFile {
        velocity1_m_s: f64,
        #[serde(default)]
        velocity2_m_s: f64,
        time_step_s: Option<f64>,
        steps_per_contact: Option<f64>,
        #[serde(default = "one")]
        output_every: usize,
    }
}

fn parse(
    text: &str,
    file: &str,
    base_dir: &Path,
    fidelity: Fidelity,
    v: &Validator,
) -> Result<Parsed> {
    let sv = v.table("specimen");
    let f: CollisionFile = parse_as(text, file)?;
    let pair = f.specimen.build(base_dir, &sv)?;
    let v1 = v.in_range("velocity1_m_s", f.velocity1_m_s, -1e4, 1e4, "m/s")?;
    let v2 = v.in_range("velocity2_m_s", f.velocity2_m_s, -1e4, 1e4, "m/s")?;
    if v1 <= v2 {
        return Err(v.error(
            "velocity1_m_s",
            format!("{v1} m/s does not exceed velocity2_m_s = {v2} m/s, so the spheres never meet"),
            "velocity1_m_s > velocity2_m_s",
        ));
    }
    let speed = v1 - v2;
    let p = pair.contact_properties();
    let tc = solver::hertz_impact_duration(pair.reduced_mass_kg(), p.e_star_pa, p.radius_m, speed);
    if !(tc.is_finite() && tc > 0.0) {
        // A closing speed so small (subnormal) that the Hertz contact time overflows.
        return Err(v.error(
            "velocity1_m_s",
            format!("closing speed {speed:e} m/s gives no finite contact time"),
            "velocity1_m_s - velocity2_m_s a normal (not subnormal) positive number of m/s",
        ));
    }
    // Issue 42: a closing speed whose approach round-off decides (restitution 1.0046 at
    // 1e-12 m/s) or that overlaps the spheres by more than a radius (9999 m/s) is refused.
    solver::check_impact_speed(
        pair.reduced_mass_kg(),
        p.e_star_pa,
        p.radius_m,
        pair.sphere1.radius_m.min(pair.sphere2.radius_m),
        pair.sphere1.radius_m + pair.sphere2.radius_m,
        speed,
    )
    .map_err(v.core("velocity1_m_s"))?;
    let n = v.in_range(
        "steps_per_contact",
        f.steps_per_contact.unwrap_or(fidelity.dem_steps()),
        20.0,
        1e8,
        "",
    )?;
    let limit = solver::stability_limit(&pair, solver::hertz_peak_force(&pair, speed));
    let dt = match f.time_step_s {
        Some(dt) => v.positive(
            "time_step_s",
            dt,
            limit,
            "s (the stability limit 1/ω of this contact, solver::stability_limit)",
        )?,
        None => tc / n,
    };
    let setup = CollisionSetup {
        velocity1_m_s: v1,
        velocity2_m_s: v2,
        dt_s: dt,
        max_time_s: solver::COLLISION_TIME_LIMIT_CONTACT_TIMES * tc,
        output_every: check_every(v, f.output_every)?,
    };
    Ok((
        super::pair_specimen(&pair, f.law_spec()),
        SceneParams::Collision(setup),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registry_entry() {
        super::super::check_kind(&KIND, &[]);
        let steps = Fidelity::ALL.map(|f| f.dem_steps().to_string()).join(", ");
        assert_eq!(KIND.keys[7].default, format!("fidelity: {steps}"));
    }

    #[test]
    fn example_values() {
        let (specimen, p) = super::super::parse_example(&KIND, Fidelity::Standard);
        let pair = specimen.unwrap().spheres().unwrap().first_pair();
        let SceneParams::Collision(s) = p else {
            panic!("not a collision: {p:?}")
        };
        assert_eq!(
            (s.velocity1_m_s, s.velocity2_m_s, s.output_every),
            (5.0, 0.0, 1)
        );
        let c = pair.contact_properties();
        let tc =
            solver::hertz_impact_duration(pair.reduced_mass_kg(), c.e_star_pa, c.radius_m, 5.0);
        assert_eq!(s.dt_s, tc / 2000.0);
        assert_eq!(s.max_time_s, 100.0 * tc);
    }

    #[test]
    fn errors_name_the_key() {
        let v = Validator::new("c.toml");
        let text = format!("velocity2_m_s = 5.0\n{}", KIND.example);
        let e = parse(&text, "c.toml", Path::new("."), Fidelity::Standard, &v).unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.toml: `velocity1_m_s`: 5 m/s does not exceed velocity2_m_s = 5 m/s, so the spheres never meet; allowed: velocity1_m_s > velocity2_m_s"
        );
    }
}
