//! The lumped grid of a bar for one time step and its exact stability limit: cells per segment,
//! node masses and element stiffnesses, Sturm-sequence bisection of K − σM (docs/physics.md §6.2,
//! "Grid" and "Stability").

use super::{Bar, BarSpec, Dispersion, EndCondition, MAX_NODES};
use crate::error::Result;

/// Relative slack for rounding in the cell count ⌊L/(cΔt)⌋ (so an exact multiple is not lost).
const CELL_COUNT_SLACK: f64 = 1e-12;

/// Relative slack for rounding when comparing Δt with the stability limit (Courant 1 sits on it).
pub(super) const STABILITY_SLACK: f64 = 1e-9;

impl BarSpec {
    /// Cells per segment for time step Δt: n_k = ⌊L_k/(c_k Δt)⌋ ≥ 1, so Courant ≤ 1 (docs/physics.md §6.2).
    pub fn cells_for_time_step(&self, dt_s: f64) -> Vec<usize> {
        self.segments
            .iter()
            .map(|s| {
                let x = s.length_m / (s.material.wave_speed_m_s() * dt_s);
                // `as` saturates; NaN gives 0, lifted to 1.
                ((x * (1.0 + CELL_COUNT_SLACK)).floor() as usize).max(1)
            })
            .collect()
    }

    /// Largest Δt at which every segment holds at least one cell of Courant ≤ 1, min_k L_k/c_k, s (always stable).
    pub fn courant_limit_s(&self) -> f64 {
        self.segments
            .iter()
            .map(|s| s.length_m / s.material.wave_speed_m_s())
            .fold(f64::INFINITY, f64::min)
    }

    /// Exact stability limit 2/√λ_max (K φ = λ M φ, Sturm bisection) of the grid with `cells[k]` cells in segment k, s.
    pub fn stability_limit_s(&self, cells: &[usize]) -> Result<f64> {
        self.validate()?;
        let v = self.validator();
        if cells.len() != self.segments.len() || cells.contains(&0) {
            return Err(v.error(
                "cells",
                format!(
                    "{} cell counts given for {} segments",
                    cells.len(),
                    self.segments.len()
                ),
                "one cell count ≥ 1 per segment",
            ));
        }
        let total = cells.iter().fold(0usize, |a, &c| a.saturating_add(c));
        if total >= MAX_NODES {
            return Err(v.error(
                "cells",
                format!("{total} cells"),
                format!("fewer than {MAX_NODES}"),
            ));
        }
        Ok(self.grid_stability_limit_s(cells))
    }

    /// Stability limit of the grid with `cells` (validated spec and cell counts).
    fn grid_stability_limit_s(&self, cells: &[usize]) -> f64 {
        let grid = Grid::build(self, cells);
        let (lo, hi) = free_range(self, grid.mass.len());
        grid.stability_limit_s(lo, hi)
    }

    /// Largest Δt that [`Bar::new`] accepts (to ~1e-6), s: iterates Δt ← 2/√λ_max(grid(Δt)) down
    /// from max_k L_k/c_k (the grid, hence its limit, changes with Δt); at least [`Self::courant_limit_s`].
    pub fn max_time_step_s(&self) -> Result<f64> {
        self.validate()?;
        let floor = self.courant_limit_s();
        let mut dt = self
            .segments
            .iter()
            .map(|s| s.length_m / s.material.wave_speed_m_s())
            .fold(0.0, f64::max);
        for _ in 0..200 {
            if dt <= floor {
                break;
            }
            let cells = self.cells_for_time_step(dt);
            if cells.iter().fold(0usize, |a, &c| a.saturating_add(c)) >= MAX_NODES {
                break;
            }
            let limit = self.grid_stability_limit_s(&cells);
            if dt <= limit * (1.0 + STABILITY_SLACK) {
                return Ok(dt);
            }
            dt = limit * (1.0 - 1e-6);
        }
        Ok(floor)
    }
}

/// Grid data of one segment.
#[derive(Debug, Clone, Copy)]
pub(super) struct SegmentGrid {
    /// Position of the segment's left end, m.
    pub(super) x0_m: f64,
    /// Its length, m.
    pub(super) length_m: f64,
    /// Index of its first element.
    pub(super) first_element: usize,
    /// Number of cells.
    pub(super) cells: usize,
    /// Cell size, m.
    pub(super) dx_m: f64,
    /// Young's modulus, Pa.
    pub(super) youngs_modulus_pa: f64,
    /// Bar wave speed c0, m/s.
    pub(super) wave_speed_m_s: f64,
}

/// The lumped chain of a bar: node positions and masses, element stiffnesses, Love coefficients.
pub(super) struct Grid {
    pub(super) x: Vec<f64>,
    pub(super) mass: Vec<f64>,
    pub(super) k: Vec<f64>,
    /// ρν²J/Δx per element (empty without the Love term).
    pub(super) beta: Vec<f64>,
    pub(super) segments: Vec<SegmentGrid>,
}

impl SegmentGrid {
    /// Courant number c Δt/Δx of the segment at time step Δt.
    pub(super) fn courant_number(&self, dt_s: f64) -> f64 {
        self.wave_speed_m_s * dt_s / self.dx_m
    }
}

