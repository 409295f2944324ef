//! `shpb run`: run a scene file, print its summary and write its results.

use super::common::print;
use shpb_core::fidelity::Fidelity;
use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_input::Result;
use shpb_input::prelude::*;
use shpb_output::io::check_output;
use shpb_output::writer::{Csv, Hdf5, Png, Writer};
use std::path::Path;

/// `shpb run SCENE [-o OUT.h5] [--csv OUT.csv] [--plot OUT.png] [--force] [--fidelity F]`.
pub fn run(
    scene: &Path,
    output: Option<&Path>,
    csv: Option<&Path>,
    plot: Option<&Path>,
    force: bool,
    fidelity: Option<Fidelity>,
) -> Result<()> {
    for p in [output, csv, plot].into_iter().flatten() {
        check_output(p, force)?;
    }
    let params = Params::from_file_with(scene, fidelity)?;
    let mut out = params.run()?;
    out.warnings.splice(0..0, params.warnings());
    for w in &out.warnings {
        eprintln!("shpb: warning: {w}");
    }
    print_summary(&params, &out)?;
    if let Some(p) = output {
        Hdf5.write_run(p, force, &params, &out)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = csv {
        Csv.write_run(p, force, &params, &out)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = plot {
        Png.write_run(p, force, &params, &out)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// Prints the run summary; a closed pipe (`shpb run … | head`) is not an error.
fn print_summary(params: &Params, out: &RunOutput) -> Result<()> {
    let mut text = if matches!(&params.params, SceneParams::Pulse { options, .. } if options.specimen.is_none())
    {
        format!("scene: {} (kind {})\n", params.source, params.kind)
    } else {
        format!(
            "scene: {} (kind {}, law {})\n",
            params.source,
            params.kind,
            params.contact_law().name()
        )
    };
    for it in &out.summary {
        text.push_str(&format!(
            "  {:<40} {:>14.6e} {}\n",
            it.key, it.value, it.unit
        ));
    }
    // True and reduced over the same window (the first loading pulse), so that a long run's
    // later impacts are not compared with the first pulse's reduction.
    if let Some(p) = out.peak_comparison() {
        text.push_str(&format!(
            "result: peak force {:.3} kN (true contact) / {:.3} kN (reduced back force); \
             displacement at peak force {:.1} µm / {:.1} µm; equilibrium ratio at peak {:.3}\n",
            p.true_peak_force_n * 1e-3,
            p.reduced_peak_force_n * 1e-3,
            p.true_displacement_at_peak_m * 1e6,
            p.reduced_displacement_at_peak_m * 1e6,
            p.equilibrium_ratio_at_peak
        ));
    }
    print(&text)
}
