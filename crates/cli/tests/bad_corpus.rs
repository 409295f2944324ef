//! The shared bad-input corpus of command cases (`tests/corpus/bad/cases/*.toml`, format in
//! `tests/corpus/bad/README.md`): each `[[case]]` runs `shpb ARGS` in a fresh temporary working
//! directory (after making its `files` there) and must exit with its `exit` code, print a
//! message containing its `stderr` fragment (`shpb: error: ` first for exit codes 1–5), print
//! nothing on stdout unless stated, and, when asked, leave nothing behind. Every failing case
//! is reported at once, by name. The case files are validated strictly (unknown keys, wrong
//! types, duplicate names fail). `SHPB_CORPUS_FILE=<area>` runs only `cases/<area>.toml`.
//! The Python side (`python/tests/test_corpus.py`) runs each case's `python` expression.

mod common;

use common::repo;
use std::collections::{BTreeMap, BTreeSet};
use std::ffi::{OsStr, OsString};
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use tempfile::TempDir;

/// Issue 42's acceptance: the corpus (the scenes `shpb run` refuses plus every command case)
/// holds at least this many cases.
const MIN_TOTAL: usize = 48;

/// A case that runs longer than this is stopped and fails (a bad input is refused up front).
const TIMEOUT: Duration = Duration::from_secs(120);

/// The keys a `[[case]]` may have (README.md of the corpus).
const KEYS: &[&str] = &[
    "name",
    "category",
    "args",
    "exit",
    "stderr",
    "stdout",
    "stdout_empty",
    "files",
    "env",
    "tmp_empty_after",
    "python",
    "python_raises",
    "python_message",
];

/// The bytes `{nonutf8}` stands for: not valid UTF-8 in any file name.
const NONUTF8: &[u8] = b"\xff\xfe";

/// One validated case of a case file.
#[derive(Debug)]
struct Case {
    file: String,
    name: String,
    args: Option<Vec<String>>,
    exit: i32,
    stderr: String,
    stdout: Option<String>,
    stdout_empty: bool,
    files: Vec<(String, String)>,
    env: Vec<(String, String)>,
    tmp_empty_after: bool,
}

/// The corpus directory and the case files in it, sorted.
fn case_files() -> Vec<PathBuf> {
    let dir = repo().join("tests/corpus/bad/cases");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

/// The scenes of `tests/corpus/bad/*.toml` (run by `bad_inputs.rs`), counted in the total.
fn scene_count() -> usize {
    std::fs::read_dir(repo().join("tests/corpus/bad"))
        .unwrap()
        .filter(|e| {
            let p = e.as_ref().unwrap().path();
            p.is_file() && p.extension().is_some_and(|e| e == "toml")
        })
        .count()
}

/// Whether `name` is kebab-case: lower-case letters and digits in words joined by `-`.
fn kebab(name: &str) -> bool {
    !name.is_empty()
        && name.split('-').all(|w| {
            !w.is_empty()
                && w.bytes()
                    .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit())
        })
}

/// A string-to-string table (`files`, `env`) in its written order.
fn string_table(v: &toml::Value, key: &str) -> Result<Vec<(String, String)>, String> {
    let t = v
        .as_table()
        .ok_or_else(|| format!("`{key}` must be a table of strings"))?;
    t.iter()
        .map(|(k, v)| {
            v.as_str()
                .map(|s| (k.clone(), s.to_string()))
                .ok_or_else(|| format!("`{key}.{k}` must be a string"))
        })
        .collect()
}

