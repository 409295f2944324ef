//! Dispersive delay lines (`dispersion = "rayleigh-love" | "pochhammer-chree"`, docs/physics.md
//! §6.2.1): the travelling waves of a uniform Courant-1 bar carry the model's phase velocity,
//! lose no energy, reduce to the exact delay line where dispersion vanishes, and the fields
//! computed after the run are the ones read while it ran.

use shpb::prelude::*;
use shpb_core::bar::{
    Bar, BarMaterial, BarSpec, Dispersion, EndCondition, Segment, measure_phase_velocity,
};
use shpb_core::dispersion::{
    velocity_ratio_at_normalised_frequency, velocity_ratio_at_radius_over_wavelength,
};
use std::f64::consts::PI;

/// The authors' bars (bars/authors.toml): maraging steel, 19.05 mm.
fn steel() -> BarMaterial {
    BarMaterial {
        density_kg_m3: 8110.0,
        youngs_modulus_pa: 192e9,
        poisson_ratio: 0.31,
    }
}
const DIAMETER_M: f64 = 0.01905;
const CELL_M: f64 = 1e-3;

fn bar(length_m: f64, diameter_m: f64, dispersion: Dispersion) -> Bar {
    let spec = BarSpec {
        name: "probe".to_string(),
        segments: vec![Segment {
            length_m,
            diameter_m,
            material: steel(),
        }],
        left_end: EndCondition::Free,
        right_end: EndCondition::Absorbing,
        dispersion,
    };
    let cells = (length_m / CELL_M).round() as usize;
    Bar::new(&spec, Bar::courant_time_step(&spec, cells)).unwrap()
}

/// A C∞ compressive force pulse (Gaussian, 8 µs wide, centred at 40 µs), N: its spectrum is
/// below 1e-300 of its peak where the delay line's band closes (Ω > π/2, 1.2 MHz at 1 mm).
fn pulse_n(t_s: f64) -> f64 {
    -1e4 * (-((t_s - 40e-6) / 8e-6).powi(2)).exp()
}

/// The harness of the Love-rod scheme's test (`bar/phase_velocity.rs`) measures each model's own phase velocity
/// on a dispersive delay line at 1 mm cells, to its resolution of 1e-4, without attenuation.
#[test]
fn each_model_carries_its_phase_velocity() {
    let m = steel();
    let c0 = m.wave_speed_m_s();
    let a = DIAMETER_M / 2.0;
    let nu = m.poisson_ratio;
    for (dispersion, relation) in [
        (
            Dispersion::PochhammerChree,
            (|nu: f64, y: f64| velocity_ratio_at_radius_over_wavelength(nu, y))
                as fn(f64, f64) -> f64,
        ),
        (Dispersion::RayleighLove, |nu: f64, y: f64| {
            1.0 / (1.0 + 0.5 * (nu * 2.0 * PI * y).powi(2)).sqrt()
        }),
    ] {
        for y in [0.05, 0.1, 0.2, 0.3] {
            let k = 2.0 * PI * y / a;
            let c = c0 * relation(nu, y);
            let meas = measure_phase_velocity(m, DIAMETER_M, dispersion, k * c, CELL_M).unwrap();
            let error = meas.phase_velocity_m_s / c - 1.0;
            println!(
                "{dispersion:?} a/Λ = {y}: c/c0 {:.6} measured, {:.6} exact: {error:+.2e}; amplitude ratio {:.6}",
                meas.phase_velocity_m_s / c0,
                c / c0,
                meas.amplitude_ratio
            );
            assert!(error.abs() < 1e-4, "{dispersion:?} a/Λ = {y}: {error:e}");
            assert!((meas.amplitude_ratio - 1.0).abs() < 1e-3);
        }
    }
}

/// Drives the left end of a 1 m bar (absorbing right end) with [`pulse_n`] for `steps` steps,
/// reading the stress at `x_read` every `every` steps; returns the bar and the readings.
fn drive(mut b: Bar, steps: usize, x_read: &[f64], every: usize) -> (Bar, Vec<Vec<f64>>) {
    let mut reads = Vec::new();
    for n in 0..steps {
        if n % every == 0 && n > 0 {
            reads.push(x_read.iter().map(|&x| b.stress_at(x)).collect());
        }
        let t = n as f64 * b.dt_s();
        b.step(pulse_n(t), 0.0);
    }
    (b, reads)
}

