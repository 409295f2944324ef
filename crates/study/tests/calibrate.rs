//! `shpb calibrate`'s library on shots simulated by shpb itself from a set-up whose constants are
//! known: the calibration must give them back.

use shpb_input::prelude::*;
use shpb_input::shots::ShotManifest;
use shpb_study::api::{Scene, load_scene, run_scene};
use shpb_study::calibrate::{Data, calibrate};
use std::path::{Path, PathBuf};

/// The repository root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The authors' set-up without its shaper, with `density` and the incident gauge at
/// `incident_gauge_m`, written to `dir` as `name.toml` (gauges `name-gauges.toml`).
fn setup(dir: &Path, name: &str, density: f64, incident_gauge_m: f64) -> PathBuf {
    let text = std::fs::read_to_string(root().join("bars/authors.toml")).unwrap();
    let text = text[..text.find("# Copper pulse shaper").unwrap()]
        .replace(
            "gauges = \"gauges-authors.toml\"",
            &format!("gauges = \"{name}-gauges.toml\""),
        )
        .replace(
            "density_kg_m3 = 8110.0",
            &format!("density_kg_m3 = {density:?}"),
        );
    let gauges = std::fs::read_to_string(root().join("bars/gauges-authors.toml"))
        .unwrap()
        .replace(
            "distance_from_specimen_m = 0.644525",
            &format!("distance_from_specimen_m = {incident_gauge_m:?}"),
        );
    std::fs::write(dir.join(format!("{name}-gauges.toml")), gauges).unwrap();
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

/// Simulates a shot of `scene` (TOML text with `BARS` for the set-up's path) and writes its
/// digitised gauge voltages as the authors' CSV `dir/name.csv`.
fn shot(dir: &Path, name: &str, scene: &str, bars: &Path) -> PathBuf {
    let text = scene.replace("BARS", &bars.display().to_string());
    let (params, _) = load_scene(Scene::Text { name, text: &text }, None, &[], String::new())
        .expect("scene loads");
    let out = run_scene(&params, &mut |_| true).expect("run");
    let t = out.time_s.expect("gauge times");
    let v = |n: &str| {
        out.gauges
            .iter()
            .find(|g| g.name == n)
            .expect("gauge")
            .voltage_v
            .clone()
    };
    let (i, tr) = (v("incident"), v("transmission"));
    let mut csv = String::from("# simulated by shpb\ntime_s,incident_V,transmission_V\n");
    for k in 0..t.len() {
        csv.push_str(&format!("{:e},{:e},{:e}\n", t[k], i[k], tr[k]));
    }
    let p = dir.join(format!("{name}.csv"));
    std::fs::write(&p, csv).unwrap();
    p
}

/// A specimen shot (an elastic aluminium cylinder: a reflected pulse and the incident bar's
/// far-end echo) and a shot with the bars pressed together (the transmitted pulse), unshaped.
const SPECIMEN_SHOT: &str = "kind = \"shpb\"\nbars = \"BARS\"\nstriker_velocity_m_s = 5.0\nend_time_s = 1.2e-3\n\
    [specimen]\nshape = \"cylinder\"\nmaterial = \"al2017\"\nlength_m = 6e-3\ndiameter_m = 12e-3\n";
const BARS_TOGETHER_SHOT: &str = "kind = \"pulse\"\nbars = \"BARS\"\nstriker_velocity_m_s = 4.0\n\
    incident_end = \"transmission\"\nend_time_s = 1.2e-3\n";

/// Wave speed and gauge distances from arrivals: shots simulated on bars of density 7900 kg/m³
/// (c0 = 4929.9 m/s) with the incident gauge 0.55 m and the transmission gauge 0.3683 m from
/// the specimen, calibrated from a base set-up of 8110 kg/m³ (c0 4865.5 m/s) with the
/// incident gauge at 0.644525 m. The feet are read on 1 mm cells (0.2 µs at c0) with a 2 mm
/// gauge grid and 10 MHz samples, so each delay is good to a few tenths of a µs: c0 over
/// 2 L_I/c0 ≈ 490 µs to 0.1 % (density 0.2 %), a distance over c0 · 0.4 µs to 2 mm.
#[test]
fn arrivals_give_back_the_wave_speed_and_the_gauge_distances() {
    let d = tempfile::tempdir().unwrap();
    let truth = setup(d.path(), "truth", 7900.0, 0.55);
    let base = setup(d.path(), "base", 8110.0, 0.644525);
    shot(d.path(), "specimen", SPECIMEN_SHOT, &truth);
    shot(d.path(), "together", BARS_TOGETHER_SHOT, &truth);
    let manifest = ShotManifest::from_toml(
        "calibrate = [\"arrivals\"]\n[[shot]]\nfile = \"specimen.csv\"\n\
         [[shot]]\nfile = \"together.csv\"\nbars_together = true\n",
        "shots.toml",
        d.path(),
    )
    .unwrap();
    let a = shpb_core::apparatus::Apparatus::from_file(&base).unwrap();
    let c = calibrate(&Data::read(a, &manifest).unwrap(), &mut |_| {}).unwrap();
    let get = |k: &str| {
        c.constants
            .iter()
            .find(|f| f.key == k)
            .unwrap_or_else(|| panic!("{k} calibrated: {c:?}"))
            .value
    };
    let rho = get("material.density_kg_m3");
    assert!((rho / 7900.0 - 1.0).abs() < 2e-3, "density {rho}");
    let di = get("gauges.incident.distance_from_specimen_m");
    assert!((di - 0.55).abs() < 2e-3, "incident gauge {di}");
    let dt = get("gauges.transmission.distance_from_specimen_m");
    assert!((dt - 0.3683).abs() < 2e-3, "transmission gauge {dt}");
}

/// The strain factor from measured velocities: unshaped shots at 4 and 6 m/s on the authors'
/// bars (no shaper) read through the authors' channel must give the factor that reads their
/// plateau as v/(2c0) — the channel's own volts per strain at that strain, since the
/// simulation's plateau is v/(2c0) (equal sections). The plateau's mean over its middle half
/// carries the bars' Pochhammer ringing: 1 %.
#[test]
fn the_strain_factor_of_an_unshaped_shot_reads_its_plateau_as_v_over_2c() {
    let d = tempfile::tempdir().unwrap();
    let bars = setup(d.path(), "bars", 8110.0, 0.644525);
    for (name, v) in [("slow", 4.0), ("fast", 6.0)] {
        let scene = BARS_TOGETHER_SHOT.replace("4.0", &format!("{v:?}"));
        shot(d.path(), name, &scene, &bars);
    }
    let manifest = ShotManifest::from_toml(
        "calibrate = [\"strain-factor\"]\n[[shot]]\nfile = \"slow.csv\"\nstriker_velocity_m_s = 4.0\n\
         [[shot]]\nfile = \"fast.csv\"\nstriker_velocity_m_s = 6.0\n",
        "shots.toml",
        d.path(),
    )
    .unwrap();
    let a = shpb_core::apparatus::Apparatus::from_file(&bars).unwrap();
    let ch = a.gauges.channel("incident").unwrap().clone();
    let c0 = a.material.wave_speed_m_s();
    let c = calibrate(&Data::read(a, &manifest).unwrap(), &mut |_| {}).unwrap();
    let f = c
        .constants
        .iter()
        .find(|f| f.key == "gauges.incident.strain_per_volt")
        .expect("a strain factor");
    let eps = -5.0 / (2.0 * c0);
    let expected = eps / ch.voltage_from_strain(eps);
    assert!(
        (f.value / expected - 1.0).abs() < 0.01,
        "{} against {expected}",
        f.value
    );
}

/// The scatter about the calibrated model (`calibrate::model_scatter`): shots simulated on bars
/// of density 7900 kg/m³ with the incident gauge 0.55 m from the specimen, calibrated by their
/// arrivals from the 8110 kg/m³ / 0.644525 m base, each shot naming its virtual test. On the
/// calibrated set-up the tests give the records' own delays back to the feet's reading (a few
/// tenths of a µs, §7.6: below 1.5 µs after the Student factor for three shots,
/// t₀.₉₅(2)/z₀.₉₅ = 1.78, or no scatter at all when they agree to the sample); on the base
/// set-up the reflected pulse comes (0.644525 − 0.55) · 2/c0 = 38.9 µs late on every shot, which
/// the scatter then carries. The measured peak is the record's largest sample (the calibration's
/// reading), above the noise-free plateau the test simulates by the noise's extreme over the
/// plateau's few hundred samples, σ √(2 ln N) ≈ 3.5 σ (σ = noise_rms_v over the channel's volts
/// per strain): each shot's peak residual lies between 0 and 4 σ of its plateau.
#[test]
fn shots_on_the_calibrated_model_scatter_by_their_reading_only() {
    use shpb_study::calibrate::model_scatter::about_model;
    let d = tempfile::tempdir().unwrap();
    let truth = setup(d.path(), "truth", 7900.0, 0.55);
    let base = setup(d.path(), "base", 8110.0, 0.644525);
    let mut shots = String::from("calibrate = [\"arrivals\"]\n");
    for (name, v) in [("a", 4.0), ("b", 5.0), ("c", 6.0)] {
        let scene = SPECIMEN_SHOT.replace("5.0", &format!("{v:?}"));
        shot(d.path(), name, &scene, &truth);
        std::fs::write(
            d.path().join(format!("{name}-test.toml")),
            scene.replace("BARS", "base.toml"),
        )
        .unwrap();
        shots.push_str(&format!(
            "[[shot]]\nfile = \"{name}.csv\"\nscene = \"{name}-test.toml\"\n"
        ));
    }
    let manifest = ShotManifest::from_toml(&shots, "shots.toml", d.path()).unwrap();
    let a = shpb_core::apparatus::Apparatus::from_file(&base).unwrap();
    let data = Data::read(a, &manifest).unwrap();
    let c = calibrate(&data, &mut |_| {}).unwrap();
    let m = about_model(&data, &c)
        .unwrap()
        .expect("the shots name their tests");
    assert_eq!(m.shots.len(), 3, "{m:?}");
    let sd = |k: &str| m.scatter.iter().find(|s| s.0 == k).map(|s| s.1);
    let reflected = sd("reflected_delay_s").unwrap_or(0.0);
    assert!(reflected < 1.5e-6, "reflected delay scatter {reflected}");
    let ch = data.base.gauges.channel("incident").unwrap();
    let noise_strain = ch.digitiser.noise_rms_v / (ch.voltage_from_strain(1e-4) / 1e-4).abs();
    let e = data.base.material.youngs_modulus_pa;
    for s in &m.shots {
        let (measured, simulated) = (s.measured[0].unwrap(), s.simulated[0].unwrap());
        let r = measured / simulated - 1.0;
        let bound = 4.0 * noise_strain * e / simulated;
        assert!(
            (0.0..bound).contains(&r),
            "{}: peak residual {r}, bound {bound}",
            s.label
        );
    }
    // The uncalibrated base: the reflected pulse 38.9 µs late on every shot.
    let none = shpb_study::calibrate::Calibration {
        constants: Vec::new(),
        correlations: Vec::new(),
        ..c.clone()
    };
    let m0 = about_model(&data, &none).unwrap().unwrap();
    let r0 = m0
        .scatter
        .iter()
        .find(|s| s.0 == "reflected_delay_s")
        .unwrap()
        .1;
    assert!(r0 > 38e-6, "uncalibrated reflected delay scatter {r0}");
}
