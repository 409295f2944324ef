//! The affine-invariant ensemble sampler of `shpb fit`'s posterior: the stretch move of
//! Goodman & Weare (Comm. App. Math. Comp. Sci. 5, 65 (2010)) in the parallel "red–black" form
//! of emcee (Foreman-Mackey, Hogg, Lang & Goodman, PASP 125, 306 (2013), §3 and Algorithm 3),
//! and the statistics of its chain: the integrated autocorrelation time (Sokal's automatic
//! window, as emcee's `integrated_time`), the effective sample size, Pearson correlations and
//! numpy's linear quantiles.
//!
//! Written here rather than taken from a crate: the one Rust ensemble sampler on crates.io
//! (`emcee`, 0.3.0 and 1.0.0-alpha) has had no release for years, pins an old `rand`, evaluates
//! the walkers one at a time through a trait (no batch to hand to rayon), keeps its generator
//! state inside the sampler (so a checkpoint cannot resume bit for bit) and has no
//! autocorrelation estimator; the algorithm itself is a few dozen lines.
//!
//! Reproducible and resumable without storing a generator: the random numbers of the move of
//! half `h` at step `t` come from xoshiro256** ([`crate::uq::Rng`]) seeded from
//! (seed, t, h) by SplitMix64 mixing ([`stream_seed`]), so a run of 2N steps equals a run of N
//! steps resumed for N more, bit for bit. Pure numerics: no I/O, no scene types.

use crate::uq::{Rng, normal_quantile, percentile};
use rustfft::num_complex::Complex;
use shpb_core::gauge::SplitMix64;
use shpb_core::numeric::{fast_fft_length, fft_plan};

/// Settings of one sampling run (Goodman & Weare 2010: ensemble size and stretch scale a).
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Number of walkers: even and at least twice the dimension (emcee's requirement).
    pub walkers: usize,
    /// Total number of steps the chain should hold when [`sample`] returns (a resumed chain
    /// continues from its `steps_done` up to this total).
    pub steps: usize,
    /// Stretch scale a > 1 of the proposal density g(z) ∝ 1/√z on [1/a, a] (2.0, as emcee).
    pub stretch_a: f64,
    /// Seed of the random streams (see [`stream_seed`]).
    pub seed: u64,
}

/// The ensemble's state after some steps (emcee's chain and log-probability arrays): resumable
/// from this alone (+ [`Settings`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    /// Dimension of the parameter space.
    pub dim: usize,
    /// Number of walkers.
    pub walkers: usize,
    /// positions[step][walker][dim] flattened: step-major, len = steps_done*walkers*dim
    pub positions: Vec<f64>,
    /// ln p of every stored position, [step][walker] flattened, len = steps_done*walkers.
    pub log_prob: Vec<f64>,
    /// Accepted proposals per walker (over all steps done, resumes included).
    pub accepted: Vec<u64>,
    /// Number of steps stored.
    pub steps_done: usize,
}

impl Chain {
    /// An empty chain of `walkers` walkers in `dim` dimensions (no step done).
    pub fn empty(dim: usize, walkers: usize) -> Chain {
        Chain {
            dim,
            walkers,
            positions: Vec::new(),
            log_prob: Vec::new(),
            accepted: vec![0; walkers],
            steps_done: 0,
        }
    }

    /// The position of `walker` after step `step` (0-based): positions[step][walker][..].
    pub fn sample(&self, step: usize, walker: usize) -> &[f64] {
        let at = (step * self.walkers + walker) * self.dim;
        &self.positions[at..at + self.dim]
    }

    /// ln p of `walker` after step `step`.
    pub fn log_prob_at(&self, step: usize, walker: usize) -> f64 {
        self.log_prob[step * self.walkers + walker]
    }

    /// The samples of every walker at the steps from `burn` on (the burn-in dropped), step-major:
    /// emcee's `get_chain(discard=burn, flat=True)`.
    pub fn flat_after(&self, burn: usize) -> Vec<Vec<f64>> {
        (burn.min(self.steps_done)..self.steps_done)
            .flat_map(|s| (0..self.walkers).map(move |w| (s, w)))
            .map(|(s, w)| self.sample(s, w).to_vec())
            .collect()
    }

