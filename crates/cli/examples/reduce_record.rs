//! Reduces a raw two-channel gauge record (the authors' CSV format `time_s,incident_V,
//! transmission_V`) with the built-in `authors` set-up and prints the peak back force and the
//! sphere approach at it: the library behind `shpb reduce RECORD --bars authors`.
//!
//! Run from the repository root with
//! `cargo run --release -p shpb --example reduce_record [RECORD]`
//! (default: `validation/gauge-records/data/2013-05-22_sample1_ss440c.csv`).

use shpb::apparatus::Apparatus;
use shpb::prelude::*; // `Apparatus::resolve`, `Apparatus::from_file`, …
use shpb::reduce::ReductionOptions;
use std::path::{Path, PathBuf};

fn main() -> shpb::Result<()> {
    let record =
        PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| {
            "validation/gauge-records/data/2013-05-22_sample1_ss440c.csv".into()
        }));

    // A built-in set-up by name (a path to a set-up file works too, relative to the base dir).
    let apparatus = Apparatus::resolve("authors", Path::new("."))?;
    println!(
        "set-up {}: incident bar {:.3} m, transmission bar {:.3} m, c0 = {:.1} m/s",
        apparatus.source,
        apparatus.incident.length_m,
        apparatus.transmission.length_m,
        apparatus.material.wave_speed_m_s()
    );

    let r = shpb::gauges::reduce_record_file(&record, &apparatus, &ReductionOptions::default())?;
    println!(
        "record {}: {} samples reduced",
        record.display(),
        r.time_s.len()
    );
    println!(
        "peak back (transmitted) force {:.3} kN at t = {:.2} µs",
        r.peak_back_force_n / 1e3,
        r.peak_back_force_time_s * 1e6
    );
    println!(
        "sphere approach at peak force {:.2} µm (front {:.2} µm, back {:.2} µm)",
        r.displacement_at_peak_force_m * 1e6,
        r.front_displacement_m[r.peak_index] * 1e6,
        r.back_displacement_m[r.peak_index] * 1e6
    );
    println!(
        "equilibrium ratio |F_front − F_back| / F_3wave at peak {:.3}",
        r.equilibrium_ratio_at_peak
    );
    for w in &r.warnings {
        println!("warning: {w}");
    }
    Ok(())
}
