//! Cylindrical specimens (issue 19; docs/physics.md §6.9, §7.8): a full test of an elastic
//! cylinder is simulated, its run file reduced back, and the modulus fitted on the loading part
//! of its stress–strain curve must be the input modulus within 1 %, through the library
//! (`shpb::reduce::reduce` of the simulated strains) and through the binary (`shpb run` +
//! `shpb reduce` of its run file, whose digitised voltages carry the gauge noise).
//!
//! Why 1 % is reachable: the simulated bars are non-dispersive (standard fidelity), so the
//! reduction without dispersion correction is exact up to the gauges' 2 mm grid and the 10 MHz
//! sampling; the specimen's static stiffness E_s A_s/L_s is exact on any number of cells. What
//! remains is the specimen's departure from equilibrium, which the shaped pulse keeps small:
//! its 10–90 % rise (≈ 52 µs) is ≈ 44 transits L_s/c_s (1.18 µs), where ring-up takes a few
//! (Ravichandran & Subhash, J. Am. Ceram. Soc. 77, 263 (1994): about four transits). The fit
//! window (`MODULUS_WINDOW`) is the loading branch from 30 % to 90 % of the peak stress: above
//! the foot, where the specimen is still ringing up, and below the rounded top, where the
//! strain rate falls to zero. The test checks that the window is in equilibrium (front/back
//! force ratio < 2 %) rather than assuming it.

use shpb::prelude::*;
use shpb::scene::{Params, SceneParams};
use shpb_core::reduce_cylinder::{CylinderGeometry, MODULUS_WINDOW, WaveAnalysis, loading_modulus};
use shpb_core::specimen::CylinderSpecimen;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

const SCENE: &str = "scenes/shpb-cylinder-al.toml";

/// The scene's cylinder (the input the reduction must give back).
fn cylinder_of(params: &Params) -> CylinderSpecimen {
    assert!(
        matches!(params.params, SceneParams::Pulse { .. }),
        "not a bar scene"
    );
    params
        .specimen
        .as_ref()
        .and_then(|s| s.cylinder())
        .expect("a cylinder specimen")
        .clone()
}

fn summary(out: &shpb::run::RunOutput, key: &str) -> f64 {
    out.summary_value(key).unwrap_or_else(|| panic!("no {key}"))
}

/// Simulates `scene`, reduces its gauge strains back through the library
/// (dispersion correction off: the simulated bars do not disperse) and fits the modulus of the
/// 1- and 3-wave curves: (input cylinder, 1-wave fit, 3-wave fit).
fn library_round_trip(
    scene: &Path,
) -> (
    CylinderSpecimen,
    shpb_core::reduce_cylinder::ModulusFit,
    shpb_core::reduce_cylinder::ModulusFit,
) {
    let params = Params::from_file(scene).unwrap();
    let cyl = cylinder_of(&params);
    let out = params.run().unwrap();
    // Equilibrium needs a rise many specimen transits long (module docs).
    let transit = cyl.length_m / cyl.material.wave_speed_m_s();
    let rise = summary(&out, "incident_rise_10_90");
    assert!(rise > 20.0 * transit, "rise {rise} s, transit {transit} s");
    // The simulated gauge strains (noise-free) reduced through the library, as `shpb reduce`
    // reduces a run file without its own set-up: no file in between.
    let SceneParams::Pulse { apparatus, .. } = &params.params else {
        panic!("not a bar scene")
    };
    let strain = |name: &str| {
        out.gauges
            .iter()
            .find(|g| g.name == name)
            .expect("a gauge")
            .strain
            .clone()
    };
    let input = shpb::reduce::ReductionInput {
        time_s: out.time_s.clone().expect("a time axis"),
        incident_strain: strain("incident"),
        transmission_strain: strain("transmission"),
    };
    let setup = shpb::reduce::ReductionSetup::from_apparatus(apparatus).unwrap();
    let reduction = shpb::reduce::reduce(
        &input,
        &setup,
        &shpb::reduce::ReductionOptions {
            dispersion: shpb::reduce::DispersionCorrection::None,
            specimen_radii_m: None,
            ..Default::default()
        },
    )
    .unwrap();
    let g = CylinderGeometry {
        length_m: cyl.length_m,
        diameter_m: cyl.diameter_m,
    };
    let c = shpb_core::reduce_cylinder::reduce_cylinder(&reduction, &setup, &g).unwrap();
    let (lo, hi) = MODULUS_WINDOW;
    let eq = &reduction.equilibrium_ratio;
    let one = loading_modulus(&c.one_wave, eq, lo, hi).unwrap();
    let three = loading_modulus(&c.three_wave, eq, lo, hi).unwrap();
    (cyl, one, three)
}

