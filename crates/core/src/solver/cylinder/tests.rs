//! The elastoplastic cylinder against its constitutive law, today's elastic cylinder, the energy
//! ledger, Davies–Hunter's inertia and the friction factors (docs/physics.md §6.12).
use super::*;
use crate::bar::{BarMaterial, BarSpec, Dispersion, EndCondition, Segment};
use crate::flow::{FlowTable, Friction, FrictionModel, JohnsonCook, ThermalSoftening};
use crate::solver::body::BodySpec;
use crate::solver::chain::{ChainSetup, simulate_chain};
use crate::solver::{GaugeProbe, Joint};
use crate::specimen::CylinderSpecimen;

const ALUMINIUM: BarMaterial = BarMaterial {
    density_kg_m3: 2700.0,
    youngs_modulus_pa: 70e9,
    poisson_ratio: 0.33,
};

const COPPER: BarMaterial = BarMaterial {
    density_kg_m3: 8960.0,
    youngs_modulus_pa: 124e9,
    poisson_ratio: 0.34,
};

fn copper_jc(thermal: bool) -> JohnsonCook {
    JohnsonCook {
        a_pa: 90e6,
        b_pa: 292e6,
        n: 0.31,
        c: 0.025,
        reference_rate_per_s: 1.0,
        thermal: thermal.then_some(ThermalSoftening {
            m: 1.09,
            room_temperature_k: 298.0,
            melt_temperature_k: 1356.0,
            specific_heat_j_kg_k: 383.0,
            taylor_quinney: 0.9,
        }),
    }
}

fn cylinder(material: BarMaterial, d: f64, l: f64, flow: FlowModel) -> CylinderSpecimen {
    CylinderSpecimen {
        material,
        diameter_m: d,
        length_m: l,
        flow,
        radial_inertia: false,
        friction: None,
        initial_temperature_k: 298.0,
        design_true_strain: 0.0,
    }
}

/// One element compressed at a constant true-ish rate between prescribed end velocities (no
/// acceleration after the first step): the element's true stress is σ_f at its own ε̄p, ε̇p and
/// T (the temperature before the step's heating) to 1e-6 (measured: ~1e-15), the faces carry it
/// too, and the curve is Johnson–Cook's (or the table's) at the nominal plastic strain.
#[test]
fn a_uniform_element_reproduces_its_flow_law() {
    let table = FlowTable::new("t", vec![0.0, 0.1, 0.4], vec![100e6, 180e6, 240e6]).unwrap();
    for flow in [
        FlowModel::JohnsonCook(copper_jc(false)),
        FlowModel::JohnsonCook(copper_jc(true)),
        FlowModel::Tabulated(table),
    ] {
        let spec = cylinder(COPPER, 5e-3, 5e-3, flow.clone());
        let dt = 5e-3 / (1.5 * COPPER.wave_speed_m_s());
        let mut c = PlasticCylinder::new(&spec, dt).unwrap();
        assert_eq!(c.element_count(), 1);
        let speed = 5.0; // ε̇ ≈ 1000/s
        let mut worst = 0.0f64;
        let mut worst_face = 0.0f64;
        let mut heat = 0.0;
        let (mut eqps, mut temp) = (0.0, 298.0);
        let mut last_flow = 0.0;
        while c.sample().true_strain < 0.3 {
            c.step_with_end_velocities(0.5 * speed, -0.5 * speed);
            let new_eqps = c.plastic_strain(0);
            if new_eqps > eqps {
                let rate = (new_eqps - eqps) / dt;
                let sigma_f = flow.flow_stress_pa(new_eqps, rate, temp);
                let sigma = -c.element_stress_pa(0);
                worst = worst.max((sigma - sigma_f).abs() / sigma_f);
                heat += 0.9 * sigma_f * (new_eqps - eqps) / (COPPER.density_kg_m3 * 383.0);
                last_flow = sigma_f;
            }
            // The faces (read one step later, at the level of the forces) carry the element's
            // stress once the velocities are steady.
            if c.time_s() > 3.0 * dt && c.sample().plastic_strain > 0.0 {
                let s = c.sample();
                worst_face = worst_face
                    .max((s.face_stress_pa - s.element_stress_pa).abs() / s.element_stress_pa);
            }
            eqps = new_eqps;
            temp = c.temperature_k(0);
        }
        assert!(worst <= 1e-6, "{flow:?}: {worst:e}");
        assert!(worst_face <= 1e-9, "{flow:?}: faces {worst_face:e}");
        // The curve: at the end, ε̄p is the true strain less the elastic one, the rate the
        // applied one, within the elastic strain's share.
        let strain = -((5e-3 + c.displacement_m(1) - c.displacement_m(0)) / 5e-3).ln();
        // −ln(l/L₀) = ε̄p − ln(1 − σ/E) (the elastic strain (l − l_p)/l_p = −σ/E).
        let nominal = strain + (1.0 - last_flow / COPPER.youngs_modulus_pa).ln();
        assert!(
            (c.plastic_strain(0) - nominal).abs() < 1e-12,
            "{} vs {nominal}",
            c.plastic_strain(0)
        );
        eprintln!("{flow:?}: element {worst:.1e}, faces {worst_face:.1e}");
        if flow.thermal().is_some() {
            let rise = c.temperature_k(0) - 298.0;
            assert!(
                rise > 10.0 && (rise - heat).abs() <= 1e-9 * rise,
                "{rise} vs {heat}"
            );
        } else {
            assert_eq!(c.temperature_k(0), 298.0);
        }
    }
}

