//! The bars: 1D longitudinal waves `ρA ü = ∂/∂x(EA ∂u/∂x)` (docs/physics.md §6) on a lumped-mass
//! chain advanced by the explicit central-difference (leapfrog) scheme, with optional Love-rod
//! lateral inertia `ρA ü = EA u'' + ρν²J ü''` (J = πa⁴/2).
//!
//! Conventions: x runs from the left end of the bar; displacements, velocities and external
//! forces are positive toward +x; strain, stress and element forces are positive in tension.
//!
//! **Grid.** A bar is a list of uniform segments. For a time step Δt, segment k (length L_k, wave
//! speed c_k) gets n_k = ⌊L_k/(c_k Δt)⌋ ≥ 1 cells of size Δx_k = L_k/n_k, so its Courant number
//! r_k = c_k Δt/Δx_k is ≤ 1, and = 1 when L_k is a multiple of c_k Δt. Nodes sit at the cell
//! boundaries; each cell is a spring k = EA/Δx and gives half its mass ρAΔx to each of its two
//! nodes, so a node on an interface carries half a cell of each segment. At Courant 1 the
//! uniform chain reproduces d'Alembert's solution exactly at the nodes (no numerical
//! dispersion), a free end is an exact mirror (its half-mass node acts as a ghost node
//! u_{N+1} = u_{N−1}), a fixed end an exact antimirror, and an interface node between two
//! Courant-1 segments reflects and transmits any pulse with the exact impedance coefficients
//! (displacement: (Z1−Z2)/(Z1+Z2) and 2Z1/(Z1+Z2); Z = ρ c0 A).
//!
//! **Scheme.** With u^n at integer and v^{n−1/2} at half time levels,
//! `M (v^{n+1/2} − v^{n−1/2}) = Δt (f_int(u^n) + f_ext^n − D (v^{n+1/2} + v^{n−1/2})/2)` and
//! `u^{n+1} = u^n + Δt v^{n+1/2}`, where M is the lumped mass matrix (plus the Love term),
//! f_int = −K u the spring forces and D the absorbing-end dashpots taken at the mid-step velocity.
//!
//! **Absorbing ends.** A dashpot Z = ρ c0 A on the half-mass end node. Taken at the mid-step
//! velocity (trapezoidal rule) and at Courant 1 (m/2 + ZΔt/2 = m), the end-node update becomes
//! `v^{n+1/2} = (u_{N−1}^n − u_N^n)/Δt`, i.e. `u_N^{n+1} = u_{N−1}^n`: the exact one-way
//! (characteristic) update, so the end is exactly non-reflecting for any pulse shape. (An
//! explicit dashpot −Z v^{n−1/2} gives `v^{n+1/2} = 2(u_{N−1}^n − u_N^n)/Δt − v^{n−1/2}` instead, which
//! reflects.) In a segment at Courant r < 1 a harmonic wave (θ = κΔx, Ω = ωΔt,
//! sin(Ω/2) = r sin(θ/2)) is reflected with the displacement coefficient
//! `R = (sin θ − sin Ω / r)/(sin θ + sin Ω / r) ≈ −(1 − r²) θ²/16` (derived from the end-node
//! equation). On a Love rod the wave impedance is Z/√(1 + ν²k²a²/2), so the dashpot reflects about
//! ν²k²a²/8 of the amplitude (continuum estimate).
//!
//! **Love rod.** The lateral kinetic energy ½ρν²J(u̇')² of each cell adds β = ρν²J/Δx·[1 −1; −1 1] to
//! the mass matrix, which becomes tridiagonal (M + β tridiag(−1, 2, −1) in a uniform interior); it is
//! factorised once (Thomas algorithm) and solved each step in O(N). On a uniform grid the scheme's
//! dispersion relation is `sin²(ωΔt/2)(1 + 4γS²) = r²S²`, S = sin(κΔx/2), γ = ν²a²/(2Δx²); at
//! Courant 1 it agrees with the Rayleigh–Love relation `c/c0 = 1/√(1 + ν²k²a²/2)` to fourth order
//! in κΔx (4.5e-6 relative at 20 cells per wavelength and a/Λ = 0.5).
//!
//! **Stability.** The scheme is stable iff Δt ≤ 2/√λ_max with λ_max the largest eigenvalue of
//! K φ = λ M φ (the dashpots, being trapezoidal and dissipative, do not lower it). For a uniform
//! lumped chain that is Courant ≤ 1; a node joining cells of Courant ≤ 1 satisfies Gershgorin's
//! bound 2Σk/m ≤ 4/Δt², so every grid built by [`Bar::new`] without a sub-cell segment is
//! stable. The Love term adds 4β to the mass of the shortest (Nyquist) mode: a uniform Love rod
//! is stable for `c0 Δt/Δx ≤ √(1 + 2ν²a²/Δx²)`, never less than the lumped chain. When a
//! segment is shorter than c_k Δt (one cell of Courant > 1), [`Bar::new`] computes λ_max exactly
//! by Sturm-sequence bisection of K − σM (Sylvester's law of inertia) and refuses Δt above
//! the limit.
//!
//! **Odd–even mode.** At Courant 1 the checkerboard u_i^n = (−1)^{i+n} H solves the scheme with
//! zero discrete energy (the Nyquist mode's double root z = −1): it neither propagates nor is
//! absorbed. A point force with a slope discontinuity excites it: a half-sine drive rising over N
//! steps leaves an alternating ripple of ≈ π/(2N) of the peak in element strains and end-element
//! forces (1.6 % for N = 97); a C¹ force (e.g. sin²) excites it ~30× less. Node values cancel it
//! exactly: [`Bar::strain_at`] at a node inside a segment averages its two elements, and there a
//! force-driven absorbing end gives exactly ε = −F(t − x/c0)/(2EA). The striker impact of
//! [`rigid_contact_force_n`] does not excite it.
//!
//! **Delay line.** In a bar of one uniform segment at Courant 1 without the Love term, the
//! interior update `u_i^{n+1} = u_{i+1}^n + u_{i−1}^n − u_i^{n−1}` is solved exactly by
//! `u_i^n = f(i − n) + g(i + n)`. With the increments `D_p = f(p+1) − f(p)` (right-going) and
//! `E_q = g(q+1) − g(q)` (left-going), element e stretches by `u_{e+1}^n − u_e^n = D_{e−n} + E_{e+n}`
//! and an interior node moves by `Δt v_i^{n−1/2} = E_{i+n−1} − D_{i−n}`. Each step only the two
//! end nodes are advanced, by the same discrete equations as the leapfrog (half mass plus added
//! masses, dashpot, end force), and each injects one new increment
//! (`D_{−n−1} = E_n − Δt v_0^{n+1/2}`, `E_{N+n} = D_{N−n−1} + Δt v_N^{n+1/2}`) into a ring buffer of
//! N values: O(1) a step, equal to the leapfrog to rounding ([`BarScheme`], docs/physics.md §6.2).
//!
//! **Energy.** The scheme conserves exactly (to rounding) the discrete energy
//! `E^{n−1/2} = ½ v^{n−1/2}ᵀ M v^{n−1/2} + ½ u^{n−1}ᵀ K u^n` of a free/fixed chain, and in general
//! `E^{n−1/2} + absorbed = E^{−1/2} + work`, where the dashpot dissipation per step is
//! `Z Δt ((v^{n+1/2} + v^{n−1/2})/2)²` and the work of an end force `F^n Δt (v^{n+1/2} + v^{n−1/2})/2`.
//! The kinetic and strain parts are reported at the half level n − 1/2 (see
//! [`Bar::kinetic_energy_j`]). Against the trapezoidal energy `½vᵀMv + ¼(u^{n−1}ᵀKu^{n−1} + u^nᵀKu^n)`
//! it differs by `(Δt²/4) vᵀKv`: O((κ c Δt)²) relative for smooth waves, but m Δv²/4 per velocity
//! step Δv of a sampled discontinuity (an impact), a quadrature error of the sampled field, not a loss.
//!
//! That identity is the bar's **energy ledger**: [`Bar::energy_j`] is carried from step to step by
//! the end work less the absorbed energy (O(1) a step), rebased on a full recomputation
//! ([`Bar::recomputed_energy_j`], a whole-bar pass) whenever masses or velocities are set outside a
//! step. The ledger therefore proves nothing by itself; [`Bar::check_energy_ledger`] compares it
//! with the recomputation, and the chain solver does so at a fixed interval and at the end of a
//! run (`solver::chain::CHECK_INTERVAL_STEPS`).

use crate::error::{Error, Named, Result};
use crate::transit::{
    BlockConvolver, MIN_BLOCK, SharedFilter, StretchPoint, TransitDesign, TransitModel,
};
use std::f64::consts::PI;
use std::sync::Arc;

/// Largest number of nodes a bar may have (a memory guard: ~100 bytes per node).
pub const MAX_NODES: usize = 20_000_000;

/// Relative slack for rounding in the cell count ⌊L/(cΔt)⌋ (so an exact multiple is not lost).
const CELL_COUNT_SLACK: f64 = 1e-12;

/// Relative slack for rounding when comparing Δt with the stability limit (Courant 1 sits on it).
const STABILITY_SLACK: f64 = 1e-9;

/// Largest |r − 1| of a segment run as a delay line (module docs, "Delay line"): a few ulp, so
/// the delay line and the leapfrog at r = 1 + δ part by about δ per step (3e-12 over 3,000 steps).
const DELAY_LINE_COURANT_SLACK: f64 = 1e-15;