/// Validates one `[[case]]` table (every key known and of its type, the required ones there).
fn parse_case(file: &str, t: &toml::Table) -> Result<Case, String> {
    if let Some(k) = t.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return Err(format!("unknown key `{k}` (allowed: {})", KEYS.join(", ")));
    }
    let string = |k: &str| -> Result<Option<String>, String> {
        t.get(k)
            .map(|v| {
                v.as_str()
                    .map(str::to_string)
                    .ok_or_else(|| format!("`{k}` must be a string"))
            })
            .transpose()
    };
    let boolean = |k: &str| -> Result<Option<bool>, String> {
        t.get(k)
            .map(|v| {
                v.as_bool()
                    .ok_or_else(|| format!("`{k}` must be true or false"))
            })
            .transpose()
    };
    let integer = |k: &str| -> Result<Option<i64>, String> {
        t.get(k)
            .map(|v| {
                v.as_integer()
                    .ok_or_else(|| format!("`{k}` must be an integer"))
            })
            .transpose()
    };
    let name = string("name")?.ok_or("no `name`")?;
    if !kebab(&name) {
        return Err(format!("name `{name}` is not kebab-case"));
    }
    let category = integer("category")?.ok_or("no `category`")?;
    if !(0..=8).contains(&category) {
        return Err(format!("category {category} (allowed: 0-8)"));
    }
    let args = t
        .get("args")
        .map(|v| {
            let a = v.as_array().ok_or("`args` must be an array of strings")?;
            if a.is_empty() {
                return Err("`args` is empty".to_string());
            }
            a.iter()
                .map(|x| {
                    x.as_str()
                        .map(str::to_string)
                        .ok_or_else(|| "`args` must be an array of strings".to_string())
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()?;
    let python = string("python")?;
    let python_raises = string("python_raises")?;
    let python_message = string("python_message")?;
    if python.is_some() != python_raises.is_some() {
        return Err("`python` and `python_raises` go together".into());
    }
    if python_message.is_some() && python.is_none() {
        return Err("`python_message` without `python`".into());
    }
    let exit = integer("exit")?;
    let stderr = string("stderr")?;
    let (exit, stderr) = match (&args, exit, stderr) {
        (Some(_), Some(x), Some(s)) => (x, s),
        (Some(_), _, _) => return Err("a case with `args` needs `exit` and `stderr`".into()),
        (None, x, s) => {
            if python.is_none() {
                return Err("a case needs `args` or `python`".into());
            }
            if x.is_some() {
                return Err("`exit` without `args`".into());
            }
            if s.is_none() && python_message.is_none() {
                return Err("a Python-only case needs `stderr` or `python_message`".into());
            }
            for k in ["stdout", "stdout_empty", "env", "tmp_empty_after"] {
                if t.contains_key(k) {
                    return Err(format!("`{k}` without `args`"));
                }
            }
            (0, s.unwrap_or_default())
        }
    };
    if !(0..=255).contains(&exit) || exit == 101 {
        return Err(format!(
            "exit {exit} (allowed: 0-255 but not 101, a panic is never expected)"
        ));
    }
    if args.is_some() && stderr.is_empty() {
        return Err("`stderr` is empty: give a fragment of the message".into());
    }
    let stdout = string("stdout")?;
    let stdout_empty = boolean("stdout_empty")?.unwrap_or(exit != 0);
    if stdout_empty && stdout.is_some() {
        return Err("`stdout` with `stdout_empty = true`".into());
    }
    let files = t
        .get("files")
        .map(|v| string_table(v, "files"))
        .transpose()?
        .unwrap_or_default();
    for (k, v) in &files {
        if k.ends_with('/') && !v.is_empty() {
            return Err(format!(
                "files.\"{k}\": a directory (ends in /) has no text"
            ));
        }
        if k.starts_with('/') || k.split('/').any(|c| c == "..") {
            return Err(format!("files.\"{k}\": must stay inside {{tmp}}"));
        }
    }
    let env = t
        .get("env")
        .map(|v| string_table(v, "env"))
        .transpose()?
        .unwrap_or_default();
    Ok(Case {
        file: file.to_string(),
        name,
        args,
        exit: exit as i32,
        stderr,
        stdout,
        stdout_empty,
        files,
        env,
        tmp_empty_after: boolean("tmp_empty_after")?.unwrap_or(false),
    })
}

/// Every case of every case file, or the problems found in them.
fn load() -> (Vec<Case>, Vec<String>) {
    let mut cases = Vec::new();
    let mut problems = Vec::new();
    let mut seen: BTreeMap<String, String> = BTreeMap::new();
    for path in case_files() {
        let file = path.file_stem().unwrap().to_string_lossy().into_owned();
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) => {
                problems.push(format!("{}: {e}", path.display()));
                continue;
            }
        };
        let doc: toml::Table = match toml::from_str(&text) {
            Ok(d) => d,
            Err(e) => {
                problems.push(format!("{}: {e}", path.display()));
                continue;
            }
        };
        if let Some(k) = doc.keys().find(|k| *k != "case") {
            problems.push(format!(
                "{}: unknown top-level key `{k}` (only [[case]])",
                path.display()
            ));
        }
        let Some(list) = doc.get("case").and_then(|c| c.as_array()) else {
            problems.push(format!("{}: no [[case]] array", path.display()));
            continue;
        };
        for (i, c) in list.iter().enumerate() {
            let Some(t) = c.as_table() else {
                problems.push(format!("{file}.toml case {}: not a table", i + 1));
                continue;
            };
            match parse_case(&file, t) {
                Ok(case) => {
                    if let Some(other) = seen.insert(case.name.clone(), file.clone()) {
                        problems.push(format!(
                            "{file}.toml: duplicate case name `{}` (also in {other}.toml)",
                            case.name
                        ));
                    }
                    cases.push(case);
                }
                Err(e) => {
                    let name = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
                    problems.push(format!("{file}.toml case {} `{name}`: {e}", i + 1));
                }
            }
        }
    }
    (cases, problems)
}

/// Replaces `{corpus}`, `{data}`, `{repo}`, `{tmp}` and `{nonutf8}` (raw bytes) in `s`.
fn substitute(s: &str, tmp: &Path) -> OsString {
    let repo = repo().canonicalize().unwrap();
    let text = s
        .replace(
            "{corpus}",
            &repo.join("tests/corpus/bad").display().to_string(),
        )
        .replace("{data}", &repo.join("tests/data").display().to_string())
        .replace("{repo}", &repo.display().to_string())
        .replace("{tmp}", &tmp.display().to_string());
    let mut bytes = Vec::new();
    let mut parts = text.split("{nonutf8}");
    bytes.extend_from_slice(parts.next().unwrap().as_bytes());
    for p in parts {
        bytes.extend_from_slice(NONUTF8);
        bytes.extend_from_slice(p.as_bytes());
    }
    OsString::from_vec(bytes)
}

/// Every path under `dir`, relative to it (directories too).
fn tree(dir: &Path) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            out.insert(p.strip_prefix(dir).unwrap().to_path_buf());
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                stack.push(p);
            }
        }
    }
    out
}

