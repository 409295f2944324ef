//! `shpb curve`: the loading curve F(δ) of a specimen as CSV on stdout.

use super::common::stdout_result;
use shpb_core::contact::LawKind;
use shpb_input::specimen::resolve_pair;
use shpb_input::{Result, Validator};
use std::io::Write;
use std::path::Path;

/// `shpb curve [--specimen S] [--rate R] [--to D] [--points N] [--law L]`.
pub fn curve(specimen: &str, rate: f64, to: f64, points: i64, law: LawKind) -> Result<()> {
    let v = Validator::new("command line");
    let pair = resolve_pair(specimen, Path::new("."), &v, "--specimen")?;
    v.in_range("--rate", rate, 0.0, 1e9, "1/s")?;
    v.positive(
        "--to",
        to,
        0.5 * pair.sphere1.radius_m.min(pair.sphere2.radius_m),
        "m",
    )?;
    if !(2..=10_000_000).contains(&points) {
        return Err(v.error(
            "--points",
            format!("{points} is out of range"),
            "2 to 10000000",
        ));
    }
    let points = points as usize;
    let law = law.build(pair.contact_properties());
    let s = shpb_core::solver::loading_curve(law.as_ref(), to, points, rate);
    let stdout = std::io::stdout();
    let mut w = std::io::BufWriter::new(stdout.lock());
    let written = (|| -> std::io::Result<()> {
        writeln!(w, "displacement_m,force_N")?;
        for (d, f) in s.displacement_m.iter().zip(&s.force_n) {
            writeln!(w, "{d:e},{f:e}")?;
        }
        w.flush()
    })();
    // A closed pipe (`shpb curve | head`) is not an error.
    stdout_result(written)
}
