//! The sphere contact's implicit solves in law evaluations on the shipped pair scenes (issue 45:
//! the chain joint's solve took 18 a step in contact, bisection to 2⁻¹² before Illinois; now the
//! bracketed secant on the branch that holds bisection's crossing, `solver::joint`). Counted by
//! `shpb::contact::law_evaluations` (trials of the solves, and one commit per contact and step);
//! the before/after table is validation/perf/solver.md. That the solve keeps bisection's
//! crossing is tested step by step in `shpb_core::solver::chain` (tests), and the scenes'
//! outputs against the previous solve in validation/perf/solver.md.

use shpb::contact::law_evaluations;
use shpb::prelude::*;
use shpb::scene::Params;
use std::path::{Path, PathBuf};

fn repo(path: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join(path)
}

/// (trial evaluations, commits, steps in contact) of one run of `scene`, this thread's counts.
fn evaluations(scene: &str) -> (u64, u64, usize) {
    let params = Params::from_file(&repo(scene)).unwrap();
    let (t0, c0) = law_evaluations();
    let out = params.run().unwrap();
    let (t1, c1) = law_evaluations();
    let loaded = out
        .contact
        .map_or(0, |c| c.force_n.iter().filter(|&&f| f > 0.0).count());
    (t1 - t0, c1 - c0, loaded)
}

/// The SS440c SHPB test (a contact joint between the bars, solved every step): about five law
/// evaluations per step in contact, commit included (5.2; 18.4 before), the steps out of contact
/// two (the law at no force gives none, and the commit), four a step over the run (12.3 before). The DEM scenes (their own
/// implicit solve of the approach speed, `solver::solve_approach_speed`, unchanged): 4.1 to 6.3
/// per contact and step, commit included, as before (at most seven).
#[test]
fn the_contact_solves_take_about_five_law_evaluations_a_step() {
    let (trials, commits, loaded) = evaluations("scenes/shpb-ss440c-10psi.toml");
    let idle = commits as usize - loaded;
    let per_loaded_step = (trials + commits - 2 * idle as u64) as f64 / loaded as f64;
    eprintln!(
        "shpb-ss440c-10psi: {trials} trials, {commits} commits, {loaded} steps in contact: \
         {per_loaded_step:.2} evaluations a step in contact, {:.2} a step",
        (trials + commits) as f64 / commits as f64
    );
    assert!(loaded > 1000, "{loaded} steps in contact");
    assert!(per_loaded_step <= 5.5, "{per_loaded_step:.2}");
    assert!((trials + commits) as f64 <= 4.5 * commits as f64);
    for scene in [
        "scenes/collision-ss440c-5ms.toml",
        "scenes/collision-dissimilar.toml",
        "scenes/force-driven-ss440c-10psi.toml",
        "scenes/chain-ss440c-10.toml",
    ] {
        let (trials, commits, _) = evaluations(scene);
        let per_step = (trials + commits) as f64 / commits as f64;
        eprintln!("{scene}: {trials} trials, {commits} commits: {per_step:.2} a contact-step");
        assert!(commits > 1000 && per_step <= 7.0, "{scene}: {per_step:.2}");
    }
}
