//! Issue 15, acceptance: random sequences of sweeps stopped at random moments (SIGINT, SIGTERM,
//! SIGKILL), resumed, forced, run twice at once on the same output, sharded and merged (with
//! shards missing or repeated), with the scene edited in between, never lose, duplicate or mix a
//! run: every study file and checkpoint holds each of its runs once, with the values of an
//! uninterrupted sweep of the scene it records; a resume keeps every run of the checkpoint it
//! takes over; a merge succeeds exactly when it is given every shard of one sweep once; and the
//! sweep can always be finished.
//!
//! A cheap scene (a two-sphere collision, 24 runs, ≈ 0.1 s a sweep) keeps a case short; the case
//! count is bounded (8; `SHPB_PROPTEST_CASES=n` for a longer search).

use proptest::prelude::*;
use shpb::study_identity::Stamp;
use shpb::sweep::RunSummary;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::Duration;

/// Runs of the sweep.
const RUNS: usize = 24;
const SET: [&str; 2] = ["--set", "velocity1_m_s=1:5:24"];

fn repo() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The scene in its two versions (a second version: the other sphere moving).
fn scene_text(version: usize) -> String {
    let text = std::fs::read_to_string(repo().join("scenes/collision-ss440c-5ms.toml")).unwrap();
    match version {
        0 => text,
        _ => text.replace("velocity2_m_s = 0.0", "velocity2_m_s = -0.5"),
    }
}

fn bits(r: &RunSummary) -> (usize, Vec<String>, [u64; 5]) {
    (r.index, r.inputs.clone(), r.values().map(f64::to_bits))
}

/// An uninterrupted sweep of each version of the scene: SHA-256 of the scene → its rows.
fn references() -> &'static HashMap<String, Vec<RunSummary>> {
    static REFS: OnceLock<HashMap<String, Vec<RunSummary>>> = OnceLock::new();
    REFS.get_or_init(|| {
        (0..2)
            .map(|v| {
                let dir = tempfile::TempDir::new().unwrap();
                std::fs::write(dir.path().join("scene.toml"), scene_text(v)).unwrap();
                let mut args = vec!["sweep", "scene.toml"];
                args.extend(SET);
                args.extend(["-o", "ref.h5"]);
                let o = shpb(dir.path(), &args);
                assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
                let rows = shpb::study_file::read_sweep_hdf5(&dir.path().join("ref.h5"))
                    .unwrap()
                    .rows;
                assert_eq!(rows.len(), RUNS);
                (shpb::provenance::sha256_hex(scene_text(v).as_bytes()), rows)
            })
            .collect()
    })
}

