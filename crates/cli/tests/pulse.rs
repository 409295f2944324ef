//! The bar apparatus end to end: gas gun, striker, pulse shaper, bars and gauges through the
//! `pulse` scene, against elementary wave theory, energy conservation and the gun's own curve;
//! and the errors a user gets for bad set-up files and pressures.

use shpb::apparatus::Apparatus;
use shpb::prelude::*;
use shpb::scene::{Params, SceneParams};
use shpb::striker::{GasGun, PSI_PA};
use shpb::units::parse_pressure;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn authors() -> Apparatus {
    Apparatus::from_file(&root().join("bars/authors.toml")).unwrap()
}

fn pulse_scene(extra: &str) -> Params {
    let text = format!(
        "kind = \"pulse\"\nbars = \"{}\"\n{extra}",
        root().join("bars/authors.toml").display()
    );
    Params::from_toml(&text, "pulse-test.toml", Path::new(".")).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Times where `s` crosses `level` going away from and back to zero (linear interpolation).
fn crossings(t: &[f64], s: &[f64], level: f64) -> (f64, f64) {
    let i = s.iter().position(|&x| x <= level).unwrap();
    let j = i + s[i..].iter().position(|&x| x > level).unwrap();
    let at = |k: usize| t[k - 1] + (level - s[k - 1]) / (s[k] - s[k - 1]) * (t[k] - t[k - 1]);
    (at(i), at(j))
}

#[test]
fn striker_without_shaper_gives_the_elementary_pulse() {
    let p = pulse_scene(
        "pressure = \"10psi\"\nincident_end = \"absorbing\"\nend_time_s = 600e-6\n[shaper]\nenabled = false\n",
    );
    let SceneParams::Pulse {
        apparatus, options, ..
    } = &p.params
    else {
        unreachable!()
    };
    let out = p.run().unwrap();
    let c0 = apparatus.material.wave_speed_m_s();
    let v = options.striker_velocity_m_s;
    let g = &out.gauges[0];
    let t = out.time_s.as_ref().unwrap();
    let amplitude = g.strain.iter().cloned().fold(0.0, f64::min);
    assert!(
        rel(-amplitude, v / (2.0 * c0)) < 1e-3,
        "amplitude {amplitude:e} vs v/2c0 = {:e}",
        v / (2.0 * c0)
    );
    // Pulse length at half amplitude: 2 Ls / c0 within one time step.
    let (a, b) = crossings(t, &g.strain, 0.5 * amplitude);
    let dt = options.cell_size_m / c0;
    let expected = 2.0 * apparatus.striker.length_m / c0;
    assert!(
        ((b - a) - expected).abs() <= dt,
        "length {:e} vs {expected:e} (Δt {dt:e})",
        b - a
    );
    // Energy: striker = bars + absorbed + joint at every recorded time, and once the pulse has
    // passed (equal impedance: the striker stops) everything has left through the absorbing end
    // except what the butt joint took at the impact: the lumped scheme merges the two half-mass
    // end nodes (m/2 at v, m/2 at rest, m = ρAΔx) into one at v/2 — the exact interface velocity —
    // which costs m v²/8, an O(Δx) loss (0.25 % at 1 mm cells).
    let e = |name: &str| &out.energy.iter().find(|(n, _)| n == name).unwrap().1;
    let (striker, total, absorbed, joint) = (e("striker"), e("total"), e("absorbed"), e("shaper"));
    for (s, tot) in striker.iter().zip(total) {
        assert!(rel(*tot, *s) < 1e-6);
    }
    let cell_mass =
        apparatus.material.density_kg_m3 * apparatus.striker.area_m2() * options.cell_size_m;
    assert!(
        rel(*joint.last().unwrap(), cell_mass * v * v / 8.0) < 1e-6,
        "impact loss {}",
        joint.last().unwrap()
    );
    assert!(
        rel(absorbed.last().unwrap() + joint.last().unwrap(), striker[0]) < 1e-6,
        "absorbed {} of {}",
        absorbed.last().unwrap(),
        striker[0]
    );
}

#[test]
fn copper_shaper_ramps_the_pulse_and_the_energy_balances() {
    let shaped = pulse_scene("pressure = \"12.5psi\"\n");
    let plain = pulse_scene("pressure = \"12.5psi\"\n[shaper]\nenabled = false\n");
    let (a, b) = (shaped.run().unwrap(), plain.run().unwrap());
    let get =
        |o: &shpb::run::RunOutput, k: &str| o.summary.iter().find(|i| i.key == k).unwrap().value;
    // The shaper lowers the peak, slows the rise (from one cell to tens of µs) and lengthens the pulse.
    assert!(get(&a, "incident_peak_stress") < 0.8 * get(&b, "incident_peak_stress"));
    assert!(get(&a, "incident_rise_10_90") > 20e-6 && get(&b, "incident_rise_10_90") < 1e-6);
    assert!(get(&a, "incident_duration_10") > 1.5 * get(&b, "incident_duration_10"));
    // Exact discrete energy identity of the scheme: striker = bars + absorbed + shaper.
    assert!(get(&a, "energy_balance_max_relative_error") < 1e-9);
    // The plastic work of the shaper is a large, positive share of the striker's energy.
    let shaper = a
        .energy
        .iter()
        .find(|(n, _)| n == "shaper")
        .unwrap()
        .1
        .last()
        .copied()
        .unwrap();
    assert!(shaper > 0.1 * get(&a, "striker_energy") && shaper < get(&a, "striker_energy"));
}

#[test]
fn pulse_converges_with_cell_size() {
    // Peak incident stress with 1 mm cells (default) against 0.25 mm: within 0.5 %.
    let peak = |cell: &str| {
        let o = pulse_scene(&format!(
            "pressure = \"10psi\"\nend_time_s = 300e-6\ncell_size_m = {cell}\n"
        ))
        .run()
        .unwrap();
        o.summary
            .iter()
            .find(|i| i.key == "incident_peak_stress")
            .unwrap()
            .value
    };
    let (a, b) = (peak("1e-3"), peak("0.25e-3"));
    assert!(rel(a, b) < 5e-3, "{a:e} vs {b:e}");
}

#[test]
fn gun_curve_follows_its_parameters_and_units() {
    let a = authors();
    let v = shpb::Validator::new("test");
    let shpb::striker::Gun::Linear(g) = a.gun else {
        panic!("the shipped gun is the linear curve")
    };
    for psi in [7.5, 10.0, 12.5, 15.0, 17.5] {
        let p = psi * PSI_PA;
        let vel = a.striker_velocity_m_s(p).unwrap();
        assert!(rel(vel * vel, g.k_m2_per_s2_per_pa * (p - g.loss_pressure_pa)) < 1e-12);
    }
    // Units: psi, kPa, Pa and bar name the same pressure.
    let p = parse_pressure("10psi").unwrap();
    assert!(rel(parse_pressure(&format!("{}kPa", p / 1e3)).unwrap(), p) < 1e-12);
    assert!(rel(parse_pressure(&format!("{p}Pa")).unwrap(), p) < 1e-12);
    assert!(rel(parse_pressure(&format!("{}bar", p / 1e5)).unwrap(), p) < 1e-12);
    assert!(
        parse_pressure("10").is_err()
            && parse_pressure("10 furlongs").is_err()
            && parse_pressure("nanpsi").is_err()
    );
    // Outside the gun's range: an input error naming the key and the range.
    let err = a
        .striker_velocity_m_s(100.0 * PSI_PA)
        .map_err(v.core("pressure"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("`pressure`") && err.contains("psi") && err.contains("allowed"),
        "{err}"
    );
}

#[test]
fn adiabatic_gun_is_linear_in_pressure() {
    // Rohrbach et al.: ½mv² is linear in the reservoir pressure, so v² = k (p − p_loss).
    let g = GasGun {
        reservoir_volume_m3: 2e-3,
        barrel_length_m: 1.5,
        friction_n: 15.0,
        gamma: 1.4,
        atmospheric_pa: 101_325.0,
        min_pressure_pa: 1e3,
        max_pressure_pa: 1e6,
    };
    let area = 2.85e-4;
    let e: Vec<f64> = [50e3, 100e3, 150e3]
        .iter()
        .map(|&p| g.kinetic_energy_j(p, area))
        .collect();
    assert!(((e[2] - e[1]) - (e[1] - e[0])).abs() < 1e-9 * e[2]);
    // At zero friction and an infinite reservoir it tends to the constant-pressure work p A L.
    let big = GasGun {
        reservoir_volume_m3: 1e6,
        friction_n: 0.0,
        ..g
    };
    assert!(rel(big.kinetic_energy_j(100e3, area), 100e3 * area * 1.5) < 1e-4);
}

fn shpb(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_shpb"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap()
}

#[test]
fn gun_command_prints_velocity_and_refuses_out_of_range() {
    let ok = shpb(&["gun", "--pressure", "10psi"]);
    assert!(ok.status.success());
    let text = String::from_utf8_lossy(&ok.stdout);
    let a = authors();
    let v = a.striker_velocity_m_s(10.0 * PSI_PA).unwrap();
    assert!(text.contains(&format!("{v:.4} m/s")), "{text}");
    for bad in ["45psi", "2psi", "-3psi", "10 psi!", "nan"] {
        let out = shpb(&["gun", "--pressure", bad]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--pressure") && err.contains("allowed"),
            "{bad}: {err}"
        );
    }
}

#[test]
fn strain_command_reads_a_raw_record() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("s1.csv");
    let rec = root().join("validation/gauge-records/data/2013-05-22_sample1_ss440c.csv");
    let out = shpb(&[
        "strain",
        rec.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = shpb::csv::CsvTable::read(&csv).unwrap();
    let raw = shpb::gauge::RawRecord::read(&rec).unwrap();
    let ch = authors().gauges.channel("incident").unwrap().clone();
    let strain = table.column("incident_strain").unwrap();
    for (k, v) in raw.incident_v.iter().enumerate().step_by(97) {
        assert!(
            (strain[k] - ch.strain_from_voltage(*v)).abs() <= 1e-12 * strain[k].abs().max(1e-9)
        );
    }
}

/// Writes a copy of bars/authors.toml with one line replaced, and returns the error text.
fn bad_set_up(find: &str, replace: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("bars/authors.toml")).unwrap();
    assert!(text.contains(find), "{find}");
    std::fs::write(dir.path().join("set-up.toml"), text.replace(find, replace)).unwrap();
    std::fs::copy(
        root().join("bars/gauges-authors.toml"),
        dir.path().join("gauges-authors.toml"),
    )
    .unwrap();
    Apparatus::from_file(&dir.path().join("set-up.toml"))
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_set_up_files_are_refused_with_file_key_and_range() {
    let e = bad_set_up("length_m = 1.21", "length_m = -1.21");
    assert!(
        e.contains("set-up.toml")
            && e.contains("`incident.length_m`")
            && e.contains("greater than 0"),
        "{e}"
    );
    let e = bad_set_up("length_m = 1.21", "length_m = nan");
    assert!(
        e.contains("`incident.length_m`") && e.contains("not a finite number"),
        "{e}"
    );
    let e = bad_set_up("length_m = 1.21", "length_m = 1.21\ncolour = \"red\"");
    assert!(e.contains("set-up.toml") && e.contains("colour"), "{e}");
    let e = bad_set_up("far_end = \"absorbing\"", "far_end = \"clay\"");
    assert!(
        e.contains("`transmission.far_end`") && e.contains("absorbing, free"),
        "{e}"
    );
    let e = bad_set_up("model = \"linear\"", "model = \"railgun\"");
    assert!(
        e.contains("`gun.model`") && e.contains("linear, adiabatic"),
        "{e}"
    );
    let e = bad_set_up(
        "gauges = \"gauges-authors.toml\"",
        "gauges = \"missing.toml\"",
    );
    assert!(e.contains("missing.toml"), "{e}");
}

#[test]
fn bad_pulse_scenes_are_refused() {
    let bars = root().join("bars/authors.toml");
    let try_scene = |extra: &str| {
        let text = format!("kind = \"pulse\"\nbars = \"{}\"\n{extra}", bars.display());
        Params::from_toml(&text, "scene.toml", Path::new("."))
            .unwrap_err()
            .to_string()
    };
    let e = try_scene("pressure = \"60psi\"\n");
    assert!(
        e.contains("scene.toml") && e.contains("`pressure`") && e.contains("allowed"),
        "{e}"
    );
    let e = try_scene("pressure = \"10\"\n");
    assert!(
        e.contains("`pressure`") && e.contains("psi, Pa, kPa"),
        "{e}"
    );
    let e = try_scene("pressure = \"10psi\"\ncell_size_m = -1\n");
    assert!(e.contains("`cell_size_m`"), "{e}");
    let e = try_scene("pressure = \"10psi\"\n[shaper]\nthickness_m = 0.0\n");
    assert!(e.contains("`shaper.thickness_m`"), "{e}");
    let e = try_scene("pressure = \"10psi\"\ndispersion = \"magic\"\n");
    assert!(e.contains("`dispersion`") && e.contains("love-rod"), "{e}");
    let text = "kind = \"pulse\"\nbars = \"nowhere.toml\"\npressure = \"10psi\"\n";
    let e = Params::from_toml(text, "scene.toml", Path::new("."))
        .unwrap_err()
        .to_string();
    assert!(e.contains("`bars`") && e.contains("nowhere.toml"), "{e}");
}

#[test]
fn most_pulse_energy_follows_momentum_and_energy_conservation() {
    use shpb::striker::most_pulse_energy_j;
    let (m, v) = (0.2312, 5.8);
    let ke = 0.5 * m * v * v;
    // A striker that stops (impulse m v) can hand over all its kinetic energy …
    assert!((most_pulse_energy_j(m, v, m * v) / ke - 1.0).abs() < 1e-12);
    // … one that rebounds elastically (impulse 2 m v) none, and no impulse means no energy.
    assert!(most_pulse_energy_j(m, v, 2.0 * m * v).abs() < 1e-12 * ke);
    assert_eq!(most_pulse_energy_j(m, v, 0.0), 0.0);
    // Stopping is the best case: more or less impulse leaves the striker some energy.
    for f in [0.5, 0.9, 1.1, 1.5] {
        assert!(most_pulse_energy_j(m, v, f * m * v) < ke);
    }
}