/// Striker → incident → specimen → transmission with butt joints, 1 mm steel cells; the
/// specimen 6 mm long (5 cells at Courant 0.85: the leapfrog, not a delay line).
fn test_chain(specimen: BodySpec, speed: f64) -> ChainSetup {
    let steel = BarMaterial {
        density_kg_m3: 8000.0,
        youngs_modulus_pa: 200e9,
        poisson_ratio: 0.29,
    };
    let bar = |name: &str, length_m: f64, right_end: EndCondition| {
        BodySpec::Bar(BarSpec {
            name: name.into(),
            segments: vec![Segment {
                length_m,
                diameter_m: 0.02,
                material: steel,
            }],
            left_end: EndCondition::Free,
            right_end,
            dispersion: Dispersion::None,
        })
    };
    ChainSetup {
        bodies: vec![
            bar("striker", 0.2, EndCondition::Free),
            bar("incident", 1.0, EndCondition::Free),
            specimen,
            bar("transmission", 1.0, EndCondition::Absorbing),
        ],
        joints: vec![Joint::Butt; 3],
        striker_velocity_m_s: speed,
        dt_s: 1e-3 / steel.wave_speed_m_s(),
        end_time_s: 500e-6,
        gauges: vec![
            GaugeProbe {
                name: "incident".into(),
                bar: 1,
                x_m: 0.5,
                length_m: 0.0,
            },
            GaugeProbe {
                name: "transmission".into(),
                bar: 3,
                x_m: 0.5,
                length_m: 0.0,
            },
        ],
        record_every: 1,
        end_masses: vec![],
        snapshot_every: None,
        snapshot_spacing_m: 1e-3,
        drive_force_n: Vec::new(),
    }
}

