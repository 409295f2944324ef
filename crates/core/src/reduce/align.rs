//! Where the reflected and transmitted windows start relative to the incident one
//! (docs/physics.md §7.6): the gauge distances (`geometric`), the feet detected in the record
//! (`foot`), or a bounded search for the shifts that balance the front and back forces over the
//! incident pulse (`balance`).

use crate::gauge::pulse_foot;

/// Window alignment strategy of the reduction (docs/physics.md §7.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Alignment {
    /// Delays from the gauge distances and c0: 2 d_I/c0 and d_I/c0 + d_T/c0 (the lab's rule).
    #[default]
    Geometric,
    /// Delays from the feet of the reflected and transmitted pulses detected in the record.
    Foot,
    /// The geometric delays shifted, within a bound, to minimise the front/back force imbalance
    /// over the incident pulse.
    Balance,
}

impl Alignment {
    /// The three strategies, in the order of the command line's help.
    pub const ALL: [Alignment; 3] = [Alignment::Geometric, Alignment::Foot, Alignment::Balance];

    /// The command-line and file name (`geometric`, `foot`, `balance`).
    pub fn name(self) -> &'static str {
        match self {
            Alignment::Geometric => "geometric",
            Alignment::Foot => "foot",
            Alignment::Balance => "balance",
        }
    }

    /// The strategy of a name (`geometric`, `foot`, `balance`).
    pub fn from_name(name: &str) -> Option<Alignment> {
        Alignment::ALL.into_iter().find(|a| a.name() == name)
    }
}

/// What the alignment chose and what it measured (record clock differences, s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlignmentReport {
    /// The strategy asked for.
    pub strategy: Alignment,
    /// Reflected delay the gauge distance predicts, 2 d_I/c0, s.
    pub geometric_reflected_delay_s: f64,
    /// Transmitted delay the gauge distances predict, d_I/c0 + d_T/c0 (+ specimen transit), s.
    pub geometric_transmitted_delay_s: f64,
    /// Foot of the reflected pulse minus foot of the incident pulse, in the record, s.
    pub measured_reflected_delay_s: Option<f64>,
    /// Foot of the transmitted pulse minus foot of the incident pulse, in the record, s.
    pub measured_transmitted_delay_s: Option<f64>,
    /// Shifts the balance search added to the geometric delays (reflected, transmitted), s.
    pub balance_shift_s: Option<(f64, f64)>,
    /// The gauge paths the balance delays imply, gauge to face (incident, transmission), m:
    /// d_I + c_I s_R/2 and d_T + c_T (s_T − s_R/2), on the bars' c0 (docs/physics.md §7.6).
    pub balance_paths_m: Option<(f64, f64)>,
    /// Bound of the balance search on each shift, s.
    pub balance_bound_s: f64,
    /// Whether a balance shift stopped at its bound (the optimum may lie beyond it).
    pub at_bound: bool,
}

/// Foot of the first pulse of sense `sign` (+1 tensile, −1 compressive) on a gauge's strain
/// `eps` after the incident foot (fractional sample `s_i`) minus that foot, s: searched from half
/// the geometric delay to twice it, and kept only when the pulse's peak (in that sense) reaches
/// `least` — a pulse that does not stand out has no foot to measure.
pub(crate) fn foot_delay_s(
    eps: &[f64],
    sign: f64,
    dt: f64,
    s_i: f64,
    geometric_s: f64,
    least: f64,
    fraction: f64,
) -> Option<f64> {
    foot_delay_between_s(
        eps,
        sign,
        dt,
        s_i,
        (0.5 * geometric_s, 2.0 * geometric_s),
        least,
        fraction,
    )
}

