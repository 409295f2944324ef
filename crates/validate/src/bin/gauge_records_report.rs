//! Regenerates `validation/gauge-records/REPORT.md` and `validation/gauge-records/*.png`: the
//! reduction (crates/core/src/reduce.rs) of the eight 2013-05-22 records against the authors'
//! own reductions, the bridge configuration that explains the records, and an analysis of the
//! displacement differences (sign, window alignment, integration start), and the timing and
//! equilibrium of the records against virtual tests of the same material and pressure
//! (docs/physics.md §7.5). Run from the repository root with
//! `cargo run --release -p shpb-validate --bin gauge_records_report`.

#![warn(missing_docs)]

mod common;

use rayon::prelude::*;
use shpb_core::apparatus::{Apparatus, IncidentDrive, Insert, PulseOptions};
use shpb_core::bar::BarMaterial;
use shpb_core::contact::LawKind;
use shpb_core::gauge::{
    BridgeKind, FOOT_FRACTION, FOOT_SMOOTHING_S, RawRecord, foot_signal, pulse_foot,
};
use shpb_core::numeric::{argmax, least_squares, min_max};
use shpb_core::reduce::{
    Alignment, Reduction, ReductionInput, ReductionOptions, ReductionSetup, WindowOverride,
    record_strains, reduce,
};
use shpb_core::scene::{Params, SceneParams};
use shpb_core::specimen::{Seating, Specimen};
use shpb_input::csv::CsvTable;
use shpb_input::gauges::reduce_record_file;
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use shpb_output::plot::{Axes, Curve, panels_figure, xy_plot};
use shpb_validate::gauge_records::{SAMPLES, SAMPLES_2013_06_06, effective_mass_kg, imbalance_rms};
use std::fmt::Write as _;
use std::path::Path;

/// The acceptance tolerance on the peak back force.
const TOLERANCE: f64 = 0.15;

/// Acceptance of issue 18 on the reflected and transmitted arrivals relative to the incident
/// one, per record, s.
const ARRIVAL_TOLERANCE_S: f64 = 3e-6;

/// The authors' 1/4" inserts between bars and spheres (shared/reference/README.md), m.
const AUTHORS_INSERT_LENGTH_M: f64 = 6.35e-3;

/// Reflected and transmitted foot minus incident foot of one test, s (docs/physics.md §7.5).
#[derive(Debug, Clone, Copy)]
struct Delays {
    /// Incident foot on the record's (or run's) own time base, s.
    incident_s: f64,
    /// Reflected foot (tension, incident gauge) − incident foot, s.
    reflected_s: f64,
    /// Transmitted foot (transmission gauge) − incident foot, s.
    transmitted_s: f64,
    /// Mean incident-gauge strain over the 25 µs that end 5 µs before the reflected foot, between
    /// the two pulses, relative to the incident pulse's peak (compression positive): where an
    /// AC-coupled amplifier's droop after the incident pulse would show.
    between_pulses: f64,
}

/// Foot delays of a test from its gauge strains on the times `t` (FOOT_FRACTION of each pulse's
/// own peak, after FOOT_SMOOTHING_S): the incident pulse is the first compressive pulse of the
/// incident gauge, the reflected one the first tensile pulse 150–500 µs after its foot, the
/// transmitted one the first compressive pulse of the transmission gauge 100–550 µs after it.
fn foot_delays(t: &[f64], eps_incident: &[f64], eps_transmission: &[f64]) -> Option<Delays> {
    let dt = t.get(1)? - t[0];
    // Compression positive.
    let inc = foot_signal(eps_incident, dt);
    let tra = foot_signal(eps_transmission, dt);
    let t_i = pulse_foot(&inc, FOOT_FRACTION)?.time_s(t);
    let foot_in = |y: &[f64], sign: f64, window: (f64, f64)| -> Option<f64> {
        crossing_after(t, y, sign, t_i, window, FOOT_FRACTION)
    };
    let reflected_s = foot_in(&inc, -1.0, REFLECTED_WINDOW_S)?;
    let (a, b) = (
        t.partition_point(|&x| x < t_i + reflected_s - 30e-6),
        t.partition_point(|&x| x <= t_i + reflected_s - 5e-6),
    );
    let peak = inc.iter().copied().fold(0.0, f64::max);
    let between_pulses = inc[a..b].iter().sum::<f64>() / (b - a).max(1) as f64 / peak;
    Some(Delays {
        incident_s: t_i,
        reflected_s,
        transmitted_s: foot_in(&tra, 1.0, TRANSMITTED_WINDOW_S)?,
        between_pulses,
    })
}

/// Where the reflected pulse is looked for: from 150 to 500 µs after the incident foot, s.
const REFLECTED_WINDOW_S: (f64, f64) = (150e-6, 500e-6);

/// Where the transmitted pulse is looked for: from 100 to 550 µs after the incident foot, s.
const TRANSMITTED_WINDOW_S: (f64, f64) = (100e-6, 550e-6);

/// Where the first pulse of `sign · y` (a [`foot_signal`] on the times `t`) inside `window`
/// after `t_i` first rises through `fraction` of its own peak ([`pulse_foot`]), less `t_i`, s.
fn crossing_after(
    t: &[f64],
    y: &[f64],
    sign: f64,
    t_i: f64,
    window: (f64, f64),
    fraction: f64,
) -> Option<f64> {
    let (a, b) = (
        t.partition_point(|&x| x < t_i + window.0),
        t.partition_point(|&x| x <= t_i + window.1),
    );
    let w: Vec<f64> = y[a..b].iter().map(|v| sign * v).collect();
    Some(pulse_foot(&w, fraction)?.time_s(&t[a..b]) - t_i)
}

/// The levels, as fractions of the transmitted pulse's own peak, at which its rise is timed in
/// *Timing* (g); the first is the foot's.
const RISE_LEVELS: [f64; 4] = [FOOT_FRACTION, 0.10, 0.20, 0.50];

/// Scale of the incident wave in the second driven run of *Timing* (g): what the transmitted
/// pulse's timing owes to the incident wave's amplitude.
const DRIVE_SCALE: f64 = 1.10;

/// Times at which the transmitted pulse of a test (transmission-gauge strain on the times `t`,
/// incident foot at `t_i`) first rises through each of [`RISE_LEVELS`] of its peak, less `t_i`, s.
fn transmitted_rise(t: &[f64], eps_transmission: &[f64], t_i: f64) -> Option<[f64; 4]> {
    let y = foot_signal(eps_transmission, t.get(1)? - t[0]);
    let mut out = [0.0; 4];
    for (o, &f) in out.iter_mut().zip(&RISE_LEVELS) {
        *o = crossing_after(t, &y, 1.0, t_i, TRANSMITTED_WINDOW_S, f)?;
    }
    Some(out)
}

/// [`transmitted_rise`] of a virtual test of record `r`, on its own incident foot, less the
/// record's: the residual (simulated − record) at each of [`RISE_LEVELS`], s.
fn rise_residuals(sim: &Simulated, r: &Row) -> [f64; 4] {
    let a = transmitted_rise(&sim.time_s, &sim.transmission_strain, sim.delays.incident_s)
        .expect("a driven test's transmitted pulse rises");
    let b = r.timing.record_rise;
    [a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3]]
}

/// A virtual test of one record's material and pressure with one set-up variant.
struct Simulated {
    /// Foot delays of its gauge signals.
    delays: Delays,
    /// Its reduction (`shpb run`'s reduction of the simulated records).
    reduction: Reduction,
    /// Times of its gauge records, s.
    time_s: Vec<f64>,
    /// Its transmission-gauge strain (noise-free, tension positive).
    transmission_strain: Vec<f64>,
}

/// Runs the virtual test `validation/fig4-virtual-shpb/<scene>.toml` with its set-up changed by
/// `variant`, and measures it.
fn simulate(root: &Path, scene: &str, variant: &dyn Fn(&mut Apparatus)) -> Result<Simulated> {
    simulate_with(root, scene, &|a, _, _| variant(a))
}

/// [`simulate`] with the run's options open to the variant too.
fn simulate_with(
    root: &Path,
    scene: &str,
    variant: &dyn Fn(&mut Apparatus, &mut PulseOptions, Option<&mut Specimen>),
) -> Result<Simulated> {
    let path = root.join(format!("validation/fig4-virtual-shpb/{scene}.toml"));
    let mut params = Params::from_file(&path)?;
    if let SceneParams::Pulse {
        apparatus, options, ..
    } = &mut params.params
    {
        variant(apparatus, options, params.specimen.as_mut());
    }
    let out = params.run()?;
    let bad = |problem: &str| Error::Input {
        file: path.display().to_string(),
        key: "kind".into(),
        problem: problem.into(),
        allowed: "an shpb scene with incident and transmission gauges".into(),
    };
    let t = out.time_s.as_deref().ok_or_else(|| bad("no time axis"))?;
    let strain = |name: &str| {
        out.gauges
            .iter()
            .find(|g| g.name == name)
            .map(|g| g.strain.as_slice())
            .ok_or_else(|| bad("missing gauge"))
    };
    let delays = foot_delays(t, strain("incident")?, strain("transmission")?)
        .ok_or_else(|| bad("no incident, reflected or transmitted foot"))?;
    let reduction = out
        .reduction
        .clone()
        .ok_or_else(|| bad("no reduction of the simulated records"))?;
    Ok(Simulated {
        delays,
        reduction,
        time_s: t.to_vec(),
        transmission_strain: strain("transmission")?.to_vec(),
    })
}

/// [`simulate`] with both gauge paths scaled by `path_scale` ([`with_scaled_paths`]) and the
/// incident bar driven by `drive` instead of gun, striker and shaper; the run is lengthened by
/// the drive's own lead before its incident foot, as a driven scene's default end is.
fn simulate_driven(
    root: &Path,
    scene: &str,
    path_scale: f64,
    drive: IncidentDrive,
) -> Result<Simulated> {
    simulate_driven_with(
        root,
        scene,
        &|a| with_scaled_paths(a, path_scale),
        drive,
        None,
        None,
    )
}

/// [`simulate_driven`] with the gauge geometry set by `geometry` instead, and the specimen's
/// contact law replaced by `law` and its seating by `seating`, each when given.
fn simulate_driven_with(
    root: &Path,
    scene: &str,
    geometry: &dyn Fn(&mut Apparatus),
    drive: IncidentDrive,
    law: Option<LawKind>,
    seating: Option<Seating>,
) -> Result<Simulated> {
    let extra_s = drive.foot_s;
    simulate_with(root, scene, &|a, o, specimen| {
        geometry(a);
        o.end_time_s += extra_s;
        o.incident_drive = Some(drive.clone());
        if let Some(Specimen::Spheres(specimen)) = specimen {
            if let Some(law) = law {
                specimen.law.kind = law;
            }
            if let Some(seating) = seating {
                specimen.seating = seating;
            }
        }
    })
}

/// The seating gap of the probe in *Timing* (g), m.
const PROBE_GAP_M: f64 = 30e-6;

/// The seating preload of the probe in *Timing* (g), N.
const PROBE_PRELOAD_N: f64 = 1e3;

/// A gap of the order of the faces' finish, to read how finely the transmitted foot depends
/// on the seating (*Timing* (g)), m.
const SMALL_GAP_M: f64 = 2e-6;

/// The authors' set-up with 1/4" inserts of bar steel, bar diameter, on both sides.
fn with_inserts(a: &mut Apparatus) {
    let insert = Insert {
        material: a.material,
        diameter_m: a.incident.diameter_m,
        length_m: AUTHORS_INSERT_LENGTH_M,
    };
    a.inserts.incident = Some(insert);
    a.inserts.transmission = Some(insert);
}

/// A heavy insert as a probe of insert inertia (not the authors', whose material and diameter are
/// not stated): 1/4" of tungsten carbide, 1" (25.4 mm) across, on both sides. WC–Co as tabulated
/// for 6 % cobalt grades: ρ = 15 630 kg/m³ (handbook range 14 900–15 700), E = 600 GPa
/// (600–630), ν = 0.22; 50 g each.
fn with_heavy_inserts(a: &mut Apparatus) {
    let insert = Insert {
        material: BarMaterial {
            density_kg_m3: 15_630.0,
            youngs_modulus_pa: 600e9,
            poisson_ratio: 0.22,
        },
        diameter_m: HEAVY_INSERT_DIAMETER_M,
        length_m: AUTHORS_INSERT_LENGTH_M,
    };
    a.inserts.incident = Some(insert);
    a.inserts.transmission = Some(insert);
}

/// Diameter of the heavy-insert probe ([`with_heavy_inserts`]), m.
const HEAVY_INSERT_DIAMETER_M: f64 = 25.4e-3;

/// Effective mass between the bar faces of a reduction over its loading (to the peak back force)
/// and the R² it explains (`shpb_validate::gauge_records::effective_mass_kg`; `z` = E A/c0).
fn mass_between_faces(r: &Reduction, z: f64) -> (f64, f64) {
    let dt = r.time_s[1] - r.time_s[0];
    effective_mass_kg(
        dt,
        &r.force_front_n,
        &r.force_back_n,
        &r.approach_velocity_m_s,
        z,
        r.peak_index + 1,
    )
    .unwrap_or((f64::NAN, f64::NAN))
}

/// The authors' set-up with the incident gauge at `d_m` from the contact (no inserts).
fn with_incident_path(a: &mut Apparatus, d_m: f64) {
    for c in &mut a.gauges.channels {
        if c.name == "incident" {
            c.distance_from_specimen_m = d_m;
        }
    }
}

/// The authors' set-up with the gauges at `(incident, transmission)` m from the specimen (no
/// inserts).
fn with_paths(a: &mut Apparatus, (d_i, d_t): (f64, f64)) {
    for c in &mut a.gauges.channels {
        match c.name.as_str() {
            "incident" => c.distance_from_specimen_m = d_i,
            "transmission" => c.distance_from_specimen_m = d_t,
            _ => {}
        }
    }
}

/// One set-up's gauge paths from the records' own balance (`--align balance`): the mean over the
/// records of the incident and transmission paths each record's balanced delays imply, m.
fn balanced_paths_m(rows: &[Row]) -> (f64, f64) {
    let paths: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| {
            r.aligned[2]
                .alignment
                .balance_paths_m
                .expect("a balanced reduction")
        })
        .collect();
    (
        mean(paths.iter().map(|p| p.0)),
        mean(paths.iter().map(|p| p.1)),
    )
}

/// The authors' set-up with both gauges' distances from the specimen scaled by `s` (no
/// inserts): for arrival times, bars whose wave speed is c0/s on the stated distances.
fn with_scaled_paths(a: &mut Apparatus, s: f64) {
    for c in &mut a.gauges.channels {
        c.distance_from_specimen_m *= s;
    }
}

/// Signed front/back imbalance (F_front − F_back)/F_3wave at the peak back force.
fn signed_imbalance_at_peak(r: &Reduction) -> f64 {
    let k = r.peak_index;
    (r.force_front_n[k] - r.force_back_n[k]) / r.force_3wave_n[k]
}

/// Front/back imbalance F_front − F_back at the peak back force relative to the incident wave's
/// peak force E A max|εI| (`ea_n` = E A of the incident bar): the share of a large wave the
/// two-wave front force must get right.
fn imbalance_of_incident(r: &Reduction, ea_n: f64) -> f64 {
    let k = r.peak_index;
    let peak = r.incident_strain.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    (r.force_front_n[k] - r.force_back_n[k]) / (ea_n * peak)
}

/// Timing and equilibrium of one record against its virtual tests.
struct Timing {
    /// The record's foot delays.
    record: Delays,
    /// Virtual test with the shipped set-up (stated gauge distance, no inserts).
    shipped: Simulated,
    /// With 1/4" inserts on both sides.
    inserts: Simulated,
    /// With the heavy-insert probe on both sides.
    heavy: Simulated,
    /// With the effective incident path (filled once it is fitted).
    effective: Option<Simulated>,
    /// With both gauge paths scaled by d_eff/d_I (filled once d_eff is fitted).
    scaled: Option<Simulated>,
    /// The same geometry driven by the record's own incident wave instead of gun, striker and
    /// shaper (docs/physics.md §6.10).
    driven: Option<Simulated>,
    /// [`transmitted_shape_rms`] of the driven test against the record.
    driven_shape_rms: f64,
    /// The driven test with the record's incident wave scaled by [`DRIVE_SCALE`].
    driven_larger: Option<Simulated>,
    /// The driven test with an elastic Hertz contact instead of the rate-dependent law.
    driven_hertz: Option<Simulated>,
    /// The driven test with the pair seated across a gap of [`PROBE_GAP_M`].
    driven_gap: Option<Simulated>,
    /// The driven test with the pair preloaded by [`PROBE_PRELOAD_N`].
    driven_preload: Option<Simulated>,
    /// The driven test with the pair seated across [`SMALL_GAP_M`].
    driven_small_gap: Option<Simulated>,
    /// (h) The driven test on the gauge paths the records' balance implies ([`balanced_paths_m`]).
    driven_balanced: Option<Simulated>,
    /// (h) The same across a seating gap of [`PROBE_GAP_M`].
    driven_balanced_gap: Option<Simulated>,
    /// The record's [`transmitted_rise`].
    record_rise: [f64; 4],
    /// The record's transmission-gauge strain on its times less its incident foot (s, strain).
    record_transmitted: (Vec<f64>, Vec<f64>),
    /// Record reduced with the reflected window on its own foot delay (transmitted as stated).
    record_reflected_on_foot: Reduction,
    /// Record reduced with the effective incident path (both windows).
    record_effective_path: Option<Reduction>,
    /// Record reduced with both windows on its feet, offset as the effective virtual test's own
    /// reduction offsets them.
    record_on_feet: Option<Reduction>,
    /// The same windows without the dispersion correction.
    record_on_feet_uncorrected: Option<Reduction>,
    /// d(signed imbalance at peak)/d(reflected window delay) around the stated geometry, 1/s.
    sensitivity_per_s: f64,
}

/// The authors' reduction of one record.
struct Authors {
    /// Displacement, m.
    x: Vec<f64>,
    /// Back force, N.
    f: Vec<f64>,
    /// Index of the largest force.
    k_peak: usize,
    /// Largest value of the 11-sample running median (spike-free peak).
    f_peak_median: f64,
}

impl Authors {
    /// Reads an `_authors_reduction.csv`.
    fn read(path: &Path) -> Result<Authors> {
        let t = CsvTable::read(path)?;
        let x = t.column("displacement_m")?.to_vec();
        let f = t.column("force_N")?.to_vec();
        let k_peak = argmax(&f);
        let f_peak_median = (0..f.len())
            .map(|k| {
                let lo = k.saturating_sub(5);
                let hi = (k + 6).min(f.len());
                let mut w = f[lo..hi].to_vec();
                w.sort_by(f64::total_cmp);
                w[w.len() / 2]
            })
            .fold(f64::NEG_INFINITY, f64::max);
        Ok(Authors {
            x,
            f,
            k_peak,
            f_peak_median,
        })
    }
    /// Their peak force, N.
    fn f_peak(&self) -> f64 {
        self.f[self.k_peak]
    }
    /// Their displacement at peak force, m.
    fn x_peak(&self) -> f64 {
        self.x[self.k_peak]
    }
}

/// How the authors' reduction sits on the record, found by least squares (module docs of the
/// report): transmitted window start `m` (record index) and strain scale `scale` from their force;
/// incident and reflected window starts `p`, `q` and the sign of the transmission term from their
/// displacement rate.
struct AuthorsFit {
    /// Transmitted window start, record index.
    m: usize,
    /// Their strain scale relative to ours.
    scale: f64,
    /// RMS residual of the force fit, relative to their peak.
    force_rms: f64,
    /// Incident window start, record index.
    p: usize,
    /// Reflected window start, record index.
    q: usize,
    /// +1: their δ is u_front + u_back; −1: u_front − u_back.
    sign: f64,
    /// RMS residual of the displacement-rate fit with that sign, relative to its largest rate.
    rate_rms: f64,
    /// The other sign's best residual.
    rate_rms_other: f64,
}

