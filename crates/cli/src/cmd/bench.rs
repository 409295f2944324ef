//! `shpb bench`: the fidelity presets and physics knobs of a full test timed.

use super::common::{plan, say, write_all};
use shpb_input::Result;
use std::path::Path;

/// `shpb bench [SCENE] [--repeats N] [--report FILE] [--force]`: prints the tables (markdown)
/// and writes them to `--report`.
pub fn bench(scene: &Path, repeats: usize, report: Option<&Path>, force: bool) -> Result<()> {
    let outputs = plan(force, &[(report, "--report", &["md"][..])])?;
    outputs.not_inputs(&[scene.to_path_buf()])?;
    let b = shpb_study::bench::bench(scene, repeats, |s| eprintln!("shpb: bench: {s}"))?;
    let md = shpb_study::bench::markdown(&b);
    if !outputs.to_stdout() {
        say(&md)?;
    }
    write_all(&outputs, || match report {
        Some(p) => shpb_output::io::write_text_atomically(p, force, &md),
        None => Ok(()),
    })
}
