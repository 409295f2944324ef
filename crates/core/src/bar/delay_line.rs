//! The exact delay line (docs/physics.md §6.2, "Delay lines"): a bar of one uniform segment at
//! Courant 1 keeps the characteristic increments D (right-going) and E (left-going) of
//! u_i^n = f(i − n) + g(i + n) in two ring buffers and advances only its end nodes, O(1) a step,
//! equal to the leapfrog to rounding; with a [`Transit`] the waves carry dispersion
//! ([`super::dispersive`], §6.2.1).

use super::dispersive::Transit;
use super::ends::{add_lumped_forces, lumped_response};
use super::leapfrog::Leapfrog;
use super::{Interior, Nodes, node_momentum};
use crate::transit::TransitDesign;
use std::sync::Arc;

/// The characteristic increments of a delay-line bar of N elements (docs/physics.md §6.2,
/// "Delay lines").
#[derive(Debug, Clone)]
struct Waves {
    /// Right-going increments: D_{e−n} in slot (e − n) mod N, m.
    right: Vec<f64>,
    /// Left-going increments: E_{e+n} in slot (e + n) mod N, m.
    left: Vec<f64>,
    /// n mod N.
    shift: usize,
    /// The dispersion the travelling waves carry, if any (docs/physics.md §6.2.1).
    transit: Option<Box<Transit>>,
}

impl Waves {
    /// A bar of `elements` elements at rest.
    fn new(elements: usize) -> Waves {
        Waves {
            right: vec![0.0; elements],
            left: vec![0.0; elements],
            shift: 0,
            transit: None,
        }
    }

    /// Slot of D_{e−n}.
    #[inline]
    fn right_slot(&self, e: usize) -> usize {
        let n = self.right.len();
        let s = e + n - self.shift;
        if s >= n { s - n } else { s }
    }

    /// Slot of E_{e+n}.
    #[inline]
    fn left_slot(&self, e: usize) -> usize {
        let n = self.left.len();
        let s = e + self.shift;
        if s >= n { s - n } else { s }
    }

    /// Right-going increment at element e at the current level: D_{e−n}, or with dispersion the
    /// wave injected e + 1 steps ago carried over e + ½ cells (at element N − 1 the arrival at
    /// the end node, over N), m.
    #[inline]
    fn d(&self, e: usize) -> f64 {
        match &self.transit {
            Some(t) if e > 0 && t.step > 0 => {
                if e + 1 == self.right.len() {
                    t.arrival[0]
                } else {
                    t.right_at(e)
                }
            }
            _ => self.right[self.right_slot(e)],
        }
    }

    /// Left-going increment at element e at the current level: E_{e+n}, or with dispersion the
    /// wave injected N − e steps ago carried over N − e − ½ cells (at element 0 the arrival at
    /// the end node, over N), m.
    #[inline]
    fn e(&self, e: usize) -> f64 {
        match &self.transit {
            Some(t) if e + 1 < self.left.len() && t.step > 0 => {
                if e == 0 {
                    t.arrival[1]
                } else {
                    t.left_at(e)
                }
            }
            _ => self.left[self.left_slot(e)],
        }
    }

    /// Stretch u_{e+1}^n − u_e^n = D_{e−n} + E_{e+n} of element e, m (without dispersion read
    /// straight from the ring buffers, the values [`Waves::d`] and [`Waves::e`] give: the x–t
    /// snapshots and the gauges read it at every sample).
    #[inline]
    fn stretch(&self, e: usize) -> f64 {
        match self.transit {
            None => self.right[self.right_slot(e)] + self.left[self.left_slot(e)],
            Some(_) => self.d(e) + self.e(e),
        }
    }

    /// Δt v_i^{n−1/2} = E_{i−1+n} − D_{i−n} of interior node i (1 ≤ i ≤ N − 1), m.
    #[inline]
    fn last_move(&self, i: usize) -> f64 {
        self.e(i - 1) - self.d(i)
    }

    /// Δt v_i^{n+1/2} = E_{i+n} − D_{i−1−n} of interior node i (1 ≤ i ≤ N − 1), m.
    #[inline]
    fn next_move(&self, i: usize) -> f64 {
        self.e(i) - self.d(i - 1)
    }