/// A yield stress far above the load (A = 1e15 Pa), and the elastic flow model, give today's
/// elastic cylinder (a bar segment between butt joints) bit for bit: gauges and energies.
#[test]
fn a_yield_far_above_the_load_is_todays_elastic_cylinder() {
    let d = 0.012;
    let elastic = BodySpec::Bar(BarSpec {
        name: "specimen".into(),
        segments: vec![Segment {
            length_m: 6e-3,
            diameter_m: d,
            material: ALUMINIUM,
        }],
        left_end: EndCondition::Free,
        right_end: EndCondition::Free,
        dispersion: Dispersion::None,
    });
    let today = simulate_chain(&test_chain(elastic, 10.0)).unwrap();
    let peak = today.strain[1].iter().fold(0.0f64, |a, &e| a.max(e.abs()));
    assert!(peak > 1e-4, "the specimen transmits: {peak}");
    let mut jc = copper_jc(true);
    jc.a_pa = 1e15;
    for flow in [FlowModel::JohnsonCook(jc), FlowModel::Elastic] {
        let spec = cylinder(ALUMINIUM, d, 6e-3, flow);
        let run = simulate_chain(&test_chain(BodySpec::Cylinder(spec), 10.0)).unwrap();
        assert_eq!(run.strain, today.strain);
        assert_eq!(run.bar_energy_j, today.bar_energy_j);
        assert_eq!(run.shaper_energy_j, today.shaper_energy_j);
        assert!(run.plastic_work_j.iter().all(|&w| w == 0.0));
        let s = run.specimen.as_ref().unwrap();
        assert_eq!(s.time_s.len(), run.time_s.len() - 1);
        assert!(s.face_stress_pa.iter().any(|&x| x > 10e6));
    }
}

/// The chain's ledger with a flowing copper specimen: striker = bodies (bars + specimen kinetic
/// and elastic) + absorbed + joints + plastic + friction − inertia exchange, at every sample to
/// 1e-9 of the striker's energy (measured ≤ 1e-14), friction and radial inertia on and off.
#[test]
fn the_energy_ledger_closes_with_a_flowing_specimen() {
    for (friction, inertia) in [
        (None, false),
        (Some(FrictionModel::Avitzur), false),
        (Some(FrictionModel::Slab), true),
        (None, true),
    ] {
        let mut spec = cylinder(COPPER, 0.01, 6e-3, FlowModel::JohnsonCook(copper_jc(true)));
        spec.design_true_strain = 0.4;
        spec.radial_inertia = inertia;
        spec.friction = friction.map(|model| Friction {
            coefficient: 0.1,
            model,
        });
        let run = simulate_chain(&test_chain(BodySpec::Cylinder(spec), 15.0)).unwrap();
        let e0 = run.striker_energy_j;
        let mut worst = 0.0f64;
        for i in 0..run.time_s.len() {
            let books = run.bar_energy_j[i]
                + run.absorbed_energy_j[i]
                + run.shaper_energy_j[i]
                + run.contact_energy_j[i]
                + run.plastic_work_j[i]
                + run.friction_work_j[i]
                - run.inertia_exchange_j[i];
            worst = worst.max((books - e0).abs() / e0);
        }
        let plastic = *run.plastic_work_j.last().unwrap();
        let friction_work = *run.friction_work_j.last().unwrap();
        let exchange = *run.inertia_exchange_j.last().unwrap();
        let s = run.specimen.as_ref().unwrap();
        let strain = s.true_strain.iter().fold(0.0f64, |a, &x| a.max(x));
        eprintln!(
            "{friction:?} inertia {inertia}: closure {worst:.1e}, plastic {:.3} of E0, friction {:.3}, exchange {:.1e}, strain {strain:.3}",
            plastic / e0,
            friction_work / e0,
            exchange / e0
        );
        assert!(worst <= 1e-9, "{friction:?} {inertia}: {worst:e}");
        assert!(
            plastic > 0.01 * e0 && strain > 0.05,
            "it flows: {plastic} of {e0}"
        );
        assert_eq!(friction_work > 0.0, friction.is_some());
        assert_eq!(exchange != 0.0, inertia);
    }
}