/// With a vanishing radius (a/Δx = 1e-5) the dispersive delay line is the exact one: the energies
/// and the fields computed after the run (ends included) agree to rounding; the end velocities
/// and the stresses read step by step away from the ends (module docs, "Causality") to the
/// filters' truncation (1e-16 of their energy: 1e-8 of the amplitude).
#[test]
fn without_dispersion_it_is_the_exact_delay_line() {
    let xs = [0.2004, 0.5, 0.7777];
    let steps = 900;
    let (plain, plain_reads) = drive(bar(1.0, 1e-8, Dispersion::None), steps, &xs, 7);
    for dispersion in [Dispersion::PochhammerChree, Dispersion::RayleighLove] {
        let (disp, reads) = drive(bar(1.0, 1e-8, dispersion), steps, &xs, 7);
        assert_eq!(disp.transit_model(), dispersion.transit_model());
        let peak = plain_reads
            .iter()
            .flatten()
            .fold(0.0f64, |m, &x| m.max(x.abs()));
        for (k, (row, prow)) in reads.iter().zip(&plain_reads).enumerate() {
            for (i, (r, p)) in row.iter().zip(prow).enumerate() {
                assert!(
                    (r - p).abs() <= 1e-7 * peak,
                    "{dispersion:?} x {} read {k}: {r} vs {p}",
                    xs[i]
                );
            }
        }
        let v = |b: &Bar, i: usize| b.half_step_velocity_m_s(i);
        let last = plain.node_count() - 1;
        // The particle velocity of the pulse's peak, F/Z.
        let z = steel().density_kg_m3 * steel().wave_speed_m_s() * PI * 1e-16 / 4.0;
        let v_peak = 1e4 / z;
        for i in [0, last] {
            let d = (v(&disp, i) - v(&plain, i)).abs();
            assert!(
                d <= 1e-7 * v_peak,
                "{dispersion:?} node {i}: {:e}",
                d / v_peak
            );
        }
        let e = plain.work_done_j();
        assert!((disp.work_done_j() - e).abs() <= 1e-9 * e);
        assert!((disp.absorbed_energy_j() - plain.absorbed_energy_j()).abs() <= 1e-9 * e);
        // After the run, the whole field at every 7th step, ends included.
        let everywhere: Vec<f64> = (0..=20).map(|i| i as f64 * 0.05).collect();
        let steps: Vec<usize> = (1..steps / 7).map(|k| 7 * k).collect();
        let after = disp.stress_history(&everywhere, &steps).unwrap();
        let mut replay = bar(1.0, 1e-8, Dispersion::None);
        let mut k = 0;
        for n in 0..steps[steps.len() - 1] + 1 {
            if k < steps.len() && n == steps[k] {
                for (x, a) in everywhere.iter().zip(&after[k]) {
                    let p = replay.stress_at(*x);
                    assert!(
                        (a - p).abs() <= 1e-9 * peak,
                        "{dispersion:?} x {x} step {n}: {a} vs {p}"
                    );
                }
                k += 1;
            }
            replay.step(pulse_n(n as f64 * replay.dt_s()), 0.0);
        }
    }
}

