//! `shpb study` (issue 21, uncertainty propagation): a study of fixed inputs equals one run; a
//! linear quantity's mean and percentiles match the analytic values within sampling error; the
//! same seed gives the same files, another seed other samples; the gun's scatter is drawn by
//! default for a fixed pressure; a single run refuses a distribution.

use shpb::prelude::*;
use shpb::scene::Params;
use shpb::sweep::summarise;
use shpb::uq::study_rows;
use std::path::{Path, PathBuf};

fn shpb(dir: &Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// A fast SS440c test at `pressure` (a TOML value: a string or a distribution table).
fn scene(dir: &Path, name: &str, pressure: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            "kind = \"shpb\"\nbars = \"authors\"\nfidelity = \"fast\"\npressure = {pressure}\n\
             [specimen]\npair = \"ss440c\"\n"
        ),
    )
    .unwrap();
    path
}

/// A study plan of `samples` samples drawn with `seed`, the gun scatter as `gun_scatter`, the
/// scene's fidelity.
fn plan(samples: usize, seed: u64, gun_scatter: bool) -> shpb::uq::StudyPlan {
    shpb::uq::StudyPlan {
        gun_scatter,
        ..shpb::uq::StudyPlan::new(samples, seed)
    }
}

/// `shpb study ARGS --summary stats.csv` in `dir`, which must succeed: what it printed and the
/// statistics CSV it wrote.
fn study_summary(dir: &Path, args: &[&str]) -> (String, String) {
    let mut all = vec!["study"];
    all.extend(args);
    all.extend(["--summary", "stats.csv", "--force"]);
    let out = shpb(dir, &all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("stats.csv")).unwrap();
    (String::from_utf8(out.stdout).unwrap(), csv)
}

/// The statistics CSV's row `quantity` as (name → cell).
fn stats_row(text: &str, quantity: &str) -> std::collections::HashMap<String, String> {
    let mut lines = text.lines();
    let head: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let row = lines
        .find(|l| l.split(',').next() == Some(quantity))
        .unwrap_or_else(|| panic!("no row {quantity} in\n{text}"));
    head.into_iter()
        .zip(row.split(',').map(String::from))
        .collect()
}

/// Fixed inputs (and the gun scatter off): every sample is the one run of the scene, bit for
/// bit, and the statistics have no spread. With the gun scatter on (the default), the fixed
/// pressure becomes an input drawn from the set-up's `velocity_scatter`.
#[test]
fn a_study_of_fixed_inputs_equals_one_run() {
    let dir = tempfile::TempDir::new().unwrap();
    let path = scene(dir.path(), "fixed.toml", "\"10psi\"");
    let one = summarise(0, vec![], &Params::from_file(&path).unwrap().run().unwrap());
    let study = study_rows(&path, &plan(3, 7, false), 2, false, |_| {}).unwrap();
    assert!(study.inputs.is_empty());
    for row in &study.rows {
        let (a, b) = (row.values(), one.values());
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.to_bits(), y.to_bits(), "{row:?} vs {one:?}");
        }
    }
    let (printed, text) = study_summary(
        dir.path(),
        &["fixed.toml", "--samples", "2", "--no-gun-scatter"],
    );
    // The printed table names every quantity.
    assert!(
        printed.contains("peak_force") && printed.contains("p95"),
        "{printed}"
    );
    let row = stats_row(&text, "peak_force");
    assert_eq!(row["sd"].parse::<f64>().unwrap(), 0.0, "{text}");
    assert_eq!(row["mean"].parse::<f64>().unwrap(), one.peak_force_n);
    // The default: the gun's shot-to-shot scatter on the fixed pressure.
    let scattered = study_rows(&path, &plan(4, 7, true), 2, false, |_| {}).unwrap();
    assert_eq!(scattered.keys(), ["pressure"]);
    assert!(scattered.statistics()[0].sd > 0.0);
}

