//! Geometric dispersion carried by the travelling waves of a delay-line bar (docs/physics.md
//! §6.2.1): the transit filter that turns a wave injected at one end into the wave that has
//! travelled d cells along a uniform bar, for the Rayleigh–Love rod or the exact first
//! Pochhammer–Chree mode.
//!
//! A bar of cells Δx at Courant 1 (Δx = c0 Δt) carries each travelling wave a whole cell a step:
//! the delay line is exact for the elementary theory, where every frequency travels at c0. With
//! a phase velocity c(ω) < c0 a component of angular frequency ω takes d Δx/c(ω) to cross d
//! cells, i.e. d steps plus a residual lag of `d φ(Ω)/Ω` steps, with Ω = ωΔt and the residual
//! phase per cell
//!
//! ```text
//! φ(Ω) = Ω (c0/c(Ω) − 1)  ≥ 0.
//! ```
//!
//! The transit filter over d cells is the all-pass response `H_d(Ω) = exp(−i d φ(Ω))` (the whole
//! delay is d steps of the delay line plus H_d). A wave is born at its end node half a step after
//! the step that injects it, so element e (counted from that end, from 0) holds it after e + ½
//! cells and the far end node of a bar of N cells receives it after N: those are the distances
//! its filters carry (only the element it is injected into reads it undispersed). Each impulse
//! response is computed once per distance on an FFT grid, shifted by `lead` samples so that its
//! small acausal precursor (the first mode alone is not exactly causal) sits at non-negative
//! indices, and truncated where the energy left out on either side is below [`TAIL_ENERGY`] of
//! the whole; the taps are then scaled so that they sum to one (a static strain passes
//! unchanged).
//!
//! Rayleigh–Love: `ω = c0 k/√(1 + βk²)`, β = ν²a²/2 (docs/physics.md §6.3), so
//! `kΔx = Ω/√(1 − βΩ²/Δx²)` and `φ = kΔx − Ω` below the cut-off `Ω_c = Δx/√β`; above it the
//! wave is evanescent and decays by `|k|Δx` nepers a cell. Pochhammer–Chree: c/c0 of the first
//! mode at f a/c0 = Ω a/(2π Δx) ([`crate::dispersion`]), tabulated once per Poisson ratio and
//! process and interpolated (8-point Lagrange; within 1e-10 of the root, unit test).

use crate::dispersion::{ModeTable, mode_table};
use crate::numeric::fft_plan;
use rustfft::num_complex::Complex64;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

/// Largest share of a transit filter's impulse-response energy left out by truncation, on
/// either side (module docs): 1e-16 of the energy is 1e-8 of the amplitude, below the
/// discretisation error of a `standard` run (3e-7 in peak force).
pub const TAIL_ENERGY: f64 = 1e-16;

/// The dispersion relation the travelling waves of a delay line follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TransitModel {
    /// Rayleigh–Love rod, c/c0 = 1/√(1 + ν²k²a²/2) (docs/physics.md §6.3).
    RayleighLove,
    /// The exact first longitudinal mode of a solid cylinder (docs/physics.md §7.9).
    PochhammerChree,
}

/// The residual phase per cell of one bar on an FFT grid, and the band it passes (module docs).
#[derive(Debug)]
pub struct TransitDesign {
    model: TransitModel,
    poisson_ratio: f64,
    /// a/Δx.
    radius_cells: f64,
    table: Option<Arc<ModeTable>>,
    n_fft: usize,
    /// φ per cell, bins 0..=n/2, rad.
    phase: Vec<f64>,
    /// Weight of each bin in one transit: 1 in the pass band, a smooth step to 0 across the
    /// taper (module docs, "Band").
    gain: Vec<f64>,
    /// Filters designed so far, by half cells ([`TransitDesign::shared_filter`]).
    filters: Mutex<HashMap<usize, Arc<SharedFilter>>>,
    /// The per-bin factors of [`TransitDesign::stretch_history`] by transform length.
    bin_tables: Mutex<HashMap<usize, Arc<BinTables>>>,
}

/// The factors of [`TransitDesign::stretch_history`] that depend only on its design and its
/// transform length n, made once per process (a sweep's or a notebook's runs share them).
#[derive(Debug)]
struct BinTables {
    /// z = e^{−i(Ω + φ)}, one cell's phase factor, bins 0..=n/2.
    z: Vec<Complex64>,
    /// The band's weight times the half cell's dispersion, g e^{−iφ/2}, bins 0..=n/2.
    carry: Vec<Complex64>,
    /// e^{2πij/n}, j = 0..n: the phase turns of the sampled times; the one-step delay e^{−iΩ}
    /// of bin k is the conjugate of the k-th.
    roots: Vec<Complex64>,
}

/// A transit filter kept by its design, with its taps also oldest first (for a dot product with
/// a history slice) and its largest power gain worked out once.
#[derive(Debug)]
pub struct SharedFilter {
    /// The filter.
    pub filter: TransitFilter,
    /// `filter.taps` reversed.
    oldest_first: Vec<f64>,
    power_gain: OnceLock<f64>,
}

impl SharedFilter {
    /// Σ_j h_j s[newest − j + lead] over the history `s` (index of the pure-delay sample
    /// `newest`; the lead never reaches past the last sample injected).
    #[inline]
    pub fn apply(&self, s: &[f64], newest: usize) -> f64 {
        let lead = self.filter.lead;
        let lo = newest + lead + 1 - self.oldest_first.len();
        dot(&self.oldest_first, &s[lo..=newest + lead])
    }

    /// The first `m` taps alone: Σ_{j<m} h_j s[newest − j + lead] (the head of a filter whose
    /// other taps a [`BlockConvolver`] applies).
    #[inline]
    pub fn apply_head(&self, s: &[f64], newest: usize, m: usize) -> f64 {
        let last = newest + self.filter.lead;
        dot(
            &self.oldest_first[self.oldest_first.len() - m..],
            &s[last + 1 - m..=last],
        )
    }