/// Fits the authors' reduction `a` with our strains `eps_i`, `eps_t` (see [`AuthorsFit`]); `ea`
/// is the transmission bar's E A, `c0` its wave speed, `dt` the sample interval.
fn fit_authors(eps_i: &[f64], eps_t: &[f64], ea: f64, c0: f64, dt: f64, a: &Authors) -> AuthorsFit {
    let n = eps_t.len();
    let l = a.f.len();
    // (i) F_auth[k] ≈ s·(−EA εT[m + k]).
    let ft: Vec<f64> = eps_t.iter().map(|e| -ea * e).collect();
    let fmax = a.f_peak();
    let (mut best, mut m_best, mut s_best) = (f64::INFINITY, 0, 1.0);
    for m in 0..n - l {
        let seg = &ft[m..m + l];
        let Some(s) = least_squares(&[seg], &a.f) else {
            continue;
        };
        let s = s[0];
        let r: f64 = seg
            .iter()
            .zip(&a.f)
            .map(|(x, y)| (s * x - y).powi(2))
            .sum::<f64>();
        if r < best {
            (best, m_best, s_best) = (r, m, s);
        }
    }
    let force_rms = (best / l as f64).sqrt() / fmax;
    let m = m_best;
    let s = s_best;
    // (ii) ẋ_auth[k] ≈ −c0·s·(εI[p + k] − εI[q + k] + σ εT[m + k]).
    let v: Vec<f64> = (0..l)
        .map(|k| {
            let (lo, hi) = (k.saturating_sub(1), (k + 1).min(l - 1));
            (a.x[hi] - a.x[lo]) / ((hi - lo) as f64 * dt)
        })
        .collect();
    let vmax = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let resid = |p: usize, q: usize, sg: f64| -> f64 {
        (0..l)
            .map(|k| {
                let model = -c0 * s * (eps_i[p + k] - eps_i[q + k] + sg * eps_t[m + k]);
                (model - v[k]).powi(2)
            })
            .sum::<f64>()
    };
    let t_lo = (150e-6 / dt) as usize;
    let t_hi = (260e-6 / dt) as usize;
    let r_lo = (220e-6 / dt) as usize;
    let r_hi = (290e-6 / dt) as usize;
    let mut out = Vec::new();
    for sg in [1.0, -1.0] {
        let mut b = (f64::INFINITY, 0, 0);
        let search = |b: &mut (f64, usize, usize), ps: Vec<usize>, dq: Vec<usize>| {
            for &p in &ps {
                for &d in &dq {
                    let q = p + d;
                    if q + l > n {
                        continue;
                    }
                    let r = resid(p, q, sg);
                    if r < b.0 {
                        *b = (r, p, q);
                    }
                }
            }
        };
        let ps: Vec<usize> = (t_lo..=t_hi)
            .step_by(5)
            .filter_map(|d| m.checked_sub(d))
            .collect();
        search(&mut b, ps, (r_lo..=r_hi).step_by(5).collect());
        let (p0, q0) = (b.1, b.2);
        let ps: Vec<usize> = (p0.saturating_sub(5)..=p0 + 5).collect();
        let d0 = q0 - p0;
        search(&mut b, ps, (d0 - 10..=d0 + 10).collect());
        out.push((sg, (b.0 / l as f64).sqrt() / vmax, b.1, b.2));
    }
    out.sort_by(|a, b| a.1.total_cmp(&b.1));
    AuthorsFit {
        m,
        scale: s,
        force_rms,
        p: out[0].2,
        q: out[0].3,
        sign: out[0].0,
        rate_rms: out[0].1,
        rate_rms_other: out[1].1,
    }
}

/// The set-up read with the authors' formula literally (full Poisson bridge, gain 1).
fn literal(a: &Apparatus) -> Apparatus {
    let mut b = a.clone();
    for c in &mut b.gauges.channels {
        c.bridge.kind = BridgeKind::FullPoisson;
        c.amplifier_gain = 1.0;
    }
    b
}

/// Everything the report says about one record.
struct Row {
    /// Sample number.
    n: usize,
    /// Specimen material, as labelled.
    material: &'static str,
    /// Gun pressure, psi.
    psi: f64,
    /// Our reduction (defaults).
    ours: Reduction,
    /// Our reduction without dispersion correction.
    ours_nodisp: Reduction,
    /// Peak back force read with the authors' formula literally, N.
    literal_peak: f64,
    /// The authors' reduction.
    authors: Authors,
    /// How the authors' reduction sits on the record.
    fit: AuthorsFit,
    /// δ at peak force of our reduction with one of the authors' conventions at a time: their
    /// sign, their window delays, their integration start, their strain scale.
    with_sign: f64,
    /// (See `with_sign`.)
    with_alignment: f64,
    /// (See `with_sign`.)
    with_start: f64,
    /// (See `with_sign`.)
    with_scale: f64,
    /// All of their conventions: δ at their peak-force index, and the curve.
    all_at_their_peak: f64,
    /// (δ, F) of our reduction with all of their conventions.
    all_curve: (Vec<f64>, Vec<f64>),
    /// u_front ± u_back at the end of their window with all their conventions (sign +, −).
    end_plus: f64,
    /// (See `end_plus`.)
    end_minus: f64,
    /// Our reduction with the reflected window on the record's reflected foot.
    record_aligned: Reduction,
    /// Their incident window start (record clock), s.
    their_start_s: f64,
    /// Timing and equilibrium against the virtual tests.
    timing: Timing,
    /// Our reduction with each window alignment of `shpb reduce --align` (geometric, foot,
    /// balance), with the command's defaults otherwise.
    aligned: Vec<Reduction>,
    /// The transmitted delays, s, over which the balanced reduction's RMS imbalance stays within
    /// [`PIN_TOLERANCE`] of its least ([`transmitted_pin`]).
    transmitted_pin_s: (f64, f64),
}

fn main() -> Result<()> {
    let root = common::repo_root();
    let out_dir = root.join("validation/gauge-records");
    let bars = root.join("bars/authors.toml");
    let app = Apparatus::from_file(&bars)?;
    let lit = literal(&app);
    let setup = ReductionSetup::from_apparatus(&app)?;
    let setup_lit = ReductionSetup::from_apparatus(&lit)?;
    let c0 = setup.incident_bar.wave_speed_m_s;
    let ea = setup.transmission_bar.youngs_modulus_pa * setup.transmission_bar.area_m2;
    // Like for like with the authors' reductions, which did not smooth: `shpb reduce --smooth 0`.
    // The alignment section uses `shpb reduce`'s defaults (its default filter).
    let default = ReductionOptions {
        smoothing_window_s: 0.0,
        filter: shpb_core::reduce::Filter::None,
        ..ReductionOptions::default()
    };
    let mut rows = Vec::new();
    for sample in SAMPLES {
        let (n, psi) = (sample.number, sample.psi);
        let material = sample.label.split(' ').next().unwrap_or(sample.material);
        let rec_path = sample.record_path(&root);
        let auth_path = sample.authors_reduction_path(&root);
        let ours = reduce_record_file(&rec_path, &app, &default)?;
        let ours_nodisp = reduce_record_file(
            &rec_path,
            &app,
            &ReductionOptions {
                dispersion: shpb_core::reduce::DispersionCorrection::None,
                ..default
            },
        )?;
        let literal_peak = reduce_record_file(&rec_path, &lit, &default)?.peak_back_force_n;
        let authors = Authors::read(&auth_path)?;
        let rec = RawRecord::read(&rec_path)?;
        let input = record_strains(&rec, &app, default.baseline_samples)?;
        let dt = rec.sample_interval_s();
        let fit = fit_authors(
            &input.incident_strain,
            &input.transmission_strain,
            ea,
            c0,
            dt,
            &authors,
        );
        let t = &input.time_s;
        let l = authors.f.len();
        let their_start = t[fit.p];
        let their_r = (fit.q - fit.p) as f64 * dt;
        let their_t = (fit.m - fit.p) as f64 * dt;
        let with = |w: WindowOverride| -> Result<Reduction> {
            reduce(
                &input,
                &setup,
                &ReductionOptions {
                    window: Some(w),
                    ..default
                },
            )
            .map_err(Error::from)
        };
        let at_peak = |r: &Reduction| r.displacement_m[r.peak_index];
        let with_sign = ours.front_displacement_m[ours.peak_index]
            + fit.sign * ours.back_displacement_m[ours.peak_index];
        let with_alignment = at_peak(&with(WindowOverride {
            reflected_delay_s: Some(their_r),
            transmitted_delay_s: Some(their_t),
            ..WindowOverride::default()
        })?);
        let with_start = at_peak(&with(WindowOverride {
            incident_start_s: Some(their_start),
            ..WindowOverride::default()
        })?);
        // Their strain scale (≈ 1 of ours, or ≈ 2 = the literal formula for sample 1).
        let scaled_setup = if fit.scale > 1.5 { &setup_lit } else { &setup };
        let scaled_input = if fit.scale > 1.5 {
            record_strains(&rec, &lit, default.baseline_samples)?
        } else {
            input.clone()
        };
        let with_scale = at_peak(&reduce(&scaled_input, scaled_setup, &default)?);
        let all = reduce(
            &scaled_input,
            scaled_setup,
            &ReductionOptions {
                window: Some(WindowOverride {
                    incident_start_s: Some(their_start),
                    reflected_delay_s: Some(their_r),
                    transmitted_delay_s: Some(their_t),
                    duration_s: Some((l - 1) as f64 * dt),
                }),
                ..default
            },
        )?;
        let conv: Vec<f64> = (0..all.time_s.len())
            .map(|k| all.front_displacement_m[k] + fit.sign * all.back_displacement_m[k])
            .collect();
        let kp = authors.k_peak.min(conv.len() - 1);
        let last = conv.len() - 1;
        let record_aligned = match ours.measured_reflected_delay_s {
            Some(d) => with(WindowOverride {
                reflected_delay_s: Some(d),
                transmitted_delay_s: Some(
                    0.5 * d + setup.transmission_gauge_m / setup.transmission_bar.wave_speed_m_s,
                ),
                ..WindowOverride::default()
            })?,
            None => ours.clone(),
        };
        let record_delays = foot_delays(t, &input.incident_strain, &input.transmission_strain)
            .ok_or_else(|| Error::Input {
                file: rec_path.display().to_string(),
                key: "incident_V".into(),
                problem: "no incident, reflected or transmitted foot".into(),
                allowed: "a record with the three pulses".into(),
            })?;
        let record_reflected_on_foot = with(WindowOverride {
            reflected_delay_s: Some(record_delays.reflected_s),
            ..WindowOverride::default()
        })?;
        let nominal_r = ours.windows.reflected_delay_s;
        let shifted = |d: f64| -> Result<f64> {
            Ok(signed_imbalance_at_peak(&with(WindowOverride {
                reflected_delay_s: Some(nominal_r + d),
                ..WindowOverride::default()
            })?))
        };
        let sensitivity_per_s = (shifted(1e-6)? - shifted(-1e-6)?) / 2e-6;
        let timing = Timing {
            record: record_delays,
            shipped: simulate(&root, sample.scene, &|_| {})?,
            inserts: simulate(&root, sample.scene, &with_inserts)?,
            heavy: simulate(&root, sample.scene, &with_heavy_inserts)?,
            effective: None,
            scaled: None,
            driven: None,
            driven_shape_rms: f64::NAN,
            driven_larger: None,
            driven_hertz: None,
            driven_gap: None,
            driven_preload: None,
            driven_small_gap: None,
            driven_balanced: None,
            driven_balanced_gap: None,
            record_rise: transmitted_rise(t, &input.transmission_strain, record_delays.incident_s)
                .ok_or_else(|| Error::Input {
                    file: rec_path.display().to_string(),
                    key: "transmission_V".into(),
                    problem: "no transmitted pulse rising through 50 % of its peak".into(),
                    allowed: "a record with the three pulses".into(),
                })?,
            record_transmitted: (
                t.iter().map(|x| x - record_delays.incident_s).collect(),
                input.transmission_strain.clone(),
            ),
            record_reflected_on_foot,
            record_effective_path: None,
            record_on_feet: None,
            record_on_feet_uncorrected: None,
            sensitivity_per_s,
        };
        let aligned = Alignment::ALL
            .into_iter()
            .map(|alignment| {
                reduce(
                    &input,
                    &setup,
                    &ReductionOptions {
                        alignment,
                        ..ReductionOptions::default()
                    },
                )
                .map_err(Error::from)
            })
            .collect::<Result<Vec<_>>>()?;
        let transmitted_pin_s = transmitted_pin(&input, &setup, &aligned[2])?;
        rows.push(Row {
            aligned,
            transmitted_pin_s,
            n,
            material,
            psi,
            literal_peak,
            with_sign,
            with_alignment,
            with_start,
            with_scale,
            all_at_their_peak: conv[kp],
            end_plus: all.front_displacement_m[last] + all.back_displacement_m[last],
            end_minus: all.front_displacement_m[last] - all.back_displacement_m[last],
            all_curve: (conv, all.force_back_n.clone()),
            authors,
            fit,
            ours,
            ours_nodisp,
            record_aligned,
            their_start_s: their_start,
            timing,
        });
    }

    // The effective incident path: the one gauge-to-contact distance that makes the simulated
    // reflected delay match the eight records' on average (docs/physics.md §7.5).
    let fit = effective_path(&rows, &app);
    let path_scale = fit.d_m / stated_paths_m(&app).0;
    let balanced_paths = balanced_paths_m(&rows);
    for (r, sample) in rows.iter_mut().zip(SAMPLES) {
        let sim = simulate(&root, sample.scene, &|a| with_incident_path(a, fit.d_m))?;
        r.timing.scaled = Some(simulate(&root, sample.scene, &|a| {
            with_scaled_paths(a, path_scale)
        })?);
        let rec = RawRecord::read(&sample.record_path(&root))?;
        let input = record_strains(&rec, &app, default.baseline_samples)?;
        let drive = IncidentDrive::from_incident_gauge(
            &input.time_s,
            &input.incident_strain,
            app.material.youngs_modulus_pa,
        )
        .ok_or_else(|| Error::Input {
            file: sample.record_path(&root).display().to_string(),
            key: "incident_V".into(),
            problem: "no incident pulse".into(),
            allowed: "a record with an incident pulse".into(),
        })?;
        let larger = IncidentDrive {
            stress_pa: drive.stress_pa.iter().map(|s| s * DRIVE_SCALE).collect(),
            ..drive.clone()
        };
        r.timing.driven_larger = Some(simulate_driven(&root, sample.scene, path_scale, larger)?);
        let variant = |law: Option<LawKind>, seating: Option<Seating>| {
            simulate_driven_with(
                &root,
                sample.scene,
                &|a| with_scaled_paths(a, path_scale),
                drive.clone(),
                law,
                seating,
            )
            .map(Some)
        };
        r.timing.driven_hertz = variant(Some(LawKind::Hertz), None)?;
        r.timing.driven_gap = variant(None, Some(Seating::Gap { gap_m: PROBE_GAP_M }))?;
        r.timing.driven_small_gap = variant(None, Some(Seating::Gap { gap_m: SMALL_GAP_M }))?;
        r.timing.driven_preload = variant(
            None,
            Some(Seating::Preload {
                force_n: PROBE_PRELOAD_N,
            }),
        )?;
        // (h): the gauge paths the records' own balance implies, touching and across the gap.
        let balanced = |seating| {
            simulate_driven_with(
                &root,
                sample.scene,
                &|a| with_paths(a, balanced_paths),
                drive.clone(),
                None,
                seating,
            )
            .map(Some)
        };
        r.timing.driven_balanced = balanced(None)?;
        r.timing.driven_balanced_gap = balanced(Some(Seating::Gap { gap_m: PROBE_GAP_M }))?;
        let driven = simulate_driven(&root, sample.scene, path_scale, drive)?;
        r.timing.driven_shape_rms = transmitted_shape_rms(
            &driven,
            &input.time_s,
            &input.transmission_strain,
            &r.timing.record,
        );
        r.timing.driven = Some(driven);
        let run_with = |w: WindowOverride, dispersion| -> Result<Reduction> {
            reduce(
                &input,
                &setup,
                &ReductionOptions {
                    window: Some(w),
                    dispersion,
                    ..default
                },
            )
            .map_err(Error::from)
        };
        let run = |w: WindowOverride| run_with(w, default.dispersion);
        r.timing.record_effective_path = Some(run(WindowOverride {
            reflected_delay_s: Some(2.0 * fit.d_m / c0),
            transmitted_delay_s: Some(
                (fit.d_m + setup.transmission_gauge_m) / setup.transmission_bar.wave_speed_m_s,
            ),
            ..WindowOverride::default()
        })?);
        // The simulated test's own windows sit this far before its feet.
        let w = &sim.reduction.windows;
        let (off_r, off_t) = (
            sim.delays.reflected_s - w.reflected_delay_s,
            sim.delays.transmitted_s - w.transmitted_delay_s,
        );
        let on_feet = WindowOverride {
            reflected_delay_s: Some(r.timing.record.reflected_s - off_r),
            transmitted_delay_s: Some(r.timing.record.transmitted_s - off_t),
            ..WindowOverride::default()
        };
        r.timing.record_on_feet = Some(run(on_feet)?);
        r.timing.record_on_feet_uncorrected = Some(run_with(
            on_feet,
            shpb_core::reduce::DispersionCorrection::None,
        )?);
        r.timing.effective = Some(sim);
    }

    // The held-out day, each record driven by its own incident wave (docs/physics.md §6.10).
    let day = SAMPLES_2013_06_06
        .iter()
        .map(|d| -> Result<DayRow> {
            let path = d.record_path(&root);
            let rec = RawRecord::read(&path)?;
            let input = record_strains(&rec, &app, default.baseline_samples)?;
            let record = reduce(&input, &setup, &default)?;
            let balanced = reduce(
                &input,
                &setup,
                &ReductionOptions {
                    alignment: Alignment::Balance,
                    ..ReductionOptions::default()
                },
            )?;
            let no_feet = || Error::Input {
                file: path.display().to_string(),
                key: "incident_V".into(),
                problem: "no incident, reflected or transmitted foot".into(),
                allowed: "a record with the three pulses".into(),
            };
            let delays = foot_delays(
                &input.time_s,
                &input.incident_strain,
                &input.transmission_strain,
            )
            .ok_or_else(no_feet)?;
            let drive = IncidentDrive::from_incident_gauge(
                &input.time_s,
                &input.incident_strain,
                app.material.youngs_modulus_pa,
            )
            .ok_or_else(no_feet)?;
            let scene = format!("{}-10psi", d.material);
            let simulated = simulate_driven(&root, &scene, path_scale, drive)?;
            Ok(DayRow {
                number: d.number,
                label: d.authors_label,
                material: d.material,
                incident_peak_pa: incident_peak_pa(&record, app.material.youngs_modulus_pa),
                shape_rms: transmitted_shape_rms(
                    &simulated,
                    &input.time_s,
                    &input.transmission_strain,
                    &delays,
                ),
                delays,
                simulated,
                record,
                balanced,
            })
        })
        .collect::<Result<Vec<_>>>()?;

    // Plots.
    for r in &rows {
        let png = out_dir.join(format!("sample{}_force_displacement.png", r.n));
        let title = format!("2013-05-22 sample {}: {} at {} psi", r.n, r.material, r.psi);
        xy_plot(
            &png,
            true,
            &Axes {
                title: &title,
                x_label: "sphere approach δ (µm)",
                y_label: "back (transmitted) force (kN)",
                x_scale: 1e6,
                y_scale: 1e-3,
            },
            &[
                Curve {
                    label: "shpb reduce (ours)".into(),
                    x: &r.ours.displacement_m,
                    y: &r.ours.force_back_n,
                    measured: false,
                },
                Curve {
                    label: "ours with the authors' conventions".into(),
                    x: &r.all_curve.0,
                    y: &r.all_curve.1,
                    measured: false,
                },
                Curve {
                    label: "authors' reduction".into(),
                    x: &r.authors.x,
                    y: &r.authors.f,
                    measured: true,
                },
            ],
        )?;
    }

    transmitted_figure(
        &out_dir.join(TRANSMITTED_PNG),
        &rows,
        app.material.youngs_modulus_pa,
    )?;

    balanced_figure(&out_dir.join(BALANCED_PNG), &rows)?;

    let md = report(&rows, &day, &app, &fit)?;
    let path = out_dir.join("REPORT.md");
    std::fs::write(&path, md).map_err(|e| Error::io(&path, e))?;
    println!("wrote {} and {} plots", path.display(), rows.len() + 2);
    Ok(())
}

