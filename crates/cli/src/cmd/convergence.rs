//! `shpb convergence`: a scene on a ladder of resolutions.

use super::common::say;
use shpb_input::Result;
use shpb_output::io::check_output;
use std::path::Path;

/// `shpb convergence`: runs the ladder with a progress line per level, prints the table, writes
/// the CSV and the error-against-run-time plot.
pub fn convergence(
    scene: &Path,
    output: Option<&Path>,
    plot: Option<&Path>,
    force: bool,
) -> Result<()> {
    for p in [output, plot].into_iter().flatten() {
        check_output(p, force)?;
    }
    let study = shpb_study::convergence::study(scene, |i, value| {
        eprintln!("shpb: convergence level {} ({value:e})", i + 1);
    })?;
    let table = shpb_study::convergence::table_text(&study);
    say(&table)?;
    if let Some(p) = output {
        shpb_study::convergence::write_csv(p, force, &study)?;
        super::common::wrote(p);
    }
    if let Some(p) = plot {
        shpb_study::convergence::plot(p, force, &study)?;
        super::common::wrote(p);
    }
    Ok(())
}