    /// max |H|² of the filter as truncated ([`max_power_gain`]).
    pub fn max_power_gain(&self) -> f64 {
        *self
            .power_gain
            .get_or_init(|| max_power_gain(&self.filter.taps))
    }
}

/// Most designs kept by [`shared_design`] (a guard for sweeps over many grids: the cache starts
/// afresh when full).
const SHARED_DESIGNS: usize = 64;

/// The design of [`TransitDesign::new`], shared by every bar of the same model, Poisson's ratio,
/// a/Δx and FFT length in the process (the input's checks and the run build the same bars, a
/// sweep builds them again for every point): identical to a fresh one, filters included.
pub fn shared_design(
    model: TransitModel,
    poisson_ratio: f64,
    radius_m: f64,
    cell_m: f64,
    max_cells: usize,
) -> Arc<TransitDesign> {
    type Key = (TransitModel, u64, u64, usize);
    static DESIGNS: OnceLock<Mutex<HashMap<Key, Arc<TransitDesign>>>> = OnceLock::new();
    let key = (
        model,
        poisson_ratio.to_bits(),
        (radius_m / cell_m).to_bits(),
        TransitDesign::fft_length(model, poisson_ratio, radius_m, cell_m, max_cells),
    );
    let designs = DESIGNS.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(d) = designs.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Arc::clone(d);
    }
    let design = Arc::new(TransitDesign::new(
        model,
        poisson_ratio,
        radius_m,
        cell_m,
        max_cells,
    ));
    let mut designs = designs.lock().unwrap_or_else(|e| e.into_inner());
    if designs.len() >= SHARED_DESIGNS {
        designs.clear();
    }
    designs.insert(key, Arc::clone(&design));
    design
}

/// The impulse response of the transit over some cells: `taps[j]` weighs the wave injected
/// `j − lead` steps before the pure delay would deliver it (`lead` < the cells: module docs,
/// "Causality").
#[derive(Debug, Clone, PartialEq)]
pub struct TransitFilter {
    /// Samples of precursor ahead of the pure delay.
    pub lead: usize,
    /// Impulse response, summing to one.
    pub taps: Vec<f64>,
}

/// Smooth (C∞) step weight: 1 up to `a`, 0 from `b`, `S(x) = e^{−1/x}/(e^{−1/x} + e^{−1/(1−x)})`
/// of x = (b − w)/(b − a) between, so the impulse response has no algebraic tail.
pub(crate) fn taper(w: f64, a: f64, b: f64) -> f64 {
    if w <= a {
        1.0
    } else if w >= b {
        0.0
    } else {
        let x = (b - w) / (b - a);
        let (p, q) = ((-1.0 / x).exp(), (-1.0 / (1.0 - x)).exp());
        p / (p + q)
    }
}

impl TransitDesign {
    /// The design for a bar of Poisson's ratio `poisson_ratio`, radius `radius_m` and cells
    /// `cell_m` (= c0 Δt) whose filters reach up to `max_cells` cells ([`shared_design`] keeps
    /// one per process).
    pub fn new(
        model: TransitModel,
        poisson_ratio: f64,
        radius_m: f64,
        cell_m: f64,
        max_cells: usize,
    ) -> TransitDesign {
        let mut design = TransitDesign::relation(model, poisson_ratio, radius_m, cell_m);
        design.n_fft = TransitDesign::fft_length(model, poisson_ratio, radius_m, cell_m, max_cells);
        (design.phase, design.gain) = (0..=design.n_fft / 2)
            .map(|k| design.phase_and_gain(2.0 * PI * k as f64 / design.n_fft as f64))
            .unzip();
        design
    }

    /// The relation alone (for [`TransitDesign::phase_and_gain`]): no FFT grid, no filters.
    pub fn relation(
        model: TransitModel,
        poisson_ratio: f64,
        radius_m: f64,
        cell_m: f64,
    ) -> TransitDesign {
        TransitDesign {
            model,
            poisson_ratio,
            radius_cells: radius_m / cell_m,
            table: (model == TransitModel::PochhammerChree).then(|| mode_table(poisson_ratio)),
            n_fft: 0,
            phase: Vec::new(),
            gain: Vec::new(),
            filters: Mutex::new(HashMap::new()),
            bin_tables: Mutex::new(HashMap::new()),
        }
    }

    /// FFT length of the design's grid for filters up to `max_cells` cells.
    fn fft_length(
        model: TransitModel,
        poisson_ratio: f64,
        radius_m: f64,
        cell_m: f64,
        max_cells: usize,
    ) -> usize {
        // The slowest group velocity passed is 0.38 c0 (Pochhammer–Chree, ν ≤ 0.5) or 0.29 c0
        // (Rayleigh–Love at the end of its taper): at most 2.5 steps a cell beyond the delay.
        // The band's smooth step of width w (rad) adds tails on both sides that fall as
        // exp(−2√(w t)): below 1e-8 of the amplitude after about 100/w samples.
        let width = match model {
            TransitModel::PochhammerChree => 0.5 * PI,
            TransitModel::RayleighLove => {
                0.25 * (2.0f64.sqrt() * cell_m / (poisson_ratio * radius_m)).min(2.0 * PI)
            }
        };
        // Twice that, for the tails the 1e-16 cut still reaches (the tabulated mode's
        // interpolation leaves its phase C⁰ at the nodes: algebraic tails near 1e-8).
        let span = (2.0 * (5.0 * max_cells as f64 + 400.0 / width)) as usize + 4096;
        span.next_power_of_two().max(1024)
    }

