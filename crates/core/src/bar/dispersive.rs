//! The dispersive delay line (docs/physics.md §6.2.1): a delay line whose travelling waves carry
//! the dispersion of a [`TransitModel`], kept as the whole histories of the increments injected
//! at the ends and read through the transit filters of [`crate::transit`]: the arrivals at the
//! ends step by step (in blocks by FFT), the gauges and x–t fields after the run.

use super::Bar;
use crate::transit::{BlockConvolver, MIN_BLOCK, SharedFilter, StretchPoint, TransitDesign};
use std::sync::Arc;

/// What a dispersive delay line keeps beyond the ring buffers (docs/physics.md
/// §6.2.1): every increment injected, and the transit filters that read them.
#[derive(Debug, Clone)]
pub(super) struct Transit {
    /// The design, shared with every bar like this one ([`crate::transit::shared_design`]).
    pub(super) design: Arc<TransitDesign>,
    /// The end-to-end filter (N cells: end node to end node).
    ends: Arc<SharedFilter>,
    /// Right-going increments A[m] injected at the left end at step m, at index m + offset
    /// (m ≥ −N: the initial field, older: its last value repeated), m.
    injected_right: Vec<f64>,
    /// Left-going increments B[m] injected at the right end, likewise, m.
    injected_left: Vec<f64>,
    /// Index of A[0] and B[0] in the histories.
    offset: usize,
    /// Elements N of the bar.
    elements: usize,
    /// Steps taken n.
    pub(super) step: usize,
    /// [D at element N − 1, E at element 0] at the current level: the waves arriving at the ends.
    pub(super) arrival: [f64; 2],
    /// Σ of the squared increments injected (the initial field included) and delivered at the
    /// ends: k times each is the wave energy into and out of the transit, m².
    pub(super) injected_sq: f64,
    pub(super) delivered_sq: f64,
    /// max |H|² − 1 (≥ 0) of the end-to-end filter as truncated: the most energy it can add.
    pub(super) ends_gain_excess: f64,
    /// The end-to-end filter applied in blocks ([`BlockConvolver`]) to the right- and
    /// left-going histories, its first [`Self::head`] taps excepted, when the filter is long
    /// enough for blocks; else the direct sum.
    blocks: Option<Box<[BlockConvolver; 2]>>,
    /// Steps by which an arrival lags the newest injection it uses: N − lead (≥ 1).
    lag: usize,
    /// Taps of the end-to-end filter summed directly beside the blocks: 0 when the lag allows
    /// blocks of [`MIN_BLOCK`] or more, else MIN_BLOCK − lag, so that the taps after them lag
    /// by a whole block (a short bar whose precursor reaches nearly across it, as a striker's).
    head: usize,
    /// Σ m v^{n−1/2} of the bar, carried by the impulse of each step ([`Bar::momentum_kg_m_s`]),
    /// kg·m/s.
    pub(super) momentum_half: f64,
}

impl Transit {
    /// The transit of a delay line of `n` elements at rest ([`Transit::restart`] takes its field).
    pub(super) fn new(design: Arc<TransitDesign>, n: usize) -> Transit {
        let ends = design.shared_filter(2 * n);
        let ends_gain_excess = (ends.max_power_gain() - 1.0).max(0.0);
        let lag = n - ends.filter.lead;
        let taps = &ends.filter.taps;
        let head = if lag < MIN_BLOCK && taps.len() >= 2 * MIN_BLOCK {
            MIN_BLOCK - lag
        } else {
            0
        };
        let blocks =
            BlockConvolver::new(&taps[head..], lag + head).map(|c| Box::new([c.clone(), c]));
        // Room for the longest filter behind the oldest pure-delay read (interior filters,
        // over fewer cells, are shorter; the slack covers their rounding).
        let offset = n + 2 * ends.filter.taps.len() + 16;
        Transit {
            design,
            ends,
            injected_right: vec![0.0; offset],
            injected_left: vec![0.0; offset],
            offset,
            elements: n,
            step: 0,
            arrival: [0.0; 2],
            injected_sq: 0.0,
            delivered_sq: 0.0,
            ends_gain_excess,
            blocks,
            lag,
            head,
            momentum_half: 0.0,
        }
    }

