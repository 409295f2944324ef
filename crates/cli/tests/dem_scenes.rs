//! The sphere-only scenes: elastic and plastic collisions against Hertz theory and energy
//! conservation, constant-rate compression, and the paper's force-driven Fig. 4 DEM against the
//! authors' measurements (validation/fig4-force-driven/data, CC-BY 4.0).

use shpb::contact::{BurgoyneDaraio, Contact, LawKind, Region2Form, Stateful, Unloading};
use shpb::material::Material;
use shpb::prelude::*;
use shpb::scene::{Params, SceneParams, compare_fig4};
use shpb::solver::{self, CollisionSetup};
use shpb::specimen::SpherePair;
use std::path::Path;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn collide(
    pair: &SpherePair,
    law: &dyn Contact,
    speed: f64,
    steps_per_contact: f64,
) -> solver::CollisionResult {
    let p = pair.contact_properties();
    let tc = solver::hertz_impact_duration(pair.reduced_mass_kg(), p.e_star_pa, p.radius_m, speed);
    let setup = CollisionSetup {
        velocity1_m_s: speed,
        velocity2_m_s: 0.0,
        dt_s: tc / steps_per_contact,
        max_time_s: 10.0 * tc,
        output_every: 1,
    };
    solver::collision(law, pair, &setup).unwrap()
}

#[test]
fn elastic_collision_matches_hertz_theory() {
    let mut m = Material::builtin("ss440c").unwrap();
    m.yield_stress_pa = 1e15; // never yields: the law is Hertz
    let pair = SpherePair::paper(m);
    // The `static` rule unloads down the Hertz curve (the default `dynamic` rule would subtract
    // its vibration loss, tested in shpb-core's contact.rs).
    let law = Stateful::new(BurgoyneDaraio::with_options(
        pair.contact_properties(),
        true,
        Region2Form::Smooth,
        Unloading::Static,
    ));
    let p = pair.contact_properties();
    for speed in [0.01, 1.0, 50.0] {
        // The scene default of 2000 steps per Hertz contact time.
        let r = collide(&pair, &law, speed, 2000.0);
        let tc =
            solver::hertz_impact_duration(pair.reduced_mass_kg(), p.e_star_pa, p.radius_m, speed);
        assert!(
            (r.restitution - 1.0).abs() < 1e-6,
            "v = {speed}: e = {}",
            r.restitution
        );
        assert!(
            rel(r.kinetic_energy_after_j, r.kinetic_energy_before_j) < 1e-6,
            "v = {speed}: energy"
        );
        assert!(
            rel(r.contact_time_s, tc) < 5e-3,
            "v = {speed}: contact time {} vs Hertz {tc}",
            r.contact_time_s
        );
        assert!(r.dissipated_j.abs() < 1e-6 * r.kinetic_energy_before_j);
        // Peak force from energy balance: F* = (4/3)E*√r δ*^{3/2}.
        let fmax = solver::hertz_peak_force(&pair, speed);
        assert!(rel(r.peak_force_n, fmax) < 1e-4, "v = {speed}: peak force");
    }
}

#[test]
fn plastic_restitution_falls_with_impact_speed_and_energy_balances() {
    let pair = SpherePair::paper(Material::builtin("ss440c").unwrap());
    for kind in [LawKind::BurgoyneDaraio, LawKind::RateIndependent] {
        let law = kind.build(pair.contact_properties());
        let mut last = f64::INFINITY;
        for speed in [0.5, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 14.0, 20.0] {
            let r = collide(&pair, law.as_ref(), speed, 2000.0);
            assert!(
                r.restitution < last,
                "{kind:?}: e({speed}) = {} not below {last}",
                r.restitution
            );
            // At 0.5 m/s the rate-hardened contact may stay elastic (e = 1); it never exceeds 1.
            assert!(
                r.restitution > 0.0 && r.restitution <= 1.0 + 1e-9,
                "{kind:?} v = {speed}: e = {}",
                r.restitution
            );
            let loss = r.kinetic_energy_before_j - r.kinetic_energy_after_j;
            // Relative to the loss; an elastic impact (loss ~ 1e-15 J, round-off) is held to 1e-12 of the KE.
            let tol = (1e-4 * loss).max(1e-12 * r.kinetic_energy_before_j);
            assert!(
                (r.dissipated_j - loss).abs() < tol,
                "{kind:?} v = {speed}: dissipated {} vs KE loss {loss}",
                r.dissipated_j
            );
            assert!(r.dissipated_j >= -1e-9 * r.kinetic_energy_before_j);
            last = r.restitution;
        }
    }
}

#[test]
fn constant_rate_force_rises_with_rate_and_is_static_at_reference_rate() {
    let pair = SpherePair::paper(Material::builtin("ss440c").unwrap());
    let law = Stateful::new(BurgoyneDaraio::new(pair.contact_properties(), true));
    let delta = 0.25e-3;
    let rates: Vec<f64> = (0..=14)
        .map(|k| 1e-3 * 10f64.powf(k as f64 * 0.5))
        .collect();
    let mut last = 0.0;
    for &rate in &rates {
        let s = solver::constant_rate(&law, &pair, rate, delta, 501);
        let f = *s.force_n.last().unwrap();
        assert_eq!(*s.displacement_m.last().unwrap(), delta);
        assert!(f > last, "F(0.25 mm) at {rate} 1/s = {f} not above {last}");
        last = f;
        let sr = s.strain_rate_per_s.as_ref().unwrap();
        assert!(rel(sr[1], rate) < 1e-12);
    }
    let s = solver::constant_rate(&law, &pair, 1e-3, delta, 501);
    for (d, f) in s.displacement_m.iter().zip(&s.force_n) {
        assert_eq!(
            *f,
            law.law.static_curve().force(*d),
            "at the reference rate the law is static"
        );
    }
}