    /// One step: the end nodes move by `left_move` = Δt v_0^{n+1/2} and `right_move` = Δt v_N^{n+1/2};
    /// injects D_{−n−1} = E_n − left_move and E_{N+n} = D_{N−n−1} + right_move, m (with
    /// dispersion, E_n and D_{N−n−1} are the arrivals).
    #[inline]
    fn advance(&mut self, left_move: f64, right_move: f64) {
        let n = self.right.len();
        let d_slot = n - 1 - self.shift;
        let (arriving_left, arriving_right) = match &self.transit {
            Some(_) => (self.e(0), self.d(n - 1)),
            None => (self.left[self.shift], self.right[d_slot]),
        };
        let entering_left = arriving_left - left_move;
        let entering_right = arriving_right + right_move;
        self.right[d_slot] = entering_left;
        self.left[self.shift] = entering_right;
        self.shift = if self.shift + 1 == n {
            0
        } else {
            self.shift + 1
        };
        if let Some(t) = &mut self.transit {
            t.inject(
                entering_left,
                entering_right,
                [arriving_right, arriving_left],
            );
        }
    }

    /// Restarts the dispersive histories from the ring buffers (at step 0).
    fn restart_transit(&mut self) {
        if let Some(t) = &mut self.transit {
            t.restart(&self.right, &self.left);
        }
    }
}

/// A delay-line bar: its waves and the lumped operator of its two end nodes.
#[derive(Debug, Clone)]
pub(super) struct DelayLine {
    /// The travelling waves of the interior.
    waves: Waves,
    /// 1/(m + Δt D/2) of the two end nodes (0 at a fixed end).
    inv_end: [f64; 2],
}

impl DelayLine {
    /// A delay line of `elements` elements at rest.
    pub(super) fn new(elements: usize) -> DelayLine {
        DelayLine {
            waves: Waves::new(elements),
            inv_end: [0.0; 2],
        }
    }

    /// A dispersive delay line of `elements` elements at rest whose waves carry `design`
    /// (docs/physics.md §6.2.1).
    pub(super) fn dispersive(design: Arc<TransitDesign>, elements: usize) -> DelayLine {
        let mut line = DelayLine::new(elements);
        line.waves.transit = Some(Box::new(Transit::new(design, elements)));
        line.waves.restart_transit();
        line
    }

    /// The ring buffers of a delay line without dispersion, for the x–t snapshots to read
    /// ([`super::Bar::sample_stress`]): `(right, left, n mod N)`, the stretch of element e being
    /// `right[(e + N − n) mod N] + left[(e + n) mod N]` as [`Waves::stretch`] reads it; None
    /// for a dispersive line.
    pub(super) fn rings(&self) -> Option<(&[f64], &[f64], usize)> {
        let w = &self.waves;
        match w.transit {
            None => Some((&w.right, &w.left, w.shift)),
            Some(_) => None,
        }
    }

    /// The impulse the coming step gives the interior nodes of a dispersive delay line,
    /// Δt (k s_{N−1} − k s_0) (every spring force between them cancels), N·s; `None` for a plain one.
    fn interior_impulse(&self, c: &Nodes) -> Option<f64> {
        let w = &self.waves;
        w.transit.as_ref()?;
        let last = c.mass.len() - 1;
        Some(c.dt_s * (c.k[last - 1] * w.stretch(last - 1) - c.k[0] * w.stretch(0)))
    }
}

impl Interior for DelayLine {
    fn refresh(&mut self, c: &Nodes, damping: &[f64], fixed: [bool; 2]) {
        let last = c.mass.len() - 1;
        let dt = c.dt_s;
        for (end, node) in [(0, 0), (1, last)] {
            self.inv_end[end] = if fixed[end] {
                0.0
            } else {
                1.0 / (c.mass[node] + 0.5 * dt * damping[node])
            };
        }
    }

    fn update_free_rate(&mut self, c: &mut Nodes) {
        let last = c.u.len() - 1;
        let w = &self.waves;
        let end_rhs = c.ends.rhs(
            [c.k[0] * w.stretch(0), c.k[last - 1] * w.stretch(last - 1)],
            [c.v[0], c.v[last]],
        );
        c.w[0] = self.inv_end[0] * end_rhs[0];
        c.w[last] = self.inv_end[1] * end_rhs[1];
    }

    fn force_response(&self, c: &Nodes, i: usize, f: [f64; 2]) -> f64 {
        lumped_response(self.inv_end, i, c.u.len() - 1, f)
    }

    fn add_end_forces(&self, c: &mut Nodes, f: [f64; 2]) {
        add_lumped_forces(self.inv_end, &mut c.w, f);
    }