/// Davies & Hunter (1963): a wide soft specimen (d = 20 mm, h = 2 mm, σ_f = 1 MPa) whose front
/// face is driven at a constant acceleration a against a fixed back face: the face-mean stress
/// exceeds the material's by ρ(h²/12 + ν_eff²d²/8)ḧ/h (ν_eff = ½, flowing; the h²/12 part is
/// the face-mean form of their axial h²/6, the lumped chain's own mass distribution; the d²/8
/// part is the radial β term), here 17 times the flow stress: within 5 % (measured below).
#[test]
fn radial_inertia_follows_davies_and_hunter() {
    let flow = FlowModel::JohnsonCook(JohnsonCook {
        a_pa: 1e6,
        b_pa: 0.0,
        n: 1.0,
        c: 0.0,
        reference_rate_per_s: 1.0,
        thermal: None,
    });
    let (d0, h0) = (0.02, 2e-3);
    let mut spec = cylinder(ALUMINIUM, d0, h0, flow);
    spec.radial_inertia = true;
    let dt = 2e-8;
    let mut c = PlasticCylinder::new(&spec, dt).unwrap();
    assert!(c.element_count() >= 10);
    let accel = 1e6;
    let mut worst = 0.0f64;
    let mut largest = 0.0f64;
    let steps = (5e-6 / dt) as usize;
    for k in 0..steps {
        let t_half = (k as f64 + 0.5) * dt;
        c.step_with_end_velocities(accel * t_half, 0.0);
        let s = *c.sample();
        let t = k as f64 * dt;
        if t < 2e-6 {
            continue;
        }
        let h = h0 * (-s.true_strain).exp();
        let d = d0 * (h0 / h).sqrt();
        let rho = ALUMINIUM.density_kg_m3;
        let expected = rho * (h * h / 12.0 + 0.25 * d * d / 8.0) * accel / h;
        worst = worst.max((s.inertia_stress_pa - expected).abs() / expected);
        largest = largest.max(expected / s.element_stress_pa);
    }
    eprintln!("Davies–Hunter: worst {worst:.2e}, inertia/flow up to {largest:.1}");
    assert!(largest > 10.0, "inertia dominates: {largest}");
    assert!(worst <= 0.05, "{worst}");
}

/// Friction where it dominates (μ = 0.3, h/d = 0.25, quasi-static): the mean axial stress over
/// the flow stress is the analytic factor at the current d/h within 5 % (measured below); the
/// friction factors reduce to Siebel's 1 + μd/(3h) for small μ.
#[test]
fn friction_raises_the_stress_by_its_factor() {
    for model in [FrictionModel::Avitzur, FrictionModel::Slab] {
        let f = Friction {
            coefficient: 1e-4,
            model,
        };
        let siebel = 1.0 + 1e-4 * 4.0 / 3.0;
        assert!((f.factor(8e-3, 2e-3) - siebel).abs() < 1e-7);
    }
    let avitzur = Friction {
        coefficient: 0.3,
        model: FrictionModel::Avitzur,
    };
    let m = 3f64.sqrt() * 0.3;
    assert!((avitzur.factor(4.0, 1.0) - (1.0 + m * 4.0 / (3.0 * 3f64.sqrt()))).abs() < 1e-15);
    for model in [FrictionModel::Avitzur, FrictionModel::Slab] {
        let sigma_f = 100e6;
        let flow = FlowModel::JohnsonCook(JohnsonCook {
            a_pa: sigma_f,
            b_pa: 0.0,
            n: 1.0,
            c: 0.0,
            reference_rate_per_s: 1.0,
            thermal: None,
        });
        let (d0, h0) = (8e-3, 2e-3);
        let mut spec = cylinder(ALUMINIUM, d0, h0, flow);
        spec.friction = Some(Friction {
            coefficient: 0.3,
            model,
        });
        spec.design_true_strain = 0.3;
        let dt = h0 / (4.0 * ALUMINIUM.wave_speed_m_s());
        let mut c = PlasticCylinder::new(&spec, dt).unwrap();
        let speed = 1.0; // ε̇ = 500/s
        let mut worst = 0.0f64;
        let mut friction_share = 0.0f64;
        while c.sample().true_strain < 0.2 {
            c.step_with_end_velocities(0.5 * speed, -0.5 * speed);
            let s = *c.sample();
            if s.true_strain < 0.02 {
                continue;
            }
            let h = h0 * (-s.true_strain).exp();
            let d = d0 * (h0 / h).sqrt();
            let factor = Friction {
                coefficient: 0.3,
                model,
            }
            .factor(d, h);
            worst = worst.max((s.face_stress_pa / sigma_f - factor).abs() / factor);
            friction_share = friction_share.max(s.friction_stress_pa / s.element_stress_pa);
        }
        eprintln!("{model:?}: worst {worst:.2e}, friction share {friction_share:.3}");
        assert!(worst <= 0.05, "{model:?}: {worst}");
        assert!(
            friction_share > 0.25,
            "friction dominates: {friction_share}"
        );
        assert!(c.friction_work_j() > 0.3 * c.plastic_work_j());
    }
}

