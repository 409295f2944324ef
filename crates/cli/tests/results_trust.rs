//! Issue 42, categories 6 and 7 (the parts that are not a refused command line, which the bad
//! corpus `tests/corpus/bad/cases/results.toml` holds): summaries that cannot be right come out
//! as not available (NaN in the files, `null` in JSON) with a warning saying why, never as a
//! wrong number with exit 0; the run-size estimate of every scene kind against the steps and the
//! memory a run takes, with the tolerance stated at each test; `-j` beyond 4 per core refused.

mod common;

use common::{repo, shpb, shpb_env, stderr, stdout};
use shpb::prelude::*;
use shpb::scene::Params;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

fn scene(name: &str) -> PathBuf {
    repo().join("scenes").join(name)
}

/// `shpb run SCENE --json ARGS` in a fresh directory: exit code, the JSON, stderr.
fn run_json(scene: &Path, args: &[&str]) -> (i32, serde_json::Value, String) {
    let dir = TempDir::new().unwrap();
    let s = scene.display().to_string();
    let mut all = vec!["run", s.as_str(), "--json"];
    all.extend_from_slice(args);
    let out = shpb(dir.path(), &all);
    let json = serde_json::from_str(&stdout(&out)).unwrap_or(serde_json::Value::Null);
    (out.status.code().unwrap_or(-1), json, stderr(&out))
}

fn overridden(path: &Path, set: &[(&str, toml::Value)]) -> Params {
    let o: Vec<(String, toml::Value)> = set
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone()))
        .collect();
    Params::from_file_overridden(path, &o).unwrap()
}

/// The first contact of the 10-sphere chain lasts ≈ 20 µs (Hertz, 5 m/s): at 5 µs it is still
/// closing, and the chain's "restitution" came out as −0.52 with exit 0 (issue 42). Now it is
/// null with a warning naming it, and so is `energy_dissipated` (work held elastically in loaded
/// contacts is not dissipated); the full run keeps both, the restitution within 0..1.
#[test]
fn a_chain_whose_first_contact_has_not_ended_has_no_restitution() {
    let (code, json, err) = run_json(
        &scene("chain-ss440c-10.toml"),
        &["--set", "end_time_s=5e-6"],
    );
    assert_eq!(code, 0, "{err}");
    let summary = &json["summary"];
    assert!(summary["restitution"]["value"].is_null(), "{summary}");
    assert!(summary["energy_dissipated"]["value"].is_null(), "{summary}");
    let warnings = json["warnings"].to_string();
    assert!(
        warnings.contains("`restitution` is not available (NaN): the first contact has not ended"),
        "{warnings}"
    );
    assert!(
        warnings.contains("`energy_dissipated` is not available"),
        "{warnings}"
    );
    assert!(
        err.contains("shpb: warning: `restitution` is not available"),
        "{err}"
    );
    let (code, json, err) = run_json(&scene("chain-ss440c-10.toml"), &[]);
    assert_eq!(code, 0, "{err}");
    let e = json["summary"]["restitution"]["value"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&e), "restitution {e}");
    assert!(
        json["summary"]["energy_dissipated"]["value"]
            .as_f64()
            .unwrap()
            > 0.0
    );
}

/// A force-driven run that ends before the measured peak force compared its early approach
/// with the measured one at peak (relative error −0.99999, exit 0): now both errors are NaN with
/// a warning. 2 µs is 16+ steps of the default step (≈ 46 ns) and far before the 10 psi peak.
#[test]
fn a_force_driven_run_ending_before_the_measured_peak_has_no_error() {
    let (code, json, err) = run_json(
        &scene("force-driven-ss440c-10psi.toml"),
        &["--set", "end_time_s=2e-6"],
    );
    assert_eq!(code, 0, "{err}");
    let s = &json["summary"];
    assert!(
        s["displacement_at_peak_relative_error"]["value"].is_null(),
        "{s}"
    );
    assert!(
        s["displacement_at_measured_peak_relative_error_paper"]["value"].is_null(),
        "{s}"
    );
    assert!(
        json["warnings"]
            .to_string()
            .contains("before the measured peak force"),
        "{json}"
    );
}