    fn advance(&mut self, c: &mut Nodes) {
        let dt = c.dt_s;
        let last = c.u.len() - 1;
        let v_before = [c.v[0], c.v[last]];
        let interior_impulse = self.interior_impulse(c).unwrap_or(0.0);
        for node in [0, last] {
            c.v[node] += dt * c.w[node];
            c.u[node] += dt * c.v[node];
        }
        if let Some(t) = &mut self.waves.transit {
            t.momentum_half += interior_impulse
                + c.mass[0] * (c.v[0] - v_before[0])
                + c.mass[last] * (c.v[last] - v_before[1]);
        }
        self.waves.advance(dt * c.v[0], dt * c.v[last]);
    }

    fn displacement(&self, c: &Nodes, i: usize) -> f64 {
        let last = c.u.len() - 1;
        let w = &self.waves;
        if i > 0 && i < last {
            // u_i = u_0 + Σ_{e<i} stretch_e, from the nearer end.
            if 2 * i <= last {
                c.u[0] + (0..i).map(|e| w.stretch(e)).sum::<f64>()
            } else {
                c.u[last] - (i..last).map(|e| w.stretch(e)).sum::<f64>()
            }
        } else {
            c.u[i]
        }
    }

    fn stretch(&self, _c: &Nodes, e: usize) -> f64 {
        self.waves.stretch(e)
    }

    fn stretch_between(&self, _c: &Nodes, a: (usize, f64), b: (usize, f64)) -> f64 {
        let waves = &self.waves;
        let ((la, wa), (lb, wb)) = (a, b);
        let between: f64 = if lb >= la {
            (la..lb).map(|e| waves.stretch(e)).sum()
        } else {
            -(lb..la).map(|e| waves.stretch(e)).sum::<f64>()
        };
        between + wb * waves.stretch(lb) - wa * waves.stretch(la)
    }

    fn half_step_velocity(&self, c: &Nodes, i: usize) -> f64 {
        if i > 0 && i + 1 < c.v.len() {
            self.waves.last_move(i) / c.dt_s
        } else {
            c.v[i]
        }
    }

    fn velocity(&self, c: &Nodes, i: usize) -> f64 {
        let w = &self.waves;
        if i > 0 && i + 1 < c.v.len() {
            0.5 * (w.last_move(i) + w.next_move(i)) / c.dt_s
        } else {
            c.v[i] + 0.5 * c.dt_s * (c.w[i] + self.force_response(c, i, c.ends.last_force))
        }
    }

    /// For a dispersive delay line (whose interior reads cost a convolution each) from its
    /// impulse ledger: Σ m v^{n−1/2} carried by the end velocities' changes and the end springs'
    /// forces, plus half the coming step's.
    fn momentum(&self, c: &Nodes) -> f64 {
        let last = c.mass.len() - 1;
        match (self.interior_impulse(c), &self.waves.transit) {
            (Some(interior), Some(t)) => {
                let coming = interior
                    + [0, last]
                        .iter()
                        .map(|&i| {
                            c.mass[i]
                                * c.dt_s
                                * (c.w[i] + self.force_response(c, i, c.ends.last_force))
                        })
                        .sum::<f64>();
                t.momentum_half + 0.5 * coming
            }
            _ => node_momentum(self, c),
        }
    }

    fn kinetic_energy(&self, c: &Nodes) -> f64 {
        let w = &self.waves;
        let last = c.mass.len() - 1;
        let dt = c.dt_s;
        let interior: f64 = (1..last)
            .map(|i| {
                let v = w.last_move(i) / dt;
                c.mass[i] * v * v
            })
            .sum();
        let ends = c.mass[0] * c.v[0] * c.v[0] + c.mass[last] * c.v[last] * c.v[last];
        0.5 * (interior + ends)
    }

    fn strain_energy(&self, c: &Nodes) -> f64 {
        let dt = c.dt_s;
        let w = &self.waves;
        let v = |i: usize| self.half_step_velocity(c, i);
        0.5 * (0..c.k.len())
            .map(|e| {
                let du = w.stretch(e);
                c.k[e] * du * (du - dt * (v(e + 1) - v(e)))
            })
            .sum::<f64>()
    }

