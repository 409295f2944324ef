//! Uncertainty propagation (`shpb study`, docs/physics.md §10): the scene's distributions
//! (`shpb_input::distribution`) and the gun's shot-to-shot scatter drawn by a seeded Latin
//! hypercube, each sample run as a normal run, and the statistics of every summary quantity:
//! mean, standard deviation, 5/50/95 % percentiles and first-order sensitivity indices.

use crate::sweep::{RunSummary, SUMMARY_COLUMNS, input_si, summarise};
use rand_xoshiro::Xoshiro256StarStar;
use rand_xoshiro::rand_core::{Rng as _, SeedableRng};
use shpb_core::apparatus::Apparatus;
use shpb_core::fidelity::Fidelity;
use shpb_core::scene::{Params, SceneParams};
use shpb_input::distribution::{Distribution, Uncertain, find_distributions};
use shpb_input::prelude::*;
use shpb_input::{Error, Result};
use std::path::Path;

/// A seeded pseudo-random generator: xoshiro256** (Blackman & Vigna 2018, "Scrambled linear
/// pseudorandom number generators", the `rand_xoshiro` crate), its state filled by SplitMix64
/// from the seed (Steele, Lea & Flood 2014): the same seed gives the same stream on every
/// platform (and the stream of shpb's own implementation before the crate, test
/// `the_stream_is_xoshiro256_starstar_seeded_by_splitmix64`).
#[derive(Debug, Clone)]
pub struct Rng {
    inner: Xoshiro256StarStar,
}

impl Rng {
    /// A generator seeded with `seed` (SplitMix64 expands it to the 256-bit state).
    pub fn new(seed: u64) -> Rng {
        Rng {
            inner: Xoshiro256StarStar::seed_from_u64(seed),
        }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.inner.next_u64()
    }

    /// A uniform number in the open interval (0, 1) (53 random bits, offset by half a step).
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A uniform index in 0..n (Lemire's multiply-shift; the bias is below n/2^64).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() as u128 * n as u128) >> 64) as usize
    }
}

/// A Latin hypercube of `n` points in `d` dimensions (McKay, Beckman & Conover 1979): for each
/// dimension an independent random permutation π of the n strata (Fisher–Yates) and
/// u = (π(i) + U)/n with U uniform in (0, 1), so every dimension has exactly one point in each
/// of its n equal-probability strata. Returned as `u[sample][dimension]`, each in (0, 1).
pub fn latin_hypercube(n: usize, d: usize, rng: &mut Rng) -> Vec<Vec<f64>> {
    let mut u = vec![vec![0.0; d]; n];
    for j in 0..d {
        let mut perm: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            perm.swap(i, rng.below(i + 1));
        }
        for (i, row) in u.iter_mut().enumerate() {
            row[j] = (perm[i] as f64 + rng.uniform()) / n as f64;
        }
    }
    u
}

/// The Student-t quantile t_p(ν), 0 < p < 1, ν ≥ 1 degrees of freedom: exact for ν = 1 and 2,
/// else the Cornish–Fisher expansion in Φ⁻¹(p) to ν⁻⁴ (Abramowitz & Stegun 26.7.5; relative
/// error below 5e-4 at ν = 3, 2e-5 at ν = 6, at p = 0.95).
pub fn student_t_quantile(p: f64, dof: f64) -> f64 {
    if dof <= 1.0 {
        return (std::f64::consts::PI * (p - 0.5)).tan();
    }
    if dof <= 2.0 {
        return (2.0 * p - 1.0) / (2.0 * p * (1.0 - p)).sqrt();
    }
    let x = normal_quantile(p);
    let (x2, n) = (x * x, dof);
    let g1 = (x2 + 1.0) * x / 4.0;
    let g2 = ((5.0 * x2 + 16.0) * x2 + 3.0) * x / 96.0;
    let g3 = (((3.0 * x2 + 19.0) * x2 + 17.0) * x2 - 15.0) * x / 384.0;
    let g4 = ((((79.0 * x2 + 776.0) * x2 + 1482.0) * x2 - 1920.0) * x2 - 945.0) * x / 92160.0;
    x + g1 / n + g2 / (n * n) + g3 / (n * n * n) + g4 / (n * n * n * n)
}

/// The standard normal quantile Φ⁻¹(p), 0 < p < 1: Acklam's rational approximation (P. J.
/// Acklam 2003, "An algorithm for computing the inverse normal cumulative distribution
/// function"; relative error below 1.15e-9 over the whole range).
#[allow(clippy::excessive_precision)] // Acklam's coefficients as published
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.383577518672690e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    const P_LOW: f64 = 0.02425;
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < P_LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    }
}

/// The value of `distribution` at probability `u` in (0, 1) (its inverse cumulative
/// distribution function): normal mean + sd Φ⁻¹(u); uniform min + u (max − min); log-normal
/// median · gsd^Φ⁻¹(u); measured values the ⌊u n⌋-th smallest (each with probability 1/n).
pub fn quantile(distribution: &Distribution, u: f64) -> f64 {
    match distribution {
        Distribution::Normal { mean, sd } => mean + sd * normal_quantile(u),
        Distribution::Uniform { min, max } => min + u * (max - min),
        Distribution::LogNormal { median, gsd } => median * gsd.powf(normal_quantile(u)),
        Distribution::Empirical { values } => {
            values[((u * values.len() as f64) as usize).min(values.len() - 1)]
        }
    }
}