/// Tension kinematics (docs/physics.md §6.13): one element pulled at a steady rate between
/// prescribed end velocities. Its true stress F/A_p (A_p = A₀L₀/l_p, constant plastic volume)
/// is σ_f at its own ε̄p, ε̇p, T to 1e-6, as in compression; and the reduction's conversion of
/// the faces' engineering stress T/A₀ and strain ΔL/L₀ in the uniform limit, σ(1 + ε) and
/// ln(1 + ε) (§7.8.1), gives σ_f (1 + σ_f/E) and ε̄p + ln(1 + σ_f/E): the constitutive law, up to
/// the elastic stretch L/l_p = 1 + σ/E that a constant-volume reduction counts as plastic
/// (exactly, to 1e-9 and 1e-12). The series in the loading's sense is tension positive.
#[test]
fn a_uniform_element_in_tension_reproduces_its_flow_law() {
    let table = FlowTable::new("t", vec![0.0, 0.1, 0.4], vec![100e6, 180e6, 240e6]).unwrap();
    for flow in [
        FlowModel::JohnsonCook(copper_jc(false)),
        FlowModel::JohnsonCook(copper_jc(true)),
        FlowModel::Tabulated(table),
    ] {
        let l0 = 5e-3;
        let spec = cylinder(COPPER, 5e-3, l0, flow.clone());
        let dt = l0 / (1.5 * COPPER.wave_speed_m_s());
        let mut c = PlasticCylinder::new(&spec, dt).unwrap();
        let speed = 5.0; // ε̇ ≈ 1000/s
        let e_mod = COPPER.youngs_modulus_pa;
        let area0 = PI * 0.25 * 5e-3 * 5e-3;
        let (mut worst, mut worst_stress, mut worst_strain) = (0.0f64, 0.0f64, 0.0f64);
        let (mut eqps, mut temp) = (0.0, 298.0);
        let mut series = SpecimenSeries::default();
        let mut steps = 0;
        // The element's stress and plastic strain at the last level (after its return map).
        let mut previous: Option<(f64, f64)> = None;
        while -c.sample().true_strain < 0.3 {
            let f = c.step_with_end_velocities(-0.5 * speed, 0.5 * speed);
            steps += 1;
            series.push(c.time_s(), c.sample());
            // Once steady, the right face's pull at level n is the element's force there: the
            // faces' engineering stress and strain at that level, converted as the reduction
            // converts them.
            if let Some((sigma_n, eqps_n)) = previous
                && steps > 3
                && eqps_n > 0.0
            {
                let length = l0 * (-c.sample().true_strain).exp();
                let (s_eng, e_eng) = (f[1] / area0, length / l0 - 1.0);
                let (s_true, e_true) = (s_eng * (1.0 + e_eng), (1.0 + e_eng).ln());
                let elastic = 1.0 + sigma_n / e_mod;
                worst_stress = worst_stress.max((s_true / (sigma_n * elastic) - 1.0).abs());
                worst_strain = worst_strain.max((e_true - (eqps_n + elastic.ln())).abs());
            }
            let new_eqps = c.plastic_strain(0);
            if new_eqps > eqps {
                let rate = (new_eqps - eqps) / dt;
                let sigma_f = flow.flow_stress_pa(new_eqps, rate, temp);
                // Tension: the element's stress is positive.
                let sigma = c.element_stress_pa(0);
                worst = worst.max((sigma - sigma_f).abs() / sigma_f);
            }
            previous = Some((c.element_stress_pa(0), new_eqps));
            eqps = new_eqps;
            temp = c.temperature_k(0);
        }
        eprintln!(
            "{flow:?}: element {worst:.1e}, true stress {worst_stress:.1e}, strain {worst_strain:.1e}"
        );
        assert!(worst <= 1e-6, "{flow:?}: {worst:e}");
        assert!(worst_stress <= 1e-9, "{flow:?}: {worst_stress:e}");
        assert!(worst_strain <= 1e-12, "{flow:?}: {worst_strain:e}");
        // It lengthened and thinned at constant plastic volume; the series reads it tension
        // positive in the loading's sense (and as written in compression).
        assert!(c.plastic_strain(0) > 0.25);
        let pulled = series
            .clone()
            .in_loading_sense(crate::loading::Loading::Tension);
        assert_eq!(
            series.in_loading_sense(crate::loading::Loading::Compression),
            SpecimenSeries {
                face_stress_pa: pulled.face_stress_pa.iter().map(|x| -x).collect(),
                element_stress_pa: pulled.element_stress_pa.iter().map(|x| -x).collect(),
                friction_stress_pa: pulled.friction_stress_pa.iter().map(|x| -x).collect(),
                inertia_stress_pa: pulled.inertia_stress_pa.iter().map(|x| -x).collect(),
                true_strain: pulled.true_strain.iter().map(|x| -x).collect(),
                true_strain_rate_per_s: pulled.true_strain_rate_per_s.iter().map(|x| -x).collect(),
                ..pulled.clone()
            }
        );
        let last = pulled.true_strain.len() - 1;
        assert!(pulled.true_strain[last] > 0.29 && pulled.face_stress_pa[last] > 100e6);
        // Its true strain rate is the pull speed over its current length, ε̇ = v/L.
        let length = l0 * pulled.true_strain[last].exp();
        assert!((pulled.true_strain_rate_per_s[last] * length / speed - 1.0).abs() < 1e-12);
    }
}