    fn set_rigid_velocity(&mut self, c: &Nodes, v_m_s: f64, name: &str, step_index: usize) {
        let w = &mut self.waves;
        // Rigid motion: every interior node moves Δt v, every element is unstretched.
        let half = 0.5 * c.dt_s * v_m_s;
        w.right.fill(-half);
        w.left.fill(half);
        assert!(
            w.transit.is_none() || step_index == 0,
            "bar {name}: a dispersive delay line is set moving only before its first step",
        );
        w.restart_transit();
    }

    fn rebase(&mut self, c: &Nodes) {
        if self.waves.transit.is_some() {
            let momentum: f64 = (0..c.mass.len())
                .map(|i| c.mass[i] * self.half_step_velocity(c, i))
                .sum();
            if let Some(t) = &mut self.waves.transit {
                t.momentum_half = momentum;
            }
        }
    }

    fn transit(&self) -> Option<&Transit> {
        self.waves.transit.as_deref()
    }

    fn is_delay_line(&self) -> bool {
        true
    }

    fn materialise(&self, c: &mut Nodes, name: &str) -> Option<Leapfrog> {
        assert!(
            self.waves.transit.is_none(),
            "bar {name}: a dispersive delay line takes added masses only at its end nodes",
        );
        let w = &self.waves;
        let last = c.u.len() - 1;
        let mut u = c.u[0];
        for i in 1..last {
            u += w.stretch(i - 1);
            c.u[i] = u;
            c.v[i] = (w.left[w.left_slot(i - 1)] - w.right[w.right_slot(i)]) / c.dt_s;
        }
        Some(Leapfrog::new(c.u.len()))
    }

    fn first_non_finite(&self, c: &Nodes) -> Option<(&'static str, usize, f64)> {
        let w = &self.waves;
        if let Some(t) = &w.transit {
            for (what, value, node) in [
                ("right-going wave arriving", t.arrival[0], c.u.len() - 1),
                ("left-going wave arriving", t.arrival[1], 0),
            ] {
                if !value.is_finite() {
                    return Some((what, node, value));
                }
            }
        }
        // D_{e−n} enters v_e, E_{e+n} enters v_{e+1} (docs/physics.md §6.2, "Delay lines").
        for e in 0..w.right.len() {
            for (what, value, node) in [
                ("right-going wave", w.right[w.right_slot(e)], e),
                ("left-going wave", w.left[w.left_slot(e)], e + 1),
            ] {
                if !value.is_finite() {
                    return Some((what, node, value));
                }
            }
        }
        None
    }

    #[cfg(test)]
    fn set_half_step_velocity(&mut self, c: &mut Nodes, i: usize, v_m_s: f64) {
        let w = &mut self.waves;
        if i > 0 && i + 1 < c.v.len() {
            // Δt v_i^{n−1/2} = E_{i−1+n} − D_{i−n}.
            let slot = w.left_slot(i - 1);
            w.left[slot] = w.right[w.right_slot(i)] + c.dt_s * v_m_s;
        } else {
            c.v[i] = v_m_s;
        }
    }
}

#[cfg(test)]
mod tests {
    //! The delay line (docs/physics.md §6.2, "Delay lines") against the leapfrog on every node:
    //! the same discrete solution to rounding, and the same energy identity.
    use super::super::{
        Bar, BarMaterial, BarScheme, BarSpec, Dispersion, EndCondition, Segment,
        rigid_contact_force_n, set_thread_bar_scheme,
    };
    use std::f64::consts::PI;

    /// Steel, 19.05 mm (the authors' bars).
    fn steel_segment(length_m: f64) -> Segment {
        Segment {
            length_m,
            diameter_m: 0.01905,
            material: BarMaterial {
                density_kg_m3: 7850.0,
                youngs_modulus_pa: 200e9,
                poisson_ratio: 0.29,
            },
        }
    }

    fn spec(length_m: f64, left: EndCondition, right: EndCondition) -> BarSpec {
        BarSpec {
            name: "probe".into(),
            segments: vec![steel_segment(length_m)],
            left_end: left,
            right_end: right,
            dispersion: Dispersion::None,
        }
    }

    /// Largest |a − b| over the largest |a| of a series (the outputs' tolerance measure).
    fn series_difference(a: &[f64], b: &[f64]) -> f64 {
        assert_eq!(a.len(), b.len());
        let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let diff = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(scale > 0.0, "an empty series proves nothing");
        diff / scale
    }