fn shpb(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

#[derive(Debug, Clone, Copy)]
enum Stop {
    Int,
    Term,
    Kill,
}

#[derive(Debug, Clone)]
enum Op {
    /// `shpb sweep … -o out.h5` (or shard k of 2 to `shard<k>.h5`), maybe stopped after `ms`.
    Sweep {
        shard: Option<usize>,
        jobs: usize,
        resume: bool,
        force: bool,
        stop: Option<(Stop, u64)>,
    },
    /// Two identical sweeps on `out.h5` started together.
    Together { resume: bool, force: bool },
    /// `shpb merge` of these shard files (1, 2; missing or repeated ones too) to `merged.h5`.
    Merge(Vec<usize>),
    /// The scene file switches to its other version.
    EditScene,
}

fn op() -> impl Strategy<Value = Op> {
    let stop = prop::option::of((
        prop_oneof![Just(Stop::Int), Just(Stop::Term), Just(Stop::Kill)],
        0u64..160,
    ));
    prop_oneof![
        4 => (prop::option::of(1usize..=2), 1usize..=2, any::<bool>(), prop::bool::weighted(0.2), stop)
            .prop_map(|(shard, jobs, resume, force, stop)| Op::Sweep { shard, jobs, resume, force, stop }),
        1 => (any::<bool>(), any::<bool>()).prop_map(|(resume, force)| Op::Together { resume, force }),
        1 => prop::collection::vec(1usize..=2, 1..=3).prop_map(Op::Merge),
        1 => Just(Op::EditScene),
    ]
}

fn sweep_args(shard: Option<usize>, jobs: usize, resume: bool, force: bool) -> Vec<String> {
    let mut a: Vec<String> = ["sweep", "scene.toml"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    a.extend(SET.iter().map(|s| s.to_string()));
    a.extend(["-j".into(), jobs.to_string()]);
    match shard {
        Some(k) => a.extend([
            "--shard".into(),
            format!("{k}/2"),
            "-o".into(),
            format!("shard{k}.h5"),
        ]),
        None => a.extend(["-o".into(), "out.h5".into()]),
    }
    if resume {
        a.push("--resume".into());
    }
    if force {
        a.push("--force".into());
    }
    a
}

/// The runs of shard k of n.
fn shard_runs((k, n): (u64, u64)) -> Vec<usize> {
    (k as usize - 1..RUNS).step_by(n as usize).collect()
}

/// Every study file holds each of its shard's runs once, equal to the reference of its scene.
/// What a study file holds: the SHA-256 of its scene and its shard.
type Holds = Option<(String, (u64, u64))>;

fn check_file(path: &Path) -> Result<Holds, TestCaseError> {
    if !path.exists() {
        return Ok(None);
    }
    let f = shpb::study_file::read_sweep_hdf5(path)
        .map_err(|e| TestCaseError::fail(format!("{}: {e}", path.display())))?;
    // The scene by the text the file stores, the shard by its `sweep` lines.
    let scene = shpb::provenance::sha256_hex(f.scene.as_bytes());
    let shard = f
        .sweep
        .iter()
        .find_map(|l| l.strip_prefix("shard "))
        .and_then(|s| s.split_once('/'))
        .map_or((1, 1), |(k, n)| (k.parse().unwrap(), n.parse().unwrap()));
    if let Some(id) = &f.identity {
        prop_assert_eq!(&id.scene.sha256, &scene);
        prop_assert_eq!(id.shard, shard);
    }
    let reference = &references()[&scene];
    let indices: Vec<usize> = f.rows.iter().map(|r| r.index).collect();
    prop_assert_eq!(&indices, &shard_runs(shard), "{}", path.display());
    for r in &f.rows {
        prop_assert_eq!(bits(r), bits(&reference[r.index]), "{}", path.display());
    }
    Ok(Some((scene, shard)))
}

/// A checkpoint's finished runs: each once, equal to the reference of the scene it records.
fn check_checkpoint(path: &Path) -> Result<usize, TestCaseError> {
    let Ok(text) = std::fs::read_to_string(path) else {
        return Ok(0);
    };
    let Some(stamp) =
        Stamp::from_checkpoint_header(text.lines().take_while(|l| l.starts_with('#')))
    else {
        // Created and locked, header not yet written when the process was killed.
        prop_assert!(text.is_empty(), "{}: {text}", path.display());
        return Ok(0);
    };
    let reference = &references()[&stamp.identity.scene.sha256];
    let mut seen = std::collections::HashSet::new();
    for line in text.split_inclusive('\n').filter(|l| !l.starts_with('#')) {
        if !line.ends_with('\n') {
            continue; // a torn last line (SIGKILL), dropped on resume
        }
        let cells: Vec<&str> = line.trim_end().split(',').collect();
        let index: usize = cells[0].parse().unwrap();
        prop_assert!(
            seen.insert(index),
            "run {} twice in {}",
            index,
            path.display()
        );
        prop_assert!(shard_runs(stamp.identity.shard).contains(&index));
        let r = &reference[index];
        prop_assert_eq!(cells[1], r.inputs[0].as_str());
        for (c, v) in cells[2..].iter().zip(r.values()) {
            prop_assert_eq!(c.parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
    }
    Ok(seen.len())
}

fn temporaries_of(dir: &Path, pid: u32) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(&format!(".shpb-tmp-{pid}-")))
        .collect()
}

/// Runs a sweep, stopped after `stop` if given; checks its exit, its temporary files and, when it
/// resumed, that it kept every run of the checkpoint.
fn run_sweep(
    dir: &Path,
    args: &[String],
    stop: Option<(Stop, u64)>,
    checkpoint: &Path,
) -> Result<(), TestCaseError> {
    let kept = check_checkpoint(checkpoint)?;
    let mut child = Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    if let Some((signal, ms)) = stop {
        std::thread::sleep(Duration::from_millis(ms));
        if child.try_wait().unwrap().is_none() {
            let s = match signal {
                Stop::Int => libc::SIGINT,
                Stop::Term => libc::SIGTERM,
                Stop::Kill => libc::SIGKILL,
            };
            // SAFETY: kill(2) of our own child, not yet reaped.
            unsafe { libc::kill(pid as i32, s) };
        }
    }
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    let code = o.status.code();
    prop_assert!(
        matches!(code, Some(0 | 2 | 130 | 143) | None),
        "{:?}: exit {:?}: {}",
        args,
        code,
        err
    );
    prop_assert!(!err.contains("panicked"), "{}", err);
    if code.is_some() {
        prop_assert!(
            temporaries_of(dir, pid).is_empty(),
            "temporary files left: {}",
            err
        );
    }
    if let Some(rest) = err.split("resuming: ").nth(1) {
        let done: usize = rest.split(' ').next().unwrap().parse().unwrap();
        prop_assert_eq!(done, kept, "runs of the checkpoint kept: {}", err);
    }
    if code == Some(130) || code == Some(143) {
        prop_assert!(err.contains("stopped by SIG"), "{}", err);
    }
    Ok(())
}

fn check_all(dir: &Path) -> Result<(), TestCaseError> {
    for name in ["out.h5", "shard1.h5", "shard2.h5", "merged.h5"] {
        check_file(&dir.join(name))?;
        check_checkpoint(&dir.join(format!("{name}.partial.csv")))?;
    }
    Ok(())
}

fn run_case(ops: &[Op]) -> Result<(), TestCaseError> {
    let dir = tempfile::TempDir::new().unwrap();
    let d = dir.path();
    let mut version = 0;
    std::fs::write(d.join("scene.toml"), scene_text(version)).unwrap();
    for op in ops {
        match op {
            Op::Sweep {
                shard,
                jobs,
                resume,
                force,
                stop,
            } => {
                let args = sweep_args(*shard, *jobs, *resume, *force);
                let out = shard.map_or("out.h5".to_string(), |k| format!("shard{k}.h5"));
                run_sweep(d, &args, *stop, &d.join(format!("{out}.partial.csv")))?;
            }
            Op::Together { resume, force } => {
                let args = sweep_args(None, 1, *resume, *force);
                let cp = d.join("out.h5.partial.csv");
                std::thread::scope(|s| {
                    let a = s.spawn(|| run_sweep(d, &args, None, &cp));
                    let b = s.spawn(|| run_sweep(d, &args, None, &cp));
                    a.join().unwrap().and(b.join().unwrap())
                })?;
            }
            Op::Merge(shards) => {
                let names: Vec<String> = shards.iter().map(|k| format!("shard{k}.h5")).collect();
                let mut args = vec!["merge".to_string()];
                args.extend(names.iter().cloned());
                args.extend(["-o".into(), "merged.h5".into(), "--force".into()]);
                let args: Vec<&str> = args.iter().map(String::as_str).collect();
                let before = std::fs::read(d.join("merged.h5")).ok();
                let o = shpb(d, &args);
                let files: Vec<Holds> = [1, 2]
                    .iter()
                    .map(|k| check_file(&d.join(format!("shard{k}.h5"))))
                    .collect::<Result<_, _>>()?;
                let mut sorted = shards.clone();
                sorted.sort_unstable();
                let whole = sorted == [1, 2]
                    && matches!((&files[0], &files[1]), (Some((a, _)), Some((b, _))) if a == b);
                prop_assert_eq!(
                    o.status.code(),
                    Some(if whole { 0 } else { 2 }),
                    "merge {:?}: {}",
                    shards,
                    String::from_utf8_lossy(&o.stderr)
                );
                if !whole {
                    prop_assert_eq!(std::fs::read(d.join("merged.h5")).ok(), before);
                }
            }
            Op::EditScene => {
                version = 1 - version;
                std::fs::write(d.join("scene.toml"), scene_text(version)).unwrap();
            }
        }
        check_all(d)?;
    }
    // The sweep can always be finished: resumed, or run afresh when what is left is another's.
    let resume = sweep_args(None, 2, true, false);
    let resume: Vec<&str> = resume.iter().map(String::as_str).collect();
    let o = shpb(d, &resume);
    if !o.status.success() {
        prop_assert_eq!(
            o.status.code(),
            Some(2),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let forced = sweep_args(None, 2, false, true);
        let forced: Vec<&str> = forced.iter().map(String::as_str).collect();
        let o = shpb(d, &forced);
        prop_assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let (scene, shard) = check_file(&d.join("out.h5"))?.expect("finished");
    prop_assert_eq!(shard, (1, 1));
    prop_assert_eq!(
        scene,
        shpb::provenance::sha256_hex(scene_text(version).as_bytes())
    );
    prop_assert!(!d.join("out.h5.partial.csv").exists());
    Ok(())
}

fn cases() -> u32 {
    std::env::var("SHPB_PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(8)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(),
        max_shrink_iters: 64,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn interrupted_resumed_concurrent_and_merged_sweeps_never_lose_duplicate_or_mix_runs(
        ops in prop::collection::vec(op(), 1..=7)
    ) {
        run_case(&ops)?;
    }
}