    /// Residual phase per cell φ(Ω) (rad) and the band's weight at Ω = ωΔt ∈ [0, π] (module docs).
    pub fn phase_and_gain(&self, w: f64) -> (f64, f64) {
        match self.model {
            TransitModel::RayleighLove => {
                let beta = 0.5 * (self.poisson_ratio * self.radius_cells).powi(2);
                let cutoff = 1.0 / beta.sqrt();
                let (a, b) = ((0.5 * cutoff).min(0.5 * PI), (0.75 * cutoff).min(PI));
                let s = 1.0 - beta * w * w;
                if w < b && s > 0.0 {
                    (w / s.sqrt() - w, taper(w, a, b))
                } else {
                    (0.0, 0.0)
                }
            }
            TransitModel::PochhammerChree => {
                let y = w * self.radius_cells / (2.0 * PI);
                let ratio = self.table.as_ref().map_or(1.0, |t| t.ratio(y));
                (w * (1.0 / ratio - 1.0), taper(w, 0.5 * PI, PI))
            }
        }
    }

    /// The model.
    pub fn model(&self) -> TransitModel {
        self.model
    }

    /// The response exp(−i d φ) times the band's weight over `cells` cells at bin k of the
    /// design's grid (Ω = 2πk/n).
    fn response(&self, k: usize, cells: f64) -> Complex64 {
        Complex64::from_polar(self.gain[k], -cells * self.phase[k])
    }

    /// The transit filter over `half_cells`/2 cells (module docs): a wave read at an element's
    /// centre has crossed a whole number of cells and a half, one read at the far end node a
    /// whole number.
    pub fn filter(&self, half_cells: usize) -> TransitFilter {
        if half_cells == 0 {
            return TransitFilter {
                lead: 0,
                taps: vec![1.0],
            };
        }
        let n = self.n_fft;
        let d = 0.5 * half_cells as f64;
        let mut spectrum: Vec<Complex64> = vec![Complex64::new(0.0, 0.0); n];
        for k in 0..=n / 2 {
            let h = self.response(k, d);
            spectrum[k] = h;
            if k > 0 && k < n / 2 {
                spectrum[n - k] = h.conj();
            }
        }
        fft_plan(n, true).process(&mut spectrum);
        let h: Vec<f64> = spectrum.iter().map(|c| c.re / n as f64).collect();
        let total: f64 = h.iter().map(|x| x * x).sum();
        let cut = TAIL_ENERGY * total;
        // Causal part: indices 0..n/2; precursor: n − 1, n − 2, … (negative times).
        let mut tail = 0.0;
        let mut len = n / 2;
        while len > 1 && tail + h[len - 1] * h[len - 1] <= cut {
            tail += h[len - 1] * h[len - 1];
            len -= 1;
        }
        let mut ahead = 0.0;
        let mut lead = n / 2 - 1;
        while lead > 0 && ahead + h[n - lead] * h[n - lead] <= cut {
            ahead += h[n - lead] * h[n - lead];
            lead -= 1;
        }
        // Causality: a wave read d cells from where it entered was injected ⌈d⌉ steps before
        // the pure delay delivers it (born half a step after its injection step), so at most
        // ⌈d⌉ − 1 samples of precursor can be known.
        let lead = lead.min(half_cells.div_ceil(2) - 1);
        let mut taps: Vec<f64> = (1..=lead).rev().map(|t| h[n - t]).collect();
        taps.extend_from_slice(&h[..len]);
        let sum: f64 = taps.iter().sum();
        if sum != 0.0 && sum.is_finite() {
            for t in &mut taps {
                *t /= sum;
            }
        }
        TransitFilter { lead, taps }
    }

    /// [`TransitDesign::filter`] over `half_cells`/2 cells, designed once per design.
    pub fn shared_filter(&self, half_cells: usize) -> Arc<SharedFilter> {
        if let Some(f) = self
            .filters
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&half_cells)
        {
            return Arc::clone(f);
        }
        let filter = self.filter(half_cells);
        let f = Arc::new(SharedFilter {
            oldest_first: filter.taps.iter().rev().copied().collect(),
            filter,
            power_gain: OnceLock::new(),
        });
        self.filters
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(half_cells, Arc::clone(&f));
        f
    }
}

/// One point of [`TransitDesign::stretch_history`]: Σ weight × stretch of element, over its
/// terms (elements in increasing order).
pub type StretchPoint = Vec<(usize, f64)>;

/// The times asked of [`TransitDesign::stretch_history`] as `first + stride·q`, q = 0, 1, …, if
/// they are such a progression with `stride` > 1.
fn progression(times: &[usize]) -> Option<(usize, usize)> {
    let (&first, &second) = (times.first()?, times.get(1)?);
    let stride = second.checked_sub(first).filter(|&s| s > 1)?;
    times
        .windows(2)
        .all(|w| w[1] == w[0] + stride)
        .then_some((first, stride))
}

impl TransitDesign {
    /// The per-bin factors of [`TransitDesign::stretch_history`] for transform length `n`, made
    /// on first use and kept by the design.
    fn bin_tables(&self, n: usize) -> Arc<BinTables> {
        let mut cache = self.bin_tables.lock().unwrap_or_else(|e| e.into_inner());
        Arc::clone(cache.entry(n).or_insert_with(|| {
            let (mut z, mut carry) = (Vec::new(), Vec::new());
            for k in 0..=n / 2 {
                let w = 2.0 * PI * k as f64 / n as f64;
                let (phi, g) = self.phase_and_gain(w);
                z.push(Complex64::from_polar(1.0, -(w + phi)));
                carry.push(Complex64::from_polar(g, -0.5 * phi));
            }
            let roots = (0..n)
                .map(|j| Complex64::from_polar(1.0, 2.0 * PI * j as f64 / n as f64))
                .collect();
            Arc::new(BinTables { z, carry, roots })
        }))
    }