    /// Restarts the histories from the field of ring buffers at step 0 (A[m] = D_{−m−1},
    /// B[m] = E_{N+m} for −N ≤ m < 0) and computes the arrivals.
    pub(super) fn restart(&mut self, right: &[f64], left: &[f64]) {
        let n = right.len();
        let pad = self.offset - n;
        self.injected_right.truncate(self.offset);
        self.injected_left.truncate(self.offset);
        for i in 0..self.offset {
            // m = i − offset; A[m] = right[−m−1] = right[offset − 1 − i] while that is < N.
            let back = self.offset - 1 - i;
            self.injected_right[i] = right[back.min(n - 1)];
            self.injected_left[i] = left[(i.max(pad)) - pad];
        }
        self.step = 0;
        self.injected_sq = right.iter().chain(left).map(|x| x * x).sum();
        self.delivered_sq = 0.0;
        if let Some(blocks) = self.blocks.as_mut() {
            // The windows of the blocks before the first, from the initial field.
            let b = blocks[0].block();
            let past = blocks[0].history_blocks();
            for (c, h) in blocks
                .iter_mut()
                .zip([&self.injected_right, &self.injected_left])
            {
                c.clear();
                for k in (1..=past).rev() {
                    let start = self.offset - self.lag - self.head - (k + 1) * b;
                    c.push(&h[start..start + 2 * b]);
                }
            }
        }
        self.update_arrivals();
    }

    /// Arrivals at the current step n: D̃ = Σ h_j A[n − N − j + lead], Ẽ likewise from B.
    fn update_arrivals(&mut self) {
        if let Some(blocks) = self.blocks.as_mut() {
            // u[n'] = history[n' + offset − lag]; block k's window is u[kB − B, kB + B).
            let b = blocks[0].block();
            let i = self.step % b;
            if i == 0 {
                let start = self.step + self.offset - self.lag - self.head - b;
                for (c, h) in blocks
                    .iter_mut()
                    .zip([&self.injected_right, &self.injected_left])
                {
                    c.process(&h[start..start + 2 * b]);
                }
            }
            self.arrival = [blocks[0].output(i), blocks[1].output(i)];
            if self.head > 0 {
                let idx = self.step + self.offset - self.elements; // A[n − N]
                self.arrival[0] += self.ends.apply_head(&self.injected_right, idx, self.head);
                self.arrival[1] += self.ends.apply_head(&self.injected_left, idx, self.head);
            }
            return;
        }
        let idx = self.step + self.offset - self.elements; // A[n − N]
        self.arrival = [
            self.ends.apply(&self.injected_right, idx),
            self.ends.apply(&self.injected_left, idx),
        ];
    }

    /// Records the increments injected at step n and moves to n + 1.
    pub(super) fn inject(&mut self, a: f64, b: f64, delivered: [f64; 2]) {
        self.delivered_sq += delivered[0] * delivered[0] + delivered[1] * delivered[1];
        self.injected_sq += a * a + b * b;
        self.injected_right.push(a);
        self.injected_left.push(b);
        self.step += 1;
        self.update_arrivals();
    }

    /// Right-going increment at element e (0 < e < N − 1): A[n − e − 1] carried over e + ½ cells.
    pub(super) fn right_at(&self, e: usize) -> f64 {
        let f = self.design.shared_filter(2 * e + 1);
        f.apply(&self.injected_right, self.step + self.offset - e - 1)
    }

    /// Left-going increment at element e (0 < e < N − 1): B[n − (N − e)] carried over N − e − ½
    /// cells.
    pub(super) fn left_at(&self, e: usize) -> f64 {
        let n = self.elements;
        let f = self.design.shared_filter(2 * (n - e) - 1);
        f.apply(&self.injected_left, self.step + self.offset - (n - e))
    }
}

impl Bar {
    /// Weighted element stretches over the past `steps` (≤ the current step) of a dispersive
    /// delay line, from its whole histories by FFT (docs/physics.md §6.2.1): one
    /// row per point, one column per step; `None` for any other bar.
    fn transit_history(&self, points: Vec<StretchPoint>, steps: &[usize]) -> Option<Vec<Vec<f64>>> {
        let t = self.transit()?;
        // Terms by element, merged (the FFT evaluation walks the elements upward).
        let points: Vec<StretchPoint> = points
            .into_iter()
            .map(|mut p| {
                p.sort_by_key(|&(e, _)| e);
                p.dedup_by(|b, a| {
                    let same = a.0 == b.0;
                    if same {
                        a.1 += b.1;
                    }
                    same
                });
                p
            })
            .collect();
        let times: Vec<usize> = steps.iter().map(|&n| n + t.offset).collect();
        Some(t.design.stretch_history(
            &t.injected_right,
            &t.injected_left,
            self.nodes.k.len(),
            &points,
            &times,
        ))
    }