    /// Fraction of the proposals accepted over all walkers and steps (Foreman-Mackey et al. 2013
    /// §4: ideally 0.2–0.5); NaN before the first step.
    pub fn acceptance_fraction(&self) -> f64 {
        let total: u64 = self.accepted.iter().sum();
        total as f64 / (self.walkers * self.steps_done) as f64
    }
}

/// The seed of the generator of half `half` at step `step`: SplitMix64's output function
/// (Steele, Lea & Flood 2014) applied to the seed, then to that xor the step, then to that xor
/// the half, so every (seed, step, half) has its own well-mixed xoshiro256** stream.
pub fn stream_seed(seed: u64, step: u64, half: u64) -> u64 {
    let mix = |x: u64| SplitMix64::new(x).next_u64();
    mix(mix(mix(seed) ^ step) ^ half)
}

/// Runs (or continues) the stretch-move sampler (Goodman & Weare 2010 eq. 7–9; emcee's parallel
/// form, Foreman-Mackey et al. 2013 Algorithm 3). `start`: walkers initial points
/// (walkers x dim) used only when `resume` is None (or a chain with no step). `log_prob_batch`
/// evaluates a batch of points at once (the caller evaluates them in parallel, e.g. rayon) and
/// returns ln p (f64::NEG_INFINITY outside the support; NaN is taken as −∞, so a walker
/// started there moves to the first proposal with a finite ln p).
/// `after_step(&Chain) -> bool` is called after each full step (checkpointing, progress,
/// Ctrl-C): returning false stops early, the Chain so far is returned.
///
/// One step: the walkers are split into halves 0..W/2 and W/2..W; each walker k of a half picks
/// a walker j of the other half (uniformly, its current position X_j), draws z from
/// g(z) ∝ 1/√z on [1/a, a] (z = ((a − 1)u + 1)²/a), proposes Y = X_j + z (X_k − X_j) and accepts
/// it with probability min(1, z^(d−1) p(Y)/p(X_k)). The proposals of a half go to
/// `log_prob_batch` in ONE call (W/2 points), so one step = two batch calls; the start is
/// evaluated once (W points) when not resuming.
///
/// # Panics
/// When the walkers are odd or fewer than 2 × dim, `start` has not `walkers` points of one
/// dimension, a resumed chain's shape differs from the settings, `stretch_a` ≤ 1, or
/// `log_prob_batch` returns a batch of another length.
pub fn sample(
    settings: &Settings,
    start: &[Vec<f64>],
    resume: Option<Chain>,
    log_prob_batch: &(dyn Fn(&[Vec<f64>]) -> Vec<f64> + Sync),
    after_step: &mut dyn FnMut(&Chain) -> bool,
) -> Chain {
    let walkers = settings.walkers;
    assert!(
        settings.stretch_a > 1.0,
        "stretch scale a = {} must exceed 1",
        settings.stretch_a
    );
    let evaluate = |points: &[Vec<f64>]| {
        let lp = log_prob_batch(points);
        assert_eq!(
            lp.len(),
            points.len(),
            "log_prob_batch returned a wrong length"
        );
        lp.into_iter()
            .map(|l| if l.is_nan() { f64::NEG_INFINITY } else { l })
            .collect::<Vec<f64>>()
    };
    let (mut chain, mut current, mut current_lp) = match resume {
        Some(chain) if chain.steps_done > 0 => {
            assert_eq!(
                chain.walkers, walkers,
                "resumed chain has another walker count"
            );
            assert!(
                chain.positions.len() == chain.steps_done * walkers * chain.dim
                    && chain.log_prob.len() == chain.steps_done * walkers
                    && chain.accepted.len() == walkers,
                "resumed chain's arrays do not match its steps, walkers and dimension"
            );
            let last = chain.steps_done - 1;
            let current: Vec<Vec<f64>> = (0..walkers)
                .map(|w| chain.sample(last, w).to_vec())
                .collect();
            let lp = chain.log_prob[last * walkers..].to_vec();
            (chain, current, lp)
        }
        other => {
            assert_eq!(start.len(), walkers, "start must hold one point per walker");
            let dim = start.first().map_or(0, Vec::len);
            assert!(
                start.iter().all(|p| p.len() == dim),
                "start points differ in dimension"
            );
            let chain = match other {
                Some(c) => {
                    assert!(
                        c.walkers == walkers && c.dim == dim,
                        "resumed chain's shape"
                    );
                    c
                }
                None => Chain::empty(dim, walkers),
            };
            (chain, start.to_vec(), evaluate(start))
        }
    };
    let dim = chain.dim;
    assert!(
        walkers.is_multiple_of(2) && walkers >= 2 * dim && walkers >= 2,
        "walkers = {walkers} must be even and at least 2 x dimension ({dim})"
    );
    let a = settings.stretch_a;
    let half_n = walkers / 2;
    let remaining = settings.steps.saturating_sub(chain.steps_done);
    chain.positions.reserve(remaining * walkers * dim);
    chain.log_prob.reserve(remaining * walkers);
    while chain.steps_done < settings.steps {
        let step = chain.steps_done as u64;
        for half in 0..2usize {
            let active = half * half_n..(half + 1) * half_n;
            let other = (1 - half) * half_n;
            let mut rng = Rng::new(stream_seed(settings.seed, step, half as u64));
            let mut z = Vec::with_capacity(half_n);
            let mut ln_u = Vec::with_capacity(half_n);
            let proposals: Vec<Vec<f64>> = active
                .clone()
                .map(|k| {
                    let j = other + rng.below(half_n);
                    let zk = ((a - 1.0) * rng.uniform() + 1.0).powi(2) / a;
                    z.push(zk);
                    ln_u.push(rng.uniform().ln());
                    current[j]
                        .iter()
                        .zip(&current[k])
                        .map(|(c, x)| c + zk * (x - c))
                        .collect()
                })
                .collect();
            let lp = evaluate(&proposals);
            for (i, (k, y)) in active.zip(proposals).enumerate() {
                let ln_q = (dim as f64 - 1.0) * z[i].ln() + lp[i] - current_lp[k];
                if ln_u[i] < ln_q {
                    current[k] = y;
                    current_lp[k] = lp[i];
                    chain.accepted[k] += 1;
                }
            }
        }
        chain.positions.extend(current.iter().flatten());
        chain.log_prob.extend(&current_lp);
        chain.steps_done += 1;
        if !after_step(&chain) {
            break;
        }
    }
    chain
}

