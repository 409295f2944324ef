//! `shpb validate`: every validation case (paper Figs. 2–4, gauge records, Hertz, restitution, the Hertz chain's solitary wave)
//! passes its checks, case names are validated, and a report is never overwritten without
//! `--force`. The PNGs and REPORT.md are not drawn here (`shpb validate --report`).

use shpb::validate::{self, CASES, Context};
use std::path::Path;
use std::sync::OnceLock;

/// One context for the whole file, so the virtual SHPB runs are shared by two cases.
fn context() -> &'static Context {
    static CTX: OnceLock<Context> = OnceLock::new();
    CTX.get_or_init(|| Context::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")))
}

fn passes(case: &str) {
    let r = validate::run_case(case, context()).unwrap();
    eprintln!("{}", validate::table(std::slice::from_ref(&r)));
    assert!(!r.checks.is_empty(), "{case}: no checks");
    let failed: Vec<_> = r.checks.iter().filter(|c| !c.passed()).collect();
    assert!(
        failed.is_empty(),
        "{case}: failed checks: {}",
        failed
            .iter()
            .map(|c| format!(
                "{} = {} (threshold {})",
                c.metric,
                c.value_text(),
                c.threshold_text()
            ))
            .collect::<Vec<_>>()
            .join("; ")
    );
    assert!(!r.section.is_empty() && !r.figure.panels.is_empty());
}

#[test]
fn fig2_quasistatic_passes() {
    passes("fig2-quasistatic");
}

#[test]
fn fig3_rate_passes() {
    passes("fig3-rate");
}

#[test]
fn fig4_force_driven_passes() {
    passes("fig4-force-driven");
}

#[test]
fn fig4_virtual_shpb_passes() {
    passes("fig4-virtual-shpb");
}

#[test]
fn gauge_records_passes() {
    passes("gauge-records");
}

#[test]
fn hertz_analytic_passes() {
    passes("hertz-analytic");
}

#[test]
fn restitution_passes() {
    passes("restitution");
}

#[test]
fn chain_passes() {
    passes("chain");
}

#[test]
fn every_case_has_a_runner_and_unknown_names_are_input_errors() {
    let all = validate::select_cases(&[]).unwrap();
    assert_eq!(all.len(), CASES.len());
    let e = validate::select_cases(&["fig5".to_string()]).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    let text = e.to_string();
    for (name, _) in CASES {
        assert!(text.contains(name), "{text}");
    }
    // Duplicates are run once, in the order given.
    let two = validate::select_cases(&[
        "restitution".into(),
        "fig3-rate".into(),
        "restitution".into(),
    ])
    .unwrap();
    assert_eq!(two, vec!["restitution", "fig3-rate"]);
}

#[test]
fn report_is_not_overwritten_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("REPORT.md");
    std::fs::write(&report, "keep").unwrap();
    let e = validate::command(&["restitution".into()], Some(dir.path()), false).unwrap_err();
    assert_eq!(e.exit_code(), 2, "{e}");
    assert_eq!(std::fs::read_to_string(&report).unwrap(), "keep");
    let files = validate::report_files(Path::new("out"), &["fig3-rate"]);
    assert_eq!(
        files,
        vec![
            Path::new("out/REPORT.md").to_path_buf(),
            Path::new("out/fig3-rate.png").to_path_buf()
        ]
    );
}
