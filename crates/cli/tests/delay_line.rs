//! The delay-line bars (docs/physics.md §6.2, `shpb_core::bar` "Delay line") against the
//! leapfrog on every node, on whole shipped scenes run in-process both ways: every series of
//! the output (contact, gauges, energies, x–t snapshots, the lab's reduction) agrees.

use shpb::bar::{BarScheme, set_thread_bar_scheme};
use shpb::prelude::*;
use shpb::run::RunOutput;
use shpb::scene::Params;
use std::path::{Path, PathBuf};

fn repo(path: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join(path)
}

/// Every numeric series of a run output, by name.
fn series(out: &RunOutput) -> Vec<(String, Vec<f64>)> {
    let mut s = Vec::new();
    if let Some(c) = &out.contact {
        s.push(("contact/force".into(), c.force_n.clone()));
        s.push(("contact/displacement".into(), c.displacement_m.clone()));
        for (name, v) in [
            ("contact/yield_stress", &c.yield_stress_pa),
            ("contact/strain_rate", &c.strain_rate_per_s),
        ] {
            if let Some(v) = v {
                s.push((name.into(), v.clone()));
            }
        }
    }
    for g in &out.gauges {
        s.push((format!("gauges/{}/strain", g.name), g.strain.clone()));
    }
    for (name, e) in &out.energy {
        s.push((format!("energy/{name}"), e.clone()));
    }
    for b in &out.bars {
        s.push((format!("bars/{}/snapshots", b.name), b.stress_pa.concat()));
    }
    // Scalars, each against itself; the energy-balance error, already a fraction of the striker's
    // energy at rounding level, in absolute terms (as validation/perf/compare_runs.py).
    for i in &out.summary {
        if i.key != "energy_balance_max_relative_error" {
            s.push((format!("summary/{}", i.key), vec![i.value]));
        }
    }
    s
}

/// Runs `scene` with the leapfrog and with delay lines; returns the largest difference of any
/// series relative to its own maximum, naming the series.
fn compare(scene: &str) -> (f64, String) {
    let params = Params::from_file(&repo(scene)).unwrap();
    let previous = set_thread_bar_scheme(BarScheme::FiniteDifference);
    let fd = params.run().unwrap();
    set_thread_bar_scheme(BarScheme::Auto);
    let dl = params.run().unwrap();
    set_thread_bar_scheme(previous);
    let (a, b) = (series(&fd), series(&dl));
    assert_eq!(a.len(), b.len());
    let mut worst = (0.0f64, String::new());
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert_eq!(x.len(), y.len(), "{name}");
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = x
            .iter()
            .zip(y)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        let d = if scale > 0.0 { diff / scale } else { diff };
        if d > worst.0 {
            worst = (d, name.clone());
        }
    }
    worst
}

/// The full `standard` SHPB test (striker, shaper, incident, spheres, transmission): every gauge,
/// contact and energy series and every summary scalar within 1e-12 of its maximum, the x–t snapshots (point stresses, where
/// the leapfrog's rounding of u ≈ 3 mm shows as ~ulp(u)/Δx) within 1e-9.
#[test]
fn the_standard_shpb_test_is_unchanged_by_delay_lines() {
    let params = Params::from_file(&repo("scenes/shpb-ss440c-10psi.toml")).unwrap();
    let fd = {
        let previous = set_thread_bar_scheme(BarScheme::FiniteDifference);
        let out = params.run().unwrap();
        set_thread_bar_scheme(previous);
        out
    };
    let dl = params.run().unwrap();
    for ((name, x), (_, y)) in series(&fd).iter().zip(&series(&dl)) {
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = x
            .iter()
            .zip(y)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        let tolerance = if name.starts_with("bars/") {
            1e-9
        } else {
            1e-12
        };
        println!("{name}: {:e}", diff / scale);
        assert!(diff <= tolerance * scale, "{name}: {:e}", diff / scale);
    }
    let (worst, name) = compare("scenes/shpb-ss440c-10psi.toml");
    assert!(worst < 1e-9, "{name}: {worst:e}");
}

/// The other shipped bar scenes (a pulse, a cylinder between the bars, whose specimen runs the
/// leapfrog at Courant < 1 beside delay-line bars): every series within 1e-9 of its maximum.
#[test]
fn the_shipped_bar_scenes_are_unchanged_by_delay_lines() {
    for scene in ["scenes/pulse-10psi.toml", "scenes/shpb-cylinder-al.toml"] {
        let (worst, name) = compare(scene);
        println!("{scene}: {name} {worst:e}");
        assert!(worst < 1e-9, "{scene}: {name}: {worst:e}");
    }
}