/// [`foot_delay_s`] searched between `within_s.0` and `within_s.1` after the incident foot.
pub(crate) fn foot_delay_between_s(
    eps: &[f64],
    sign: f64,
    dt: f64,
    s_i: f64,
    within_s: (f64, f64),
    least: f64,
    fraction: f64,
) -> Option<f64> {
    let from = (s_i + within_s.0 / dt).max(0.0) as usize;
    let to = ((s_i + within_s.1 / dt).max(0.0) as usize).min(eps.len());
    if from + 2 >= to {
        return None;
    }
    let y: Vec<f64> = eps[from..to].iter().map(|e| sign * e).collect();
    pulse_foot(&y, fraction)
        .filter(|f| y[f.peak_index] > least)
        .map(|f| (from as f64 + f.index as f64 - s_i) * dt)
}

/// The balance search's inputs: the incident wave at the face and the reflected and transmitted
/// waves at the faces cut from `margin` samples before their geometric starts, `window + 2
/// margin` long (so that a shift of j samples is the slice `margin + j ..`).
pub(crate) struct BalanceProblem<'a> {
    /// Incident strain at the face over the window.
    pub incident: &'a [f64],
    /// Reflected strain at the face, extended by `margin` on both sides.
    pub reflected: &'a [f64],
    /// Transmitted strain at the face, extended by `margin` on both sides.
    pub transmitted: &'a [f64],
    /// Largest shift, samples.
    pub margin: usize,
    /// E A of the incident bar, N.
    pub ea_incident_n: f64,
    /// E A of the transmission bar, N.
    pub ea_transmission_n: f64,
}

/// The span of an incident wave at the face (compression negative) the balance search weighs:
/// from the first sample reaching 10 % of its peak, through the peak, to the last sample before
/// it falls below 10 % again, as sample indices (docs/physics.md §7.6). The whole pulse, not its
/// rise alone: a rise fits a shifted copy of itself almost as well, its fall pins the shift.
pub(crate) fn pulse_span(incident: &[f64]) -> (usize, usize) {
    let y: Vec<f64> = incident.iter().map(|e| -e).collect();
    let (k_start, k_peak) = super::quality::rising_span(&y, 0.1);
    let level = 0.1 * y[k_peak];
    let k_end = (k_peak..y.len())
        .take_while(|&k| y[k] >= level)
        .last()
        .unwrap_or(k_peak);
    (k_start, k_end)
}

impl BalanceProblem<'_> {
    /// Σ (F_front − F_back)² / Σ F_back² over the pulse span for shifts (jr, jt) in samples.
    fn cost(&self, span: (usize, usize), jr: isize, jt: isize) -> f64 {
        let m = self.margin as isize;
        let (r0, t0) = ((m + jr) as usize, (m + jt) as usize);
        let (mut num, mut den) = (0.0, 0.0);
        for k in span.0..=span.1 {
            let front = -self.ea_incident_n * (self.incident[k] + self.reflected[r0 + k]);
            let back = -self.ea_transmission_n * self.transmitted[t0 + k];
            num += (front - back) * (front - back);
            den += back * back;
        }
        if den > 0.0 { num / den } else { f64::INFINITY }
    }

    /// The shifts (reflected, transmitted), in samples within ±margin, that minimise the
    /// imbalance over the incident pulse ([`pulse_span`]): a grid of step ⌈margin/50⌉, then, from
    /// each of its eight best points, every sample within one step of the best point so far until
    /// it stays. Returns the shifts and whether one of them is at ±margin.
    pub fn solve(&self) -> ((isize, isize), bool) {
        let span = pulse_span(self.incident);
        let m = self.margin as isize;
        let step = (self.margin.div_ceil(50)).max(1) as isize;
        let mut grid = Vec::new();
        let mut jr = -m;
        while jr <= m {
            let mut jt = -m;
            while jt <= m {
                grid.push((self.cost(span, jr, jt), jr, jt));
                jt += step;
            }
            jr += step;
        }
        grid.sort_by(|a, b| a.0.total_cmp(&b.0));
        // From each of the best grid points, every sample within one step of the best point so
        // far, until it stays: a valley slanting across the grid is followed to its floor, and a
        // shallower valley the grid happened to sample better does not hide the deepest one.
        let mut best = (f64::INFINITY, 0isize, 0isize);
        for &start in grid.iter().take(REFINED_GRID_POINTS) {
            let mut here = start;
            loop {
                let (_, br, bt) = here;
                for jr in (br - step).max(-m)..=(br + step).min(m) {
                    for jt in (bt - step).max(-m)..=(bt + step).min(m) {
                        let c = self.cost(span, jr, jt);
                        if c < here.0 {
                            here = (c, jr, jt);
                        }
                    }
                }
                if (here.1, here.2) == (br, bt) {
                    break;
                }
            }
            if here.0 < best.0 {
                best = here;
            }
        }
        let (_, jr, jt) = best;
        ((jr, jt), jr.abs() == m || jt.abs() == m)
    }
}