/// A curve of a figure: label, abscissae, ordinates, whether measured.
type Trace = (String, Vec<f64>, Vec<f64>, bool);

/// The figure of *Timing* (g): each record's transmitted pulse against its driven tests.
const TRANSMITTED_PNG: &str = "transmitted_driven.png";

/// Writes [`TRANSMITTED_PNG`]: per record, the transmission-gauge stress (compression positive,
/// on the feet's moving average) against the time since the incident foot, record and driven
/// tests touching, across the probe gap and preloaded.
fn transmitted_figure(path: &Path, rows: &[Row], e_pa: f64) -> Result<()> {
    let stress = |t: &[f64], eps: &[f64]| -> Vec<f64> {
        foot_signal(eps, t[1] - t[0])
            .iter()
            .map(|x| x * e_pa)
            .collect()
    };
    let window = |t: &[f64]| {
        (
            t.partition_point(|&x| x < TRANSMITTED_WINDOW_S.0 + 80e-6),
            t.partition_point(|&x| x <= TRANSMITTED_WINDOW_S.0 + 380e-6),
        )
    };
    // (time since the incident foot, stress) of each curve of each record.
    let series: Vec<Vec<Trace>> = rows
        .iter()
        .map(|r| {
            let (tr, er) = &r.timing.record_transmitted;
            let mut v = vec![("record".to_string(), tr.clone(), stress(tr, er), true)];
            let sims: [(&str, Option<&Simulated>); 3] = [
                ("driven, touching (f)", Some(driven(r))),
                ("driven, gap", r.timing.driven_gap.as_ref()),
                ("driven, preload", r.timing.driven_preload.as_ref()),
            ];
            for (label, sim) in sims {
                if let Some(x) = sim {
                    let t: Vec<f64> = x.time_s.iter().map(|t| t - x.delays.incident_s).collect();
                    let y = stress(&x.time_s, &x.transmission_strain);
                    v.push((label.to_string(), t, y, false));
                }
            }
            // A point every 0.5 µs (plot_stride).
            v.into_iter()
                .map(|(label, t, y, measured)| {
                    let (a, b) = window(&t);
                    let every = plot_stride(&t);
                    let pick = |x: &[f64]| x[a..b].iter().step_by(every).copied().collect();
                    (label, pick(&t), pick(&y), measured)
                })
                .collect()
        })
        .collect();
    record_panels(
        path,
        rows,
        &series,
        (
            "time since the incident foot (µs)",
            "transmission-gauge stress (MPa)",
        ),
        1e-6,
    )
}

/// The RMS front/back imbalance a reduction's baseline noise alone gives, relative to its 3-wave
/// peak: E A √(2 σ_I² + σ_T²) (the front force adds two samples of the incident channel).
fn noise_floor(r: &Reduction, ea_n: f64) -> f64 {
    let (si, st) = r.quality.noise_strain;
    let peak = r.force_3wave_n.iter().copied().fold(0.0, f64::max);
    ea_n * (2.0 * si * si + st * st).sqrt() / peak
}

/// (h)'s two driven tests of a record: touching, and across the probe gap.
fn balanced_sims(r: &Row) -> (&Simulated, &Simulated) {
    (
        r.timing
            .driven_balanced
            .as_ref()
            .expect("run before the report"),
        r.timing
            .driven_balanced_gap
            .as_ref()
            .expect("run before the report"),
    )
}

/// (h) Each record's driven test on the gauge paths the records' balance implies, touching and
/// across the probe gap: residual arrivals against the record, reflected foot and transmitted
/// rise level by level.
fn balanced_timing_paragraph(w: &mut String, rows: &[Row], c0: f64) {
    let (d_i, d_t) = balanced_paths_m(rows);
    let levels: Vec<String> = RISE_LEVELS
        .iter()
        .map(|f| format!("{:.0}", f * 100.0))
        .collect();
    let slash = levels.join(" / ");
    let _ = writeln!(
        w,
        "\n**(h) Arrivals on the balanced paths.** One set-up's gauge paths from the records' own \
         balance: the mean over the eight records of the paths in the table above, incident \
         {d_i:.4} m and transmission {d_t:.4} m. Each record's driven test (its own incident \
         wave, docs/physics.md §6.10) on these paths, touching and across a {:.0} µm gap; \
         residuals simulated − record of the reflected foot and of the transmitted pulse where it \
         first rises through {slash} % of its peak (as (g)).\n",
        PROBE_GAP_M * 1e6
    );
    let _ = writeln!(
        w,
        "| sample | specimen | reflected foot (µs): touching / gap | transmitted at {slash} % (µs), touching | the same across the gap |\n\
         |---|---|---|---|---|"
    );
    let signed = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{:+.1}", x * 1e6))
            .collect::<Vec<_>>()
            .join(" / ")
    };
    // Residuals simulated − record, once per seating (0 touching, 1 across the gap) and record:
    // the reflected foot, and the transmitted rise at each of RISE_LEVELS, s.
    let residuals: [Vec<(f64, [f64; 4])>; 2] = [0, 1].map(|seated| {
        rows.iter()
            .map(|r| {
                let (t, g) = balanced_sims(r);
                let x = if seated == 1 { g } else { t };
                (
                    x.delays.reflected_s - r.timing.record.reflected_s,
                    rise_residuals(x, r),
                )
            })
            .collect()
    });
    for (k, r) in rows.iter().enumerate() {
        let (t, g) = (residuals[0][k], residuals[1][k]);
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {} | {} | {} |",
            r.n,
            r.material,
            r.psi,
            signed(&[t.0, g.0]),
            signed(&t.1),
            signed(&g.1),
        );
    }
    let within = |v: &[f64]| v.iter().filter(|x| x.abs() <= 3e-6).count();
    // Mean ± sd and how many records fall within 3 µs, of residuals in s.
    let stats = |v: &[f64]| {
        let m = mean(v.iter().copied());
        format!(
            "{:+.1} ± {:.1} µs ({} within 3 µs)",
            m * 1e6,
            sample_sd(v, m) * 1e6,
            within(v)
        )
    };
    let reflected = |seated: usize| -> Vec<f64> { residuals[seated].iter().map(|x| x.0).collect() };
    let level = |seated: usize, k: usize| -> Vec<f64> {
        residuals[seated].iter().map(|x| x.1[k]).collect()
    };
    let per_level = |seated: usize| {
        (0..RISE_LEVELS.len())
            .map(|k| format!("{} %: {}", levels[k], stats(&level(seated, k))))
            .collect::<Vec<_>>()
            .join("; ")
    };
    let reflected_all = [reflected(0), reflected(1)].concat();
    // The best level and seating for the transmitted arrival: most records within 3 µs.
    let best_transmitted = (0..2)
        .flat_map(|seated| (0..RISE_LEVELS.len()).map(move |k| (seated, k)))
        .map(|(seated, k)| within(&level(seated, k)))
        .max()
        .unwrap_or(0);
    let (p_lo, p_hi) = min_max(rows.iter().map(|r| {
        r.aligned[2]
            .alignment
            .balance_paths_m
            .map_or(f64::NAN, |p| p.1)
    }));
    let _ = writeln!(
        w,
        "\nReflected foot: {} touching, {} across the gap. Transmitted, touching: {}. Across the \
         gap: {}. Reading: on paths taken from the records' own balance the reflected foot comes \
         within 3 µs of the record's on {} of {} runs, but late by about one constant on all of \
         them: the balance weighs the reflected pulse's body, the 2 % foot sits in its toe (the \
         path fitted on the feet themselves, variant (e) above, removes the constant). The \
         transmitted pulse comes within 3 µs on at most {} of {} records at any level, touching \
         or seated, though across the gap its mean residual at 20 % is small: the paths are a \
         mean over records whose balanced transmission paths differ by up to {:.0} mm ({:.1} µs), \
         and the pair's seating moves the toe against the body. One set-up constant does not \
         place every record's transmitted pulse within 3 µs on the gauge's clock; at the faces \
         (figure `{BALANCED_PNG}`) the simulated and the balanced recorded forces agree as the \
         table above says.\n",
        stats(&reflected(0)),
        stats(&reflected(1)),
        per_level(0),
        per_level(1),
        within(&reflected_all),
        reflected_all.len(),
        best_transmitted,
        rows.len(),
        (p_hi - p_lo) * 1e3,
        (p_hi - p_lo) / c0 * 1e6,
    );
}

/// When a reduction's back force first rises through half its peak (linear between samples), s
/// on its time axis.
fn half_rise_s(r: &Reduction) -> f64 {
    let f = &r.force_back_n;
    let level = 0.5 * f[r.peak_index];
    (1..=r.peak_index)
        .find(|&k| f[k] >= level)
        .map_or(f64::NAN, |k| {
            let a = (level - f[k - 1]) / (f[k] - f[k - 1]);
            r.time_s[k - 1] + a * (r.time_s[k] - r.time_s[k - 1])
        })
}

/// The figure of *The windows that balance the records*.
const BALANCED_PNG: &str = "balanced_windows.png";

/// Writes [`BALANCED_PNG`]: per record, the front and back forces through the stated windows and
/// through the balanced ones (`--align balance`), and the virtual test's back force.
fn balanced_figure(path: &Path, rows: &[Row]) -> Result<()> {
    let series: Vec<Vec<Trace>> = rows
        .iter()
        .map(|r| {
            let (stated, balanced) = (&r.aligned[0], &r.aligned[2]);
            let sim = &r.timing.shipped.reduction;
            [
                ("front, stated windows", stated, false),
                ("back, stated windows", stated, true),
                ("front, balanced windows", balanced, false),
                ("back, balanced windows", balanced, true),
                ("virtual test (a), back", sim, true),
            ]
            .into_iter()
            .map(|(label, x, back)| {
                let y = if back {
                    &x.force_back_n
                } else {
                    &x.force_front_n
                };
                let every = plot_stride(&x.time_s);
                let pick = |v: &[f64]| -> Vec<f64> { v.iter().step_by(every).copied().collect() };
                (label.to_string(), pick(&x.time_s), pick(y), false)
            })
            .collect()
        })
        .collect();
    record_panels(
        path,
        rows,
        &series,
        ("time at the faces (µs)", "force (kN)"),
        1e-3,
    )
}

/// Every how many samples of the series on times `t` a figure takes a point: one per 0.5 µs
/// shows all there is on the 2 µs-smoothed traces (and keeps the PNGs small).
fn plot_stride(t: &[f64]) -> usize {
    ((0.5e-6 / (t[1] - t[0])).round() as usize).max(1)
}

/// Writes one panel per record (4 across, titled by sample, material and pressure) of its
/// `series`, time in µs against the quantity times `y_scale`, labelled `(x, y)`.
fn record_panels(
    path: &Path,
    rows: &[Row],
    series: &[Vec<Trace>],
    (x_label, y_label): (&str, &str),
    y_scale: f64,
) -> Result<()> {
    let titles: Vec<String> = rows
        .iter()
        .map(|r| format!("sample {}: {} at {} psi", r.n, r.material, r.psi))
        .collect();
    let panels: Vec<(Axes, Vec<Curve>)> = series
        .iter()
        .zip(&titles)
        .map(|(curves, title)| {
            (
                Axes {
                    title,
                    x_label,
                    y_label,
                    x_scale: 1e6,
                    y_scale,
                },
                curves
                    .iter()
                    .map(|(label, t, y, measured)| Curve {
                        label: label.clone(),
                        x: t,
                        y,
                        measured: *measured,
                    })
                    .collect(),
            )
        })
        .collect();
    panels_figure(path, true, 4, &panels)
}

/// A time or a displacement in µs or µm, one decimal.
fn us(x: f64) -> String {
    format!("{:.1}", x * 1e6)
}