    /// Stretches of a dispersive delay line of `elements` elements at `points`, at the history
    /// indices `times`, from its whole histories (module docs, "After the run"): `right[i]` and
    /// `left[i]` are the increments injected at index i (i from the start of the histories,
    /// whose first value stands for all earlier ones). The element fields are
    /// `R_e(t) = (h_{e+½} ⊛ right)(t − e − 1)` and `L_e(t) = (h_{N−e−½} ⊛ left)(t − N + e)`, with
    /// the exact responses h_d (not truncated, precursor included) and the first cell of each
    /// wave undispersed, as the delay line reads them step by step. Returns one row per point.
    ///
    /// One FFT of each history, then per point its spectrum (z^e by recurrence from the previous
    /// point, |z| = 1) and one inverse FFT; when the times are a progression of stride K (x–t
    /// snapshots), the spectrum is folded K times first (sampling every K-th value), so the
    /// inverse FFT is K times shorter.
    pub fn stretch_history(
        &self,
        right: &[f64],
        left: &[f64],
        elements: usize,
        points: &[StretchPoint],
        times: &[usize],
    ) -> Vec<Vec<f64>> {
        let (Some(&a0), Some(&b0), Some(&last_time)) =
            (right.first(), left.first(), times.iter().max())
        else {
            return vec![vec![0.0; times.len()]; points.len()];
        };
        // The histories before the first value that differs from the constant past add
        // nothing; start there (less a transit's precursor) to keep the transform short.
        let changed = |s: &[f64], base: f64| s.iter().position(|&x| x != base).unwrap_or(s.len());
        let start = changed(right, a0)
            .min(changed(left, b0))
            .saturating_sub(2 * elements)
            .min(times.iter().copied().min().unwrap_or(0));
        let span = last_time.max(right.len()) - start;
        // Zero padding beyond the longest transit — a whole bar of pure delay plus the group
        // delay beyond c0 (1.6 steps a cell at most for Pochhammer–Chree, 2.5 for the
        // Rayleigh–Love band) — and the band's tails and the precursor (1024 steps; their
        // amplitude there is below 1e-10) keeps the circular convolution linear over the times
        // asked for: the last injections' responses do not wrap onto them. (Until 2026-11-24 the
        // pure delay was left out and a power-of-two length made up for it by chance: within
        // 2.4e-11 of a 40 000-step padding on the SS440c `reference` run, 6e-7 without it.)
        let tail = match self.model {
            TransitModel::PochhammerChree => 1.7,
            TransitModel::RayleighLove => 2.6,
        };
        let need = span + ((1.0 + tail) * elements as f64) as usize + 1024;
        let fold = progression(times).map_or(1, |(_, k)| k);
        // An even length of small prime factors (bins 0 and n/2 are the real ones below).
        let n = fold * 2 * crate::numeric::fast_fft_length(need.div_ceil(fold).div_ceil(2));
        let forward = fft_plan(n, false);
        let spectrum = |s: &[f64], base: f64| {
            let mut v: Vec<Complex64> = vec![Complex64::new(0.0, 0.0); n];
            for (c, &x) in v.iter_mut().zip(&s[start.min(s.len())..]) {
                c.re = x - base;
            }
            forward.process(&mut v);
            v
        };
        let (fa, fb) = (spectrum(right, a0), spectrum(left, b0));
        let half = n / 2;
        let last = elements - 1;
        // Per bin k = 0..=n/2: z = e^{−i(Ω + φ)} (one cell), the band's weight times the
        // dispersion of the half cell between an element's centre and its end of the bar, and
        // the history spectra times the one-step delay (the left one carried over the whole
        // bar, z^{N−1}).
        let tables = self.bin_tables(n);
        let (z, carry) = (tables.z.as_slice(), tables.carry.as_slice());
        let delay = |k: usize| tables.roots[k].conj();
        let u: Vec<Complex64> = (0..=half).map(|k| fa[k] * delay(k)).collect();
        let v: Vec<Complex64> = (0..=half)
            .map(|k| fb[k] * delay(k) * z[k].powu(last as u32))
            .collect();
        // Times relative to the transform's start; sampled every `fold` from `offset`.
        let local: Vec<usize> = times.iter().map(|&t| t - start).collect();
        let (offset, m) = (local[0] % fold, n / fold);
        let inverse = fft_plan(m, true);
        // One scratch for every point's inverse transform (`process` would allocate it each time).
        let mut scratch = vec![Complex64::new(0.0, 0.0); inverse.get_inplace_scratch_len()];
        // y(offset + fold·q) = (1/n) Σ_k Y_k e^{2πik·offset/n} e^{2πikq/m}, over each k ≤ n/2
        // and its mirror n − k (Y_{n−k} = conj Y_k): the two phase turns and folded slots.
        let turn = |k: usize| tables.roots[(k * offset) % n];
        let turns: Vec<(Complex64, Complex64)> =
            (0..=half).map(|k| (turn(k), turn(n - k))).collect();
        // The usual point inside the bar, in separate real arrays ([`InteriorBins`]).
        let interior = InteriorBins::new(&u, &v, carry, &turns, z, half);
        let mut pw: Vec<Complex64> = vec![Complex64::new(1.0, 0.0); half + 1];
        let mut pw_element = 0usize;
        let mut z_stride: (usize, Vec<Complex64>) = (0, Vec::new());
        let mut sums = FoldSums::new(m);
        // A point's folded spectrum (a real series', Hermitian) into `folded`; returns the
        // constant the histories' first values add, or None for a point with no terms.
        let mut fold_point = |p: &StretchPoint, folded: &mut [Complex64]| -> Option<f64> {
            let &(first, _) = p.first()?;
            let e0 = first.min(last);
            let ends = p.iter().any(|&(e, _)| e == 0 || e >= last);
            // The usual point inside the bar: one element, or two neighbours.
            let pair = match p.as_slice() {
                [(_, w0)] if !ends => Some((*w0, 0.0)),
                [(e0, w0), (e1, w1)] if !ends && *e1 == e0 + 1 => Some((*w0, *w1)),
                _ => None,
            };
            // z^Δ for this stride, kept while points come at the same spacing.
            let stride = e0.checked_sub(pw_element).filter(|&s| s > 0);
            if let Some(stride) = stride
                && stride != z_stride.0
            {
                z_stride = (stride, z.iter().map(|c| c.powu(stride as u32)).collect());
            }
            if e0 < pw_element {
                for (c, zk) in pw.iter_mut().zip(z) {
                    *c = zk.powu(e0 as u32);
                }
            }
            pw_element = e0;
            if let Some((w0, w1)) = pair {
                // Bins 1..half in one pass (advancing z^e by the stride on the way), then DC
                // and Nyquist.
                let step = stride.map(|_| z_stride.1.as_slice());
                sums.interior(&interior, &mut pw, step, (w0, w1), m);
                sums.write_to(folded);
                for k in [0, half] {
                    let h_r = pw[k] * Complex64::new(w0 + w1 * z[k].re, w1 * z[k].im);
                    let value = (u[k] * h_r + v[k] * h_r.conj()) * carry[k];
                    folded[k % m] += Complex64::new(value.re, 0.0) * turns[k].0;
                }
                hermitian_completion(folded);
                return Some((a0 + b0) * (w0 + w1));
            }
            folded.fill(Complex64::new(0.0, 0.0));
            if stride.is_some() {
                for (c, zk) in pw.iter_mut().zip(&z_stride.1) {
                    *c *= zk;
                }
            }
            for k in 0..=half {
                let g = carry[k];
                // The right- and left-going sums h_r and h_l (each term's wave undispersed
                // over its first cell).
                let (mut zr, mut h_r) = (pw[k], Complex64::new(0.0, 0.0));
                let mut h_l = h_r;
                let mut at = e0;
                for &(e, weight) in p {
                    let e = e.min(last);
                    while at < e {
                        zr *= z[k];
                        at += 1;
                    }
                    // R_e: dispersion over e + ½ cells (none for e = 0); L_e: over
                    // N − e − ½ (none for e = N − 1): z^{N−1−e} = z^{N−1} conj(z^e), the
                    // half cell in g.
                    let one = Complex64::new(1.0, 0.0);
                    let gr = if e == 0 { one } else { g };
                    let gl = if e == last { one } else { g };
                    h_r += zr * gr * weight;
                    h_l += zr.conj() * gl * weight;
                }
                let value = u[k] * h_r + v[k] * h_l;
                let (t_k, t_mirror) = turns[k];
                if k == 0 || 2 * k == n {
                    folded[k % m] += Complex64::new(value.re, 0.0) * t_k;
                } else {
                    folded[k % m] += value * t_k;
                    folded[(n - k) % m] += value.conj() * t_mirror;
                }
            }
            Some((a0 + b0) * p.iter().map(|&(_, w)| w).sum::<f64>())
        };
        // The points' series are real, so two go through one inverse transform: the spectrum
        // of the first plus i times that of the second gives the first as the real part and the
        // second as the imaginary part.
        let read = |y: &[Complex64], part: fn(&Complex64) -> f64, dc: f64| -> Vec<f64> {
            local
                .iter()
                .map(|&t| part(&y[(t - offset) / fold]) / n as f64 + dc)
                .collect()
        };
        let mut rows: Vec<Vec<f64>> = vec![Vec::new(); points.len()];
        let mut held: Option<(usize, f64)> = None;
        let mut spare = vec![Complex64::new(0.0, 0.0); m];
        let mut folded = vec![Complex64::new(0.0, 0.0); m];
        for (j, p) in points.iter().enumerate() {
            let Some(dc) = fold_point(p, &mut folded) else {
                rows[j] = vec![0.0; times.len()];
                continue;
            };
            match held.take() {
                None => {
                    std::mem::swap(&mut spare, &mut folded);
                    held = Some((j, dc));
                }
                Some((i, dc_i)) => {
                    for (a, b) in spare.iter_mut().zip(&folded) {
                        *a += Complex64::new(-b.im, b.re);
                    }
                    inverse.process_with_scratch(&mut spare, &mut scratch);
                    rows[i] = read(&spare, |c| c.re, dc_i);
                    rows[j] = read(&spare, |c| c.im, dc);
                }
            }
        }
        if let Some((i, dc_i)) = held {
            inverse.process_with_scratch(&mut spare, &mut scratch);
            rows[i] = read(&spare, |c| c.re, dc_i);
        }
        rows
    }
}