/// At the authors' 19.05 mm the pulse disperses (its peak at mid-bar drops and arrives late)
/// but loses no energy: once it has left through the absorbing end, the energy absorbed there
/// is the work done at the driven end, to the filters' truncation (their gain is one to 1e-8 in
/// amplitude, 2e-8 in energy; 1e-7 allowed), and the bar's ledger and its passivity check hold
/// throughout.
#[test]
fn dispersion_conserves_the_energy_of_a_pulse() {
    // 1 m crossing: 205 µs at c0, the pulse's content (≤ 60 kHz) at ≥ 0.98 c0 in group.
    let steps = 2000;
    let (plain, plain_reads) = drive(bar(1.0, DIAMETER_M, Dispersion::None), steps, &[0.5], 1);
    for dispersion in [Dispersion::PochhammerChree, Dispersion::RayleighLove] {
        let mut b = bar(1.0, DIAMETER_M, dispersion);
        let mut reads = Vec::new();
        for n in 0..steps {
            if n > 0 {
                reads.push(b.stress_at(0.5));
            }
            b.step(pulse_n(n as f64 * b.dt_s()), 0.0);
            if n % 256 == 0 {
                b.check_energy_ledger(0.0).unwrap();
            }
        }
        b.check_finite().unwrap();
        let work = b.work_done_j();
        assert!(
            (work - plain.work_done_j()).abs() < 1e-12 * work,
            "the end sees the same impedance"
        );
        let left = b.absorbed_energy_j() - work;
        println!(
            "{dispersion:?}: energy left {:.2e} of the work",
            left / work
        );
        assert!(
            left.abs() < 1e-5 * work,
            "{dispersion:?}: {left:e} of {work:e} J"
        );
        assert!(b.energy_j().abs() < 1e-5 * work);
        let peak = |r: &[f64]| {
            r.iter().enumerate().fold(
                (0, 0.0f64),
                |(i, m), (j, &x)| if x.abs() > m { (j, x.abs()) } else { (i, m) },
            )
        };
        let plain_mid: Vec<f64> = plain_reads.iter().map(|r| r[0]).collect();
        let ((i0, p0), (i1, p1)) = (peak(&plain_mid), peak(&reads));
        println!(
            "{dispersion:?}: mid-bar peak {p1:.4e} Pa at step {i1}, elementary {p0:.4e} Pa at step {i0}"
        );
        assert!(
            p1 < p0 && i1 >= i0,
            "{dispersion:?}: dispersion delays and spreads the pulse"
        );
    }
}

/// `x` passed through the transit over `cells` cells of the exact first mode, exp(−i d φ(Ω)),
/// φ = Ω (c0/c − 1) (docs/physics.md §6.2.1), evaluated directly on an 8192-point DFT grid
/// (zero-padded) up to Ω = π/4, beyond which [`pulse_n`]'s content is below 1e-300.
fn exact_transit(x: &[f64], cells: f64, radius_cells: f64, poisson_ratio: f64) -> Vec<f64> {
    let n = 8192;
    let mut out = vec![0.0; x.len()];
    for k in 0..=n / 8 {
        let w = 2.0 * PI * k as f64 / n as f64;
        let ratio =
            velocity_ratio_at_normalised_frequency(poisson_ratio, w * radius_cells / (2.0 * PI));
        let phase = cells * w * (1.0 / ratio - 1.0);
        let (mut re, mut im) = (0.0, 0.0);
        for (j, &v) in x.iter().enumerate() {
            re += v * (w * j as f64).cos();
            im -= v * (w * j as f64).sin();
        }
        let (re, im) = (
            re * phase.cos() + im * phase.sin(),
            im * phase.cos() - re * phase.sin(),
        );
        let scale = if k == 0 { 1.0 } else { 2.0 } / n as f64;
        for (j, o) in out.iter_mut().enumerate() {
            *o += scale * (re * (w * j as f64).cos() - im * (w * j as f64).sin());
        }
    }
    out
}

/// Each wave carries the dispersion of the distance it has travelled, from the node that
/// launched it (born half a step after the step that injects it): e + ½ cells to the centre of
/// element e, N cells to the far end node. The stress at an element's centre and the far end's
/// velocity are the elementary delay line's passed through the exact transit over those
/// distances, to the filters' truncation and the mode table's interpolation (1e-8; 1e-6
/// allowed). The rule before, e and N − 1 cells (a wave's first cell left undispersed), is off
/// by about 1e-4 of the peak here.
#[test]
fn each_wave_is_dispersed_over_the_distance_it_travelled() {
    let m = steel();
    let (cells, element, steps) = (1000usize, 300usize, 2000usize);
    let x = (element as f64 + 0.5) * CELL_M;
    let run = |dispersion| {
        let mut b = bar(cells as f64 * CELL_M, DIAMETER_M, dispersion);
        let (mut stress, mut end) = (Vec::new(), Vec::new());
        for n in 0..steps {
            b.step(pulse_n(n as f64 * b.dt_s()), 0.0);
            stress.push(b.stress_at(x));
            end.push(b.half_step_velocity_m_s(cells));
        }
        (stress, end)
    };
    let (plain_stress, plain_end) = run(Dispersion::None);
    let (stress, end) = run(Dispersion::PochhammerChree);
    let radius_cells = 0.5 * DIAMETER_M / CELL_M;
    for (what, got, plain, distance, before) in [
        (
            "stress at element 300",
            &stress,
            &plain_stress,
            element as f64 + 0.5,
            element as f64,
        ),
        (
            "far end velocity",
            &end,
            &plain_end,
            cells as f64,
            cells as f64 - 1.0,
        ),
    ] {
        let expected = exact_transit(plain, distance, radius_cells, m.poisson_ratio);
        let rule_before = exact_transit(plain, before, radius_cells, m.poisson_ratio);
        let peak = plain.iter().fold(0.0f64, |a, &v| a.max(v.abs()));
        let worst = |y: &[f64]| {
            got.iter()
                .zip(y)
                .fold(0.0f64, |a, (g, e)| a.max((g - e).abs()))
                / peak
        };
        let (error, other) = (worst(&expected), worst(&rule_before));
        println!("{what}: {error:.2e} of the peak ({other:.2e} against the rule before)");
        assert!(error < 1e-6, "{what}: {error:e}");
        assert!(other > 100.0 * error, "{what}: {other:e}");
    }
}

