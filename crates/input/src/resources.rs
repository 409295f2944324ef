//! Whether a run can finish on this machine: the core's estimate of a scene
//! ([`shpb_core::estimate::RunEstimate`]) against the machine's [`Limits`]. Every scene read from
//! a file is checked ([`crate::scene::SceneFile::from_toml`]) before anything is allocated for
//! its run, so a run that cannot finish is refused (exit code 2) with its estimate and the limit,
//! instead of growing until an allocation fails.
//!
//! The limits:
//!
//! * **Memory**: the estimate's `memory_bytes` must not exceed the memory available, read from
//!   `MemAvailable` in `/proc/meminfo` (Linux: free memory plus what the kernel can reclaim
//!   without swapping). Where that file cannot be read the limit is
//!   [`FALLBACK_MEMORY_BYTES`] (4 GB). The environment variable `SHPB_MEMORY_LIMIT` (bytes, e.g.
//!   `2e9`) replaces both, e.g. to share a machine between parallel jobs.
//! * **Steps**: at most [`MAX_STEPS`] time steps (1e10: about an hour of the two-sphere
//!   stepper) and [`MAX_UPDATES`] node updates (steps × bar nodes, 1e12: about an hour of a bar
//!   run); a run beyond them does not fit in a working day, whatever its memory.

use crate::error::{Error, Result};
use shpb_core::error::format_si;
use shpb_core::estimate::RunEstimate;
use shpb_core::scene::Params;

/// The most time steps a run may take (module docs).
pub const MAX_STEPS: f64 = 1e10;

/// The most node updates (steps × degrees of freedom) a run may take (module docs).
pub const MAX_UPDATES: f64 = 1e12;

/// The memory limit where `/proc/meminfo` cannot be read (not Linux), bytes.
pub const FALLBACK_MEMORY_BYTES: f64 = 4e9;

/// The environment variable that sets the memory limit, bytes.
pub const MEMORY_LIMIT_VAR: &str = "SHPB_MEMORY_LIMIT";

/// What a run may use on this machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// The most time steps.
    pub max_steps: f64,
    /// The most node updates (steps × degrees of freedom).
    pub max_updates: f64,
    /// The memory a run may take, bytes.
    pub memory_bytes: f64,
    /// Where the memory limit comes from (for messages).
    pub memory_source: String,
}

impl Limits {
    /// The limits of this machine: [`MAX_STEPS`], [`MAX_UPDATES`] and the memory available
    /// (`SHPB_MEMORY_LIMIT`, else `MemAvailable` of `/proc/meminfo`, else
    /// [`FALLBACK_MEMORY_BYTES`]).
    pub fn of_machine() -> Result<Limits> {
        let (memory_bytes, memory_source) = match std::env::var(MEMORY_LIMIT_VAR) {
            Ok(text) => (
                parse_limit(&text)?,
                format!("{MEMORY_LIMIT_VAR} in the environment"),
            ),
            Err(_) => match std::fs::read_to_string("/proc/meminfo")
                .ok()
                .as_deref()
                .and_then(mem_available)
            {
                Some(bytes) => (
                    bytes,
                    "available: MemAvailable in /proc/meminfo".to_string(),
                ),
                None => (
                    FALLBACK_MEMORY_BYTES,
                    "assumed: /proc/meminfo unreadable; set SHPB_MEMORY_LIMIT".to_string(),
                ),
            },
        };
        Ok(Limits {
            max_steps: MAX_STEPS,
            max_updates: MAX_UPDATES,
            memory_bytes,
            memory_source,
        })
    }
}

/// `MemAvailable` of a `/proc/meminfo` text, bytes.
fn mem_available(meminfo: &str) -> Option<f64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line.split_whitespace().skip(1);
    let value: f64 = words.next()?.parse().ok()?;
    let scale = match words.next() {
        Some("kB") => 1024.0,
        None => 1.0,
        Some(_) => return None,
    };
    Some(value * scale)
}

/// The value of `SHPB_MEMORY_LIMIT`: a positive number of bytes.
fn parse_limit(text: &str) -> Result<f64> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(Error::Input {
            file: "environment".into(),
            key: MEMORY_LIMIT_VAR.into(),
            problem: format!("`{text}` is not a positive number of bytes"),
            allowed: "a positive number of bytes, e.g. 2e9".into(),
        }),
    }
}

/// Checks the run of `params` against this machine's limits ([`Limits::of_machine`]); returns
/// its estimate.
pub fn check_run(params: &Params) -> Result<RunEstimate> {
    check(params, &Limits::of_machine()?)
}

/// Checks the run of `params` against `limits`: an [`Error::TooLarge`] naming the scene, the
/// estimate, the limit and the keys that make the run smaller when it does not fit.
pub fn check(params: &Params, limits: &Limits) -> Result<RunEstimate> {
    let e = params.estimate();
    check_estimate(&params.source, &params.kind, &e, limits)?;
    Ok(e)
}

