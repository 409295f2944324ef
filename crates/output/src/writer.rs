//! The one writer trait of shpb ([`Writer`]) and its three formats: [`Hdf5`] (the full run with
//! its scene text), [`Csv`] (the contact or gauge series) and [`Png`] (the run's figure).

use shpb_core::run::RunOutput;
use shpb_core::scene::Params;
use shpb_input::Result;
use std::path::Path;

/// A file format a run can be written in. Every implementation writes atomically and refuses
/// an existing `path` unless `force` (lumol's `Output` trait has the same role).
pub trait Writer {
    /// The format's name as shown to the user (`HDF5`, `CSV`, `PNG`).
    fn format(&self) -> &'static str;
    /// Writes the run of the scene `params` to `path`.
    fn write_run(&self, path: &Path, force: bool, params: &Params, out: &RunOutput) -> Result<()>;
}

/// HDF5: every series, the summary, the reduction, the scene text and, when known, the run's
/// provenance (`shpb run -o`).
#[derive(Debug, Clone, Default)]
pub struct Hdf5 {
    /// What the run read and how it was asked for (`/provenance`), if known.
    pub provenance: Option<shpb_input::files::Provenance>,
}

/// CSV: the contact series, or the gauge series of bar scenes (`shpb run --csv`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Csv;

/// PNG: F–δ for sphere scenes, gauge signals for bar scenes, three panels for a full test
/// (`shpb run --plot`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Png;

impl Writer for Hdf5 {
    fn format(&self) -> &'static str {
        "HDF5"
    }
    fn write_run(&self, path: &Path, force: bool, params: &Params, out: &RunOutput) -> Result<()> {
        crate::io::write_hdf5(path, force, &params.text, self.provenance.as_ref(), out)
    }
}

impl Writer for Csv {
    fn format(&self) -> &'static str {
        "CSV"
    }
    fn write_run(&self, path: &Path, force: bool, _params: &Params, out: &RunOutput) -> Result<()> {
        crate::io::write_csv(path, force, out)
    }
}

impl Writer for Png {
    fn format(&self) -> &'static str {
        "PNG"
    }
    fn write_run(&self, path: &Path, force: bool, params: &Params, out: &RunOutput) -> Result<()> {
        crate::plot::plot_run(path, force, params, out)
    }
}
