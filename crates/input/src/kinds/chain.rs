//! `kind = "chain"`: a free chain of N ≥ 2 spheres in a line, struck by its first sphere or a
//! striker mass, optionally against a wall (docs/physics.md §8).

use super::{CHAIN_SPECIMEN, Key, LAW, Parsed, REGION2, SceneKind, UNLOADING, check_every};
use crate::error::{Result, Validator};
use crate::material::MaterialFile;
use crate::toml_file::parse_as;
use serde::Deserialize;
use shpb_core::fidelity::Fidelity;
use shpb_core::material::Material;
use shpb_core::scene::SceneParams;
use shpb_core::solver::{FreeChainSetup, StrikerMass, Wall};
use shpb_core::specimen::{Seating, Specimen, SphereSpecimen};
use std::path::Path;

/// The registry entry.
pub(super) const KIND: SceneKind = SceneKind {
    name: "chain",
    help: "N spheres in a line struck by the first (or a striker), optional wall: contact forces, velocities, energy",
    keys: &[
        CHAIN_SPECIMEN,
        LAW,
        REGION2,
        UNLOADING,
        Key {
            key: "velocity1_m_s",
            unit: "m/s",
            default: "required (without striker)",
            meaning: "initial velocity of sphere 1 toward the others, which rest: greater than 0, at most 1e4",
        },
        Key {
            key: "end_time_s",
            unit: "s",
            default: "(N + 2) × the longest Hertz contact time (twice that with a wall)",
            meaning: "end of the run: greater than 0, at most 1",
        },
        Key {
            key: "striker",
            unit: "",
            default: "none",
            meaning: "a rigid striker with a flat face hitting sphere 1 instead: mass_kg (0 to 1e6), velocity_m_s (0 to 1e4), optional material of its face (built-in or .toml; none: rigid)",
        },
        Key {
            key: "wall",
            unit: "",
            default: "none (free end)",
            meaning: "a fixed flat after the last sphere: kind = \"rigid\", or kind = \"elastic\" with material (built-in or .toml)",
        },
        Key {
            key: "time_step_s",
            unit: "s",
            default: "shortest Hertz contact time / steps_per_contact",
            meaning: "time step; at most the stability limit 1/ω of the stiffest contact",
        },
        Key {
            key: "steps_per_contact",
            unit: "",
            default: "fidelity: 200, 2000, 20000",
            meaning: "time steps per Hertz contact time of the stiffest contact, 20 to 1e8",
        },
        Key {
            key: "output_every",
            unit: "",
            default: "1, or the smallest n keeping the series within 2e7 numbers (160 MB)",
            meaning: "keep every n-th step in the output (1 or more); unset, the run warns when it keeps fewer than every step",
        },
    ],
    example: "kind = \"chain\"\nvelocity1_m_s = 5.0\nend_time_s = 75e-6\nspecimen = { count = 10, material = \"ss440c\", diameter_m = 6.35e-3 }\n",
    example_dir: None,
    parse,
};

/// `[striker]` of a chain scene.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StrikerSpec {
    mass_kg: f64,
    velocity_m_s: f64,
    material: Option<String>,
}

/// `[wall]` of a chain scene.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct WallSpec {
    kind: String,
    material: Option<String>,
}

super::sphere_scene_file! {
    struct ChainFile {
        velocity1_m_s: Option<f64>,
        end_time_s: Option<f64>,
        striker: Option<StrikerSpec>,
        wall: Option<WallSpec>,
        time_step_s: Option<f64>,
        steps_per_contact: Option<f64>,
        output_every: Option<usize>,
    }
}

