//! Helpers shared by the subcommands: printing on stdout (a closed pipe is not an error), the
//! `--bars` set-up, the gun's `--pressure`, and input errors of the command line.

use shpb_input::{Error, Result};
use std::io::Write;
use std::path::Path;

/// How results and messages are shown (`--quiet`, `--json`): set once by the command line.
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
static JSON: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Sets the output mode: `quiet` drops the result table and the `wrote` lines (warnings and
/// errors still go to stderr); `json` prints the result as one JSON object on stdout instead.
pub fn set_output_mode(quiet: bool, json: bool) {
    QUIET.store(quiet, std::sync::atomic::Ordering::Relaxed);
    JSON.store(json, std::sync::atomic::Ordering::Relaxed);
}

/// Whether `--json` was given.
pub fn json_mode() -> bool {
    JSON.load(std::sync::atomic::Ordering::Relaxed)
}

/// Whether `--quiet` was given.
pub fn quiet_mode() -> bool {
    QUIET.load(std::sync::atomic::Ordering::Relaxed)
}

/// Reports a file written (`wrote PATH` on stderr), unless quiet or the file went to stdout.
pub fn wrote(path: &Path) {
    if !quiet_mode() && !shpb_output::atomic::is_stdout(path) {
        eprintln!("wrote {}", path.display());
    }
}

/// A warning on stderr (also with `--quiet`).
pub fn warn(message: &str) {
    eprintln!("shpb: warning: {message}");
}

/// Prints a command's result: `json()` as one JSON object with `--json`, else `text` (nothing
/// with `--quiet`).
pub fn report(text: &str, json: impl FnOnce() -> serde_json::Value) -> Result<()> {
    if json_mode() {
        print(&format!("{}\n", json()))
    } else if quiet_mode() {
        Ok(())
    } else {
        print(text)
    }
}

/// A progress line with an ETA on stderr for a run that takes longer than two seconds, shown
/// only on a terminal and not with `--quiet` or `--json`. `SHPB_PROGRESS=always` prints it as
/// plain lines at once, anywhere (for logs and tests).
pub struct ProgressLine {
    start: std::time::Instant,
    label: String,
    bar: Option<indicatif::ProgressBar>,
    terminal: bool,
    plain: bool,
    last_decile: i64,
}

impl ProgressLine {
    /// A progress line labelled `label` (e.g. the scene file).
    pub fn new(label: &str) -> ProgressLine {
        use std::io::IsTerminal;
        ProgressLine {
            start: std::time::Instant::now(),
            label: label.to_string(),
            bar: None,
            terminal: std::io::stderr().is_terminal() && !quiet_mode() && !json_mode(),
            plain: std::env::var("SHPB_PROGRESS").is_ok_and(|v| v == "always"),
            last_decile: -1,
        }
    }

    /// Shows `fraction` done (0 to 1).
    pub fn update(&mut self, fraction: f64) {
        let elapsed = self.start.elapsed();
        if self.plain {
            let decile = (fraction * 10.0).floor() as i64;
            if decile > self.last_decile && fraction > 0.0 {
                self.last_decile = decile;
                let eta = elapsed.as_secs_f64() * (1.0 - fraction) / fraction;
                eprintln!(
                    "{}: {:.0} % done, elapsed {:.1} s, ETA {:.1} s",
                    self.label,
                    100.0 * fraction,
                    elapsed.as_secs_f64(),
                    eta
                );
            }
            return;
        }
        if !self.terminal || elapsed < std::time::Duration::from_secs(2) {
            return;
        }
        let bar = self.bar.get_or_insert_with(|| {
            let bar = indicatif::ProgressBar::new(1000);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "{msg} [{bar:40}] {percent:>3}% elapsed {elapsed} ETA {eta}",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar.set_message(self.label.clone());
            bar
        });
        bar.set_position((fraction.clamp(0.0, 1.0) * 1000.0) as u64);
    }

    /// Removes the line (the result follows).
    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}

/// The command line of this process as text (a name that is not UTF-8 shown with U+FFFD).
pub fn command_line() -> String {
    std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(" ")
}

/// A number for JSON, which has no NaN or infinity: those become null.
pub fn finite(v: f64) -> serde_json::Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        serde_json::Value::Null
    }
}

/// Refuses two things on stdout at once: `--json` or the result table and an output `-`.
pub fn stdout_once(outputs: &[Option<&Path>]) -> Result<bool> {
    let to_stdout = outputs
        .iter()
        .flatten()
        .filter(|p| shpb_output::atomic::is_stdout(p))
        .count();
    if to_stdout > 1 || (to_stdout == 1 && json_mode()) {
        return Err(input_err(
            "command line",
            "-",
            "standard output can take only one of: --json, one output `-`",
            "at most one output `-`, and not with --json",
        ));
    }
    Ok(to_stdout == 1)
}

