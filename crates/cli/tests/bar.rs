//! The bar wave guide (physics.md §6): striker impact, impedance interfaces, end conditions, the
//! Love rod's dispersion and input validation, each checked against closed-form 1D wave physics.
//!
//! Most checks run at Courant number 1, where the lumped chain is exact (d'Alembert at the nodes,
//! exact mirrors and interface coefficients, exactly non-reflecting dashpot ends); their
//! tolerances (1e-9) only cover floating-point rounding over ~10³ steps. Cases off Courant 1 use
//! the looser tolerances of the brief and print the error they actually reach.

use shpb::bar::{
    Bar, BarMaterial, BarSpec, Dispersion, EndCondition, Segment, measure_phase_velocity,
    rigid_contact_force_n,
};
use shpb::error::Error;
use std::f64::consts::PI;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// Maraging steel of the authors' bars (E, ρ from the brief; ν = 0.31 as in the Bancroft fit, physics.md §7).
fn maraging() -> BarMaterial {
    BarMaterial {
        density_kg_m3: 8110.0,
        youngs_modulus_pa: 192e9,
        poisson_ratio: 0.31,
    }
}

/// Aluminium 7075-T6 (handbook values), about a third of the steel's impedance.
fn aluminium() -> BarMaterial {
    BarMaterial {
        density_kg_m3: 2810.0,
        youngs_modulus_pa: 71.7e9,
        poisson_ratio: 0.33,
    }
}

const DIAMETER_M: f64 = 19.05e-3;

fn seg(length_m: f64, diameter_m: f64, material: BarMaterial) -> Segment {
    Segment {
        length_m,
        diameter_m,
        material,
    }
}

fn spec(name: &str, segments: Vec<Segment>, left: EndCondition, right: EndCondition) -> BarSpec {
    BarSpec {
        name: name.to_string(),
        segments,
        left_end: left,
        right_end: right,
        dispersion: Dispersion::None,
    }
}