/// `--fidelity` runs every sample at that preset, as `shpb run --fidelity` runs the scene: a
/// study of fixed inputs at `standard` (the scene says `fast`) is the one run at `standard` bit
/// for bit, not the scene's own; the study's description names the preset; `shpb study
/// --fidelity` gives the same mean.
#[test]
fn the_fidelity_flag_runs_every_sample_at_that_preset() {
    use shpb::fidelity::Fidelity;
    let dir = tempfile::TempDir::new().unwrap();
    let path = scene(dir.path(), "fixed.toml", "\"10psi\"");
    let one = |f: Option<Fidelity>| {
        let params = Params::from_file_with(&path, f).unwrap();
        summarise(0, vec![], &params.run().unwrap())
    };
    let (standard, fast) = (one(Some(Fidelity::Standard)), one(None));
    assert_ne!(standard.values(), fast.values(), "the presets differ here");
    let at_standard = shpb::uq::StudyPlan {
        fidelity: Some(Fidelity::Standard),
        ..plan(2, 7, false)
    };
    let study = study_rows(&path, &at_standard, 2, false, |_| {}).unwrap();
    for row in &study.rows {
        for (x, y) in row.values().iter().zip(&standard.values()) {
            assert_eq!(x.to_bits(), y.to_bits(), "{row:?} vs {standard:?}");
        }
    }
    assert!(
        study
            .specification()
            .iter()
            .any(|l| l.contains("fidelity standard")),
        "{:?}",
        study.specification()
    );
    let (_, text) = study_summary(
        dir.path(),
        &[
            "fixed.toml",
            "--samples",
            "2",
            "--no-gun-scatter",
            "--fidelity",
            "standard",
        ],
    );
    let mean: f64 = stats_row(&text, "peak_force")["mean"].parse().unwrap();
    assert_eq!(mean, standard.peak_force_n, "{text}");
}

/// The drawn pressure is itself a linear test quantity (Y = X): its mean and percentiles must be
/// the normal's, within the sampling error of N = 16 samples. The mean: 3 standard errors of
/// simple random sampling, 3 sd/√N (a Latin hypercube's is never larger, asymptotically; for the
/// identity it is far smaller). The percentiles of a sample of 16 (type 7): the standard error of
/// a p quantile is √(p(1 − p)/N)/φ(z_p) sd = 0.64 sd at p = 5 %, 0.31 sd at the median; 3 of them.
/// The peak force follows the pressure, which carries all its variance: its first-order index is
/// large.
#[test]
fn a_linear_quantity_has_the_analytic_mean_and_percentiles() {
    let dir = tempfile::TempDir::new().unwrap();
    scene(
        dir.path(),
        "normal.toml",
        "{ mean = \"12.5psi\", sd = \"0.6psi\" }",
    );
    let (_, text) = study_summary(dir.path(), &["normal.toml", "--samples", "16", "-j", "2"]);
    let psi = shpb::units::PSI_PA;
    let (mean, sd, n) = (12.5 * psi, 0.6 * psi, 16.0f64);
    let row = stats_row(&text, "input pressure");
    let get = |k: &str| row[k].parse::<f64>().unwrap();
    assert_eq!(row["unit"], "Pa");
    assert!((get("mean") - mean).abs() < 3.0 * sd / n.sqrt(), "{row:?}");
    assert!(
        (get("sd") - sd).abs() < 3.0 * sd / (2.0 * n).sqrt(),
        "{row:?}"
    );
    for (k, z, se) in [
        ("p5", -1.644_853_6, 0.64),
        ("p50", 0.0, 0.31),
        ("p95", 1.644_853_6, 0.64),
    ] {
        let want = mean + z * sd;
        assert!(
            (get(k) - want).abs() < 3.0 * se * sd,
            "{k}: {} vs {want}",
            get(k)
        );
    }
    let force = stats_row(&text, "peak_force");
    assert!(
        force["S_pressure"].parse::<f64>().unwrap() > 0.5,
        "{force:?}"
    );
}