/// Runs one case; `Err` says what went wrong.
fn check(case: &Case) -> Result<(), String> {
    let args = case.args.as_ref().expect("a CLI case");
    let tmp = TempDir::new().unwrap();
    let work = tmp.path().canonicalize().unwrap();
    let capture = TempDir::new().unwrap();
    let mut made = BTreeSet::new();
    for (name, text) in &case.files {
        let rel = PathBuf::from(substitute(name, &work));
        let path = work.join(&rel);
        for a in rel.ancestors().skip(1) {
            if !a.as_os_str().is_empty() {
                made.insert(a.to_path_buf());
            }
        }
        made.insert(rel.clone());
        if name.ends_with('/') {
            std::fs::create_dir_all(&path).unwrap();
        } else {
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).unwrap();
            }
            std::fs::write(&path, substitute(text, &work).as_bytes()).unwrap();
        }
    }
    let out_path = capture.path().join("stdout");
    let err_path = capture.path().join("stderr");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_shpb"));
    cmd.current_dir(&work)
        .args(args.iter().map(|a| substitute(a, &work)))
        .env_remove("SHPB_MEMORY_LIMIT")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap());
    for (k, v) in &case.env {
        cmd.env(k, substitute(v, &work));
    }
    let start = Instant::now();
    let mut child = cmd.spawn().map_err(|e| format!("cannot start shpb: {e}"))?;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("still running after {TIMEOUT:?} (stopped)"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stdout = String::from_utf8_lossy(&std::fs::read(&out_path).unwrap()).into_owned();
    let stderr = String::from_utf8_lossy(&std::fs::read(&err_path).unwrap()).into_owned();
    let mut wrong = Vec::new();
    if status.code() != Some(case.exit) {
        wrong.push(format!("exit {:?}, expected {}", status.code(), case.exit));
    }
    if !stderr.contains(&case.stderr) {
        wrong.push(format!("stderr lacks `{}`", case.stderr));
    }
    if (1..=5).contains(&case.exit) && !stderr.lines().any(|l| l.starts_with("shpb: error: ")) {
        wrong.push("no `shpb: error: ` line on stderr".into());
    }
    if case.stdout_empty && !stdout.is_empty() {
        let head: String = stdout.chars().take(200).collect();
        wrong.push(format!("stdout not empty: {head:?}"));
    }
    if let Some(f) = &case.stdout
        && !stdout.contains(f.as_str())
    {
        wrong.push(format!("stdout lacks `{f}`"));
    }
    if case.tmp_empty_after {
        let extra: Vec<String> = tree(&work)
            .difference(&made)
            .map(|p| p.display().to_string())
            .collect();
        if !extra.is_empty() {
            wrong.push(format!("left in {{tmp}}: {}", extra.join(", ")));
        }
    }
    if wrong.is_empty() {
        Ok(())
    } else {
        let shown: Vec<String> = args
            .iter()
            .map(|a| substitute(a, &work).to_string_lossy().into_owned())
            .collect();
        Err(format!(
            "{}\n    shpb {}\n    stderr: {}",
            wrong.join("; "),
            shown.join(" "),
            stderr.trim_end().replace('\n', "\n            ")
        ))
    }
}

