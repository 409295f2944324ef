//! `shpb sweep`: the Cartesian product, deterministic shards whose union is the whole sweep,
//! summaries identical to single runs, parallel runs identical to serial ones, and clear errors
//! for bad `--set` specifications.

use shpb::prelude::*;
use shpb::scene::Params;
use shpb::sweep::{overrides, parse_axis, parse_shard, product, run_points, shard, summarise};
use std::path::PathBuf;

fn scene() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("scenes/shpb-ss440c-10psi.toml")
}

fn axes() -> Vec<shpb::sweep::Axis> {
    // `fast` keeps the test quick; the summary's physics is the same at every preset (tests/fidelity.rs).
    [
        "fidelity=fast",
        "pressure=8psi:16psi:3",
        "shaper.thickness=0.35mm,0.5mm",
    ]
    .iter()
    .map(|s| parse_axis(s).unwrap())
    .collect()
}

/// `--plot` draws the one- and two-parameter summary figures.
#[test]
fn sweep_plots_one_and_two_parameters() {
    let dir = tempfile::TempDir::new().unwrap();
    let scene = scene();
    for (name, extra) in [
        ("one.png", vec![]),
        ("two.png", vec!["--set", "shaper.thickness=0.35mm,0.45mm"]),
    ] {
        let mut args = vec![
            "sweep",
            scene.to_str().unwrap(),
            "--set",
            "pressure=8psi:16psi:3",
            "--plot",
            name,
        ];
        args.extend(extra);
        let out = shpb(dir.path(), &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(std::fs::metadata(dir.path().join(name)).unwrap().len() > 10_000);
    }
}

#[test]
fn set_specifications_parse_with_units_and_aliases() {
    let a = parse_axis("striker.pressure=5psi:20psi:16").unwrap();
    assert_eq!(a.key, "pressure");
    assert_eq!(a.labels.len(), 16);
    assert_eq!(
        (a.labels[0].as_str(), a.labels[15].as_str()),
        ("5psi", "20psi")
    );
    let t = parse_axis("shaper.thickness=0.5mm,1mm,1.5mm").unwrap();
    assert_eq!(t.key, "shaper.thickness_m");
    assert_eq!(t.values[1], shpb::scene::Value::Float(1e-3));
    for bad in [
        "pressure",
        "=1,2",
        "pressure=5psi:20bar:3",
        "pressure=1:2:x",
        "shaper.thickness_m=1furlong",
        "pressure=1,,2",
        "pressure=1:2:1",
    ] {
        let e = parse_axis(bad).unwrap_err().to_string();
        assert!(e.contains("--set"), "{bad}: {e}");
    }
    assert!(
        parse_shard("0/2").is_err() && parse_shard("3/2").is_err() && parse_shard("a").is_err()
    );
    assert_eq!(parse_shard("2/4").unwrap(), (2, 4));
}

#[test]
fn shards_partition_the_product_and_parallel_runs_match_single_runs() {
    let axes = axes();
    let all = product(&axes);
    assert_eq!(all.len(), 6);
    let whole = run_points(&scene(), &axes, &all, 2, |_| {}).unwrap();
    // Each run equals the same scene run on its own, bit for bit.
    for (p, row) in all.iter().zip(&whole) {
        let out = Params::from_file_overridden(&scene(), &overrides(&axes, p))
            .unwrap()
            .run()
            .unwrap();
        assert_eq!(summarise(p.index, row.inputs.clone(), &out), *row);
    }
    // Two shards, run serially, together are the whole sweep.
    let mut merged = Vec::new();
    for k in 1..=2 {
        let part = shard(all.clone(), k, 2);
        merged.extend(run_points(&scene(), &axes, &part, 1, |_| {}).unwrap());
    }
    merged.sort_by_key(|r| r.index);
    assert_eq!(merged, whole);
    // Peak force grows with pressure at each shaper thickness.
    for j in 0..2 {
        assert!(whole[j].peak_force_n < whole[2 + j].peak_force_n);
        assert!(whole[2 + j].peak_force_n < whole[4 + j].peak_force_n);
    }
}

fn shpb(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// The finished runs in a checkpoint (its lines after the `#` header).
fn checkpoint_rows(path: &std::path::Path) -> usize {
    std::fs::read_to_string(path)
        .map(|t| t.lines().filter(|l| !l.starts_with('#')).count())
        .unwrap_or(0)
}

/// The summary attributes of a sweep file, for comparison.
fn summary(path: &std::path::Path) -> Vec<shpb::sweep::RunSummary> {
    shpb::study_file::read_sweep_hdf5(path).unwrap().rows
}

/// Killing a sweep midway and running it again with `--resume` gives the same summary as an
/// uninterrupted sweep (values round-trip exactly through the checkpoint); two shards merged
/// equal the unsharded sweep.
#[test]
fn killed_sweep_resumes_and_shards_merge_to_the_whole() {
    let dir = tempfile::TempDir::new().unwrap();
    let scene = scene();
    let scene = scene.to_str().unwrap();
    let set = [
        "--set",
        "pressure=8psi:20psi:5",
        "--set",
        "shaper.thickness=0.35mm,0.45mm",
    ];
    let run = |extra: &[&str]| {
        let mut args = vec!["sweep", scene];
        args.extend(set);
        args.extend(extra);
        shpb(dir.path(), &args)
    };
    let whole = run(&["-o", "whole.h5", "-j", "2"]);
    assert!(
        whole.status.success(),
        "{}",
        String::from_utf8_lossy(&whole.stderr)
    );

    // Interrupted: kill the process once the checkpoint holds a run, before it finishes.
    let mut args = vec!["sweep", scene];
    args.extend(set);
    args.extend(["-o", "resumed.h5", "-j", "1"]);
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir.path())
        .args(&args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let checkpoint = dir.path().join("resumed.h5.partial.csv");
    let start = std::time::Instant::now();
    while start.elapsed().as_secs() < 60 {
        if checkpoint_rows(&checkpoint) >= 2 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !dir.path().join("resumed.h5").exists(),
        "no output before the sweep completes"
    );
    let done_before = checkpoint_rows(&checkpoint);
    assert!(
        (1..10).contains(&done_before),
        "{done_before} runs checkpointed"
    );
    let again = run(&["-o", "resumed.h5"]);
    assert_eq!(
        again.status.code(),
        Some(2),
        "a checkpoint needs --resume or --force"
    );
    let resumed = run(&["-o", "resumed.h5", "--resume"]);
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    assert!(String::from_utf8_lossy(&resumed.stderr).contains(&format!("{done_before} runs done")));
    assert!(!checkpoint.exists(), "checkpoint removed after completion");
    assert_eq!(
        summary(&dir.path().join("resumed.h5")),
        summary(&dir.path().join("whole.h5"))
    );

    for k in ["1/2", "2/2"] {
        let name = format!("shard{}.h5", &k[..1]);
        let out = run(&["--shard", k, "-o", &name]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let merged = shpb(
        dir.path(),
        &["merge", "shard1.h5", "shard2.h5", "-o", "merged.h5"],
    );
    assert!(
        merged.status.success(),
        "{}",
        String::from_utf8_lossy(&merged.stderr)
    );
    assert_eq!(
        summary(&dir.path().join("merged.h5")),
        summary(&dir.path().join("whole.h5"))
    );
}

/// `shpb sweep --fidelity NAME` is `--set fidelity=NAME`: the same table, its `fidelity` column
/// included; given with `--set fidelity=…` as well, the key is reported as given twice.
#[test]
fn the_fidelity_flag_is_a_one_value_fidelity_axis() {
    let dir = tempfile::TempDir::new().unwrap();
    let scene = scene();
    // A sweep of two pressures with the extra arguments `how`, its exit code and its CSV's
    // rows with the columns in name order.
    let sweep = |how: &str, csv: &str| {
        let mut args = vec!["sweep", scene.to_str().unwrap(), "--csv", csv];
        args.extend(how.split(' '));
        let out = shpb(dir.path(), &args);
        let text = std::fs::read_to_string(dir.path().join(csv)).unwrap_or_default();
        let lines: Vec<Vec<&str>> = text.lines().map(|l| l.split(',').collect()).collect();
        let mut order: Vec<usize> = (0..lines.first().map_or(0, Vec::len)).collect();
        order.sort_by_key(|&i| lines[0][i]);
        let rows: Vec<Vec<String>> = lines
            .iter()
            .map(|l| order.iter().map(|&i| l[i].to_string()).collect())
            .collect();
        (out, rows)
    };
    let (flag, a) = sweep("--fidelity fast --set pressure=9psi,11psi", "a.csv");
    assert!(
        flag.status.success(),
        "{}",
        String::from_utf8_lossy(&flag.stderr)
    );
    let (set, b) = sweep("--set pressure=9psi,11psi --set fidelity=fast", "b.csv");
    assert!(
        set.status.success(),
        "{}",
        String::from_utf8_lossy(&set.stderr)
    );
    assert_eq!(a, b);
    let column = a[0]
        .iter()
        .position(|c| c == "fidelity")
        .expect("a fidelity column");
    assert!(a[1..].iter().all(|row| row[column] == "fast"));
    let (both, _) = sweep(
        "--fidelity fast --set fidelity=standard --set pressure=9psi",
        "c.csv",
    );
    assert_eq!(both.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&both.stderr).contains("fidelity"));
}

/// Issue 45: with the points validated in parallel on the pool of the runs, a sweep on one thread
/// and on two writes the same files: the CSV byte for byte, the study file's datasets and
/// attributes bit for bit; and an invalid point late in the product is reported as the first
/// invalid one in order, the same error at `-j 1` and `-j 2`, before any run.
#[test]
fn one_and_two_threads_write_the_same_rows_and_the_same_first_error() {
    let dir = tempfile::TempDir::new().unwrap();
    let scene = scene();
    let scene = scene.to_str().unwrap();
    let set = [
        "--set",
        "fidelity=fast",
        "--set",
        "pressure=8psi:16psi:3",
        "--set",
        "shaper.thickness=0.35mm,0.5mm",
    ];
    for j in ["1", "2"] {
        let (h5, csv) = (format!("j{j}.h5"), format!("j{j}.csv"));
        let mut args = vec!["--quiet", "sweep", scene];
        args.extend(set);
        args.extend(["-j", j, "-o", &h5, "--csv", &csv]);
        let o = shpb(dir.path(), &args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert_eq!(read("j1.csv"), read("j2.csv"));
    assert_eq!(read("j1.csv").iter().filter(|&&b| b == b'\n').count(), 7);
    // Every dataset and attribute of the two study files, as h5dump prints them.
    let dump = |name: &str| {
        let o = std::process::Command::new("h5dump")
            .arg(dir.path().join(name))
            .output()
            .unwrap();
        assert!(o.status.success());
        String::from_utf8(o.stdout).unwrap().replace(name, "FILE")
    };
    let (one, two) = (dump("j1.h5"), dump("j2.h5"));
    assert!(one.contains("peak_force"), "{one}");
    assert_eq!(one, two);
    // Invalid shaper thicknesses at runs 4 and 5 of 6 (and a valid one after): the error names
    // the first (-1 mm), at one thread and two, and nothing is written.
    let mut errors = Vec::new();
    for j in ["1", "2"] {
        let o = shpb(
            dir.path(),
            &[
                "--quiet",
                "sweep",
                scene,
                "--set",
                "fidelity=fast",
                "--set",
                "shaper.thickness=0.5mm,0.4mm,0.3mm,-1mm,-2mm,0.2mm",
                "-j",
                j,
                "--csv",
                "bad.csv",
            ],
        );
        assert_eq!(o.status.code(), Some(2));
        errors.push(String::from_utf8_lossy(&o.stderr).into_owned());
        assert!(!dir.path().join("bad.csv").exists());
    }
    assert_eq!(errors[0], errors[1]);
    assert!(errors[0].contains("-1 mm is out of range"), "{}", errors[0]);
}