/// Half-sine force pulse of duration `tau_s` (compressive on a left end), N.
fn half_sine(t_s: f64, tau_s: f64, peak_n: f64) -> f64 {
    if t_s < tau_s {
        peak_n * (PI * t_s / tau_s).sin()
    } else {
        0.0
    }
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

// ---------------------------------------------------------------------------------------------
// 1. Striker on incident bar
// ---------------------------------------------------------------------------------------------

/// Linearly interpolated times at which |ε| first rises through and last falls through `level`.
fn crossing_times(record: &[f64], level: f64, dt: f64) -> (f64, f64) {
    let a: Vec<f64> = record.iter().map(|x| x.abs()).collect();
    let first = a.iter().position(|&x| x >= level).expect("pulse present");
    let last = a.iter().rposition(|&x| x >= level).expect("pulse present");
    let rise = if first == 0 {
        0.0
    } else {
        (first - 1) as f64 + (level - a[first - 1]) / (a[first] - a[first - 1])
    };
    let fall = last as f64 + (a[last] - level) / (a[last] - a[last + 1]);
    (rise * dt, fall * dt)
}

#[test]
fn striker_impact_gives_the_elementary_pulse_and_conserves_energy() {
    let m = maraging();
    let c0 = m.wave_speed_m_s();
    assert!((c0 - 4865.5).abs() < 0.5, "c0 = {c0}"); // √(192e9/8110) = 4865.64
    let v0 = 10.0;
    let (ls, lb) = (0.1, 1.2);
    let striker_spec = spec(
        "striker",
        vec![seg(ls, DIAMETER_M, m)],
        EndCondition::Free,
        EndCondition::Free,
    );
    let bar_spec = spec(
        "incident",
        vec![seg(lb, DIAMETER_M, m)],
        EndCondition::Free,
        EndCondition::Absorbing,
    );
    let n_s = 100;
    let dt = Bar::courant_time_step(&striker_spec, n_s);
    let mut striker = Bar::new(&striker_spec, dt).unwrap();
    let mut bar = Bar::new(&bar_spec, dt).unwrap();
    // Both at Courant 1 (1.2 m is a multiple of c0Δt = 1 mm).
    assert_eq!(bar.segment_cells(0), 1200);
    assert!((striker.courant_number(0) - 1.0).abs() < 1e-12);
    assert!((bar.courant_number(0) - 1.0).abs() < 1e-12);

    striker.set_initial_velocity(v0);
    let area = PI * DIAMETER_M * DIAMETER_M / 4.0;
    let ke0 = striker.kinetic_energy_j();
    assert!(rel(ke0, 0.5 * m.density_kg_m3 * area * ls * v0 * v0) < 1e-12);
    assert_eq!(striker.strain_energy_j(), 0.0);

    // A gauge at 0.6 m, and the element whose centre is next to it (0.6005 m) for the pulse integrals.
    let gauge_x = 0.6;
    let gauge_element = 600;
    let energy = |s: &Bar, b: &Bar| {
        s.kinetic_energy_j()
            + s.strain_energy_j()
            + b.kinetic_energy_j()
            + b.strain_energy_j()
            + b.absorbed_energy_j()
    };
    // The tail leaves the absorbing end after (L_b + 2 L_s)/c0 = 1400 steps.
    let steps = 1600;
    let mut gauge = Vec::with_capacity(steps);
    let mut element = Vec::with_capacity(steps);
    let mut totals = Vec::with_capacity(steps);
    let mut ledger_error: f64 = 0.0;
    let mut last_contact_step = 0;
    let mut peak_force: f64 = 0.0;
    for n in 0..steps {
        let f = rigid_contact_force_n(&striker, &bar, 0.0);
        assert!(f >= 0.0);
        // A force above rounding (a delay line leaves ~1e-16 v0 at the separated faces, whose
        // contact then carries ~1e-26 N).
        peak_force = peak_force.max(f);
        if f > 1e-12 * peak_force {
            last_contact_step = n;
        }
        striker.step(0.0, -f);
        bar.step(f, 0.0);
        gauge.push(bar.strain_at(gauge_x));
        element.push(bar.element_strain(gauge_element));
        let e = energy(&striker, &bar);
        totals.push(e);
        // Exact discrete balance: energy + absorbed − work of the contact forces = initial energy.
        ledger_error =
            ledger_error.max((e - striker.work_done_j() - bar.work_done_j() - ke0).abs() / ke0);
    }
    striker.check_finite().unwrap();
    bar.check_finite().unwrap();

    // Amplitude v/(2c0): exact at Courant 1 (brief: 0.1 %).
    let amplitude = v0 / (2.0 * c0);
    let peak = gauge.iter().fold(0.0f64, |a, &x| a.min(x));
    println!(
        "incident strain {peak:e} vs −v/(2c0) = {:e}: rel. error {:e}",
        -amplitude,
        rel(-peak, amplitude)
    );
    assert!(rel(-peak, amplitude) < 1e-9);
    assert!(gauge.iter().all(|&x| x <= 1e-15), "compressive pulse only");
    // Flat top: every sample above 10 % of the amplitude is on the plateau, except the two edge
    // samples of a gauge between element centres (there: exactly half).
    let off_plateau = gauge
        .iter()
        .filter(|&&x| x.abs() > 0.1 * amplitude && rel(x.abs(), amplitude) > 1e-9)
        .count();
    assert!(off_plateau <= 2, "{off_plateau} samples off the plateau");

    // Duration at half amplitude: 2 L_s/c0 within one step.
    let (rise, fall) = crossing_times(&gauge, 0.5 * amplitude, dt);
    let duration = fall - rise;
    println!(
        "pulse length {duration:e} s vs 2L/c0 = {:e} s (Δt = {dt:e} s)",
        2.0 * ls / c0
    );
    assert!((duration - 2.0 * ls / c0).abs() <= dt);
    // It arrives at the gauge after (x/c0) (the front passes the face node at step 0).
    assert!((rise - gauge_x / c0).abs() <= dt, "arrival {rise:e} s");

    // Energy: the exact discrete ledger, and conservation of KE + SE + absorbed from the first
    // step on (the closed contact does no work: both face nodes move together).
    println!("ledger error {ledger_error:e}");
    assert!(ledger_error < 1e-9);
    let drift = totals
        .iter()
        .map(|e| (e - totals[0]).abs() / ke0)
        .fold(0.0, f64::max);
    println!("energy drift after the first step {drift:e} (brief: 1e-6)");
    assert!(drift < 1e-9);
    // The first step merges the two face half-nodes (v0 and 0): the discrete counterpart of the
    // velocity jump, ½·(m/4)·v0² with m = ρAΔx, i.e. KE0/(4 n_s) (module docs, "Energy").
    let cell_mass = m.density_kg_m3 * area * (ls / n_s as f64);
    let impact_term = cell_mass * v0 * v0 / 8.0;
    println!(
        "first-step energy term {:e} J = KE0 × {:e} (1/(4 n_s) = {:e})",
        ke0 - totals[0],
        (ke0 - totals[0]) / ke0,
        0.25 / n_s as f64
    );
    assert!(rel(ke0 - totals[0], impact_term) < 1e-6);

    // Equal impedance: the striker stops and separates when the release wave returns (2L_s/c0).
    assert!(
        (last_contact_step as f64 - 2.0 * n_s as f64).abs() <= 1.0,
        "contact ended at step {last_contact_step}"
    );
    let striker_speed = (0..striker.node_count())
        .map(|i| striker.half_step_velocity_m_s(i).abs())
        .fold(0.0, f64::max);
    println!("striker speed after separation {striker_speed:e} m/s");
    assert!(striker_speed < 1e-9 * v0);
    assert!(striker.kinetic_energy_j() + striker.strain_energy_j().abs() < 1e-12 * ke0);
    // Everything has left through the absorbing end.
    assert!(bar.kinetic_energy_j() + bar.strain_energy_j().abs() < 1e-12 * ke0);
    let absorbed = bar.absorbed_energy_j();
    println!(
        "absorbed {absorbed:e} J, KE0 {ke0:e} J: absorbed/KE0 − 1 = {:e}",
        absorbed / ke0 - 1.0
    );
    assert!(rel(absorbed, ke0 - impact_term) < 1e-9);

    // The physical content of the recorded pulse: energy A E c0 ∫ε² dt and impulse A E ∫|ε| dt
    // equal the striker's KE0 and momentum m_s v0 (physics.md §6 momentum check): exact here.
    let e_a = m.youngs_modulus_pa * area;
    let pulse_energy: f64 = element.iter().map(|x| e_a * c0 * x * x * dt).sum();
    let impulse: f64 = element.iter().map(|x| e_a * x.abs() * dt).sum();
    let momentum = m.density_kg_m3 * area * ls * v0;
    println!(
        "gauge pulse energy/KE0 − 1 = {:e}, impulse/(m_s v0) − 1 = {:e}",
        pulse_energy / ke0 - 1.0,
        impulse / momentum - 1.0
    );
    assert!(rel(pulse_energy, ke0) < 1e-9);
    assert!(rel(impulse, momentum) < 1e-9);
}

// ---------------------------------------------------------------------------------------------
// 2. Impedance interfaces
// ---------------------------------------------------------------------------------------------

struct InterfaceResult {
    reflection: f64,
    transmission: f64,
    expected_reflection: f64,
    expected_transmission: f64,
    waveform_error: f64,
    courant2: f64,
}

/// A half-sine force pulse from the absorbing left end of segment 1 (1 m, 1000 cells) onto
/// segment 2 (`cells2` × c2Δt long): stress at the node 500 cells before the interface and at the
/// node 200 cells after it (node gauges: the mean of the two adjacent elements, module docs).
fn interface_case(s1: (f64, BarMaterial), s2: (f64, BarMaterial), cells2: f64) -> InterfaceResult {
    let (d1, m1) = s1;
    let (d2, m2) = s2;
    let cells1 = 1000;
    let l1 = 1.0;
    let dt = l1 / (m1.wave_speed_m_s() * cells1 as f64);
    let l2 = cells2 * m2.wave_speed_m_s() * dt;
    let spec = spec(
        "interface",
        vec![seg(l1, d1, m1), seg(l2, d2, m2)],
        EndCondition::Absorbing,
        EndCondition::Absorbing,
    );
    let mut bar = Bar::new(&spec, dt).unwrap();
    assert_eq!(bar.segment_cells(0), cells1);
    let (i1, i2) = (500, cells1 + 200);
    let (x1, x2) = (bar.node_position_m(i1), bar.node_position_m(i2));
    let delay_r = 2 * (cells1 - i1);
    let delay_t = (cells1 - i1) + (i2 - cells1);
    let tau = 20e-6;
    // The incident pulse passes gauge 1 during steps ≈ 500..600, its echo ≈ 1500..1600.
    let steps = 2 * delay_r;
    let (mut s_1, mut s_2) = (Vec::new(), Vec::new());
    for n in 0..steps {
        s_1.push(bar.stress_at(x1));
        s_2.push(bar.stress_at(x2));
        bar.step(half_sine(n as f64 * dt, tau, 1e4), 0.0);
    }
    bar.check_finite().unwrap();
    // Incident: everything at gauge 1 before a reflection can arrive.
    let incident: Vec<f64> = s_1[..delay_r].to_vec();
    let reflected: Vec<f64> = s_1[delay_r..].to_vec();
    let peak_i = max_abs(&incident);
    let (z1, z2) = (
        spec.segments[0].impedance_kg_s(),
        spec.segments[1].impedance_kg_s(),
    );
    let (a1, a2) = (spec.segments[0].area_m2(), spec.segments[1].area_m2());
    let expected_reflection = (z2 - z1) / (z1 + z2);
    // Force transmission 2Z2/(Z1+Z2); stress = force/area.
    let expected_transmission = 2.0 * z2 / (z1 + z2) * a1 / a2;
    let mut waveform_error: f64 = 0.0;
    for n in 0..steps {
        if n >= delay_r {
            let want = expected_reflection * incident[n - delay_r];
            waveform_error = waveform_error.max((s_1[n] - want).abs() / peak_i);
        }
        // (The incident pulse has passed gauge 1 long before step delay_r.)
        let want_t = match n.checked_sub(delay_t) {
            Some(j) if j < delay_r => expected_transmission * incident[j],
            _ => 0.0,
        };
        waveform_error = waveform_error.max((s_2[n] - want_t).abs() / peak_i);
    }
    // Signed peak ratios (the incident pulse is compressive).
    let signed_peak = |x: &[f64]| {
        x.iter()
            .fold(0.0f64, |a, &v| if v.abs() > a.abs() { v } else { a })
    };
    InterfaceResult {
        reflection: signed_peak(&reflected) / signed_peak(&incident),
        transmission: signed_peak(&s_2) / signed_peak(&incident),
        expected_reflection,
        expected_transmission,
        waveform_error,
        courant2: bar.courant_number(1),
    }
}

#[test]
fn interfaces_reflect_and_transmit_with_the_impedance_coefficients() {
    let (st, al) = (maraging(), aluminium());
    let small = 12.7e-3;
    let cases = [
        (
            "steel → aluminium (Z2 < Z1)",
            (DIAMETER_M, st),
            (DIAMETER_M, al),
        ),
        (
            "aluminium → steel (Z2 > Z1)",
            (DIAMETER_M, al),
            (DIAMETER_M, st),
        ),
        ("19.05 → 12.7 mm (Z2 < Z1)", (DIAMETER_M, st), (small, st)),
        ("12.7 → 19.05 mm (Z2 > Z1)", (small, st), (DIAMETER_M, st)),
    ];
    for (label, s1, s2) in cases {
        // Segment 2 a multiple of c2Δt: both segments at Courant 1, the interface exact.
        let r = interface_case(s1, s2, 800.0);
        println!(
            "{label}: R {:.9} (theory {:.9}), T {:.9} (theory {:.9}), waveform error {:e}",
            r.reflection,
            r.expected_reflection,
            r.transmission,
            r.expected_transmission,
            r.waveform_error
        );
        assert!((r.courant2 - 1.0).abs() < 1e-12);
        assert!(r.waveform_error < 1e-9, "{label}");
        assert!(rel(r.reflection, r.expected_reflection) < 1e-9, "{label}");
        assert!(
            rel(r.transmission, r.expected_transmission) < 1e-9,
            "{label}"
        );
        // Same-material stress check of the brief: with equal areas σ_T/σ_I = 2Z2/(Z1+Z2).
        if s1.0 == s2.0 {
            let (z1, z2) = (
                seg(1.0, s1.0, s1.1).impedance_kg_s(),
                seg(1.0, s2.0, s2.1).impedance_kg_s(),
            );
            assert!(rel(r.transmission, 2.0 * z2 / (z1 + z2)) < 1e-9);
        }
    }
    // Segment 2 not a multiple of c2Δt (800.5 cells' worth): Courant < 1 there, numerical
    // dispersion in it and a slightly frequency-dependent interface.
    for (label, s1, s2) in [
        (
            "steel → aluminium, off Courant 1",
            (DIAMETER_M, st),
            (DIAMETER_M, al),
        ),
        (
            "aluminium → steel, off Courant 1",
            (DIAMETER_M, al),
            (DIAMETER_M, st),
        ),
    ] {
        let r = interface_case(s1, s2, 800.5);
        let (er, et) = (
            rel(r.reflection, r.expected_reflection),
            rel(r.transmission, r.expected_transmission),
        );
        println!(
            "{label}: Courant {:.6} in segment 2: R error {er:e}, T error {et:e}",
            r.courant2
        );
        assert!(r.courant2 < 1.0);
        assert!(er < 5e-3 && et < 5e-3, "{label}");
    }
}

// ---------------------------------------------------------------------------------------------
// 3. End conditions
// ---------------------------------------------------------------------------------------------

/// A compressive force pulse `force(t)` on the absorbing left end of a `length_m` bar with cells
/// of c0Δt = 1 mm onto `right`: the strain at the node 500 cells before the right end, that node,
/// and the bar afterwards.
fn end_case(
    right: EndCondition,
    length_m: f64,
    force: impl Fn(f64) -> f64,
) -> (Vec<f64>, usize, Bar) {
    let m = maraging();
    let spec = spec(
        "end",
        vec![seg(length_m, DIAMETER_M, m)],
        EndCondition::Absorbing,
        right,
    );
    let dt = 1e-3 / m.wave_speed_m_s();
    let mut bar = Bar::new(&spec, dt).unwrap();
    let cells = bar.element_count();
    let node = cells - 500;
    let x = bar.node_position_m(node);
    // Until the echo has also left through the absorbing left end.
    let steps = 2 * cells + 200;
    let mut rec = Vec::with_capacity(steps);
    for n in 0..steps {
        rec.push(bar.strain_at(x));
        bar.step(force(n as f64 * dt), 0.0);
    }
    bar.check_finite().unwrap();
    (rec, node, bar)
}

#[test]
fn free_fixed_and_absorbing_ends_reflect_as_the_wave_equation_says() {
    let m = maraging();
    let ea = m.youngs_modulus_pa * PI * DIAMETER_M * DIAMETER_M / 4.0;
    let tau = 20e-6;
    let force = |t: f64| half_sine(t, tau, 1e4);
    for (right, sign) in [
        (EndCondition::Free, -1.0),
        (EndCondition::Fixed, 1.0),
        (EndCondition::Absorbing, 0.0),
    ] {
        let (rec, node, bar) = end_case(right, 1.0, force);
        assert!((bar.courant_number(0) - 1.0).abs() < 1e-12);
        let dt = bar.dt_s();
        let delay = 2 * (bar.element_count() - node);
        let incident: Vec<f64> = rec[..delay].to_vec();
        let peak = max_abs(&incident);
        // The driven absorbing end splits the force equally between its dashpot and the bar:
        // at a node, ε(t) = −F(t − x/c0)/(2EA) exactly at Courant 1.
        let drive_error = incident
            .iter()
            .enumerate()
            .map(|(n, e)| {
                let want = if n >= node {
                    -force((n - node) as f64 * dt) / (2.0 * ea)
                } else {
                    0.0
                };
                (e - want).abs() / peak
            })
            .fold(0.0, f64::max);
        assert!(drive_error < 1e-9, "{right:?}: drive error {drive_error:e}");
        let sampled_peak = (0..delay).map(|n| force(n as f64 * dt)).fold(0.0, f64::max);
        assert!(rel(peak, sampled_peak / (2.0 * ea)) < 1e-9);
        let mut err: f64 = 0.0;
        for n in delay..rec.len().min(2 * delay) {
            err = err.max((rec[n] - sign * incident[n - delay]).abs() / peak);
        }
        let reflected_peak = rec[delay..]
            .iter()
            .fold(0.0f64, |a, &v| if v.abs() > a.abs() { v } else { a });
        let energy_i: f64 = incident.iter().map(|x| x * x).sum();
        let energy_r: f64 = rec[delay..].iter().map(|x| x * x).sum();
        println!(
            "{right:?} end: reflected/incident peak {:+.12}, waveform error {err:e}, reflected energy fraction {:e}",
            reflected_peak / -peak,
            energy_r / energy_i
        );
        assert!(err < 1e-9, "{right:?}");
        match right {
            // Free end: tension of equal amplitude; fixed end: compression of equal amplitude.
            EndCondition::Free => assert!(rel(reflected_peak, peak) < 1e-9),
            EndCondition::Fixed => assert!(rel(reflected_peak, -peak) < 1e-9),
            // Exactly non-reflecting at Courant 1: only rounding is left (brief: < 1e-6).
            EndCondition::Absorbing => assert!(energy_r / energy_i < 1e-12),
        }
        // Every wave has left through the absorbing end(s): all the work done went there. The
        // slope kinks of the half-sine leave a standing odd–even (checkerboard) displacement
        // ±H(−1)^{i+n} behind the pulse: at Courant 1 it has zero discrete energy (its kinetic
        // and strain parts cancel), so it is seen here only in the split, and not at node gauges.
        let w = bar.work_done_j();
        assert!(w > 0.0);
        assert!(rel(bar.absorbed_energy_j(), w) < 1e-9, "{right:?}");
        assert!((bar.kinetic_energy_j() + bar.strain_energy_j()).abs() < 1e-12 * w);
        println!(
            "  left behind: kinetic part of the checkerboard {:e} of the work",
            bar.kinetic_energy_j() / w
        );
    }
}

#[test]
fn absorbing_end_off_courant_one_reflects_as_little_as_the_analysis_says() {
    // 1.0005 m at c0Δt = 1 mm: 1000 cells at Courant r = 0.9995. A smooth (sin², C¹) 20 µs
    // pulse spans ~97 steps, so its energy sits at θ = κΔx ≲ 0.1, where the dashpot's
    // reflection R ≈ −(1 − r²)θ²/16 ≲ 1e-6: the reflected energy fraction ≲ R² ≪ 1e-6.
    let tau = 20e-6;
    let smooth = |t: f64| {
        if t < tau {
            1e4 * (PI * t / tau).sin().powi(2)
        } else {
            0.0
        }
    };
    let (rec, _, bar) = end_case(EndCondition::Absorbing, 1.0005, smooth);
    let r = bar.courant_number(0);
    assert!(r < 1.0 && r > 0.999);
    let split = 1000;
    let energy_i: f64 = rec[..split].iter().map(|x| x * x).sum();
    let energy_r: f64 = rec[split..].iter().map(|x| x * x).sum();
    println!(
        "Courant {r:.6}: reflected energy fraction {:e}",
        energy_r / energy_i
    );
    assert!(energy_r / energy_i < 1e-6);
}

// ---------------------------------------------------------------------------------------------
// 4. Love rod
// ---------------------------------------------------------------------------------------------

/// Rayleigh–Love phase velocity c/c0 = 1/√(1 + ν²k²a²/2), written out independently of the crate.
fn rayleigh_love(nu: f64, ka: f64) -> f64 {
    1.0 / (1.0 + nu * nu * ka * ka / 2.0).sqrt()
}

/// Wavenumber of ω in the discrete Love scheme on a uniform grid at Courant 1:
/// sin²(ωΔt/2)(1 + 4γS²) = S², S = sin(kΔx/2), γ = ν²a²/(2Δx²).
fn discrete_love_wavenumber(nu: f64, a: f64, dx: f64, dt: f64, omega: f64) -> f64 {
    let gamma = nu * nu * a * a / (2.0 * dx * dx);
    let p = (omega * dt / 2.0).sin().powi(2);
    let s2 = p / (1.0 - 4.0 * gamma * p);
    2.0 / dx * s2.sqrt().asin()
}

#[test]
fn love_rod_phase_velocity_follows_rayleigh_love() {
    let m = maraging();
    let c0 = m.wave_speed_m_s();
    let a = DIAMETER_M / 2.0;
    let nu = m.poisson_ratio;
    for y in [0.05, 0.1, 0.2, 0.3] {
        let k = 2.0 * PI * y / a;
        let c_rl = c0 * rayleigh_love(nu, k * a);
        let omega = k * c_rl;
        // 20 cells per wavelength: the scheme's own error is ~1e-6 at Courant 1 (fourth order).
        let cell = 2.0 * PI / k / 20.0;
        let meas = measure_phase_velocity(m, DIAMETER_M, Dispersion::LoveRod, omega, cell).unwrap();
        let k_disc = discrete_love_wavenumber(nu, a, meas.cell_m, meas.dt_s, omega);
        let err_rl = meas.phase_velocity_m_s / c_rl - 1.0;
        let err_disc = meas.wavenumber_rad_m / k_disc - 1.0;
        println!(
            "a/Λ = {y}: c/c0 sim {:.6}, Rayleigh–Love {:.6}: error {err_rl:+.2e}; vs discrete relation {err_disc:+.2e}; amplitude ratio {:.6}; {} nodes × {} steps",
            meas.phase_velocity_m_s / c0,
            c_rl / c0,
            meas.amplitude_ratio,
            meas.nodes,
            meas.steps
        );
        assert!(err_rl.abs() < 5e-3, "a/Λ = {y}: {err_rl:e}");
        // The measurement itself resolves the scheme's relation to 1e-4 and sees no attenuation.
        assert!(err_disc.abs() < 1e-4, "a/Λ = {y}: {err_disc:e}");
        assert!((meas.amplitude_ratio - 1.0).abs() < 1e-3);
        // Control: without the Love term the same harness measures c0 (exact at Courant 1).
        let plain = measure_phase_velocity(m, DIAMETER_M, Dispersion::None, omega, cell).unwrap();
        assert!(
            rel(plain.phase_velocity_m_s, c0) < 1e-5,
            "{}",
            plain.phase_velocity_m_s / c0
        );
    }
}

#[test]
fn love_rod_scheme_converges_to_rayleigh_love_with_the_grid() {
    // Against the continuum relation, the discrete Love scheme at Courant 1 errs by O((kΔx)⁴):
    // doubling the cells per wavelength divides the error by ≈ 16 (2nd order would give 4).
    let m = maraging();
    let c0 = m.wave_speed_m_s();
    let a = DIAMETER_M / 2.0;
    let y = 0.3;
    let k = 2.0 * PI * y / a;
    let c_rl = c0 * rayleigh_love(m.poisson_ratio, k * a);
    let omega = k * c_rl;
    let errors: Vec<f64> = [4.0, 8.0]
        .iter()
        .map(|cpw| {
            let cell = 2.0 * PI / k / cpw;
            let meas =
                measure_phase_velocity(m, DIAMETER_M, Dispersion::LoveRod, omega, cell).unwrap();
            let e = meas.phase_velocity_m_s / c_rl - 1.0;
            println!("{cpw} cells per wavelength: c/c_RL − 1 = {e:+.3e}");
            e
        })
        .collect();
    let ratio = errors[0] / errors[1];
    assert!(ratio > 8.0, "error ratio {ratio}");
}

// ---------------------------------------------------------------------------------------------
// 5. Validation and stability limits
// ---------------------------------------------------------------------------------------------

fn input_error(e: impl Into<Error>) -> (String, String, String, String) {
    match e.into() {
        Error::Input {
            file,
            key,
            problem,
            allowed,
        } => (file, key, problem, allowed),
        other => panic!("expected an input error, got {other}"),
    }
}

#[test]
fn a_time_step_above_the_stability_limit_is_refused_naming_the_limit() {
    let m = maraging();
    // A 0.4 mm segment between two 0.2 m ones: at c0Δt = 1 mm it gets one cell at Courant 2.5.
    let s = spec(
        "adapter",
        vec![
            seg(0.2, DIAMETER_M, m),
            seg(0.4e-3, DIAMETER_M, m),
            seg(0.2, DIAMETER_M, m),
        ],
        EndCondition::Free,
        EndCondition::Free,
    );
    let dt = 1e-3 / m.wave_speed_m_s();
    let cells = s.cells_for_time_step(dt);
    assert_eq!(cells, vec![200, 1, 200]);
    let limit = s.stability_limit_s(&cells).unwrap();
    assert!(limit < dt);
    let (file, key, problem, allowed) = input_error(Bar::new(&s, dt).unwrap_err());
    println!("{file}: {key}: {problem}; allowed: {allowed}");
    assert_eq!(file, "bar adapter");
    assert_eq!(key, "time_step_s");
    assert!(allowed.contains(&format!("{limit:e}")), "{allowed}");
    assert!(problem.contains("segment 1"), "{problem}");
    // A smaller step refines the long segments and lowers the limit; the largest accepted step
    // (named in the message too) is a fixed point Δt = limit(grid(Δt)).
    let best = s.max_time_step_s().unwrap();
    assert!(allowed.contains(&format!("{best:e}")), "{allowed}");
    assert!(best > s.courant_limit_s() && best < limit);
    let mut bar = Bar::new(&s, best).unwrap();
    assert_eq!(bar.segment_cells(1), 1);
    assert!(rel(bar.stability_limit_s(), best) < 1e-5);
    assert!(Bar::new(&s, best * (1.0 + 1e-4)).is_err());
    // At the limit it stays bounded: the energy ledger closes after 2e4 steps.
    for n in 0..20_000 {
        bar.step(half_sine(n as f64 * bar.dt_s(), 5e-6, 1e3), 0.0);
    }
    bar.check_finite().unwrap();
    let e = bar.kinetic_energy_j() + bar.strain_energy_j();
    assert!(
        rel(e, bar.work_done_j()) < 1e-9,
        "energy {e:e} vs work {:e}",
        bar.work_done_j()
    );
    // Every step up to min L/c0 (each segment a full cell at Courant ≤ 1) is accepted.
    assert!(Bar::new(&s, s.courant_limit_s()).is_ok());
}

#[test]
fn stability_limits_match_the_closed_forms() {
    let m = maraging();
    let c0 = m.wave_speed_m_s();
    let a = DIAMETER_M / 2.0;
    let mut s = spec(
        "uniform",
        vec![seg(0.5, DIAMETER_M, m)],
        EndCondition::Free,
        EndCondition::Absorbing,
    );
    for cells in [10, 100, 500] {
        let dx = 0.5 / cells as f64;
        s.dispersion = Dispersion::None;
        let lumped = s.stability_limit_s(&[cells]).unwrap();
        assert!(rel(lumped, dx / c0) < 1e-10, "{lumped} vs {}", dx / c0);
        // Love: c0Δt/Δx ≤ √(1 + 2ν²a²/Δx²).
        s.dispersion = Dispersion::LoveRod;
        let love = s.stability_limit_s(&[cells]).unwrap();
        let want = dx / c0 * (1.0 + 2.0 * (m.poisson_ratio * a / dx).powi(2)).sqrt();
        assert!(rel(love, want) < 1e-10, "{love} vs {want}");
        // And the built bar at Courant 1 is accepted.
        assert!(Bar::new(&s, dx / c0).is_ok());
    }
}

#[test]
fn bad_geometry_and_time_steps_are_refused() {
    let m = maraging();
    for (length, diameter, key) in [
        (-1.0, DIAMETER_M, "segments[0].length_m"),
        (f64::NAN, DIAMETER_M, "segments[0].length_m"),
        (0.0, DIAMETER_M, "segments[0].length_m"),
        (1.0, -0.01, "segments[0].diameter_m"),
        (1.0, f64::NAN, "segments[0].diameter_m"),
        (1.0, f64::INFINITY, "segments[0].diameter_m"),
    ] {
        let s = spec(
            "probe",
            vec![seg(length, diameter, m)],
            EndCondition::Free,
            EndCondition::Free,
        );
        let (file, k, _, _) = input_error(s.validate().unwrap_err());
        assert_eq!((file.as_str(), k.as_str()), ("bar probe", key));
        let (_, k, _, _) = input_error(Bar::new(&s, 1e-7).unwrap_err());
        assert_eq!(k, key);
    }
    let mut bad = m;
    bad.density_kg_m3 = f64::NAN;
    let s = spec(
        "probe",
        vec![seg(1.0, DIAMETER_M, bad)],
        EndCondition::Free,
        EndCondition::Free,
    );
    let (_, k, _, _) = input_error(s.validate().unwrap_err());
    assert_eq!(k, "segments[0].material.density_kg_m3");
    let empty = spec("probe", vec![], EndCondition::Free, EndCondition::Free);
    assert_eq!(input_error(empty.validate().unwrap_err()).1, "segments");
    let good = spec(
        "probe",
        vec![seg(1.0, DIAMETER_M, m)],
        EndCondition::Free,
        EndCondition::Free,
    );
    for dt in [0.0, -1e-7, f64::NAN, f64::INFINITY] {
        assert_eq!(
            input_error(Bar::new(&good, dt).unwrap_err()).1,
            "time_step_s"
        );
    }
    // Too fine a time step for memory is refused, not attempted.
    assert_eq!(
        input_error(Bar::new(&good, 1e-15).unwrap_err()).1,
        "time_step_s"
    );
}

// ---------------------------------------------------------------------------------------------
// Other guarantees other modules rely on
// ---------------------------------------------------------------------------------------------

#[test]
fn grid_rule_positions_and_interpolation() {
    let (st, al) = (maraging(), aluminium());
    let s = spec(
        "two",
        vec![seg(0.3, DIAMETER_M, st), seg(0.2, 12.7e-3, al)],
        EndCondition::Free,
        EndCondition::Fixed,
    );
    let dt = 0.3 / (st.wave_speed_m_s() * 300.0);
    let bar = Bar::new(&s, dt).unwrap();
    let n2 = (0.2 / (al.wave_speed_m_s() * dt)).floor() as usize;
    assert_eq!((bar.segment_cells(0), bar.segment_cells(1)), (300, n2));
    assert_eq!(bar.node_count(), 300 + n2 + 1);
    assert!(bar.courant_number(1) <= 1.0 && bar.courant_number(1) > n2 as f64 / (n2 + 1) as f64);
    assert_eq!(bar.node_position_m(0), 0.0);
    assert!((bar.node_position_m(300) - 0.3).abs() < 1e-15);
    assert!((bar.node_position_m(bar.node_count() - 1) - 0.5).abs() < 1e-15);
    // Interface node: half a cell of each segment.
    let half = |d: f64, mat: BarMaterial, dx: f64| 0.5 * mat.density_kg_m3 * PI * d * d / 4.0 * dx;
    let want = half(DIAMETER_M, st, 0.3 / 300.0) + half(12.7e-3, al, 0.2 / n2 as f64);
    assert!(rel(bar.node_mass_kg(300), want) < 1e-12);
}

#[test]
fn strain_interpolates_between_element_centres_within_a_segment() {
    let m = maraging();
    let s = spec(
        "ramp",
        vec![seg(0.1, DIAMETER_M, m)],
        EndCondition::Free,
        EndCondition::Free,
    );
    let dt = 0.1 / (m.wave_speed_m_s() * 10.0);
    let mut bar = Bar::new(&s, dt).unwrap();
    // One step with a pull on the right end: only the last element is strained.
    bar.step(0.0, 1e4);
    let n = bar.element_count();
    let last = bar.element_strain(n - 1);
    assert!(last > 0.0);
    let dx = bar.cell_size_m(0);
    assert_eq!(bar.strain_at(bar.element_centre_m(n - 1)), last);
    assert!(
        rel(bar.strain_at(0.1 - 0.25 * dx), last) < 1e-12,
        "constant beyond the last centre"
    );
    let mid = bar.strain_at(bar.element_centre_m(n - 2) + 0.25 * dx);
    assert!(rel(mid, 0.25 * last) < 1e-12);
    assert!(rel(bar.stress_at(0.1), m.youngs_modulus_pa * last) < 1e-12);
    assert!(
        rel(
            bar.end_force_n(true),
            m.youngs_modulus_pa * PI * DIAMETER_M.powi(2) / 4.0 * last
        ) < 1e-12
    );
}

#[test]
fn integer_level_velocity_is_the_mean_of_the_half_steps_under_a_held_force() {
    let m = maraging();
    for dispersion in [Dispersion::None, Dispersion::LoveRod] {
        let mut s = spec(
            "v",
            vec![seg(0.2, DIAMETER_M, m)],
            EndCondition::Free,
            EndCondition::Absorbing,
        );
        s.dispersion = dispersion;
        let dt = Bar::courant_time_step(&s, 100);
        let mut bar = Bar::new(&s, dt).unwrap();
        let f = 2e3;
        bar.step(f, 0.0);
        for _ in 0..30 {
            let predicted: Vec<f64> = (0..bar.node_count()).map(|i| bar.velocity_m_s(i)).collect();
            let before: Vec<f64> = (0..bar.node_count())
                .map(|i| bar.half_step_velocity_m_s(i))
                .collect();
            let free = bar.free_end_velocity_m_s(false);
            let mobility = bar.end_mobility_s_per_kg(false, false);
            bar.step(f, 0.0);
            let got = bar.half_step_velocity_m_s(0);
            assert!(
                (got - (free + mobility * f)).abs() <= 1e-12 * (free.abs() + (mobility * f).abs()),
                "{dispersion:?}: {got:e} vs {free:e} + {:e}",
                mobility * f
            );
            for (i, (p, b)) in predicted.iter().zip(&before).enumerate() {
                let mean = 0.5 * (b + bar.half_step_velocity_m_s(i));
                assert!(
                    (p - mean).abs() <= 1e-12 * mean.abs().max(1e-3),
                    "{dispersion:?} node {i}"
                );
            }
        }
    }
}

#[test]
fn love_rod_energy_ledger_is_exact() {
    let m = maraging();
    let mut s = spec(
        "love",
        vec![seg(0.3, DIAMETER_M, m)],
        EndCondition::Free,
        EndCondition::Absorbing,
    );
    s.dispersion = Dispersion::LoveRod;
    let dt = Bar::courant_time_step(&s, 300);
    let mut bar = Bar::new(&s, dt).unwrap();
    bar.add_node_mass(0, 1e-3);
    let mut worst: f64 = 0.0;
    for n in 0..3000 {
        bar.step(half_sine(n as f64 * dt, 10e-6, 5e3), 0.0);
        let e = bar.kinetic_energy_j() + bar.strain_energy_j() + bar.absorbed_energy_j();
        worst = worst.max((e - bar.work_done_j()).abs());
    }
    println!("Love ledger error {:e} of {:e} J", worst, bar.work_done_j());
    assert!(worst < 1e-10 * bar.work_done_j());
}

#[test]
fn non_finite_state_is_reported_with_step_and_node() {
    let m = maraging();
    let s = spec(
        "nan",
        vec![seg(0.1, DIAMETER_M, m)],
        EndCondition::Free,
        EndCondition::Free,
    );
    let mut bar = Bar::new(&s, Bar::courant_time_step(&s, 10)).unwrap();
    bar.step(0.0, 0.0);
    bar.check_finite().unwrap();
    bar.step(f64::NAN, 0.0);
    match Error::from(bar.check_finite().unwrap_err()) {
        Error::Unstable { step, quantity, .. } => {
            assert_eq!(step, 2);
            assert!(
                quantity.contains("bar nan") && quantity.contains("node 0"),
                "{quantity}"
            );
        }
        other => panic!("expected Unstable, got {other}"),
    }
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "timing is meaningful in release builds only"
)]
fn uniform_bar_steps_fast() {
    // 500 nodes × 1e5 steps; the brief asks for well under a second (generous bound for loaded CI).
    let m = maraging();
    let s = spec(
        "speed",
        vec![seg(0.499, DIAMETER_M, m)],
        EndCondition::Free,
        EndCondition::Absorbing,
    );
    let mut bar = Bar::new(&s, Bar::courant_time_step(&s, 499)).unwrap();
    assert_eq!(bar.node_count(), 500);
    let start = std::time::Instant::now();
    for n in 0..100_000 {
        bar.step(if n < 100 { 1e3 } else { 0.0 }, 0.0);
    }
    let elapsed = start.elapsed().as_secs_f64();
    bar.check_finite().unwrap();
    println!(
        "500 nodes × 1e5 steps: {elapsed:.3} s ({:.2} ns per node-step)",
        elapsed / 5e7 * 1e9
    );
    assert!(elapsed < 2.0);
}