/// The normalised autocorrelation function ρ(t) = C(t)/C(0) of one series by FFT
/// (Wiener–Khinchin, zero-padded to ≥ 2n so it is the linear, not circular, one; emcee's
/// `function_1d`). A constant series has no variance: returned as ρ ≡ 1 (fully correlated).
pub fn autocorrelation(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let len = fast_fft_length(2 * n);
    let mut buf: Vec<Complex<f64>> = x
        .iter()
        .map(|v| Complex::new(v - mean, 0.0))
        .chain(std::iter::repeat(Complex::new(0.0, 0.0)))
        .take(len)
        .collect();
    fft_plan(len, false).process(&mut buf);
    for c in buf.iter_mut() {
        *c = Complex::new(c.norm_sqr(), 0.0);
    }
    fft_plan(len, true).process(&mut buf);
    let c0 = buf[0].re;
    if c0 <= 0.0 || !c0.is_finite() {
        return vec![1.0; n];
    }
    buf[..n].iter().map(|c| c.re / c0).collect()
}

/// The integrated autocorrelation time τ of each parameter from the steps after `burn`
/// (emcee's `integrated_time`, Foreman-Mackey et al. 2013 §5 and the emcee autocorrelation
/// tutorial): the average over walkers of each walker's normalised autocorrelation function
/// ρ̄(t) (by FFT), τ(M) = 1 + 2 Σ_{t=1..M} ρ̄(t), and Sokal's automatic window (Sokal 1997,
/// "Monte Carlo methods in statistical mechanics", §3; Goodman & Weare 2010 §5): the smallest M
/// with M ≥ c τ(M), c = 5 (the last lag when none). NaN with fewer than 2 steps after `burn`.
pub fn integrated_autocorr_time(chain: &Chain, burn: usize) -> Vec<f64> {
    let n = chain.steps_done.saturating_sub(burn);
    if n < 2 {
        return vec![f64::NAN; chain.dim];
    }
    (0..chain.dim)
        .map(|d| {
            let mut mean_acf = vec![0.0; n];
            for w in 0..chain.walkers {
                let series: Vec<f64> = (burn..chain.steps_done)
                    .map(|s| chain.sample(s, w)[d])
                    .collect();
                for (m, r) in mean_acf.iter_mut().zip(autocorrelation(&series)) {
                    *m += r / chain.walkers as f64;
                }
            }
            windowed_time(&mean_acf)
        })
        .collect()
}