    /// Every element strain, node velocity (half and whole level), end force, end displacement
    /// and energy of a bar at one level, flattened by kind.
    fn state(bar: &Bar) -> Vec<Vec<f64>> {
        let n = bar.node_count();
        vec![
            (0..bar.element_count())
                .map(|e| bar.element_strain(e))
                .collect(),
            (0..n).map(|i| bar.half_step_velocity_m_s(i)).collect(),
            (0..n).map(|i| bar.velocity_m_s(i)).collect(),
            vec![bar.end_force_n(false), bar.end_force_n(true)],
            vec![bar.displacement_m(0), bar.displacement_m(n - 1)],
            vec![
                bar.displacement_m(n / 3) - bar.displacement_m(0),
                bar.stretch_between_m(0.1003, 0.1051),
                bar.strain_at(0.2507),
            ],
            vec![bar.recomputed_energy_j(), bar.energy_j()],
        ]
    }

    /// A free (fixed, absorbing) bar moving at 7 m/s, pushed at its left end by a half-sine
    /// and pulled at its right end: every quantity of the delay line equals the leapfrog's to 1e-12
    /// of its series maximum over 3 transits.
    #[test]
    fn a_moving_bar_under_end_forces_is_the_leapfrog_to_rounding() {
        for (left, right) in [
            (EndCondition::Free, EndCondition::Free),
            (EndCondition::Free, EndCondition::Fixed),
            (EndCondition::Absorbing, EndCondition::Free),
            (EndCondition::Fixed, EndCondition::Absorbing),
        ] {
            let s = spec(0.4, left, right);
            let dt = Bar::courant_time_step(&s, 400);
            let mut fd = Bar::with_scheme(&s, dt, BarScheme::FiniteDifference).unwrap();
            let mut dl = Bar::with_scheme(&s, dt, BarScheme::Auto).unwrap();
            assert!(dl.is_delay_line() && !fd.is_delay_line());
            for b in [&mut fd, &mut dl] {
                b.add_node_mass(0, 2e-3);
                b.set_initial_velocity(7.0);
            }
            let mut series: Vec<Vec<Vec<f64>>> = vec![Vec::new(); 2];
            for n in 0..1200 {
                let t = n as f64 / 150.0;
                let push = if t < 1.0 { 4e4 * (PI * t).sin() } else { 0.0 };
                let pull = if (2.0..3.0).contains(&t) {
                    -1e4 * (PI * t).sin().powi(2)
                } else {
                    0.0
                };
                for (k, b) in [&mut fd, &mut dl].into_iter().enumerate() {
                    b.step(push, pull);
                    if n % 7 == 0 {
                        series[k].push(state(b).concat());
                    }
                }
            }
            let kinds = state(&fd).len();
            let mut worst = vec![0.0f64; kinds];
            let widths: Vec<usize> = state(&fd).iter().map(Vec::len).collect();
            for kind in 0..kinds {
                let offset: usize = widths[..kind].iter().sum();
                for j in 0..widths[kind] {
                    let pick = |k: usize| -> Vec<f64> {
                        series[k].iter().map(|row| row[offset + j]).collect()
                    };
                    let (a, b) = (pick(0), pick(1));
                    if a.iter().all(|&x| x == 0.0) {
                        assert!(b.iter().all(|&x| x.abs() < 1e-300), "{left:?}/{right:?}");
                        continue;
                    }
                    let d = series_difference(&a, &b);
                    worst[kind] = worst[kind].max(d);
                }
            }
            // The leapfrog carries u ≈ 1e-2 m and takes strains and forces as differences of it,
            // so each holds ~ulp(u)/Δx of rounding that grows as √n: 4e-11 of the series maximum
            // here (3e-12 with the bar at rest at first), which bounds the agreement. The delay
            // line carries the stretches themselves. Quantities that are not differences of u
            // agree closer: the energies to 1e-14.
            let tolerance = [1e-10, 1e-10, 1e-11, 1e-10, 1e-12, 1e-10, 1e-13];
            for kind in 0..kinds {
                assert!(
                    worst[kind] < tolerance[kind],
                    "{left:?}/{right:?}: kind {kind}: {:e}",
                    worst[kind]
                );
            }
            fd.check_energy_ledger(0.0).unwrap();
            dl.check_energy_ledger(0.0).unwrap();
        }
    }

