//! The SLURM recipe of the README (`examples/slurm/sweep.sbatch`, `examples/slurm/submit.sh`),
//! run through bash as SLURM would run it, with stand-ins for `shpb` and `sbatch` on the PATH:
//! for the file's own `--array` range and for 0-based and one-task arrays, the tasks' `--shard k/n`
//! cover every run of the sweep exactly once with distinct outputs; a stepped array is refused;
//! `submit.sh` queues the merge after the array with exactly the files the tasks write; and the
//! whole recipe, run for real (at the `fast` preset), merges into the complete sweep. (That the
//! merged shards equal the unsharded sweep is `tests/sweep.rs`.)

mod common;
use common::repo;
use shpb::sweep::{parse_axes, parse_shard, run_count, shard_points};
use std::collections::BTreeMap;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

const SBATCH: &str = "examples/slurm/sweep.sbatch";
const SUBMIT: &str = "examples/slurm/submit.sh";

/// Writes an executable script `name` in `dir`.
fn script(dir: &Path, name: &str, body: &str) {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// A PATH with `bin` first.
fn path_with(bin: &Path) -> String {
    format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    )
}

/// The `#SBATCH --array=A-B` range of the batch file.
fn array_range() -> (usize, usize) {
    let text = std::fs::read_to_string(repo().join(SBATCH)).unwrap();
    let range = text
        .lines()
        .find_map(|l| l.strip_prefix("#SBATCH --array="))
        .expect("an #SBATCH --array= line");
    let (a, b) = range.trim().split_once('-').expect("A-B");
    (a.parse().unwrap(), b.parse().unwrap())
}

/// The `--set` specifications of the batch file's sweep.
fn sbatch_sets() -> Vec<String> {
    let text = std::fs::read_to_string(repo().join(SBATCH)).unwrap();
    text.split("--set ")
        .skip(1)
        .map(|s| s.split_whitespace().next().unwrap().to_string())
        .collect()
}

/// Runs task `id` of an array `min..=max` of `count` tasks through bash, as SLURM would, with
/// `bin` first on the PATH, `OUT=out` and `LOG_DIR=logs` (for the recording stand-in); returns
/// the exit status.
fn run_task(
    bin: &Path,
    out: &Path,
    logs: &Path,
    (id, min, max, count): (usize, usize, usize, usize),
) -> std::process::ExitStatus {
    Command::new("bash")
        .arg(repo().join(SBATCH))
        .current_dir(repo())
        .env("PATH", path_with(bin))
        .env("OUT", out)
        .env("LOG_DIR", logs)
        .env("SLURM_ARRAY_TASK_ID", id.to_string())
        .env("SLURM_ARRAY_TASK_MIN", min.to_string())
        .env("SLURM_ARRAY_TASK_MAX", max.to_string())
        .env("SLURM_ARRAY_TASK_COUNT", count.to_string())
        .env("SLURM_CPUS_PER_TASK", "1")
        .stdout(std::process::Stdio::null())
        .status()
        .unwrap()
}

/// The arguments a task gave `shpb` (recorded one per line by the stand-in).
fn recorded(log: &Path) -> Vec<String> {
    std::fs::read_to_string(log)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

fn value_of<'a>(args: &'a [String], flag: &str) -> Vec<&'a str> {
    args.windows(2)
        .filter(|w| w[0] == flag)
        .map(|w| w[1].as_str())
        .collect()
}