/// The test chain loaded in tension (docs/physics.md §6.13): the striker on the flange (a joint
/// that pulls only) moving away at `speed`, the specimen bonded to both bars.
fn tension_chain(specimen: BodySpec, speed: f64) -> ChainSetup {
    let mut setup = test_chain(specimen, -speed);
    setup.joints = vec![Joint::Flange(None), Joint::Bonded, Joint::Bonded];
    setup
}

/// The tension bar's flange is the pressure bar's striker mirrored: until the specimen's
/// reflection reaches the incident gauge the tension run's gauge strain is the compression run's
/// with its sign turned, bit for bit. The copper specimen then flows in tension (lengthens), and
/// the chain's energy ledger closes at every sample to 1e-9 of the striker's energy (striker =
/// bars + specimen + joints + plastic work), friction off, radial inertia off and on.
#[test]
fn a_tension_chain_mirrors_the_striker_and_closes_its_ledger() {
    for inertia in [false, true] {
        let mut spec = cylinder(COPPER, 0.01, 6e-3, FlowModel::JohnsonCook(copper_jc(true)));
        spec.radial_inertia = inertia;
        spec.design_true_strain = 0.4;
        let pushed = simulate_chain(&test_chain(BodySpec::Cylinder(spec.clone()), 15.0)).unwrap();
        let pulled = simulate_chain(&tension_chain(BodySpec::Cylinder(spec), 15.0)).unwrap();
        // Incident wave at the gauge (x = 0.5 m of 1 m) from 0.5/c0; the reflection from 1.5/c0.
        let c0 = (200e9f64 / 8000.0).sqrt();
        let before = pulled.time_s.iter().position(|&t| t >= 1.45 / c0).unwrap();
        let mirrored: Vec<f64> = pushed.strain[0][..before].iter().map(|e| -e).collect();
        assert_eq!(pulled.strain[0][..before], mirrored[..]);
        assert!(pulled.strain[0][..before].iter().any(|&e| e > 1e-4));
        assert_eq!(pulled.striker_energy_j, pushed.striker_energy_j);
        let e0 = pulled.striker_energy_j;
        let mut worst = 0.0f64;
        for i in 0..pulled.time_s.len() {
            let books = pulled.bar_energy_j[i]
                + pulled.absorbed_energy_j[i]
                + pulled.shaper_energy_j[i]
                + pulled.contact_energy_j[i]
                + pulled.plastic_work_j[i]
                + pulled.friction_work_j[i]
                - pulled.inertia_exchange_j[i];
            worst = worst.max((books - e0).abs() / e0);
        }
        let s = pulled
            .specimen
            .clone()
            .unwrap()
            .in_loading_sense(crate::loading::Loading::Tension);
        let strain = s.true_strain.iter().fold(0.0f64, |a, &x| a.max(x));
        let plastic = *pulled.plastic_work_j.last().unwrap();
        eprintln!(
            "inertia {inertia}: closure {worst:.1e}, plastic {:.3} of E0, tensile strain {strain:.3}",
            plastic / e0
        );
        assert!(worst <= 1e-9, "inertia {inertia}: {worst:e}");
        assert!(plastic > 0.01 * e0 && strain > 0.05, "it flows: {strain}");
        // The transmission bar is pulled: its gauge reads tension.
        assert!(pulled.strain[1].iter().fold(0.0f64, |a, &e| a.max(e)) > 1e-4);
    }
}