#[test]
fn every_case_of_the_bad_input_corpus_is_handled_as_it_expects() {
    let (cases, mut problems) = load();
    let only = std::env::var("SHPB_CORPUS_FILE").ok();
    if let Some(area) = &only {
        assert!(
            cases.iter().any(|c| &c.file == area) || problems.iter().any(|p| p.contains(area)),
            "SHPB_CORPUS_FILE={area}: no tests/corpus/bad/cases/{area}.toml with cases"
        );
    }
    let mut ran = 0;
    for case in &cases {
        if only.as_ref().is_some_and(|a| a != &case.file) || case.args.is_none() {
            continue;
        }
        let start = Instant::now();
        if let Err(e) = check(case) {
            problems.push(format!("{}.toml `{}`: {e}", case.file, case.name));
        }
        let took = start.elapsed();
        if took > Duration::from_secs(5) {
            eprintln!("slow case `{}`: {took:.1?}", case.name);
        }
        ran += 1;
    }
    let scenes = scene_count();
    let total = scenes + cases.len();
    println!(
        "bad-input corpus: {total} cases ({scenes} scenes refused by `shpb run`, {} command \
         and Python cases in {} files); ran {ran} command cases{}",
        cases.len(),
        case_files().len(),
        only.as_ref()
            .map(|a| format!(" of {a}.toml"))
            .unwrap_or_default()
    );
    assert!(
        problems.is_empty(),
        "{} of the bad-input corpus failed:\n{}",
        problems.len(),
        problems.join("\n")
    );
    if only.is_none() {
        assert!(
            total >= MIN_TOTAL,
            "the bad-input corpus has {total} cases, issue 42 asks for at least {MIN_TOTAL}"
        );
    }
}

#[test]
fn substitution_makes_a_name_that_is_not_utf8() {
    let s = substitute("{tmp}/a{nonutf8}.csv", Path::new("/t"));
    assert!(s.to_str().is_none());
    assert_eq!(s.as_bytes(), b"/t/a\xff\xfe.csv");
    assert_eq!(
        OsStr::new("x"),
        substitute("x", Path::new("/t")).as_os_str()
    );
}

#[test]
fn the_case_validation_refuses_unknown_keys_and_bad_values() {
    let parse = |s: &str| parse_case("t", &toml::from_str::<toml::Table>(s).unwrap());
    let ok = "name = \"a-b\"\ncategory = 0\nargs = [\"x\"]\nexit = 2\nstderr = \"m\"\n";
    assert!(parse(ok).is_ok());
    assert!(
        parse(&format!("{ok}colour = 1\n"))
            .unwrap_err()
            .contains("unknown key `colour`")
    );
    assert!(
        parse(&ok.replace("a-b", "A_b"))
            .unwrap_err()
            .contains("kebab")
    );
    assert!(
        parse(&ok.replace("category = 0", "category = 9"))
            .unwrap_err()
            .contains("category")
    );
    assert!(
        parse(&ok.replace("exit = 2", "exit = 101"))
            .unwrap_err()
            .contains("panic")
    );
    assert!(
        parse(&ok.replace("exit = 2", "exit = \"2\""))
            .unwrap_err()
            .contains("integer")
    );
    assert!(
        parse(&format!("{ok}python = \"shpb.run('x')\"\n"))
            .unwrap_err()
            .contains("go together")
    );
    assert!(
        parse(
            "name = \"p\"\ncategory = 0\npython = \"1\"\npython_raises = \"E\"\nstderr = \"m\"\n"
        )
        .is_ok()
    );
}
