//! Johnson–Cook constants of Yao et al.'s 945 steel from its two shots (issue 44): the fit
//! problems of `validation/fit-yao/` (`shpb fit` on a scene driven by each record's own incident
//! wave, docs/physics.md §6.10 and §11), shared by the report generator
//! (`crates/validate/src/bin/fit_yao.rs`) and its fast test (`tests/fit_yao.rs`).

use shpb_input::Result;
use shpb_study::fit::Problem;
use shpb_study::fit::spec::{Free, Residual, parse_free};
use std::path::{Path, PathBuf};

/// The two shots: sample folder name and the lab's strain rate, 1/s (the lab's 3-wave rate
/// averaged over the rows it chose, `tests/data/labs/yao-2026/lab_processing.csv`).
pub const SAMPLES: [(&str, f64); 2] = [("sample_01", 1875.9), ("sample_02", 3290.1)];

/// The free constants and their uniform-prior bounds (`--free KEY=MIN:MAX`): A, B, n and C of
/// the Johnson–Cook law σ = (A + B εpⁿ)(1 + C ln(ε̇/ε̇0))(1 − T*ᵐ) (docs/physics.md §6.12). The
/// bounds span what structural and armour steels take (A 0.3–1.2 GPa, B 0.1–1.5 GPa, n 0.05–1,
/// C 0–0.05; e.g. 4340: 792 MPa, 510 MPa, 0.26, 0.014).
pub const FREE: [&str; 4] = [
    "specimen.johnson_cook.a_pa=300e6:1200e6",
    "specimen.johnson_cook.b_pa=100e6:1500e6",
    "specimen.johnson_cook.n=0.05:1.0",
    "specimen.johnson_cook.c=0:0.05",
];

/// The shot's raw microstrain record (XLS for sample_01, XLSX for sample_02).
pub fn record(root: &Path, sample: &str) -> PathBuf {
    let ext = if sample == "sample_01" { "xls" } else { "xlsx" };
    root.join(format!(
        "tests/data/labs/yao-2026/steel_945/{sample}/raw_microstrain.{ext}"
    ))
}

/// The shot's scene: Yao's bars, the 945-steel cylinder, the record's incident wave as drive.
pub fn scene(root: &Path, sample: &str) -> PathBuf {
    root.join(format!(
        "validation/fit-yao/scenes/yao-945-{}.toml",
        sample.replace('_', "")
    ))
}

/// The lab's own reduction of the shot (extracted from its `manual_processing_result.xlsx`,
/// `validation/fit-yao/lab/README.md`).
pub fn lab_curve(root: &Path, sample: &str) -> PathBuf {
    root.join(format!(
        "validation/fit-yao/lab/{sample}_lab_stress_strain.csv"
    ))
}

/// The free keys parsed ([`FREE`]).
pub fn free() -> Result<Vec<Free>> {
    FREE.iter().map(|f| parse_free(f)).collect()
}

/// The fit of `samples` (one: that shot; several: jointly, each record's model driven by its own
/// incident wave, the scene being the first sample's) on the stress–strain residual.
pub fn problem(root: &Path, samples: &[&str]) -> Result<Problem> {
    problem_with(root, samples, free()?)
}

/// [`problem`] with other free keys.
pub fn problem_with(root: &Path, samples: &[&str], free: Vec<Free>) -> Result<Problem> {
    let records: Vec<PathBuf> = samples.iter().map(|s| record(root, s)).collect();
    Problem::new(
        &scene(root, samples[0]),
        free,
        Vec::new(),
        Some(Residual::StressStrain),
        &records,
    )
}

/// The lab's reduced curve: (2-wave strain, 2-wave stress in Pa) up to its largest strain (the
/// loading branch). The lab's 2-wave stress is the transmitted bar's (its column Q), the strain
/// the reflected wave's integral (its column O): what shpb calls the 1-wave stress and strain.
pub fn lab_loading(root: &Path, sample: &str) -> Result<(Vec<f64>, Vec<f64>)> {
    let t = shpb_input::csv::CsvTable::read(&lab_curve(root, sample))?;
    let e = t.column("two_wave_strain")?;
    let s = t.column("two_wave_stress_Pa")?;
    let end = e
        .iter()
        .enumerate()
        .fold(0, |b, (i, &v)| if v > e[b] { i } else { b });
    Ok((e[..=end].to_vec(), s[..=end].to_vec()))
}