/// τ = 2 Σ_{t=0..M} ρ(t) − 1 of a normalised autocorrelation function ρ (ρ(0) = 1) with Sokal's
/// automatic window: the first M with M ≥ c τ(M), c = 5 (the last lag when none).
pub fn windowed_time(acf: &[f64]) -> f64 {
    const C: f64 = 5.0;
    let mut tau = -1.0;
    for (m, r) in acf.iter().enumerate() {
        tau += 2.0 * r;
        if m as f64 >= C * tau {
            break;
        }
    }
    tau
}

/// The effective number of independent samples of each parameter after `burn`:
/// walkers × (steps − burn) / τ (Goodman & Weare 2010 §5; τ from [`integrated_autocorr_time`]).
pub fn effective_sample_size(chain: &Chain, burn: usize) -> Vec<f64> {
    let n = (chain.walkers * chain.steps_done.saturating_sub(burn)) as f64;
    integrated_autocorr_time(chain, burn)
        .into_iter()
        // τ below 1 (a short chain's estimate, or anticorrelated steps) would claim more
        // independent samples than were drawn: at most the samples kept.
        .map(|tau| n / tau.max(1.0))
        .collect()
}

/// The Pearson correlation matrix r_ij = Σ(x_i − x̄_i)(x_j − x̄_j) / √(Σ(x_i − x̄_i)² Σ(x_j − x̄_j)²)
/// of `samples` (each a point of the same dimension); 1 on the diagonal, NaN where a parameter
/// does not vary.
pub fn correlations(samples: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let dim = samples.first().map_or(0, Vec::len);
    let n = samples.len() as f64;
    let mean: Vec<f64> = (0..dim)
        .map(|d| samples.iter().map(|p| p[d]).sum::<f64>() / n)
        .collect();
    let mut cov = vec![vec![0.0; dim]; dim];
    for p in samples {
        for i in 0..dim {
            for j in i..dim {
                cov[i][j] += (p[i] - mean[i]) * (p[j] - mean[j]);
            }
        }
    }
    (0..dim)
        .map(|i| {
            (0..dim)
                .map(|j| {
                    let (lo, hi) = (i.min(j), i.max(j));
                    if i == j {
                        1.0
                    } else {
                        cov[lo][hi] / (cov[lo][lo] * cov[hi][hi]).sqrt()
                    }
                })
                .collect()
        })
        .collect()
}

/// The `q` quantile (0 ≤ q ≤ 1) of `values`, sorted or not, by linear interpolation between
/// order statistics (Hyndman & Fan 1996 type 7, numpy's default; [`crate::uq::percentile`]);
/// NaN for no values.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    percentile(&sorted, q)
}

/// The central 90 % band of `values`: their 5 % and 95 % quantiles ([`quantile`]).
pub fn band_90(values: &[f64]) -> [f64; 2] {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    [percentile(&sorted, 0.05), percentile(&sorted, 0.95)]
}