#[test]
fn array_tasks_cover_every_run_exactly_once() {
    let dir = tempfile::TempDir::new().unwrap();
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    // The stand-in records its arguments, one per line, in $LOG_DIR/<task id>.
    script(
        &bin,
        "shpb",
        "#!/bin/bash\nprintf '%s\\n' \"$@\" > \"$LOG_DIR/$SLURM_ARRAY_TASK_ID\"\n",
    );
    let (a, b) = array_range();
    assert_eq!(a, 1, "the batch file's array is 1-based, like the shards");
    for (min, max) in [(a, b), (0, 3), (1, 7), (0, 0), (5, 6)] {
        let logs = dir.path().join(format!("logs-{min}-{max}"));
        std::fs::create_dir(&logs).unwrap();
        let count = max - min + 1;
        let out = dir.path().join("study");
        let mut shards = BTreeMap::new();
        let mut axes = None;
        for id in min..=max {
            let status = run_task(&bin, &out, &logs, (id, min, max, count));
            assert!(status.success(), "task {id} of {min}-{max}");
            let args = recorded(&logs.join(id.to_string()));
            assert_eq!(args[0], "sweep");
            let (k, n) = parse_shard(value_of(&args, "--shard")[0]).unwrap();
            assert_eq!(n, count, "task {id} of {min}-{max}");
            let output = value_of(&args, "-o")[0].to_string();
            assert!(args.iter().any(|a| a == "--resume"));
            let sets: Vec<String> = value_of(&args, "--set")
                .into_iter()
                .map(String::from)
                .collect();
            let these = parse_axes(&sets).unwrap();
            if let Some(first) = &axes {
                assert_eq!(first, &these, "every task runs the same sweep");
            }
            assert_eq!(these, parse_axes(&sbatch_sets()).unwrap());
            axes = Some(these);
            assert!(
                shards.insert(k, output).is_none(),
                "shard {k} twice in {min}-{max}"
            );
        }
        // Shards 1..=n, each once, with distinct outputs ($OUT-k.h5).
        assert_eq!(
            shards.keys().copied().collect::<Vec<_>>(),
            (1..=count).collect::<Vec<_>>()
        );
        for (k, o) in &shards {
            assert_eq!(o, &format!("{}-{k}.h5", out.display()));
        }
        // Every run of the sweep in exactly one shard.
        let axes = axes.unwrap();
        let total = run_count(&axes).unwrap() as usize;
        let mut seen = vec![0u32; total];
        for &k in shards.keys() {
            for p in shard_points(&axes, k, count) {
                seen[p.index] += 1;
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "{min}-{max}: {seen:?}");
    }
    // A stepped array (0-6:2: ids 0, 2, 4, 6, count 4) is refused before shpb runs.
    let logs = dir.path().join("logs-stepped");
    std::fs::create_dir(&logs).unwrap();
    let status = run_task(&bin, &dir.path().join("study"), &logs, (2, 0, 6, 4));
    assert_eq!(status.code(), Some(2));
    assert!(!logs.join("2").exists());
}

/// `submit.sh` queues the array with `--array=1-SHARDS` and the merge after it
/// (`afterok:<array id>`) over exactly the files the tasks write; then the recipe runs for real
/// (tasks through bash with the real `shpb`, at `fast` to keep the test short) and the merge
/// holds every run of the sweep once.
#[test]
fn submit_queues_the_merge_of_exactly_the_shards_and_the_recipe_runs() {
    let dir = tempfile::TempDir::new().unwrap();
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    let log = dir.path().join("sbatch.log");
    // The stand-in for sbatch records each call's arguments (one per line, calls separated by a
    // `--` line) and answers with a job id and cluster, as `--parsable` does.
    script(
        &bin,
        "sbatch",
        &format!(
            "#!/bin/bash\nn=$(grep -c '^--$' {log} 2>/dev/null || true)\nprintf '%s\\n' \"$@\" \
             -- >> {log}\necho \"$((4000 + n));cluster\"\n",
            log = log.display()
        ),
    );
    let shards = 3usize;
    let out = dir.path().join("study");
    let status = Command::new("bash")
        .arg(repo().join(SUBMIT))
        .current_dir(repo())
        .env("PATH", path_with(&bin))
        .env("SHARDS", shards.to_string())
        .env("OUT", &out)
        .status()
        .unwrap();
    assert!(status.success());
    let text = std::fs::read_to_string(&log).unwrap();
    let calls: Vec<Vec<&str>> = text
        .split("--\n")
        .filter(|c| !c.is_empty())
        .map(|c| c.lines().collect())
        .collect();
    assert_eq!(calls.len(), 2, "{text}");
    assert!(calls[0].contains(&"--array=1-3"), "{:?}", calls[0]);
    assert!(calls[0].last().unwrap().ends_with("sweep.sbatch"));
    assert!(
        calls[1].contains(&"--dependency=afterok:4000"),
        "{:?}",
        calls[1]
    );
    let wrap = calls[1]
        .iter()
        .find_map(|a| a.strip_prefix("--wrap="))
        .expect("--wrap");
    let o = out.display();
    assert_eq!(
        wrap,
        format!("shpb merge {o}-1.h5 {o}-2.h5 {o}-3.h5 -o {o}.h5 --csv {o}.csv")
    );

    // The recipe for real: the tasks of --array=1-3, then the merge command, through bash.
    let real = PathBuf::from(env!("CARGO_BIN_EXE_shpb"));
    script(
        &bin,
        "shpb",
        &format!(
            "#!/bin/bash\nif [ \"$1\" = sweep ]; then exec {r} \"$@\" --set fidelity=fast; fi\n\
             exec {r} \"$@\"\n",
            r = real.display()
        ),
    );
    for id in 1..=shards {
        let status = run_task(&bin, &out, dir.path(), (id, 1, shards, shards));
        assert!(status.success(), "task {id}");
    }
    let merged = Command::new("bash")
        .args(["-c", wrap])
        .current_dir(repo())
        .env("PATH", path_with(&bin))
        .output()
        .unwrap();
    assert!(
        merged.status.success(),
        "{}",
        String::from_utf8_lossy(&merged.stderr)
    );
    let csv = std::fs::read_to_string(format!("{o}.csv")).unwrap();
    let runs: Vec<usize> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    let total = run_count(&parse_axes(&sbatch_sets()).unwrap()).unwrap() as usize;
    assert_eq!(runs, (0..total).collect::<Vec<_>>());
}