fn parse(
    text: &str,
    file: &str,
    base_dir: &Path,
    fidelity: Fidelity,
    v: &Validator,
) -> Result<Parsed> {
    let f: ChainFile = parse_as(text, file)?;
    let chain = f.specimen.build_chain(base_dir, &v.table("specimen"))?;
    let striker = match &f.striker {
        Some(s) => {
            let sv = v.table("striker");
            if f.velocity1_m_s.is_some() {
                return Err(v.error(
                    "velocity1_m_s",
                    "given with a [striker]: the striker moves, the spheres rest",
                    "either velocity1_m_s or a [striker] table",
                ));
            }
            Some(StrikerMass {
                mass_kg: sv.positive("mass_kg", s.mass_kg, 1e6, "kg")?,
                velocity_m_s: sv.positive("velocity_m_s", s.velocity_m_s, 1e4, "m/s")?,
                material: s
                    .material
                    .as_deref()
                    .map(|m| Material::resolve(m, base_dir, &sv, "material"))
                    .transpose()?,
            })
        }
        None => None,
    };
    let velocity1_m_s = match (f.velocity1_m_s, &striker) {
        (Some(v1), None) => {
            if !(v1.is_finite() && v1 > 0.0) {
                return Err(v.error(
                    "velocity1_m_s",
                    format!("{v1} m/s: sphere 1 never reaches the others, which rest"),
                    "greater than 0, at most 1e4 m/s",
                ));
            }
            v.positive("velocity1_m_s", v1, 1e4, "m/s")?
        }
        (None, None) => {
            return Err(v.error(
                "velocity1_m_s",
                "missing",
                "the initial velocity of sphere 1 (greater than 0, at most 1e4 m/s), or a [striker] table",
            ));
        }
        (_, Some(_)) => 0.0,
    };
    let wall = match &f.wall {
        None => None,
        Some(w) => {
            let wv = v.table("wall");
            match (w.kind.as_str(), &w.material) {
                ("rigid", None) => Some(Wall::Rigid),
                ("elastic", Some(m)) => Some(Wall::Elastic(Material::resolve(
                    m, base_dir, &wv, "material",
                )?)),
                ("rigid", Some(_)) => {
                    return Err(wv.error(
                        "material",
                        "a rigid wall has no material",
                        "kind = \"elastic\" with a material, or kind = \"rigid\" alone",
                    ));
                }
                ("elastic", None) => {
                    return Err(wv.error(
                        "material",
                        "missing: an elastic wall needs its material",
                        "a built-in material name or a material .toml file",
                    ));
                }
                (other, _) => {
                    return Err(wv.error(
                        "kind",
                        format!("unknown wall `{other}`"),
                        "rigid, elastic",
                    ));
                }
            }
        }
    };
    let mut setup = FreeChainSetup {
        chain,
        law: f.law_spec(),
        velocity1_m_s,
        striker,
        wall,
        dt_s: 0.0,
        end_time_s: 0.0,
        output_every: f.output_every.map_or(Ok(1), |n| check_every(v, n))?,
        output_every_by_budget: f.output_every.is_none(),
    };
    let times = setup.hertz_contact_times_s();
    let tc_max = times.iter().copied().fold(0.0, f64::max);
    if !times.iter().all(|t| t.is_finite() && *t > 0.0) {
        return Err(v.error(
            "velocity1_m_s",
            format!(
                "striking speed {:e} m/s gives no finite contact time",
                setup.impact_speed_m_s()
            ),
            "a normal (not subnormal) positive number of m/s",
        ));
    }
    // Issue 42: the first contact's striking speed within the resolvable, in-model range.
    let speed_key = if setup.striker.is_some() {
        "striker.velocity_m_s"
    } else {
        "velocity1_m_s"
    };
    setup.check_impact_speed().map_err(v.core(speed_key))?;
    let n = v.in_range(
        "steps_per_contact",
        f.steps_per_contact.unwrap_or(fidelity.dem_steps()),
        20.0,
        1e8,
        "",
    )?;
    setup.dt_s = match f.time_step_s {
        Some(dt) => v.positive(
            "time_step_s",
            dt,
            setup.stability_limit(),
            "s (the stability limit 1/ω of the stiffest contact)",
        )?,
        None => setup.default_time_step(n),
    };
    let walls = if setup.wall.is_some() { 2.0 } else { 1.0 };
    let default_end = walls * (setup.chain.len() as f64 + 2.0) * tc_max;
    setup.end_time_s = match f.end_time_s {
        Some(t) => v.positive("end_time_s", t, 1.0, "s")?,
        None => default_end,
    };
    // Issue 45: unless the scene sets it, keep the series within the budget.
    if setup.output_every_by_budget {
        setup.output_every =
            setup.output_every_within(shpb_core::solver::spheres::CHAIN_OUTPUT_BUDGET_NUMBERS);
    }
    let specimen = Specimen::Spheres(SphereSpecimen {
        chain: setup.chain.clone(),
        law: setup.law,
        seating: Seating::Touching,
    });
    Ok((Some(specimen), SceneParams::Chain(Box::new(setup))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registry_entry() {
        super::super::check_kind(&KIND, &[]);
        let steps = Fidelity::ALL.map(|f| f.dem_steps().to_string()).join(", ");
        assert_eq!(KIND.keys[9].default, format!("fidelity: {steps}"));
    }

    #[test]
    fn example_values() {
        let (specimen, p) = super::super::parse_example(&KIND, Fidelity::Standard);
        let pair = specimen.unwrap().spheres().unwrap().first_pair();
        let SceneParams::Chain(s) = p else {
            panic!("not a chain: {p:?}")
        };
        assert_eq!(s.chain.len(), 10);
        assert_eq!((s.velocity1_m_s, s.end_time_s), (5.0, 75e-6));
        assert_eq!(s.chain.pair(0), pair);
        // Identical spheres: every contact has the pair's Hertz time; the step is 1/2000 of it.
        let c = pair.contact_properties();
        let tc = shpb_core::solver::hertz_impact_duration(
            pair.reduced_mass_kg(),
            c.e_star_pa,
            c.radius_m,
            5.0,
        );
        assert_eq!(s.dt_s, tc / 2000.0);
    }

    fn error(extra: &str, specimen: &str) -> String {
        let v = Validator::new("c.toml");
        let text = format!("kind = \"chain\"\n{extra}\n[specimen]\n{specimen}\n");
        parse(&text, "c.toml", Path::new("."), Fidelity::Standard, &v)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn errors_name_file_key_and_range() {
        let ten = "count = 10\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3";
        for (extra, specimen, expected) in [
            (
                "velocity1_m_s = 5.0",
                "count = 1\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3",
                "c.toml: `specimen.count`: 1 is out of range; allowed: 2 to 100000",
            ),
            (
                "velocity1_m_s = 5.0",
                "count = 3\nmaterial = \"ss440c\"\ndiameter_m = -6.35e-3",
                "c.toml: `specimen.diameter_m`",
            ),
            (
                "velocity1_m_s = 5.0",
                "count = 2\n[[specimen.sphere]]\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3",
                "c.toml: `specimen.count`: give either `count`",
            ),
            (
                "velocity1_m_s = 5.0",
                "[[specimen.sphere]]\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3",
                "c.toml: `specimen.sphere`: 1 sphere table(s); allowed: 2 to 100000",
            ),
            ("velocity1_m_s = 0.0", ten, "c.toml: `velocity1_m_s`: 0 m/s"),
            ("", ten, "c.toml: `velocity1_m_s`: missing"),
            (
                "velocity1_m_s = 5.0\n[striker]\nmass_kg = 1.0\nvelocity_m_s = 2.0",
                ten,
                "c.toml: `velocity1_m_s`: given with a [striker]",
            ),
            (
                "velocity1_m_s = 5.0\n[wall]\nkind = \"soft\"",
                ten,
                "c.toml: `wall.kind`: unknown wall `soft`; allowed: rigid, elastic",
            ),
            (
                "velocity1_m_s = 5.0\n[wall]\nkind = \"elastic\"",
                ten,
                "c.toml: `wall.material`: missing",
            ),
            (
                "velocity1_m_s = 5.0\ntime_step_s = 1e-5",
                ten,
                "c.toml: `time_step_s`: ",
            ),
        ] {
            let e = error(extra, specimen);
            assert!(e.starts_with(expected), "{e}\n  expected: {expected}");
        }
    }

    #[test]
    fn a_striker_and_a_wall() {
        let v = Validator::new("c.toml");
        let text = "kind = \"chain\"\n[striker]\nmass_kg = 0.01\nvelocity_m_s = 2.0\nmaterial = \"ss302\"\n[wall]\nkind = \"rigid\"\n[specimen]\ncount = 3\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3\n";
        let (_, p) = parse(text, "c.toml", Path::new("."), Fidelity::Fast, &v).unwrap();
        let SceneParams::Chain(s) = p else {
            panic!("not a chain")
        };
        assert_eq!(s.impact_speed_m_s(), 2.0);
        assert_eq!(s.first_sphere(), 1);
        assert_eq!(s.wall, Some(Wall::Rigid));
        assert_eq!(
            s.hertz_contact_times_s().len(),
            4,
            "striker, 2 sphere contacts, wall"
        );
    }

    fn parsed(text: &str) -> Box<FreeChainSetup> {
        let v = Validator::new("c.toml");
        match parse(text, "c.toml", Path::new("."), Fidelity::Standard, &v).unwrap() {
            (_, SceneParams::Chain(s)) => s,
            (_, p) => panic!("not a chain: {p:?}"),
        }
    }

    /// Issue 45: without `output_every` a chain keeps every step when that fits the budget (the
    /// shipped 10-sphere scene) and otherwise the smallest n that does; a value the scene sets
    /// is kept as written, whatever the budget.
    #[test]
    fn output_every_is_chosen_for_the_budget_unless_set() {
        let scene = |count: usize, extra: &str| {
            format!(
                "kind = \"chain\"\nvelocity1_m_s = 20.0\nend_time_s = 75e-6\n{extra}\n\
                 [specimen]\ncount = {count}\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3\n"
            )
        };
        let budget = shpb_core::solver::spheres::CHAIN_OUTPUT_BUDGET_NUMBERS;
        let small = parsed(&scene(10, ""));
        assert_eq!(
            (small.output_every, small.output_every_by_budget),
            (1, true)
        );
        let big = parsed(&scene(10_000, ""));
        assert!(big.output_every_by_budget);
        assert_eq!(big.output_every, big.output_every_within(budget));
        assert!(big.output_every > 1);
        let kept = (big.samples_kept(big.output_every) * big.numbers_per_sample()) as f64;
        assert!(kept <= budget, "{kept}");
        let set = parsed(&scene(10_000, "output_every = 3"));
        assert_eq!((set.output_every, set.output_every_by_budget), (3, false));
        let one = parsed(&scene(10_000, "output_every = 1"));
        assert_eq!((one.output_every, one.output_every_by_budget), (1, false));
        assert!(
            error(
                "velocity1_m_s = 20.0\noutput_every = 0",
                "count = 3\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3"
            )
            .starts_with("c.toml: `output_every`: 0 is out of range; allowed: 1 or more")
        );
    }
}