/// `walkers` starting points in a small Gaussian ball around the best fit (Foreman-Mackey et al.
/// 2013 §4): centre + scale ⊙ N(0, I), each redrawn until `inside` (the prior's support) holds.
/// Normal deviates by inversion, Φ⁻¹(U) ([`crate::uq::normal_quantile`]), of a xoshiro256**
/// stream seeded from `seed`.
///
/// # Panics
/// When `centre` and `scale` differ in length, or 10 000 draws in a row all fall outside.
pub fn initial_ball(
    centre: &[f64],
    scale: &[f64],
    walkers: usize,
    seed: u64,
    inside: &dyn Fn(&[f64]) -> bool,
) -> Vec<Vec<f64>> {
    const MAX_DRAWS: usize = 10_000;
    assert_eq!(
        centre.len(),
        scale.len(),
        "centre and scale differ in length"
    );
    let mut rng = Rng::new(stream_seed(seed, u64::MAX, u64::MAX));
    (0..walkers)
        .map(|w| {
            for _ in 0..MAX_DRAWS {
                let p: Vec<f64> = centre
                    .iter()
                    .zip(scale)
                    .map(|(c, s)| c + s * normal_quantile(rng.uniform()))
                    .collect();
                if inside(&p) {
                    return p;
                }
            }
            panic!(
                "walker {w}: {MAX_DRAWS} draws around the centre all fell outside the prior's support"
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(walkers: usize, steps: usize, seed: u64) -> Settings {
        Settings {
            walkers,
            steps,
            stretch_a: 2.0,
            seed,
        }
    }

    /// A batch evaluator from a pointwise ln p.
    fn batch(f: impl Fn(&[f64]) -> f64 + Sync) -> impl Fn(&[Vec<f64>]) -> Vec<f64> + Sync {
        move |pts: &[Vec<f64>]| pts.iter().map(|p| f(p)).collect()
    }

    const MEAN: [f64; 2] = [1.0, -2.0];
    const SIGMA: [f64; 2] = [1.0, 3.0];
    const RHO: f64 = 0.9;

    /// ln p of the 2-D Gaussian N(MEAN, Σ), Σ = [[σ1², ρσ1σ2], [ρσ1σ2, σ2²]], up to a constant:
    /// −(u² − 2ρuv + v²) / (2(1 − ρ²)) with u, v the standardised coordinates.
    fn gaussian_ln_p(p: &[f64]) -> f64 {
        let u = (p[0] - MEAN[0]) / SIGMA[0];
        let v = (p[1] - MEAN[1]) / SIGMA[1];
        -(u * u - 2.0 * RHO * u * v + v * v) / (2.0 * (1.0 - RHO * RHO))
    }

    #[test]
    fn mcmc_samples_a_correlated_gaussian_within_its_monte_carlo_error() {
        let (walkers, steps, burn) = (32, 3000, 300);
        let start = initial_ball(&MEAN, &[0.1, 0.1], walkers, 11, &|_| true);
        let lp = batch(gaussian_ln_p);
        let chain = sample(&settings(walkers, steps, 5), &start, None, &lp, &mut |_| {
            true
        });
        assert_eq!(chain.steps_done, steps);
        // The stretch move is affine invariant, so its acceptance on any 2-D Gaussian is that on
        // N(0, I): ≈ 0.715 (above emcee's 0.2–0.5 rule of thumb, which holds from d ≈ 5 on,
        // test `mcmc_acceptance_is_the_stretch_moves_stationary_expectation`).
        let acc = chain.acceptance_fraction();
        let expected = stationary_acceptance(2, 2.0, 200_000, 1);
        assert!(
            (acc - expected).abs() < 0.02,
            "acceptance {acc} vs {expected}"
        );
        let tau = integrated_autocorr_time(&chain, burn);
        let ess = effective_sample_size(&chain, burn);
        // The chain is long enough to trust τ (emcee's rule: > 50 τ steps).
        assert!(
            tau.iter().all(|t| 50.0 * t < (steps - burn) as f64),
            "tau {tau:?}"
        );
        let ess_min = ess.iter().cloned().fold(f64::INFINITY, f64::min);
        let flat = chain.flat_after(burn);
        let n = flat.len() as f64;
        for d in 0..2 {
            let m = flat.iter().map(|p| p[d]).sum::<f64>() / n;
            let var = flat.iter().map(|p| (p[d] - m).powi(2)).sum::<f64>() / (n - 1.0);
            // Monte Carlo standard errors from the ESS: the mean σ/√ESS; the variance of a
            // Gaussian √2 σ²/√ESS; four of each.
            let se_mean = SIGMA[d] / ess[d].sqrt();
            assert!((m - MEAN[d]).abs() < 4.0 * se_mean, "mean {d}: {m}");
            let se_var = 2f64.sqrt() * SIGMA[d].powi(2) / ess_min.sqrt();
            assert!(
                (var - SIGMA[d].powi(2)).abs() < 4.0 * se_var,
                "var {d}: {var}"
            );
        }
        // The sample correlation's standard error (1 − ρ²)/√ESS (Fisher 1915).
        let r = correlations(&flat)[0][1];
        assert!(
            (r - RHO).abs() < 4.0 * (1.0 - RHO * RHO) / ess_min.sqrt(),
            "rho {r}"
        );
        assert_eq!(correlations(&flat)[1][0], r);
    }

    /// The stretch move's acceptance probability at stationarity for an infinite ensemble on
    /// N(0, I_d) (Goodman & Weare 2010 eq. 7–9), by plain Monte Carlo over independent draws:
    /// E[min(1, z^(d−1) p(Y)/p(X))], X and the partner C ~ N(0, I), z ~ g, Y = C + z (X − C).
    fn stationary_acceptance(d: usize, a: f64, draws: usize, seed: u64) -> f64 {
        let mut rng = Rng::new(seed);
        let mut total = 0.0;
        for _ in 0..draws {
            let x: Vec<f64> = (0..d).map(|_| normal_quantile(rng.uniform())).collect();
            let c: Vec<f64> = (0..d).map(|_| normal_quantile(rng.uniform())).collect();
            let z = ((a - 1.0) * rng.uniform() + 1.0).powi(2) / a;
            let (mut yy, mut xx) = (0.0, 0.0);
            for i in 0..d {
                let y = c[i] + z * (x[i] - c[i]);
                yy += y * y;
                xx += x[i] * x[i];
            }
            total += ((d as f64 - 1.0) * z.ln() - 0.5 * (yy - xx)).min(0.0).exp();
        }
        total / draws as f64
    }

    #[test]
    fn mcmc_acceptance_is_the_stretch_moves_stationary_expectation() {
        // 5-D standard Gaussian started in its own law (a ball of scale 1 around 0): the measured
        // acceptance is the stationary expectation (≈ 0.55, emcee's quickstart value for 5-D),
        // within emcee's recommended 0.2–0.5(0.6) band. Tolerance 0.02: the expectation's Monte
        // Carlo error is ≈ 0.001 and the chain's ≈ 0.005 (16 000 decisions, correlated).
        let d = 5;
        let lp = batch(|p: &[f64]| -0.5 * p.iter().map(|x| x * x).sum::<f64>());
        let start = initial_ball(&[0.0; 5], &[1.0; 5], 16, 2, &|_| true);
        let chain = sample(&settings(16, 1000, 3), &start, None, &lp, &mut |_| true);
        let acc = chain.acceptance_fraction();
        let expected = stationary_acceptance(d, 2.0, 200_000, 4);
        assert!((0.2..0.6).contains(&acc), "acceptance {acc}");
        assert!(
            (acc - expected).abs() < 0.02,
            "acceptance {acc} vs {expected}"
        );
    }

    #[test]
    fn mcmc_never_leaves_a_uniform_box() {
        let (lo, hi) = ([0.0, 2.0], [1.0, 5.0]);
        let inside = |p: &[f64]| (0..2).all(|d| p[d] > lo[d] && p[d] < hi[d]);
        let lp = batch(|p| if inside(p) { 0.0 } else { f64::NEG_INFINITY });
        let start = initial_ball(&[0.98, 4.9], &[0.1, 0.3], 8, 3, &inside);
        assert!(start.iter().all(|p| inside(p)));
        let chain = sample(&settings(8, 2000, 9), &start, None, &lp, &mut |_| true);
        let flat = chain.flat_after(0);
        assert!(flat.iter().all(|p| inside(p)));
        assert!(chain.log_prob.iter().all(|&l| l == 0.0));
        // It does explore the box: the samples reach both ends of each side.
        for d in 0..2 {
            let v: Vec<f64> = flat.iter().map(|p| p[d]).collect();
            let w = hi[d] - lo[d];
            assert!(band_90(&v)[0] < lo[d] + 0.2 * w && band_90(&v)[1] > hi[d] - 0.2 * w);
        }
    }

    #[test]
    fn mcmc_takes_nan_as_outside_and_brings_a_stray_walker_in() {
        // ln p: 0 on (0, 1)², NaN left of it, −∞ elsewhere. One walker starts in the NaN
        // region: it is moved by the first proposal that lands inside, and stays inside.
        let lp = batch(|p: &[f64]| {
            if p[0] < 0.0 {
                f64::NAN
            } else if p[0] < 1.0 && p[1] > 0.0 && p[1] < 1.0 {
                0.0
            } else {
                f64::NEG_INFINITY
            }
        });
        let mut start = initial_ball(&[0.5, 0.5], &[0.1, 0.1], 8, 5, &|_| true);
        start[0] = vec![-0.5, 0.5];
        let chain = sample(&settings(8, 300, 2), &start, None, &lp, &mut |_| true);
        assert!(chain.log_prob.iter().all(|l| !l.is_nan()));
        let moved = (0..chain.steps_done).find(|&s| chain.log_prob_at(s, 0) == 0.0);
        let moved = moved.expect("the stray walker came in");
        assert!((moved..chain.steps_done).all(|s| chain.log_prob_at(s, 0) == 0.0));
        assert!((moved..chain.steps_done).all(|s| chain.sample(s, 0)[0] > 0.0));
    }

    #[test]
    fn mcmc_autocorrelation_time_of_ar1_series_is_one_plus_phi_over_one_minus_phi() {
        // x_{t+1} = φ x_t + ε, ε ~ N(0, 1), started in its stationary law N(0, 1/(1 − φ²)):
        // ρ(t) = φ^t, so τ = 1 + 2 Σ φ^t = (1 + φ)/(1 − φ) = 19 at φ = 0.9. The estimator's
        // relative standard error is about √(2(2M + 1)/N) (Sokal 1997 eq. 3.19, M ≈ 5τ the window,
        // N the samples over all walkers), here ≈ 4 %: 15 % is beyond 3.5 of them.
        let (phi, walkers, steps): (f64, usize, usize) = (0.9, 32, 8000);
        let mut rng = Rng::new(2024);
        let mut normal = || normal_quantile(rng.uniform());
        let mut series = vec![vec![0.0; steps]; walkers];
        for s in series.iter_mut() {
            s[0] = normal() / (1.0 - phi * phi).sqrt();
            for t in 1..steps {
                s[t] = phi * s[t - 1] + normal();
            }
        }
        let mut chain = Chain::empty(1, walkers);
        for t in 0..steps {
            chain.positions.extend(series.iter().map(|s| s[t]));
            chain.log_prob.extend(std::iter::repeat_n(0.0, walkers));
        }
        chain.steps_done = steps;
        let exact = (1.0 + phi) / (1.0 - phi);
        let tau = integrated_autocorr_time(&chain, 0)[0];
        assert!((tau / exact - 1.0).abs() < 0.15, "tau {tau} vs {exact}");
        let ess = effective_sample_size(&chain, 0)[0];
        assert!((ess - (walkers * steps) as f64 / tau).abs() < 1e-9 * ess);
    }

    #[test]
    fn mcmc_resumes_bit_for_bit_and_stops_when_asked() {
        let lp = batch(gaussian_ln_p);
        let start = initial_ball(&MEAN, &[0.5, 0.5], 8, 1, &|_| true);
        let full = sample(&settings(8, 200, 77), &start, None, &lp, &mut |_| true);
        let half = sample(&settings(8, 100, 77), &start, None, &lp, &mut |_| true);
        assert_eq!(half.steps_done, 100);
        // The start is not needed to resume (an empty one is given).
        let resumed = sample(&settings(8, 200, 77), &[], Some(half), &lp, &mut |_| true);
        assert_eq!(resumed, full);
        // Another seed gives another chain.
        let other = sample(&settings(8, 200, 78), &start, None, &lp, &mut |_| true);
        assert_ne!(other.positions, full.positions);
        // after_step is called once per step, with the chain so far; false stops there.
        let mut seen = Vec::new();
        let stopped = sample(&settings(8, 200, 77), &start, None, &lp, &mut |c| {
            seen.push(c.steps_done);
            c.steps_done < 3
        });
        assert_eq!(seen, [1, 2, 3]);
        assert_eq!(stopped.steps_done, 3);
        assert_eq!(stopped.positions, full.positions[..3 * 8 * 2]);
        assert_eq!(stopped.log_prob.len(), 3 * 8);
    }

    #[test]
    fn mcmc_batches_each_half_in_one_call() {
        let calls = std::sync::Mutex::new(Vec::new());
        let lp = |pts: &[Vec<f64>]| {
            calls.lock().unwrap().push(pts.len());
            pts.iter().map(|p| gaussian_ln_p(p)).collect()
        };
        let start = initial_ball(&MEAN, &[0.5, 0.5], 12, 1, &|_| true);
        sample(&settings(12, 4, 1), &start, None, &lp, &mut |_| true);
        assert_eq!(*calls.lock().unwrap(), [12, 6, 6, 6, 6, 6, 6, 6, 6]);
    }

    #[test]
    fn mcmc_is_affine_invariant() {
        // Goodman & Weare's point: the stretch move commutes with x ↦ A x + b, so sampling the
        // Gaussian stretched by ≈ 1e9 along one axis makes the same accept decisions with the
        // same seed (the positions scaled), however ill-conditioned. The factor is 2^30
        // (1.07e9): a power of two scales floating-point numbers exactly, so the two runs agree
        // bit for bit; with 1e9 itself the last-bit rounding differences grow along the
        // ensemble's dynamics and, after some hundred steps, flip a decision.
        const S: f64 = (1u64 << 30) as f64;
        let scaled = |p: &[f64]| gaussian_ln_p(&[p[0] / S, p[1]]);
        let start = initial_ball(&MEAN, &[0.5, 0.5], 16, 4, &|_| true);
        let start_scaled: Vec<Vec<f64>> = start.iter().map(|p| vec![p[0] * S, p[1]]).collect();
        let a = sample(
            &settings(16, 500, 8),
            &start,
            None,
            &batch(gaussian_ln_p),
            &mut |_| true,
        );
        let b = sample(
            &settings(16, 500, 8),
            &start_scaled,
            None,
            &batch(scaled),
            &mut |_| true,
        );
        assert_eq!(a.accepted, b.accepted);
        assert_eq!(a.acceptance_fraction(), b.acceptance_fraction());
        for (x, y) in a.positions.chunks(2).zip(b.positions.chunks(2)) {
            assert_eq!([x[0] * S, x[1]], [y[0], y[1]]);
        }
    }

    #[test]
    fn mcmc_quantile_is_numpys_linear_interpolation() {
        // numpy.quantile([10, 1, 4, 2, 3], q): sorted 1 2 3 4 10, h = 4q,
        // x[⌊h⌋] + (h − ⌊h⌋)(x[⌊h⌋+1] − x[⌊h⌋]).
        let v = [10.0, 1.0, 4.0, 2.0, 3.0];
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 10.0);
        assert_eq!(quantile(&v, 0.5), 3.0);
        assert!((quantile(&v, 0.3) - 2.2).abs() < 1e-12); // h = 1.2: 2 + 0.2·1
        assert!((quantile(&v, 0.95) - 8.8).abs() < 1e-12); // h = 3.8: 4 + 0.8·6
        let b = band_90(&v);
        assert!((b[0] - 1.2).abs() < 1e-12 && (b[1] - 8.8).abs() < 1e-12); // h = 0.2, 3.8
        assert!((quantile(&[1.0, 2.0, 3.0, 4.0], 0.25) - 1.75).abs() < 1e-12); // h = 0.75
        assert!(quantile(&[], 0.5).is_nan());
    }

    #[test]
    fn mcmc_initial_ball_respects_the_support_and_the_seed() {
        let inside = |p: &[f64]| p[0] >= 0.0;
        let a = initial_ball(&[0.0, 5.0], &[1.0, 2.0], 20, 6, &inside);
        assert_eq!(a.len(), 20);
        assert!(a.iter().all(|p| p[0] >= 0.0));
        assert_eq!(a, initial_ball(&[0.0, 5.0], &[1.0, 2.0], 20, 6, &inside));
        assert_ne!(a, initial_ball(&[0.0, 5.0], &[1.0, 2.0], 20, 7, &inside));
    }
}