/// One test at a time touches HDF5 files in this process: two test threads writing and
/// reopening HDF5 files were seen to fail with "unable to lock file" (errno 11) from the HDF5 C
/// library, whose open-file table is process-wide.
fn hdf5_in_this_process() -> std::sync::MutexGuard<'static, ()> {
    static HDF5: std::sync::Mutex<()> = std::sync::Mutex::new(());
    HDF5.lock().unwrap_or_else(|e| e.into_inner())
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// The acceptance test through the library, on the shipped scene (6 mm × 12 mm al2017): the
/// 3-wave curve (the specimen's shortening δ/L_s against the mean face stress) gives E_s within
/// 1 % over an equilibrated window.
#[test]
fn the_shipped_cylinder_round_trip_recovers_its_modulus_through_the_library() {
    let (cyl, one, three) = library_round_trip(&root().join(SCENE));
    let e = cyl.material.youngs_modulus_pa;
    eprintln!(
        "6 × 12 mm: 3-wave E {:.4e} Pa ({:+.3} %), 1-wave E {:.4e} Pa ({:+.3} %), equilibrium ratio ≤ {:.4} over samples {}..{}",
        three.modulus_pa,
        100.0 * (three.modulus_pa / e - 1.0),
        one.modulus_pa,
        100.0 * (one.modulus_pa / e - 1.0),
        three.max_equilibrium_ratio,
        three.first_index,
        three.last_index
    );
    assert!(three.max_equilibrium_ratio < 0.02, "{three:?}");
    assert!(rel(three.modulus_pa, e) < 0.01, "{three:?} vs {e}");
}

/// A more compliant cylinder (10 mm long, 8 mm across: a third of the stiffness) reflects more
/// of the incident wave, so the 1-wave strain (from εR alone, assuming equilibrium) is as good:
/// both analyses give E_s within 1 %. (On the stiff 6 × 12 mm specimen εR is ≈ 8 % of εI, and
/// the 1 % force imbalance of the window weighs ~10 times more in the 1-wave strain: it comes out
/// ≈ 2 % stiff, which is why the shipped scene is fitted on the 3-wave curve.)
#[test]
fn a_compliant_cylinder_round_trip_recovers_its_modulus_by_the_one_and_three_wave_analyses() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join(SCENE))
        .unwrap()
        .replace("length_m = 6e-3", "length_m = 10e-3")
        .replace("diameter_m = 12e-3", "diameter_m = 8e-3")
        .replace("../bars/authors.toml", "authors");
    let scene = dir.path().join("compliant.toml");
    std::fs::write(&scene, text).unwrap();
    let (cyl, one, three) = library_round_trip(&scene);
    assert_eq!((cyl.length_m, cyl.diameter_m), (10e-3, 8e-3));
    let e = cyl.material.youngs_modulus_pa;
    eprintln!(
        "10 × 8 mm: 3-wave E ({:+.3} %), 1-wave E ({:+.3} %), equilibrium ratio ≤ {:.4}",
        100.0 * (three.modulus_pa / e - 1.0),
        100.0 * (one.modulus_pa / e - 1.0),
        one.max_equilibrium_ratio
    );
    assert!(one.max_equilibrium_ratio < 0.02, "{one:?}");
    assert!(rel(one.modulus_pa, e) < 0.01, "{one:?} vs {e}");
    assert!(rel(three.modulus_pa, e) < 0.01, "{three:?} vs {e}");
}