/// The x–t fields computed after the run from the histories by FFT are the stresses the bar
/// read step by step: for the first mode to the filters' truncation (1e-8 of the amplitude for
/// each of the two waves at each of the two elements a point reads; 1e-7 allowed); for the
/// Rayleigh–Love band, whose precursor is broad (its band ends below the Love rod's cut-off),
/// to what the causality rule cuts of it within half a metre of the injecting end (1e-5).
#[test]
fn fields_after_the_run_are_the_fields_read_during_it() {
    // Away from the ends, where a wave read step by step has all its precursor (module docs,
    // "Causality": within about 10 cm of the end that launched it, it has not).
    let xs: Vec<f64> = (0..=20).map(|i| 0.25 + i as f64 * 0.025).collect();
    let every = 23;
    for dispersion in [Dispersion::PochhammerChree, Dispersion::RayleighLove] {
        let (b, reads) = drive(bar(1.0, DIAMETER_M, dispersion), 1500, &xs, every);
        let steps: Vec<usize> = (1..=reads.len()).map(|k| k * every).collect();
        let after = b.stress_history(&xs, &steps).unwrap();
        let peak = reads.iter().flatten().fold(0.0f64, |m, &x| m.max(x.abs()));
        let worst = reads
            .iter()
            .flatten()
            .zip(after.iter().flatten())
            .fold(0.0f64, |m, (r, a)| m.max((r - a).abs()));
        println!(
            "{dispersion:?}: largest difference {:.2e} of the peak",
            worst / peak
        );
        let allowed = match dispersion {
            Dispersion::PochhammerChree => 1e-7,
            _ => 1e-5,
        };
        assert!(worst < allowed * peak, "{dispersion:?}: {:e}", worst / peak);
    }
    assert!(
        bar(1.0, DIAMETER_M, Dispersion::None)
            .stress_history(&xs, &[1])
            .is_none()
    );
}

/// A gauge's series computed after the run (what the recorders write for a dispersive bar) is
/// what it read step by step: a 3.3 mm grid (stretch between its ends) and a point.
#[test]
fn gauge_series_after_the_run_are_the_readings() {
    let (xa, xb, x) = (0.49835, 0.50165, 0.6101);
    for dispersion in [Dispersion::PochhammerChree, Dispersion::RayleighLove] {
        let mut b = bar(1.0, DIAMETER_M, dispersion);
        let (mut grid, mut point, mut steps) = (Vec::new(), Vec::new(), Vec::new());
        for n in 0..1200 {
            steps.push(n);
            grid.push(b.stretch_between_m(xa, xb));
            point.push(b.strain_at(x));
            b.step(pulse_n(n as f64 * b.dt_s()), 0.0);
        }
        let grid_after = b.stretch_between_history(xa, xb, &steps).unwrap();
        let point_after = b.strain_history(x, &steps).unwrap();
        for (during, after) in [(&grid, &grid_after), (&point, &point_after)] {
            let peak = during.iter().fold(0.0f64, |m, &v| m.max(v.abs()));
            let worst = during
                .iter()
                .zip(after)
                .fold(0.0f64, |m, (d, a)| m.max((d - a).abs()));
            let allowed = match dispersion {
                Dispersion::PochhammerChree => 1e-7,
                _ => 1e-5,
            };
            assert!(worst < allowed * peak, "{dispersion:?}: {:e}", worst / peak);
        }
    }
}

