//! `shpb validate`: the validation cases (paper Figs. 2–4, gauge records, Hertz, restitution).

use shpb_input::Result;
use std::path::Path;

/// `shpb validate [CASE…] [--data DIR] [--report DIR] [--force]` (issue 7): the reference data
/// of `--data DIR` (holding `validation/` and `bars/`), else the copy embedded in the binary; see
/// [`shpb_validate::command_with_data`].
pub fn validate(
    cases: &[String],
    data: Option<&Path>,
    report: Option<&Path>,
    force: bool,
) -> Result<()> {
    shpb_validate::command_with_data(cases, data, report, force)
}