/// The bins 0..half of [`TransitDesign::stretch_history`]'s terms for the usual point inside the
/// bar ([`InteriorBins::new`]) and of one cell's phase factor z, as separate real arrays (index
/// k), so that the loop over its bins streams plain slices the compiler can vectorise.
struct InteriorBins {
    /// Re and Im of the four terms: sum·t_k, difference·t_k, sum·conj(t_mirror),
    /// difference·conj(t_mirror).
    terms: [[Vec<f64>; 2]; 4],
    /// Re and Im of z.
    z: [Vec<f64>; 2],
}

impl InteriorBins {
    /// From the history spectra `u`, `v` (with their delays), the band's weights with the half
    /// cell's dispersion, the phase turns of each bin and its mirror, and z, over the bins
    /// 0..`half`.
    fn new(
        u: &[Complex64],
        v: &[Complex64],
        carry: &[Complex64],
        turns: &[(Complex64, Complex64)],
        z: &[Complex64],
        half: usize,
    ) -> InteriorBins {
        // Inside the bar (both waves weighted by the band and carried the half cell, one complex
        // weight g) the value at bin k is g (u h + v conj h) = g ((u + v) Re h + i (u − v) Im h),
        // h the right-going sum: with its two phase turns folded in, four real products a turn.
        let inside: Vec<[Complex64; 4]> = (0..half)
            .map(|k| {
                let (sum, difference) = ((u[k] + v[k]) * carry[k], (u[k] - v[k]) * carry[k]);
                let (t_k, t_mirror) = turns[k];
                [
                    sum * t_k,
                    difference * t_k,
                    sum * t_mirror.conj(),
                    difference * t_mirror.conj(),
                ]
            })
            .collect();
        let part = |f: &dyn Fn(usize) -> f64| (0..half).map(f).collect::<Vec<f64>>();
        InteriorBins {
            terms: std::array::from_fn(|j| {
                [part(&|k| inside[k][j].re), part(&|k| inside[k][j].im)]
            }),
            z: [part(&|k| z[k].re), part(&|k| z[k].im)],
        }
    }
}

