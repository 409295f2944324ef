//! `shpb bench`: the fidelity presets and physics knobs of a full test timed.

use super::common::say;
use shpb_input::Result;
use shpb_output::io::check_output;
use std::path::Path;

/// `shpb bench [SCENE] [--repeats N] [--report FILE] [--force]`: prints the tables (markdown)
/// and writes them to `--report`.
pub fn bench(scene: &Path, repeats: usize, report: Option<&Path>, force: bool) -> Result<()> {
    if let Some(p) = report {
        check_output(p, force)?;
    }
    let b = shpb_study::bench::bench(scene, repeats, |s| eprintln!("shpb: bench: {s}"))?;
    let md = shpb_study::bench::markdown(&b);
    say(&md)?;
    if let Some(p) = report {
        shpb_output::io::write_text_atomically(p, force, &md)?;
        super::common::wrote(p);
    }
    Ok(())
}