/// Checks estimate `e` of a run of scene `file` of kind `kind` against `limits` (what
/// [`check`] does, for a caller that has the estimate before the scene is complete).
pub fn check_estimate(file: &str, kind: &str, e: &RunEstimate, limits: &Limits) -> Result<()> {
    let fits = e.steps <= limits.max_steps
        && e.updates() <= limits.max_updates
        && e.memory_bytes <= limits.memory_bytes;
    if fits {
        return Ok(());
    }
    Err(Error::TooLarge {
        file: file.to_string(),
        needs: format!(
            "{} time steps ({} node updates), {} of memory, {} of output",
            format_si(e.steps.ceil(), ""),
            format_si(e.updates(), ""),
            format_si(e.memory_bytes, "B"),
            format_si(e.output_bytes, "B"),
        ),
        limit: format!(
            "{} time steps, {} node updates, {} of memory ({})",
            format_si(limits.max_steps, ""),
            format_si(limits.max_updates, ""),
            format_si(limits.memory_bytes, "B"),
            limits.memory_source
        ),
        hint: smaller_run_hint(kind).to_string(),
    })
}

/// The keys that make a run of scene kind `kind` smaller.
fn smaller_run_hint(kind: &str) -> &'static str {
    match kind {
        "collision" => {
            "a larger time_step_s, fewer steps_per_contact or a larger output_every make it smaller"
        }
        "force-driven" => {
            "a larger time_step_s, fewer steps_per_period, a shorter end_time_s or a larger output_every make it smaller"
        }
        "pulse" | "shpb" => "a larger cell_size_m or a shorter end_time_s make it smaller",
        "quasistatic" | "constant-rate" => "fewer points make it smaller",
        _ => "a coarser fidelity makes it smaller",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneFile;
    use std::path::Path;

    fn limits(memory_bytes: f64) -> Limits {
        Limits {
            max_steps: MAX_STEPS,
            max_updates: MAX_UPDATES,
            memory_bytes,
            memory_source: "test".into(),
        }
    }

    #[test]
    fn meminfo_is_read_in_bytes() {
        let text = "MemTotal:       32000000 kB\nMemFree:  1 kB\nMemAvailable:   23546964 kB\n";
        assert_eq!(mem_available(text), Some(23546964.0 * 1024.0));
        assert_eq!(mem_available("MemFree: 1 kB\n"), None);
        assert!(parse_limit("2e9").is_ok());
        assert!(parse_limit("-1").is_err() && parse_limit("lots").is_err());
    }

    #[test]
    fn a_femtosecond_collision_step_is_refused_with_its_estimate_and_the_limit() {
        // Issue 15, item 5: this grew by ~60 MB/s until an allocation failed.
        let text = "kind = \"collision\"\nvelocity1_m_s = 5.0\nspecimen = { pair = \"ss440c\" }\ntime_step_s = 1e-15\n";
        let e = Params::from_toml(text, "c.toml", Path::new(".")).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let msg = e.to_string();
        // 3 Hertz contact times (14.03 µs at 5 m/s for the paper's pair) of 1 fs steps
        // (estimate::COLLISION_ESTIMATE_CONTACT_TIMES).
        assert!(
            msg.starts_with(
                "c.toml: the run cannot finish on this machine: it needs 4.21e10 time steps"
            ),
            "{msg}"
        );
        for part in [
            "TB of memory",
            "of memory",
            "of output",
            "limit: 1e10 time steps, 1e12 node updates, ",
            "a larger time_step_s",
        ] {
            assert!(msg.contains(part), "{part} not in {msg}");
        }
        // The same scene at its default step fits easily.
        let ok = "kind = \"collision\"\nvelocity1_m_s = 5.0\nspecimen = { pair = \"ss440c\" }\n";
        let p = Params::from_toml(ok, "c.toml", Path::new(".")).unwrap();
        let est = check(&p, &limits(1e9)).unwrap();
        // 3 Hertz contact times of 2000 steps each (the standard steps_per_contact).
        assert!((est.steps - 6000.0).abs() <= 1.0, "{}", est.steps);
        // …but not on a machine with 100 kB to spare (it keeps 6000 samples of 5 numbers); the
        // message says how much it has.
        let msg = check(&p, &limits(1e5)).unwrap_err().to_string();
        assert!(
            msg.contains("limit: 1e10 time steps, 1e12 node updates, 100 kB of memory (test)"),
            "{msg}"
        );
    }

    #[test]
    fn a_bar_run_over_the_update_cap_is_refused() {
        // 10 µm cells for 0.1 s: 5e7 steps over 2.4e5 nodes.
        let text = "kind = \"pulse\"\nbars = \"authors\"\npressure = \"10psi\"\ncell_size_m = 1e-5\nend_time_s = 0.1\n";
        let msg = Params::from_toml(text, "p.toml", Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("node updates") && msg.contains("a larger cell_size_m"),
            "{msg}"
        );
        // The default end time with those cells is long but finishes.
        let text =
            "kind = \"pulse\"\nbars = \"authors\"\npressure = \"10psi\"\ncell_size_m = 1e-5\n";
        Params::from_toml(text, "p.toml", Path::new(".")).unwrap();
    }
}