/// The folded spectrum of one point inside the bar, as two accumulators indexed by k mod m:
/// `forward` collects the bins' own slots k mod m, `mirror` the slots (n − k) mod m of their
/// conjugate mirrors (n a multiple of m), so that each pass over a block of m bins writes
/// consecutive slots.
struct FoldSums {
    forward: [Vec<f64>; 2],
    mirror: [Vec<f64>; 2],
}

impl FoldSums {
    fn new(m: usize) -> FoldSums {
        FoldSums {
            forward: [vec![0.0; m], vec![0.0; m]],
            mirror: [vec![0.0; m], vec![0.0; m]],
        }
    }

    /// Accumulates the bins 1..half of a point whose stretch is `w0` of element e plus `w1` of
    /// element e + 1: h = z^e (w0 + w1 z), with z^e in `pw` advanced first by `step` (z^stride)
    /// when given; the value at bin k is g (u h + v conj h) with its two phase turns
    /// (`InteriorBins::terms`). Only the terms that reach the folded slots 0..=m/2 are summed:
    /// the folded spectrum of a real series is Hermitian, so [`hermitian_completion`] fills the
    /// rest (a bin's own term reaches slot k mod m, its mirror's slot (m − k mod m) mod m, and
    /// inside a block of m bins all but slots 0 and m/2 need one of the two).
    fn interior(
        &mut self,
        bins: &InteriorBins,
        pw: &mut [Complex64],
        step: Option<&[Complex64]>,
        weights: (f64, f64),
        m: usize,
    ) {
        // Zero the slots the pass writes and write_to reads (no others).
        let hm = m / 2;
        for a in &mut self.forward {
            a[..=hm].fill(0.0);
        }
        for a in &mut self.mirror {
            a[0] = 0.0;
            a[m - hm..].fill(0.0);
        }
        let half = bins.z[0].len();
        let mut start = 1;
        while start < half {
            // The block of bins k in [start, end) sharing the slots k − base.
            let base = start - start % m;
            let end = (base + m).min(half);
            if let Some(step) = step {
                for (c, s) in pw[start..end].iter_mut().zip(&step[start..end]) {
                    *c *= s;
                }
            }
            // Slots [lo, hi): 0 takes both terms, then own terms up to m − hm (exclusive), both
            // at hm when m is even, mirror terms from hm + 1.
            let (lo, hi) = (start - base, end - base);
            let segment = |a: usize, b: usize| (a.max(lo), b.min(hi));
            let parts = [
                (segment(0, 1), true, true),
                (segment(1, m - hm), true, false),
                (segment(m - hm, hm + 1), true, true),
                (segment(hm + 1, m), false, true),
            ];
            for ((a, b), own, mirror) in parts {
                if a < b {
                    let k = base + a..base + b;
                    match (own, mirror) {
                        (true, true) => self.pass::<true, true>(bins, pw, weights, k, a),
                        (true, false) => self.pass::<true, false>(bins, pw, weights, k, a),
                        _ => self.pass::<false, true>(bins, pw, weights, k, a),
                    }
                }
            }
            start = end;
        }
        // DC and Nyquist (summed by the caller) advance too.
        if let Some(step) = step {
            pw[0] *= step[0];
            pw[half] *= step[half];
        }
    }

    /// [`FoldSums::interior`] over the bins `k`, whose slots start at `slot`: the own terms
    /// (`OWN`) and/or the mirror terms (`MIRROR`).
    #[inline(always)]
    fn pass<const OWN: bool, const MIRROR: bool>(
        &mut self,
        bins: &InteriorBins,
        pw: &[Complex64],
        (w0, w1): (f64, f64),
        k: std::ops::Range<usize>,
        slot: usize,
    ) {
        let len = k.len();
        let [[s1r, s1i], [d1r, d1i], [s2r, s2i], [d2r, d2i]] = &bins.terms;
        let (zr, zi, pw) = (&bins.z[0][k.clone()], &bins.z[1][k.clone()], &pw[k.clone()]);
        let (s1r, s1i, d1r, d1i) = (
            &s1r[k.clone()],
            &s1i[k.clone()],
            &d1r[k.clone()],
            &d1i[k.clone()],
        );
        let (s2r, s2i, d2r, d2i) = (&s2r[k.clone()], &s2i[k.clone()], &d2r[k.clone()], &d2i[k]);
        let [fr, fi] = &mut self.forward;
        let [mr, mi] = &mut self.mirror;
        let (fr, fi) = (&mut fr[slot..slot + len], &mut fi[slot..slot + len]);
        let (mr, mi) = (&mut mr[slot..slot + len], &mut mi[slot..slot + len]);
        for j in 0..len {
            let c = pw[j];
            let (qr, qi) = (w0 + w1 * zr[j], w1 * zi[j]);
            let (hr, hi) = (c.re * qr - c.im * qi, c.re * qi + c.im * qr);
            if OWN {
                fr[j] += s1r[j] * hr - d1i[j] * hi;
                fi[j] += s1i[j] * hr + d1r[j] * hi;
            }
            if MIRROR {
                mr[j] += s2r[j] * hr - d2i[j] * hi;
                mi[j] -= s2i[j] * hr + d2r[j] * hi;
            }
        }
    }

