//! Helpers shared by the subcommands: printing on stdout (a closed pipe is not an error), the
//! `--bars` set-up, the gun's `--pressure`, and input errors of the command line.

use shpb_core::apparatus::Apparatus;
use shpb_input::prelude::*;
use shpb_input::{Error, Result, Validator};
use std::io::Write;
use std::path::Path;

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

/// Names `--bars` and what is allowed when the set-up named on the command line is neither a
/// built-in set-up ([`shpb_input::builtin::SETUPS`]) nor an existing file.
pub fn require_bars(bars: &Path) -> Result<()> {
    let builtin = bars
        .to_str()
        .is_some_and(|name| shpb_input::builtin::setup(name).is_some());
    if !builtin && !bars.is_file() {
        return Err(input_err(
            "command line",
            "--bars",
            format!(
                "cannot read {}: not a built-in set-up and no such file",
                bars.display()
            ),
            format!(
                "a built-in set-up ({}) or a bar set-up .toml file such as bars/authors.toml",
                shpb_input::builtin::setup_names()
            ),
        ));
    }
    Ok(())
}

/// The bar set-up named by `--bars`: a built-in set-up or a set-up file (relative to the current
/// directory).
pub fn load_apparatus(bars: &Path) -> Result<Apparatus> {
    require_bars(bars)?;
    match bars.to_str() {
        Some(reference) => Apparatus::resolve(reference, Path::new(".")),
        None => Apparatus::from_file(bars),
    }
}

/// The `--pressure` option read and checked against the set-up's gun: (gauge pressure Pa,
/// striker velocity m/s).
pub fn gun_shot(apparatus: &Apparatus, pressure: &str) -> Result<(f64, f64)> {
    let p = shpb_input::units::cli_pressure(pressure)?;
    let v = apparatus
        .striker_velocity_m_s(p)
        .map_err(Validator::new("command line").core("--pressure"))?;
    Ok((p, v))
}

/// Writes a study's summary `table` as CSV and its HDF5 (atomically; an existing file is
/// replaced only with `replace`), the HDF5 stamped with the sweep's `identity`.
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
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = output {
        shpb_study::file::write_sweep_hdf5(p, replace, scene_text, spec, identity, keys, rows)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}
