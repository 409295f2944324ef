//! `shpb convergence`: a scene on a ladder of resolutions.

use super::common::{plan, say, write_all};
use shpb_input::Result;
use std::path::Path;

/// `shpb convergence`: runs the ladder with a progress line per level, prints the table, writes
/// the CSV and the error-against-run-time plot.
pub fn convergence(
    scene: &Path,
    output: Option<&Path>,
    plot: Option<&Path>,
    force: bool,
) -> Result<()> {
    let outputs = plan(
        force,
        &[
            (output, "--output", &["csv"][..]),
            (plot, "--plot", &["png"][..]),
        ],
    )?;
    outputs.not_inputs(&[scene.to_path_buf()])?;
    let study = shpb_study::convergence::study(scene, |i, value| {
        eprintln!("shpb: convergence level {} ({value:e})", i + 1);
    })?;
    let table = shpb_study::convergence::table_text(&study);
    if !outputs.to_stdout() {
        say(&table)?;
    }
    write_all(&outputs, || {
        if let Some(p) = output {
            shpb_study::convergence::write_csv(p, force, &study)?;
        }
        if let Some(p) = plot {
            shpb_study::convergence::plot(p, force, &study)?;
        }
        Ok(())
    })
}