/// How many of the balance search's best grid points are refined sample by sample.
const REFINED_GRID_POINTS: usize = 8;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for a in Alignment::ALL {
            assert_eq!(Alignment::from_name(a.name()), Some(a));
        }
        assert_eq!(Alignment::from_name("auto"), None);
    }

    /// A balanced test (F_front = F_back at every instant) whose reflected and transmitted waves
    /// were cut off by known shifts, small ones and ones of the size the authors' records need
    /// (docs/physics.md §7.6): the search recovers both shifts exactly.
    #[test]
    fn the_balance_search_recovers_known_shifts() {
        for (shifts, margin) in [((7, -4), 30), ((-22, -41), 60)] {
            recovers(shifts, margin);
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

        /// Any shifts inside the bound, with the bound of the authors' records (60 samples
        /// here): the search finds them exactly and does not call them at the bound.
        #[test]
        fn the_balance_search_recovers_any_shifts_inside_its_bound(
            sr in -59isize..=59,
            st in -59isize..=59,
        ) {
            recovers((sr, st), 60);
        }
    }

    fn recovers((sr, st): (isize, isize), margin: usize) {
        let n = 400;
        let pulse = |k: f64| {
            let x = k / 200.0;
            if (0.0..=1.0).contains(&x) {
                (std::f64::consts::PI * x).sin().powi(2)
            } else {
                0.0
            }
        };
        // εI = −p, εT = −0.4 p(k − 3) (a later, smaller back force), εR from balance:
        // −(εI + εR) = −εT  ⇒  εR = εT − εI.
        let incident: Vec<f64> = (0..n).map(|k| -pulse(k as f64)).collect();
        let transmitted_at = |k: f64| -0.4 * pulse(k - 3.0);
        let reflected_at = |k: f64| transmitted_at(k) + pulse(k);
        let ext = |f: &dyn Fn(f64) -> f64, s: isize| -> Vec<f64> {
            (0..n + 2 * margin)
                .map(|i| f((i as isize - margin as isize - s) as f64))
                .collect()
        };
        let (reflected, transmitted) = (ext(&reflected_at, sr), ext(&transmitted_at, st));
        let p = BalanceProblem {
            incident: &incident,
            reflected: &reflected,
            transmitted: &transmitted,
            margin,
            ea_incident_n: 1.0,
            ea_transmission_n: 1.0,
        };
        let ((jr, jt), at_bound) = p.solve();
        assert_eq!((jr, jt), (sr, st));
        assert!(!at_bound);
    }

    #[test]
    fn the_pulse_span_runs_from_ten_percent_up_to_ten_percent_down() {
        // A triangle 0 → 50 (k = 50) → 0 (k = 100): 10 % is 5, reached at k = 5 and left after
        // k = 95.
        let incident: Vec<f64> = (0..120)
            .map(|k| -(50.0 - (k as f64 - 50.0).abs()).max(0.0))
            .collect();
        assert_eq!(pulse_span(&incident), (5, 95));
    }
}