/// How a [`Bar`] advances its interior (module docs, "Delay line"; docs/physics.md §6.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BarScheme {
    /// An exact delay line when the bar is one uniform segment at Courant 1 with the elementary
    /// theory, else the leapfrog on every node.
    #[default]
    Auto,
    /// The leapfrog on every node (module docs, "Scheme"), whatever the bar.
    FiniteDifference,
}

thread_local! {
    /// The scheme [`Bar::new`] uses on this thread ([`set_thread_bar_scheme`]).
    static THREAD_SCHEME: std::cell::Cell<BarScheme> = const { std::cell::Cell::new(BarScheme::Auto) };
}

/// Sets the scheme [`Bar::new`] uses on the calling thread and returns the previous one (module
/// docs, "Delay line"): a hook for tests and benchmarks to run a whole simulation both ways.
pub fn set_thread_bar_scheme(scheme: BarScheme) -> BarScheme {
    THREAD_SCHEME.with(|s| s.replace(scheme))
}

/// Elastic bar material (docs/physics.md §6): density, Young's modulus, Poisson's ratio (Love rod only).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarMaterial {
    /// Mass density ρ, kg/m³.
    pub density_kg_m3: f64,
    /// Young's modulus E, Pa.
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio ν (enters only the Love-rod lateral inertia ρν²J).
    pub poisson_ratio: f64,
}

impl BarMaterial {
    /// Bar wave speed c0 = √(E/ρ) (docs/physics.md §6).
    pub fn wave_speed_m_s(&self) -> f64 {
        (self.youngs_modulus_pa / self.density_kg_m3).sqrt()
    }
}

/// One uniform piece of a piecewise-uniform bar (docs/physics.md §6); impedance Z = ρ c0 A.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Length L, m.
    pub length_m: f64,
    /// Diameter d = 2a, m.
    pub diameter_m: f64,
    /// Material.
    pub material: BarMaterial,
}

impl Segment {
    /// Cross-section A = πd²/4, m².
    pub fn area_m2(&self) -> f64 {
        PI * self.diameter_m * self.diameter_m / 4.0
    }

    /// Mechanical impedance Z = ρ c0 A, kg/s (docs/physics.md §6).
    pub fn impedance_kg_s(&self) -> f64 {
        self.material.density_kg_m3 * self.material.wave_speed_m_s() * self.area_m2()
    }

    /// Polar moment of the cross-section J = πa⁴/2, m⁴ (Love-rod lateral inertia ρν²J).
    pub fn polar_moment_m4(&self) -> f64 {
        let a = self.diameter_m / 2.0;
        PI * a.powi(4) / 2.0
    }
}

/// Boundary condition at one end of a bar (module docs, "Absorbing ends").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndCondition {
    /// Traction-free end (external end forces act on it).
    Free,
    /// Clamped end: the end node does not move (external forces on it are ignored).
    Fixed,
    /// Non-reflecting end (a momentum trap): dashpot Z = ρ c0 A at the mid-step velocity,
    /// exactly non-reflecting at Courant 1.
    Absorbing,
}

/// Which 1D bar theory to integrate (docs/physics.md §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dispersion {
    /// Elementary bar theory, `ρA ü = (EA u')'`: non-dispersive.
    #[default]
    None,
    /// Love rod with lateral inertia, `ρA ü = EA u'' + ρν²J ü''` (Rayleigh–Love dispersion),
    /// integrated by finite differences on every node.
    LoveRod,
    /// The Rayleigh–Love relation applied to the travelling waves of a delay line (module docs,
    /// "Dispersive delay line"; [`crate::transit`]).
    RayleighLove,
    /// The exact first Pochhammer–Chree mode applied to the travelling waves of a delay line
    /// (module docs, "Dispersive delay line"; [`crate::transit`]).
    PochhammerChree,
}

impl Dispersion {
    /// Every bar theory, in the order the documentation lists them.
    pub const ALL: [Dispersion; 4] = [
        Dispersion::None,
        Dispersion::LoveRod,
        Dispersion::RayleighLove,
        Dispersion::PochhammerChree,
    ];

    /// The name scene files use (`dispersion = "…"`).
    pub fn name(self) -> &'static str {
        match self {
            Dispersion::None => "none",
            Dispersion::LoveRod => "love-rod",
            Dispersion::RayleighLove => "rayleigh-love",
            Dispersion::PochhammerChree => "pochhammer-chree",
        }
    }

    /// Parses a name of [`Dispersion::name`] (`None` for an unknown one).
    pub fn parse(name: &str) -> Option<Dispersion> {
        Dispersion::ALL.into_iter().find(|d| d.name() == name)
    }

    /// The relation a dispersive delay line applies, for the two transit variants.
    pub fn transit_model(self) -> Option<TransitModel> {
        match self {
            Dispersion::RayleighLove => Some(TransitModel::RayleighLove),
            Dispersion::PochhammerChree => Some(TransitModel::PochhammerChree),
            Dispersion::None | Dispersion::LoveRod => None,
        }
    }
}

/// A bar: uniform segments from left to right, its end conditions and theory (docs/physics.md §6).
#[derive(Debug, Clone, PartialEq)]
pub struct BarSpec {
    /// Name used in error messages (`bar <name>`).
    pub name: String,
    /// Segments from the left end.
    pub segments: Vec<Segment>,
    /// Condition at x = 0.
    pub left_end: EndCondition,
    /// Condition at x = L.
    pub right_end: EndCondition,
    /// Bar theory.
    pub dispersion: Dispersion,
}

impl BarSpec {
    /// The validator whose errors name this bar (`bar <name>`).
    fn validator(&self) -> Named {
        Named::new(format!("bar {}", self.name))
    }

    /// Checks the segments: at least one, finite positive length and diameter, a valid material.
    pub fn validate(&self) -> Result<()> {
        let v = self.validator();
        if self.segments.is_empty() {
            return Err(v.error(
                "segments",
                "the bar has no segments",
                "at least one segment",
            ));
        }
        for (k, s) in self.segments.iter().enumerate() {
            let t = v.table(&format!("segments[{k}]"));
            t.positive("length_m", s.length_m, 1e4, "m")?;
            t.positive("diameter_m", s.diameter_m, 10.0, "m")?;
            let m = t.table("material");
            m.positive("density_kg_m3", s.material.density_kg_m3, 1e5, "kg/m³")?;
            m.positive(
                "youngs_modulus_pa",
                s.material.youngs_modulus_pa,
                1e13,
                "Pa",
            )?;
            m.in_range("poisson_ratio", s.material.poisson_ratio, -0.99, 0.4999, "")?;
        }
        Ok(())
    }

    /// Total length ΣL_k, m.
    pub fn length_m(&self) -> f64 {
        self.segments.iter().map(|s| s.length_m).sum()
    }

