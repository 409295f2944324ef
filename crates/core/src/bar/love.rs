//! The Love rod (docs/physics.md §6.3): the lateral inertia ρν²J(u̇')² of each cell adds
//! β = ρν²J/Δx·[1 −1; −1 1] to the mass matrix, which becomes tridiagonal, is factorised once
//! (Thomas algorithm) and solved each step in O(N); the field is the leapfrog's on every node
//! ([`super::leapfrog`]).

use super::leapfrog::{lumped_kinetic, node_strain_energy, tensions};
use super::{Interior, Nodes};
use crate::numeric::Tridiagonal;

/// The Love rod on every node: factorised M + β-terms + ΔtD/2 and the responses to unit end forces.
#[derive(Debug, Clone)]
pub(super) struct LoveRod {
    /// ρν²J/Δx per element.
    beta: Vec<f64>,
    /// Factorised A = M_L + Δt D/2 (fixed nodes: identity rows).
    matrix: Tridiagonal,
    /// A⁻¹ e_0 and A⁻¹ e_N (zero for a fixed end).
    response: [Vec<f64>; 2],
    /// Scratch: element forces (tension), N.
    tension: Vec<f64>,
}

impl LoveRod {
    /// The rod of `nodes` nodes with the Love coefficients `beta` ([`Interior::refresh`] factorises it).
    pub(super) fn new(beta: Vec<f64>, nodes: usize) -> LoveRod {
        LoveRod {
            beta,
            matrix: Tridiagonal::factor(&[1.0], Vec::new()),
            response: [Vec::new(), Vec::new()],
            tension: vec![0.0; nodes - 1],
        }
    }
}

impl Interior for LoveRod {
    fn refresh(&mut self, c: &Nodes, damping: &[f64], fixed: [bool; 2]) {
        let n = c.mass.len();
        let dt = c.dt_s;
        let b = &self.beta;
        let mut diag: Vec<f64> = (0..n)
            .map(|i| {
                let bl = if i > 0 { b[i - 1] } else { 0.0 };
                let br = if i + 1 < n { b[i] } else { 0.0 };
                c.mass[i] + bl + br + 0.5 * dt * damping[i]
            })
            .collect();
        let mut off: Vec<f64> = b.iter().map(|&be| -be).collect();
        if fixed[0] {
            diag[0] = 1.0;
            off[0] = 0.0;
        }
        if fixed[1] {
            diag[n - 1] = 1.0;
            off[n - 2] = 0.0;
        }
        self.matrix = Tridiagonal::factor(&diag, off);
        for (end, node) in [(0usize, 0usize), (1, n - 1)] {
            let mut r = vec![0.0; n];
            if !fixed[end] {
                r[node] = 1.0;
                self.matrix.solve(&mut r);
            }
            self.response[end] = r;
        }
    }

    fn update_free_rate(&mut self, c: &mut Nodes) {
        let last = c.u.len() - 1;
        tensions(c, &mut self.tension);
        let end_rhs = c.ends.rhs(
            [self.tension[0], self.tension[last - 1]],
            [c.v[0], c.v[last]],
        );
        for (wi, t) in c.w[1..last].iter_mut().zip(self.tension.windows(2)) {
            *wi = t[1] - t[0];
        }
        let fixed = c.ends.fixed();
        c.w[0] = if fixed[0] { 0.0 } else { end_rhs[0] };
        c.w[last] = if fixed[1] { 0.0 } else { end_rhs[1] };
        self.matrix.solve(&mut c.w);
    }

    fn force_response(&self, _c: &Nodes, i: usize, f: [f64; 2]) -> f64 {
        f[0] * self.response[0][i] + f[1] * self.response[1][i]
    }

    fn add_end_forces(&self, c: &mut Nodes, f: [f64; 2]) {
        for (end, &fe) in f.iter().enumerate() {
            if fe != 0.0 {
                for (wi, &g) in c.w.iter_mut().zip(&self.response[end]) {
                    *wi += fe * g;
                }
            }
        }
    }

    fn kinetic_energy(&self, c: &Nodes) -> f64 {
        let lumped = lumped_kinetic(c);
        let lateral: f64 = self
            .beta
            .iter()
            .zip(c.v.windows(2))
            .map(|(b, vv)| b * (vv[1] - vv[0]).powi(2))
            .sum();
        0.5 * (lumped + lateral)
    }

    fn strain_energy(&self, c: &Nodes) -> f64 {
        node_strain_energy(c)
    }

    fn lateral_mass(&self) -> &[f64] {
        &self.beta
    }
}