/// Every summary value of every shipped scene, and of the scenes cut short, is a finite number
/// or comes with a warning naming it (no silent NaN of any kind).
#[test]
fn every_summary_that_is_not_a_number_is_explained() {
    let short = |t: f64| vec![("end_time_s", toml::Value::Float(t))];
    let mut cases: Vec<(PathBuf, Vec<(&str, toml::Value)>)> = Vec::new();
    for entry in std::fs::read_dir(repo().join("scenes")).unwrap() {
        let path = entry.unwrap().path();
        cases.push((
            path.clone(),
            vec![("fidelity", toml::Value::String("fast".into()))],
        ));
    }
    cases.push((scene("chain-ss440c-10.toml"), short(1e-6)));
    cases.push((scene("force-driven-ss440c-10psi.toml"), short(1e-6)));
    for (path, set) in cases {
        let p = overridden(&path, &set);
        let out = p.run().unwrap();
        for s in &out.summary {
            if !s.value.is_finite() {
                let named = format!("`{}`", s.key);
                assert!(
                    out.warnings.iter().any(|w| w.contains(&named)),
                    "{}: {} is {} without a warning: {:?}",
                    path.display(),
                    s.key,
                    s.value,
                    out.warnings
                );
            }
        }
    }
}

/// Steps a collision run takes: its contact series keeps every step (`output_every = 1`) plus
/// the start.
fn collision_steps(p: &Params) -> f64 {
    let out = p.run().unwrap();
    (out.contact.unwrap().force_n.len() - 1) as f64
}

/// The collision estimate against the steps taken, over the three laws, two pairs and closing
/// speeds from 1 mm/s to 200 m/s (faster, a yielding law reaches an approach of a radius
/// and the run is refused). Stated tolerance: the estimate is an upper bound, at most 4
/// times the steps taken (it takes 3 Hertz contact times, `estimate::
/// COLLISION_ESTIMATE_CONTACT_TIMES`; contacts last 0.95–1.5 t_c). Until issue 42 it took the
/// solver's 100 t_c time limit, 85–270 times the steps.
#[test]
fn the_collision_estimate_is_within_four_times_the_steps_taken() {
    let mut worst: f64 = 0.0;
    for file in ["collision-ss440c-5ms.toml", "collision-dissimilar.toml"] {
        for law in ["burgoyne-daraio", "rate-independent", "hertz"] {
            for v in [1e-3, 1.0, 5.0, 50.0, 200.0] {
                let p = overridden(
                    &scene(file),
                    &[
                        ("law", toml::Value::String(law.into())),
                        ("velocity1_m_s", toml::Value::Float(v)),
                        ("velocity2_m_s", toml::Value::Float(0.0)),
                        ("fidelity", toml::Value::String("fast".into())),
                    ],
                );
                let e = p.estimate();
                let taken = collision_steps(&p);
                let ratio = e.steps / taken;
                println!(
                    "{file} {law} {v} m/s: estimate {} steps, taken {taken}",
                    e.steps
                );
                assert!(
                    (1.0..=4.0).contains(&ratio),
                    "{file} {law} {v} m/s: estimate {} steps, taken {taken}",
                    e.steps
                );
                assert!(e.samples_stored >= taken + 1.0);
                worst = worst.max(ratio);
            }
        }
    }
    println!("largest estimate / steps taken: {worst:.2}");
}

/// The other kinds take exactly the steps their estimate says (their end time over the step):
/// chain and force-driven keep every step at `output_every = 1`, so their series hold the steps
/// (within the one or two samples the estimate adds for the start and the end); the curve kinds
/// hold their points.
#[test]
fn the_other_kinds_estimate_the_samples_they_keep() {
    for (file, series) in [
        ("chain-ss440c-10.toml", "chain"),
        ("force-driven-ss440c-10psi.toml", "contact"),
        ("quasistatic-fig2.toml", "contact"),
        ("constant-rate-ss440c-1e4.toml", "contact"),
    ] {
        let p = overridden(
            &scene(file),
            &[("fidelity", toml::Value::String("fast".into()))],
        );
        let e = p.estimate();
        let out = p.run().unwrap();
        let kept = match series {
            "chain" => out.chain.as_ref().unwrap().time_s.len(),
            _ => out.contact.as_ref().unwrap().force_n.len(),
        } as f64;
        println!("{file}: estimate {} samples, kept {kept}", e.samples_stored);
        assert!(
            e.samples_stored >= kept && e.samples_stored <= kept + 3.0,
            "{file}: estimate {} samples, kept {kept}",
            e.samples_stored
        );
    }
}