    /// Cells per segment for time step Δt: n_k = ⌊L_k/(c_k Δt)⌋ ≥ 1, so Courant ≤ 1 (module docs).
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
struct SegmentGrid {
    /// Position of the segment's left end, m.
    x0_m: f64,
    /// Its length, m.
    length_m: f64,
    /// Index of its first element.
    first_element: usize,
    /// Number of cells.
    cells: usize,
    /// Cell size, m.
    dx_m: f64,
    /// Young's modulus, Pa.
    youngs_modulus_pa: f64,
    /// Bar wave speed c0, m/s.
    wave_speed_m_s: f64,
}

/// The lumped chain of a bar: node positions and masses, element stiffnesses, Love coefficients.
struct Grid {
    x: Vec<f64>,
    mass: Vec<f64>,
    k: Vec<f64>,
    /// ρν²J/Δx per element (empty without the Love term).
    beta: Vec<f64>,
    segments: Vec<SegmentGrid>,
}

impl Grid {
    /// Assembles the chain for `cells[k]` cells in segment k (module docs, "Grid").
    fn build(spec: &BarSpec, cells: &[usize]) -> Grid {
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
    fn gershgorin(&self, lo: usize, hi: usize) -> f64 {
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
    fn stability_limit_s(&self, lo: usize, hi: usize) -> f64 {
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
fn free_range(spec: &BarSpec, nodes: usize) -> (usize, usize) {
    let lo = usize::from(spec.left_end == EndCondition::Fixed);
    let hi = nodes - 1 - usize::from(spec.right_end == EndCondition::Fixed);
    (lo, hi)
}

/// A factorised symmetric tridiagonal matrix (Thomas algorithm).
#[derive(Debug, Clone)]
struct Tridiagonal {
    /// Off-diagonal A_{i,i+1}.
    off: Vec<f64>,
    /// Modified upper coefficients c'_i = A_{i,i+1}/den_i.
    cprime: Vec<f64>,
    /// 1/den_i of the forward sweep.
    inv_den: Vec<f64>,
}

impl Tridiagonal {
    /// Factorises the matrix with diagonal `diag` and off-diagonal `off` (diagonally dominant here).
    fn factor(diag: &[f64], off: Vec<f64>) -> Tridiagonal {
        let n = diag.len();
        let mut cprime = vec![0.0; n.saturating_sub(1)];
        let mut inv_den = vec![0.0; n];
        let mut prev_c = 0.0;
        for i in 0..n {
            let den = if i == 0 {
                diag[0]
            } else {
                diag[i] - off[i - 1] * prev_c
            };
            inv_den[i] = 1.0 / den;
            if i + 1 < n {
                prev_c = off[i] * inv_den[i];
                cprime[i] = prev_c;
            }
        }
        Tridiagonal {
            off,
            cprime,
            inv_den,
        }
    }

    /// Solves A x = b in place (b in, x out).
    fn solve(&self, x: &mut [f64]) {
        let n = x.len();
        x[0] *= self.inv_den[0];
        for i in 1..n {
            x[i] = (x[i] - self.off[i - 1] * x[i - 1]) * self.inv_den[i];
        }
        for i in (0..n - 1).rev() {
            x[i] -= self.cprime[i] * x[i + 1];
        }
    }
}

/// The Love-rod mass operator: factorised M + β-terms + ΔtD/2 and the responses to unit end forces.
#[derive(Debug, Clone)]
struct LoveOperator {
    /// ρν²J/Δx per element.
    beta: Vec<f64>,
    /// Factorised A = M_L + Δt D/2 (fixed nodes: identity rows).
    matrix: Tridiagonal,
    /// A⁻¹ e_0 and A⁻¹ e_N (zero for a fixed end).
    response: [Vec<f64>; 2],
}

/// The characteristic increments of a delay-line bar of N elements (module docs, "Delay line").
#[derive(Debug, Clone)]
struct Waves {
    /// Right-going increments: D_{e−n} in slot (e − n) mod N, m.
    right: Vec<f64>,
    /// Left-going increments: E_{e+n} in slot (e + n) mod N, m.
    left: Vec<f64>,
    /// n mod N.
    shift: usize,
    /// The dispersion the travelling waves carry, if any (module docs, "Dispersive delay line").
    transit: Option<Box<Transit>>,
}

/// What a dispersive delay line keeps beyond the ring buffers (module docs, "Dispersive delay
/// line"): every increment injected, and the transit filters that read them.
#[derive(Debug, Clone)]
struct Transit {
    /// The design, shared with every bar like this one ([`crate::transit::shared_design`]).
    design: Arc<TransitDesign>,
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
    step: usize,
    /// [D at element N − 1, E at element 0] at the current level: the waves arriving at the ends.
    arrival: [f64; 2],
    /// Σ of the squared increments injected (the initial field included) and delivered at the
    /// ends: k times each is the wave energy into and out of the transit, m².
    injected_sq: f64,
    delivered_sq: f64,
    /// max |H|² − 1 (≥ 0) of the end-to-end filter as truncated: the most energy it can add.
    ends_gain_excess: f64,
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
}

impl Transit {
    /// The transit of a delay line of `n` elements at rest ([`Transit::restart`] takes its field).
    fn new(design: Arc<TransitDesign>, n: usize) -> Transit {
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
        }
    }

    /// Restarts the histories from the field of ring buffers at step 0 (A[m] = D_{−m−1},
    /// B[m] = E_{N+m} for −N ≤ m < 0) and computes the arrivals.
    fn restart(&mut self, right: &[f64], left: &[f64]) {
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
    fn inject(&mut self, a: f64, b: f64, delivered: [f64; 2]) {
        self.delivered_sq += delivered[0] * delivered[0] + delivered[1] * delivered[1];
        self.injected_sq += a * a + b * b;
        self.injected_right.push(a);
        self.injected_left.push(b);
        self.step += 1;
        self.update_arrivals();
    }

    /// Right-going increment at element e (0 < e < N − 1): A[n − e − 1] carried over e + ½ cells.
    fn right_at(&self, e: usize) -> f64 {
        let f = self.design.shared_filter(2 * e + 1);
        f.apply(&self.injected_right, self.step + self.offset - e - 1)
    }

    /// Left-going increment at element e (0 < e < N − 1): B[n − (N − e)] carried over N − e − ½
    /// cells.
    fn left_at(&self, e: usize) -> f64 {
        let n = self.elements;
        let f = self.design.shared_filter(2 * (n - e) - 1);
        f.apply(&self.injected_left, self.step + self.offset - (n - e))
    }
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

    /// Stretch u_{e+1}^n − u_e^n = D_{e−n} + E_{e+n} of element e, m.
    #[inline]
    fn stretch(&self, e: usize) -> f64 {
        self.d(e) + self.e(e)
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

/// A bar discretised for one time step and advanced by [`Bar::step`] (module docs).
#[derive(Debug, Clone)]
pub struct Bar {
    name: String,
    dt_s: f64,
    step_index: usize,
    ends: [EndCondition; 2],
    /// Dashpot coefficient Z at each end (0 unless absorbing), kg/s.
    end_impedance: [f64; 2],
    x: Vec<f64>,
    /// u^n, m.
    u: Vec<f64>,
    /// v^{n−1/2}, m/s.
    v: Vec<f64>,
    /// Free rate: v^{n+1/2} = v^{n−1/2} + Δt (w + response to end forces).
    w: Vec<f64>,
    /// Scratch: element forces (tension), N.
    tension: Vec<f64>,
    /// Element stiffness EA/Δx, N/m.
    k: Vec<f64>,
    /// Lumped node mass (with added masses), kg.
    mass: Vec<f64>,
    /// Lumped chain: 1/(m_i + Δt D_i/2) (0 at a fixed node).
    inv_a: Vec<f64>,
    love: Option<LoveOperator>,
    /// The delay line (module docs): then u, v and w hold only the end nodes.
    waves: Option<Waves>,
    segments: Vec<SegmentGrid>,
    last_force: [f64; 2],
    absorbed_j: f64,
    work_j: f64,
    /// Kinetic + strain energy at n − 1/2 carried by the ledger: the last full recomputation plus
    /// the end work and minus the absorbed energy of every step since (module docs, "Energy"), J.
    ledger_j: f64,
    /// The energy that has passed through the ledger (|energy| at the last full recomputation plus
    /// every step's |work| and absorbed energy since): the scale of its rounding error, J.
    ledger_turnover_j: f64,
    /// Σ m v^{n−1/2} of a dispersive delay line, carried by the impulse of each step
    /// ([`Bar::momentum_kg_m_s`]), kg·m/s.
    momentum_half: f64,
}

/// Largest accepted difference between a bar's energy ledger and its full recomputation, relative
/// to the energy that has passed through the ledger or, if larger, the energy in play around the
/// bar (e.g. the whole chain's: [`Bar::check_energy_ledger`]). The two agree to rounding: each step
/// adds a few ulp of the turnover, so 10⁶ steps stay near 1e-10; 1e-9 is the output tolerance of
/// the results ("results unchanged", `validation/perf/REPORT.md`).
pub const ENERGY_LEDGER_TOLERANCE: f64 = 1e-9;

impl Bar {
    /// Builds the grid for time step Δt: n_k = ⌊L_k/(c_k Δt)⌋ ≥ 1 cells in segment k (Courant ≤ 1,
    /// = 1 when L_k is a multiple of c_k Δt: exact, no numerical dispersion); refuses (Error::Input)
    /// a Δt above the exact stability limit of that grid (e.g. a segment shorter than c_k Δt), naming it.
    /// Runs as a delay line where it can unless [`set_thread_bar_scheme`] said otherwise.
    pub fn new(spec: &BarSpec, dt_s: f64) -> Result<Bar> {
        Bar::with_scheme(spec, dt_s, THREAD_SCHEME.with(|s| s.get()))
    }

    /// [`Bar::new`] with the interior scheme chosen explicitly (module docs, "Delay line").
    pub fn with_scheme(spec: &BarSpec, dt_s: f64, scheme: BarScheme) -> Result<Bar> {
        spec.validate()?;
        let val = spec.validator();
        val.positive("time_step_s", dt_s, 1.0, "s")?;
        let cells = spec.cells_for_time_step(dt_s);
        let total = cells.iter().fold(0usize, |a, &c| a.saturating_add(c));
        if total >= MAX_NODES {
            return Err(val.error(
                "time_step_s",
                format!("{dt_s:e} s gives {total} cells"),
                format!("a time step giving fewer than {MAX_NODES} cells"),
            ));
        }
        let grid = Grid::build(spec, &cells);
        let (lo, hi) = free_range(spec, grid.mass.len());
        if lo <= hi && dt_s * dt_s * grid.gershgorin(lo, hi) > 4.0 * (1.0 + STABILITY_SLACK) {
            let limit = grid.stability_limit_s(lo, hi);
            if dt_s > limit * (1.0 + STABILITY_SLACK) {
                let culprits: Vec<String> = spec
                    .segments
                    .iter()
                    .zip(&grid.segments)
                    .enumerate()
                    .filter_map(|(k, (s, g))| {
                        let courant = s.material.wave_speed_m_s() * dt_s / g.dx_m;
                        (courant > 1.0 + STABILITY_SLACK).then(|| {
                            format!(
                                "segment {k} ({} m) is shorter than c0·Δt = {:e} m: one cell at Courant number {courant:.4}",
                                s.length_m,
                                s.material.wave_speed_m_s() * dt_s
                            )
                        })
                    })
                    .collect();
                return Err(val.error(
                    "time_step_s",
                    format!(
                        "{dt_s:e} s exceeds the stability limit {limit:e} s of the grid it gives ({})",
                        culprits.join("; ")
                    ),
                    format!(
                        "at most {limit:e} s for this grid (a smaller step refines the long segments and lowers it); \
                         the largest accepted step is {:e} s; every step up to {:e} s (each segment at least one cell \
                         of Courant number ≤ 1) is stable",
                        spec.max_time_step_s().unwrap_or_else(|_| spec.courant_limit_s()),
                        spec.courant_limit_s()
                    ),
                ));
            }
        }
        let n = grid.mass.len();
        let z = |s: &Segment, end: EndCondition| {
            if end == EndCondition::Absorbing {
                s.impedance_kg_s()
            } else {
                0.0
            }
        };
        let (first, last) = (&spec.segments[0], &spec.segments[spec.segments.len() - 1]);
        let mut bar = Bar {
            name: spec.name.clone(),
            dt_s,
            step_index: 0,
            ends: [spec.left_end, spec.right_end],
            end_impedance: [z(first, spec.left_end), z(last, spec.right_end)],
            x: grid.x,
            u: vec![0.0; n],
            v: vec![0.0; n],
            w: vec![0.0; n],
            tension: vec![0.0; n - 1],
            k: grid.k,
            mass: grid.mass,
            inv_a: vec![0.0; n],
            love: None,
            waves: None,
            segments: grid.segments,
            last_force: [0.0; 2],
            absorbed_j: 0.0,
            work_j: 0.0,
            ledger_j: 0.0,
            ledger_turnover_j: 0.0,
            momentum_half: 0.0,
        };
        let uniform_courant_1 = bar.segments.len() == 1
            && (bar.courant_number(0) - 1.0).abs() <= DELAY_LINE_COURANT_SLACK;
        if scheme == BarScheme::Auto
            && (spec.dispersion == Dispersion::None || spec.dispersion.transit_model().is_some())
            && uniform_courant_1
        {
            bar.waves = Some(Waves::new(bar.k.len()));
        }
        if let Some(model) = spec.dispersion.transit_model() {
            let Some(waves) = bar.waves.as_mut() else {
                return Err(val.error(
                    "dispersion",
                    format!(
                        "dispersion = \"{}\" rides on the travelling waves of a delay line, but bar {} is {}",
                        spec.dispersion.name(),
                        spec.name,
                        if scheme == BarScheme::FiniteDifference {
                            "forced onto finite differences".to_string()
                        } else if bar.segments.len() > 1 {
                            format!("{} segments", bar.segments.len())
                        } else {
                            format!(
                                "at Courant number {:.6} ({} m is not a whole number of cells c0·Δt = {:e} m)",
                                bar.courant_number(0),
                                first.length_m,
                                first.material.wave_speed_m_s() * dt_s
                            )
                        }
                    ),
                    "one uniform segment whose length is a whole number of cells c0·Δt (choose the \
                     cell size so, e.g. 1 mm for the authors' bars), or dispersion = \"love-rod\" \
                     (finite differences on any bar)",
                ));
            };
            let seg = &spec.segments[0];
            let design = crate::transit::shared_design(
                model,
                seg.material.poisson_ratio,
                0.5 * seg.diameter_m,
                bar.segments[0].dx_m,
                bar.k.len(),
            );
            waves.transit = Some(Box::new(Transit::new(design, bar.k.len())));
            waves.restart_transit();
        }
        if spec.dispersion == Dispersion::LoveRod {
            bar.love = Some(LoveOperator {
                beta: grid.beta,
                matrix: Tridiagonal::factor(&[1.0], Vec::new()),
                response: [Vec::new(), Vec::new()],
            });
        }
        bar.refresh_operators();
        Ok(bar)
    }

    /// Time step giving Courant number 1 in the first segment with `cells_in_first_segment` (≥ 1) cells there: L_0/(c_0 n), s.
    pub fn courant_time_step(spec: &BarSpec, cells_in_first_segment: usize) -> f64 {
        match spec.segments.first() {
            Some(s) => {
                s.length_m / (s.material.wave_speed_m_s() * cells_in_first_segment.max(1) as f64)
            }
            None => f64::NAN,
        }
    }

    /// Recomputes the mass operators after a change of masses, and the free rate w.
    fn refresh_operators(&mut self) {
        let n = self.mass.len();
        let dt = self.dt_s;
        let fixed = [
            self.ends[0] == EndCondition::Fixed,
            self.ends[1] == EndCondition::Fixed,
        ];
        let mut damping = vec![0.0; n];
        damping[0] += self.end_impedance[0];
        damping[n - 1] += self.end_impedance[1];
        if let Some(love) = &mut self.love {
            let b = &love.beta;
            let mut diag: Vec<f64> = (0..n)
                .map(|i| {
                    let bl = if i > 0 { b[i - 1] } else { 0.0 };
                    let br = if i + 1 < n { b[i] } else { 0.0 };
                    self.mass[i] + bl + br + 0.5 * dt * damping[i]
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
            love.matrix = Tridiagonal::factor(&diag, off);
            for (end, node) in [(0usize, 0usize), (1, n - 1)] {
                let mut r = vec![0.0; n];
                if !fixed[end] {
                    r[node] = 1.0;
                    love.matrix.solve(&mut r);
                }
                love.response[end] = r;
            }
        } else {
            for (ia, (&m, &d)) in self.inv_a.iter_mut().zip(self.mass.iter().zip(&damping)) {
                *ia = 1.0 / (m + 0.5 * dt * d);
            }
            if fixed[0] {
                self.inv_a[0] = 0.0;
            }
            if fixed[1] {
                self.inv_a[n - 1] = 0.0;
            }
        }
        self.update_free_rate();
        self.rebase_energy_ledger();
    }

    /// Restarts the energy ledger from a full recomputation (after the masses or the velocities
    /// were set outside a step).
    fn rebase_energy_ledger(&mut self) {
        self.ledger_j = self.recomputed_energy_j();
        self.ledger_turnover_j = self.ledger_j.abs();
        if self.transit().is_some() {
            self.momentum_half = (0..self.mass.len())
                .map(|i| self.mass[i] * self.half_step_velocity_m_s(i))
                .sum();
        }
    }

    /// w = A⁻¹ (f_int(u^n) − D v^{n−1/2}): the free velocity change per unit time of the coming step.
    fn update_free_rate(&mut self) {
        let n = self.u.len();
        let last = n - 1;
        if let Some(waves) = &self.waves {
            let end_rhs = [
                self.k[0] * waves.stretch(0) - self.end_impedance[0] * self.v[0],
                -self.k[last - 1] * waves.stretch(last - 1) - self.end_impedance[1] * self.v[last],
            ];
            self.w[0] = self.inv_a[0] * end_rhs[0];
            self.w[last] = self.inv_a[last] * end_rhs[1];
            return;
        }
        for ((t, uu), &kk) in self.tension.iter_mut().zip(self.u.windows(2)).zip(&self.k) {
            *t = kk * (uu[1] - uu[0]);
        }
        let end_rhs = [
            self.tension[0] - self.end_impedance[0] * self.v[0],
            -self.tension[last - 1] - self.end_impedance[1] * self.v[last],
        ];
        match &self.love {
            None => {
                for ((wi, t), &ia) in self.w[1..last]
                    .iter_mut()
                    .zip(self.tension.windows(2))
                    .zip(&self.inv_a[1..last])
                {
                    *wi = ia * (t[1] - t[0]);
                }
                self.w[0] = self.inv_a[0] * end_rhs[0];
                self.w[last] = self.inv_a[last] * end_rhs[1];
            }
            Some(love) => {
                for (wi, t) in self.w[1..last].iter_mut().zip(self.tension.windows(2)) {
                    *wi = t[1] - t[0];
                }
                self.w[0] = if self.ends[0] == EndCondition::Fixed {
                    0.0
                } else {
                    end_rhs[0]
                };
                self.w[last] = if self.ends[1] == EndCondition::Fixed {
                    0.0
                } else {
                    end_rhs[1]
                };
                love.matrix.solve(&mut self.w);
            }
        }
    }

    /// Change of node i's v^{n+1/2} per unit time from end forces `f` = [left, right], m/s².
    fn force_response(&self, i: usize, f: [f64; 2]) -> f64 {
        match &self.love {
            None => {
                let last = self.u.len() - 1;
                let mut r = 0.0;
                if i == 0 {
                    r += self.inv_a[0] * f[0];
                }
                if i == last {
                    r += self.inv_a[last] * f[1];
                }
                r
            }
            Some(love) => f[0] * love.response[0][i] + f[1] * love.response[1][i],
        }
    }

    /// The bar's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Time step Δt, s.
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Number of nodes N + 1 (cell boundaries, both ends included).
    pub fn node_count(&self) -> usize {
        self.u.len()
    }

    /// Number of cells (elements) N.
    pub fn element_count(&self) -> usize {
        self.k.len()
    }

    /// Number of cells n_k of segment k.
    pub fn segment_cells(&self, k: usize) -> usize {
        self.segments[k].cells
    }

    /// Cell size Δx_k = L_k/n_k of segment k, m.
    pub fn cell_size_m(&self, k: usize) -> f64 {
        self.segments[k].dx_m
    }

    /// Courant number c_k Δt/Δx_k of segment k (≤ 1 unless the segment is shorter than c_k Δt).
    pub fn courant_number(&self, k: usize) -> f64 {
        let s = &self.segments[k];
        s.wave_speed_m_s * self.dt_s / s.dx_m
    }

    /// Segment containing element e.
    fn segment_of_element(&self, e: usize) -> usize {
        self.segments
            .iter()
            .rposition(|s| s.first_element <= e)
            .unwrap_or(0)
    }

    /// Exact stability limit 2/√λ_max of this grid (current masses; Sturm bisection), s.
    pub fn stability_limit_s(&self) -> f64 {
        let n = self.u.len();
        let lo = usize::from(self.ends[0] == EndCondition::Fixed);
        let hi = n - 1 - usize::from(self.ends[1] == EndCondition::Fixed);
        let grid = Grid {
            x: Vec::new(),
            mass: self.mass.clone(),
            k: self.k.clone(),
            beta: self
                .love
                .as_ref()
                .map(|l| l.beta.clone())
                .unwrap_or_default(),
            segments: Vec::new(),
        };
        grid.stability_limit_s(lo, hi)
    }

    /// Position of node i along the bar from the left end, m.
    pub fn node_position_m(&self, i: usize) -> f64 {
        self.x[i]
    }

    /// Displacement u_i^n of node i at the current time level, m.
    pub fn displacement_m(&self, i: usize) -> f64 {
        let last = self.u.len() - 1;
        match &self.waves {
            // u_i = u_0 + Σ_{e<i} stretch_e, from the nearer end (module docs, "Delay line").
            Some(w) if i > 0 && i < last => {
                if 2 * i <= last {
                    self.u[0] + (0..i).map(|e| w.stretch(e)).sum::<f64>()
                } else {
                    self.u[last] - (i..last).map(|e| w.stretch(e)).sum::<f64>()
                }
            }
            _ => self.u[i],
        }
    }

    /// Whether the bar runs as an exact delay line (module docs, "Delay line").
    pub fn is_delay_line(&self) -> bool {
        self.waves.is_some()
    }

    /// Node interval holding x: (lo, w) with x = x_lo + w (x_{lo+1} − x_lo), w clamped to [0, 1].
    fn node_interval(&self, x_m: f64) -> (usize, f64) {
        let n = self.x.len();
        let (mut lo, mut hi) = (0, n - 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.x[mid] <= x_m {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (x0, x1) = (self.x[lo], self.x[hi]);
        (lo, ((x_m - x0) / (x1 - x0)).clamp(0.0, 1.0))
    }

    /// Axial displacement at x, linear between nodes (clamped to the bar), m.
    pub fn displacement_at_m(&self, x_m: f64) -> f64 {
        let (lo, w) = self.node_interval(x_m);
        self.displacement_m(lo) * (1.0 - w) + self.displacement_m(lo + 1) * w
    }

    /// u(x_b) − u(x_a) with u linear between nodes, m: the stretch a gauge grid from x_a to x_b
    /// reads (a delay line sums the element stretches between, O((x_b − x_a)/Δx)).
    pub fn stretch_between_m(&self, x_a_m: f64, x_b_m: f64) -> f64 {
        let Some(waves) = &self.waves else {
            return self.displacement_at_m(x_b_m) - self.displacement_at_m(x_a_m);
        };
        let (la, wa) = self.node_interval(x_a_m);
        let (lb, wb) = self.node_interval(x_b_m);
        let between: f64 = if lb >= la {
            (la..lb).map(|e| waves.stretch(e)).sum()
        } else {
            -(lb..la).map(|e| waves.stretch(e)).sum::<f64>()
        };
        between + wb * waves.stretch(lb) - wa * waves.stretch(la)
    }

    /// Leapfrog velocity v_i^{n−1/2} of node i (half a step behind the current level), m/s.
    pub fn half_step_velocity_m_s(&self, i: usize) -> f64 {
        match &self.waves {
            Some(w) if i > 0 && i + 1 < self.v.len() => w.last_move(i) / self.dt_s,
            _ => self.v[i],
        }
    }

    /// Velocity of node i at the current level n, (v^{n−1/2} + v^{n+1/2})/2 with v^{n+1/2} predicted
    /// from the current internal forces and the end forces of the previous step, m/s.
    pub fn velocity_m_s(&self, i: usize) -> f64 {
        match &self.waves {
            Some(w) if i > 0 && i + 1 < self.v.len() => {
                0.5 * (w.last_move(i) + w.next_move(i)) / self.dt_s
            }
            _ => {
                self.v[i] + 0.5 * self.dt_s * (self.w[i] + self.force_response(i, self.last_force))
            }
        }
    }

    /// v^{n+1/2} that an end node gets from the coming step if no external force acts, m/s (for contacts).
    pub fn free_end_velocity_m_s(&self, right: bool) -> f64 {
        let i = if right { self.u.len() - 1 } else { 0 };
        self.v[i] + self.dt_s * self.w[i]
    }

    /// ∂v^{n+1/2}/∂F of the end node `velocity_at_right` per newton on end `force_at_right`: Δt (A⁻¹)_{ij}, s/kg.
    pub fn end_mobility_s_per_kg(&self, velocity_at_right: bool, force_at_right: bool) -> f64 {
        let i = if velocity_at_right {
            self.u.len() - 1
        } else {
            0
        };
        let f = if force_at_right {
            [0.0, 1.0]
        } else {
            [1.0, 0.0]
        };
        self.dt_s * self.force_response(i, f)
    }

    /// Adds a lumped mass to node i (e.g. a sphere joining the end node), kg; best before stepping.
    ///
    /// Only raises the stability limit. The energy ledger uses the current masses, so a mass added
    /// to a moving node changes the reported kinetic energy.
    ///
    /// # Panics
    /// If `i` is out of range or `mass_kg` is negative or not finite (a programming error: validate input first).
    pub fn add_node_mass(&mut self, i: usize, mass_kg: f64) {
        assert!(
            mass_kg.is_finite() && mass_kg >= 0.0,
            "bar {}: added node mass must be finite and ≥ 0, got {mass_kg}",
            self.name
        );
        if i > 0 && i + 1 < self.u.len() {
            self.materialise();
        }
        self.mass[i] += mass_kg;
        self.refresh_operators();
    }

    /// Lumped (diagonal) mass of node i, kg: half of each neighbouring cell plus added masses (no Love term).
    pub fn node_mass_kg(&self, i: usize) -> f64 {
        self.mass[i]
    }

    /// Momentum Σ m v of the nodes at level n, kg·m/s: the sum over the nodes of
    /// [`Bar::velocity_m_s`]; for a dispersive delay line (whose interior reads cost a
    /// convolution each) the same quantity from its impulse ledger: Σ m v^{n−1/2} carried by the
    /// end velocities' changes and the end springs' forces, plus half the coming step's.
    pub fn momentum_kg_m_s(&self) -> f64 {
        let last = self.mass.len() - 1;
        match self.transit_interior_impulse() {
            Some(interior) => {
                let coming = interior
                    + [0, last]
                        .iter()
                        .map(|&i| {
                            self.mass[i]
                                * self.dt_s
                                * (self.w[i] + self.force_response(i, self.last_force))
                        })
                        .sum::<f64>();
                self.momentum_half + 0.5 * coming
            }
            _ => (0..=last)
                .map(|i| self.node_mass_kg(i) * self.velocity_m_s(i))
                .sum(),
        }
    }

    /// The impulse the coming step gives the interior nodes of a dispersive delay line,
    /// Δt (k s_{N−1} − k s_0) (every spring force between them cancels), N·s; `None` for any
    /// other bar.
    fn transit_interior_impulse(&self) -> Option<f64> {
        let w = self.waves.as_ref().filter(|w| w.transit.is_some())?;
        let last = self.mass.len() - 1;
        Some(self.dt_s * (self.k[last - 1] * w.stretch(last - 1) - self.k[0] * w.stretch(0)))
    }

    /// Sets the whole bar moving rigidly at `v_m_s` (a striker): v^{−1/2} = v, fixed end nodes stay at rest.
    pub fn set_initial_velocity(&mut self, v_m_s: f64) {
        self.v.fill(v_m_s);
        if let Some(w) = &mut self.waves {
            // Rigid motion: every interior node moves Δt v, every element is unstretched.
            let half = 0.5 * self.dt_s * v_m_s;
            w.right.fill(-half);
            w.left.fill(half);
            assert!(
                w.transit.is_none() || self.step_index == 0,
                "bar {}: a dispersive delay line is set moving only before its first step",
                self.name
            );
            w.restart_transit();
        }
        let n = self.v.len();
        if self.ends[0] == EndCondition::Fixed {
            self.v[0] = 0.0;
        }
        if self.ends[1] == EndCondition::Fixed {
            self.v[n - 1] = 0.0;
        }
        self.update_free_rate();
        self.rebase_energy_ledger();
    }

    /// Advances one step with external axial forces (N, toward +x) on the first and last node at the
    /// current level: v^{n+1/2} = v^{n−1/2} + Δt M⁻¹(f_int + f_ext − D v̄), u^{n+1} = u^n + Δt v^{n+1/2} (module docs).
    pub fn step(&mut self, left_force_n: f64, right_force_n: f64) {
        let dt = self.dt_s;
        let last = self.u.len() - 1;
        let f = [
            if self.ends[0] == EndCondition::Fixed {
                0.0
            } else {
                left_force_n
            },
            if self.ends[1] == EndCondition::Fixed {
                0.0
            } else {
                right_force_n
            },
        ];
        let v_before = [self.v[0], self.v[last]];
        let interior_impulse = self.transit_interior_impulse().unwrap_or(0.0);
        match &self.love {
            None => {
                self.w[0] += self.inv_a[0] * f[0];
                self.w[last] += self.inv_a[last] * f[1];
            }
            Some(love) => {
                for (end, &fe) in f.iter().enumerate() {
                    if fe != 0.0 {
                        for (wi, &g) in self.w.iter_mut().zip(&love.response[end]) {
                            *wi += fe * g;
                        }
                    }
                }
            }
        }
        if let Some(waves) = &mut self.waves {
            for node in [0, last] {
                self.v[node] += dt * self.w[node];
                self.u[node] += dt * self.v[node];
            }
            if waves.transit.is_some() {
                self.momentum_half += interior_impulse
                    + self.mass[0] * (self.v[0] - v_before[0])
                    + self.mass[last] * (self.v[last] - v_before[1]);
            }
            waves.advance(dt * self.v[0], dt * self.v[last]);
        } else {
            for ((ui, vi), &wi) in self.u.iter_mut().zip(self.v.iter_mut()).zip(&self.w) {
                *vi += dt * wi;
                *ui += dt * *vi;
            }
        }
        for (end, &node) in [0, last].iter().enumerate() {
            let mean = 0.5 * (v_before[end] + self.v[node]);
            let work = f[end] * mean * dt;
            let absorbed = self.end_impedance[end] * mean * mean * dt;
            self.work_j += work;
            self.absorbed_j += absorbed;
            // The scheme's energy identity: E^{n+1/2} − E^{n−1/2} = Σ_ends (F − Z v̄) v̄ Δt.
            self.ledger_j += work - absorbed;
            self.ledger_turnover_j += work.abs() + absorbed;
        }
        self.last_force = f;
        self.step_index += 1;
        self.update_free_rate();
    }

    /// Strain (u_{e+1} − u_e)/Δx of element e at the current level (tension positive).
    pub fn element_strain(&self, e: usize) -> f64 {
        let s = &self.segments[self.segment_of_element(e)];
        match &self.waves {
            Some(w) => w.stretch(e) / s.dx_m,
            None => (self.u[e + 1] - self.u[e]) / s.dx_m,
        }
    }

    /// Position of the centre of element e, m.
    pub fn element_centre_m(&self, e: usize) -> f64 {
        0.5 * (self.x[e] + self.x[e + 1])
    }

    /// Segment containing x (an interface belongs to the segment on its right; clamped to the bar).
    fn segment_at(&self, x_m: f64) -> usize {
        self.segments
            .iter()
            .position(|s| x_m < s.x0_m + s.length_m)
            .unwrap_or(self.segments.len() - 1)
    }

    /// Where [`Bar::strain_at`] reads x: the segment, the element e and the weight t of element
    /// e + 1 (strain = (1 − t) ε_e + t ε_{e+1}; t = 0 in a one-cell segment).
    fn strain_point(&self, x_m: f64) -> (usize, usize, f64) {
        let k = self.segment_at(x_m);
        let s = &self.segments[k];
        if s.cells == 1 {
            return (k, s.first_element, 0.0);
        }
        let xi = ((x_m - s.x0_m) / s.dx_m - 0.5).clamp(0.0, (s.cells - 1) as f64);
        // xi ≥ 0 (NaN → 0): truncation is the floor, without a libm call.
        let j = (xi as usize).min(s.cells - 2);
        (k, s.first_element + j, xi - j as f64)
    }

    /// Axial strain at x (tension positive): linear between element centres of the segment holding x,
    /// constant from the outermost centre to the segment's ends.
    pub fn strain_at(&self, x_m: f64) -> f64 {
        let (k, e, t) = self.strain_point(x_m);
        let dx = self.segments[k].dx_m;
        // [`Bar::element_strain`] of an element of segment k.
        let strain = |e: usize| match &self.waves {
            Some(w) => w.stretch(e) / dx,
            None => (self.u[e + 1] - self.u[e]) / dx,
        };
        if t == 0.0 {
            return strain(e);
        }
        (1.0 - t) * strain(e) + t * strain(e + 1)
    }

    /// Weighted element stretches over the past `steps` (≤ the current step) of a dispersive
    /// delay line, from its whole histories by FFT (module docs, "Dispersive delay line"): one
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
            self.k.len(),
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
    /// dispersive delay line, one row per step, from its whole histories by FFT (module docs,
    /// "Dispersive delay line"; what [`Bar::stress_at`] read then, to the filters' truncation,
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

    /// Axial stress E·ε at x with E of the segment there, Pa (tension positive).
    pub fn stress_at(&self, x_m: f64) -> f64 {
        self.segments[self.segment_at(x_m)].youngs_modulus_pa * self.strain_at(x_m)
    }

    /// Axial force (tension positive) in the end element, k (u_1 − u_0) or k (u_N − u_{N−1}), N.
    pub fn end_force_n(&self, right: bool) -> f64 {
        let e = if right { self.k.len() - 1 } else { 0 };
        match &self.waves {
            Some(w) => self.k[e] * w.stretch(e),
            None => self.k[e] * (self.u[e + 1] - self.u[e]),
        }
    }

    /// Kinetic energy ½ v^{n−1/2}ᵀ M v^{n−1/2} at the half level n − 1/2 (with the Love lateral part), J.
    pub fn kinetic_energy_j(&self) -> f64 {
        if let Some(w) = &self.waves {
            let last = self.mass.len() - 1;
            let dt = self.dt_s;
            let interior: f64 = (1..last)
                .map(|i| {
                    let v = w.last_move(i) / dt;
                    self.mass[i] * v * v
                })
                .sum();
            let ends = self.mass[0] * self.v[0] * self.v[0]
                + self.mass[last] * self.v[last] * self.v[last];
            return 0.5 * (interior + ends);
        }
        let lumped: f64 = self.mass.iter().zip(&self.v).map(|(m, v)| m * v * v).sum();
        let lateral: f64 = match &self.love {
            None => 0.0,
            Some(love) => love
                .beta
                .iter()
                .zip(self.v.windows(2))
                .map(|(b, vv)| b * (vv[1] - vv[0]).powi(2))
                .sum(),
        };
        0.5 * (lumped + lateral)
    }

    /// Strain energy ½ u^{n−1}ᵀ K u^n at the half level n − 1/2: with the kinetic energy, the scheme's exactly conserved energy, J.
    pub fn strain_energy_j(&self) -> f64 {
        let dt = self.dt_s;
        if let Some(w) = &self.waves {
            let v = |i: usize| self.half_step_velocity_m_s(i);
            return 0.5
                * (0..self.k.len())
                    .map(|e| {
                        let du = w.stretch(e);
                        self.k[e] * du * (du - dt * (v(e + 1) - v(e)))
                    })
                    .sum::<f64>();
        }
        0.5 * self
            .k
            .iter()
            .zip(self.u.windows(2).zip(self.v.windows(2)))
            .map(|(k, (uu, vv))| {
                let du = uu[1] - uu[0];
                k * du * (du - dt * (vv[1] - vv[0]))
            })
            .sum::<f64>()
    }

    /// Kinetic plus strain energy at the half level n − 1/2 from the energy ledger: the last full
    /// recomputation plus the end work less the absorbed energy of each step since, O(1), J. Equal
    /// to [`Bar::recomputed_energy_j`] to rounding ([`Bar::check_energy_ledger`]).
    pub fn energy_j(&self) -> f64 {
        self.ledger_j
    }

    /// The energy that has passed through the ledger since its last rebase (|energy| then, plus
    /// every step's |work| and absorbed energy), J: the scale of the ledger's rounding.
    pub fn energy_turnover_j(&self) -> f64 {
        self.ledger_turnover_j
    }

    /// Kinetic plus strain energy at the half level n − 1/2 summed over every node and element
    /// (a whole-bar pass), J.
    pub fn recomputed_energy_j(&self) -> f64 {
        self.kinetic_energy_j() + self.strain_energy_j()
    }

    /// Compares the energy ledger with a full recomputation: Error::Unstable (naming step, time,
    /// bar and the difference) if they differ by more than [`ENERGY_LEDGER_TOLERANCE`] of the
    /// larger of the energy that has passed through the ledger and `scale_j` (the energy in play
    /// around the bar, J: a bar reached only by a tiny precursor has a turnover of 1e-315 J, whose
    /// rounding is judged against the energy of the test), or if the ledger is not finite.
    pub fn check_energy_ledger(&self, scale_j: f64) -> Result<()> {
        if let Some(t) = self.transit().filter(|t| t.step > 0) {
            return self.check_transit_passivity(t, scale_j);
        }
        let full = self.recomputed_energy_j();
        let difference = self.ledger_j - full;
        let scale = self.ledger_turnover_j.max(scale_j);
        if difference.is_finite() && difference.abs() <= ENERGY_LEDGER_TOLERANCE * scale {
            return Ok(());
        }
        Err(Error::Unstable {
            step: self.step_index,
            time_s: self.time_s(),
            quantity: format!(
                "bar {}: energy ledger {:e} J minus its recomputation {full:e} J (allowed: {ENERGY_LEDGER_TOLERANCE:e} of {scale:e} J)",
                self.name, self.ledger_j
            ),
            value: difference,
        })
    }

    /// The dispersive delay line's energy check (module docs, "Dispersive delay line"): the
    /// transit delivers no more wave energy than was injected into it (k Σ D̃² ≤ k Σ D², the
    /// filters being passive), and the ledger is finite and not below zero, each within
    /// [`ENERGY_LEDGER_TOLERANCE`] of the energy in play.
    fn check_transit_passivity(&self, t: &Transit, scale_j: f64) -> Result<()> {
        let k = self.k[0];
        let scale = self.ledger_turnover_j.max(scale_j);
        // A truncated filter's gain may exceed one by its truncation error: allow that share
        // of the wave energy delivered, on top of the rounding of the energy in play.
        let excess = k * (t.delivered_sq - t.injected_sq);
        let allowed = ENERGY_LEDGER_TOLERANCE * scale + k * t.delivered_sq * t.ends_gain_excess;
        let (quantity, value) = if excess.is_nan() || excess > allowed {
            (
                format!(
                    "bar {}: the dispersive transit delivered {excess:e} J more wave energy than it was given \
                     (allowed: {allowed:e} J)",
                    self.name
                ),
                excess,
            )
        } else if self.ledger_j.is_nan() || self.ledger_j < -allowed {
            (
                format!(
                    "bar {}: energy ledger {:e} J (allowed: ≥ {:e} J)",
                    self.name, self.ledger_j, -allowed
                ),
                self.ledger_j,
            )
        } else {
            return Ok(());
        };
        Err(Error::Unstable {
            step: self.step_index,
            time_s: self.time_s(),
            quantity,
            value,
        })
    }

    /// The dispersive transit of a delay line, if the bar has one.
    fn transit(&self) -> Option<&Transit> {
        self.waves.as_ref().and_then(|w| w.transit.as_deref())
    }

    /// The dispersion relation the bar's travelling waves carry, if it is a dispersive delay line.
    pub fn transit_model(&self) -> Option<TransitModel> {
        self.transit().map(|t| t.design.model())
    }

    /// O(1) check of one step: the energy ledger is finite (it takes the end velocities every
    /// step, so a non-finite value at an end, where the joints read the bar, shows at once); if it
    /// is not, the whole-bar [`Bar::check_finite`] names the node.
    pub fn check_step(&self) -> Result<()> {
        if self.ledger_j.is_finite() {
            return Ok(());
        }
        self.check_finite()?;
        self.check_energy_ledger(0.0)
    }

    /// Test hook: sets v_i^{n−1/2} of node i and shifts the energy ledger by `ledger_offset_j`
    /// without rebasing it (a state corrupted behind the ledger's back).
    #[cfg(test)]
    pub(crate) fn corrupt_for_test(&mut self, i: usize, v_m_s: f64, ledger_offset_j: f64) {
        match &mut self.waves {
            Some(w) if i > 0 && i + 1 < self.v.len() => {
                // Δt v_i^{n−1/2} = E_{i−1+n} − D_{i−n}.
                let slot = w.left_slot(i - 1);
                w.left[slot] = w.right[w.right_slot(i)] + self.dt_s * v_m_s;
            }
            _ => self.v[i] = v_m_s,
        }
        self.ledger_j += ledger_offset_j;
    }

    /// Energy that left through absorbing ends so far, Σ Z Δt ((v^{n+1/2} + v^{n−1/2})/2)², J.
    pub fn absorbed_energy_j(&self) -> f64 {
        self.absorbed_j
    }

    /// Work done by the external end forces so far, Σ F^n Δt (v^{n+1/2} + v^{n−1/2})/2, J.
    pub fn work_done_j(&self) -> f64 {
        self.work_j
    }

    /// Time t = nΔt of the current level, s.
    pub fn time_s(&self) -> f64 {
        self.step_index as f64 * self.dt_s
    }

    /// Number n of steps taken.
    pub fn step_index(&self) -> usize {
        self.step_index
    }

    /// Checks that displacements and velocities are finite (Error::Unstable naming step, time, node).
    pub fn check_finite(&self) -> Result<()> {
        for (what, values) in [("displacement", &self.u), ("half-step velocity", &self.v)] {
            if let Some((i, &value)) = values.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                return Err(self.unstable_node(what, i, value));
            }
        }
        if let Some(t) = self.transit() {
            for (what, value, node) in [
                ("right-going wave arriving", t.arrival[0], self.u.len() - 1),
                ("left-going wave arriving", t.arrival[1], 0),
            ] {
                if !value.is_finite() {
                    return Err(self.unstable_node(what, node, value));
                }
            }
        }
        if let Some(w) = &self.waves {
            // D_{e−n} enters v_e, E_{e+n} enters v_{e+1} (module docs, "Delay line").
            for e in 0..w.right.len() {
                for (what, value, node) in [
                    ("right-going wave", w.right[w.right_slot(e)], e),
                    ("left-going wave", w.left[w.left_slot(e)], e + 1),
                ] {
                    if !value.is_finite() {
                        return Err(self.unstable_node(what, node, value));
                    }
                }
            }
        }
        Ok(())
    }

    /// Error::Unstable naming step, time, bar, the quantity `what` of node i and its value.
    fn unstable_node(&self, what: &str, i: usize, value: f64) -> Error {
        Error::Unstable {
            step: self.step_index,
            time_s: self.time_s(),
            quantity: format!(
                "bar {}: {what} of node {i} (x = {} m)",
                self.name, self.x[i]
            ),
            value,
        }
    }

    /// Turns a delay line into the leapfrog on every node (before an interior node mass).
    fn materialise(&mut self) {
        assert!(
            self.transit().is_none(),
            "bar {}: a dispersive delay line takes added masses only at its end nodes",
            self.name
        );
        let Some(w) = self.waves.take() else {
            return;
        };
        let last = self.u.len() - 1;
        let mut u = self.u[0];
        for i in 1..last {
            u += w.stretch(i - 1);
            self.u[i] = u;
            self.v[i] = (w.left[w.left_slot(i - 1)] - w.right[w.right_slot(i)]) / self.dt_s;
        }
    }
}

/// The largest cell ≤ `at_most_m` that makes every length of `lengths_m` a whole number of cells
/// (to 1e-9 of a cell), so that bars of one wave speed can all run as (dispersive) delay lines
/// (docs/physics.md §6.2.1); tries up to four times the cells of the first length at `at_most_m`;
/// `None` if no such cell is found.
pub fn delay_line_cell_m(lengths_m: &[f64], at_most_m: f64) -> Option<f64> {
    let (&first, rest) = lengths_m.split_first()?;
    if !(first > 0.0 && at_most_m > 0.0) {
        return None;
    }
    let start = ((first / at_most_m) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
    (start..=4 * start).map(|n| first / n as f64).find(|&cell| {
        rest.iter().all(|&l| {
            let cells = l / cell;
            (cells - cells.round()).abs() <= 1e-9 && cells.round() >= 1.0
        })
    })
}

/// Compression-only rigid contact between the right end of `left` and the left end of `right`
/// (same Δt): the force (N, ≥ 0, compressive) that closes the gap exactly at the end of the
/// coming step if it would otherwise close, else 0; apply it as `left.step(.., −F)`, `right.step(F, ..)`.
///
/// The gap at the current level is `initial_gap_m + u_right(0) − u_left(N)`. While closed, the two
/// half-mass end nodes move as one full node, so two equal bars at Courant 1 behave exactly as one
/// continuous bar (the impact of a striker is exact); the very first step of an impact merges two
/// half-mass nodes of different velocities, the discrete counterpart of the velocity jump (module
/// docs, "Energy"). Forces applied by the caller at the far ends are not included (their
/// cross-mobility is zero for a lumped chain and decays geometrically along a Love rod).
pub fn rigid_contact_force_n(left: &Bar, right: &Bar, initial_gap_m: f64) -> f64 {
    let dt = left.dt_s();
    debug_assert!(
        (right.dt_s() - dt).abs() <= 1e-12 * dt,
        "contact between bars with different time steps"
    );
    let gap = initial_gap_m + right.displacement_m(0) - left.displacement_m(left.node_count() - 1);
    let closing =
        gap + dt * (right.free_end_velocity_m_s(false) - left.free_end_velocity_m_s(true));
    let mobility =
        left.end_mobility_s_per_kg(true, true) + right.end_mobility_s_per_kg(false, false);
    if closing < 0.0 && mobility > 0.0 {
        -closing / (dt * mobility)
    } else {
        0.0
    }
}

/// Rayleigh–Love phase velocity c/c0 = 1/√(1 + ν²k²a²/2) at y = a/Λ (k a = 2πy) (docs/physics.md §6).
pub fn rayleigh_love_velocity_ratio(poisson_ratio: f64, radius_over_wavelength: f64) -> f64 {
    let ka = 2.0 * PI * radius_over_wavelength;
    1.0 / (1.0 + 0.5 * poisson_ratio * poisson_ratio * ka * ka).sqrt()
}

/// γ = ν²a²/(2Δx²) of the discrete Love relation (0 without the Love term: the grid of a
/// dispersive delay line is elementary, its dispersion is in the transit filters).
fn love_gamma(material: &BarMaterial, diameter_m: f64, dispersion: Dispersion, cell_m: f64) -> f64 {
    match dispersion {
        Dispersion::None | Dispersion::RayleighLove | Dispersion::PochhammerChree => 0.0,
        Dispersion::LoveRod => {
            let a = diameter_m / 2.0;
            material.poisson_ratio.powi(2) * a * a / (2.0 * cell_m * cell_m)
        }
    }
}

/// Angular frequency of wavenumber κ on a uniform grid of this scheme, from
/// sin²(ωΔt/2)(1 + 4γS²) = r²S², S = sin(κΔx/2), r = c0Δt/Δx, γ = ν²a²/(2Δx²) (module docs), rad/s;
/// for a dispersive delay line, its model's relation (the grid itself being exact), with the
/// Pochhammer–Chree root solved rather than tabulated.
pub fn scheme_angular_frequency_rad_s(
    material: &BarMaterial,
    diameter_m: f64,
    dispersion: Dispersion,
    cell_m: f64,
    dt_s: f64,
    wavenumber_rad_m: f64,
) -> f64 {
    let (c0, k, a) = (
        material.wave_speed_m_s(),
        wavenumber_rad_m,
        0.5 * diameter_m,
    );
    match dispersion.transit_model() {
        Some(TransitModel::RayleighLove) => {
            return c0 * k / (1.0 + 0.5 * (material.poisson_ratio * a * k).powi(2)).sqrt();
        }
        Some(TransitModel::PochhammerChree) => {
            let ratio = crate::dispersion::velocity_ratio_at_radius_over_wavelength(
                material.poisson_ratio,
                k * a / (2.0 * PI),
            );
            return c0 * k * ratio;
        }
        None => {}
    }
    let gamma = love_gamma(material, diameter_m, dispersion, cell_m);
    let r = material.wave_speed_m_s() * dt_s / cell_m;
    let s = (0.5 * wavenumber_rad_m * cell_m).sin();
    2.0 / dt_s * (r * s / (1.0 + 4.0 * gamma * s * s).sqrt()).asin()
}

/// Wavenumber of angular frequency ω on a uniform grid of this scheme (inverse of
/// [`scheme_angular_frequency_rad_s`]; NaN above the grid's cut-off), rad/m.
pub fn scheme_wavenumber_rad_m(
    material: &BarMaterial,
    diameter_m: f64,
    dispersion: Dispersion,
    cell_m: f64,
    dt_s: f64,
    angular_frequency_rad_s: f64,
) -> f64 {
    if let Some(model) = dispersion.transit_model() {
        // The grid at Courant 1 carries Ω = ωΔt exactly; the transit adds φ(Ω) a cell.
        let design =
            TransitDesign::relation(model, material.poisson_ratio, 0.5 * diameter_m, cell_m);
        let w = angular_frequency_rad_s * dt_s;
        return (w + design.phase_and_gain(w).0) / cell_m;
    }
    let gamma = love_gamma(material, diameter_m, dispersion, cell_m);
    let r = material.wave_speed_m_s() * dt_s / cell_m;
    let p = (0.5 * angular_frequency_rad_s * dt_s).sin().powi(2);
    let s2 = p / (r * r - 4.0 * gamma * p);
    if !(0.0..=1.0).contains(&s2) {
        return f64::NAN;
    }
    2.0 / cell_m * s2.sqrt().asin()
}

/// A harmonic wave train measured on a simulated uniform bar by [`measure_phase_velocity`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseVelocityMeasurement {
    /// Driving angular frequency ω, rad/s.
    pub angular_frequency_rad_s: f64,
    /// Measured wavenumber k = Δφ/d from the phase lag between the two stations, rad/m.
    pub wavenumber_rad_m: f64,
    /// Measured phase velocity ω/k, m/s.
    pub phase_velocity_m_s: f64,
    /// Distance d between the two stations, m.
    pub station_spacing_m: f64,
    /// Amplitude at the far station over that at the near one (1 for a lossless, reflection-free train).
    pub amplitude_ratio: f64,
    /// Cell size Δx, m.
    pub cell_m: f64,
    /// Time step Δx/c0 (Courant 1), s.
    pub dt_s: f64,
    /// Nodes of the simulated bar.
    pub nodes: usize,
    /// Steps simulated.
    pub steps: usize,
}

/// Least-squares fit y ≈ c + a cos ωt + b sin ωt (normal equations of the three basis functions).
#[derive(Debug, Clone, Copy, Default)]
struct HarmonicFit {
    gram: [[f64; 3]; 3],
    rhs: [f64; 3],
}

impl HarmonicFit {
    /// Adds the sample y at phase ωt.
    fn add(&mut self, phase: f64, y: f64) {
        let basis = [1.0, phase.cos(), phase.sin()];
        for (i, bi) in basis.iter().enumerate() {
            for (j, bj) in basis.iter().enumerate() {
                self.gram[i][j] += bi * bj;
            }
            self.rhs[i] += bi * y;
        }
    }

    /// Amplitude √(a² + b²) and phase θ of y = A cos(ωt − θ) (Cramer's rule on the 3×3 normal equations).
    fn amplitude_phase(&self) -> (f64, f64) {
        let det = |m: &[[f64; 3]; 3]| {
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        };
        let with_column = |c: usize| {
            let mut m = self.gram;
            for (row, r) in m.iter_mut().zip(&self.rhs) {
                row[c] = *r;
            }
            m
        };
        let d = det(&self.gram);
        let a = det(&with_column(1)) / d;
        let b = det(&with_column(2)) / d;
        (a.hypot(b), b.atan2(a))
    }
}

/// Measures the phase velocity at ω on a simulated uniform bar (validation of the Love scheme,
/// docs/physics.md §6): a long bar at Courant 1 with cells `cell_m`, both ends absorbing, is driven at
/// its left end by a force sin ωt switched on over 8 periods (sin² ramp); the strain at two
/// element centres ≈ Λ and 1.75Λ from the driven end (Λ from the scheme's own relation, for
/// placement only) is fitted to c + a cos ωt + b sin ωt over 24 periods that start 8 periods
/// after the ramp has reached the far station at the group velocity and end before anything
/// reflected from the far end (at up to c0) can return; k = (θ₂ − θ₁ mod 2π)/d.
pub fn measure_phase_velocity(
    material: BarMaterial,
    diameter_m: f64,
    dispersion: Dispersion,
    angular_frequency_rad_s: f64,
    cell_m: f64,
) -> Result<PhaseVelocityMeasurement> {
    let val = Named::new("phase-velocity measurement");
    let omega = val.positive(
        "angular_frequency_rad_s",
        angular_frequency_rad_s,
        1e12,
        "rad/s",
    )?;
    let cell = val.positive("cell_m", cell_m, 1.0, "m")?;
    val.positive("diameter_m", diameter_m, 10.0, "m")?;
    let c0 = material.wave_speed_m_s();
    let dt = cell / c0;
    let k_est = scheme_wavenumber_rad_m(&material, diameter_m, dispersion, cell, dt, omega);
    if !k_est.is_finite() || k_est <= 0.0 {
        return Err(val.error(
            "angular_frequency_rad_s",
            format!("{omega:e} rad/s is above the cut-off of a grid with {cell:e} m cells"),
            "a propagating frequency (refine the grid)",
        ));
    }
    let wavelength = 2.0 * PI / k_est;
    let period = 2.0 * PI / omega;
    let dk = 1e-4 * k_est;
    let w_of =
        |k: f64| scheme_angular_frequency_rad_s(&material, diameter_m, dispersion, cell, dt, k);
    let group = (w_of(k_est + dk) - w_of(k_est - dk)) / (2.0 * dk);
    let first = ((wavelength / cell).ceil() as usize).max(1);
    let spacing = ((0.75 * wavelength / cell).round() as usize).max(1);
    let second = first + spacing;
    let x_far = (second as f64 + 0.5) * cell;
    let ramp = 8.0 * period;
    let t_start = ramp + x_far / group + 8.0 * period;
    let t_end = t_start + 24.0 * period;
    let length = 0.5 * (c0 * t_end + x_far) + 2.0 * wavelength;
    let cells = (length / cell).ceil();
    if cells.is_nan() || cells >= MAX_NODES as f64 {
        return Err(val.error(
            "cell_m",
            format!("{cells} cells would be needed"),
            format!("fewer than {MAX_NODES} cells (coarser cells)"),
        ));
    }
    let cells = cells as usize;
    let spec = BarSpec {
        name: "phase-velocity probe".to_string(),
        segments: vec![Segment {
            length_m: cells as f64 * cell,
            diameter_m,
            material,
        }],
        left_end: EndCondition::Absorbing,
        right_end: EndCondition::Absorbing,
        dispersion,
    };
    let dt = Bar::courant_time_step(&spec, cells);
    let mut bar = Bar::new(&spec, dt)?;
    let n_start = (t_start / dt).ceil() as usize;
    let n_end = (t_end / dt).ceil() as usize;
    let mut fits = [HarmonicFit::default(); 2];
    // A dispersive delay line's stations are read after the run, with each wave's whole
    // response (module docs, "Dispersive delay line").
    let after = bar.transit_model().is_some();
    for n in 0..n_end {
        let t = n as f64 * dt;
        if n >= n_start && !after {
            fits[0].add(omega * t, bar.element_strain(first));
            fits[1].add(omega * t, bar.element_strain(second));
        }
        let envelope = if t < ramp {
            (0.5 * PI * t / ramp).sin().powi(2)
        } else {
            1.0
        };
        bar.step(1e3 * envelope * (omega * t).sin(), 0.0);
    }
    bar.check_finite()?;
    let centres = [bar.element_centre_m(first), bar.element_centre_m(second)];
    let steps: Vec<usize> = (n_start..n_end).collect();
    if let Some(rows) = bar.stress_history(&centres, &steps) {
        for (&n, row) in steps.iter().zip(&rows) {
            for (fit, stress) in fits.iter_mut().zip(row) {
                fit.add(omega * n as f64 * dt, stress / material.youngs_modulus_pa);
            }
        }
    }
    let (a1, th1) = fits[0].amplitude_phase();
    let (a2, th2) = fits[1].amplitude_phase();
    let d = spacing as f64 * cell;
    let k = (th2 - th1).rem_euclid(2.0 * PI) / d;
    Ok(PhaseVelocityMeasurement {
        angular_frequency_rad_s: omega,
        wavenumber_rad_m: k,
        phase_velocity_m_s: omega / k,
        station_spacing_m: d,
        amplitude_ratio: a2 / a1,
        cell_m: cell,
        dt_s: dt,
        nodes: bar.node_count(),
        steps: n_end,
    })
}

#[cfg(test)]
mod tests {
    //! The delay line (module docs, "Delay line") against the leapfrog on every node: the same
    //! discrete solution to rounding, and the same energy identity.
    use super::*;

    /// The authors' bars (1.21, 1.02 and 0.10 m) are whole numbers of 1 mm cells, and of 10/3 mm
    /// cells but of no cell between 10/3 and 4 mm.
    #[test]
    fn delay_line_cells_divide_every_bar() {
        let bars = [1.21, 1.02, 0.10];
        assert_eq!(delay_line_cell_m(&bars, 1e-3), Some(1.21 / 1210.0));
        let fast = delay_line_cell_m(&bars, 4e-3).unwrap();
        assert!((fast - 1e-2 / 3.0).abs() < 1e-15, "{fast}");
        assert_eq!(delay_line_cell_m(&[1.0, 0.3333333], 1e-3), None);
    }

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
