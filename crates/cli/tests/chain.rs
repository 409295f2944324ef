//! Chains of spheres (issue 17 part 2, docs/physics.md §8): the `chain` scene against the
//! `collision` scene for two spheres, the full SHPB test with a chain specimen against the pair
//! test, a longer chain between the bars, and the `/chain` layout of the run file.

mod common;

use common::{repo_path, shpb};
use shpb::prelude::*;
use shpb::run::RunOutput;
use shpb::scene::Params;
use std::path::Path;

fn run(text: &str) -> RunOutput {
    Params::from_toml(text, "t.toml", Path::new("."))
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
        .run()
        .unwrap()
}

fn summary(out: &RunOutput, key: &str) -> f64 {
    out.summary_value(key)
        .unwrap_or_else(|| panic!("no summary item {key}"))
}

/// Largest |a − b| over the common length, relative to the largest |b|.
fn series_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / scale
}

/// Acceptance: a `chain` scene of two spheres gives the `collision` scene's restitution, peak
/// force, max approach and force series to 1e-12 relative (the same arithmetic: measured 0),
/// through the scene files, for the three laws and three speeds.
#[test]
fn a_chain_scene_of_two_is_the_collision_scene() {
    for law in ["burgoyne-daraio", "rate-independent", "hertz"] {
        for speed in [1.0, 5.0, 20.0] {
            let collision = run(&format!(
                "kind = \"collision\"\nlaw = \"{law}\"\nvelocity1_m_s = {speed}\nspecimen = {{ pair = \"ss440c\" }}\n"
            ));
            let chain = run(&format!(
                "kind = \"chain\"\nlaw = \"{law}\"\nvelocity1_m_s = {speed}\nspecimen = {{ count = 2, material = \"ss440c\", diameter_m = 6.35e-3 }}\n"
            ));
            let mut worst = 0.0f64;
            for key in ["restitution", "peak_force", "max_approach", "time_step"] {
                let (a, b) = (summary(&chain, key), summary(&collision, key));
                worst = worst.max((a - b).abs() / b.abs());
            }
            let (c, p) = (
                chain.contact.as_ref().unwrap(),
                collision.contact.as_ref().unwrap(),
            );
            worst = worst.max(series_difference(&c.force_n, &p.force_n));
            worst = worst.max(series_difference(&c.displacement_m, &p.displacement_m));
            println!("{law} at {speed} m/s: chain − collision {worst:e}");
            assert!(worst <= 1e-12, "{law} at {speed} m/s: {worst:e}");
            // The ledger: kinetic after + dissipated = before, to the run's own ledger error.
            let (ke0, ke1, w) = (
                summary(&chain, "kinetic_energy_before"),
                summary(&chain, "kinetic_energy_after"),
                summary(&chain, "energy_dissipated"),
            );
            let err = summary(&chain, "energy_balance_max_relative_error");
            assert!(((ke1 + w - ke0) / ke0).abs() <= err * (1.0 + 1e-9));
        }
    }
}

fn shpb_scene(specimen: &str) -> String {
    format!(
        "kind = \"shpb\"\nbars = \"authors\"\npressure = \"10psi\"\nfidelity = \"fast\"\n[specimen]\n{specimen}\n"
    )
}

/// Acceptance: the full SHPB test with a chain of two (as `count`, or as two
/// `[[specimen.sphere]]` tables) reproduces the pair test to 1e-12 on the gauge signals, the
/// true contact force and the reduced forces (same chain of bodies: measured 0).
#[test]
fn an_shpb_test_with_a_chain_of_two_is_the_pair_test() {
    let pair = run(&shpb_scene("pair = \"ss440c\""));
    for specimen in [
        "count = 2\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3",
        "[[specimen.sphere]]\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3\n[[specimen.sphere]]\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3",
    ] {
        let chain = run(&shpb_scene(specimen));
        let mut worst = 0.0f64;
        for (a, b) in chain.gauges.iter().zip(&pair.gauges) {
            worst = worst.max(series_difference(&a.strain, &b.strain));
            worst = worst.max(series_difference(&a.voltage_v, &b.voltage_v));
        }
        let (c, p) = (
            chain.contact.as_ref().unwrap(),
            pair.contact.as_ref().unwrap(),
        );
        worst = worst.max(series_difference(&c.force_n, &p.force_n));
        let (rc, rp) = (
            chain.reduction.as_ref().unwrap(),
            pair.reduction.as_ref().unwrap(),
        );
        worst = worst.max(series_difference(&rc.force_back_n, &rp.force_back_n));
        worst = worst.max(series_difference(&rc.force_front_n, &rp.force_front_n));
        worst = worst.max(series_difference(&rc.displacement_m, &rp.displacement_m));
        println!("shpb chain of two − pair: {worst:e}");
        assert!(worst <= 1e-12, "{worst:e}");
        assert_eq!(chain.summary, pair.summary);
    }
}