    /// Sets the folded slots 0..=m/2 of `folded` from the accumulators (own slot s to s, mirror
    /// slot s to (m − s) mod m), for the caller's DC and Nyquist terms to join before
    /// [`hermitian_completion`] fills the slots above m/2.
    fn write_to(&self, folded: &mut [Complex64]) {
        let m = folded.len();
        let hm = m / 2;
        let [re, im] = &self.forward;
        for ((f, &r), &i) in folded[..=hm].iter_mut().zip(re).zip(im) {
            *f = Complex64::new(r, i);
        }
        folded[0] += Complex64::new(self.mirror[0][0], self.mirror[1][0]);
        for s in m - hm..m {
            folded[m - s] += Complex64::new(self.mirror[0][s], self.mirror[1][s]);
        }
    }
}

/// The slots above m/2 of a folded spectrum of a real series from those below: F[m − s] =
/// conj F[s].
fn hermitian_completion(folded: &mut [Complex64]) {
    let m = folded.len();
    for s in m / 2 + 1..m {
        folded[s] = folded[m - s].conj();
    }
}

/// Uniformly partitioned overlap-save convolution (the "causal blocks" of docs/physics.md
/// §6.2.1): y[n] = Σ_j h_j u[n − j] computed a block of B outputs at a time from the 2B inputs
/// u[kB − B, kB + B) (all known when the filter's input lags its output by at least B steps),
/// with h cut into partitions of B taps whose spectra multiply those of the past input windows:
/// O(log B + P/B) a sample instead of P.
#[derive(Clone)]
pub struct BlockConvolver {
    block: usize,
    /// Spectra of the partitions h[pB, (p + 1)B), zero-padded to 2B.
    parts: Vec<Vec<Complex64>>,
    /// Spectra of the input windows, the newest first.
    inputs: std::collections::VecDeque<Vec<Complex64>>,
    /// y[kB, (k + 1)B) of the current block.
    out: Vec<f64>,
    forward: Arc<dyn rustfft::Fft<f64>>,
    inverse: Arc<dyn rustfft::Fft<f64>>,
}

impl std::fmt::Debug for BlockConvolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BlockConvolver")
            .field("block", &self.block)
            .field("parts", &self.parts.len())
            .finish()
    }
}

/// Smallest block worth the transforms (below it a direct sum is as quick).
pub const MIN_BLOCK: usize = 64;
/// Largest block (longer ones save little and delay nothing).
const MAX_BLOCK: usize = 1024;

impl BlockConvolver {
    /// A convolver of `taps` (h_0 first) with blocks of the largest power of two ≤ `max_block`,
    /// the taps and [`MAX_BLOCK`]; `None` when that is below [`MIN_BLOCK`].
    pub fn new(taps: &[f64], max_block: usize) -> Option<BlockConvolver> {
        let cap = max_block.min(taps.len()).min(MAX_BLOCK);
        if cap < MIN_BLOCK {
            return None;
        }
        let block = 1usize << (usize::BITS - 1 - cap.leading_zeros());
        let forward = fft_plan(2 * block, false);
        let inverse = fft_plan(2 * block, true);
        let parts: Vec<Vec<Complex64>> = taps
            .chunks(block)
            .map(|c| {
                let mut v = vec![Complex64::new(0.0, 0.0); 2 * block];
                for (x, &t) in v.iter_mut().zip(c) {
                    x.re = t;
                }
                forward.process(&mut v);
                v
            })
            .collect();
        Some(BlockConvolver {
            block,
            inputs: std::collections::VecDeque::with_capacity(parts.len()),
            parts,
            out: vec![0.0; block],
            forward,
            inverse,
        })
    }

    /// The block size B.
    pub fn block(&self) -> usize {
        self.block
    }

    /// The number of past windows the next [`Self::process`] needs pushed before it (partitions
    /// less one).
    pub fn history_blocks(&self) -> usize {
        self.parts.len() - 1
    }

    /// Forgets the input windows taken so far.
    pub fn clear(&mut self) {
        self.inputs.clear();
    }

    /// Takes the input window u[kB − B, kB + B) of block k (2B values) without computing
    /// outputs (to fill the history before the first block).
    pub fn push(&mut self, window: &[f64]) {
        let mut v: Vec<Complex64> = window.iter().map(|&x| Complex64::new(x, 0.0)).collect();
        self.forward.process(&mut v);
        if self.inputs.len() == self.parts.len() {
            self.inputs.pop_back();
        }
        self.inputs.push_front(v);
    }

    /// Takes the window of block k and computes y[kB, (k + 1)B) ([`Self::output`]).
    pub fn process(&mut self, window: &[f64]) {
        self.push(window);
        let mut acc = vec![Complex64::new(0.0, 0.0); 2 * self.block];
        for (g, u) in self.parts.iter().zip(&self.inputs) {
            for ((a, gk), uk) in acc.iter_mut().zip(g).zip(u) {
                *a += gk * uk;
            }
        }
        self.inverse.process(&mut acc);
        let scale = 1.0 / (2 * self.block) as f64;
        for (o, a) in self.out.iter_mut().zip(&acc[self.block..]) {
            *o = a.re * scale;
        }
    }

    /// y[kB + i] of the current block.
    #[inline]
    pub fn output(&self, i: usize) -> f64 {
        self.out[i]
    }
}

/// max over frequency of |Σ_j h_j e^{−iΩj}|², on a grid 8 times finer than the taps are long.
pub fn max_power_gain(taps: &[f64]) -> f64 {
    let n = (8 * taps.len()).next_power_of_two().max(64);
    let mut v: Vec<Complex64> = vec![Complex64::new(0.0, 0.0); n];
    for (c, &t) in v.iter_mut().zip(taps) {
        c.re = t;
    }
    fft_plan(n, false).process(&mut v);
    v.iter().map(|c| c.norm_sqr()).fold(0.0, f64::max)
}