impl Grid {
    /// Assembles the chain for `cells[k]` cells in segment k (docs/physics.md §6.2).
    pub(super) fn build(spec: &BarSpec, cells: &[usize]) -> Grid {
        let elements: usize = cells.iter().sum();
        let love = spec.dispersion == Dispersion::LoveRod;
        let mut x = Vec::with_capacity(elements + 1);
        let mut mass = vec![0.0; elements + 1];
        let mut k = Vec::with_capacity(elements);
        let mut beta = Vec::with_capacity(if love { elements } else { 0 });
        let mut segments = Vec::with_capacity(spec.segments.len());
        x.push(0.0);
        let mut x0 = 0.0;
        let mut e = 0;
        for (s, &n) in spec.segments.iter().zip(cells) {
            let dx = s.length_m / n as f64;
            let area = s.area_m2();
            let half_cell_mass = 0.5 * s.material.density_kg_m3 * area * dx;
            let stiffness = s.material.youngs_modulus_pa * area / dx;
            let lateral = s.material.density_kg_m3
                * s.material.poisson_ratio
                * s.material.poisson_ratio
                * s.polar_moment_m4()
                / dx;
            segments.push(SegmentGrid {
                x0_m: x0,
                length_m: s.length_m,
                first_element: e,
                cells: n,
                dx_m: dx,
                youngs_modulus_pa: s.material.youngs_modulus_pa,
                wave_speed_m_s: s.material.wave_speed_m_s(),
            });
            for j in 0..n {
                mass[e] += half_cell_mass;
                mass[e + 1] += half_cell_mass;
                k.push(stiffness);
                if love {
                    beta.push(lateral);
                }
                x.push(x0 + s.length_m * (j + 1) as f64 / n as f64);
                e += 1;
            }
            x0 += s.length_m;
        }
        Grid {
            x,
            mass,
            k,
            beta,
            segments,
        }
    }

    /// Gershgorin bound max_i 2(k_{i−1} + k_i)/m_i ≥ λ_max over the free nodes lo..=hi (lumped mass).
    pub(super) fn gershgorin(&self, lo: usize, hi: usize) -> f64 {
        let ne = self.k.len();
        (lo..=hi)
            .map(|i| {
                let kl = if i > 0 { self.k[i - 1] } else { 0.0 };
                let kr = if i < ne { self.k[i] } else { 0.0 };
                2.0 * (kl + kr) / self.mass[i]
            })
            .fold(0.0, f64::max)
    }

    /// Number of eigenvalues of K φ = λ M φ (free nodes lo..=hi) below σ: negative pivots of K − σM.
    fn count_below(&self, sigma: f64, lo: usize, hi: usize) -> usize {
        let ne = self.k.len();
        let beta = |e: usize| {
            if self.beta.is_empty() {
                0.0
            } else {
                self.beta[e]
            }
        };
        let mut count = 0;
        let mut q_prev = 1.0;
        for i in lo..=hi {
            let (kl, bl) = if i > 0 {
                (self.k[i - 1], beta(i - 1))
            } else {
                (0.0, 0.0)
            };
            let (kr, br) = if i < ne {
                (self.k[i], beta(i))
            } else {
                (0.0, 0.0)
            };
            let diag = (kl + kr) - sigma * (self.mass[i] + bl + br);
            let mut q = if i > lo {
                // Off-diagonal of K − σM between i−1 and i: −k_{i−1} + σ β_{i−1}.
                let off = -kl + sigma * bl;
                diag - off * off / q_prev
            } else {
                diag
            };
            if q == 0.0 {
                q = -f64::EPSILON * ((kl + kr).abs() + (sigma * self.mass[i]).abs());
            }
            if q < 0.0 {
                count += 1;
            }
            q_prev = q;
        }
        count
    }

    /// Stability limit 2/√λ_max of the free nodes lo..=hi, s (∞ without degrees of freedom).
    pub(super) fn stability_limit_s(&self, lo: usize, hi: usize) -> f64 {
        if lo > hi {
            return f64::INFINITY;
        }
        let n = hi - lo + 1;
        let (mut a, mut b) = (
            0.0,
            self.gershgorin(lo, hi) * (1.0 + 1e-6) + f64::MIN_POSITIVE,
        );
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if self.count_below(mid, lo, hi) >= n {
                b = mid;
            } else {
                a = mid;
            }
            if b - a <= 1e-15 * b {
                break;
            }
        }
        if b <= 0.0 {
            f64::INFINITY
        } else {
            2.0 / b.sqrt()
        }
    }
}

/// The nodes that can move: 0..=N without the fixed ends.
pub(super) fn free_range(spec: &BarSpec, nodes: usize) -> (usize, usize) {
    let lo = usize::from(spec.left_end == EndCondition::Fixed);
    let hi = nodes - 1 - usize::from(spec.right_end == EndCondition::Fixed);
    (lo, hi)
}

impl Bar {
    /// Exact stability limit 2/√λ_max of this grid (current masses; Sturm bisection), s.
    pub fn stability_limit_s(&self) -> f64 {
        let n = self.nodes.u.len();
        let lo = usize::from(self.nodes.ends.condition[0] == EndCondition::Fixed);
        let hi = n - 1 - usize::from(self.nodes.ends.condition[1] == EndCondition::Fixed);
        let grid = Grid {
            x: Vec::new(),
            mass: self.nodes.mass.clone(),
            k: self.nodes.k.clone(),
            beta: self.interior.get().lateral_mass().to_vec(),
            segments: Vec::new(),
        };
        grid.stability_limit_s(lo, hi)
    }
}