/// A chain of five between the bars: the three middle spheres are rigid masses joined by
/// contacts; the energy ledger of the whole test (striker = bars + absorbed + shaper +
/// contacts) holds as for a pair (1e-10), and the load passes through the chain to the
/// transmission bar: a transmitted pulse, smaller than the pair's (four contacts in series are
/// four times as compliant, so the same incident pulse loads them less) but not negligible.
#[test]
fn an_shpb_test_with_a_chain_of_five() {
    let pair = run(&shpb_scene("pair = \"ss440c\""));
    let chain = run(&shpb_scene(
        "count = 5\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3",
    ));
    let err = summary(&chain, "energy_balance_max_relative_error");
    assert!(err < 1e-10, "energy ledger {err:e}");
    let (fc, fp) = (
        summary(&chain, "reduced_peak_back_force"),
        summary(&pair, "reduced_peak_back_force"),
    );
    println!("reduced peak back force: chain of five {fc:e} N, pair {fp:e} N");
    assert!(fc > 0.1 * fp && fc < fp, "{fc} vs {fp}");
    // Its `/chain` series: four contacts, five spheres on one time axis; contact 1 is the
    // `/contact` history (the same joint's evaluations), and the spheres end moving toward the
    // transmission bar or at rest (the bars only push). A pair keeps its output without `/chain`.
    assert!(pair.chain.is_none());
    let c = chain
        .chain
        .as_ref()
        .expect("a chain specimen writes /chain");
    assert_eq!((c.contact_force_n.len(), c.velocity_m_s.len()), (4, 5));
    let nt = c.time_s.len();
    assert!(
        c.contact_force_n
            .iter()
            .chain(&c.velocity_m_s)
            .all(|r| r.len() == nt)
    );
    let contact = chain.contact.as_ref().unwrap();
    let first_peak = c.contact_force_n[0].iter().copied().fold(0.0, f64::max);
    assert_eq!(first_peak, contact.force_n[contact.peak_index()]);
    // The bars load the chain over tens of µs, far longer than a contact wave takes through five
    // spheres, so the chain is nearly in equilibrium: a middle sphere's inertia m δ/t² ≈ 1e-3 kg ×
    // 7e-5 m / (5e-5 s)² ≈ 30 N is about 1 % of the force. All contacts peak within 5 %.
    let peaks: Vec<f64> = c
        .contact_force_n
        .iter()
        .map(|r| r.iter().copied().fold(0.0, f64::max))
        .collect();
    let (lo, hi) = (
        peaks.iter().copied().fold(f64::INFINITY, f64::min),
        peaks.iter().copied().fold(0.0, f64::max),
    );
    assert!(hi / lo < 1.05, "contact peaks {peaks:?}");
}