/// Arithmetic mean and sample standard deviation (divisor n − 1) of `x` (NaN for an empty `x`;
/// sd NaN for one value).
pub fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let ss: f64 = x.iter().map(|v| (v - mean) * (v - mean)).sum();
    (mean, (ss / (n - 1.0)).sqrt())
}

/// The `p` quantile (0 ≤ p ≤ 1) of `sorted` (ascending) by linear interpolation between order
/// statistics, Hyndman & Fan (1996) type 7 (R's and numpy's default): h = (n − 1) p,
/// x[⌊h⌋] + (h − ⌊h⌋)(x[⌊h⌋+1] − x[⌊h⌋]).
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = (sorted.len() - 1) as f64 * p;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(sorted.len() - 1);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// The first-order sensitivity index S = Var(E[Y|X]) / Var(Y) of output `y` to input `x`
/// (Sobol' 1993), estimated from one sample by the correlation ratio: the samples sorted by x
/// are cut into B = ⌊√N⌋ bins of (nearly) equal count, E[Y|X] is the bin mean, and
/// the raw ratio η² = SS_between / SS_total, SS_between = Σ_b n_b (ȳ_b − ȳ)², has expectation
/// ≈ (B − 1)/(N − 1) (≈ 1/√N) for an input without effect, so the index returned is Kelley's
/// (1935) bias-corrected ε² = (SS_between − (B − 1) SS_within/(N − B)) / SS_total, clamped to
/// [0, 1]. Left: the spread of E[Y|X] within a bin is lost (≈ 1/B² of a linear response's
/// variance for a uniform input, more in the tails of a normal one). NaN when Y does not vary or
/// fewer than 4 pairs are finite.
pub fn first_order_index(x: &[f64], y: &[f64]) -> f64 {
    let mut pairs: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .collect();
    let n = pairs.len();
    if n < 4 {
        return f64::NAN;
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let ybar = pairs.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let total: f64 = pairs.iter().map(|p| (p.1 - ybar) * (p.1 - ybar)).sum();
    if total <= 0.0 {
        return f64::NAN;
    }
    let bins = (n as f64).sqrt().floor() as usize;
    let between: f64 = (0..bins)
        .map(|b| {
            let chunk = &pairs[b * n / bins..(b + 1) * n / bins];
            let m = chunk.iter().map(|p| p.1).sum::<f64>() / chunk.len() as f64;
            chunk.len() as f64 * (m - ybar) * (m - ybar)
        })
        .sum();
    let within = total - between;
    let corrected = (between - (bins - 1) as f64 * within / (n - bins) as f64) / total;
    corrected.clamp(0.0, 1.0)
}

/// The statistics of one quantity over a study's samples (its finite values only).
#[derive(Debug, Clone, PartialEq)]
pub struct Stats {
    /// Quantity name (a summary column, or an input key).
    pub name: String,
    /// SI units.
    pub unit: String,
    /// Finite values counted.
    pub count: usize,
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation (n − 1).
    pub sd: f64,
    /// 5, 50 and 95 % percentiles (type 7, [`percentile`]).
    pub p5_p50_p95: [f64; 3],
    /// First-order sensitivity index to each input ([`first_order_index`]; empty for an input).
    pub first_order: Vec<f64>,
}

/// The statistics of values `y` named `name` in `unit`, with first-order indices to `inputs`.
pub fn stats_of(name: &str, unit: &str, y: &[f64], inputs: &[Vec<f64>]) -> Stats {
    let mut finite: Vec<f64> = y.iter().copied().filter(|v| v.is_finite()).collect();
    finite.sort_by(f64::total_cmp);
    let (mean, sd) = mean_sd(&finite);
    Stats {
        name: name.to_string(),
        unit: unit.to_string(),
        count: finite.len(),
        mean,
        sd,
        p5_p50_p95: [0.05, 0.5, 0.95].map(|p| percentile(&finite, p)),
        first_order: inputs.iter().map(|x| first_order_index(x, y)).collect(),
    }
}

/// Where an input of a study comes from.
#[derive(Debug, Clone)]
pub enum Source {
    /// A distribution written in the scene.
    Scene(Uncertain),
    /// The gun's shot-to-shot scatter (`[gun] velocity_scatter` of the set-up): the drawn number
    /// is the striker velocity over its nominal value, normal with mean 1 and sd `scatter`; the
    /// run gets the gun pressure that gives that velocity ([`pressure_for_velocity`]).
    GunScatter {
        /// The scene's (fixed) gun pressure, Pa.
        pressure_pa: f64,
        /// Relative standard deviation of the striker velocity.
        scatter: f64,
        /// The set-up (its gun and striker).
        apparatus: Box<Apparatus>,
    },
}

/// One input of a study: the scene key it sets and where its numbers come from.
#[derive(Debug, Clone)]
pub struct StudyInput {
    /// Scene key (`pressure`, `shaper.thickness_m`).
    pub key: String,
    /// The distribution or the gun scatter.
    pub source: Source,
}

impl StudyInput {
    /// The distribution the Latin hypercube draws from.
    pub fn distribution(&self) -> Distribution {
        match &self.source {
            Source::Scene(u) => u.distribution.clone(),
            Source::GunScatter { scatter, .. } => Distribution::Normal {
                mean: 1.0,
                sd: *scatter,
            },
        }
    }

    /// The scene value and the text as written of a drawn number `x`.
    pub fn value(&self, x: f64) -> Result<(shpb_input::scene::Value, String)> {
        match &self.source {
            Source::Scene(u) => Ok((u.value(x), u.label(x))),
            Source::GunScatter {
                pressure_pa,
                apparatus,
                ..
            } => {
                let v = x * apparatus.striker_velocity_m_s(*pressure_pa)?;
                let p = pressure_for_velocity(apparatus, v)?;
                let label = format!("{p}Pa");
                Ok((shpb_input::scene::Value::String(label.clone()), label))
            }
        }
    }

    /// The input as described in tables (`pressure: normal(mean=12.5, sd=0.6) psi`).
    pub fn describe(&self) -> String {
        match &self.source {
            Source::Scene(u) => format!("{}: {}", self.key, u.distribution.describe(&u.unit)),
            Source::GunScatter {
                pressure_pa,
                scatter,
                ..
            } => format!(
                "{}: gun shot-to-shot scatter at {pressure_pa} Pa, striker velocity relative sd \
                 {scatter} (the set-up's [gun] velocity_scatter)",
                self.key
            ),
        }
    }
}

/// The gauge pressure at which the set-up's gun launches its striker at `velocity_m_s` (the gun
/// curve inverted by bisection to 1e-12 relative; it rises with pressure, docs/physics.md §6.4);
/// an input error when the velocity is outside the gun's range.
pub fn pressure_for_velocity(a: &Apparatus, velocity_m_s: f64) -> Result<f64> {
    let (mut lo, mut hi) = a.gun.range_pa();
    let (vlo, vhi) = (a.striker_velocity_m_s(lo)?, a.striker_velocity_m_s(hi)?);
    if !(vlo..=vhi).contains(&velocity_m_s) {
        return Err(Error::Input {
            file: a.source.clone(),
            key: "gun.velocity_scatter".into(),
            problem: format!(
                "a drawn striker velocity {velocity_m_s:.4} m/s is outside the gun's range"
            ),
            allowed: format!("{vlo:.4} to {vhi:.4} m/s (the gun's pressure range)"),
        });
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if a.striker_velocity_m_s(mid)? < velocity_m_s {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// The inputs of a study of `scene`: every distribution the scene writes, then (with
/// `gun_scatter`, when the scene's `pressure` is one fixed value and its set-up states a
/// `velocity_scatter`) the gun's shot-to-shot scatter as an input of `pressure`.
pub fn study_inputs(scene: &Path, gun_scatter: bool) -> Result<Vec<StudyInput>> {
    let text = shpb_input::files::read_to_string(scene).map_err(|e| Error::io(scene, e))?;
    let file = scene.display().to_string();
    let uncertain = find_distributions(&text, &file)?;
    let mut inputs: Vec<StudyInput> = uncertain
        .iter()
        .map(|u| StudyInput {
            key: u.key.clone(),
            source: Source::Scene(u.clone()),
        })
        .collect();
    if gun_scatter && !inputs.iter().any(|i| i.key == "pressure") {
        let central: Vec<(String, shpb_input::scene::Value)> = uncertain
            .iter()
            .map(|u| (u.key.clone(), u.value(u.distribution.central())))
            .collect();
        let params = Params::from_file_overridden(scene, &central)?;
        // A test driven by a recorded incident wave has no gun to scatter (docs/physics.md §6.10).
        if let SceneParams::Pulse {
            apparatus,
            pressure_pa,
            options,
        } = &params.params
            && options.incident_drive.is_none()
            && let Some(scatter) = apparatus.gun_velocity_scatter
            && scatter > 0.0
        {
            inputs.push(StudyInput {
                key: "pressure".into(),
                source: Source::GunScatter {
                    pressure_pa: *pressure_pa,
                    scatter,
                    apparatus: apparatus.clone(),
                },
            });
        }
    }
    Ok(inputs)
}

/// The drawn samples of a study: per sample, per input, the scene value and its text.
#[derive(Debug, Clone)]
pub struct Samples {
    /// The scene overrides of each sample.
    pub overrides: Vec<Vec<(String, shpb_input::scene::Value)>>,
    /// The inputs as written for each sample (`12.53psi`).
    pub labels: Vec<Vec<String>>,
}

/// Draws `n` samples of `inputs` by a Latin hypercube seeded with `seed` ([`latin_hypercube`],
/// [`quantile`]).
pub fn draw(inputs: &[StudyInput], n: usize, seed: u64) -> Result<Samples> {
    let u = latin_hypercube(n, inputs.len(), &mut Rng::new(seed));
    let distributions: Vec<Distribution> = inputs.iter().map(StudyInput::distribution).collect();
    let mut overrides = Vec::with_capacity(n);
    let mut labels = Vec::with_capacity(n);
    for row in &u {
        let mut o = Vec::with_capacity(inputs.len());
        let mut l = Vec::with_capacity(inputs.len());
        for ((input, d), &ui) in inputs.iter().zip(&distributions).zip(row) {
            let (value, label) = input.value(quantile(d, ui))?;
            o.push((input.key.clone(), value));
            l.push(label);
        }
        overrides.push(o);
        labels.push(l);
    }
    Ok(Samples { overrides, labels })
}

/// A run's time series kept for the band plots: time (s) and the value.
pub type Trace = (Vec<f64>, Vec<f64>);

/// The traces of one run drawn as bands: the reduced back force (N) and the transmission
/// gauge's strain against time (empty when the run has none).
#[derive(Debug, Clone, Default)]
pub struct RunTraces {
    /// Reduced back (transmitted) force against reduced time.
    pub back_force: Option<Trace>,
    /// Transmission gauge strain against run time.
    pub transmitted_strain: Option<Trace>,
    /// True contact force (N) against approach (m) on loading: up to the peak force, the points
    /// where the approach exceeds every earlier one.
    pub force_approach: Option<Trace>,
}

/// The loading branch of a force–approach curve: up to the peak force, the points whose approach
/// exceeds every earlier one (so the approach rises strictly and can be interpolated).
pub fn loading_branch(approach_m: &[f64], force_n: &[f64], peak: usize) -> Trace {
    let mut x = Vec::new();
    let mut y = Vec::new();
    for (&d, &f) in approach_m.iter().zip(force_n).take(peak + 1) {
        if x.last().is_none_or(|&last| d > last) {
            x.push(d);
            y.push(f);
        }
    }
    (x, y)
}

/// The samples whose traces a study keeps for its band plots (the first ones, a random sample of
/// the same distribution: ≈ 150 kB each, so a large study does not hold them all).
pub const MAX_TRACED_SAMPLES: usize = 1000;

/// A finished study: its inputs, samples, one summary row per sample and, when asked, traces.
#[derive(Debug, Clone)]
pub struct Study {
    /// The inputs.
    pub inputs: Vec<StudyInput>,
    /// The drawn samples.
    pub samples: Samples,
    /// The summary of each sample's run, in sample order.
    pub rows: Vec<RunSummary>,
    /// The traces of each run (empty unless asked for).
    pub traces: Vec<RunTraces>,
    /// The seed.
    pub seed: u64,
    /// The fidelity preset every run took in place of the scene's (`--fidelity`), if given.
    pub fidelity: Option<Fidelity>,
}

/// What a study draws and how each sample runs (`shpb study`'s `--samples`, `--seed`,
/// `--no-gun-scatter` and `--fidelity`): every shard of a study and their join take the same.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StudyPlan {
    /// Samples (runs), 2 to 1,000,000.
    pub samples: usize,
    /// Seed of the Latin hypercube.
    pub seed: u64,
    /// Whether the set-up's shot-to-shot gun scatter is drawn on a fixed pressure.
    pub gun_scatter: bool,
    /// The fidelity preset of every run in place of the scene's (as `shpb run --fidelity`).
    pub fidelity: Option<Fidelity>,
}

impl StudyPlan {
    /// `samples` samples drawn with `seed`, the gun scatter on, the scene's fidelity.
    pub fn new(samples: usize, seed: u64) -> StudyPlan {
        StudyPlan {
            samples,
            seed,
            gun_scatter: true,
            fidelity: None,
        }
    }
}

/// Runs a study of `scene`: the plan's samples (≥ 2) drawn with its seed from the scene's inputs
/// ([`study_inputs`]), each sample validated before the first run, then run on `jobs` threads
/// (each a normal run of the scene with the sample's values, at the plan's fidelity), `done`
/// called as each finishes; traces kept with `keep_traces` (of the first [`MAX_TRACED_SAMPLES`]).
pub fn study_rows(
    scene: &Path,
    plan: &StudyPlan,
    jobs: usize,
    keep_traces: bool,
    done: impl Fn(&RunSummary) + Sync,
) -> Result<Study> {
    study_shard_rows(scene, plan, jobs, keep_traces, (1, 1), done)
}

/// The inputs and samples of a study of `scene` (the plan's samples drawn with its seed, each
/// sample's overrides ending with the plan's fidelity): what each shard of the study, and the
/// join of their rows, recompute identically.
fn study_draw(scene: &Path, plan: &StudyPlan) -> Result<(Vec<StudyInput>, Samples)> {
    let (n, seed) = (plan.samples, plan.seed);
    crate::sweep::require_scene(scene)?;
    if !(2..=1_000_000).contains(&n) {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--samples".into(),
            problem: format!("{n}"),
            allowed: "2 to 1000000 samples".into(),
        });
    }
    let inputs = study_inputs(scene, plan.gun_scatter)?;
    let mut samples = draw(&inputs, n, seed)?;
    // (`fidelity` is a name, never drawn: distributions are of quantities.)
    if let Some(f) = plan.fidelity {
        let preset = (
            "fidelity".to_string(),
            shpb_input::scene::Value::String(f.name().into()),
        );
        for o in &mut samples.overrides {
            o.push(preset.clone());
        }
    }
    Ok((inputs, samples))
}

/// [`study_draw`] with every sample validated before the first run (a bad draw fails fast,
/// naming its value), in parallel on `pool` (the pool of the runs, issue 45); the error is the
/// first invalid sample's, as a serial loop gives it.
fn study_samples(
    scene: &Path,
    plan: &StudyPlan,
    pool: &rayon::ThreadPool,
) -> Result<(Vec<StudyInput>, Samples)> {
    use rayon::prelude::*;
    let (inputs, samples) = study_draw(scene, plan)?;
    let keys: Vec<&str> = inputs.iter().map(|input| input.key.as_str()).collect();
    let check = |i: usize, o: &Vec<(String, shpb_input::scene::Value)>| -> Result<()> {
        // A drawn value of the wrong type (a number where the key takes a quantity with its
        // unit): name the inputs and the sample, not the line of a scene text nobody wrote nor
        // a command line that did not set it.
        let drawn = |reason: &str| Error::Input {
            file: scene.display().to_string(),
            key: keys.join(", "),
            problem: format!(
                "sample {i} ({}) is not a value the scene takes: {reason}",
                samples.labels[i].join(", ")
            ),
            allowed: "a distribution in the key's own form: with its unit where the key takes \
                      one (pressure = { mean = \"12.5psi\", sd = \"0.6psi\" })"
                .into(),
        };
        Params::from_file_overridden(scene, o)
            .map(drop)
            .map_err(|e| match e {
                Error::Parse { message, .. } => drawn(&message),
                Error::Input { key, problem, .. } if keys.contains(&key.as_str()) => drawn(
                    problem
                        .split_once(" on the command line: ")
                        .map_or(problem.as_str(), |(_, reason)| reason),
                ),
                other => other,
            })
    };
    // The first failure in sample order (`find_first` stops the samples after one found).
    let first_bad = pool.install(|| {
        samples
            .overrides
            .par_iter()
            .enumerate()
            .map(|(i, o)| check(i, o))
            .find_first(Result::is_err)
    });
    if let Some(e) = first_bad {
        e?;
    }
    Ok((inputs, samples))
}

/// Shard `k` of `m` of a study ([`study_rows`]): the same samples of the same plan, of which only
/// those with index ≡ k − 1 (mod m) are run (as `shpb sweep --shard k/m` cuts a sweep), so
/// shards run anywhere (a Dask worker, a job array) and [`Study::from_rows`] joins their rows into
/// the study [`study_rows`] gives.
pub fn study_shard_rows(
    scene: &Path,
    plan: &StudyPlan,
    jobs: usize,
    keep_traces: bool,
    shard: (usize, usize),
    done: impl Fn(&RunSummary) + Sync,
) -> Result<Study> {
    study_shard_rows_until(scene, plan, jobs, keep_traces, shard, done, &|| true)
        .map(|(study, _)| study)
}

/// [`study_shard_rows`] that `keep_going` may stop (`crate::sweep::run_until`): the study of the
/// samples finished (its `rows` then miss the others) and whether it was stopped (how
/// `shpb.study` keeps its rows on Ctrl-C).
pub fn study_shard_rows_until(
    scene: &Path,
    plan: &StudyPlan,
    jobs: usize,
    keep_traces: bool,
    (k, m): (usize, usize),
    done: impl Fn(&RunSummary) + Sync,
    keep_going: &(dyn Fn() -> bool + Sync),
) -> Result<(Study, bool)> {
    let (k, m) = crate::sweep::check_shard(k, m)?;
    let n = plan.samples;
    let pool = crate::sweep::thread_pool(jobs)?;
    let (inputs, samples) = study_samples(scene, plan, &pool)?;
    let indices: Vec<usize> = (k - 1..n).step_by(m).collect();
    let finished = crate::sweep::run_until(&pool, &indices, keep_going, |&i, progress| {
        let params = Params::from_file_overridden(scene, &samples.overrides[i])?.summary_only();
        // Every warning of the run kept in its row, the scene's first.
        let mut out = params.run_with_progress(progress)?;
        out.warnings.splice(0..0, params.warnings());
        let row = summarise(i, samples.labels[i].clone(), &out);
        let traces = if keep_traces && i < MAX_TRACED_SAMPLES {
            RunTraces {
                back_force: out
                    .reduction
                    .as_ref()
                    .map(|r| (r.time_s.clone(), r.force_back_n.clone())),
                transmitted_strain: out.time_s.as_ref().and_then(|t| {
                    out.gauges
                        .iter()
                        .find(|g| g.name.contains("transmi"))
                        .map(|g| (t.clone(), g.strain.clone()))
                }),
                force_approach: out
                    .contact
                    .as_ref()
                    .map(|c| loading_branch(&c.displacement_m, &c.force_n, c.peak_index())),
            }
        } else {
            RunTraces::default()
        };
        done(&row);
        Ok((row, traces))
    })?;
    let (rows, traces): (Vec<_>, Vec<_>) = finished.rows.into_iter().unzip();
    let study = Study {
        inputs,
        samples,
        rows,
        traces: if keep_traces {
            traces.into_iter().take(MAX_TRACED_SAMPLES).collect()
        } else {
            Vec::new()
        },
        seed: plan.seed,
        fidelity: plan.fidelity,
    };
    Ok((study, finished.interrupted))
}

impl Study {
    /// The study of `scene` (`n` samples drawn with `seed`) from the rows of its shards
    /// ([`study_shard_rows`]), in any order: each sample's row exactly once, or an error.
    pub fn from_rows(scene: &Path, plan: &StudyPlan, mut rows: Vec<RunSummary>) -> Result<Study> {
        let (n, seed) = (plan.samples, plan.seed);
        // The shards validated and ran the samples; the join only needs them drawn again.
        let (inputs, samples) = study_draw(scene, plan)?;
        rows.sort_by_key(|r| r.index);
        let complete = rows.len() == n
            && rows
                .iter()
                .enumerate()
                .all(|(i, r)| r.index == i && r.inputs == samples.labels[i]);
        if !complete {
            return Err(Error::Input {
                file: scene.display().to_string(),
                key: "rows".into(),
                problem: format!(
                    "{} rows do not hold each of the {n} samples of seed {seed} exactly once",
                    rows.len()
                ),
                allowed: "the rows of every shard k/m of the same study, k = 1..m".into(),
            });
        }
        Ok(Study {
            inputs,
            samples,
            rows,
            traces: Vec::new(),
            seed,
            fidelity: plan.fidelity,
        })
    }

    /// The scene keys of the inputs, in order.
    pub fn keys(&self) -> Vec<String> {
        self.inputs.iter().map(|i| i.key.clone()).collect()
    }

    /// Each input's drawn values in SI units (`shpb sweep`'s [`input_si`]).
    pub fn input_values_si(&self) -> Vec<Vec<f64>> {
        self.inputs
            .iter()
            .enumerate()
            .map(|(k, input)| {
                self.samples
                    .labels
                    .iter()
                    .map(|l| input_si(&input.key, &l[k]).map_or(f64::NAN, |(v, _)| v))
                    .collect()
            })
            .collect()
    }

    /// The statistics of each input (SI units, as drawn) and of each summary column, with the
    /// first-order indices of the summary columns to each input.
    pub fn statistics(&self) -> Vec<Stats> {
        let x = self.input_values_si();
        let mut stats: Vec<Stats> = self
            .inputs
            .iter()
            .zip(&x)
            .enumerate()
            .map(|(k, (input, values))| {
                let unit = self
                    .samples
                    .labels
                    .first()
                    .and_then(|l| input_si(&input.key, &l[k]))
                    .map_or("1", |(_, u)| u);
                stats_of(&format!("input {}", input.key), unit, values, &[])
            })
            .collect();
        for (c, (name, unit)) in SUMMARY_COLUMNS.iter().enumerate() {
            let y: Vec<f64> = self.rows.iter().map(|r| r.values()[c]).collect();
            stats.push(stats_of(name, unit, &y, &x));
        }
        stats
    }

    /// The statistics as CSV: quantity, unit, n, mean, sd, p5, p50, p95, then `S_<key>` per
    /// input (first-order index; empty for the inputs' own rows). Numbers in `{:e}` (exact).
    pub fn statistics_csv(&self) -> String {
        let mut head = vec!["quantity", "unit", "n", "mean", "sd", "p5", "p50", "p95"]
            .into_iter()
            .map(String::from)
            .collect::<Vec<_>>();
        head.extend(self.inputs.iter().map(|i| format!("S_{}", i.key)));
        let mut text = head.join(",");
        text.push('\n');
        for s in self.statistics() {
            let mut cells = vec![
                s.name.clone(),
                s.unit.clone(),
                s.count.to_string(),
                format!("{:e}", s.mean),
                format!("{:e}", s.sd),
            ];
            cells.extend(s.p5_p50_p95.iter().map(|v| format!("{v:e}")));
            if s.first_order.is_empty() {
                cells.extend(self.inputs.iter().map(|_| String::new()));
            } else {
                cells.extend(s.first_order.iter().map(|v| format!("{v:e}")));
            }
            text.push_str(&cells.join(","));
            text.push('\n');
        }
        text
    }

    /// The statistics as an aligned text table (what `shpb study` prints): quantity, unit, n,
    /// mean, sd, p5, p50, p95 and `S_<key>`, numbers with four significant digits.
    pub fn statistics_table(&self) -> String {
        let csv = self.statistics_csv();
        let rows: Vec<Vec<String>> = csv
            .lines()
            .enumerate()
            .map(|(i, line)| {
                line.split(',')
                    .enumerate()
                    .map(|(j, cell)| match cell.parse::<f64>() {
                        Ok(v) if i > 0 && j > 2 => four_digits(v),
                        _ => cell.to_string(),
                    })
                    .collect()
            })
            .collect();
        let columns = rows.iter().map(Vec::len).max().unwrap_or(0);
        let widths: Vec<usize> = (0..columns)
            .map(|j| {
                rows.iter()
                    .map(|r| r.get(j).map_or(0, |c| c.chars().count()))
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let mut text = String::new();
        for r in &rows {
            let cells: Vec<String> = r
                .iter()
                .zip(&widths)
                .enumerate()
                .map(|(j, (c, &w))| {
                    if j == 0 {
                        format!("{c:<w$}")
                    } else {
                        format!("{c:>w$}")
                    }
                })
                .collect();
            text.push_str(cells.join("  ").trim_end());
            text.push('\n');
        }
        text
    }

    /// What the study was (for the study file's `sweep` attribute and the table's head): the
    /// sample count, the seed, the design and each input.
    pub fn specification(&self) -> Vec<String> {
        let mut spec = vec![format!(
            "study: {} samples, Latin hypercube, seed {}",
            self.rows.len(),
            self.seed
        )];
        if let Some(f) = self.fidelity {
            spec.push(format!("every run at fidelity {} (--fidelity)", f.name()));
        }
        spec.extend(self.inputs.iter().map(StudyInput::describe));
        spec
    }
}

/// A number with four significant digits, plainly between 0.01 and 99999, else in `e` notation.
fn four_digits(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs().log10().floor() as i64;
    if (-2..5).contains(&magnitude) {
        let digits = (3 - magnitude).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.3e}")
    }
}

/// The 5/50/95 % bands of `traces` on the grid of the trace with the widest span (each trace interpolated
/// linearly; outside its own span it does not count): (time, p5, p50, p95).
pub fn bands(traces: &[&Trace]) -> Option<(Vec<f64>, [Vec<f64>; 3])> {
    let span =
        |t: &&Trace| t.0.last().copied().unwrap_or(0.0) - t.0.first().copied().unwrap_or(0.0);
    let grid = &traces.iter().max_by(|a, b| span(a).total_cmp(&span(b)))?.0;
    let mut out = [vec![], vec![], vec![]];
    let mut at = Vec::with_capacity(traces.len());
    for &t in grid {
        at.clear();
        for (x, y) in traces {
            if x.len() < 2 || t < x[0] || t > x[x.len() - 1] {
                continue;
            }
            let k = x.partition_point(|&v| v <= t).clamp(1, x.len() - 1);
            let w = (t - x[k - 1]) / (x[k] - x[k - 1]);
            let v = y[k - 1] + w * (y[k] - y[k - 1]);
            if v.is_finite() {
                at.push(v);
            }
        }
        at.sort_by(f64::total_cmp);
        for (o, p) in out.iter_mut().zip([0.05, 0.5, 0.95]) {
            o.push(percentile(&at, p));
        }
    }
    Some((grid.clone(), out))
}

#[cfg(test)]
mod tests {

    #[test]
    fn student_t_quantiles_match_the_tables() {
        // t_0.95(ν) from the standard tables (e.g. NIST/SEMATECH e-Handbook, Table 1.3.6.7.2).
        for (dof, t) in [
            (1.0, 6.313752),
            (2.0, 2.919986),
            (3.0, 2.353363),
            (6.0, 1.943180),
            (10.0, 1.812461),
            (30.0, 1.697261),
        ] {
            let q = student_t_quantile(0.95, dof);
            assert!((q / t - 1.0).abs() < 5e-4, "nu = {dof}: {q} against {t}");
        }
    }

    use super::*;

    #[test]
    fn the_stream_is_xoshiro256_starstar_seeded_by_splitmix64() {
        // The reference algorithms written out (Blackman & Vigna; Steele, Lea & Flood): the
        // crate's stream is theirs, bit for bit, so seeded studies repeat across versions.
        fn reference(seed: u64, n: usize) -> Vec<u64> {
            let mut x = seed;
            let mut splitmix = || {
                x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let mut z = x;
                z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                z ^ (z >> 31)
            };
            let mut s = [splitmix(), splitmix(), splitmix(), splitmix()];
            (0..n)
                .map(|_| {
                    let result = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
                    let t = s[1] << 17;
                    s[2] ^= s[0];
                    s[3] ^= s[1];
                    s[1] ^= s[2];
                    s[0] ^= s[3];
                    s[2] ^= t;
                    s[3] = s[3].rotate_left(45);
                    result
                })
                .collect()
        }
        for seed in [0, 1, 7, 42, u64::MAX] {
            let mut rng = Rng::new(seed);
            let stream: Vec<u64> = (0..1000).map(|_| rng.next_u64()).collect();
            assert_eq!(stream, reference(seed, 1000), "seed {seed}");
        }
    }

    /// Standard normal CDF by the complementary error function's series-free bound check:
    /// Φ(Φ⁻¹(p)) = p is tested against known quantiles instead.
    #[test]
    fn the_normal_quantile_matches_tabulated_values() {
        // Φ⁻¹ at 0.5, 0.975, 0.95, 0.001 (tables; Acklam's relative error < 1.15e-9).
        for (p, z) in [
            (0.5, 0.0),
            (0.975, 1.959_963_984_540_054),
            (0.95, 1.644_853_626_951_472_2),
            (0.001, -3.090_232_306_167_813_6),
        ] {
            let q = normal_quantile(p);
            assert!(
                (q - z).abs() <= 1.2e-9 * z.abs().max(1.0),
                "{p}: {q} vs {z}"
            );
        }
        assert!((normal_quantile(0.2) + normal_quantile(0.8)).abs() < 1e-12);
    }

    #[test]
    fn a_latin_hypercube_has_one_point_in_every_stratum_and_is_reproducible() {
        let (n, d) = (50, 3);
        let u = latin_hypercube(n, d, &mut Rng::new(7));
        for j in 0..d {
            let mut strata: Vec<usize> = u.iter().map(|r| (r[j] * n as f64) as usize).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..n).collect::<Vec<_>>());
        }
        assert_eq!(u, latin_hypercube(n, d, &mut Rng::new(7)));
        assert_ne!(u, latin_hypercube(n, d, &mut Rng::new(8)));
    }

    #[test]
    fn type_7_percentiles_interpolate_between_order_statistics() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(percentile(&x, 0.5), 3.0);
        assert_eq!(percentile(&x, 0.05), 1.2); // h = 0.2
        assert_eq!(percentile(&x, 0.95), 4.8);
        assert_eq!(percentile(&x, 1.0), 5.0);
        let (m, s) = mean_sd(&x);
        assert_eq!(m, 3.0);
        assert!((s - 2.5f64.sqrt()).abs() < 1e-15);
    }

    /// Y = a X1 + b X2 with X1 ~ N(m1, σ1), X2 ~ U(0, w) drawn by the Latin hypercube: the mean,
    /// sd and percentiles match the analytic ones and S_i ≈ a²Var(X_i)/Var(Y).
    #[test]
    fn a_linear_model_gives_its_analytic_statistics_and_indices() {
        let (a, b, m1, s1, w) = (2.0, -3.0, 10.0, 0.5, 1.0);
        let d1 = Distribution::Normal { mean: m1, sd: s1 };
        let d2 = Distribution::Uniform { min: 0.0, max: w };
        let n = 1024;
        let u = latin_hypercube(n, 2, &mut Rng::new(42));
        let x1: Vec<f64> = u.iter().map(|r| quantile(&d1, r[0])).collect();
        let x2: Vec<f64> = u.iter().map(|r| quantile(&d2, r[1])).collect();
        let y: Vec<f64> = x1.iter().zip(&x2).map(|(p, q)| a * p + b * q).collect();
        let var1 = a * a * s1 * s1;
        let var2 = b * b * w * w / 12.0;
        let (mean, sd) = (a * m1 + b * w / 2.0, (var1 + var2).sqrt());
        let s = stats_of("y", "1", &y, &[x1, x2]);
        // Mean: within 3 standard errors of simple random sampling (LHS's is never more than
        // N/(N − 1) times that, Owen 1997; for an additive Y it is far smaller).
        assert!(
            (s.mean - mean).abs() < 3.0 * sd / (n as f64).sqrt(),
            "{s:?}"
        );
        // sd: the standard error of a sample sd is ≈ sd/√(2N) for near-normal Y; 3 of them.
        assert!(
            (s.sd - sd).abs() < 3.0 * sd / (2.0 * n as f64).sqrt(),
            "{s:?}"
        );
        // Percentiles of Y (not normal: a normal plus a uniform) computed by the same LHS
        // composite on a 200 000-point reference sample; the sampling error of a p quantile is
        // √(p(1 − p)/N)/f(y_p) ≤ 0.0068/f; with f ≥ 0.15/sd at p = 5 %, within 0.15 sd.
        let mut rng = Rng::new(1);
        let mut big: Vec<f64> = (0..200_000)
            .map(|_| a * quantile(&d1, rng.uniform()) + b * quantile(&d2, rng.uniform()))
            .collect();
        big.sort_by(f64::total_cmp);
        for (k, p) in [0.05, 0.5, 0.95].into_iter().enumerate() {
            let want = percentile(&big, p);
            assert!(
                (s.p5_p50_p95[k] - want).abs() < 0.15 * sd,
                "p{p}: {} vs {want}",
                s.p5_p50_p95[k]
            );
        }
        // First-order indices (N = 1024, B = 32): the bias left after Kelley's correction is the
        // within-bin loss, ≈ 1/B² = 0.001 for the uniform input, a few % for the normal one's
        // tail bins; the sampling error of ε² is ≈ 0.02 here. 0.05 covers both.
        let (si1, si2) = (var1 / (var1 + var2), var2 / (var1 + var2));
        assert!(
            (s.first_order[0] - si1).abs() < 0.05,
            "{:?} vs {si1}",
            s.first_order
        );
        assert!(
            (s.first_order[1] - si2).abs() < 0.05,
            "{:?} vs {si2}",
            s.first_order
        );
        // An input without effect: ε² near 0 (the raw η² would be ≈ (B − 1)/(N − 1) = 0.03).
        let noise: Vec<f64> = (0..n).map(|i| ((i * 7919) % n) as f64).collect();
        assert!(first_order_index(&noise, &y) < 0.02);
    }

    /// Bands of y = c·x for c = 1…5 are c = 1.2 / 3 / 4.8 times x (type 7 at 5/50/95 %), each
    /// trace counting only over its own span; the loading branch keeps a strictly rising approach.
    #[test]
    fn bands_are_percentiles_across_traces_at_each_abscissa() {
        let traces: Vec<Trace> = (1..=5)
            .map(|c| {
                let x: Vec<f64> = (0..=10).map(|i| i as f64 * 0.1).collect();
                let y = x.iter().map(|v| c as f64 * v).collect();
                (x, y)
            })
            .collect();
        let refs: Vec<&Trace> = traces.iter().collect();
        let (x, [p5, p50, p95]) = bands(&refs).unwrap();
        for (i, &xi) in x.iter().enumerate() {
            assert!((p5[i] - 1.2 * xi).abs() < 1e-12);
            assert!((p50[i] - 3.0 * xi).abs() < 1e-12);
            assert!((p95[i] - 4.8 * xi).abs() < 1e-12);
        }
        let (d, f) = loading_branch(
            &[0.0, 1.0, 1.0, 0.5, 2.0, 3.0],
            &[0.0, 1.0, 2.0, 3.0, 4.0, 9.0],
            4,
        );
        assert_eq!((d, f), (vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 4.0]));
    }

    #[test]
    fn measured_values_are_drawn_with_equal_weight() {
        let d = Distribution::Empirical {
            values: vec![1.0, 2.0, 4.0, 8.0],
        };
        let u = latin_hypercube(400, 1, &mut Rng::new(3));
        let mut counts = [0; 4];
        for r in &u {
            let v = quantile(&d, r[0]);
            counts[[1.0, 2.0, 4.0, 8.0].iter().position(|&x| x == v).unwrap()] += 1;
        }
        // One stratum per sample: exactly n/4 of each.
        assert_eq!(counts, [100; 4]);
    }
}