/// The output plan of a command ([`OutputPlan`]): every output (`(path, flag, extensions)`)
/// checked before anything runs, at most one on standard output and none there with `--json`.
/// A command that has an output `-` prints nothing else on stdout ([`OutputPlan::to_stdout`]).
pub fn plan(force: bool, outputs: &[(Option<&Path>, &str, &[&str])]) -> Result<OutputPlan> {
    let plan = OutputPlan::new(force, outputs)?;
    plan.refuse_stdout_with(json_mode().then_some("--json"))?;
    Ok(plan)
}

/// Writes the outputs of `plan` through `write`, all or none, and prints a `wrote` line for each
/// once all are in place.
pub fn write_all(plan: &OutputPlan, write: impl FnOnce() -> Result<()>) -> Result<()> {
    plan.write(write, wrote)
}

/// [`report`], unless an output goes to standard output (which then holds only that file).
pub fn report_unless_stdout(
    plan: &OutputPlan,
    text: &str,
    json: impl FnOnce() -> serde_json::Value,
) -> Result<()> {
    if plan.to_stdout() {
        return Ok(());
    }
    report(text, json)
}

pub use shpb_output::atomic::free_space;
pub use shpb_output::plan::OutputPlan;
pub use shpb_study::api::DEFAULT_BARS;

/// An input error (exit code 2) naming the file (or "command line"), the key, the problem and
/// what is allowed.
pub fn input_err(
    file: &str,
    key: &str,
    problem: impl Into<String>,
    allowed: impl Into<String>,
) -> Error {
    Error::Input {
        file: file.to_string(),
        key: key.to_string(),
        problem: problem.into(),
        allowed: allowed.into(),
    }
}

/// The result of writing to stdout: a closed pipe (`shpb … | head`) is not an error.
pub fn stdout_result(written: std::io::Result<()>) -> Result<()> {
    match written {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::io(Path::new("stdout"), e))
        }
        _ => Ok(()),
    }
}

/// Prints `text` on stdout as it is and flushes; a closed pipe is not an error.
pub fn print(text: &str) -> Result<()> {
    let stdout = std::io::stdout();
    let mut w = stdout.lock();
    stdout_result(w.write_all(text.as_bytes()).and_then(|_| w.flush()))
}

/// Prints a line on stdout; a closed pipe (`shpb … | head`) is not an error.
pub fn say(line: &str) -> Result<()> {
    print(&format!("{line}\n"))
}

pub use shpb_study::api::{gun_shot, load_apparatus, require_bars};

/// Writes a study's summary `table` as CSV and its HDF5 (atomically; an existing file is
/// replaced only with `replace`), the HDF5 stamped with the sweep's `identity`; called inside
/// the command's [`write_all`], which reports the files.
#[allow(clippy::too_many_arguments)]
pub fn write_study(
    scene_text: &str,
    spec: &[String],
    identity: Option<&shpb_study::identity::Identity>,
    keys: &[String],
    rows: &[shpb_study::sweep::RunSummary],
    table: &str,
    (output, csv): (Option<&Path>, Option<&Path>),
    replace: bool,
) -> Result<()> {
    if let Some(p) = csv {
        shpb_output::io::write_text_atomically(p, replace, table)?;
    }
    if let Some(p) = output {
        shpb_study::file::write_sweep_hdf5(p, replace, scene_text, spec, identity, keys, rows)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_larger_than_the_free_space_together_are_refused_with_both_numbers() {
        let dir = std::env::temp_dir();
        let (out, csv) = (dir.join("run.h5"), dir.join("run.csv"));
        let free = free_space(&dir).expect("statvfs of the temporary directory") as f64;
        let both = OutputPlan::new(
            true,
            &[(Some(&out), "--output", &[]), (Some(&csv), "--csv", &[])],
        )
        .unwrap();
        assert!(
            both.check_space(&[Some(0.3 * free), Some(0.3 * free)])
                .is_ok()
        );
        // Each fits alone, not both together.
        let e = both
            .check_space(&[Some(0.6 * free + 1e6), Some(0.6 * free + 1e6)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("--output") && e.contains("free there"), "{e}");
        // stdout takes no disk space.
        let dash = OutputPlan::new(true, &[(Some(Path::new("-")), "--csv", &[])]).unwrap();
        assert!(dash.check_space(&[Some(1e30)]).is_ok());
    }
}