/// The same seed gives byte-identical CSV and HDF5 outputs; another seed draws
/// other samples.
#[test]
fn the_same_seed_gives_the_same_files() {
    let dir = tempfile::TempDir::new().unwrap();
    scene(dir.path(), "u.toml", "{ min = \"10psi\", max = \"14psi\" }");
    let run = |seed: &str, tag: &str| {
        let (runs, stats, h5) = (
            format!("runs-{tag}.csv"),
            format!("stats-{tag}.csv"),
            format!("study-{tag}.h5"),
        );
        let out = shpb(
            dir.path(),
            &[
                "study",
                "u.toml",
                "--samples",
                "4",
                "--seed",
                seed,
                "-j",
                "2",
                "--csv",
                &runs,
                "--summary",
                &stats,
                "-o",
                &h5,
            ],
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let read = |f: &str| std::fs::read(dir.path().join(f)).unwrap();
        (read(&runs), read(&stats), dir.path().join(h5))
    };
    let a = run("5", "a");
    let b = run("5", "b");
    let c = run("6", "c");
    assert_eq!(a.0, b.0, "runs CSV");
    assert_eq!(a.1, b.1, "statistics CSV");
    assert_ne!(a.0, c.0, "another seed draws other samples");
    let (fa, fb) = (
        shpb::study_file::read_sweep_hdf5(&a.2).unwrap(),
        shpb::study_file::read_sweep_hdf5(&b.2).unwrap(),
    );
    assert_eq!(fa.rows, fb.rows);
    assert_eq!(
        std::fs::read(&a.2).unwrap(),
        std::fs::read(&b.2).unwrap(),
        "HDF5 bytes"
    );
    // An existing output is not replaced without --force.
    let again = shpb(
        dir.path(),
        &["study", "u.toml", "--samples", "4", "--csv", "runs-a.csv"],
    );
    assert_eq!(again.status.code(), Some(2));
}

/// `shpb run` refuses a scene with a distribution, naming the key and pointing to `shpb study`;
/// a malformed distribution is an input error naming the file, the key and the forms.
#[test]
fn a_single_run_refuses_a_distribution() {
    let dir = tempfile::TempDir::new().unwrap();
    scene(
        dir.path(),
        "d.toml",
        "{ mean = \"12.5psi\", sd = \"0.6psi\" }",
    );
    let out = shpb(dir.path(), &["run", "d.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("`pressure`") && e.contains("shpb study"), "{e}");
    scene(dir.path(), "bad.toml", "{ mean = \"12.5psi\" }");
    let out = shpb(dir.path(), &["study", "bad.toml", "--samples", "2"]);
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("bad.toml: `pressure`") && e.contains("log-normal"),
        "{e}"
    );
}

/// The shipped example study (README "Uncertainty studies") draws valid scenes.
#[test]
fn the_shipped_example_study_draws_valid_scenes() {
    let path = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("examples/study/ss440c-12p5psi.toml");
    let inputs = shpb::uq::study_inputs(&path, true).unwrap();
    let keys: Vec<&str> = inputs.iter().map(|i| i.key.as_str()).collect();
    assert_eq!(keys, ["pressure", "shaper.thickness_m"]);
    let samples = shpb::uq::draw(&inputs, 8, 1).unwrap();
    for o in &samples.overrides {
        Params::from_file_overridden(&path, o).unwrap();
    }
    assert!(Params::from_file(&path).is_err(), "a single run refuses it");
}

/// Shards of a study (as Dask workers or a job array run them) join into the whole study: the
/// same rows bit for bit and the same statistics; a shard's rows alone are refused.
#[test]
fn shards_of_a_study_join_into_the_whole_study() {
    let dir = tempfile::TempDir::new().unwrap();
    let path = scene(
        dir.path(),
        "uncertain.toml",
        "{ mean = \"10psi\", sd = \"0.5psi\" }",
    );
    let whole = study_rows(&path, &plan(5, 11, false), 1, false, |_| {}).unwrap();
    let mut rows = Vec::new();
    for k in [2, 1] {
        let part = shpb::uq::study_shard_rows(&path, &plan(5, 11, false), 1, false, (k, 2), |_| {})
            .unwrap();
        assert!(part.rows.iter().all(|r| r.index % 2 == k - 1));
        rows.extend(part.rows);
    }
    let first = rows[..2].to_vec();
    let joined = shpb::uq::Study::from_rows(&path, &plan(5, 11, false), rows).unwrap();
    assert_eq!(joined.rows, whole.rows);
    assert_eq!(joined.statistics_csv(), whole.statistics_csv());
    let e = shpb::uq::Study::from_rows(&path, &plan(5, 11, false), first).unwrap_err();
    assert!(e.to_string().contains("exactly once"), "{e}");
}

/// A distribution whose draws the key does not take (a plain number where `pressure` needs its
/// unit) is refused before any run, naming the key, the sample and the form to write.
#[test]
fn a_unitless_pressure_distribution_is_refused_naming_the_key() {
    let dir = tempfile::TempDir::new().unwrap();
    let path = scene(dir.path(), "unitless.toml", "{ mean = 12.5, sd = 1.0 }");
    let out = shpb(
        dir.path(),
        &["study", path.to_str().unwrap(), "--samples", "4"],
    );
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("`pressure`: sample 0"), "{e}");
    assert!(e.contains("\"12.5psi\""), "{e}");
}