/// Σ a_i b_i in four independent lanes (so the compiler vectorises it).
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let chunks = n / 4;
    for (ca, cb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for l in 0..4 {
            acc[l] += ca[l] * cb[l];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for i in 4 * chunks..n {
        s += a[i] * b[i];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shared design is one per key and gives a fresh design's filters bit for bit, with the
    /// same power gain; another grid gets another design.
    #[test]
    fn shared_designs_equal_fresh_ones() {
        let m = TransitModel::PochhammerChree;
        let a = shared_design(m, 0.29, 9.525e-3, 1e-3, 300);
        let b = shared_design(m, 0.29, 9.525e-3, 1e-3, 300);
        assert!(Arc::ptr_eq(&a, &b));
        let fresh = TransitDesign::new(m, 0.29, 9.525e-3, 1e-3, 300);
        for half_cells in [1, 17, 299, 600] {
            let shared = a.shared_filter(half_cells);
            let f = fresh.filter(half_cells);
            assert_eq!(shared.filter, f);
            assert!(Arc::ptr_eq(&shared, &a.shared_filter(half_cells)));
            assert_eq!(shared.max_power_gain(), max_power_gain(&f.taps));
        }
        assert!(!Arc::ptr_eq(
            &a,
            &shared_design(m, 0.29, 9.525e-3, 0.5e-3, 300)
        ));
        // The relation alone evaluates the same phase.
        let w = 0.7;
        assert_eq!(
            TransitDesign::relation(m, 0.29, 9.525e-3, 1e-3).phase_and_gain(w),
            fresh.phase_and_gain(w)
        );
    }

    /// Points evaluated together (two series through one inverse transform, the factors kept
    /// by the design) equal each point evaluated alone, to rounding, for both models, at ends
    /// and inside, with a time stride (x–t snapshots) and without (gauges).
    #[test]
    fn points_evaluated_together_equal_points_evaluated_alone() {
        let elements = 120;
        let right: Vec<f64> = (0..900)
            .map(|i| 0.1 + (-((i as f64 - 150.0) / 25.0).powi(2)).exp())
            .collect();
        let left: Vec<f64> = (0..900)
            .map(|i| -0.05 + 0.3 * (-((i as f64 - 400.0) / 40.0).powi(2)).exp())
            .collect();
        let points: Vec<StretchPoint> = vec![
            vec![(0, 1.0)],
            vec![(7, 0.25), (8, 0.5)],
            vec![(12, 2.0)],
            vec![(60, 0.5), (61, 0.5)],
            vec![],
            vec![(119, 1.0)],
            vec![(90, 1.0)],
        ];
        for model in [TransitModel::PochhammerChree, TransitModel::RayleighLove] {
            let design = TransitDesign::new(model, 0.29, 9.525e-3, 1e-3, 2 * elements);
            for times in [(0..900).step_by(5).collect::<Vec<_>>(), (0..900).collect()] {
                let together = design.stretch_history(&right, &left, elements, &points, &times);
                let peak = together
                    .iter()
                    .flatten()
                    .fold(0.0f64, |a, &x| a.max(x.abs()));
                for (p, row) in points.iter().zip(&together) {
                    let alone = &design.stretch_history(
                        &right,
                        &left,
                        elements,
                        std::slice::from_ref(p),
                        &times,
                    )[0];
                    let worst = row
                        .iter()
                        .zip(alone)
                        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
                    assert!(
                        worst <= 1e-14 * peak,
                        "{model:?} {p:?}: {worst:e} of {peak:e}"
                    );
                }
            }
        }
    }

    /// A filter's DFT is exp(−i d φ) in its band (at the design's bins), and its taps sum to one.
    #[test]
    fn filters_are_the_all_pass_transit_of_each_model() {
        for model in [TransitModel::PochhammerChree, TransitModel::RayleighLove] {
            let design = TransitDesign::new(model, 0.31, 9.525e-3, 1e-3, 400);
            let f = design.filter(800);
            assert!((f.taps.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(
                f.taps.len() < design.n_fft / 2,
                "{model:?}: {} taps",
                f.taps.len()
            );
            for k in [3usize, 40, 150, 300, 700] {
                let w = 2.0 * PI * k as f64 / design.n_fft as f64;
                let hk: Complex64 = f
                    .taps
                    .iter()
                    .enumerate()
                    .map(|(j, &t)| Complex64::from_polar(t, -w * (j as f64 - f.lead as f64)))
                    .sum();
                let expected = design.response(k, 400.0);
                assert!(
                    (hk - expected).norm() < 1e-5,
                    "{model:?} bin {k}: {hk} vs {expected}"
                );
            }
        }
    }

    /// The block convolution is the direct sum to rounding, block after block.
    #[test]
    fn block_convolution_is_the_direct_sum() {
        let taps: Vec<f64> = (0..700)
            .map(|j| ((j as f64) * 0.37).sin() / (1.0 + j as f64))
            .collect();
        let u: Vec<f64> = (0..6000)
            .map(|n| ((n as f64) * 0.011).cos() + 0.3 * ((n * n) as f64 * 1e-5).sin())
            .collect();
        let mut c = BlockConvolver::new(&taps, 300).unwrap();
        let b = c.block();
        assert_eq!(b, 256);
        let start = (c.history_blocks() + 1) * b; // first block whose whole history is in u
        for k in (start / b - c.history_blocks())..(start / b) {
            c.push(&u[k * b - b..k * b + b]);
        }
        for k in start / b..u.len() / b - 1 {
            c.process(&u[k * b - b..k * b + b]);
            for i in 0..b {
                let n = k * b + i;
                let direct: f64 = taps.iter().enumerate().map(|(j, &h)| h * u[n - j]).sum();
                assert!(
                    (c.output(i) - direct).abs() < 1e-12,
                    "n {n}: {} vs {direct}",
                    c.output(i)
                );
            }
        }
    }

    #[test]
    fn dot_is_the_sum_of_products() {
        let a: Vec<f64> = (0..11).map(|i| i as f64).collect();
        let b: Vec<f64> = (0..11).map(|i| 1.0 / (1.0 + i as f64)).collect();
        let direct: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        assert!((dot(&a, &b) - direct).abs() < 1e-12);
    }
}