/// The x–t snapshots' sampler reads a cylinder as [`PlasticCylinder::stress_at`] does, bit for
/// bit (the same formula on the same operands, element and weight found once): a copper cylinder
/// squeezed into plastic flow (slack in its elements) and a one-element one, at points before,
/// on and beyond its ends, on element centres and between them.
#[test]
fn sampled_stresses_are_stress_at() {
    for (d, l) in [(5e-3, 5e-3), (8e-3, 4e-3)] {
        let spec = cylinder(COPPER, d, l, FlowModel::JohnsonCook(copper_jc(false)));
        let dt = if d == l {
            l / (1.5 * COPPER.wave_speed_m_s())
        } else {
            2e-9
        };
        let mut c = PlasticCylinder::new(&spec, dt).unwrap();
        let length = c.initial_length_m();
        let mut x_m: Vec<f64> = (-2..=42).map(|k| length * k as f64 / 40.0).collect();
        x_m.extend([0.5 * length / c.element_count() as f64, 1e-12, length]);
        let sampler = c.stress_sampler(&x_m);
        let mut compared = 0;
        for k in 0..400 {
            c.step_with_end_velocities(10.0 * (k as f64 / 50.0).min(1.0), -3.0);
            let sampled = c.sample_stress(&sampler);
            for (x, s) in x_m.iter().zip(&sampled) {
                let reference = c.stress_at(*x);
                assert_eq!(s.to_bits(), reference.to_bits(), "at {x}");
                compared += usize::from(reference != 0.0);
            }
        }
        assert!(c.plastic_strain(0) > 0.0, "the cylinder did not yield");
        assert!(compared > 10_000, "only {compared} loaded points");
        eprintln!("{} elements: {compared} points", c.element_count());
    }
}
