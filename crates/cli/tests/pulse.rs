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
    let get = |o: &shpb::run::RunOutput, k: &str| o.summary_value(k).unwrap();
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
        o.summary_value("incident_peak_stress").unwrap()
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
    // The pre-trigger baseline (mean of the first 900 samples, as the reduction takes it) is
    // removed from the voltages before the bridge converts them.
    let baseline = raw.incident_v[..900].iter().sum::<f64>() / 900.0;
    for (k, v) in raw.incident_v.iter().enumerate().step_by(97) {
        let expected = ch.strain_from_voltage(*v - baseline);
        assert!((strain[k] - expected).abs() <= 1e-12 * strain[k].abs().max(1e-9));
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

/// A `kind` scene of the authors' set-up with `extra` keys: its apparatus, bar-run options and
/// specimen.
fn bar_run(
    kind: &str,
    extra: &str,
) -> (
    Apparatus,
    shpb::apparatus::PulseOptions,
    Option<shpb_core::specimen::Specimen>,
) {
    let text = format!(
        "kind = \"{kind}\"\nbars = \"{}\"\n{extra}",
        root().join("bars/authors.toml").display()
    );
    let params = Params::from_toml(&text, "insert-test.toml", Path::new(".")).unwrap();
    match params.params {
        SceneParams::Pulse {
            apparatus, options, ..
        } => (*apparatus, *options, params.specimen),
        _ => unreachable!(),
    }
}

/// Gauge strains (incident, transmission) of a bar run and the recording times.
fn gauge_strains(
    a: &Apparatus,
    o: &shpb::apparatus::PulseOptions,
    specimen: Option<&shpb_core::specimen::Specimen>,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let setup = a.pulse_chain(o, specimen);
    let r = shpb::solver::simulate_chain(&setup).unwrap();
    let k = |n: &str| setup.gauges.iter().position(|g| g.name == n).unwrap();
    (
        r.time_s.clone(),
        r.strain[k("incident")].clone(),
        r.strain[k("transmission")].clone(),
    )
}

/// The 1/4" insert of the authors' tests, of the bars' own material and diameter.
fn quarter_inch_insert(a: &Apparatus) -> shpb::apparatus::Insert {
    shpb::apparatus::Insert {
        material: a.material,
        diameter_m: a.incident.diameter_m,
        length_m: 6.35e-3,
    }
}

#[test]
fn inserts_of_the_bar_itself_only_delay_the_reflected_and_transmitted_pulses() {
    for (length_m, tolerance) in [(6e-3, 1e-9), (6.35e-3, 2.5e-2)] {
        insert_only_delays(length_m, tolerance);
    }
}

/// Reflected and transmitted signals with `length_m` inserts of bar material on both sides
/// against those without, delayed by 2 L/c0: largest difference at most `tolerance` of the peak.
fn insert_only_delays(length_m: f64, tolerance: f64) {
    // A 1/4" insert of bar material and diameter on each side of the SS440c spheres: the waves
    // meet no impedance change, so the incident pulse is unchanged and the reflected and
    // transmitted pulses are the same as without inserts, later by the extra path
    // 2 L/c0 (reflected: in and out of the incident insert; transmitted: through both inserts).
    let (mut a, o, sp) = bar_run(
        "shpb",
        "pressure = \"10psi\"\nend_time_s = 620e-6\n[specimen]\npair = \"ss440c\"\n",
    );
    let (t, inc0, tra0) = gauge_strains(&a, &o, sp.as_ref());
    let ins = shpb::apparatus::Insert {
        length_m,
        ..quarter_inch_insert(&a)
    };
    a.inserts.incident = Some(ins);
    a.inserts.transmission = Some(ins);
    let (t1, inc1, tra1) = gauge_strains(&a, &o, sp.as_ref());
    assert_eq!(t, t1);
    let c0 = a.material.wave_speed_m_s();
    let delay = 2.0 * ins.length_m / c0;
    let shifted = |y: &[f64]| -> Vec<f64> {
        let tt: Vec<f64> = t.iter().map(|x| x - delay).collect();
        shpb::numeric::resample(&t, y, &tt)
    };
    let peak = |y: &[f64]| y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // The incident pulse (before the reflection returns, 2 (L_I − d_I)... at 2 d_I/c0 after it)
    // is untouched; compare every sample up to the reflection's earliest return.
    let d_i = a
        .gauges
        .channel("incident")
        .unwrap()
        .distance_from_specimen_m;
    let x_i = a.incident.length_m - d_i;
    let t_back = (x_i + 2.0 * d_i) / c0 + 2.0 * (ins.length_m / c0) - 5e-6;
    for (k, &tk) in t.iter().enumerate().filter(|(_, tk)| **tk < t_back) {
        assert!(
            (inc1[k] - inc0[k]).abs() <= 1e-9 * peak(&inc0),
            "incident changed at {tk:e} s"
        );
    }
    // Reflected and transmitted: the no-insert signals delayed by 2 L/c0. The insert has
    // A 6 mm insert is six whole 1 mm cells at Courant 1: the chain is then the d'Alembert
    // solution at the nodes and the delay 12 steps exactly, so only rounding remains (1e-9).
    // The 1/4" insert has ⌊L/Δx⌋ = 6 cells at Courant 0.945: its interfaces with the Courant-1
    // bars are no longer exact (physics §6.2) and its grid carries the steepest part of the contact's
    // response with a small phase error; measured 0.8 % (reflected) and 1.9 % (transmitted) of
    // the peak, bounded at 2.5 %.
    for (name, with, without, from) in [
        ("reflected", &inc1, &inc0, t_back),
        ("transmitted", &tra1, &tra0, 0.0),
    ] {
        let expected = shifted(without);
        let worst = t
            .iter()
            .enumerate()
            .filter(|(_, tk)| **tk >= from)
            .map(|(k, _)| (with[k] - expected[k]).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= tolerance * peak(without),
            "{name}: largest difference {:.2e} of the peak against the delay {delay:e} s",
            worst / peak(without)
        );
    }
}

#[test]
fn an_insert_of_another_impedance_transmits_and_reflects_as_impedance_theory_says() {
    // Unshaped 10 cm striker (41 µs square pulse, 0.2 m long) on the incident bar, then a
    // 0.3 m insert of half the bar's diameter (Z2 = Z1/4), then the transmission bar. The first
    // pulse in the transmission bar has crossed two interfaces: force ratio
    // T = 2Z2/(Z1+Z2) · 2Z1/(Z1+Z2) = 4 Z1 Z2/(Z1+Z2)² = 0.64; the incident gauge sees the
    // reflection R = (Z2 − Z1)/(Z1 + Z2) = −0.6 of the incident force (tension).
    let (mut a, o, sp) = bar_run(
        "pulse",
        "pressure = \"10psi\"\nincident_end = \"transmission\"\nend_time_s = 450e-6\n[shaper]\nenabled = false\n",
    );
    let ins = shpb::apparatus::Insert {
        material: a.material,
        diameter_m: a.incident.diameter_m / 2.0,
        length_m: 0.3,
    };
    a.inserts.incident = Some(ins);
    let (t, inc, tra) = gauge_strains(&a, &o, sp.as_ref());
    let (z1, z2) = (1.0, 0.25);
    let t_expected = 4.0 * z1 * z2 / ((z1 + z2) * (z1 + z2));
    let r_expected = (z2 - z1) / (z1 + z2);
    let c0 = a.material.wave_speed_m_s();
    let d_i = a
        .gauges
        .channel("incident")
        .unwrap()
        .distance_from_specimen_m;
    let d_t = a
        .gauges
        .channel("transmission")
        .unwrap()
        .distance_from_specimen_m;
    let t_inc = (a.incident.length_m - d_i) / c0;
    // Plateau means over the middle 20 µs of each 41 µs pulse (edges excluded: the butt joint's
    // first-impact step and the 2 mm gauge grid round them over a few steps).
    let plateau = |y: &[f64], start: f64| -> f64 {
        let (lo, hi) = (start + 10e-6, start + 30e-6);
        let v: Vec<f64> = t
            .iter()
            .zip(y)
            .filter(|(x, _)| (lo..hi).contains(*x))
            .map(|(_, v)| *v)
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let incident = plateau(&inc, t_inc);
    let reflected = plateau(&inc, t_inc + 2.0 * d_i / c0);
    let transmitted = plateau(&tra, t_inc + (d_i + ins.length_m + d_t) / c0);
    // Courant 1 in bars and insert (0.3 m is a whole number of 1 mm cells): the interfaces are
    // exact (physics §6.2); 0.5 % covers the plateau's ripple from the first-impact step.
    assert!(incident < 0.0);
    assert!(
        rel(reflected / incident, r_expected) < 5e-3,
        "R = {:.4}, expected {r_expected}",
        reflected / incident
    );
    assert!(
        rel(transmitted / incident, t_expected) < 5e-3,
        "T = {:.4}, expected {t_expected}",
        transmitted / incident
    );
}

#[test]
fn an_insert_shorter_than_a_cell_is_a_rigid_mass() {
    // 0.5 mm at 1 mm cells: one rigid body of ρAL. The chain runs and the insert's mass shows in
    // the setup; its transit (0.1 µs) is below one step.
    let (mut a, o, sp) = bar_run(
        "shpb",
        "pressure = \"10psi\"\nend_time_s = 100e-6\n[specimen]\npair = \"ss440c\"\n",
    );
    let mut ins = quarter_inch_insert(&a);
    ins.length_m = 0.5e-3;
    a.inserts.incident = Some(ins);
    let setup = a.pulse_chain(&o, sp.as_ref());
    let mass = setup.bodies.iter().find_map(|b| match b {
        shpb::solver::BodySpec::Mass(m) if m.name == "incident insert" => Some(m.mass_kg),
        _ => None,
    });
    // The first sphere sits on the rigid insert, so its mass is the insert's plus the sphere's.
    let sphere = match &sp {
        Some(shpb_core::specimen::Specimen::Spheres(s)) => s.chain.spheres[0].mass_kg,
        _ => unreachable!(),
    };
    assert!(rel(mass.unwrap(), ins.mass_kg() + sphere) < 1e-12);
    shpb::solver::simulate_chain(&setup).unwrap();
}

#[test]
fn set_up_files_read_inserts_with_the_bar_material_by_default() {
    let text = std::fs::read_to_string(root().join("bars/authors.toml")).unwrap()
        + "\n[inserts.incident]\nlength_m = 6.35e-3\n[inserts.transmission]\nlength_m = 5e-3\ndiameter_m = 0.0127\nmaterial = { density_kg_m3 = 4430.0, youngs_modulus_pa = 114e9, poisson_ratio = 0.34 }\n";
    let dir = std::env::temp_dir().join(format!("shpb-inserts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(
        root().join("bars/gauges-authors.toml"),
        dir.join("gauges-authors.toml"),
    )
    .unwrap();
    std::fs::write(dir.join("set-up.toml"), &text).unwrap();
    let a = Apparatus::from_file(&dir.join("set-up.toml")).unwrap();
    let i = a.inserts.incident.unwrap();
    assert_eq!((i.length_m, i.diameter_m), (6.35e-3, a.incident.diameter_m));
    assert_eq!(i.material, a.material);
    let t = a.inserts.transmission.unwrap();
    assert_eq!((t.diameter_m, t.material.density_kg_m3), (0.0127, 4430.0));
    std::fs::write(
        dir.join("bad.toml"),
        text.replace("length_m = 5e-3", "length_m = -5e-3"),
    )
    .unwrap();
    let e = Apparatus::from_file(&dir.join("bad.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("inserts.transmission") && e.contains("length_m"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Work the shaper holds at the end of a run (its last `/energy/shaper` value), J.
fn shaper_work_j(o: &shpb::run::RunOutput) -> f64 {
    *o.energy
        .iter()
        .find(|(n, _)| n == "shaper")
        .unwrap()
        .1
        .last()
        .unwrap()
}

/// The whole incident pulse lies inside the run: its gauge is back within 2 % of its peak at the end.
fn assert_whole_pulse_in_run(o: &shpb::run::RunOutput) {
    let g = &o.gauges[0];
    let peak = g.strain.iter().cloned().fold(0.0, f64::min);
    assert!(
        g.strain.last().unwrap().abs() < 0.02 * peak.abs(),
        "{:e} at the end against a peak of {peak:e}",
        g.strain.last().unwrap()
    );
}

/// The exponential shaper (docs/physics.md §6.5.3) in a `pulse` scene: elastic (the energy
/// identity holds and the shaper keeps no work at the end), its default run long enough for the
/// whole pulse, and scale-free while F0 ≪ the pulse's force: a tenfold smaller F0 only delays
/// the pulse, by the closure λ ln 10 passed at about the striker's speed, and leaves its shape.
#[test]
fn the_exponential_shaper_is_elastic_and_its_onset_force_only_moves_the_foot() {
    let scene = |f0: f64| {
        pulse_scene(&format!(
            "pressure = \"12.5psi\"\n[shaper]\nmodel = \"exponential\"\nstiffening_length_m = 9.4e-5\nonset_force_n = {f0}\n"
        ))
    };
    let (p10, p1) = (scene(10.0), scene(1.0));
    let SceneParams::Pulse { options, .. } = &p10.params else {
        unreachable!()
    };
    let v = options.striker_velocity_m_s;
    let (a, b) = (p10.run().unwrap(), p1.run().unwrap());
    let get = |o: &shpb::run::RunOutput, k: &str| o.summary_value(k).unwrap();
    assert!(get(&a, "energy_balance_max_relative_error") < 1e-9);
    // Elastic: whatever the shaper held is given back once striker and bar part, up to the
    // discrete work's second-order error in the closure step (a plastic disc keeps ≈ 10 %).
    assert!(
        shaper_work_j(&a).abs() < 1e-5 * get(&a, "striker_energy"),
        "{}",
        shaper_work_j(&a)
    );
    // The whole pulse inside the default run.
    assert_whole_pulse_in_run(&a);
    // Shape unchanged by F0 (to 0.5 %: the "−1" of F0 (e^{c/λ} − 1) is 1e-3 of the force at
    // the 10 % foot), foot later by ≈ λ ln 10 / v (the closing speed is v until the force rises).
    for k in [
        "incident_peak_stress",
        "incident_rise_10_90",
        "incident_duration_10",
    ] {
        assert!(
            rel(get(&b, k), get(&a, k)) < 5e-3,
            "{k}: {} vs {}",
            get(&b, k),
            get(&a, k)
        );
    }
    let t = a.time_s.as_ref().unwrap();
    let foot = |o: &shpb::run::RunOutput| {
        let s = &o.gauges[0].strain;
        let lo = s.iter().cloned().fold(0.0, f64::min);
        crossings(t, s, 0.1 * lo).0
    };
    let shift = foot(&b) - foot(&a);
    let expect = 9.4e-5 * 10f64.ln() / v;
    assert!(rel(shift, expect) < 0.05, "{shift:e} vs {expect:e}");
}

/// The crushed disc seated through an exponential cushion (docs/physics.md §6.5.4) in a `pulse`
/// scene: the energy identity holds, the disc keeps plastic work (positive, below the striker's
/// energy), its default run holds the whole pulse (the cushion's onset delay included), and a
/// cushion of negligible length gives the bare disc's pulse back.
#[test]
fn a_cushioned_crushed_disc_dissipates_and_closes_the_energy_ledger() {
    let scene = |cushion: &str| {
        pulse_scene(&format!(
            "pressure = \"12.5psi\"\n[shaper]\nmodel = \"crushed-disc\"\ndiameter_m = 12.3e-3\n\
             thickness_m = 0.574e-3\nyoungs_modulus_pa = 117e9\n{cushion}"
        ))
    };
    let cushioned = scene("stiffening_length_m = 8.27e-5\nonset_force_n = 10.0\n")
        .run()
        .unwrap();
    let get = |o: &shpb::run::RunOutput, k: &str| o.summary_value(k).unwrap();
    assert!(get(&cushioned, "energy_balance_max_relative_error") < 1e-9);
    let kept = shaper_work_j(&cushioned) / get(&cushioned, "striker_energy");
    assert!(
        kept > 0.01 && kept < 1.0,
        "the disc keeps {kept} of the striker's energy"
    );
    assert_whole_pulse_in_run(&cushioned);
    // λ = 1 nm: the cushion takes under 1e-8 m of closure at the pulse's forces, against a
    // closure of ~0.3 mm; the pulse is the bare disc's to well within 1e-3.
    let (tiny, bare) = (
        scene("stiffening_length_m = 1e-9\nonset_force_n = 10.0\n")
            .run()
            .unwrap(),
        scene("").run().unwrap(),
    );
    for k in [
        "incident_peak_stress",
        "incident_rise_10_90",
        "incident_duration_10",
    ] {
        assert!(
            rel(get(&tiny, k), get(&bare, k)) < 1e-3,
            "{k}: {} vs {}",
            get(&tiny, k),
            get(&bare, k)
        );
    }
}
