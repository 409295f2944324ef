//! `shpb curve`: the loading curve F(δ) of a specimen as CSV on stdout.

use super::common::stdout_result;
use shpb_core::contact::LawKind;
use shpb_input::Result;
use std::io::Write;

/// `shpb curve [--specimen S] [--rate R] [--to D] [--points N] [--law L]`.
pub fn curve(specimen: &str, rate: f64, to: f64, points: i64, law: LawKind) -> Result<()> {
    let s = shpb_study::api::loading_curve(specimen, rate, to, points, law)?;
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