/// `/chain` velocities are at the contacts' levels, on the forces' time axis: a middle sphere
/// (a rigid mass between two contacts) moves with its initial velocity plus the trapezoidal
/// integral of its net recorded force (contact on its left minus contact on its right) over its
/// mass, at every sample, to rounding (1e-9 of its largest velocity), and the mass that relation
/// implies is the sphere's, ρ π d³/6 with SS440c's 7800 kg/m³ (specimens/ss440c.toml). Half-step
/// velocities on the level times (as recorded before 2026-11-24) are half a step of force off.
#[test]
fn chain_velocities_are_the_impulse_of_the_recorded_forces() {
    let out = run(&shpb_scene(
        "count = 5\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3",
    ));
    let c = out.chain.as_ref().unwrap();
    let dt = c.time_s[1] - c.time_s[0];
    assert!(
        c.time_s
            .windows(2)
            .all(|w| ((w[1] - w[0]) / dt - 1.0).abs() < 1e-9),
        "one sample a step"
    );
    let mass_kg = 7800.0 * std::f64::consts::PI / 6.0 * 6.35e-3f64.powi(3);
    for sphere in 1..=3 {
        let v = &c.velocity_m_s[sphere];
        let net: Vec<f64> = (0..v.len())
            .map(|n| c.contact_force_n[sphere - 1][n] - c.contact_force_n[sphere][n])
            .collect();
        let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let (mut impulse, mut worst) = (0.0, 0.0f64);
        for n in 1..v.len() {
            impulse += 0.5 * dt * (net[n - 1] + net[n]);
            worst = worst.max((v[n] - v[0] - impulse / mass_kg).abs());
        }
        println!(
            "sphere {}: largest departure {:.2e} of {scale:.3} m/s",
            sphere + 1,
            worst / scale
        );
        assert!(
            worst < 1e-9 * scale,
            "sphere {}: {:e}",
            sphere + 1,
            worst / scale
        );
    }
}

/// The run file of the example chain scene: `/chain` datasets with their shapes and units,
/// and the CSV of per-contact forces.
#[test]
fn the_chain_run_file_has_the_documented_layout() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo_path("scenes/chain-ss440c-10.toml");
    let out = shpb(
        dir.path(),
        &[
            "run", &scene, "-o", "c.h5", "--csv", "c.csv", "--plot", "c.png",
        ],
    );
    assert!(out.status.success(), "{}", common::stderr(&out));
    let f = shpb_output::run_file::read_run_file(&dir.path().join("c.h5")).unwrap();
    let get = |p: &str| {
        f.datasets
            .iter()
            .find(|d| d.path == p)
            .unwrap_or_else(|| panic!("no {p}"))
    };
    let t = get("chain/time");
    let nt = t.shape[0];
    assert_eq!(t.units, "s");
    for (p, rows, units) in [
        ("chain/contact_force", 9, "N"),
        ("chain/contact_approach", 9, "m"),
        ("chain/velocity", 10, "m/s"),
    ] {
        let d = get(p);
        assert_eq!(
            (d.shape.clone(), d.units.as_ref()),
            (vec![rows, nt], units),
            "{p}"
        );
    }
    // Contact 1 is between spheres 1 and 2: the wave from sphere 1 peaks there first, then at
    // each next contact in turn (rows are contacts, columns times).
    let force = &get("chain/contact_force").data;
    let peak_at = |k: usize| {
        (0..nt)
            .max_by(|&a, &b| force[k * nt + a].total_cmp(&force[k * nt + b]))
            .unwrap()
    };
    assert!((1..9).all(|k| peak_at(k) > peak_at(k - 1)));
    let csv = std::fs::read_to_string(dir.path().join("c.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.starts_with("time_s,contact1_force_N,contact2_force_N"),
        "{header}"
    );
    assert!(header.ends_with("sphere10_velocity_m_s"));
    assert_eq!(csv.lines().count(), nt + 1);
    assert!(dir.path().join("c.png").is_file());
}