fn fig4_files() -> Vec<std::path::PathBuf> {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("validation/fig4-force-driven/data");
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .collect();
    v.sort();
    assert_eq!(v.len(), 8);
    v
}

fn fig4_scene(csv: &Path, law: &str) -> Params {
    let material = csv
        .file_name()
        .unwrap()
        .to_string_lossy()
        .split('_')
        .next()
        .unwrap()
        .to_string();
    let text = format!(
        "kind = \"force-driven\"\nlaw = \"{law}\"\nforce_csv = \"{}\"\n[specimen]\npair = \"{material}\"\n",
        csv.display()
    );
    Params::from_toml(&text, "fig4-test.toml", Path::new(".")).unwrap()
}

#[test]
fn force_driven_runs_every_fig4_experiment_and_rate_dependence_wins_for_steels() {
    for csv in fig4_files() {
        let name = csv.file_name().unwrap().to_string_lossy().to_string();
        let mut errors = Vec::new();
        for law in ["burgoyne-daraio", "rate-independent"] {
            let params = fig4_scene(&csv, law);
            let out = params.run().unwrap();
            let SceneParams::ForceDriven {
                setup,
                measured_displacement_m,
            } = &params.params
            else {
                unreachable!()
            };
            let c = compare_fig4(
                out.contact.as_ref().unwrap(),
                &setup.drive,
                measured_displacement_m.as_ref().unwrap(),
            );
            assert!(
                out.contact
                    .as_ref()
                    .unwrap()
                    .force_n
                    .iter()
                    .all(|f| f.is_finite())
            );
            // The model's peak force follows the drive's (sphere 2 on a stiff bar): within 10 %.
            assert!(
                rel(c.model_peak_force_n, c.measured_peak_force_n) < 0.1,
                "{name} {law}: peak force"
            );
            errors.push(c.relative_error().abs());
            eprintln!(
                "{name:32} {law:17} δ at peak: model {:.4e} m, measured {:.4e} m (offset {:.2e} m), error {:+.1} %",
                c.model_displacement_at_peak_m,
                c.measured_displacement_at_peak_m,
                c.measured_initial_displacement_m,
                100.0 * c.relative_error()
            );
        }
        if name.starts_with("ss") {
            assert!(
                errors[0] < errors[1],
                "{name}: rate-dependent error {} not below rate-independent {}",
                errors[0],
                errors[1]
            );
        }
    }
}

fn run_with_step(params: &Params, divide: f64) -> solver::ForceDrivenResult {
    let SceneParams::ForceDriven { setup, .. } = &params.params else {
        unreachable!()
    };
    let mut s = setup.clone();
    s.dt_s /= divide;
    let (pair, law) = params.pair_and_law().unwrap();
    let law = law.build(pair.contact_properties());
    solver::force_driven(law.as_ref(), &pair, &s).unwrap()
}

fn at_peak(r: &solver::ForceDrivenResult) -> (f64, f64) {
    let s = &r.series;
    (
        s.displacement_m[s.peak_index()],
        s.displacement_m.iter().cloned().fold(0.0, f64::max),
    )
}

#[test]
fn force_driven_converges_in_time_step() {
    // Halving and quartering the default step changes the displacement at peak force and the
    // largest approach by < 1e-4: the default rule is converged far below the model-vs-measurement
    // differences (several %). The rate-dependent law needs the implicit strain rate and the
    // σy* = σy turning point (contact.rs) for this; with an explicit rate it scattered by 0.5 %.
    for law in ["rate-independent", "burgoyne-daraio"] {
        let params = fig4_scene(&fig4_files()[5], law);
        let base = at_peak(&run_with_step(&params, 1.0));
        for divide in [2.0, 4.0] {
            let other = at_peak(&run_with_step(&params, divide));
            assert!(
                rel(base.0, other.0) < 1e-4,
                "{law}: δ at peak {base:?} vs {other:?} (Δt/{divide})"
            );
            assert!(
                rel(base.1, other.1) < 1e-4,
                "{law}: max δ {base:?} vs {other:?} (Δt/{divide})"
            );
        }
    }
}

#[test]
fn collision_restitution_converges_in_time_step() {
    // From 250 to 8000 steps per Hertz contact time the restitution of a plastic impact moves by < 1e-5.
    let pair = SpherePair::paper(Material::builtin("ss440c").unwrap());
    let law = Stateful::new(BurgoyneDaraio::new(pair.contact_properties(), true));
    let reference = collide(&pair, &law, 5.0, 8000.0).restitution;
    for n in [250.0, 1000.0, 2000.0] {
        let e = collide(&pair, &law, 5.0, n).restitution;
        assert!(
            rel(e, reference) < 1e-5,
            "{n} steps: e = {e} vs {reference}"
        );
    }
}

#[test]
fn force_driven_energy_balances() {
    // Work of the drive = contact work + energy radiated into the bar + kinetic energy (discrete
    // identity of the scheme up to O(Δt²)).
    let params = fig4_scene(&fig4_files()[5], "burgoyne-daraio");
    let SceneParams::ForceDriven { setup, .. } = &params.params else {
        unreachable!()
    };
    let (pair, law) = params.pair_and_law().unwrap();
    let law = law.build(pair.contact_properties());
    let r = solver::force_driven(law.as_ref(), &pair, setup).unwrap();
    let e = r.energy;
    let balance = e.contact_work_j + e.radiated_j + r.kinetic_energy_j;
    assert!(
        rel(balance, e.external_work_j) < 1e-3,
        "{balance} vs {}",
        e.external_work_j
    );
}