fn shpb(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

fn read(f: &hdf5::File, name: &str) -> Vec<f64> {
    f.dataset(name).unwrap().read_raw::<f64>().unwrap()
}

fn units(f: &hdf5::File, name: &str) -> String {
    let a: hdf5::types::VarLenUnicode = f
        .dataset(name)
        .unwrap()
        .attr("units")
        .unwrap()
        .read_scalar()
        .unwrap();
    a.to_string()
}

/// The acceptance test through the binary: `shpb run` the shipped scene, `shpb reduce` its run
/// file with the cylinder's geometry; the HDF5 `/reduction/cylinder` curves give E_s within 1 %,
/// the CSV carries the same columns, the JSON summary the same peak.
#[test]
fn shpb_run_and_shpb_reduce_recover_the_cylinder_modulus() {
    let _one_at_a_time = hdf5_in_this_process();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = root().join(SCENE);
    let params = Params::from_file(&scene).unwrap();
    let cyl = cylinder_of(&params);
    let o = shpb(d, &["run", scene.to_str().unwrap(), "-o", "run.h5"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (l, dia) = (cyl.length_m.to_string(), cyl.diameter_m.to_string());
    let args = [
        "reduce",
        "run.h5",
        "--no-dispersion",
        "--specimen-length",
        &l,
        "--specimen-diameter",
        &dia,
        "-o",
        "red.h5",
        "--csv",
        "red.csv",
    ];
    let o = shpb(d, &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("peak stress") && text.contains("mean strain rate"),
        "{text}"
    );

    let f = hdf5::File::open(d.join("red.h5")).unwrap();
    let analysis = |a: &str| WaveAnalysis {
        stress_pa: read(&f, &format!("reduction/cylinder/{a}/stress")),
        strain: read(&f, &format!("reduction/cylinder/{a}/strain")),
        strain_rate_per_s: read(&f, &format!("reduction/cylinder/{a}/strain_rate")),
        true_stress_pa: read(&f, &format!("reduction/cylinder/{a}/true_stress")),
        true_strain: read(&f, &format!("reduction/cylinder/{a}/true_strain")),
    };
    for a in ["one_wave", "two_wave", "three_wave"] {
        for (s, u) in [
            ("stress", "Pa"),
            ("strain", "1"),
            ("strain_rate", "1/s"),
            ("true_stress", "Pa"),
            ("true_strain", "1"),
        ] {
            assert_eq!(units(&f, &format!("reduction/cylinder/{a}/{s}")), u);
        }
    }
    let three = analysis("three_wave");
    let eq = read(&f, "reduction/equilibrium_ratio");
    let (lo, hi) = MODULUS_WINDOW;
    let fit = loading_modulus(&three, &eq, lo, hi).unwrap();
    let e = cyl.material.youngs_modulus_pa;
    eprintln!(
        "shpb reduce: 3-wave E {:.4e} Pa ({:+.3} %)",
        fit.modulus_pa,
        100.0 * (fit.modulus_pa / e - 1.0)
    );
    // `shpb reduce` reads the run's digitised voltages, noise and all, as a lab reads a record:
    // the pointwise ratio carries that noise (≈ 0.03 here against < 0.01 on the noise-free strains
    // of the library round trips above), so the window is held to the lab's own equilibrium
    // criterion, R ≤ 0.05 (Ravichandran & Subhash 1994; reduce::quality).
    assert!(
        fit.max_equilibrium_ratio < shpb::reduce::quality::EQUILIBRIUM_TOLERANCE,
        "{fit:?}"
    );
    assert!(rel(fit.modulus_pa, e) < 0.01, "{fit:?} vs {e}");
    // True stress and strain at constant volume, compression positive.
    for i in 0..three.strain.len() {
        let eps = three.strain[i];
        assert!((three.true_strain[i] + (1.0 - eps).ln()).abs() < 1e-15);
        let s = three.stress_pa[i] * (1.0 - eps);
        assert!((three.true_stress_pa[i] - s).abs() <= 1e-12 * s.abs().max(1.0));
    }

    // The CSV holds the same curves.
    let t = shpb::csv::CsvTable::read(&d.join("red.csv")).unwrap();
    let k = t
        .names
        .iter()
        .position(|n| n == "three_wave_stress_Pa")
        .unwrap();
    let j = t
        .names
        .iter()
        .position(|n| n == "one_wave_true_strain")
        .unwrap();
    let col = |c: usize| -> &Vec<f64> { &t.columns[c] };
    let one = analysis("one_wave");
    for (a, b) in col(k).iter().zip(&three.stress_pa) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0));
    }
    for (a, b) in col(j).iter().zip(&one.true_strain) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-30));
    }

    // --json prints the same peak as the HDF5 1-wave curve.
    let mut json_args = args[..7].to_vec();
    json_args.push("--json");
    let o = shpb(d, &json_args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let peak = one.stress_pa.iter().copied().fold(f64::MIN, f64::max);
    let json_peak = v["cylinder"]["peak_stress_Pa"].as_f64().unwrap();
    assert!(
        (json_peak - peak).abs() <= 1e-12 * peak,
        "{json_peak} vs {peak}"
    );
    assert!(v["cylinder"]["mean_strain_rate_per_s"].as_f64().unwrap() > 0.0);
    // Without the flags, a cylinder's run file is reduced as its own cylinder.
    let o = shpb(d, &["reduce", "run.h5", "--no-dispersion", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let own: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(own["cylinder"], v["cylinder"]);
}

/// `--specimen-length` without `--specimen-diameter` (or the reverse) is refused, naming the
/// missing flag (exit code 2, bad input); so is a length out of range.
#[test]
fn the_cylinder_flags_come_in_pairs_and_in_range() {
    let dir = tempfile::tempdir().unwrap();
    let rec = root().join("validation/gauge-records/data/2013-05-22_sample1_ss440c.csv");
    let rec = rec.to_str().unwrap();
    let o = shpb(dir.path(), &["reduce", rec, "--specimen-length", "6e-3"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("`--specimen-diameter`: missing") && err.contains("or neither"),
        "{err}"
    );
    let o = shpb(dir.path(), &["reduce", rec, "--specimen-diameter", "6e-3"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("`--specimen-length`: missing"));
    let o = shpb(
        dir.path(),
        &[
            "reduce",
            rec,
            "--specimen-length=-1",
            "--specimen-diameter",
            "0.01",
        ],
    );
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("`--specimen-length`") && err.contains("at most 1"),
        "{err}"
    );
}