/// Issue 45: the shipped chain's file keeps each sphere's final velocity once, in
/// `/chain/final_velocity` (marked `summary_key`), not as a `/summary` attribute and dataset per
/// sphere; the summary `shpb run --json` prints still has every `final_velocity_<k>`, equal to
/// its element k − 1, and `output_every` = 1 (the scene fits the budget: no warning).
#[test]
fn a_chain_s_final_velocities_are_one_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo_path("scenes/chain-ss440c-10.toml");
    let out = shpb(dir.path(), &["run", &scene, "-o", "c.h5", "--json"]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    assert!(!common::stderr(&out).contains("output_every"));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let printed = &json["summary"];
    let f = hdf5::File::open(dir.path().join("c.h5")).unwrap();
    let final_velocity = f
        .dataset("chain/final_velocity")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    assert_eq!(final_velocity.len(), 10);
    for (k, v) in final_velocity.iter().enumerate() {
        assert_eq!(printed[format!("final_velocity_{}", k + 1)]["value"], *v);
    }
    assert_eq!(printed["output_every"]["value"], 1.0);
    let s = f.group("summary").unwrap();
    let names = s.member_names().unwrap();
    assert!(
        names.iter().all(|n| !n.starts_with("final_velocity")),
        "{names:?}"
    );
    assert!(s.attr("final_velocity_1").is_err());
    let back = shpb_output::run_file::read_run_file(&dir.path().join("c.h5")).unwrap();
    let keys: Vec<&str> = back.summary.iter().map(|(k, _, _)| k.as_str()).collect();
    assert_eq!(keys.len(), printed.as_object().unwrap().len());
    assert!(keys.contains(&"final_velocity_10") && keys.contains(&"output_every"));
}

/// Issue 45: a chain whose every step would not fit the budget (3000 spheres, 3760 steps:
/// 9007 numbers a step, 3.4e7 in all) keeps one step in 2 (1881 samples, 1.7e7 numbers), says so
/// in a warning and in its summary, and its samples are those of the every-step run at the
/// steps kept; `output_every` set in the scene is obeyed.
#[test]
fn a_chain_beyond_the_output_budget_keeps_fewer_steps_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo_path("scenes/chain-ss440c-10.toml");
    let sets = [
        "specimen.count=3000",
        "velocity1_m_s=20",
        "end_time_s=2e-6",
        "steps_per_contact=20000",
    ];
    let run = |name: &str, extra: &[&str]| {
        let mut args = vec!["run", scene.as_str(), "-q", "-o", name];
        for s in sets.iter().chain(extra) {
            args.extend(["--set", s]);
        }
        let out = shpb(dir.path(), &args);
        assert!(out.status.success(), "{}", common::stderr(&out));
        let file = shpb_output::run_file::read_run_file(&dir.path().join(name)).unwrap();
        (common::stderr(&out), file)
    };
    let get = |f: &shpb_output::run_file::RunFile, p: &str| {
        f.datasets
            .iter()
            .find(|d| d.path == p)
            .unwrap_or_else(|| panic!("no {p}"))
            .clone()
    };
    let (warned, some) = run("some.h5", &[]);
    assert!(
        warned.contains("output_every = 2 (the scene does not set it)"),
        "{warned}"
    );
    let every = some
        .summary
        .iter()
        .find(|(k, _, _)| k == "output_every")
        .unwrap()
        .1;
    assert_eq!(every, 2.0);
    let velocity = get(&some, "chain/velocity");
    let (spheres, kept) = (velocity.shape[0], velocity.shape[1]);
    assert_eq!(spheres, 3000);
    assert!((kept * (3 * spheres + 7)) as f64 <= 2e7, "{kept} samples");
    let (quiet, all) = run("all.h5", &["output_every=1"]);
    assert!(!quiet.contains("output_every"), "{quiet}");
    let steps = get(&all, "chain/time").shape[0] - 1;
    assert!(
        ((3 * spheres + 7) * (steps + 1)) as f64 > 2e7,
        "{steps} steps fit"
    );
    let picked: Vec<usize> = (0..=steps).filter(|n| n % 2 == 0 || *n == steps).collect();
    assert_eq!(kept, picked.len());
    for p in [
        "chain/velocity",
        "chain/contact_force",
        "chain/contact_approach",
    ] {
        let (a, s) = (get(&all, p), get(&some, p));
        let rows = a.shape[0];
        for r in [0, 1, rows / 2, rows - 1] {
            for (j, &n) in picked.iter().enumerate() {
                assert_eq!(
                    s.data[r * kept + j],
                    a.data[r * (steps + 1) + n],
                    "{p}[{r}, {n}]"
                );
            }
        }
    }
    assert_eq!(
        get(&some, "chain/final_velocity").data,
        get(&all, "chain/final_velocity").data
    );
}
