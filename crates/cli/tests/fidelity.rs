//! Fidelity presets and convergence studies: the order estimate on an analytic ladder, presets
//! that agree with each other, explicit knobs that win over presets, and the observed order of
//! the DEM collision (velocity Verlet with a trapezoidal dashpot: second order).

use shpb::convergence::{observed_order, richardson, study};
use shpb::fidelity::Fidelity;
use shpb::prelude::*;
use shpb::scene::{Params, SceneParams};
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo(path: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join(path)
}

/// f(h) = f0 + c h² sampled at h, h/2, h/4 has order exactly 2 and extrapolates to f0.
#[test]
fn observed_order_and_richardson_recover_an_analytic_ladder() {
    let f = |h: f64| 3.0 + 0.7 * h * h;
    let p = observed_order(f(0.4), f(0.2), f(0.1), 2.0).unwrap();
    assert!((p - 2.0).abs() < 1e-9, "{p}");
    let ex = richardson(f(0.2), f(0.1), 2.0, p);
    assert!((ex - 3.0).abs() < 1e-12, "{ex}");
    // Round-off level or non-monotone differences give no order.
    assert!(observed_order(1.0, 1.0, 1.0, 2.0).is_none());
    assert!(observed_order(1.0, 2.0, 1.0, 2.0).is_none());
}

fn cell_size(p: &Params) -> f64 {
    match &p.params {
        SceneParams::Pulse { options, .. } => options.cell_size_m,
        _ => unreachable!("a shpb scene"),
    }
}

/// The presets set the grid; an explicit `cell_size_m` in the scene wins over any preset; an
/// unknown preset is refused naming the key and the allowed values.
#[test]
fn presets_set_the_knobs_and_explicit_keys_win() {
    let scene = repo("scenes/shpb-ss440c-10psi.toml");
    for f in Fidelity::ALL {
        let p = Params::from_file_with(&scene, Some(f)).unwrap();
        assert_eq!(p.fidelity, f);
        assert_eq!(cell_size(&p), f.bar_knobs().cell_size_m);
    }
    let dir = tempfile::TempDir::new().unwrap();
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        "../bars/authors.toml",
        repo("bars/authors.toml").to_str().unwrap(),
    );
    let explicit = dir.path().join("explicit.toml");
    std::fs::write(&explicit, format!("cell_size_m = 2e-3\n{text}")).unwrap();
    let p = Params::from_file_with(&explicit, Some(Fidelity::Reference)).unwrap();
    assert_eq!(cell_size(&p), 2e-3);
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, format!("fidelity = \"ultra\"\n{text}")).unwrap();
    let msg = Params::from_file(&bad).unwrap_err().to_string();
    assert!(
        msg.contains("fidelity") && msg.contains("fast, standard, reference"),
        "{msg}"
    );
}

fn bar_knobs_of(p: &Params) -> (f64, shpb::bar::Dispersion) {
    match &p.params {
        SceneParams::Pulse { options, .. } => (options.cell_size_m, options.dispersion),
        _ => unreachable!("a shpb scene"),
    }
}