    /// A striker on a bar through [`rigid_contact_force_n`] (a butt joint), the bar's far end
    /// absorbing: the contact force and the strain at a gauge agree with the leapfrog to 1e-12 of
    /// their maxima.
    #[test]
    fn a_striker_on_a_bar_is_the_leapfrog_to_rounding() {
        let run = |scheme: BarScheme| {
            let striker = spec(0.1, EndCondition::Free, EndCondition::Free);
            let incident = spec(1.2, EndCondition::Free, EndCondition::Absorbing);
            let dt = Bar::courant_time_step(&striker, 100);
            let mut s = Bar::with_scheme(&striker, dt, scheme).unwrap();
            let mut b = Bar::with_scheme(&incident, dt, scheme).unwrap();
            assert_eq!(
                s.is_delay_line() && b.is_delay_line(),
                scheme == BarScheme::Auto
            );
            s.set_initial_velocity(9.0);
            let (mut force, mut gauge) = (Vec::new(), Vec::new());
            for _ in 0..1500 {
                let f = rigid_contact_force_n(&s, &b, 0.0);
                s.step(0.0, -f);
                b.step(f, 0.0);
                force.push(f);
                gauge.push(b.strain_at(0.6));
            }
            (force, gauge, b.absorbed_energy_j())
        };
        let (f0, g0, a0) = run(BarScheme::FiniteDifference);
        let (f1, g1, a1) = run(BarScheme::Auto);
        assert!(series_difference(&f0, &f1) < 1e-12);
        assert!(series_difference(&g0, &g1) < 1e-12);
        assert!((a0 - a1).abs() < 1e-12 * a0);
    }

    /// The delay line keeps the scheme's energy identity: kinetic + strain energy recomputed from
    /// the waves equals the initial energy plus the end work less the absorbed energy, to 1e-13.
    #[test]
    fn a_delay_line_conserves_the_discrete_energy() {
        let s = spec(0.3, EndCondition::Free, EndCondition::Absorbing);
        let dt = Bar::courant_time_step(&s, 300);
        let mut bar = Bar::new(&s, dt).unwrap();
        assert!(bar.is_delay_line());
        bar.set_initial_velocity(-3.0);
        let e0 = bar.recomputed_energy_j();
        for n in 0..2000 {
            let f = if n < 80 {
                2e4 * (PI * n as f64 / 80.0).sin()
            } else {
                0.0
            };
            bar.step(f, 0.0);
            let balance = e0 + bar.work_done_j() - bar.absorbed_energy_j();
            let full = bar.recomputed_energy_j();
            assert!(
                (full - balance).abs() < 1e-13 * bar.energy_turnover_j(),
                "step {n}: {full} vs {balance}"
            );
        }
        // Everything has left through the absorbing end.
        assert!(bar.recomputed_energy_j().abs() < 1e-12 * bar.energy_turnover_j());
    }

    /// Only what is exact runs as a delay line: a bar at Courant < 1, a Love rod and a bar of two
    /// segments run the leapfrog; an interior node mass turns a delay line into the leapfrog
    /// with the same state.
    #[test]
    fn a_delay_line_only_where_it_is_exact() {
        let s = spec(0.3, EndCondition::Free, EndCondition::Free);
        let dt = Bar::courant_time_step(&s, 300);
        assert!(Bar::new(&s, dt).unwrap().is_delay_line());
        assert!(!Bar::new(&s, dt * 0.999).unwrap().is_delay_line());
        let love = BarSpec {
            dispersion: Dispersion::LoveRod,
            ..s.clone()
        };
        assert!(!Bar::new(&love, dt).unwrap().is_delay_line());
        let two = BarSpec {
            segments: vec![steel_segment(0.1), steel_segment(0.2)],
            ..s.clone()
        };
        assert!(!Bar::new(&two, dt).unwrap().is_delay_line());
        let previous = set_thread_bar_scheme(BarScheme::FiniteDifference);
        assert!(!Bar::new(&s, dt).unwrap().is_delay_line());
        set_thread_bar_scheme(previous);

        let mut bar = Bar::new(&s, dt).unwrap();
        bar.set_initial_velocity(2.0);
        for n in 0..150 {
            bar.step(if n < 30 { 1e4 } else { 0.0 }, 0.0);
        }
        let before = state(&bar);
        bar.add_node_mass(100, 0.0);
        assert!(!bar.is_delay_line());
        let after = state(&bar);
        // Strains and velocities (a free end's force is rounding of u: nothing to compare).
        for (a, b) in before.iter().zip(&after).take(3) {
            let d = series_difference(a, b);
            assert!(d < 1e-12, "{a:?} vs {b:?}: {d:e}");
        }
    }
}