/// A bar run's output estimate against the HDF5 file it writes (`shpb run -o`), over the pulse,
/// sphere and cylinder scenes shipped. Stated tolerance: the estimate bounds the file (it is
/// compared with the free disk before a run, issue 42) and is at most 1.5 times it (the
/// reduction's series are counted at the record's length, the window is shorter).
#[test]
fn a_bar_run_s_output_estimate_bounds_its_file() {
    for file in [
        "pulse-10psi.toml",
        "shpb-ss440c-10psi.toml",
        "shpb-cylinder-copper.toml",
    ] {
        let dir = TempDir::new().unwrap();
        let e = Params::from_file(&scene(file)).unwrap().estimate();
        let s = scene(file).display().to_string();
        let out = shpb(dir.path(), &["run", s.as_str(), "-q", "-o", "r.h5"]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let size = std::fs::metadata(dir.path().join("r.h5")).unwrap().len() as f64;
        println!(
            "{file}: estimate {:.0} B, file {size:.0} B, ratio {:.3}",
            e.output_bytes,
            e.output_bytes / size
        );
        assert!(e.output_bytes >= size, "{file}: estimate below the file");
        assert!(
            e.output_bytes <= 1.5 * size,
            "{file}: estimate over 1.5 times the file"
        );
    }
}

/// A collision of 2e6 steps per Hertz contact time: its memory estimate against the data the
/// run keeps (its contact series, 5 numbers a step). Stated tolerance: the estimate bounds it
/// and is at most 10 times it (3 contact times where ≈ 1 is taken, times 3 for a series that
/// grows by doubling). The run fits a 1 GB memory limit and is not refused; the estimate of the
/// 100 t_c time limit (issue 42) asked for 24 GB.
#[test]
fn a_collision_that_fits_is_run_and_its_memory_is_estimated() {
    let dir = TempDir::new().unwrap();
    let text = "kind = \"collision\"\nvelocity1_m_s = 5.0\nsteps_per_contact = 2e6\n\
                [specimen]\npair = \"ss440c\"\n";
    std::fs::write(dir.path().join("big.toml"), text).unwrap();
    let p = Params::from_file(&dir.path().join("big.toml")).unwrap();
    let e = p.estimate();
    let data = 8.0 * 5.0 * p.run().unwrap().contact.unwrap().force_n.len() as f64;
    println!("estimate {:.3e} B, data kept {data:.3e} B", e.memory_bytes);
    assert!(e.memory_bytes >= data, "estimate below the data kept");
    assert!(
        e.memory_bytes <= 10.0 * data,
        "estimate over 10 times the data kept"
    );
    let out = shpb_env(
        dir.path(),
        &["run", "big.toml", "-q"],
        &[("SHPB_MEMORY_LIMIT", "1e9")],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

/// `-j` beyond 4 worker threads per core is refused before anything runs (it spawned hundreds
/// of threads silently), naming `-j` and the range; `-j` up to the limit runs.
#[test]
fn too_many_jobs_are_refused_naming_the_limit() {
    let dir = TempDir::new().unwrap();
    let s = scene("collision-ss440c-5ms.toml").display().to_string();
    let most = shpb::sweep::max_jobs();
    for cmd in ["sweep", "study"] {
        let mut args = vec![cmd, s.as_str(), "-j", "100000"];
        if cmd == "sweep" {
            args.extend(["--set", "velocity1_m_s=1,2"]);
        }
        let out = shpb(dir.path(), &args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains("`-j`: 100000 worker threads is more than 4 per core"),
            "{err}"
        );
        assert!(err.contains(&format!("allowed: 1 to {most}")), "{err}");
        assert!(stdout(&out).is_empty());
    }
    let j = most.to_string();
    let out = shpb(
        dir.path(),
        &["sweep", &s, "--set", "velocity1_m_s=1,2", "-j", &j],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

/// `curve --specimen` takes a material file, as its help says (the paper's 6.35 mm pair of it,
/// as for a built-in name): `specimens/ss440c.toml` is the built-in ss440c, so the curves are the
/// same text. It was refused with a TOML error about a pair file.
#[test]
fn curve_takes_a_material_file() {
    let dir = TempDir::new().unwrap();
    let file = repo().join("specimens/ss440c.toml").display().to_string();
    let from_file = shpb(dir.path(), &["curve", "--specimen", &file, "--points", "5"]);
    assert_eq!(from_file.status.code(), Some(0), "{}", stderr(&from_file));
    let builtin = shpb(
        dir.path(),
        &["curve", "--specimen", "ss440c", "--points", "5"],
    );
    assert_eq!(stdout(&from_file), stdout(&builtin));
    let pair = repo()
        .join("specimens/pair-6.35mm-ss440c.toml")
        .display()
        .to_string();
    let from_pair = shpb(dir.path(), &["curve", "--specimen", &pair, "--points", "5"]);
    assert_eq!(stdout(&from_pair), stdout(&builtin));
}