    /// [`Bar::strain_at`]'s reading of x as element stretches, each weight scaled by `scale`.
    fn strain_terms(&self, x_m: f64, scale: f64) -> StretchPoint {
        let (k, e, w) = self.strain_point(x_m);
        let scale = scale / self.segments[k].dx_m;
        if w == 0.0 {
            vec![(e, scale)]
        } else {
            vec![(e, (1.0 - w) * scale), (e + 1, w * scale)]
        }
    }

    /// Axial stress at each of `x_m` at each of the past `steps` (≤ the current step) of a
    /// dispersive delay line, one row per step, from its whole histories by FFT (docs/physics.md
    /// §6.2.1; what [`Bar::stress_at`] read then, to the filters' truncation,
    /// with each wave's whole precursor), Pa; `None` for any other bar.
    pub fn stress_history(&self, x_m: &[f64], steps: &[usize]) -> Option<Vec<Vec<f64>>> {
        let e_pa = self.segments.first()?.youngs_modulus_pa;
        let points = x_m.iter().map(|&x| self.strain_terms(x, e_pa)).collect();
        let columns = self.transit_history(points, steps)?;
        Some(
            (0..steps.len())
                .map(|i| columns.iter().map(|c| c[i]).collect())
                .collect(),
        )
    }

    /// [`Bar::strain_at`] at x over the past `steps` of a dispersive delay line ([`Bar::stress_history`]).
    pub fn strain_history(&self, x_m: f64, steps: &[usize]) -> Option<Vec<f64>> {
        let points = vec![self.strain_terms(x_m, 1.0)];
        self.transit_history(points, steps)?.pop()
    }

    /// [`Bar::stretch_between_m`] over the past `steps` of a dispersive delay line
    /// ([`Bar::stress_history`]), m.
    pub fn stretch_between_history(
        &self,
        x_a_m: f64,
        x_b_m: f64,
        steps: &[usize],
    ) -> Option<Vec<f64>> {
        let (la, wa) = self.node_interval(x_a_m);
        let (lb, wb) = self.node_interval(x_b_m);
        let mut terms: StretchPoint = if lb >= la {
            (la..lb).map(|e| (e, 1.0)).collect()
        } else {
            (lb..la).map(|e| (e, -1.0)).collect()
        };
        terms.extend([(lb, wb), (la, -wa)]);
        self.transit_history(vec![terms], steps)?.pop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transit::TransitModel;

    /// A striker's transit (0.1 m of 19.05 mm steel bar in 1 mm and 0.25 mm cells, the exact
    /// first mode): its precursor reaches nearly across the bar (lag 1 step), so the first taps
    /// are summed directly and the rest in blocks; each arrival is the direct sum over the whole
    /// filter to rounding (1e-13 of the largest arrival), from a field at rest and from a
    /// field that is not.
    #[test]
    fn a_short_lag_transit_sums_its_head_directly_and_the_rest_in_blocks() {
        for (cell_m, n) in [(1e-3, 100), (0.25e-3, 400)] {
            let design = crate::transit::shared_design(
                TransitModel::PochhammerChree,
                0.29,
                0.009525,
                cell_m,
                n,
            );
            let mut t = Transit::new(design, n);
            assert!(
                t.lag < MIN_BLOCK && t.head == MIN_BLOCK - t.lag,
                "lag {}",
                t.lag
            );
            assert!(t.blocks.is_some());
            let right: Vec<f64> = (0..n).map(|i| (i as f64 * 0.05).sin()).collect();
            let left: Vec<f64> = (0..n).map(|i| (i as f64 * 0.03).cos()).collect();
            t.restart(&right, &left);
            let (mut worst, mut largest) = (0.0f64, 0.0f64);
            for step in 0..3000 {
                let x = step as f64;
                let direct =
                    |h: &[f64], t: &Transit| t.ends.apply(h, t.step + t.offset - t.elements);
                let expect = [direct(&t.injected_right, &t), direct(&t.injected_left, &t)];
                for (a, e) in t.arrival.iter().zip(expect) {
                    worst = worst.max((a - e).abs());
                    largest = largest.max(e.abs());
                }
                let (a, b) = ((x * 0.021).sin() + 0.2, (x * x * 1e-5).cos());
                t.inject(a, b, [0.0, 0.0]);
            }
            assert!(worst <= 1e-13 * largest, "{cell_m}: {worst} of {largest}");
        }
    }
}