/// `reference` runs the exact first mode on delay lines at 1 mm where the bars allow it, inserts
/// (elementary beside them) included; bars no cell ≤ 1 mm divides fall back to the Love-rod
/// chain at 0.125 mm; a dispersion chosen in the scene is never replaced. Inserts of the bars'
/// own material and diameter only delay the waves: with 6 mm ones (whole cells, exact delay
/// lines) the `reference` run's contact force is the run without inserts, six steps later, to
/// 1e-12 of its peak (the waves' precursors ahead of the contact differ at rounding level).
#[test]
fn reference_falls_back_to_the_love_rod_chain_where_delay_lines_cannot_run() {
    use shpb::bar::Dispersion;
    let dir = tempfile::TempDir::new().unwrap();
    let setup = std::fs::read_to_string(repo("bars/authors.toml"))
        .unwrap()
        .replace(
            "gauges = \"gauges-authors.toml\"",
            &format!(
                "gauges = \"{}\"",
                repo("bars/gauges-authors.toml").to_str().unwrap()
            ),
        );
    let scene = |name: &str, setup_text: String, extra: &str| {
        let bars = dir.path().join(format!("{name}-bars.toml"));
        std::fs::write(&bars, setup_text).unwrap();
        let path = dir.path().join(format!("{name}.toml"));
        std::fs::write(
            &path,
            format!(
                "kind = \"shpb\"\nbars = \"{}\"\npressure = \"10psi\"\nfidelity = \"reference\"\n{extra}[specimen]\npair = \"ss440c\"\n",
                bars.display()
            ),
        )
        .unwrap();
        bar_knobs_of(&Params::from_file(&path).unwrap())
    };
    let fallback = Fidelity::Reference.fallback_bar_knobs().unwrap();
    assert_eq!(
        scene("plain", setup.clone(), ""),
        (1e-3, Dispersion::PochhammerChree)
    );
    let with_inserts = format!(
        "{setup}\n[inserts.incident]\nlength_m = 0.00635\n[inserts.transmission]\nlength_m = 0.00635\n"
    );
    assert_eq!(
        scene("inserts", with_inserts.clone(), ""),
        (1e-3, Dispersion::PochhammerChree)
    );
    let run = |name: &str, setup_text: String| {
        let bars = dir.path().join(format!("{name}-bars.toml"));
        std::fs::write(&bars, setup_text).unwrap();
        let text = format!(
            "kind = \"shpb\"\nbars = \"{}\"\npressure = \"10psi\"\nfidelity = \"reference\"\n[specimen]\npair = \"ss440c\"\n",
            bars.display()
        );
        Params::from_toml(&text, "t.toml", dir.path())
            .unwrap()
            .run()
            .unwrap()
    };
    let (plain, inserted) = (
        run("plain-run", setup.clone()),
        run(
            "inserts-6mm",
            format!(
                "{setup}\n[inserts.incident]\nlength_m = 0.006\n[inserts.transmission]\nlength_m = 0.006\n"
            ),
        ),
    );
    // The contact's force history, from its first non-zero sample: the incident insert delays
    // it by its six steps and the run ends at the same time, so it is six samples shorter.
    let force = |o: &shpb::run::RunOutput| {
        let f = &o.contact.as_ref().unwrap().force_n;
        let first = f.iter().position(|&x| x != 0.0).unwrap();
        (first, f[first..].to_vec())
    };
    let ((first, plain), (first_inserted, inserted)) = (force(&plain), force(&inserted));
    assert_eq!(first_inserted, first + 6);
    let peak = plain.iter().fold(0.0f64, |m, &x| m.max(x));
    let worst = plain
        .iter()
        .zip(&inserted)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst <= 1e-12 * peak, "{:e} of the peak", worst / peak);
    // A 1.23456 m incident bar: the largest cell dividing it and the 1.02 and 0.10 m bars is
    // 0.16 mm, beyond the 4× refinement of 1 mm that the preset tries.
    let odd = setup.replacen("length_m = 1.21", "length_m = 1.23456", 1);
    assert_eq!(
        scene("odd", odd, ""),
        (fallback.cell_size_m, Dispersion::LoveRod)
    );
    // An explicit cell that does not divide the bars gets the fallback theory at that cell.
    assert_eq!(
        scene("explicit-cell", setup.clone(), "cell_size_m = 0.3e-3\n"),
        (0.3e-3, Dispersion::LoveRod)
    );
    // A dispersion the scene chooses wins over the preset and its fallback.
    assert_eq!(
        scene("explicit", with_inserts, "dispersion = \"none\"\n"),
        (1e-3, Dispersion::None)
    );
}

