//! Loads a scene file, runs it at the `fast` fidelity preset and prints its summary and the peak
//! contact force: the library behind `shpb run scenes/shpb-ss440c-10psi.toml --fidelity fast`.
//!
//! Run from the repository root with
//! `cargo run --release -p shpb --example run_scene [SCENE]`
//! (default scene: `scenes/shpb-ss440c-10psi.toml`).

use shpb::fidelity::Fidelity;
use shpb::prelude::*; // the file readers: `Params::from_file`, `Apparatus::from_file`, …
use shpb::scene::Params;
use std::path::PathBuf;

fn main() -> shpb::Result<()> {
    let path = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "scenes/shpb-ss440c-10psi.toml".into()),
    );

    // The scene as written (validated: every bad key names the file, key and allowed range) …
    let as_written = Params::from_file(&path)?;
    println!(
        "{}: kind `{}`, fidelity as written `{:?}`",
        as_written.source, as_written.kind, as_written.fidelity
    );

    // … and the same scene with its fidelity preset replaced, as `--fidelity fast` does.
    let params = Params::from_file_with(&path, Some(Fidelity::Fast))?;
    for w in params.warnings() {
        eprintln!("warning: {w}");
    }
    let started = std::time::Instant::now();
    let out = params.run()?;
    println!(
        "ran at fidelity `{:?}` in {:.2} s\n",
        params.fidelity,
        started.elapsed().as_secs_f64()
    );

    println!("summary:");
    for item in &out.summary {
        println!("  {:<40} {:>14.6e} {}", item.key, item.value, item.unit);
    }
    for w in &out.warnings {
        println!("warning: {w}");
    }

    if let Some(c) = &out.contact {
        let k = c.peak_index();
        let t = c.time_s.as_ref().map_or(f64::NAN, |t| t[k]);
        println!(
            "\npeak contact force {:.3} kN at t = {:.2} µs, sphere approach {:.2} µm",
            c.force_n[k] / 1e3,
            t * 1e6,
            c.displacement_m[k] * 1e6
        );
    }
    if let Some(r) = &out.reduction {
        println!(
            "reduced from the simulated gauges: peak back force {:.3} kN, approach at it {:.2} µm",
            r.peak_back_force_n / 1e3,
            r.displacement_at_peak_force_m * 1e6
        );
    }
    Ok(())
}
