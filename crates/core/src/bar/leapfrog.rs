//! The lumped-mass chain advanced node by node by the leapfrog (docs/physics.md §6.2): a
//! diagonal mass operator 1/(m_i + Δt D_i/2); the node-field helpers here serve the Love rod too
//! ([`super::love`]).

use super::ends::{add_lumped_forces, lumped_response};
use super::{Interior, Nodes};

/// The lumped chain on every node (docs/physics.md §6.2).
#[derive(Debug, Clone)]
pub(super) struct Leapfrog {
    /// 1/(m_i + Δt D_i/2) (0 at a fixed node).
    inv_a: Vec<f64>,
    /// Scratch: element forces (tension), N.
    tension: Vec<f64>,
}

impl Leapfrog {
    /// The chain of `nodes` nodes ([`Interior::refresh`] sets its operator).
    pub(super) fn new(nodes: usize) -> Leapfrog {
        Leapfrog {
            inv_a: vec![0.0; nodes],
            tension: vec![0.0; nodes - 1],
        }
    }

    /// 1/(m + Δt D/2) of the two end nodes.
    fn inv_ends(&self) -> [f64; 2] {
        [self.inv_a[0], self.inv_a[self.inv_a.len() - 1]]
    }
}

/// Element tensions k_e (u_{e+1} − u_e) into `tension`, N.
pub(super) fn tensions(c: &Nodes, tension: &mut [f64]) {
    for ((t, uu), &kk) in tension.iter_mut().zip(c.u.windows(2)).zip(&c.k) {
        *t = kk * (uu[1] - uu[0]);
    }
}

/// v^{n+1/2} = v^{n−1/2} + Δt w and u^{n+1} = u^n + Δt v^{n+1/2} on every node.
pub(super) fn advance_nodes(c: &mut Nodes) {
    let dt = c.dt_s;
    for ((ui, vi), &wi) in c.u.iter_mut().zip(c.v.iter_mut()).zip(&c.w) {
        *vi += dt * wi;
        *ui += dt * *vi;
    }
}

/// Σ m v² of the nodes at n − 1/2 (twice the lumped kinetic energy), J.
pub(super) fn lumped_kinetic(c: &Nodes) -> f64 {
    c.mass.iter().zip(&c.v).map(|(m, v)| m * v * v).sum()
}

/// Strain energy ½ u^{n−1}ᵀ K u^n = ½ Σ k Δu (Δu − Δt Δv) of the nodes' field, J.
pub(super) fn node_strain_energy(c: &Nodes) -> f64 {
    let dt = c.dt_s;
    0.5 * c
        .k
        .iter()
        .zip(c.u.windows(2).zip(c.v.windows(2)))
        .map(|(k, (uu, vv))| {
            let du = uu[1] - uu[0];
            k * du * (du - dt * (vv[1] - vv[0]))
        })
        .sum::<f64>()
}

impl Interior for Leapfrog {
    fn refresh(&mut self, c: &Nodes, damping: &[f64], fixed: [bool; 2]) {
        let n = c.mass.len();
        let dt = c.dt_s;
        for (ia, (&m, &d)) in self.inv_a.iter_mut().zip(c.mass.iter().zip(damping)) {
            *ia = 1.0 / (m + 0.5 * dt * d);
        }
        if fixed[0] {
            self.inv_a[0] = 0.0;
        }
        if fixed[1] {
            self.inv_a[n - 1] = 0.0;
        }
    }

    fn update_free_rate(&mut self, c: &mut Nodes) {
        let last = c.u.len() - 1;
        tensions(c, &mut self.tension);
        let end_rhs = c.ends.rhs(
            [self.tension[0], self.tension[last - 1]],
            [c.v[0], c.v[last]],
        );
        for ((wi, t), &ia) in c.w[1..last]
            .iter_mut()
            .zip(self.tension.windows(2))
            .zip(&self.inv_a[1..last])
        {
            *wi = ia * (t[1] - t[0]);
        }
        c.w[0] = self.inv_a[0] * end_rhs[0];
        c.w[last] = self.inv_a[last] * end_rhs[1];
    }

    fn force_response(&self, c: &Nodes, i: usize, f: [f64; 2]) -> f64 {
        lumped_response(self.inv_ends(), i, c.u.len() - 1, f)
    }

    fn add_end_forces(&self, c: &mut Nodes, f: [f64; 2]) {
        add_lumped_forces(self.inv_ends(), &mut c.w, f);
    }

    fn kinetic_energy(&self, c: &Nodes) -> f64 {
        // Σ m v² is never −0, so adding no lateral term changes nothing.
        0.5 * lumped_kinetic(c)
    }

    fn strain_energy(&self, c: &Nodes) -> f64 {
        node_strain_energy(c)
    }
}
