//! Stability at the extremes (issue 8, part 4): impact speeds 1e-3 to 500 m/s, yield stresses
//! 1 MPa to 100 GPa, strain rates 1e-6 to 1e6 1/s, a soft sphere on one 1000 times stiffer, time
//! steps at 0.99 and 1.01 of the stability limits, bar grids of 1 to 50 nodes per mm, 10 ms runs,
//! and instabilities that stop with an error naming the step, time and quantity.
//!
//! Every expected value is computed from physics (Hertz/Johnson closed forms, elementary wave
//! theory, the energy ledgers, the Johnson–Cook law), never copied from a previous run. Runs are
//! kept short where the physics allows (short bars, coarse DEM steps where only stability is at
//! stake); each test says why that loses nothing.

use shpb::bar::{Bar, BarMaterial, BarSpec, Dispersion, EndCondition, Segment};
use shpb::contact::{
    BurgoyneDaraio, Contact, Degenerate, LawKind, Region2Form, Stateful, Unloading,
};
use shpb::error::Error;
use shpb::material::Material;
use shpb::prelude::*;
use shpb::scene::{Params, SceneParams};
use shpb::solver::{self, CollisionResult, CollisionSetup, ForceDrivenSetup, ForceHistory};
use shpb::solver::{ChainSetup, GaugeProbe, Joint, simulate_chain};
use shpb::specimen::{Sphere, SpherePair};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The paper's law with the `static` unloading rule, which unloads an elastic contact down the
/// Hertz curve: what the Hertz checks compare (the default `dynamic` rule also takes out its
/// vibration loss, docs/physics.md §3, tested in shpb-core's contact.rs).
fn static_rule(pair: &SpherePair) -> Stateful<BurgoyneDaraio> {
    Stateful::new(BurgoyneDaraio::with_options(
        pair.contact_properties(),
        true,
        Region2Form::Smooth,
        Unloading::Static,
    ))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn ss440c_pair() -> SpherePair {
    SpherePair::paper(Material::builtin("ss440c").unwrap())
}

/// A material file's text (the format of `specimens/*.toml`).
fn material_toml(name: &str, rho: f64, e: f64, nu: f64, sigma_y: f64, jc_c: f64) -> String {
    format!(
        "name = \"{name}\"\ndensity_kg_m3 = {rho:e}\nyoungs_modulus_pa = {e:e}\npoisson_ratio = {nu}\n\
         yield_stress_pa = {sigma_y:e}\njc_c = {jc_c}\njc_reference_rate_per_s = 1e-3\n"
    )
}

/// SS440c (paper Table I, Fig. 4 C) with another quasi-static yield stress.
fn ss440c_with_yield(sigma_y: f64) -> Material {
    Material::from_toml(
        &material_toml("ss440c-variant", 7800.0, 204e9, 0.28, sigma_y, 0.035),
        "ss440c-variant.toml",
    )
    .unwrap()
}

/// Hertz contact duration of a pair at approach speed `speed`, s.
fn hertz_tc(pair: &SpherePair, speed: f64) -> f64 {
    let p = pair.contact_properties();
    solver::hertz_impact_duration(pair.reduced_mass_kg(), p.e_star_pa, p.radius_m, speed)
}

/// Sphere 1 hits sphere 2 (at rest) at `speed`, `steps` time steps per Hertz contact duration.
fn collide(law: &dyn Contact, pair: &SpherePair, speed: f64, steps: f64) -> CollisionResult {
    let tc = hertz_tc(pair, speed);
    let setup = CollisionSetup {
        velocity1_m_s: speed,
        velocity2_m_s: 0.0,
        dt_s: tc / steps,
        max_time_s: 1000.0 * tc,
        output_every: 1,
    };
    solver::collision(law, pair, &setup).unwrap()
}

/// Every output of a collision is finite, the contact does not return more energy than it took
/// (restitution ≤ 1 + `slack`), and the ledger ∮F dδ equals the kinetic energy lost: 1e-4 of the
/// loss as in tests/dem_scenes.rs, plus 1e-9 of the energy for round-off — δ is a difference of
/// sphere positions ~ r1 + r2 = 6 mm, so at 1 mm/s (δ ~ 3e-8 m) each step carries 1e-16 · 6e-3 /
/// 3e-8 = 2e-11 relative round-off, ~1e-9 after a few thousand steps.
fn assert_sound(r: &CollisionResult, slack: f64, what: &str) {
    for (name, x) in [
        ("restitution", r.restitution),
        ("contact time", r.contact_time_s),
        ("peak force", r.peak_force_n),
        ("max approach", r.max_approach_m),
        ("dissipated", r.dissipated_j),
        ("residual approach", r.residual_approach_m),
        ("KE after", r.kinetic_energy_after_j),
    ] {
        assert!(x.is_finite(), "{what}: {name} = {x}");
    }
    assert!(
        r.series
            .force_n
            .iter()
            .chain(&r.series.displacement_m)
            .all(|x| x.is_finite()),
        "{what}: non-finite sample in the series"
    );
    assert!(
        r.restitution > 0.0 && r.restitution <= 1.0 + slack,
        "{what}: restitution {}",
        r.restitution
    );
    let loss = r.kinetic_energy_before_j - r.kinetic_energy_after_j;
    let tol = 1e-4 * loss.abs() + 1e-9 * r.kinetic_energy_before_j;
    assert!(
        (r.dissipated_j - loss).abs() < tol,
        "{what}: dissipated {:e} J vs kinetic energy lost {loss:e} J",
        r.dissipated_j
    );
}

/// An elastic impact against Johnson's closed forms (Contact Mechanics §11.4): restitution 1,
/// largest approach δ* and duration t_c. With 2000 steps per contact the sampled maximum misses
/// δ* by (t_c/2000)²·a/8 ≈ 4e-7 of it, and the restitution is 1 to 1e-6 (tests/dem_scenes.rs).
/// The duration's end is a linear interpolation of δ through zero where F ∝ δ^{3/2}: its error is
/// a fraction of a step, 1/2000 of t_c, so 1e-3 holds it.
fn assert_hertz(r: &CollisionResult, pair: &SpherePair, speed: f64, what: &str) {
    let p = pair.contact_properties();
    let m = pair.reduced_mass_kg();
    let d_star = solver::hertz_max_approach(m, p.e_star_pa, p.radius_m, speed);
    assert!(
        (r.restitution - 1.0).abs() < 1e-6,
        "{what}: e = {}",
        r.restitution
    );
    assert!(
        rel(r.max_approach_m, d_star) < 1e-5,
        "{what}: δmax {:e} vs Hertz {d_star:e}",
        r.max_approach_m
    );
    let tc = solver::hertz_impact_duration(m, p.e_star_pa, p.radius_m, speed);
    assert!(
        rel(r.contact_time_s, tc) < 1e-3,
        "{what}: contact time {:e} vs Hertz {tc:e}",
        r.contact_time_s
    );
    assert!(
        rel(r.peak_force_n, solver::hertz_peak_force(pair, speed)) < 1e-4,
        "{what}: peak force"
    );
}

fn input_error(e: impl Into<Error>) -> (String, String, String) {
    match e.into() {
        Error::Input {
            key,
            problem,
            allowed,
            ..
        } => (key, problem, allowed),
        other => panic!("expected an input error, got {other}"),
    }
}

fn summary_finite(out: &shpb::run::RunOutput, what: &str) {
    for item in &out.summary {
        assert!(
            item.value.is_finite(),
            "{what}: summary {} = {}",
            item.key,
            item.value
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Impact speeds 1e-3 to 500 m/s
// ---------------------------------------------------------------------------------------------

/// Two SS440c spheres under the rate-dependent law from 1 mm/s to 500 m/s (the scene default of
/// 2000 steps per Hertz contact time): every result is finite, no impact creates energy
/// (restitution ≤ 1 + 1e-6, the elastic discretisation error), the energy ledger closes, the
/// spheres never interpenetrate past their centres (δmax < r1 + r2, here 23 % of it at
/// 500 m/s), and restitution falls with speed once the contact yields (more plastic work). At
/// 1 mm/s the peak force is below 1e-3 of the yield force Fy, so the impact is Hertz's.
#[test]
fn impact_speeds_from_1e_3_to_500_m_s_are_finite_and_create_no_energy() {
    let pair = ss440c_pair();
    let law = Stateful::new(BurgoyneDaraio::new(pair.contact_properties(), true));
    let sum_r = pair.sphere1.radius_m + pair.sphere2.radius_m;
    let mut plastic_e = Vec::new();
    for speed in [1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 500.0] {
        let r = collide(&law, &pair, speed, 2000.0);
        let what = format!("v = {speed} m/s");
        assert_sound(&r, 1e-6, &what);
        assert!(
            r.max_approach_m < sum_r,
            "{what}: δmax {:e}",
            r.max_approach_m
        );
        println!(
            "{what}: e = {:.4}, δmax = {:.3e} m, F = {:.3e} N, t = {:.3e} s",
            r.restitution, r.max_approach_m, r.peak_force_n, r.contact_time_s
        );
        if speed >= 1.0 {
            plastic_e.push(r.restitution);
        }
        if speed == 1e-3 {
            assert!(r.peak_force_n < 1e-2 * law.law.static_curve().force_y_n);
            let r = collide(&static_rule(&pair), &pair, speed, 2000.0);
            assert_hertz(&r, &pair, speed, &what);
        }
    }
    assert!(
        plastic_e.windows(2).all(|w| w[1] < w[0]),
        "restitution does not fall with speed: {plastic_e:?}"
    );
    // The collision scene accepts both extremes and reports finite results.
    for speed in [1e-3, 500.0] {
        let text = format!(
            "kind = \"collision\"\nvelocity1_m_s = {speed}\n[specimen]\npair = \"ss440c\"\n"
        );
        let out = Params::from_toml(&text, "extreme-speed.toml", Path::new("."))
            .unwrap()
            .run()
            .unwrap();
        summary_finite(&out, &format!("scene at {speed} m/s"));
    }
}

// ---------------------------------------------------------------------------------------------
// Yield stress 1 MPa to 100 GPa
// ---------------------------------------------------------------------------------------------

/// SS440c spheres with σy from 1 MPa to 100 GPa hit at 5 m/s (rate-dependent law, 2000 steps per
/// contact). All runs are finite, passive and close their ledger, and the restitution does not
/// fall as σy rises (a harder contact stores more of the energy elastically). At 100 GPa,
/// q = E*/σy = 1.1: region II does not exist and the region-III line never reaches the Hertz
/// curve (p0 < 0 in the paper's fit), so the law must be exactly Hertz — checked against
/// Johnson's closed forms. At 1 MPa (q = 1e5) yield starts at δy ~ 1e-12 m: the impact is almost
/// wholly plastic. Johnson's fully plastic scaling (Contact Mechanics §11.5),
/// e ~ (σy/E*)^{1/2} (ρv²/σy)^{-1/8} = 3.7e-3 here without its O(1) prefactor, bounds it: asserted
/// e < 10 times that (the rebound keeps < 0.14 % of the energy of the relative motion).
#[test]
fn yield_stress_from_1_mpa_to_100_gpa_spans_plastic_to_pure_hertz() {
    let speed = 5.0;
    let mut last_e = 0.0;
    for sigma_y in [1e6, 1e7, 1e8, 1e9, 1e10, 1e11] {
        let pair = SpherePair::paper(ss440c_with_yield(sigma_y));
        let law = Stateful::new(BurgoyneDaraio::new(pair.contact_properties(), true));
        let what = format!("σy = {sigma_y:e} Pa");
        let r = collide(&law, &pair, speed, 2000.0);
        assert_sound(&r, 1e-6, &what);
        println!(
            "{what}: e = {:.4}, dissipated {:.3} of the energy, degenerate {:?}",
            r.restitution,
            r.dissipated_j / r.kinetic_energy_before_j,
            law.law.static_curve().degenerate
        );
        assert!(r.restitution >= last_e - 1e-9, "{what}: e fell");
        last_e = r.restitution;
        // The quasi-static loading curve up to a tenth of the radius: finite, ≥ 0, rising.
        let curve = solver::loading_curve(&law, 0.1 * pair.sphere1.radius_m, 401, 0.0);
        assert!(curve.force_n.iter().all(|f| f.is_finite() && *f >= 0.0));
        assert!(
            curve.force_n.windows(2).all(|w| w[1] > w[0]),
            "{what}: loading curve not rising"
        );
        if sigma_y == 1e6 {
            let m = &pair.sphere1.material;
            let scale = (sigma_y / pair.contact_properties().e_star_pa).sqrt()
                * (m.density_kg_m3 * speed * speed / sigma_y).powf(-0.125);
            assert!(
                r.restitution < 10.0 * scale,
                "{what}: e = {} vs Johnson's scale {scale:e}",
                r.restitution
            );
        }
        if sigma_y == 1e11 {
            assert_eq!(law.law.static_curve().degenerate, Degenerate::HertzOnly);
            let r = collide(&static_rule(&pair), &pair, speed, 2000.0);
            assert_hertz(&r, &pair, speed, &what);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Strain rates 1e-6 to 1e6 1/s
// ---------------------------------------------------------------------------------------------

/// Constant-rate compression of SS440c spheres from 1e-6 to 1e6 1/s. At or below ε̇0 = 1e-3 1/s
/// the static σy applies (paper Eq. 2) and the force equals the static loading curve exactly;
/// above it σy* = σy(1 + C ln(ε̇/ε̇0)) to round-off, and the force at a given approach does not
/// fall with the rate. Times (δ/δ̇, up to 4e4 s at 1e-6 1/s) and forces are finite. Both extremes
/// also run as `constant-rate` scenes.
#[test]
fn strain_rates_from_1e_6_to_1e6_per_s_use_the_static_yield_stress_up_to_the_reference_rate() {
    let pair = ss440c_pair();
    let props = pair.contact_properties();
    let law = Stateful::new(BurgoyneDaraio::new(props, true));
    let (sigma_y, c, rate0) = (
        props.yield_stress_pa,
        props.rate.c,
        props.rate.reference_rate_per_s,
    );
    let delta = 0.25e-3;
    let mut last = 0.0;
    for k in -6..=6 {
        let rate = 10f64.powi(k);
        let s = solver::constant_rate(&law, &pair, rate, delta, 201);
        let t = s.time_s.as_ref().unwrap();
        let sy = s.yield_stress_pa.as_ref().unwrap();
        assert!(
            t.iter().chain(&s.force_n).chain(sy).all(|x| x.is_finite()),
            "ε̇ = {rate:e}: non-finite sample"
        );
        assert!(rel(*t.last().unwrap(), delta / (rate * props.sum_of_radii_m)) < 1e-12);
        let want = if rate <= rate0 {
            sigma_y
        } else {
            sigma_y * (1.0 + c * (rate / rate0).ln())
        };
        assert!(
            sy[1..].iter().all(|&x| rel(x, want) < 1e-12),
            "ε̇ = {rate:e}: σy* {} vs {want:e}",
            sy[1]
        );
        if rate <= rate0 {
            for (d, f) in s.displacement_m.iter().zip(&s.force_n) {
                assert_eq!(
                    *f,
                    law.law.static_curve().force(*d),
                    "ε̇ = {rate:e}, δ = {d:e}"
                );
            }
        }
        let f = *s.force_n.last().unwrap();
        assert!(f >= last, "ε̇ = {rate:e}: F = {f} below {last}");
        last = f;
    }
    for rate in [1e-6, 1e6] {
        let text = format!(
            "kind = \"constant-rate\"\nstrain_rate_per_s = {rate:e}\nmax_displacement_m = 2.5e-4\n\
             [specimen]\npair = \"ss440c\"\n"
        );
        let out = Params::from_toml(&text, "extreme-rate.toml", Path::new("."))
            .unwrap()
            .run()
            .unwrap();
        summary_finite(&out, &format!("scene at {rate:e} 1/s"));
        let c = out.contact.as_ref().unwrap();
        assert!(c.force_n.iter().all(|f| f.is_finite()));
    }
}

// ---------------------------------------------------------------------------------------------
// Very soft on very stiff
// ---------------------------------------------------------------------------------------------

/// A polymer-like sphere (E = 0.204 GPa, σy = 20 MPa) against SS440c (E = 204 GPa): E ratio
/// 1000, so E* = E'soft/(1 + E'soft/E'stiff) is within 0.11 % of the soft sphere's plane-strain
/// modulus E' = E/(1 − ν²). From 1 mm/s to 100 m/s all impacts are finite, passive and close their ledger. At 1 mm/s the peak Hertz force is far
/// below the soft sphere's yield force, so the impact must match Johnson's closed forms with the
/// pair's E*, r and reduced mass. Swapping which sphere moves (soft on stiff, stiff on soft, same
/// approach speed) leaves the relative motion — and so the restitution — unchanged up to
/// round-off (1e-9): the solver has no hidden asymmetry between the spheres. One impact also runs
/// as a scene that reads the soft material from a file.
#[test]
fn very_soft_on_very_stiff_spheres_with_modulus_ratio_1000() {
    let soft = Material::from_toml(
        &material_toml("soft", 1200.0, 0.204e9, 0.40, 20e6, 0.05),
        "soft.toml",
    )
    .unwrap();
    let stiff = Material::builtin("ss440c").unwrap();
    assert_eq!(stiff.youngs_modulus_pa / soft.youngs_modulus_pa, 1000.0);
    let r = 6.35e-3 / 2.0;
    let soft_on_stiff = SpherePair {
        sphere1: Sphere::full(soft.clone(), r),
        sphere2: Sphere::full(stiff.clone(), r),
    };
    let stiff_on_soft = SpherePair {
        sphere1: Sphere::full(stiff, r),
        sphere2: Sphere::full(soft.clone(), r),
    };
    let props = soft_on_stiff.contact_properties();
    assert!(rel(props.e_star_pa, soft.plane_strain_modulus_pa()) < 1.2e-3);
    assert_eq!(props.yield_stress_pa, soft.yield_stress_pa);
    for speed in [1e-3, 0.1, 1.0, 10.0, 100.0] {
        let mut e = Vec::new();
        for pair in [&soft_on_stiff, &stiff_on_soft] {
            let law = Stateful::new(BurgoyneDaraio::new(pair.contact_properties(), true));
            let res = collide(&law, pair, speed, 2000.0);
            let what = format!("v = {speed} m/s, sphere 1 {}", pair.sphere1.material.name);
            assert_sound(&res, 1e-6, &what);
            if speed == 1e-3 {
                assert!(res.peak_force_n < 1e-2 * law.law.static_curve().force_y_n);
                let res = collide(&static_rule(pair), pair, speed, 2000.0);
                assert_hertz(&res, pair, speed, &what);
            }
            e.push(res.restitution);
        }
        println!("v = {speed} m/s: e = {:.6} / {:.6}", e[0], e[1]);
        assert!((e[0] - e[1]).abs() < 1e-9, "v = {speed}: {e:?}");
    }
    // The same pair through the specimen API of a collision scene (material read from a file).
    let dir = std::env::temp_dir().join(format!("shpb-extremes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("soft.toml"),
        material_toml("soft", 1200.0, 0.204e9, 0.40, 20e6, 0.05),
    )
    .unwrap();
    let text = "kind = \"collision\"\nvelocity1_m_s = 10.0\n\
                [specimen.sphere1]\nmaterial = \"soft.toml\"\ndiameter_m = 6.35e-3\n\
                [specimen.sphere2]\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3\n";
    let params = Params::from_toml(text, "soft-on-stiff.toml", &dir).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(params.sphere_pair().unwrap().0, soft_on_stiff);
    summary_finite(&params.run().unwrap(), "soft-on-stiff scene");
}

// ---------------------------------------------------------------------------------------------
// Time step at 0.99 and 1.01 of the stability limit
// ---------------------------------------------------------------------------------------------

/// The `collision` scene's `time_step_s` at 0.99 and 1.01 of `solver::stability_limit` (1/ω at
/// the Hertz peak force, solver module docs). 0.99 runs: finite, and passive to the 2 % that the
/// solver docs measure for ωΔt ≤ 1 (about four steps per contact; at 0.99 of the old 2/ω limit
/// this impact returned 2.8 times its energy). 1.01 is refused as bad input naming the key and
/// the limit's value.
#[test]
fn collision_time_step_at_0_99_runs_and_at_1_01_is_refused() {
    let pair = ss440c_pair();
    let speed = 5.0;
    let limit = solver::stability_limit(&pair, solver::hertz_peak_force(&pair, speed));
    let scene = |dt: f64| {
        let text = format!(
            "kind = \"collision\"\nvelocity1_m_s = {speed}\ntime_step_s = {dt:e}\n\
             law = \"hertz\"\n[specimen]\npair = \"ss440c\"\n"
        );
        Params::from_toml(&text, "dt-limit.toml", Path::new("."))
    };
    let out = scene(0.99 * limit).unwrap().run().unwrap();
    // At 0.99 of the limit the elastic impact takes a handful of steps and its stepped
    // restitution comes out above 1 (the integrator's energy error, bounded below): issue 42
    // reports it as not available with a warning saying so, never as a number above 1; every
    // other summary is finite.
    let e = out
        .summary
        .iter()
        .find(|s| s.key == "restitution")
        .unwrap()
        .value;
    assert!(
        e <= 1.0 + shpb::scene::RESTITUTION_ROUND_OFF
            || (e.is_nan()
                && out
                    .warnings
                    .iter()
                    .any(|w| w.contains("`restitution` is not available (NaN)"))),
        "restitution {e}: {:?}",
        out.warnings
    );
    let mut others = out.clone();
    others.summary.retain(|s| s.key != "restitution");
    summary_finite(&others, "0.99 of the limit");
    // The elastic law isolates the scheme: any energy change is the integrator's.
    let law = LawKind::Hertz.build(pair.contact_properties());
    let tc = hertz_tc(&pair, speed);
    let r = collide(law.as_ref(), &pair, speed, tc / (0.99 * limit));
    assert_sound(&r, 0.02, "Hertz at 0.99 of the limit");
    assert!(rel(r.kinetic_energy_after_j, r.kinetic_energy_before_j) < 0.02);
    let (key, problem, allowed) = input_error(scene(1.01 * limit).unwrap_err());
    println!("refused: `{key}`: {problem}; allowed: {allowed}");
    assert_eq!(key, "time_step_s");
    assert!(allowed.contains("stability limit"), "{allowed}");
    // The limit as messages write numbers (3 significant digits, rounded down to stay allowed).
    assert!(allowed.contains(&shown_limit(limit)), "{allowed}");
}

/// The Fig. 4 force-driven scene (SS440c, 10 psi drive) with `time_step_s` at 0.99 and 1.01 of
/// the stability limit at the drive's peak force. 0.99 runs (~100 steps over the record): finite,
/// the contact takes positive work, and the energy ledger W_ext = KE + ∫F dδ + radiated closes to
/// 1 % (velocity Verlet's ledger is exact only to O(Δt²); it closes to ~1e-8 at the default step).
/// 1.01 is refused naming the limit.
#[test]
fn force_driven_time_step_at_0_99_runs_and_at_1_01_is_refused() {
    let csv = root().join("validation/fig4-force-driven/data/ss440c_10psi_force10.csv");
    let scene = |extra: &str| {
        let text = format!(
            "kind = \"force-driven\"\nforce_csv = \"{}\"\n{extra}[specimen]\npair = \"ss440c\"\n",
            csv.display()
        );
        Params::from_toml(&text, "fd-limit.toml", Path::new("."))
    };
    let base = scene("").unwrap();
    let SceneParams::ForceDriven { setup, .. } = &base.params else {
        unreachable!()
    };
    let limit = solver::stability_limit(&base.sphere_pair().unwrap().0, setup.drive.peak_n());
    let p = scene(&format!("time_step_s = {:e}\n", 0.99 * limit)).unwrap();
    let SceneParams::ForceDriven { setup, .. } = &p.params else {
        unreachable!()
    };
    let pair = p.sphere_pair().unwrap().0;
    let r = solver::force_driven(p.contact_law().unwrap().as_ref(), &pair, setup).unwrap();
    let e = r.energy;
    println!(
        "0.99 of {limit:e} s: {} steps, W_ext {:e} J, ledger error {:e}",
        r.series.force_n.len() - 1,
        e.external_work_j,
        (e.external_work_j - r.kinetic_energy_j - e.contact_work_j - e.radiated_j)
            / e.external_work_j
    );
    assert!(r.series.force_n.iter().all(|f| f.is_finite()));
    assert!(e.contact_work_j > 0.0 && e.radiated_j > 0.0);
    assert!(
        (e.external_work_j - r.kinetic_energy_j - e.contact_work_j - e.radiated_j).abs()
            < 0.01 * e.external_work_j
    );
    let (key, _, allowed) =
        input_error(scene(&format!("time_step_s = {:e}\n", 1.01 * limit)).unwrap_err());
    assert_eq!(key, "time_step_s");
    assert!(allowed.contains("stability limit"), "{allowed}");
    // The limit as messages write numbers (3 significant digits, rounded down to stay allowed).
    assert!(allowed.contains(&shown_limit(limit)), "{allowed}");
}

/// An upper limit of seconds as the range messages write it (`3.48 µs`).
fn shown_limit(limit_s: f64) -> String {
    let range = shpb_core::error::format_range(0.0, limit_s, "s");
    range.rsplit(" to ").next().unwrap().to_string()
}

fn maraging() -> BarMaterial {
    BarMaterial {
        density_kg_m3: 8110.0,
        youngs_modulus_pa: 192e9,
        poisson_ratio: 0.31,
    }
}

const BAR_D: f64 = 19.05e-3;

fn bar_spec(name: &str, lengths: &[f64], left: EndCondition, right: EndCondition) -> BarSpec {
    BarSpec {
        name: name.into(),
        segments: lengths
            .iter()
            .map(|&length_m| Segment {
                length_m,
                diameter_m: BAR_D,
                material: maraging(),
            })
            .collect(),
        left_end: left,
        right_end: right,
        dispersion: Dispersion::None,
    }
}

/// A bar whose 0.4 mm insert (shorter than c0Δt at 1 mm cells) sets the stability limit; the
/// largest accepted step `max_time_step_s` is the limit of the grid it builds. At 0.99 of it the
/// bar is built and stays bounded over 2e4 steps of a force pulse, its energy ledger exact to
/// 1e-9 (the leapfrog energy identity holds to round-off when stable). At 1.01 `Bar::new` refuses
/// with an input error that names the limit and the largest accepted step; a chain run with that
/// bar (`simulate_chain`) stops with the same error before stepping.
#[test]
fn bar_time_step_at_0_99_runs_and_at_1_01_is_refused() {
    let s = bar_spec(
        "insert",
        &[0.2, 0.4e-3, 0.2],
        EndCondition::Free,
        EndCondition::Free,
    );
    let limit = s.max_time_step_s().unwrap();
    assert!(limit > s.courant_limit_s());
    let mut bar = Bar::new(&s, 0.99 * limit).unwrap();
    let tau = 5e-6;
    for n in 0..20_000 {
        let t = n as f64 * bar.dt_s();
        let f = if t < tau {
            1e3 * (PI * t / tau).sin()
        } else {
            0.0
        };
        bar.step(f, 0.0);
    }
    bar.check_finite().unwrap();
    let e = bar.kinetic_energy_j() + bar.strain_energy_j();
    assert!(
        rel(e, bar.work_done_j()) < 1e-9,
        "{e:e} vs {:e}",
        bar.work_done_j()
    );
    let (key, problem, allowed) = input_error(Bar::new(&s, 1.01 * limit).unwrap_err());
    println!("refused: `{key}`: {problem}; allowed: {allowed}");
    assert_eq!(key, "time_step_s");
    assert!(problem.contains("stability limit"), "{problem}");
    assert!(allowed.contains(&format!("{limit:e}")), "{allowed}");
    let chain = ChainSetup {
        bodies: vec![s.into()],
        joints: vec![],
        striker_velocity_m_s: 1.0,
        dt_s: 1.01 * limit,
        end_time_s: 1e-5,
        gauges: vec![],
        record_every: 1,
        end_masses: vec![],
        snapshot_every: None,
        snapshot_spacing_m: 1e-3,
        drive_force_n: Vec::new(),
    };
    let (key, problem, _) = input_error(simulate_chain(&chain).unwrap_err());
    assert_eq!(key, "time_step_s");
    assert!(problem.contains("stability limit"), "{problem}");
}

// ---------------------------------------------------------------------------------------------
// Bars of 1 to 50 nodes per mm
// ---------------------------------------------------------------------------------------------

/// A 10 mm striker at 10 m/s on a 60 mm bar with an absorbing end, at 1, 2, 5, 10, 20 and 50
/// nodes per mm (Courant 1). Short bars keep the finest grid to 3500 nodes × 3400 steps; at
/// Courant 1 the scheme is exact for any length, so nothing is lost. At every grid the pulse at a
/// gauge 30 mm down the bar has the elementary amplitude v/(2c0) (exact at Courant 1: 1e-9 covers
/// round-off), its front crosses half amplitude at x/c0 and its length at half amplitude is
/// 2Ls/c0, each within one time step (the front is a one-step jump sampled on the grid). The
/// energy ledger (striker = bars + absorbed + joint) holds to 1e-9 at every step, and the only
/// loss, the butt joint's merge of two half-mass nodes at impact, is m_cell v²/8: it falls with
/// the grid as Δx/(4Ls) of the striker's energy.
#[test]
fn bars_from_1_to_50_nodes_per_mm_carry_the_elementary_pulse() {
    let m = maraging();
    let c0 = m.wave_speed_m_s();
    let (ls, lb, xg, v) = (10e-3, 60e-3, 30e-3, 10.0);
    let area = PI * BAR_D * BAR_D / 4.0;
    for nodes_per_mm in [1.0, 2.0, 5.0, 10.0, 20.0, 50.0] {
        for dispersion in [Dispersion::None, Dispersion::LoveRod] {
            if dispersion == Dispersion::LoveRod && !(nodes_per_mm == 1.0 || nodes_per_mm == 50.0) {
                continue;
            }
            let dx = 1e-3 / nodes_per_mm;
            let dt = dx / c0;
            let mut striker = bar_spec("striker", &[ls], EndCondition::Free, EndCondition::Free);
            let mut incident = bar_spec(
                "incident",
                &[lb],
                EndCondition::Free,
                EndCondition::Absorbing,
            );
            striker.dispersion = dispersion;
            incident.dispersion = dispersion;
            let setup = ChainSetup {
                bodies: vec![striker.into(), incident.into()],
                joints: vec![Joint::Butt],
                striker_velocity_m_s: v,
                dt_s: dt,
                end_time_s: (xg + 2.0 * ls) / c0 + 4e-6,
                gauges: vec![GaugeProbe {
                    name: "gauge".into(),
                    bar: 1,
                    x_m: xg,
                    length_m: 0.0,
                }],
                record_every: 1,
                end_masses: vec![],
                snapshot_every: None,
                snapshot_spacing_m: 1e-3,
                drive_force_n: Vec::new(),
            };
            let out = simulate_chain(&setup).unwrap();
            let what = format!("{nodes_per_mm} nodes/mm, {dispersion:?}");
            let s = &out.strain[0];
            assert!(s.iter().all(|x| x.is_finite()), "{what}");
            for (i, t) in out.time_s.iter().enumerate() {
                let sum = out.bar_energy_j[i] + out.absorbed_energy_j[i] + out.shaper_energy_j[i];
                assert!(
                    rel(sum, out.striker_energy_j) < 1e-9,
                    "{what}: ledger at t = {t:e}"
                );
            }
            if dispersion == Dispersion::LoveRod {
                continue;
            }
            let amplitude = s.iter().cloned().fold(0.0, f64::min);
            assert!(
                rel(-amplitude, v / (2.0 * c0)) < 1e-9,
                "{what}: amplitude {amplitude:e}"
            );
            let half = 0.5 * amplitude;
            let i = s.iter().position(|&x| x <= half).unwrap();
            let j = i + s[i..].iter().position(|&x| x > half).unwrap();
            let cross = |k: usize| (k - 1) as f64 * dt + (half - s[k - 1]) / (s[k] - s[k - 1]) * dt;
            let (rise, fall) = (cross(i), cross(j));
            println!(
                "{what}: arrival {:+.3} Δt, length {:+.3} Δt, joint loss {:.3e} of the striker's",
                (rise - xg / c0) / dt,
                (fall - rise - 2.0 * ls / c0) / dt,
                out.shaper_energy_j.last().unwrap() / out.striker_energy_j
            );
            assert!((rise - xg / c0).abs() <= dt, "{what}: arrival {rise:e}");
            assert!(
                (fall - rise - 2.0 * ls / c0).abs() <= dt,
                "{what}: length {:e}",
                fall - rise
            );
            let cell_mass = m.density_kg_m3 * area * dx;
            assert!(
                rel(
                    *out.shaper_energy_j.last().unwrap(),
                    cell_mass * v * v / 8.0
                ) < 1e-6,
                "{what}: joint loss"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 10 ms runs
// ---------------------------------------------------------------------------------------------

/// The Fig. 4 DEM (SS440c, 10 psi drive, rate-dependent law, scene defaults: 1.5e6 steps) run for
/// 10 ms, 50 times the 0.2 ms record. After the drive ends sphere 2 stops on the transmission-bar
/// dashpot (time constant m2/Z ≈ 0.1 µs) and sphere 1 rebounds from it with the elastic energy of
/// the unloading contact, then flies free for ~10 ms. Everything stays finite, the ledger
/// W_ext = KE + ∫F dδ + radiated closes to 1e-6 over all 1.5e6 steps (velocity Verlet's ledger
/// error is O(Δt²) and does not drift: ~1e-8 measured), the contact keeps the positive work it took
/// (plastic dissipation), and at 10 ms the spheres are apart (δ < 0, F = 0), δ falling at a
/// constant rate whose kinetic energy ½m1δ̇² is all the energy left in motion.
#[test]
fn a_10_ms_force_driven_run_stays_finite_and_conserves_energy() {
    let csv = root().join("validation/fig4-force-driven/data/ss440c_10psi_force10.csv");
    let text = format!(
        "kind = \"force-driven\"\nforce_csv = \"{}\"\nend_time_s = 10e-3\noutput_every = 1000\n\
         [specimen]\npair = \"ss440c\"\n",
        csv.display()
    );
    let p = Params::from_toml(&text, "fd-10ms.toml", Path::new(".")).unwrap();
    let SceneParams::ForceDriven { setup, .. } = &p.params else {
        unreachable!()
    };
    let start = std::time::Instant::now();
    let pair = p.sphere_pair().unwrap().0;
    let r = solver::force_driven(p.contact_law().unwrap().as_ref(), &pair, setup).unwrap();
    let e = r.energy;
    let closure = (e.external_work_j - r.kinetic_energy_j - e.contact_work_j - e.radiated_j).abs();
    println!(
        "10 ms force-driven: {:.0} steps in {:.2} s, ledger error {:e} of {:e} J, final KE {:e} J",
        10e-3 / setup.dt_s,
        start.elapsed().as_secs_f64(),
        closure / e.external_work_j,
        e.external_work_j,
        r.kinetic_energy_j
    );
    let c = &r.series;
    let t_end = *c.time_s.as_ref().unwrap().last().unwrap();
    assert!(
        t_end >= 10e-3 && t_end < 10e-3 + setup.dt_s,
        "t_end {t_end:e}"
    );
    assert!(
        r.series
            .force_n
            .iter()
            .chain(&r.series.displacement_m)
            .all(|x| x.is_finite())
    );
    assert!(closure < 1e-6 * e.external_work_j);
    assert!(e.contact_work_j > 0.0 && e.radiated_j > 0.0);
    assert!(*c.displacement_m.last().unwrap() < 0.0 && *c.force_n.last().unwrap() == 0.0);
    // Free flight: δ falls linearly, at sphere 1's speed (sphere 2 is at rest), and that speed
    // accounts for all the kinetic energy left (1e-6: the samples' rounding of δ ~ 3.5e-2 m).
    let (t, d, k) = (
        c.time_s.as_ref().unwrap(),
        &c.displacement_m,
        c.force_n.len() - 2,
    );
    let speed = (d[k] - d[k - 1]) / (t[k] - t[k - 1]);
    let earlier = (d[k - 1] - d[k - 2]) / (t[k - 1] - t[k - 2]);
    assert!(rel(speed, earlier) < 1e-6, "{speed} vs {earlier} m/s");
    let ke1 = 0.5 * p.sphere_pair().unwrap().0.sphere1.mass_kg * speed * speed;
    assert!(
        rel(ke1, r.kinetic_energy_j) < 1e-6,
        "{ke1:e} vs {:e} J",
        r.kinetic_energy_j
    );
}

/// The whole virtual SHPB test (SS440c, 10 psi, 1 mm cells) run for 10 ms instead of ~0.7 ms:
/// ~49 000 steps in which the pulses ring through the free incident bar and the spheres. The
/// scheme's energy identity (striker = bars + absorbed + shaper + contact) holds to round-off
/// (1e-9) over the whole run, every gauge strain and contact sample is finite, and the summary
/// (including the data reduction of 10 ms of records) is finite.
#[test]
fn a_10_ms_shpb_test_stays_finite_and_conserves_energy() {
    let text = format!(
        "kind = \"shpb\"\nbars = \"{}\"\npressure = \"10psi\"\nend_time_s = 10e-3\n\
         [specimen]\npair = \"ss440c\"\n",
        root().join("bars/authors.toml").display()
    );
    let start = std::time::Instant::now();
    let out = Params::from_toml(&text, "shpb-10ms.toml", Path::new("."))
        .unwrap()
        .run()
        .unwrap();
    println!("10 ms SHPB test in {:.2} s", start.elapsed().as_secs_f64());
    // The records are the digitiser's 10 MHz samples of the whole 10 ms.
    let t = out.time_s.as_ref().unwrap();
    assert!(
        *t.last().unwrap() > 10e-3 - 2e-7,
        "records end at {:e}",
        t.last().unwrap()
    );
    // The contact is sampled at the levels its joint is solved at: every one but the last, so
    // its series ends one time step before the run does.
    let c = out.contact.as_ref().unwrap();
    let dt = out.summary_value("time_step").unwrap();
    assert!(*c.time_s.as_ref().unwrap().last().unwrap() >= 10e-3 - dt * (1.0 + 1e-9));
    summary_finite(&out, "10 ms SHPB");
    let err = out
        .summary_value("energy_balance_max_relative_error")
        .unwrap();
    assert!(err < 1e-9, "energy balance error {err:e}");
    for g in &out.gauges {
        assert!(g.strain.iter().all(|x| x.is_finite()), "gauge {}", g.name);
    }
    assert!(
        c.force_n
            .iter()
            .chain(&c.displacement_m)
            .all(|x| x.is_finite())
    );
}

// ---------------------------------------------------------------------------------------------
// No NaN, no silent blow-up
// ---------------------------------------------------------------------------------------------

/// Checks an `Error::Unstable`: the step and time are consistent (t = n Δt), the quantity
/// contains `quantity`, the message names all three, and the exit code is 3.
fn assert_unstable(e: impl Into<Error>, dt: f64, quantity: &str) -> usize {
    let e: Error = e.into();
    let msg = e.to_string();
    assert_eq!(e.exit_code(), 3, "{msg}");
    match e {
        Error::Unstable {
            step,
            time_s,
            quantity: q,
            ..
        } => {
            assert!(step >= 1, "{msg}");
            assert!(rel(time_s, step as f64 * dt) < 1e-12, "{msg}");
            assert!(q.contains(quantity), "{msg}");
            assert!(
                msg.contains(&format!("step {step}")) && msg.contains(&q),
                "{msg}"
            );
            assert!(msg.contains(&format!("{time_s:.6e} s")), "{msg}");
            step
        }
        other => panic!("expected Unstable, got {other}"),
    }
}

/// A collision through the low-level solver (which, unlike the scene, accepts any step) at 4 and
/// 20 times the stability limit, from 1 mm/s to 500 m/s, elastic and elastoplastic: without the
/// passivity check the elastic impacts return restitutions of 17 and 1000 — finite, silent and
/// wrong. The solver stops them with `Error::Unstable` naming the step, time and the contact work
/// (the contact returned more than 10 % of the energy put in). At 0.99 of the limit the same
/// impacts run and stay passive to 2 % (the solver docs' bound for ωΔt ≤ 1).
#[test]
fn an_impact_past_the_stability_limit_stops_naming_step_time_and_quantity() {
    let pair = ss440c_pair();
    for kind in [LawKind::Hertz, LawKind::BurgoyneDaraio] {
        let law = kind.build(pair.contact_properties());
        for speed in [1e-3, 5.0, 500.0] {
            let limit = solver::stability_limit(&pair, solver::hertz_peak_force(&pair, speed));
            let tc = hertz_tc(&pair, speed);
            let run = |frac: f64| {
                solver::collision(
                    law.as_ref(),
                    &pair,
                    &CollisionSetup {
                        velocity1_m_s: speed,
                        velocity2_m_s: 0.0,
                        dt_s: frac * limit,
                        max_time_s: 1000.0 * tc,
                        output_every: 1,
                    },
                )
            };
            let ok = run(0.99).unwrap();
            assert_sound(&ok, 0.02, &format!("{kind:?} {speed} m/s at 0.99"));
            for frac in [4.0, 20.0] {
                let e = run(frac).unwrap_err();
                println!("{kind:?} {speed} m/s ×{frac}: {e}");
                assert_unstable(e, frac * limit, "contact work");
            }
        }
    }
}

/// Non-finite input cannot leak into results: a NaN in the force history driving sphere 1 stops
/// the force-driven DEM at the first step whose interpolated drive touches the NaN sample (after
/// the sample before it, no later than the sample itself), naming sphere 1's velocity; a NaN striker velocity stops the bar chain at its first
/// step naming the striker's node. A force-driven run at 20 times the stability limit (drive
/// peak) stops on the contact-work check instead of returning garbage.
#[test]
fn non_finite_input_and_over_limit_drives_stop_with_unstable_errors() {
    let pair = ss440c_pair();
    let law = Stateful::new(BurgoyneDaraio::new(pair.contact_properties(), true));
    let t: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-6).collect();
    let mut f: Vec<f64> = t
        .iter()
        .map(|&x| 2e3 * (PI * x / 200e-6).sin().powi(2))
        .collect();
    let nan_at = 120;
    f[nan_at] = f64::NAN;
    let drive = ForceHistory {
        time_s: t.clone(),
        force_n: f.clone(),
    };
    let dt = 1e-8;
    let setup = ForceDrivenSetup {
        drive,
        medium_impedance_kg_s: 1.12e4,
        dt_s: dt,
        end_time_s: 200e-6,
        output_every: 1,
    };
    let step = assert_unstable(
        solver::force_driven(&law, &pair, &setup).unwrap_err(),
        dt,
        "sphere 1 velocity",
    );
    // Interpolation touches the NaN sample from the step after t[nan_at − 1] on.
    let first = (t[nan_at - 1] / dt).floor() as usize + 1;
    assert!(
        step >= first && step <= (t[nan_at] / dt).ceil() as usize,
        "step {step}, NaN enters at {first}"
    );
    // Over the limit, finite drive: the contact-work check stops it.
    f[nan_at] = f[nan_at - 1];
    let drive = ForceHistory {
        time_s: t,
        force_n: f,
    };
    let limit = solver::stability_limit(&pair, drive.peak_n());
    let over = ForceDrivenSetup {
        drive,
        dt_s: 20.0 * limit,
        ..setup
    };
    assert_unstable(
        solver::force_driven(&law, &pair, &over).unwrap_err(),
        20.0 * limit,
        "contact work",
    );
    // Bar chain: a NaN striker velocity is caught at step 1, naming the bar and node.
    let m = maraging();
    let dt = 1e-3 / m.wave_speed_m_s();
    let chain = ChainSetup {
        bodies: vec![
            bar_spec("striker", &[0.1], EndCondition::Free, EndCondition::Free).into(),
            bar_spec(
                "incident",
                &[0.5],
                EndCondition::Free,
                EndCondition::Absorbing,
            )
            .into(),
        ],
        joints: vec![Joint::Butt],
        striker_velocity_m_s: f64::NAN,
        dt_s: dt,
        end_time_s: 1e-4,
        gauges: vec![],
        record_every: 1,
        end_masses: vec![],
        snapshot_every: None,
        snapshot_spacing_m: 1e-3,
        drive_force_n: Vec::new(),
    };
    let step = assert_unstable(simulate_chain(&chain).unwrap_err(), dt, "bar striker");
    assert_eq!(step, 1);
}