/// Dispersion on travelling waves needs a delay line: a bar of two segments, or one whose
/// length is not a whole number of cells, is refused with the key and what would do.
#[test]
fn a_bar_that_is_not_a_delay_line_is_refused() {
    let seg = |length_m: f64| Segment {
        length_m,
        diameter_m: DIAMETER_M,
        material: steel(),
    };
    for segments in [vec![seg(0.5), seg(0.5)], vec![seg(1.0005)]] {
        let spec = BarSpec {
            name: "probe".to_string(),
            segments,
            left_end: EndCondition::Free,
            right_end: EndCondition::Absorbing,
            dispersion: Dispersion::PochhammerChree,
        };
        let dt = CELL_M / steel().wave_speed_m_s();
        let message = Bar::new(&spec, dt).unwrap_err().to_string();
        assert!(
            message.contains("dispersion") && message.contains("love-rod"),
            "{message}"
        );
    }
}

/// A full test with `dispersion = "pochhammer-chree"` runs at every preset: at `fast` the 4 mm
/// cell is refined to 10/3 mm, the largest that divides the authors' 1.21, 1.02 and 0.10 m bars;
/// `standard` and `reference` keep their 1 mm.
#[test]
fn a_dispersive_test_runs_at_every_preset() {
    let scene = std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("scenes/shpb-ss440c-10psi.toml");
    let text = |s: &str| shpb::scene::Value::String(s.into());
    let c0 = steel().wave_speed_m_s();
    for (fidelity, cell) in [
        ("fast", 1e-2 / 3.0),
        ("standard", 1e-3),
        ("reference", 1e-3),
    ] {
        let set = [
            ("dispersion".to_string(), text("pochhammer-chree")),
            ("fidelity".to_string(), text(fidelity)),
        ];
        let out = shpb::scene::Params::from_file_overridden(&scene, &set)
            .unwrap()
            .run()
            .unwrap();
        let get = |key: &str| out.summary_value(key).unwrap();
        assert!(
            (get("time_step") * c0 / cell - 1.0).abs() < 1e-12,
            "{fidelity}"
        );
        assert!(
            get("energy_balance_max_relative_error") < 1e-9,
            "{fidelity}"
        );
        assert!(get("peak_contact_force") > 9e3, "{fidelity}");
    }
}

/// A dispersive delay line's momentum (its impulse ledger) is the plain delay line's node sum
/// where dispersion vanishes, and on a free–free bar it is the impulse applied, whatever the
/// dispersion (momentum is conserved by the scheme to rounding).
#[test]
fn momentum_is_the_impulse_applied() {
    let free_bar = |diameter_m: f64, dispersion: Dispersion| {
        let spec = BarSpec {
            name: "probe".to_string(),
            segments: vec![Segment {
                length_m: 0.3,
                diameter_m,
                material: steel(),
            }],
            left_end: EndCondition::Free,
            right_end: EndCondition::Free,
            dispersion,
        };
        Bar::new(&spec, Bar::courant_time_step(&spec, 300)).unwrap()
    };
    let mut plain = free_bar(1e-8, Dispersion::None);
    let mut thin = free_bar(1e-8, Dispersion::PochhammerChree);
    let mut thick = free_bar(DIAMETER_M, Dispersion::PochhammerChree);
    let mut impulse = 0.0;
    for n in 0..1500 {
        let f = pulse_n(n as f64 * plain.dt_s());
        for b in [&mut plain, &mut thin, &mut thick] {
            b.step(f, 0.0);
        }
        impulse += f * plain.dt_s();
        if n % 100 == 99 {
            let p = plain.momentum_kg_m_s();
            assert!(
                (thin.momentum_kg_m_s() - p).abs() <= 1e-12 * impulse.abs(),
                "step {n}"
            );
        }
    }
    // The last step's force is 1e-300 of the peak: level n and n − 1/2 agree.
    let p = thick.momentum_kg_m_s();
    assert!(
        (p - impulse).abs() <= 1e-12 * impulse.abs(),
        "{p} vs {impulse}"
    );
}