/// The text of REPORT.md.
fn report(rows: &[Row], day: &[DayRow], app: &Apparatus, fit: &PathFit) -> Result<String> {
    let mut md = String::new();
    let w = &mut md;
    let inc = app.gauges.channel("incident").expect("incident channel");
    let c0 = app.material.wave_speed_m_s();
    let pass = rows
        .iter()
        .filter(|r| (r.ours.peak_back_force_n / r.authors.f_peak() - 1.0).abs() <= TOLERANCE)
        .count();
    let (d_i, d_t) = stated_paths_m(app);
    // Writing to a String cannot fail.
    let _ = writeln!(
        w,
        "# Gauge records of 2013-05-22: our reduction against the authors'\n"
    );
    let _ = writeln!(
        w,
        "Generated by `cargo run --release -p shpb-validate --bin gauge_records_report` \
         (crates/validate/src/bin/gauge_records_report.rs); do not edit by hand. Records and the authors' reductions: \
         `validation/gauge-records/data/` (Daraio-lab/Burgoyne_PRE_2014, CC-BY 4.0). The same \
         reduction is `shpb reduce RECORD --bars bars/authors.toml --smooth 0 -o OUT.h5` (no filter, as the authors; the last section uses the command's default filter).\n"
    );
    let _ = writeln!(w, "## Set-up and rules\n");
    let _ = writeln!(
        w,
        "* Bars (`bars/authors.toml`): E = {:.0} GPa, c0 = {:.1} m/s, radius {:.3} mm, ν = {}; incident \
         gauge d_I = {d_i} m, transmission gauge d_T = {d_t} m from the specimen faces.",
        app.material.youngs_modulus_pa / 1e9,
        c0,
        app.incident.diameter_m / 2.0 * 1e3,
        app.material.poisson_ratio
    );
    let _ = writeln!(
        w,
        "* **Bridge configuration** (`bars/gauges-authors.toml`, both channels): `{}` bridge, amplifier \
         gain {}, GF {}, Vex {} V, polarity {:+}: the recorded volts read as **half the strain of the \
         authors' literal formula** σ = −E·2V/(Vex·GF·((1+ν) + V(ν−1)/Vex)) (the formula is the \
         full-Poisson-bridge inverse at gain 1; see the section *Bridge* below).",
        inc.bridge.kind.name(),
        inc.amplifier_gain,
        inc.bridge.gauge_factor,
        inc.bridge.excitation_v,
        inc.polarity
    );
    let _ = writeln!(
        w,
        "* Windows (src/reduce.rs): baseline = mean of the first 900 samples (90 µs of pre-trigger); \
         incident start t_I = last sample before the first incident peak below 2 % of it; reflected \
         window from t_I + 2d_I/c0 = t_I + {} µs, transmitted from t_I + (d_I + d_T)/c0 = t_I + {} µs \
         (specimen transit neglected), fractional delays applied by Fourier phase shift; length \
         2(L_I − d_I)/c0 = {} µs (the reflected wave's return from the impact end). t = 0 is the \
         incident foot at the specimen face. Dispersion correction on (Bancroft, ν = 0.31 fit), \
         δ = u_front − u_back (compression positive), F_back = −E A εT.",
        us(2.0 * d_i / c0),
        us((d_i + d_t) / c0),
        us(2.0 * (app.incident.length_m - d_i) / c0)
    );
    let _ = writeln!(
        w,
        "* Acceptance: peak back force within {:.0} % of the authors' reduction (largest `force_N` of \
         `_authors_reduction.csv`) for at least 6 of 8 records: **{pass} of 8 pass**.\n",
        TOLERANCE * 100.0
    );

    let _ = writeln!(w, "## Per sample\n");
    let _ = writeln!(
        w,
        "| sample | specimen | peak F_back ours (kN) | authors (kN) | ours/authors | ±15 % | δ at peak ours (µm) | authors (µm) | difference (µm) | equilibrium ratio at peak | reflected foot in record − t_I (µs) |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let ratio = r.ours.peak_back_force_n / r.authors.f_peak();
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {:.2} | {:.2} | {:.3} | {} | {} | {} | {:+.1} | {:.2} | {} |",
            r.n,
            r.material,
            r.psi,
            r.ours.peak_back_force_n / 1e3,
            r.authors.f_peak() / 1e3,
            ratio,
            if (ratio - 1.0).abs() <= TOLERANCE {
                "pass"
            } else {
                "fail"
            },
            us(r.ours.displacement_at_peak_force_m),
            us(r.authors.x_peak()),
            (r.ours.displacement_at_peak_force_m - r.authors.x_peak()) * 1e6,
            r.ours.equilibrium_ratio_at_peak,
            r.ours
                .measured_reflected_delay_s
                .map(us)
                .unwrap_or_else(|| "–".into())
        );
    }
    let _ = writeln!(
        w,
        "\nPlots: `sample<N>_force_displacement.png` (ours, ours with the authors' conventions, and the \
         authors' reduction dashed).\n"
    );

    let _ = writeln!(w, "## Bridge: which reading explains the records\n");
    let _ = writeln!(
        w,
        "A least-squares fit of each authors' force history to our transmitted force −E A εT (any \
         window start, free scale) gives the strain scale their reduction used relative to ours, with \
         the residual of the fit. The literal formula (full Poisson bridge, gain 1) doubles our \
         strains.\n"
    );
    let _ = writeln!(
        w,
        "| sample | gun (psi) | our incident peak (MPa) | authors' scale / ours | RMS residual (of peak) | peak F_back literal formula (kN) | literal / authors |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            w,
            "| {} | {} | {:.0} | {:.3} | {:.3} | {:.2} | {:.2} |",
            r.n,
            r.psi,
            incident_peak_pa(&r.ours, app.material.youngs_modulus_pa) / 1e6,
            r.fit.scale,
            r.fit.force_rms,
            r.literal_peak / 1e3,
            r.literal_peak / r.authors.f_peak()
        );
    }
    let s1 = &rows[0];
    let _ = writeln!(
        w,
        "\nSamples 2–8 were reduced by the authors at half the literal formula's strain (scale \
         {:.3}–{:.3}); the reading of `bars/gauges-authors.toml` reproduces them. Sample 1 was reduced \
         with the formula literally (scale {:.3}): its force is twice ours ({:.1} kN against {:.1} kN), \
         and at 10 psi it would be the strongest transmitted pulse of the day, above samples 2–3 at \
         12.5–15 psi (ours: {:.1}, {:.1} kN) and the 12.3 kN of the paper's Fig. 4 data at 10 psi, \
         while its incident pulse read like the others ({:.0} MPa) matches sample 6 at the same \
         10 psi ({:.0} MPa) and falls below those at 12.5–15 psi. So one bridge reading \
         explains all eight records, and the authors' sample-1 reduction is the odd one out: it \
         applies the factor-2 formula that their other seven reductions do not. We keep one reading \
         for all records; sample 1 therefore fails the 15 % criterion by construction (ratio {:.2}).\n",
        rows[1..]
            .iter()
            .map(|r| r.fit.scale)
            .fold(f64::INFINITY, f64::min),
        rows[1..].iter().map(|r| r.fit.scale).fold(0.0, f64::max),
        s1.fit.scale,
        s1.authors.f_peak() / 1e3,
        s1.ours.peak_back_force_n / 1e3,
        rows[1].ours.peak_back_force_n / 1e3,
        rows[2].ours.peak_back_force_n / 1e3,
        incident_peak_pa(&s1.ours, app.material.youngs_modulus_pa) / 1e6,
        incident_peak_pa(&rows[5].ours, app.material.youngs_modulus_pa) / 1e6,
        s1.ours.peak_back_force_n / s1.authors.f_peak()
    );
    let spiky: Vec<&Row> = rows
        .iter()
        .filter(|r| r.authors.f_peak() > 1.08 * r.authors.f_peak_median)
        .collect();
    if !spiky.is_empty() {
        let _ = writeln!(
            w,
            "Peaks of the authors' reductions that are single-sample spikes (more than 8 % above the \
             11-sample running median, not present in the raw records): {}. Against the spike-free \
             peak our ratios are {}. The spikes sit at sample index {} of their series, where the \
             raw transmission record is smooth: an artefact of their processing (plausibly of \
             `disp_corr.m`, which projects on cos(kω0t), sin(kω0t) with ω0 = 2π/t_end, functions that \
             are not orthogonal on the window), not of the tests. They lift the authors' peaks by {} % \
             above the spike-free ones, which is why our ratios for these samples are the lowest of \
             the passing ones.\n",
            spiky
                .iter()
                .map(|r| format!(
                    "sample {} ({:.2} kN spike, {:.2} kN median peak)",
                    r.n,
                    r.authors.f_peak() / 1e3,
                    r.authors.f_peak_median / 1e3
                ))
                .collect::<Vec<_>>()
                .join(", "),
            spiky
                .iter()
                .map(|r| format!(
                    "{:.3} (sample {})",
                    r.ours.peak_back_force_n / r.authors.f_peak_median,
                    r.n
                ))
                .collect::<Vec<_>>()
                .join(", "),
            spiky
                .iter()
                .map(|r| r.authors.k_peak.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            spiky
                .iter()
                .map(|r| format!(
                    "{:.0}",
                    (r.authors.f_peak() / r.authors.f_peak_median - 1.0) * 100.0
                ))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let _ = writeln!(
        w,
        "Dispersion correction changes our peak back force by {} % (off → on, per sample).\n",
        rows.iter()
            .map(|r| format!(
                "{:+.1}",
                (r.ours.peak_back_force_n / r.ours_nodisp.peak_back_force_n - 1.0) * 100.0
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );

    let _ = writeln!(w, "## Displacement: what the authors did\n");
    let _ = writeln!(
        w,
        "The authors' displacement rate ẋ was fitted by our raw gauge strains (no dispersion \
         correction) in their scale s as `ẋ = −c0·s·(εI(t_p + t) − εI(t_q + t) ± εT(t_m + t))`, \
         searching the incident and reflected window starts t_p, t_q and the sign, with the \
         transmitted start t_m from the force fit above. `+` means their δ is u_front + u_back, `−` \
         the physical u_front − u_back. The delays are relative to their incident window start t_p \
         (record clock); ours are 2d_I/c0 = {} µs and (d_I + d_T)/c0 = {} µs from our foot t_I.\n",
        us(2.0 * d_i / c0),
        us((d_i + d_t) / c0)
    );
    let _ = writeln!(
        w,
        "| sample | sign | RMS residual (of max ẋ) | other sign | their t_p (µs) | our t_I (µs) | their reflected delay (µs) | their transmitted delay (µs) | x_end authors (µm) | u_f + u_b (µm) | u_f − u_b (µm) |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let dt = 1e-7;
        let t_p = r.their_start_s;
        let _ = writeln!(
            w,
            "| {} | {} | {:.3} | {:.3} | {} | {} | {} | {} | {} | {} | {} |",
            r.n,
            if r.fit.sign > 0.0 { "+" } else { "−" },
            r.fit.rate_rms,
            r.fit.rate_rms_other,
            us(t_p),
            us(r.ours.windows.incident_start_s),
            us((r.fit.q - r.fit.p) as f64 * dt),
            us((r.fit.m - r.fit.p) as f64 * dt),
            us(*r.authors.x.last().unwrap_or(&0.0)),
            us(r.end_plus),
            us(r.end_minus)
        );
    }
    let plus: Vec<usize> = rows
        .iter()
        .filter(|r| r.fit.sign > 0.0)
        .map(|r| r.n)
        .collect();
    let minus: Vec<usize> = rows
        .iter()
        .filter(|r| r.fit.sign < 0.0)
        .map(|r| r.n)
        .collect();
    let end_err = rows
        .iter()
        .map(|r| {
            let conv = if r.fit.sign > 0.0 {
                r.end_plus
            } else {
                r.end_minus
            };
            (conv / r.authors.x.last().copied().unwrap_or(f64::NAN) - 1.0).abs()
        })
        .fold(0.0, f64::max);
    let _ = writeln!(
        w,
        "\n**Sign.** For samples {plus:?} the authors' displacement is u_front + u_back: the \
         transmission bar's face displacement is *added* to the incident bar's. At the end of their \
         window, where the window details no longer matter, their x_end equals u_f + u_b (with their \
         windows and scale) within {:.1} %, while u_f − u_b is far off; the rate fit prefers the same \
         sign by a wide margin. `analysis.m` computes `disp = −(front_disp + back_disp)`, where \
         `front_disp = c0/E∫(σi − σr)` and `back_disp = c0/E∫σt` are both positive along the bar \
         axis for compressive pulses: the sum counts the back face moving *away* from the specimen \
         as approach (the overall sign only follows the recording polarity). The physical approach \
         is u_front − u_back (physics.md §7). Sample{} {minus:?} alone match{} u_f − u_b — together \
         with its different bridge factor, a sign that it went through a different version of the \
         script. The sign alone adds 2·u_back to δ.\n",
        end_err * 100.0,
        if minus.len() == 1 { "" } else { "s" },
        if minus.len() == 1 { "es" } else { "" },
    );
    let rd = |f: &dyn Fn(&Row) -> f64| {
        (
            rows.iter().map(f).fold(f64::INFINITY, f64::min),
            rows.iter().map(f).fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let (r_lo, r_hi) = rd(&|r| (r.fit.q - r.fit.p) as f64 * 1e-7);
    let (t_lo, t_hi) = rd(&|r| (r.fit.m - r.fit.p) as f64 * 1e-7);
    let (s_lo, s_hi) = rd(&|r| r.ours.windows.incident_start_s - r.their_start_s);
    let _ = writeln!(
        w,
        "**Window alignment.** The authors' windows are not the 2d_I/c0 and (d_I + d_T)/c0 of their \
         script: their reflected window starts {}–{} µs after their incident window (nominal {} µs), \
         and their transmitted window only {}–{} µs after it (nominal {} µs, plus the specimen \
         transit). With the transmitted wave taken ≈ 25 µs early relative to the incident one, each \
         force sample is paired with a displacement reached ≈ 25 µs later in the loading, which \
         raises their δ at peak force further.\n",
        us(r_lo),
        us(r_hi),
        us(2.0 * d_i / c0),
        us(t_lo),
        us(t_hi),
        us((d_i + d_t) / c0)
    );
    let _ = writeln!(
        w,
        "**Integration start.** Their incident window (and integration) starts {}–{} µs before our \
         incident foot; over that stretch the windows hold only noise and pre-trigger offsets.\n",
        us(s_lo),
        us(s_hi)
    );
    let (m_lo, m_hi) = (
        rows.iter()
            .filter_map(|r| r.ours.measured_reflected_delay_s)
            .fold(f64::INFINITY, f64::min),
        rows.iter()
            .filter_map(|r| r.ours.measured_reflected_delay_s)
            .fold(0.0, f64::max),
    );
    let m_mean = mean(
        rows.iter()
            .filter_map(|r| r.ours.measured_reflected_delay_s),
    );
    let better = rows
        .iter()
        .filter(|r| imbalance_rms(&r.record_aligned) < imbalance_rms(&r.ours))
        .count();
    let _ = writeln!(
        w,
        "**The records' own reflected delay.** In all eight records the reflected pulse's foot (same \
         2 % rule) comes {}–{} µs after the incident foot, {:.0} µs before 2d_I/c0 = {} µs (the \
         incident channel is flat, within ≈ 1 % of the incident peak, from 200 µs until the \
         tensile pulse rises). Taken as geometry, the incident gauge would sit ≈ {:.3} m rather than \
         {d_i} m from the specimen face (or c0 would be ≈ {:.0} m/s on that path); the authors' own \
         reflected delays ({}–{} µs) lie in between. A reduction with that effective geometry \
         (reflected delay as measured, transmitted delay = half of it + d_T/c0) lowers the \
         front/back imbalance (RMS of F_front − F_back while F_3wave > 20 % of its peak, relative \
         to that peak) for {better} of 8 records, but not the single equilibrium ratio at peak force \
         consistently. {} `shpb reduce` prints a warning with the measured delay; \
         `WindowOverride::reflected_delay_s`/`transmitted_delay_s` (or the gauge distance in \
         `bars/gauges-authors.toml`) select the effective geometry. Effect on δ at peak force and \
         on the balance (nominal → effective geometry):\n",
        us(m_lo),
        us(m_hi),
        (2.0 * d_i / c0 - m_mean) * 1e6,
        us(2.0 * d_i / c0),
        c0 * m_mean / 2.0,
        2.0 * d_i / m_mean,
        us(r_lo),
        us(r_hi),
        if better >= 6 {
            "The records thus favour the shorter effective distance; the stated 0.644525 m (the \
             authors' script, 25.375 in) is what the gauge file holds and the default keeps it, \
             since the cause (gauge position, c0, or the timing of the reflection at the spheres) \
             is not known."
        } else {
            "The records therefore do not single out a geometry, and the default keeps the stated \
             one."
        },
    );
    let _ = writeln!(
        w,
        "| sample | δ at peak nominal (µm) | effective (µm) | imbalance RMS nominal | effective | equilibrium ratio at peak nominal | effective |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {:.3} | {:.3} | {:.2} | {:.2} |",
            r.n,
            us(r.ours.displacement_at_peak_force_m),
            us(r.record_aligned.displacement_at_peak_force_m),
            imbalance_rms(&r.ours),
            imbalance_rms(&r.record_aligned),
            r.ours.equilibrium_ratio_at_peak,
            r.record_aligned.equilibrium_ratio_at_peak
        );
    }
    let _ = writeln!(
        w,
        "\n## Displacement at peak force: one convention at a time\n"
    );
    let _ = writeln!(
        w,
        "Our δ at our peak back force with one of the authors' conventions applied at a time \
         (their sign; their window delays; their integration start t_p; their strain scale), then \
         all of them together with their window length, evaluated at the index of their peak force, \
         against their value (µm). Last two columns: δ when the back force first reaches 5 % of its \
         peak (the offset at near-zero force).\n"
    );
    let _ = writeln!(
        w,
        "| sample | ours | their sign | their delays | their start | their scale | all of theirs | authors | all/authors | δ at 5 % force ours | authors |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {:.3} | {} | {} |",
            r.n,
            us(r.ours.displacement_at_peak_force_m),
            us(r.with_sign),
            us(r.with_alignment),
            us(r.with_start),
            us(r.with_scale),
            us(r.all_at_their_peak),
            us(r.authors.x_peak()),
            r.all_at_their_peak / r.authors.x_peak(),
            us(onset(&r.ours.displacement_m, &r.ours.force_back_n)),
            us(onset(&r.authors.x, &r.authors.f)),
        );
    }
    let ratios: Vec<f64> = rows
        .iter()
        .map(|r| r.all_at_their_peak / r.authors.x_peak())
        .collect();
    let (st_lo, st_hi) = rd(&|r| r.with_start - r.ours.displacement_at_peak_force_m);
    let sg: Vec<f64> = rows
        .iter()
        .filter(|r| r.fit.sign > 0.0)
        .map(|r| r.with_sign - r.ours.displacement_at_peak_force_m)
        .collect();
    let (sg_lo, sg_hi) = (
        sg.iter().copied().fold(f64::INFINITY, f64::min),
        sg.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    let (al_lo, al_hi) = rd(&|r| r.with_alignment - r.ours.displacement_at_peak_force_m);
    let (_, on_hi) = rd(&|r| onset(&r.authors.x, &r.authors.f));
    let _ = writeln!(
        w,
        "\n**What explains the offset.** With all their conventions together our reduction \
         reproduces their displacement at peak force within {:+.1} to {:+.1} % ({}), so the \
         differences are conventions, not data. One at a time: their sign adds {}–{} µm (samples \
         {plus:?}), their window delays add {}–{} µm, their earlier \
         integration start only {}–{} µm, and for sample 1 their literal bridge factor doubles δ. \
         Their displacement has already reached up to {} µm when their force first reaches 5 % of \
         its peak, ours at most {} µm (their transmitted window, early relative to the incident one, lets δ grow before the \
         force does) — the same kind \
         of offset at near-zero force that README.md notes in the Fig. 4 data. Our values follow \
         physics.md §7: δ = u_front − u_back integrated from the incident foot, windows from the \
         stated gauge distances.\n",
        (ratios.iter().copied().fold(f64::INFINITY, f64::min) - 1.0) * 100.0,
        (ratios.iter().copied().fold(0.0, f64::max) - 1.0) * 100.0,
        ratios
            .iter()
            .map(|x| format!("{x:.3}"))
            .collect::<Vec<_>>()
            .join(", "),
        us(sg_lo),
        us(sg_hi),
        us(al_lo),
        us(al_hi),
        us(st_lo),
        us(st_hi),
        us(on_hi),
        us(rd(&|r| onset(&r.ours.displacement_m, &r.ours.force_back_n)).1),
    );
    timing_section(w, rows, app, fit);
    balanced_windows_section(w, rows, day, app);
    held_out_day_section(w, rows, day);
    alignment_section(w, rows);
    Ok(md)
}

/// One record of 2013-06-06 and its virtual test driven by its own incident wave.
struct DayRow {
    /// Sample number.
    number: usize,
    /// The specimen as the authors' `test_data.txt` writes it.
    label: &'static str,
    /// Specimen material read from it.
    material: &'static str,
    /// Peak of the record's incident wave at the face (our reduction), Pa.
    incident_peak_pa: f64,
    /// The record's foot delays.
    delays: Delays,
    /// The record's reduction (defaults).
    record: Reduction,
    /// The record reduced with `shpb reduce --align balance`'s defaults.
    balanced: Reduction,
    /// The virtual test: geometry (e), driven by the record's incident wave.
    simulated: Simulated,
    /// [`transmitted_shape_rms`] of the virtual test against the record.
    shape_rms: f64,
}

impl DayRow {
    /// Transmitted arrival of the virtual test less the record's, s.
    fn transmitted_residual_s(&self) -> f64 {
        self.simulated.delays.transmitted_s - self.delays.transmitted_s
    }
}

/// The section on the 2013-06-06 records: pressures, striker and shaper unknown, so the record's
/// own incident wave drives the virtual test (docs/physics.md §6.10), which then predicts the
/// transmitted peak force and arrival of a day nothing was fitted on.
fn held_out_day_section(w: &mut String, rows: &[Row], day: &[DayRow]) {
    let peak_back = |x: &Reduction| x.force_back_n[x.peak_index];
    let _ = writeln!(
        w,
        "\n## The 2013-06-06 records, driven by their own incident waves\n"
    );
    let _ = writeln!(
        w,
        "Eight records of another day on the same bars (`validation/gauge-records/data/2013-06-06_*`, \
         CC-BY 4.0), whose gun pressure, striker and shaper are stated nowhere \
         (validation/pulse/REPORT.md): the gun and shaper models cannot be run for them, but each \
         record's own incident wave can drive the virtual test of its specimen \
         (`validation/fig4-virtual-shpb/<material>-10psi.toml` for the sphere pair and contact \
         law, its pressure unused; the geometry of timing variant (e); docs/physics.md §6.10). \
         Nothing here was fitted on this day. Record: our reduction with the defaults; arrivals as \
         in *Timing*.\n"
    );
    let _ = writeln!(
        w,
        "| sample | specimen (test_data.txt) | incident peak (MPa) | peak back force record / simulated (kN) | simulated / record | Δ_T record / simulated (µs) | residual T (µs) | within 3 µs | equilibrium ratio at peak, record: stated geometry / balanced; simulated | transmitted shape RMS, of its peak |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|");
    for d in day {
        let (f_rec, f_sim) = (peak_back(&d.record), peak_back(&d.simulated.reduction));
        let residual = d.transmitted_residual_s();
        let _ = writeln!(
            w,
            "| {} | {} (\"{}\") | {:.1} | {:.2} / {:.2} | {:.3} | {} / {} | {:+.1} | {} | {:.2} / {:.3}; {:.3} | {:.3} |",
            d.number,
            d.material,
            d.label,
            d.incident_peak_pa / 1e6,
            f_rec / 1e3,
            f_sim / 1e3,
            f_sim / f_rec,
            us(d.delays.transmitted_s),
            us(d.simulated.delays.transmitted_s),
            residual * 1e6,
            yes(within(residual)),
            d.record.equilibrium_ratio_at_peak,
            d.balanced.equilibrium_ratio_at_peak,
            d.simulated.reduction.equilibrium_ratio_at_peak,
            d.shape_rms,
        );
    }
    let ratios: Vec<f64> = day
        .iter()
        .map(|d| peak_back(&d.simulated.reduction) / peak_back(&d.record))
        .collect();
    let (r_lo, r_hi) = min_max(ratios.iter().copied());
    let day_residuals: Vec<f64> = day.iter().map(DayRow::transmitted_residual_s).collect();
    let m = mean(day_residuals.iter().copied());
    let sd = sample_sd(&day_residuals, m);
    let k = day_residuals.iter().filter(|x| within(**x)).count();
    let (f_lo, f_hi) = min_max(
        rows.iter()
            .map(|r| peak_back(&driven(r).reduction) / peak_back(&r.ours)),
    );
    let (q_lo, q_hi) = min_max(day.iter().map(|d| d.record.equilibrium_ratio_at_peak));
    let close: Vec<usize> = day
        .iter()
        .zip(&ratios)
        .filter(|(_, r)| (**r - 1.0).abs() <= 0.10)
        .map(|(d, _)| d.number)
        .collect();
    let far: Vec<String> = day
        .iter()
        .zip(&ratios)
        .filter(|(_, r)| (**r - 1.0).abs() > 0.10)
        .map(|(d, r)| {
            format!(
                "sample {} ({:.2}; transmitted foot {:+.1} µs off, the record's equilibrium ratio {:.2})",
                d.number,
                r,
                d.transmitted_residual_s() * 1e6,
                d.record.equilibrium_ratio_at_peak
            )
        })
        .collect();
    let _ = writeln!(
        w,
        "\nSimulated / record peak back force {:.3}–{:.3} (2013-05-22 driven the same way, *Timing* \
         (f): {:.3}–{:.3}); within ±10 % on samples {close:?} ({}/{}); further off: {}. \
         Transmitted residual {:+.1} ± {:.1} µs (mean ± sd), {k}/{} within 3 µs; transmitted \
         shape RMS {:.3}–{:.3} of the record's peak (as in *Timing* (f)); the records' \
         equilibrium ratio at peak {:.2}–{:.2}.\n",
        r_lo,
        r_hi,
        f_lo,
        f_hi,
        close.len(),
        day.len(),
        far.join("; "),
        m * 1e6,
        sd * 1e6,
        day.len(),
        min_max(day.iter().map(|d| d.shape_rms)).0,
        min_max(day.iter().map(|d| d.shape_rms)).1,
        q_lo,
        q_hi,
    );
    // The largest miss against the records of each label at a like incident wave.
    if let Some((worst, ratio)) = day
        .iter()
        .zip(&ratios)
        .max_by(|a, b| (a.1 - 1.0).abs().total_cmp(&(b.1 - 1.0).abs()))
    {
        let by_label = |label: &str| {
            min_max(
                day.iter()
                    .filter(|d| d.label == label && d.number != worst.number)
                    .map(|d| peak_back(&d.record) / 1e3),
            )
        };
        // Records whose transmitted foot comes far later than the driven model's.
        const LATE_FOOT_US: f64 = 10.0;
        let late: Vec<usize> = day
            .iter()
            .filter(|d| -d.transmitted_residual_s() * 1e6 > LATE_FOOT_US)
            .map(|d| d.number)
            .collect();
        let (k_lo, k_hi) = min_max(
            day.iter()
                .zip(&ratios)
                .filter(|(d, _)| d.number != worst.number && !late.contains(&d.number))
                .map(|(_, r)| *r),
        );
        let kept_label = {
            let mut out: Vec<usize> = late.clone();
            out.push(worst.number);
            out.sort_unstable();
            format!("samples {out:?}")
        };
        let mut labels: Vec<&str> = day.iter().map(|d| d.label).collect();
        labels.sort_unstable();
        labels.dedup();
        let ranges: Vec<String> = labels
            .iter()
            .map(|l| {
                let (lo, hi) = by_label(l);
                format!("\"{l}\" {lo:.2}–{hi:.2} kN")
            })
            .collect();
        let _ = writeln!(
            w,
            "Reading (an inference from eight records). The largest miss, sample {} (\"{}\", {:.2}), \
             is the record's, not the model's alone: its back force, {:.2} kN at an incident peak \
             of {:.1} MPa, is not what the day's other records of its label read (the other \
             records' back forces by label, incident peaks {:.0}–{:.0} MPa: {}), and its \
             equilibrium ratio, {:.2}, is the day's largest — a pair seated or labelled otherwise \
             than stated. {}Without {}, simulated / record is {:.3}–{:.3} (2013-05-22: {:.3}–{:.3}): \
             given each record's own incident wave, the contact law predicts the transmitted peak \
             of a day nothing was fitted on about as well as on the day the timing was read on, and \
             the transmitted arrivals scatter there too: a property of how each pair sat in the \
             bars, not of one day's calibration.\n",
            worst.number,
            worst.label,
            ratio,
            peak_back(&worst.record) / 1e3,
            worst.incident_peak_pa / 1e6,
            min_max(day.iter().map(|d| d.incident_peak_pa / 1e6)).0,
            min_max(day.iter().map(|d| d.incident_peak_pa / 1e6)).1,
            ranges.join(", "),
            worst.record.equilibrium_ratio_at_peak,
            if late.is_empty() {
                String::new()
            } else {
                format!(
                    "Sample(s) {late:?} transmit more than {LATE_FOOT_US:.0} µs later than the \
                     model given their own incident waves (on 2013-05-22 at most {:.1} µs): a \
                     gap the pair closed first. ",
                    rows.iter()
                        .map(|r| -residuals(driven(r), r).1 * 1e6)
                        .fold(f64::NEG_INFINITY, f64::max)
                )
            },
            kept_label,
            k_lo,
            k_hi,
            f_lo,
            f_hi,
        );
    }
}

/// The section *Window alignment*: each strategy of `shpb reduce --align` on every record, what
/// it chose and what that does to δ at peak and to equilibrium (docs/physics.md §7.6).
fn alignment_section(w: &mut String, rows: &[Row]) {
    let _ = writeln!(w, "\n## Window alignment (`shpb reduce --align`)\n");
    let _ = writeln!(
        w,
        "Every record reduced with each alignment of the reflected and transmitted windows \
         (docs/physics.md §7.6), with `shpb reduce`'s other defaults: *geometric* takes the delays \
         from the stated gauge distances (2 d_I/c0, (d_I + d_T)/c0); *foot* from the feet (2 % of \
         each pulse's own peak) of the reflected and transmitted pulses in the record; *balance* \
         shifts the geometric delays, each within ±{} µs, to minimise Σ(F_front − F_back)²/ΣF_back² \
         over the incident pulse (from 10 % of its peak up to 10 % down). The same numbers come from \
         `shpb reduce RECORD --bars bars/authors.toml --align STRATEGY`. The verdict judges the \
         equilibrium ratio over the loading (25 % of the 3-wave peak to the peak) against 0.05.\n",
        us(shpb_core::reduce::DEFAULT_BALANCE_BOUND_S)
    );
    let _ = writeln!(
        w,
        "| sample | alignment | reflected delay (µs) | transmitted delay (µs) | peak back force (kN) | δ at peak (µm) | equilibrium at peak | mean / max over loading | verdict |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    for r in rows {
        for red in &r.aligned {
            let a = &red.alignment;
            let shift = |geometric: f64, used: f64| {
                if (used - geometric).abs() < 1e-9 {
                    us(used)
                } else {
                    format!("{} ({:+.1})", us(used), (used - geometric) * 1e6)
                }
            };
            let _ = writeln!(
                w,
                "| {} | {}{} | {} | {} | {:.2} | {} | {:.3} | {:.3} / {:.3} | {} |",
                r.n,
                a.strategy.name(),
                if a.at_bound { " (at bound)" } else { "" },
                shift(a.geometric_reflected_delay_s, red.windows.reflected_delay_s),
                shift(
                    a.geometric_transmitted_delay_s,
                    red.windows.transmitted_delay_s
                ),
                red.peak_back_force_n * 1e-3,
                us(red.displacement_at_peak_force_m),
                red.equilibrium_ratio_at_peak,
                red.quality.equilibrium_mean,
                red.quality.equilibrium_max,
                red.quality.verdict.name()
            );
        }
    }
    // What the strategies agree on.
    let shifts = |k: usize, f: &dyn Fn(&Reduction) -> f64| -> (f64, f64) {
        min_max(rows.iter().map(|r| f(&r.aligned[k])))
    };
    let d_r = |r: &Reduction| {
        (r.windows.reflected_delay_s - r.alignment.geometric_reflected_delay_s) * 1e6
    };
    let d_t = |r: &Reduction| {
        (r.windows.transmitted_delay_s - r.alignment.geometric_transmitted_delay_s) * 1e6
    };
    let (fr_lo, fr_hi) = shifts(1, &d_r);
    let (ft_lo, ft_hi) = shifts(1, &d_t);
    let (br_lo, br_hi) = shifts(2, &d_r);
    let (bt_lo, bt_hi) = shifts(2, &d_t);
    let spread = rows.iter().map(|r| {
        let (lo, hi) = min_max(r.aligned.iter().map(|a| a.displacement_at_peak_force_m));
        (hi - lo) / lo
    });
    let (sp_lo, sp_hi) = min_max(spread);
    let in_eq = rows
        .iter()
        .flat_map(|r| &r.aligned)
        .filter(|a| a.quality.verdict != shpb_core::reduce::EquilibriumVerdict::NotInEquilibrium)
        .count();
    let best_mean = rows
        .iter()
        .flat_map(|r| &r.aligned)
        .map(|a| a.quality.equilibrium_mean)
        .fold(f64::INFINITY, f64::min);
    let _ = writeln!(
        w,
        "\nShifts from the geometric delays: the records' own feet put the reflected pulse {:+.1} \
         to {:+.1} µs and the transmitted one {:+.1} to {:+.1} µs off; the balance search moves the \
         reflected window {:+.1} to {:+.1} µs and the transmitted one {:+.1} to {:+.1} µs. δ at peak \
         changes by {:.0}–{:.0} % between the strategies on one record (largest over smallest). \
         {} of the {} reductions are in or near equilibrium by the 0.05 criterion; the smallest \
         mean ratio over the loading is {:.3}.\n",
        fr_lo,
        fr_hi,
        ft_lo,
        ft_hi,
        br_lo,
        br_hi,
        bt_lo,
        bt_hi,
        100.0 * sp_lo,
        100.0 * sp_hi,
        in_eq,
        3 * rows.len(),
        best_mean
    );
    let at_bound = rows
        .iter()
        .filter(|r| r.aligned[2].alignment.at_bound)
        .count();
    let _ = writeln!(
        w,
        "Reading (inference from the table): the records' reflected feet and the balance search \
         agree that the reflected window belongs {:.0}–{:.0} µs before the geometric delay on every \
         record, two independent estimates of the offset of *The records' own reflected delay* \
         above (the stated incident-gauge distance, or c0, does not describe these tests). The \
         transmitted delay is not pinned by the feet, which scatter over {:.0} µs between records \
         and wait for the contact force to build; the balance search, stopping inside its ±{:.0} µs \
         bound on {} of {} records, puts it {:.0}–{:.0} µs before the geometric delay, where the \
         records come nearest equilibrium ({}; *The windows that balance the records* above reads \
         what that offset means). `foot` is the strategy whose choices need no model of the \
         test; `balance` the one that finds where a record's windows balance, and says when its \
         shift reached the bound.\n",
        -fr_hi.max(br_hi),
        -fr_lo.min(br_lo),
        ft_hi - ft_lo,
        shpb_core::reduce::DEFAULT_BALANCE_BOUND_S * 1e6,
        rows.len() - at_bound,
        rows.len(),
        -bt_hi,
        -bt_lo,
        if in_eq == 0 {
            "though none within the 0.05 criterion".to_string()
        } else {
            format!(
                "{in_eq} of the {} reductions in or near equilibrium by the 0.05 criterion",
                3 * rows.len()
            )
        }
    );
}

/// The last word on the records' imbalance: both windows searched at once by `shpb reduce --align
/// balance` (docs/physics.md §7.5–7.6), the paths its delays imply, and the records so balanced
/// against the virtual tests.
fn balanced_windows_section(w: &mut String, rows: &[Row], day: &[DayRow], app: &Apparatus) {
    let c0 = app.material.wave_speed_m_s();
    let (d_i_stated, d_t_stated) = stated_paths_m(app);
    let ea = app.material.youngs_modulus_pa * app.incident.area_m2();
    // Paths of a balanced reduction (incident, transmission; `balance_paths_m`) and how early
    // the transmitted window is against the stated transmission path, s.
    let paths = |b: &Reduction| {
        let (d_i, d_t) = b.alignment.balance_paths_m.expect("a balanced reduction");
        (d_i, d_t, (d_t_stated - d_t) / c0)
    };
    let foot_t = |x: &Reduction| x.alignment.measured_transmitted_delay_s.unwrap_or(f64::NAN);
    // Face-to-face transit: the transmitted foot after the transmitted window's start, s.
    let transit = |x: &Reduction| foot_t(x) - x.windows.transmitted_delay_s;
    let _ = writeln!(
        w,
        "\n**The windows that balance the records.** The paragraphs above move the reflected window \
         alone, or put both windows on the records' feet. `shpb reduce --align balance` \
         (docs/physics.md §7.6) searches both at once, each within ±{} µs of its geometric delay, for \
         the shifts that minimise Σ(F_front − F_back)²/ΣF_back² over the whole incident pulse (10 % \
         of its peak up to 10 % down); on a virtual test it returns the test's own geometry within \
         1 µs (`crates/cli/tests/reduce_batch.rs`), so it does not make a shift up. Its delays \
         imply the paths: incident gauge d_I = c0 Δ_R/2 (stated {:.4} m), transmission gauge \
         c0 Δ_T − d_I (stated {:.4} m). *Δ_T pinned to*: the transmitted delays whose RMS imbalance \
         (below) stays within {:.0} % of the least, the reflected window held where the balance put \
         it (a scan of ±{:.0} µs in {:.1} µs steps): how sharply the record fixes Δ_T (this measure \
         weighs where F_3wave exceeds 20 % of its peak, the search the incident pulse, so the \
         search's Δ_T may sit up to a µs or so outside it). *Early*: how \
         much sooner the transmitted window starts than that d_I and the stated transmission path \
         allow. *Transit*: the record's transmitted \
         foot after the window's start, i.e. from the incident pulse's arrival at the front face to \
         the transmitted pulse's departure from the back face (simulated: the virtual test (a)'s, \
         on its own geometry). RMS imbalance: |F_front − F_back| where F_3wave exceeds 20 % of its \
         peak, of that peak; its noise floor is what the channels' baseline noise alone gives \
         (E A √(2 σ_I² + σ_T²) of the same peak, σ the smoothed baseline RMS strain: the front \
         force adds two samples of the incident channel). Simulated: virtual test (a), shipped set-up. Figure `{BALANCED_PNG}`: each record's \
         front and back forces through the stated and the balanced windows, with the virtual \
         test's back force.\n",
        us(shpb_core::reduce::DEFAULT_BALANCE_BOUND_S),
        d_i_stated,
        d_t_stated,
        PIN_TOLERANCE * 100.0,
        PIN_SCAN_S.1 * 1e6,
        PIN_SCAN_S.0 * 1e6,
    );
    // The pinned interval of Δ_T, with "≤"/"≥" where it reaches the scan's edge.
    let at_edge = |r: &Row, x: f64| {
        (x - r.aligned[2].windows.transmitted_delay_s).abs() >= PIN_SCAN_S.1 - 0.5 * PIN_SCAN_S.0
    };
    let pinned = |r: &Row| {
        let (lo, hi) = r.transmitted_pin_s;
        format!(
            "{}{}–{}{}",
            if at_edge(r, lo) { "≤ " } else { "" },
            us(lo),
            us(hi),
            if at_edge(r, hi) { " or more" } else { "" }
        )
    };
    let _ = writeln!(
        w,
        "| sample | specimen | Δ_R (µs) | d_I (m) | Δ_T (µs) | Δ_T pinned to (µs) | transmission path (m) | early (µs) | transit (µs): record / simulated | RMS imbalance: stated geometry / feet / balanced / simulated / noise floor | ratio at peak: balanced / simulated | δ at peak (µm): balanced / simulated | back force at half its peak, rising (µs): balanced / simulated |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in rows {
        let b = &r.aligned[2];
        let sim = &r.timing.shipped.reduction;
        let (d_i, d_t, early) = paths(b);
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {} | {:.4} | {} | {} | {:.3} | {} | {} / {} | {:.3} / {:.3} / {:.3} / {:.3} / {:.3} | {:.3} / {:.3} | {} / {} | {} / {} |",
            r.n,
            r.material,
            r.psi,
            us(b.windows.reflected_delay_s),
            d_i,
            us(b.windows.transmitted_delay_s),
            pinned(r),
            d_t,
            us(early),
            us(transit(b)),
            us(transit(sim)),
            imbalance_rms(&r.aligned[0]),
            imbalance_rms(&r.aligned[1]),
            imbalance_rms(b),
            imbalance_rms(sim),
            noise_floor(b, ea),
            b.equilibrium_ratio_at_peak,
            sim.equilibrium_ratio_at_peak,
            us(b.displacement_at_peak_force_m),
            us(sim.displacement_at_peak_force_m),
            us(half_rise_s(b)),
            us(half_rise_s(sim)),
        );
    }
    let balanced: Vec<&Reduction> = rows.iter().map(|r| &r.aligned[2]).collect();
    let range = |f: &dyn Fn(&Reduction) -> f64| min_max(balanced.iter().map(|b| f(b)));
    let d_is: Vec<f64> = balanced.iter().map(|b| paths(b).0).collect();
    let d_i_mean = mean(d_is.iter().copied());
    let d_i_sd = sample_sd(&d_is, d_i_mean);
    let (r_lo, r_hi) = range(&|b| b.windows.reflected_delay_s * 1e6);
    let (sr_lo, sr_hi) =
        range(&|b| (b.windows.reflected_delay_s - b.alignment.geometric_reflected_delay_s) * 1e6);
    let (af_lo, af_hi) = range(&|b| {
        (b.windows.reflected_delay_s - b.alignment.measured_reflected_delay_s.unwrap_or(f64::NAN))
            * 1e6
    });
    let (st_lo, st_hi) = range(&|b| {
        (b.windows.transmitted_delay_s - b.alignment.geometric_transmitted_delay_s) * 1e6
    });
    let (e_lo, e_hi) = range(&|b| paths(b).2 * 1e6);
    let (p_lo, p_hi) = range(&|b| paths(b).1);
    let at_bound = balanced.iter().filter(|b| b.alignment.at_bound).count();
    let by_material =
        |m: &str, f: &dyn Fn(&Row) -> f64| min_max(rows.iter().filter(|r| r.material == m).map(f));
    let mut materials: Vec<&str> = rows.iter().map(|r| r.material).collect();
    materials.dedup();
    // One phrase per specimen material, joined.
    let each_material = |phrase: &dyn Fn(&str) -> String| {
        materials
            .iter()
            .map(|m| phrase(m))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let early_by_material = each_material(&|m| {
        let (lo, hi) = by_material(m, &|r| paths(&r.aligned[2]).2 * 1e6);
        format!("{m} {lo:.1}–{hi:.1} µs")
    });
    let pin_by_material = each_material(&|m| {
        let g: Vec<&Row> = rows.iter().filter(|r| r.material == m).collect();
        let loose = g
            .iter()
            .any(|r| at_edge(r, r.transmitted_pin_s.0) || at_edge(r, r.transmitted_pin_s.1));
        let (lo, hi) = min_max(
            g.iter()
                .map(|r| 0.5 * (r.transmitted_pin_s.1 - r.transmitted_pin_s.0) * 1e6),
        );
        if loose {
            format!(
                "{m}: not within the ±{:.0} µs scan on every record",
                PIN_SCAN_S.1 * 1e6
            )
        } else {
            format!("{m} ±{lo:.1}–{hi:.1} µs")
        }
    });
    let transit_by_material = each_material(&|m| {
        let (lo, hi) = by_material(m, &|r| transit(&r.aligned[2]) * 1e6);
        let (slo, shi) = by_material(m, &|r| transit(&r.timing.shipped.reduction) * 1e6);
        format!("{m} {lo:.1}–{hi:.1} µs against {slo:.1}–{shi:.1} µs")
    });
    let rms = |k: usize| min_max(rows.iter().map(|r| imbalance_rms(&r.aligned[k])));
    let (g_lo, g_hi) = rms(0);
    let (f_lo, f_hi) = rms(1);
    let (b_lo, b_hi) = rms(2);
    let (s_lo, s_hi) = min_max(
        rows.iter()
            .map(|r| imbalance_rms(&r.timing.shipped.reduction)),
    );
    let (q_lo, q_hi) = range(&|b| b.equilibrium_ratio_at_peak);
    let (n_lo, n_hi) = range(&|b| noise_floor(b, ea));
    let steels =
        |f: &dyn Fn(&Row) -> f64| min_max(rows.iter().filter(|r| r.material != "Al2017").map(f));
    let (qs_lo, qs_hi) = steels(&|r| r.aligned[2].equilibrium_ratio_at_peak);
    let (qa_lo, qa_hi) = by_material("Al2017", &|r| r.aligned[2].equilibrium_ratio_at_peak);
    let (sq_lo, sq_hi) = min_max(
        rows.iter()
            .map(|r| r.timing.shipped.reduction.equilibrium_ratio_at_peak),
    );
    let delta = |r: &Row| {
        100.0
            * (r.aligned[2].displacement_at_peak_force_m
                / r.timing.shipped.reduction.displacement_at_peak_force_m
                - 1.0)
    };
    let (dd_lo, dd_hi) = min_max(rows.iter().map(delta));
    // The balanced records' RMS imbalance over the virtual test's and the noise floor together.
    let beyond = min_max(rows.iter().map(|r| {
        let b = &r.aligned[2];
        imbalance_rms(b) / imbalance_rms(&r.timing.shipped.reduction).hypot(noise_floor(b, ea))
    }));
    // The records' RMS imbalance (alignment k) over the virtual test's.
    let times = |k: usize| {
        min_max(
            rows.iter()
                .map(|r| imbalance_rms(&r.aligned[k]) / imbalance_rms(&r.timing.shipped.reduction)),
        )
    };
    let half_rise_lag =
        |r: &Row| (half_rise_s(&r.aligned[2]) - half_rise_s(&r.timing.shipped.reduction)) * 1e6;
    let (pl_lo, pl_hi) = min_max(rows.iter().map(half_rise_lag));
    let half_rise_by_material = each_material(&|m| {
        let (lo, hi) = by_material(m, &half_rise_lag);
        format!("{m} {lo:+.1} to {hi:+.1} µs")
    });
    let (pls_lo, pls_hi) = steels(&half_rise_lag);
    let (dg_lo, dg_hi) = min_max(rows.iter().map(|r| {
        100.0
            * (r.aligned[0].displacement_at_peak_force_m
                / r.timing.shipped.reduction.displacement_at_peak_force_m
                - 1.0)
    }));
    let _ = writeln!(
        w,
        "\nThe search stops inside its bound on {} of {} records. It moves the reflected window \
         {sr_lo:+.1} to {sr_hi:+.1} µs from the geometric delay, to {r_lo:.1}–{r_hi:.1} µs on every \
         record (a spread of {:.1} µs, {af_lo:.1}–{af_hi:.1} µs after the records' 2 % reflected \
         feet, which sit on the pulses' toe): one incident path, d_I = {d_i_mean:.4} ± {d_i_sd:.4} m \
         (sample sd), {:.1} % short of the stated one. It moves the transmitted window \
         {st_lo:+.1} to {st_hi:+.1} µs: with that incident path, {e_lo:.1}–{e_hi:.1} µs earlier \
         than the stated transmission path allows (a path of {p_lo:.3}–{p_hi:.3} m against \
         {d_t_stated:.4} m; by specimen: {early_by_material}); the records pin Δ_T to within \
         {pin_by_material} (half the *pinned* interval). So balanced, the records' RMS \
         imbalance over the pulse falls from {g_lo:.3}–{g_hi:.3} (stated geometry) and \
         {f_lo:.3}–{f_hi:.3} (feet) to {b_lo:.3}–{b_hi:.3}, against {s_lo:.3}–{s_hi:.3} for the \
         virtual tests and a noise floor of {n_lo:.3}–{n_hi:.3}; the ratio at peak to {q_lo:.3}–{q_hi:.3} (SS440c and SS302 \
         {qs_lo:.3}–{qs_hi:.3}, Al2017 {qa_lo:.3}–{qa_hi:.3}) against {sq_lo:.3}–{sq_hi:.3} \
         simulated; and δ at peak comes {dd_lo:+.0} to {dd_hi:+.0} % off the simulated one (with \
         the stated geometry {dg_lo:+.0} to {dg_hi:+.0} %); the balanced back force \
         rises through half its peak {pl_lo:+.1} to {pl_hi:+.1} µs from the virtual test's \
         (steels {pls_lo:+.1} to {pls_hi:+.1} µs; figure). Measured by the 2 % feet, the transit from face to face is \
         longer than the touching pair's in the virtual test: {transit_by_material}.\n",
        rows.len() - at_bound,
        rows.len(),
        r_hi - r_lo,
        100.0 * (1.0 - d_i_mean / d_i_stated),
    );
    balanced_timing_paragraph(w, rows, c0);
    // The held-out day, the same search.
    let day_range = |f: &dyn Fn(&Reduction) -> f64| min_max(day.iter().map(|d| f(&d.balanced)));
    let (dr_lo, dr_hi) = day_range(&|b| b.windows.reflected_delay_s * 1e6);
    let (ddi_lo, ddi_hi) = day_range(&|b| paths(b).0);
    let (de_lo, de_hi) = day_range(&|b| paths(b).2 * 1e6);
    let (dq_lo, dq_hi) = day_range(&|b| b.equilibrium_ratio_at_peak);
    let (dgq_lo, dgq_hi) = min_max(day.iter().map(|d| d.record.equilibrium_ratio_at_peak));
    let day_bound = day.iter().filter(|d| d.balanced.alignment.at_bound).count();
    let _ = writeln!(
        w,
        "The held-out day (2013-06-06, below) gives the same: the search stops inside its bound on \
         {} of {} records, reflected windows at {dr_lo:.1}–{dr_hi:.1} µs (d_I = \
         {ddi_lo:.4}–{ddi_hi:.4} m), transmitted ones {de_lo:.1}–{de_hi:.1} µs earlier than the \
         stated path allows, ratios at peak {dq_lo:.3}–{dq_hi:.3} balanced against \
         {dgq_lo:.3}–{dgq_hi:.3} with the stated geometry.\n",
        day.len() - day_bound,
        day.len(),
    );
    let _ = writeln!(
        w,
        "Reading (inference). Cut where the stated distances put them, each record's back force \
         runs ahead of its front force; the balance starts the transmitted windows {:.1}–{:.1} µs \
         earlier than the stated distances do (the reflected ones {:.1}–{:.1} µs), which moves the \
         back force later against the front one. No passive specimen does that in one dimension: a light pair carries the same \
         force on both faces, a mass between them makes the front force lead (*Mass between the \
         faces* above), a compliance or a seating gap delays both alike. Moved so, the records' RMS \
         imbalance is {:.1}–{:.1} times the virtual tests', against {:.0}–{:.0} times through the \
         stated windows, and {:.1}–{:.1} times what the virtual test's imbalance and the record's \
         noise floor give together (√(simulated² + floor²)); the rest is the records' own \
         (pulse shapes the virtual test does not have). The soft Al2017 pair balances least: its \
         small back force pins its shift least. So the imbalance \
         these records show through geometric windows is not the specimens' state but where their \
         transmitted pulses sit against their incident ones, which the paragraphs above, moving \
         one window at a time or both to the feet, could not find. At the faces, so placed, the \
         records' forces come near the virtual tests' in time and shape (figure; half-peak rise \
         {}): what the simulation predicts at the faces the records show, within those lags, once \
         their windows balance; what it does not predict is where each record's transmitted pulse \
         sits on its gauge's clock. What puts it there the records cannot tell: a transmission gauge nearer \
         the specimen than stated, by about the amount the *Seating* probe needed (0.252 m), or a \
         delay between the two channels' clocks (trigger, digitiser). A fixed gauge or clock \
         offset would be the same on every record; here it grows from SS440c to the softer pairs \
         (on some records by more than the records pin Δ_T), so part of it may come with the \
         specimen (the 2 % feet, which sit in the toes, suggest \
         transits longer than the touching pair's; seating gaps of tens of µm lengthen it by \
         about that much, *Seating* in *Timing*), or with the pulse shapes the search matches. The simulator's equilibrium prediction stands as that of the ideal test at the \
         stated seating; a real record's equilibrium can be judged only once its transmitted \
         window is placed by something other than the stated distance — its own balance, which by \
         construction finds the best balance the record allows.",
        -st_hi,
        -st_lo,
        -sr_hi,
        -sr_lo,
        times(2).0,
        times(2).1,
        times(0).0,
        times(0).1,
        beyond.0,
        beyond.1,
        half_rise_by_material,
    );
}

/// The effective incident path fitted on the records' reflected feet.
struct PathFit {
    /// Gauge-to-contact distance, m.
    d_m: f64,
    /// Half the spread of the per-record fits, m.
    half_spread_m: f64,
    /// Standard deviation of the per-record fits, m.
    std_m: f64,
}

/// Fits one incident gauge-to-contact distance on the records' reflected foot delays: each
/// record implies d_I − c0 (Δ_R,sim − Δ_R,rec)/2 (the shipped virtual test's reflected delay
/// corrected to the record's); the fit is their mean, with half their spread.
fn effective_path(rows: &[Row], app: &Apparatus) -> PathFit {
    let c0 = app.material.wave_speed_m_s();
    let d_i = app
        .gauges
        .channel("incident")
        .expect("incident channel")
        .distance_from_specimen_m;
    let each: Vec<f64> = rows
        .iter()
        .map(|r| {
            d_i - 0.5 * c0 * (r.timing.shipped.delays.reflected_s - r.timing.record.reflected_s)
        })
        .collect();
    let d_m = mean(each.iter().copied());
    let lo = each.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = each.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    PathFit {
        d_m,
        half_spread_m: 0.5 * (hi - lo),
        std_m: sample_sd(&each, d_m),
    }
}

/// Compressive peak of the incident wave at the face, Pa.
fn incident_peak_pa(r: &Reduction, e: f64) -> f64 {
    -e * r.incident_strain.iter().copied().fold(0.0, f64::min)
}

/// δ when the force first reaches 5 % of its peak.
fn onset(x: &[f64], f: &[f64]) -> f64 {
    let peak = f.iter().copied().fold(0.0, f64::max);
    f.iter()
        .position(|&v| v >= 0.05 * peak)
        .map(|k| x[k])
        .unwrap_or(f64::NAN)
}

/// Mean of the values (0 for none).
fn mean(it: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = it.collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Sample standard deviation (n − 1) about `m` (0 for fewer than two values).
fn sample_sd(v: &[f64], m: f64) -> f64 {
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len().max(2) - 1) as f64).sqrt()
}

/// Arrival residuals (reflected, transmitted) of a virtual test against its record, s.
fn residuals(x: &Simulated, r: &Row) -> (f64, f64) {
    (
        x.delays.reflected_s - r.timing.record.reflected_s,
        x.delays.transmitted_s - r.timing.record.transmitted_s,
    )
}

/// Transmitted residuals of one variant over the records: mean, sample sd and how many within
/// the arrival acceptance, s.
fn transmitted_stats(rows: &[Row], variant: &dyn Fn(&Row) -> &Simulated) -> (f64, f64, usize) {
    let t: Vec<f64> = rows.iter().map(|r| residuals(variant(r), r).1).collect();
    let m = mean(t.iter().copied());
    (
        m,
        sample_sd(&t, m),
        t.iter().filter(|x| within(**x)).count(),
    )
}

/// "yes" or "no".
fn yes(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// Window of the transmitted-shape comparison around each transmitted foot, s.
const SHAPE_WINDOW_S: (f64, f64) = (-10e-6, 250e-6);

/// RMS difference of a virtual test's transmission-gauge signal and a record's, each on its own
/// time base from its own transmitted foot over [`SHAPE_WINDOW_S`] (so the arrival residual does
/// not enter), both after the feet's moving average, relative to the record's peak: how well the
/// pulse's shape is predicted.
fn transmitted_shape_rms(
    sim: &Simulated,
    record_t: &[f64],
    record_strain: &[f64],
    record: &Delays,
) -> f64 {
    // Compression positive (the sign leaves the RMS of a difference and |peak| unchanged).
    let smooth = |t: &[f64], e: &[f64]| foot_signal(e, t[1] - t[0]);
    let (a, b) = (
        smooth(&sim.time_s, &sim.transmission_strain),
        smooth(record_t, record_strain),
    );
    let at = |t: &[f64], e: &[f64], x: f64| {
        let j = t.partition_point(|&v| v < x).clamp(1, t.len() - 1);
        let w = ((x - t[j - 1]) / (t[j] - t[j - 1])).clamp(0.0, 1.0);
        e[j - 1] + w * (e[j] - e[j - 1])
    };
    let foot_sim = sim.delays.incident_s + sim.delays.transmitted_s;
    let foot_rec = record.incident_s + record.transmitted_s;
    let dt = record_t[1] - record_t[0];
    let n = ((SHAPE_WINDOW_S.1 - SHAPE_WINDOW_S.0) / dt).round() as usize;
    let diff: Vec<f64> = (0..=n)
        .map(|k| {
            let tau = SHAPE_WINDOW_S.0 + k as f64 * dt;
            at(&sim.time_s, &a, foot_sim + tau) - at(record_t, &b, foot_rec + tau)
        })
        .collect();
    let peak = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (diff.iter().map(|d| d * d).sum::<f64>() / diff.len() as f64).sqrt() / peak
}

/// The virtual test with the effective incident path (fitted before the report is written).
fn eff(r: &Row) -> &Simulated {
    r.timing
        .effective
        .as_ref()
        .expect("fitted before the report")
}

/// Whether a residual meets the arrival acceptance.
fn within(x: f64) -> bool {
    x.abs() <= ARRIVAL_TOLERANCE_S
}

/// The virtual test with both gauge paths scaled (built with the effective path).
fn scaled(r: &Row) -> &Simulated {
    r.timing.scaled.as_ref().expect("built before the report")
}

/// How far above its least the RMS imbalance may rise for a transmitted delay to count as
/// balancing the record as well ([`transmitted_pin`]): 10 %.
const PIN_TOLERANCE: f64 = 0.10;

/// Step and half-width of the scan of [`transmitted_pin`], s.
const PIN_SCAN_S: (f64, f64) = (0.5e-6, 20e-6);

/// How well a record pins its balanced transmitted delay: with the reflected window where the
/// balance put it, the transmitted delay is scanned ±20 µs around the balanced one (0.5 µs
/// steps, `shpb reduce`'s defaults otherwise) and the delays whose RMS imbalance
/// ([`imbalance_rms`]) stays within [`PIN_TOLERANCE`] of the least are returned as (first, last),
/// s; an end at the scan's edge means the record does not pin it within the scan.
fn transmitted_pin(
    input: &ReductionInput,
    setup: &ReductionSetup,
    balanced: &Reduction,
) -> Result<(f64, f64)> {
    let (step, half) = PIN_SCAN_S;
    let n = (half / step).round() as i64;
    let scan = (-n..=n)
        .into_par_iter()
        .map(|k| {
            let delay = balanced.windows.transmitted_delay_s + k as f64 * step;
            let r = reduce(
                input,
                setup,
                &ReductionOptions {
                    window: Some(WindowOverride {
                        reflected_delay_s: Some(balanced.windows.reflected_delay_s),
                        transmitted_delay_s: Some(delay),
                        ..WindowOverride::default()
                    }),
                    ..ReductionOptions::default()
                },
            )?;
            Ok((delay, imbalance_rms(&r)))
        })
        .collect::<Result<Vec<(f64, f64)>>>()?;
    let least = scan.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    Ok(min_max(
        scan.iter()
            .filter(|p| p.1 <= (1.0 + PIN_TOLERANCE) * least)
            .map(|p| p.0),
    ))
}

/// The set-up's stated gauge distances from the specimen (incident, transmission), m.
fn stated_paths_m(app: &Apparatus) -> (f64, f64) {
    let distance = |name: &str| {
        app.gauges
            .channel(name)
            .expect("a channel of the authors' set-up")
            .distance_from_specimen_m
    };
    (distance("incident"), distance("transmission"))
}

/// Timing variant (e): both stated gauge distances scaled by d_eff/d_I, the one constant (c)
/// fitted on the reflected feet, so that the transmitted arrivals test it independently.
fn scaled_paths_paragraph(w: &mut String, rows: &[Row], app: &Apparatus, fit: &PathFit) {
    let c0 = app.material.wave_speed_m_s();
    let (d_i, d_t) = stated_paths_m(app);
    let s = fit.d_m / d_i;
    let res = residuals;
    let _ = writeln!(
        w,
        "**(e) Both gauge paths scaled.** The same fitted constant read as a scale of both stated \
         distances: incident gauge at d_eff = {:.4} m and transmission gauge at {:.4} m instead of \
         {d_t} m (× {:.4}, both {:.1} % shorter), no inserts; for arrival times this is also what \
         bars whose wave speed were c0 / {:.4} = {:.0} m/s on the stated distances would give. \
         Nothing is fitted on the transmitted arrivals, so they test the reading; the offsets \
         of (c) and (e) differ only by the transmission path's share.\n",
        fit.d_m,
        d_t * s,
        s,
        (1.0 - s) * 100.0,
        s,
        c0 / s
    );
    let _ = writeln!(
        w,
        "| sample | specimen | (e) Δ_R / Δ_T (µs) | residual R / T (µs) | within 3 µs R / T | residual T with (c) (µs) |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|");
    for r in rows {
        let (er, et) = res(scaled(r), r);
        let (_, ct) = res(eff(r), r);
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {} / {} | {:+.1} / {:+.1} | {} / {} | {:+.1} |",
            r.n,
            r.material,
            r.psi,
            us(scaled(r).delays.reflected_s),
            us(scaled(r).delays.transmitted_s),
            er * 1e6,
            et * 1e6,
            yes(within(er)),
            yes(within(et)),
            ct * 1e6,
        );
    }
    let n = rows.len();
    let (em, esd, ek) = transmitted_stats(rows, &scaled);
    let (cm, csd, ck) = transmitted_stats(rows, &eff);
    let both = rows
        .iter()
        .filter(|r| {
            let (x, y) = res(scaled(r), r);
            within(x) && within(y)
        })
        .count();
    let _ = writeln!(
        w,
        "\nTransmitted residual, mean ± standard deviation over the {n} records: (c) {:+.1} ± {:.1} \
         µs ({ck}/{n} within 3 µs), (e) {:+.1} ± {:.1} µs ({ek}/{n}); both arrivals within 3 µs \
         with (e) on {both}/{n} records. Reading (an inference from eight records): the common \
         offset that (c) leaves on the transmitted arrivals is what the same scale applied to the \
         transmission side removes, so a constant fitted on the reflected feet alone predicts the \
         transmitted arrivals' mean; what remains is their record-to-record scatter (standard \
         deviation {:.1} µs), which no geometry removes. Which reading is physical is not settled \
         here: a wave speed of {:.0} m/s would need E = ρ c² = {:.0} GPa at the stated density, \
         {:.0} % above the stated {:.0} GPa, against a c0 the authors state as measured on these \
         bars, so distances both {:.1} % shorter than stated (or measured to another reference than \
         the specimen face) are the likelier reading; `bars/authors.toml` keeps the stated \
         distances.\n",
        cm * 1e6,
        csd * 1e6,
        em * 1e6,
        esd * 1e6,
        esd * 1e6,
        c0 / s,
        app.material.density_kg_m3 * (c0 / s).powi(2) / 1e9,
        ((c0 / s).powi(2) / c0.powi(2) - 1.0) * 100.0,
        app.material.youngs_modulus_pa / 1e9,
        (1.0 - s) * 100.0,
    );
}

/// The virtual test driven by the record's own incident wave (built with the effective path).
fn driven(r: &Row) -> &Simulated {
    r.timing.driven.as_ref().expect("built before the report")
}

/// Timing variant (f): the geometry of (e) driven by each record's own incident wave instead of
/// the gun, striker and shaper models, so that what remains is the specimen side's.
fn driven_paragraph(w: &mut String, rows: &[Row]) {
    let res = residuals;
    let peak_back = |x: &Reduction| x.force_back_n[x.peak_index];
    let _ = writeln!(
        w,
        "**(f) Driven by the record's own incident wave.** The geometry of (e), with the incident \
         bar driven at its impact end by the record's incident-gauge stress (from its first sample \
         to {:.0} µs before its reflected wave; `IncidentDrive::from_incident_gauge`, \
         docs/physics.md §6.10) instead of the gun, striker and shaper models: on these elementary \
         bars the virtual incident gauge reads the record's incident wave again, so what differs \
         from the record is the specimen side's (contact law, seating, transmission bar). The same \
         virtual test's peak back force against the record's (our reduction of both), beside the \
         shipped shaper model's (a).\n",
        shpb_core::apparatus::DRIVE_MARGIN_S * 1e6
    );
    let _ = writeln!(
        w,
        "| sample | specimen | (f) Δ_R / Δ_T (µs) | residual R / T (µs) | within 3 µs R / T | peak back force, (f) / record | (a) shipped / record | equilibrium ratio at peak, (f) | transmitted shape RMS, of its peak |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let d = driven(r);
        let (fr, ft) = res(d, r);
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {} / {} | {:+.1} / {:+.1} | {} / {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            r.n,
            r.material,
            r.psi,
            us(d.delays.reflected_s),
            us(d.delays.transmitted_s),
            fr * 1e6,
            ft * 1e6,
            yes(within(fr)),
            yes(within(ft)),
            peak_back(&d.reduction) / peak_back(&r.ours),
            peak_back(&r.timing.shipped.reduction) / peak_back(&r.ours),
            d.reduction.equilibrium_ratio_at_peak,
            r.timing.driven_shape_rms,
        );
    }
    let (s_lo, s_hi) = min_max(rows.iter().map(|r| r.timing.driven_shape_rms));
    let _ = writeln!(
        w,
        "\nTransmitted shape RMS: the RMS difference of the virtual and the recorded \
         transmission-gauge stress, each from its own transmitted foot over {:.0} to {:.0} µs \
         (the arrival residual left out), both on the feet's {:.0} µs moving average, relative to \
         the record's peak: {:.3}–{:.3}, the record's noise included.",
        SHAPE_WINDOW_S.0 * 1e6,
        SHAPE_WINDOW_S.1 * 1e6,
        FOOT_SMOOTHING_S * 1e6,
        s_lo,
        s_hi
    );
    let n = rows.len();
    let (m, sd, k) = transmitted_stats(rows, &driven);
    let (m_e, sd_e, _) = transmitted_stats(rows, &scaled);
    let (f_lo, f_hi) = min_max(
        rows.iter()
            .map(|r| peak_back(&driven(r).reduction) / peak_back(&r.ours)),
    );
    let (a_lo, a_hi) = min_max(
        rows.iter()
            .map(|r| peak_back(&r.timing.shipped.reduction) / peak_back(&r.ours)),
    );
    let (q_lo, q_hi) = min_max(
        rows.iter()
            .map(|r| driven(r).reduction.equilibrium_ratio_at_peak),
    );
    let (r_lo, r_hi) = min_max(rows.iter().map(|r| r.ours.equilibrium_ratio_at_peak));
    let _ = writeln!(
        w,
        "\nTransmitted residual with the record's own incident wave: {:+.1} ± {:.1} µs (mean ± sd; \
         {k}/{n} within 3 µs), against {:+.1} ± {:.1} µs with the shaper model's in (e). Reading \
         (an inference from eight records): the records' incident waves differ (toe, rise, the \
         SS302 set's longer toe: validation/pulse/REPORT.md), but giving the virtual test each \
         record's own wave leaves the transmitted arrivals as scattered as before, so the \
         arrival scatter is not the incident pulse's: it lies on the specimen side (how each \
         pair of spheres was seated and touched the bars), which no input records. Peak back \
         force: {:.3}–{:.3} of the records' with their own incident waves, {:.3}–{:.3} with the \
         shaper model, so the transmitted-peak errors of the virtual tests are not the shaper \
         model's either; and the simulated equilibrium ratio at peak stays {:.3}–{:.3} (records \
         {:.2}–{:.2}, next section): the records' imbalance does not come from the shape of their \
         incident waves.\n",
        m * 1e6,
        sd * 1e6,
        m_e * 1e6,
        sd_e * 1e6,
        f_lo,
        f_hi,
        a_lo,
        a_hi,
        q_lo,
        q_hi,
        r_lo,
        r_hi,
    );
}

/// *Timing* (g): the transmitted pulse's rise, level by level, record against driven test.
fn rise_paragraph(w: &mut String, rows: &[Row]) {
    let levels: Vec<String> = RISE_LEVELS
        .iter()
        .map(|f| format!("{:.0}", f * 100.0))
        .collect();
    let _ = writeln!(
        w,
        "**(g) The transmitted pulse's rise, level by level.** A foot is one point of a pulse. \
         Where the transmitted pulse first rises through {} % of its own peak (the first is the \
         foot; each on the feet's {:.0} µs moving average, relative to the incident foot on the \
         same time base), in each record and in its driven test (f), as residuals (f) − record; \
         and the same with the record's incident wave scaled by {:.2} before it drives the test, \
         to see what the timing owes to the wave's amplitude. Figure: \
         `transmitted_driven.png` (each record's transmitted pulse against its driven tests, \
         touching and seated as below).\n",
        levels.join(", "),
        FOOT_SMOOTHING_S * 1e6,
        DRIVE_SCALE
    );
    let slash = levels.join(" / ");
    let _ = writeln!(
        w,
        "| sample | specimen | record at {slash} % (µs) | residual (f) at {slash} % (µs) | with the drive × {DRIVE_SCALE:.2} (µs) | with an elastic Hertz contact (µs) | its peak back force / record |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|");
    let fmt = |v: &[f64], signed: bool| -> String {
        v.iter()
            .map(|x| {
                if signed {
                    format!("{:+.1}", x * 1e6)
                } else {
                    format!("{:.1}", x * 1e6)
                }
            })
            .collect::<Vec<_>>()
            .join(" / ")
    };
    // Residuals (f) − record per level, over the records.
    let mut res = vec![Vec::new(); RISE_LEVELS.len()];
    let mut res_hertz = vec![Vec::new(); RISE_LEVELS.len()];
    let mut hertz_peak = Vec::new();
    let mut moved = 0.0f64;
    for r in rows {
        let rec = r.timing.record_rise;
        let larger = r
            .timing
            .driven_larger
            .as_ref()
            .expect("run before the report");
        let hertz = r
            .timing
            .driven_hertz
            .as_ref()
            .expect("run before the report");
        let (rd, rl, rh) = (
            rise_residuals(driven(r), r),
            rise_residuals(larger, r),
            rise_residuals(hertz, r),
        );
        for k in 0..RISE_LEVELS.len() {
            res[k].push(rd[k]);
            res_hertz[k].push(rh[k]);
        }
        moved = moved.max(
            rd.iter()
                .zip(&rl)
                .fold(0.0, |m, (a, b)| m.max((a - b).abs())),
        );
        let peak = hertz.reduction.peak_back_force_n / r.ours.peak_back_force_n;
        hertz_peak.push(peak);
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {} | {} | {} | {} | {:.2} |",
            r.n,
            r.material,
            r.psi,
            fmt(&rec, false),
            fmt(&rd, true),
            fmt(&rl, true),
            fmt(&rh, true),
            peak,
        );
    }
    let stats: Vec<(f64, f64)> = res
        .iter()
        .map(|v| {
            let m = mean(v.iter().copied());
            (m, sample_sd(v, m))
        })
        .collect();
    let summary: Vec<String> = RISE_LEVELS
        .iter()
        .zip(&stats)
        .map(|(f, (m, sd))| format!("{:.0} %: {:+.1} ± {:.1} µs", f * 100.0, m * 1e6, sd * 1e6))
        .collect();
    let last = RISE_LEVELS.len() - 1;
    let (worst_n, worst) =
        rows.iter().zip(&res[last]).fold(
            (0, f64::MIN),
            |a, (r, &v)| if v > a.1 { (r.n, v) } else { a },
        );
    let _ = writeln!(
        w,
        "\nResidual (f) − record, mean ± sd over the {} records: {}; largest at {:.0} %: \
         {:+.1} µs (sample {worst_n}). The drive × {DRIVE_SCALE:.2} moves no crossing of any \
         record by more than {:.1} µs.\n",
        rows.len(),
        summary.join(", "),
        RISE_LEVELS[last] * 100.0,
        worst * 1e6,
        moved * 1e6,
    );
    // Records on which the simulated pulse is later than the record's at every level above
    // the foot, and the range of its lag at 20 %.
    let later = (0..rows.len())
        .filter(|&i| res[1..].iter().all(|v| v[i] > 0.0))
        .count();
    let (lo20, hi20) = min_max(res[2].iter().copied());
    let (h_lo20, h_hi20) = min_max(res_hertz[2].iter().copied());
    let h_mean20 = mean(res_hertz[2].iter().copied());
    let (hp_lo, hp_hi) = min_max(hertz_peak.iter().copied());
    let _ = writeln!(
        w,
        "Reading (an inference from eight records). The feet agree on average, but above the \
         foot the simulated transmitted pulse comes later than the record's at every level on \
         {later} of {} records — at {:.0} % by {:+.1} to {:+.1} µs, with less scatter between \
         records (sd {:.1} µs) than the feet have (sd {:.1} µs): after its foot the virtual \
         test's back force builds more slowly than the real one. Not the incident wave: the \
         test is driven by the record's own, and {:.0} % more of it moves the crossings by at \
         most {:.1} µs. Nor the contact law's plasticity or rate dependence: with an elastic \
         Hertz contact, stiffer than any elastoplastic law (its peak back force {:.2}–{:.2} of \
         the records'), the pulse still lags at {:.0} % by {:+.1} to {:+.1} µs (mean {:+.1}). \
         Once it starts, the records' force builds faster than that of a pair of spheres \
         touching at rest under the same wave: how the pair sat against the inserts (a \
         preload, which stiffens the contact from the start; or a gap that the face crosses at \
         speed before the pair is struck, which would also delay the foot, so that the paths \
         would have to be shorter still), which no input records. The foot agreement of (e) and (f) is that of the toe alone; so the \
         transmitted arrival is not brought within 3 µs by a set-up constant: a geometry that \
         matched the pulses at {:.0} % would put the feet {:.1} µs early on average.\n",
        rows.len(),
        RISE_LEVELS[2] * 100.0,
        lo20 * 1e6,
        hi20 * 1e6,
        stats[2].1 * 1e6,
        stats[0].1 * 1e6,
        (DRIVE_SCALE - 1.0) * 100.0,
        moved * 1e6,
        hp_lo,
        hp_hi,
        RISE_LEVELS[2] * 100.0,
        h_lo20 * 1e6,
        h_hi20 * 1e6,
        h_mean20 * 1e6,
        RISE_LEVELS[2] * 100.0,
        (stats[2].0 - stats[0].0) * 1e6,
    );
}

/// One virtual test of a record among several variants of it.
type Variant = fn(&Row) -> &Simulated;

/// *Timing* (g), continued: the driven tests with the pair seated across a gap or preloaded
/// (docs/physics.md §6.11), residual per level and its spread over the levels.
fn seating_paragraph(w: &mut String, rows: &[Row], c0: f64, d_t_stated_m: f64, d_t_scaled_m: f64) {
    let spread = |v: &[f64; 4]| {
        let (lo, hi) = min_max(v.iter().copied());
        hi - lo
    };
    let fmt = |v: &[f64; 4]| -> String {
        format!(
            "{} ({:.1})",
            v.iter()
                .map(|x| format!("{:+.1}", x * 1e6))
                .collect::<Vec<_>>()
                .join(" / "),
            spread(v) * 1e6
        )
    };
    let variants: [(&str, Variant); 3] = [
        ("touching (f)", |r| driven(r)),
        ("gap", |r| {
            r.timing.driven_gap.as_ref().expect("run before the report")
        }),
        ("preload", |r| {
            r.timing
                .driven_preload
                .as_ref()
                .expect("run before the report")
        }),
    ];
    let _ = writeln!(
        w,
        "**Seating.** The same driven tests with the pair seated otherwise (docs/physics.md \
         §6.11): across a gap of {:.0} µm at the contact, or pressed by a static preload of \
         {:.0} N before the wave arrives. Residual − record at {} % of the transmitted peak, and \
         in brackets the spread of the four (largest − smallest): a spread near zero is a pulse \
         of the record's shape, late or early by the residual. The preloaded column is known \
         to a few tenths of a µs only: the pair waits at rest, and where the wave arrives the \
         rate-dependent law takes its static or its rate-hardened branch from approach rates of \
         order 1e-10 m a step, so the force may hop by 5 % for a step and back (measured \
         2026-11-25: a change of the contact solve that left every shipped scene within 5e-12 \
         moved sample 1's preloaded crossings by up to 0.4 µs).\n",
        PROBE_GAP_M * 1e6,
        PROBE_PRELOAD_N,
        RISE_LEVELS
            .iter()
            .map(|f| format!("{:.0}", f * 100.0))
            .collect::<Vec<_>>()
            .join(" / "),
    );
    let _ = writeln!(
        w,
        "| sample | specimen | touching, (f) (µs) | gap {:.0} µm (µs) | preload {:.0} N (µs) |",
        PROBE_GAP_M * 1e6,
        PROBE_PRELOAD_N
    );
    let _ = writeln!(w, "|---|---|---|---|---|");
    for r in rows {
        let cells: Vec<String> = variants
            .iter()
            .map(|(_, v)| fmt(&rise_residuals(v(r), r)))
            .collect();
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {} |",
            r.n,
            r.material,
            r.psi,
            cells.join(" | ")
        );
    }
    // Mean spread and mean residual of each variant over the steels and over Al2017.
    let stats = |v: Variant, steel: bool| -> (f64, f64, f64) {
        let sel: Vec<[f64; 4]> = rows
            .iter()
            .filter(|r| r.material.starts_with("SS") == steel)
            .map(|r| rise_residuals(v(r), r))
            .collect();
        let n = sel.len() as f64;
        let spread_mean = sel.iter().map(&spread).sum::<f64>() / n;
        let offset = sel.iter().map(|x| x.iter().sum::<f64>() / 4.0).sum::<f64>() / n;
        let foot = sel.iter().map(|x| x[0]).sum::<f64>() / n;
        (spread_mean, offset, foot)
    };
    let line: Vec<String> = variants
        .iter()
        .map(|(name, v)| {
            let (s_st, o_st, _) = stats(*v, true);
            let (s_al, o_al, _) = stats(*v, false);
            format!(
                "{name}: steels spread {:.1} µs, residual {:+.1} µs; Al2017 {:.1} µs, {:+.1} µs",
                s_st * 1e6,
                o_st * 1e6,
                s_al * 1e6,
                o_al * 1e6
            )
        })
        .collect();
    let _ = writeln!(
        w,
        "\nMean over the records (spread; residual averaged over the four levels): {}.\n",
        line.join("; ")
    );
    let (s_touch, _, _) = stats(variants[0].1, true);
    let (s_gap, o_gap, _) = stats(variants[1].1, true);
    let (s_pre, _, f_pre) = stats(variants[2].1, true);
    let al_least = variants
        .iter()
        .map(|(_, v)| stats(*v, false).0)
        .fold(f64::INFINITY, f64::min);
    let d_t_gap = d_t_scaled_m - o_gap * c0;
    let ratio = |k: usize| {
        min_max(
            rows.iter()
                .map(|r| variants[k].1(r).reduction.equilibrium_ratio_at_peak),
        )
    };
    let ((t_lo, t_hi), (g_lo, g_hi), (p_lo, p_hi)) = (ratio(0), ratio(1), ratio(2));
    let (r_lo, r_hi) = min_max(rows.iter().map(|r| r.ours.equilibrium_ratio_at_peak));
    let feet: Vec<f64> = rows.iter().map(|r| r.timing.record.transmitted_s).collect();
    let feet_sd = sample_sd(&feet, mean(feet.iter().copied()));
    // How far a gap of the faces' finish moves the transmitted foot, per record.
    let (sh_lo, sh_hi) = min_max(rows.iter().map(|r| {
        let small = r
            .timing
            .driven_small_gap
            .as_ref()
            .expect("run before the report");
        small.delays.transmitted_s - driven(r).delays.transmitted_s
    }));
    let _ = writeln!(
        w,
        "Reading (an inference from eight records and two probes). Across a {:.0} µm gap the \
         steels' transmitted pulses come nearer the records' shape (spread {:.1} µs against \
         {:.1} touching) but {:+.1} µs late on average over the levels: the gap delays the pair's loading, \
         then loads it at speed. Read as the seating, it would put the transmission gauge \
         {:.3} m from the contact, {:.0} % short of the stated {:.4} m, where the reflected \
         feet put the incident gauge {:.1} % short (the path of (e)). A {:.0} N preload \
         sharpens the toe (foot {:+.1} µs) and leaves the body late (spread {:.1} µs). Al2017 \
         keeps a spread of {:.1} µs or more in all three. So seating as modelled here accounts \
         for the shape of the steels' pulses only with a transmission path the arrivals alone do \
         not support — but the records' own front/back balance, searched independently of any \
         model, puts the SS440c transmitted windows at that path too (*The windows that balance \
         the records*, next section); the records do not say how the pairs sat. Nor does either \
         seating unbalance the simulated test as the records are through the stated windows: equilibrium ratio at peak {:.3}–{:.3} across \
         the gap, {:.3}–{:.3} preloaded, {:.3}–{:.3} touching (records {:.2}–{:.2}, next \
         section).\n\nHow finely the foot depends on the seating: a gap of only {:.0} µm, the \
         order of a ground face's finish, delays the transmitted foot of the driven tests by \
         {:.1}–{:.1} µs (the face crosses it while the incident wave is still in its toe). The \
         3 µs acceptance on every record therefore needs each pair's seating known to within \
         about {:.1}–{:.1} µm (3 µs over those shifts per µm of gap), which no record or set-up \
         states; the records' transmitted feet scatter by {:.1} µs (sd) between tests of one \
         geometry.\n",
        PROBE_GAP_M * 1e6,
        s_gap * 1e6,
        s_touch * 1e6,
        o_gap * 1e6,
        d_t_gap,
        (1.0 - d_t_gap / d_t_stated_m) * 100.0,
        d_t_stated_m,
        (1.0 - d_t_scaled_m / d_t_stated_m) * 100.0,
        PROBE_PRELOAD_N,
        f_pre * 1e6,
        s_pre * 1e6,
        al_least * 1e6,
        g_lo,
        g_hi,
        p_lo,
        p_hi,
        t_lo,
        t_hi,
        r_lo,
        r_hi,
        SMALL_GAP_M * 1e6,
        sh_lo * 1e6,
        sh_hi * 1e6,
        ARRIVAL_TOLERANCE_S / sh_hi * SMALL_GAP_M * 1e6,
        ARRIVAL_TOLERANCE_S / sh_lo * SMALL_GAP_M * 1e6,
        feet_sd * 1e6,
    );
}

/// The sections *Timing* and *Equilibrium* (docs/physics.md §7.5).
fn timing_section(w: &mut String, rows: &[Row], app: &Apparatus, fit: &PathFit) {
    let c0 = app.material.wave_speed_m_s();
    let d_i = app
        .gauges
        .channel("incident")
        .expect("incident channel")
        .distance_from_specimen_m;
    let _ = writeln!(w, "\n## Timing: arrivals relative to the incident pulse\n");
    let _ = writeln!(
        w,
        "Feature (docs/physics.md §7.5, `shpb_core::gauge::pulse_foot`): the foot of a pulse is where \
         it first rises through {:.0} % of its own peak (linear interpolation), after a {:.0} µs \
         centred moving average, on records and simulated gauge strains alike; Δ_R and Δ_T are the \
         reflected (incident gauge, tension) and transmitted feet minus the incident foot on the same \
         time base, so trigger and pre-trigger cancel. Simulations: the virtual test of the record's \
         material and pressure (`validation/fig4-virtual-shpb/`) with (a) the shipped set-up \
         `bars/authors.toml` (d_I = {d_i} m, no inserts), (b) the same with 1/4\" ({:.2} mm) inserts \
         of bar steel on both sides, (c) the effective incident path below (no inserts, incident \
         gauge at d_eff from the contact; a set-up variant built here, `bars/authors.toml` keeps the \
         stated distance). Residual = simulated − record. Acceptance (issue 18): |residual| ≤ {:.0} µs \
         for both arrivals on every record.\n",
        FOOT_FRACTION * 100.0,
        FOOT_SMOOTHING_S * 1e6,
        AUTHORS_INSERT_LENGTH_M * 1e3,
        ARRIVAL_TOLERANCE_S * 1e6
    );
    let (p_lo, p_hi) = min_max(rows.iter().map(|r| {
        d_i - 0.5 * c0 * (r.timing.shipped.delays.reflected_s - r.timing.record.reflected_s)
    }));
    let _ = writeln!(
        w,
        "**Effective incident path (fitted).** d_eff = **{:.4} m ± {:.1} mm** (± half the spread; \
         standard deviation {:.1} mm) from the incident gauge to the contact, fitted on the eight \
         reflected feet of 2013-05-22: each record implies d_I − c0 (Δ_R,sim − Δ_R,record)/2 with \
         Δ_R,sim from (a), {:.4}–{:.4} m; d_eff is their mean. It is {:.1} mm shorter than the \
         stated {d_i} m (25.375\"); equivalently c0 = {:.0} m/s on the stated distance. Its one \
         input is the reflected delay, so it cannot be tested on the reflected arrivals themselves; \
         the transmitted arrivals are its independent check.\n",
        fit.d_m,
        fit.half_spread_m * 1e3,
        fit.std_m * 1e3,
        p_lo,
        p_hi,
        (d_i - fit.d_m) * 1e3,
        c0 * d_i / fit.d_m
    );
    let _ = writeln!(
        w,
        "| sample | specimen | record Δ_R (µs) | Δ_T (µs) | (a) shipped Δ_R / Δ_T (µs) | residual R / T (µs) | (b) inserts Δ_R / Δ_T (µs) | residual R / T (µs) | (c) effective path Δ_R / Δ_T (µs) | residual R / T (µs) | (c) within 3 µs R / T |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|---|");
    let res = residuals;
    for r in rows {
        let t = &r.timing;
        let pair = |s: &Simulated| {
            format!(
                "{} / {}",
                us(s.delays.reflected_s),
                us(s.delays.transmitted_s)
            )
        };
        let resid = |s: &Simulated| {
            let (a, b) = res(s, r);
            format!("{:+.1} / {:+.1}", a * 1e6, b * 1e6)
        };
        let (er, et) = res(eff(r), r);
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {} | {} | {} | {} | {} | {} | {} | {} | {} / {} |",
            r.n,
            r.material,
            r.psi,
            us(t.record.reflected_s),
            us(t.record.transmitted_s),
            pair(&t.shipped),
            resid(&t.shipped),
            pair(&t.inserts),
            resid(&t.inserts),
            pair(eff(r)),
            resid(eff(r)),
            yes(within(er)),
            yes(within(et)),
        );
    }
    let count = |f: &dyn Fn(&Row) -> &Simulated| -> (usize, usize, (f64, f64), (f64, f64)) {
        let rr: Vec<(f64, f64)> = rows.iter().map(|r| res(f(r), r)).collect();
        (
            rr.iter().filter(|x| within(x.0)).count(),
            rr.iter().filter(|x| within(x.1)).count(),
            min_max(rr.iter().map(|x| x.0)),
            min_max(rr.iter().map(|x| x.1)),
        )
    };
    let (a, b, c) = (
        count(&|r| &r.timing.shipped),
        count(&|r| &r.timing.inserts),
        count(&eff),
    );
    let n = rows.len();
    let (rt_lo, rt_hi) = min_max(rows.iter().map(|r| r.timing.record.transmitted_s));
    let (rr_lo, rr_hi) = min_max(rows.iter().map(|r| r.timing.record.reflected_s));
    let (st_lo, st_hi) = min_max(rows.iter().map(|r| eff(r).delays.transmitted_s));
    let both = rows
        .iter()
        .filter(|r| {
            let (x, y) = res(eff(r), r);
            within(x) && within(y)
        })
        .map(|r| r.n)
        .collect::<Vec<_>>();
    let um = |x: (f64, f64)| format!("{:+.1} to {:+.1}", x.0 * 1e6, x.1 * 1e6);
    let _ = writeln!(
        w,
        "\n**Which meet the 3 µs acceptance.** Reflected / transmitted within 3 µs: (a) shipped \
         {}/{n} and {}/{n} (residuals {} and {} µs); (b) inserts {}/{n} and {}/{n} ({} and {} µs): \
         inserts of bar steel only delay both pulses (2L/c0 on the reflected, (L_I + L_T)/c0 on the \
         transmitted path, physics.md §6.8) and make the gap worse, so they are not the cause; \
         (c) effective path {}/{n} and {}/{n} ({} and {} µs). Both arrivals within 3 µs with (c): \
         samples {both:?}. The reflected arrivals meet the acceptance with (c) by construction (the \
         records' Δ_R span only {:.1} µs, {}–{} µs). The transmitted arrivals do not, and no single \
         geometry can make them: the records' Δ_T scatter over {:.1} µs ({}–{} µs) between tests of \
         one geometry, with no order by material or pressure, while the virtual tests' stay within \
         {:.1} µs ({}–{} µs). The transmitted foot waits for the contact force to build, so what \
         the model lacks is shot-to-shot contact conditions (a gap or preload between spheres and \
         inserts, seating of the truncated spheres) that no input records; the residual of (c) is the \
         record-to-record scatter plus a common offset.\n",
        a.0,
        a.1,
        um(a.2),
        um(a.3),
        b.0,
        b.1,
        um(b.2),
        um(b.3),
        c.0,
        c.1,
        um(c.2),
        um(c.3),
        (rr_hi - rr_lo) * 1e6,
        us(rr_lo),
        us(rr_hi),
        (rt_hi - rt_lo) * 1e6,
        us(rt_lo),
        us(rt_hi),
        (st_hi - st_lo) * 1e6,
        us(st_lo),
        us(st_hi),
    );
    scaled_paths_paragraph(w, rows, app, fit);
    driven_paragraph(w, rows);
    rise_paragraph(w, rows);
    let (d_i, d_t) = stated_paths_m(app);
    seating_paragraph(
        w,
        rows,
        app.material.wave_speed_m_s(),
        d_t,
        d_t * fit.d_m / d_i,
    );

    let _ = writeln!(w, "## Equilibrium: record against simulation\n");
    let _ = writeln!(
        w,
        "Equilibrium ratio |F_front − F_back| / F_3wave at the peak back force (reduce.rs). Record: \
         our reduction (defaults) with the stated geometry; with the reflected window on the \
         record's own reflected foot delay Δ_R (transmitted as stated); with the effective path \
         (reflected 2 d_eff/c0, transmitted (d_eff + d_T)/c0); and with both windows on the record's \
         feet (each foot delay less the offset between feet and windows in the virtual test (c), \
         so record and simulation are aligned alike). Sensitivity: d[(F_front − F_back)/F_3wave at \
         peak]/d(reflected window delay) around the stated geometry, per µs (±1 µs). Simulated: the \
         reduction `shpb run` applies to the virtual test's digitised records (same reduce.rs, \
         default filter, windows from the set-up's own geometry), with (a) the shipped set-up, (b) \
         the 1/4\" inserts of bar steel and (c) the effective path.\n"
    );
    let _ = writeln!(
        w,
        "| sample | specimen | record, stated geometry | reflected on its foot | effective path | both windows on the feet | sensitivity (per µs) | misalignment that would explain it (µs) | F_front − F_back at peak, of the incident peak force (%) | simulated (a) shipped | simulated (b) inserts | simulated (c) effective path |"
    );
    let _ = writeln!(w, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    let ratio =
        |r: &Option<Reduction>| r.as_ref().map_or(f64::NAN, |x| x.equilibrium_ratio_at_peak);
    let ea = app.material.youngs_modulus_pa * app.incident.area_m2();
    for r in rows {
        let t = &r.timing;
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {:.2} | {:.2} | {:.2} | {:.2} | {:+.3} | {:.0} | {:+.1} | {:.3} | {:.3} | {:.3} |",
            r.n,
            r.material,
            r.psi,
            r.ours.equilibrium_ratio_at_peak,
            t.record_reflected_on_foot.equilibrium_ratio_at_peak,
            ratio(&t.record_effective_path),
            ratio(&t.record_on_feet),
            t.sensitivity_per_s * 1e-6,
            ratio(&t.record_on_feet) / t.sensitivity_per_s.abs() * 1e6,
            t.record_on_feet
                .as_ref()
                .map_or(f64::NAN, |x| imbalance_of_incident(x, ea) * 100.0),
            t.shipped.reduction.equilibrium_ratio_at_peak,
            t.inserts.reduction.equilibrium_ratio_at_peak,
            eff(r).reduction.equilibrium_ratio_at_peak,
        );
    }
    let _ = writeln!(w);
    let on_feet = |r: &Row| ratio(&r.timing.record_on_feet);
    let mut materials: Vec<&str> = rows.iter().map(|r| r.material).collect();
    materials.dedup();
    for m in materials {
        let g: Vec<&Row> = rows.iter().filter(|r| r.material == m).collect();
        let rg = |f: &dyn Fn(&Row) -> f64| min_max(g.iter().map(|r| f(r)));
        let stated = rg(&|r| r.ours.equilibrium_ratio_at_peak);
        let feet = rg(&on_feet);
        let sens = rg(&|r| r.timing.sensitivity_per_s * 1e-6);
        let need = rg(&|r| on_feet(r) / r.timing.sensitivity_per_s.abs() * 1e6);
        let share = rg(&|r| {
            r.timing
                .record_on_feet
                .as_ref()
                .map_or(f64::NAN, |x| imbalance_of_incident(x, ea) * 100.0)
        });
        let sim = rg(&|r| eff(r).reduction.equilibrium_ratio_at_peak);
        let _ = writeln!(
            w,
            "**{m}.** Record {:.2}–{:.2} with the stated geometry, {:.2}–{:.2} with both windows on \
             the feet, against {:.3}–{:.3} simulated: aligning the windows {} the ratio, and what \
             remains would need {:.0}–{:.0} µs of further misalignment at the measured sensitivity \
             ({:.3}–{:.3} per µs), far more than the ±{:.1} µs of the fitted path or the sub-µs foot \
             resolution, so it is not the reflected window's timing. At the peak F_front − F_back is {:+.1} to {:+.1} % of the incident wave's \
             peak force, front below back: the two-wave front force A(σI + σR) is the small \
             difference of two large waves, and an error of that share of the incident wave in the \
             reflected one (or the incident one) at that instant gives the whole imbalance; \
the simulated ratio is the ideal test's lower bound.\n",
            stated.0,
            stated.1,
            feet.0,
            feet.1,
            sim.0,
            sim.1,
            if feet.1 < stated.0 {
                "lowers"
            } else if feet.0 > stated.1 {
                "raises"
            } else {
                "does not consistently lower"
            },
            need.0,
            need.1,
            sens.0,
            sens.1,
            fit.half_spread_m / c0 * 2.0 * 1e6,
            share.0,
            share.1,
        );
    }
    let all_share = min_max(rows.iter().map(|r| {
        r.timing
            .record_on_feet
            .as_ref()
            .map_or(f64::NAN, |x| imbalance_of_incident(x, ea) * 100.0)
    }));
    let sensitivity = min_max(rows.iter().map(|r| r.timing.sensitivity_per_s * 1e-6));
    let _ = writeln!(
        w,
        "So misalignment of the reflected window explains little of the records' imbalance: \
         re-aligned by their own feet or by the effective path, the ratios at peak stay more than ten times the simulated ones and do \
         not fall consistently (the RMS imbalance over the loading does, table *The records' own reflected \
         delay* above). The ratio's sensitivity to the reflected window, taken relative to the \
         ratio's own denominator F_3wave, is {:.3}–{:.3} per µs for every material (docs/physics.md \
         §7.5 estimates 0.03 per µs for SS440c and 0.18 per µs for Al2017 relative to the back \
         force, which for Al2017 is a third of F_3wave at a ratio near 1). What remains is the same \
         share of the incident wave, {:+.1} to {:+.1} %, on every record whatever the material, pressure \
         or ratio. Read at that one instant it looks like a mismatch between the records' incident \
         and reflected waves (their relative amplitude or shape as read at the gauge: attenuation \
         over the extra 2 d_eff of path, the dispersion correction, the incident-bar end and insert \
         interfaces, contact misalignment); the next paragraphs test those candidates, and the time \
         history of the imbalance (*Mass between the faces*, *The windows that balance the \
         records*) shows where it comes from instead.",
        sensitivity.0, sensitivity.1, all_share.0, all_share.1,
    );
    let quiet = min_max(rows.iter().map(|r| r.timing.record.between_pulses * 100.0));
    let inserts_ratio = min_max(
        rows.iter()
            .map(|r| r.timing.inserts.reduction.equilibrium_ratio_at_peak),
    );
    let inserts_share = min_max(
        rows.iter()
            .map(|r| imbalance_of_incident(&r.timing.inserts.reduction, ea) * 100.0),
    );
    let uncorrected = min_max(rows.iter().map(|r| {
        r.timing
            .record_on_feet_uncorrected
            .as_ref()
            .map_or(f64::NAN, |x| imbalance_of_incident(x, ea) * 100.0)
    }));
    let _ = writeln!(
        w,
        "\nThree candidates excluded. An AC-coupled amplifier would let the incident channel droop after \
         the long compressive incident pulse, so that the reflected pulse rides on a tensile offset \
         and F_front reads low by that offset, the same share of the incident wave on every record. \
         Between the two pulses (the 25 µs ending 5 µs before each reflected foot) the records' \
         incident channel sits at {:+.1} to {:+.1} % of its incident peak (compression positive): the \
         incident pulse's own slow tail, of the other sign and an order of magnitude smaller than the {:+.1} to {:+.1} % the \
         imbalance would need. Nor attenuation, by its sign: over its longer path the reflected \
         pulse would arrive smaller at the gauge and F_front read high, not low. Nor the dispersion \
         correction: with both windows on the feet and no correction the share is {:+.1} to {:+.1} % \
         (with the Bancroft correction {:+.1} to {:+.1} %). Inserts as the model has them, bar steel \
         pressed flat on both sides ((b)), leave the simulated tests balanced (ratio at peak \
         {:.3}–{:.3}, F_front − F_back {:+.1} to {:+.1} % of the incident peak force). Left after these \
         three: the incident-bar end, the inserts (their material, faces and seating) and contact \
         misalignment; the next paragraph tests what the inserts could do.",
        quiet.0,
        quiet.1,
        all_share.0,
        all_share.1,
        uncorrected.0,
        uncorrected.1,
        all_share.0,
        all_share.1,
        inserts_ratio.0,
        inserts_ratio.1,
        inserts_share.0,
        inserts_share.1,
    );
    mass_between_faces_section(w, rows, ea / c0, ea);
}

/// The fourth candidate: a mass between the bar faces (heavy inserts), tested on the time history
/// of the imbalance rather than its value at peak (docs/physics.md §7.5).
fn mass_between_faces_section(w: &mut String, rows: &[Row], z: f64, ea: f64) {
    let _ = writeln!(
        w,
        "\n**Mass between the faces.** A mass m between a bar face and the contact (an insert, a \
         holder) makes the two-wave front force exceed the contact force by m a_front and the \
         one-wave back force fall short of it by m a_back, so F_front − F_back = m (a_front + a_back), \
         front below back wherever the faces slow down, as at the peak. The probe (d) is a heavy insert, \
         1/4\" of tungsten carbide 1\" across on both sides (ρ = 15 630 kg/m³, E = 600 GPa, 50 g \
         each; a probe, not the authors' inserts, whose material and diameter are not stated). The value at peak is one \
         instant; the time history tests the hypothesis: from rest, ∫₀ᵗ (F_front − F_back) dt = m (v_front + v_back), with v_back = F_back/Z \
         and v_front = δ̇ + v_back (Z = E A/c0 = {z:.0} kg/s), so the least-squares m of that relation \
         over the loading (to the peak back force; `shpb_validate::gauge_records::effective_mass_kg`, \
         unit-tested on a synthetic 50 g pair) is the mass between the faces, and R² says how much \
         of the imbalance's impulse it explains.\n"
    );
    let _ = writeln!(
        w,
        "| sample | specimen | record m (g), stated geometry | R² | record m (g), both windows on the feet | R² | simulated m (g): (a) shipped | (b) bar-steel inserts | (d) heavy inserts | (d) R² | ratio at peak: (d) | record on the feet | F_front − F_back at peak, of the incident peak force (%): (d) | record on the feet |"
    );
    let _ = writeln!(
        w,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    /// One record's fits (m kg, R²): the record with the stated geometry and on its feet, and its
    /// virtual tests (a) shipped, (b) bar-steel inserts, (d) heavy inserts.
    struct Fits {
        stated: (f64, f64),
        feet: (f64, f64),
        shipped: (f64, f64),
        inserts: (f64, f64),
        heavy: (f64, f64),
    }
    let g = |r: &Reduction| mass_between_faces(r, z);
    let feet = |r: &Row, f: &dyn Fn(&Reduction) -> f64| {
        r.timing.record_on_feet.as_ref().map_or(f64::NAN, f)
    };
    let fits: Vec<Fits> = rows
        .iter()
        .map(|r| Fits {
            stated: g(&r.ours),
            feet: r
                .timing
                .record_on_feet
                .as_ref()
                .map_or((f64::NAN, f64::NAN), g),
            shipped: g(&r.timing.shipped.reduction),
            inserts: g(&r.timing.inserts.reduction),
            heavy: g(&r.timing.heavy.reduction),
        })
        .collect();
    for (r, m) in rows.iter().zip(&fits) {
        let t = &r.timing;
        let _ = writeln!(
            w,
            "| {} | {} {} psi | {:+.1} | {:.3} | {:+.1} | {:.3} | {:+.1} | {:+.1} | {:+.1} | {:.3} | {:.3} | {:.3} | {:+.1} | {:+.1} |",
            r.n,
            r.material,
            r.psi,
            m.stated.0 * 1e3,
            m.stated.1,
            m.feet.0 * 1e3,
            m.feet.1,
            m.shipped.0 * 1e3,
            m.inserts.0 * 1e3,
            m.heavy.0 * 1e3,
            m.heavy.1,
            t.heavy.reduction.equilibrium_ratio_at_peak,
            feet(r, &|x| x.equilibrium_ratio_at_peak),
            imbalance_of_incident(&t.heavy.reduction, ea) * 100.0,
            feet(r, &|x| imbalance_of_incident(x, ea) * 100.0),
        );
    }
    let range =
        |f: &dyn Fn(&Row, &Fits) -> f64| min_max(rows.iter().zip(&fits).map(|(r, m)| f(r, m)));
    let m_rec = range(&|_, m| m.stated.0 * 1e3);
    let r2_rec = range(&|_, m| m.stated.1);
    let m_feet = range(&|_, m| m.feet.0 * 1e3);
    let r2_feet = range(&|_, m| m.feet.1);
    let m_heavy = range(&|_, m| m.heavy.0 * 1e3);
    let r2_heavy = range(&|_, m| m.heavy.1);
    let m_shipped = range(&|_, m| m.shipped.0 * 1e3);
    let share_heavy = range(&|r, _| imbalance_of_incident(&r.timing.heavy.reduction, ea) * 100.0);
    let share_feet = range(&|r, _| feet(r, &|x| imbalance_of_incident(x, ea) * 100.0));
    let factor = range(&|r, _| {
        let (a, b) = (
            r.timing.heavy.reduction.equilibrium_ratio_at_peak,
            feet(r, &|x| x.equilibrium_ratio_at_peak),
        );
        (a / b).max(b / a)
    });
    let _ = writeln!(
        w,
        "\nThe virtual tests recover a positive mass: {:+.1} to {:+.1} g with the shipped set-up (the \
         spheres), {:+.1} to {:+.1} g with the heavy inserts (R² {:.3}–{:.3}; less than the inserts' \
         50 g, since an insert of another impedance is not a rigid mass and the run's reduction adds \
         its transit). At the peak the heavy inserts look like the records on their feet: shares \
         {:+.1} to {:+.1} % against {:+.1} to {:+.1} %, ratios within a factor {:.2} of the records'. \
         Over the loading they do not. On the feet the records' m is {:+.1} to {:+.1} g and explains \
         {:.0}–{:.0} % of the imbalance's impulse (R²), where the heavy inserts' m explains \
         {:.0}–{:.0} %; with the stated geometry it is {:+.1} to {:+.1} g (R² {:.3}–{:.3}), the inertia's \
         form with the other sign: an impulse of the front force below the back one that grows with \
         the faces' speed. A mass between the faces can only be positive and would show as one, so \
         insert inertia is excluded whatever the inserts' material or size, and the heavy inserts' \
         match at peak is a coincidence of one instant. Nor can anything else between the faces give \
         it: a massless compliance (an insert's seating, a gap closing) carries the same force on \
         both sides, and a holder leaking force to the frame would leave the back force below the \
         front one, the other sign. What is left is how the records' waves are placed against \
         each other, which the next paragraph searches.",
        m_shipped.0,
        m_shipped.1,
        m_heavy.0,
        m_heavy.1,
        r2_heavy.0,
        r2_heavy.1,
        share_heavy.0,
        share_heavy.1,
        share_feet.0,
        share_feet.1,
        factor.1,
        m_feet.0,
        m_feet.1,
        r2_feet.0 * 100.0,
        r2_feet.1 * 100.0,
        r2_heavy.0 * 100.0,
        r2_heavy.1 * 100.0,
        m_rec.0,
        m_rec.1,
        r2_rec.0,
        r2_rec.1,
    );
}