/// `fast` (4 mm cells) and `standard` (1 mm) agree within 0.1 % in peak force and approach at
/// peak: the bars are exact at Courant 1, so only the joints' O(Δt²) error differs
/// (validation/perf/REPORT.md measures both against `reference`).
#[test]
fn fast_and_standard_presets_agree() {
    let scene = repo("scenes/shpb-ss440c-10psi.toml");
    let peak = |f| {
        let out = Params::from_file_with(&scene, Some(f))
            .unwrap()
            .run()
            .unwrap();
        let c = out.contact.unwrap();
        shpb::convergence::interpolated_peak(&c.force_n, &c.displacement_m)
    };
    let (f1, d1) = peak(Fidelity::Fast);
    let (f2, d2) = peak(Fidelity::Standard);
    assert!((f1 / f2 - 1.0).abs() < 1e-3, "{f1} vs {f2}");
    assert!((d1 / d2 - 1.0).abs() < 1e-3, "{d1} vs {d2}");
}

/// The contact series is stamped with the time of the level its joint was solved at: the time of
/// the peak force (parabola through the samples) is the same at 4 mm and 1 mm cells within 1 %
/// of the coarse step (stamped one step late, as before 2026-11-24, the two differed by 3/4 of it).
#[test]
fn the_contact_series_is_on_the_time_of_its_level() {
    let scene = repo("scenes/shpb-ss440c-10psi.toml");
    let peak_time = |f: Fidelity| {
        let out = Params::from_file_with(&scene, Some(f))
            .unwrap()
            .run()
            .unwrap();
        let dt = out.summary_value("time_step").unwrap();
        let c = out.contact.unwrap();
        let t = c.time_s.unwrap();
        // Sampled every step: consecutive samples one step apart, the first at t = 0.
        assert_eq!(t[0], 0.0);
        assert!((t[1] - t[0] - dt).abs() < 1e-12 * dt);
        (shpb::convergence::interpolated_peak(&c.force_n, &t).1, dt)
    };
    let (t_fast, dt_fast) = peak_time(Fidelity::Fast);
    let (t_std, _) = peak_time(Fidelity::Standard);
    assert!(
        (t_fast - t_std).abs() < 0.01 * dt_fast,
        "{t_fast} vs {t_std} (Δt {dt_fast})"
    );
}

/// The collision ladder (125 … 8000 steps per contact) converges at second order in the peak
/// force, as velocity Verlet with the trapezoidal dashpot should (observed 1.8–2.6).
#[test]
fn collision_converges_at_second_order() {
    let s = study(&repo("scenes/collision-ss440c-5ms.toml"), |_, _| {}).unwrap();
    let p = s.peak_order.order.expect("an order");
    assert!((1.5..3.0).contains(&p), "observed order {p}");
    assert!(s.levels.iter().all(|l| l.metrics.peak.is_finite()));
}

/// `shpb run --fidelity fast` uses the preset's time step (Δt = 4 mm / c0) and
/// `shpb convergence` refuses a scene kind with nothing to converge.
#[test]
fn cli_fidelity_flag_and_convergence_errors() {
    let bin = env!("CARGO_BIN_EXE_shpb");
    let out = Command::new(bin)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .args(["run", "scenes/shpb-ss440c-10psi.toml", "--fidelity", "fast"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // The header names the bars the preset chose.
    assert!(
        text.contains("fidelity fast: elementary bars, 4 mm cells"),
        "{text}"
    );
    let dt: f64 = text
        .lines()
        .find(|l| l.trim_start().starts_with("time_step "))
        .and_then(|l| l.split_whitespace().nth(1))
        .unwrap()
        .parse()
        .unwrap();
    let c0 = (192e9f64 / 8110.0).sqrt();
    // The summary prints 7 significant digits.
    assert!((dt * c0 / 4e-3 - 1.0).abs() < 1e-6, "Δt = {dt}");
    let out = Command::new(bin)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .args(["convergence", "scenes/quasistatic-fig2.toml"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("kind"));
}
