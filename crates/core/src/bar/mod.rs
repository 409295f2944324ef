//! The bars (docs/physics.md §6): 1D longitudinal waves `ρA ü = ∂/∂x(EA ∂u/∂x)` on a lumped grid
//! stepped by the leapfrog (§6.2) under one of four theories, each a module behind the private
//! `Interior` trait: `leapfrog` (lumped chain), `love` (Love rod, §6.3), `delay_line` (§6.2) and
//! `dispersive` (§6.2.1); `ends` and `ledger` (§6.6) are shared. x runs from the left end; u, v and
//! forces are positive toward +x, strain, stress and element forces positive in tension.

mod delay_line;
mod dispersive;
mod ends;
mod grid;
mod leapfrog;
mod ledger;
mod love;
mod phase_velocity;

pub use ends::rigid_contact_force_n;
pub use ledger::ENERGY_LEDGER_TOLERANCE;
pub use phase_velocity::{
    PhaseVelocityMeasurement, measure_phase_velocity, rayleigh_love_velocity_ratio,
    scheme_angular_frequency_rad_s, scheme_wavenumber_rad_m,
};

use crate::error::{Named, Result};
use crate::transit::TransitModel;
use delay_line::DelayLine;
use dispersive::Transit;
use ends::Ends;
use grid::{Grid, STABILITY_SLACK, SegmentGrid, free_range};
use leapfrog::Leapfrog;
use ledger::Ledger;
use love::LoveRod;
use std::f64::consts::PI;

/// Largest number of nodes a bar may have (a memory guard: ~100 bytes per node).
pub const MAX_NODES: usize = 20_000_000;

/// Largest |r − 1| of a segment run as a delay line (docs/physics.md §6.2, "Delay lines"): a few ulp, so
/// the delay line and the leapfrog at r = 1 + δ part by about δ per step (3e-12 over 3,000 steps).
const DELAY_LINE_COURANT_SLACK: f64 = 1e-15;

/// How a [`Bar`] advances its interior (docs/physics.md §6.2, "Delay lines").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BarScheme {
    /// An exact delay line when the bar is one uniform segment at Courant 1 with the elementary
    /// theory, else the leapfrog on every node.
    #[default]
    Auto,
    /// The leapfrog on every node (docs/physics.md §6.2), whatever the bar.
    FiniteDifference,
}

thread_local! {
    /// The scheme [`Bar::new`] uses on this thread ([`set_thread_bar_scheme`]).
    static THREAD_SCHEME: std::cell::Cell<BarScheme> = const { std::cell::Cell::new(BarScheme::Auto) };
}

/// Sets the scheme [`Bar::new`] uses on the calling thread and returns the previous one
/// (docs/physics.md §6.2, "Delay lines"): a hook for tests and benchmarks to run a whole simulation both ways.
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

/// Boundary condition at one end of a bar (docs/physics.md §6.2, "Absorbing end").
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
    /// The Rayleigh–Love relation applied to the travelling waves of a delay line
    /// (docs/physics.md §6.2.1; [`crate::transit`]).
    RayleighLove,
    /// The exact first Pochhammer–Chree mode applied to the travelling waves of a delay line
    /// (docs/physics.md §6.2.1; [`crate::transit`]).
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
}

/// A bar discretised for one time step and advanced by [`Bar::step`] (docs/physics.md §6.2).
#[derive(Debug, Clone)]
pub struct Bar {
    name: String,
    step_index: usize,
    x: Vec<f64>,
    segments: Vec<SegmentGrid>,
    /// The node state every theory shares.
    nodes: Nodes,
    /// The theory that holds and advances the interior.
    interior: Theory,
    /// The energy ledger (docs/physics.md §6.6).
    ledger: Ledger,
}

/// The node state every bar theory shares: time step, ends, masses, stiffnesses and u, v, w of
/// every node (a delay line keeps only its end nodes' u, v, w here; docs/physics.md §6.2).
#[derive(Debug, Clone)]
struct Nodes {
    dt_s: f64,
    ends: Ends,
    /// Element stiffness EA/Δx, N/m.
    k: Vec<f64>,
    /// Lumped node mass (with added masses), kg.
    mass: Vec<f64>,
    /// u^n, m.
    u: Vec<f64>,
    /// v^{n−1/2}, m/s.
    v: Vec<f64>,
    /// Free rate: v^{n+1/2} = v^{n−1/2} + Δt (w + response to end forces).
    w: Vec<f64>,
}

/// The interior of a bar under one theory: its mass operator and how it holds and advances the
/// field (docs/physics.md §6.2). `c` is the bar's shared node state; node and element indices
/// run over the whole bar, ends included.
trait Interior {
    /// Recomputes the mass operator after a change of masses (`damping`: the dashpot coefficient
    /// of each node; `fixed`: which ends are clamped).
    fn refresh(&mut self, c: &Nodes, damping: &[f64], fixed: [bool; 2]);

    /// w = A⁻¹ (f_int(u^n) − D v^{n−1/2}): the free velocity change per unit time of the coming step.
    fn update_free_rate(&mut self, c: &mut Nodes);

    /// Change of node i's v^{n+1/2} per unit time from end forces `f` = [left, right], m/s².
    fn force_response(&self, c: &Nodes, i: usize, f: [f64; 2]) -> f64;

    /// Adds the response to the end forces `f` to the free rate w.
    fn add_end_forces(&self, c: &mut Nodes, f: [f64; 2]);

    /// One step of the field: v^{n+1/2} = v^{n−1/2} + Δt w, u^{n+1} = u^n + Δt v^{n+1/2}
    /// (default: the leapfrog on every node).
    fn advance(&mut self, c: &mut Nodes) {
        leapfrog::advance_nodes(c);
    }

    /// Displacement u_i^n, m (default: the node's own, when every node is stepped).
    fn displacement(&self, c: &Nodes, i: usize) -> f64 {
        c.u[i]
    }

    /// Stretch u_{e+1}^n − u_e^n of element e, m.
    fn stretch(&self, c: &Nodes, e: usize) -> f64 {
        c.u[e + 1] - c.u[e]
    }

    /// u(b) − u(a) with u linear between nodes, the points given as (node, weight of the next), m.
    fn stretch_between(&self, c: &Nodes, a: (usize, f64), b: (usize, f64)) -> f64 {
        let at = |(lo, w): (usize, f64)| {
            self.displacement(c, lo) * (1.0 - w) + self.displacement(c, lo + 1) * w
        };
        at(b) - at(a)
    }

    /// Leapfrog velocity v_i^{n−1/2}, m/s.
    fn half_step_velocity(&self, c: &Nodes, i: usize) -> f64 {
        c.v[i]
    }

    /// Velocity at level n, (v^{n−1/2} + v^{n+1/2})/2 with v^{n+1/2} predicted from the current
    /// internal forces and the end forces of the previous step, m/s.
    fn velocity(&self, c: &Nodes, i: usize) -> f64 {
        c.v[i] + 0.5 * c.dt_s * (c.w[i] + self.force_response(c, i, c.ends.last_force))
    }

    /// Momentum Σ m v at level n, kg·m/s.
    fn momentum(&self, c: &Nodes) -> f64 {
        node_momentum(self, c)
    }

    /// Kinetic energy ½ v^{n−1/2}ᵀ M v^{n−1/2}, J.
    fn kinetic_energy(&self, c: &Nodes) -> f64;

    /// Strain energy ½ u^{n−1}ᵀ K u^n, J.
    fn strain_energy(&self, c: &Nodes) -> f64;

    /// Sets the interior moving rigidly at `v_m_s` (the nodes' v is already set).
    fn set_rigid_velocity(&mut self, _c: &Nodes, _v_m_s: f64, _name: &str, _step_index: usize) {}

    /// Restarts what the theory carries beside the energy ledger from the current state.
    fn rebase(&mut self, _c: &Nodes) {}

    /// The Love term ρν²J/Δx per element (empty without it).
    fn lateral_mass(&self) -> &[f64] {
        &[]
    }

    /// The dispersive transit, for a dispersive delay line.
    fn transit(&self) -> Option<&Transit> {
        None
    }

    /// Whether the interior is a delay line.
    fn is_delay_line(&self) -> bool {
        false
    }

    /// The leapfrog on every node with the same state, for a delay line (its interior nodes'
    /// u and v written into `c`); `None` for a bar already on every node.
    fn materialise(&self, _c: &mut Nodes, _name: &str) -> Option<Leapfrog> {
        None
    }

    /// The first non-finite value the interior holds beyond the nodes' u and v: (what, node, value).
    fn first_non_finite(&self, _c: &Nodes) -> Option<(&'static str, usize, f64)> {
        None
    }

    /// Test hook: sets v_i^{n−1/2} of node i.
    #[cfg(test)]
    fn set_half_step_velocity(&mut self, c: &mut Nodes, i: usize, v_m_s: f64) {
        c.v[i] = v_m_s;
    }
}

/// Σ m v of the nodes at level n from [`Interior::velocity`], kg·m/s.
fn node_momentum<I: Interior + ?Sized>(interior: &I, c: &Nodes) -> f64 {
    let last = c.mass.len() - 1;
    (0..=last)
        .map(|i| c.mass[i] * interior.velocity(c, i))
        .sum()
}

/// The bar theories ([`Interior`]).
#[derive(Debug, Clone)]
enum Theory {
    /// The lumped chain on every node ([`leapfrog`]).
    Leapfrog(Leapfrog),
    /// The Love rod on every node ([`love`]).
    Love(LoveRod),
    /// The exact delay line, plain or dispersive ([`delay_line`], [`dispersive`]).
    DelayLine(DelayLine),
}

impl Theory {
    /// The interface of the theory.
    fn get(&self) -> &dyn Interior {
        match self {
            Theory::Leapfrog(t) => t,
            Theory::Love(t) => t,
            Theory::DelayLine(t) => t,
        }
    }

    /// The interface of the theory, mutable.
    fn get_mut(&mut self) -> &mut dyn Interior {
        match self {
            Theory::Leapfrog(t) => t,
            Theory::Love(t) => t,
            Theory::DelayLine(t) => t,
        }
    }
}

impl Bar {
    /// Builds the grid for time step Δt: n_k = ⌊L_k/(c_k Δt)⌋ ≥ 1 cells in segment k (Courant ≤ 1,
    /// = 1 when L_k is a multiple of c_k Δt: exact, no numerical dispersion); refuses (Error::Input)
    /// a Δt above the exact stability limit of that grid (e.g. a segment shorter than c_k Δt), naming it.
    /// Runs as a delay line where it can unless [`set_thread_bar_scheme`] said otherwise.
    pub fn new(spec: &BarSpec, dt_s: f64) -> Result<Bar> {
        Bar::with_scheme(spec, dt_s, THREAD_SCHEME.with(|s| s.get()))
    }

    /// [`Bar::new`] with the interior scheme chosen explicitly (docs/physics.md §6.2, "Delay lines").
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
        let elements = grid.k.len();
        let first = &spec.segments[0];
        let uniform_courant_1 = grid.segments.len() == 1
            && (grid.segments[0].courant_number(dt_s) - 1.0).abs() <= DELAY_LINE_COURANT_SLACK;
        let delay_line = scheme == BarScheme::Auto
            && (spec.dispersion == Dispersion::None || spec.dispersion.transit_model().is_some())
            && uniform_courant_1;
        let interior = match spec.dispersion.transit_model() {
            Some(model) => {
                if !delay_line {
                    return Err(val.error(
                        "dispersion",
                        format!(
                            "dispersion = \"{}\" rides on the travelling waves of a delay line, but bar {} is {}",
                            spec.dispersion.name(),
                            spec.name,
                            if scheme == BarScheme::FiniteDifference {
                                "forced onto finite differences".to_string()
                            } else if grid.segments.len() > 1 {
                                format!("{} segments", grid.segments.len())
                            } else {
                                format!(
                                    "at Courant number {:.6} ({} m is not a whole number of cells c0·Δt = {:e} m)",
                                    grid.segments[0].courant_number(dt_s),
                                    first.length_m,
                                    first.material.wave_speed_m_s() * dt_s
                                )
                            }
                        ),
                        "one uniform segment whose length is a whole number of cells c0·Δt (choose the \
                         cell size so, e.g. 1 mm for the authors' bars), or dispersion = \"love-rod\" \
                         (finite differences on any bar)",
                    ));
                }
                let design = crate::transit::shared_design(
                    model,
                    first.material.poisson_ratio,
                    0.5 * first.diameter_m,
                    grid.segments[0].dx_m,
                    elements,
                );
                Theory::DelayLine(DelayLine::dispersive(design, elements))
            }
            None if delay_line => Theory::DelayLine(DelayLine::new(elements)),
            None if spec.dispersion == Dispersion::LoveRod => {
                Theory::Love(LoveRod::new(grid.beta, n))
            }
            None => Theory::Leapfrog(Leapfrog::new(n)),
        };
        let mut bar = Bar {
            name: spec.name.clone(),
            step_index: 0,
            x: grid.x,
            segments: grid.segments,
            nodes: Nodes {
                dt_s,
                ends: Ends::new(spec),
                k: grid.k,
                mass: grid.mass,
                u: vec![0.0; n],
                v: vec![0.0; n],
                w: vec![0.0; n],
            },
            interior,
            ledger: Ledger::default(),
        };
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
        let fixed = self.nodes.ends.fixed();
        let damping = self.nodes.ends.damping(self.nodes.mass.len());
        self.interior
            .get_mut()
            .refresh(&self.nodes, &damping, fixed);
        self.update_free_rate();
        self.rebase_energy_ledger();
    }

    /// w = A⁻¹ (f_int(u^n) − D v^{n−1/2}): the free velocity change per unit time of the coming step.
    fn update_free_rate(&mut self) {
        self.interior.get_mut().update_free_rate(&mut self.nodes);
    }

    /// The bar's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Time step Δt, s.
    pub fn dt_s(&self) -> f64 {
        self.nodes.dt_s
    }

    /// Number of nodes N + 1 (cell boundaries, both ends included).
    pub fn node_count(&self) -> usize {
        self.nodes.u.len()
    }

    /// Number of cells (elements) N.
    pub fn element_count(&self) -> usize {
        self.nodes.k.len()
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
        self.segments[k].courant_number(self.nodes.dt_s)
    }

    /// Segment containing element e.
    fn segment_of_element(&self, e: usize) -> usize {
        self.segments
            .iter()
            .rposition(|s| s.first_element <= e)
            .unwrap_or(0)
    }

    /// Position of node i along the bar from the left end, m.
    pub fn node_position_m(&self, i: usize) -> f64 {
        self.x[i]
    }

    /// Displacement u_i^n of node i at the current time level, m (a delay line sums the element
    /// stretches from the nearer end, docs/physics.md §6.2).
    pub fn displacement_m(&self, i: usize) -> f64 {
        self.interior.get().displacement(&self.nodes, i)
    }

    /// Whether the bar runs as an exact delay line (docs/physics.md §6.2, "Delay lines").
    pub fn is_delay_line(&self) -> bool {
        self.interior.get().is_delay_line()
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
        let a = self.node_interval(x_a_m);
        let b = self.node_interval(x_b_m);
        self.interior.get().stretch_between(&self.nodes, a, b)
    }

    /// Leapfrog velocity v_i^{n−1/2} of node i (half a step behind the current level), m/s.
    pub fn half_step_velocity_m_s(&self, i: usize) -> f64 {
        self.interior.get().half_step_velocity(&self.nodes, i)
    }

    /// Velocity of node i at the current level n, (v^{n−1/2} + v^{n+1/2})/2 with v^{n+1/2} predicted
    /// from the current internal forces and the end forces of the previous step, m/s.
    pub fn velocity_m_s(&self, i: usize) -> f64 {
        self.interior.get().velocity(&self.nodes, i)
    }

    /// Sets the whole bar moving rigidly at `v_m_s` (a striker): v^{−1/2} = v, fixed end nodes stay at rest.
    pub fn set_initial_velocity(&mut self, v_m_s: f64) {
        self.nodes.v.fill(v_m_s);
        self.interior
            .get_mut()
            .set_rigid_velocity(&self.nodes, v_m_s, &self.name, self.step_index);
        let n = self.nodes.v.len();
        let fixed = self.nodes.ends.fixed();
        if fixed[0] {
            self.nodes.v[0] = 0.0;
        }
        if fixed[1] {
            self.nodes.v[n - 1] = 0.0;
        }
        self.update_free_rate();
        self.rebase_energy_ledger();
    }

    /// Advances one step with external axial forces (N, toward +x) on the first and last node at the
    /// current level: v^{n+1/2} = v^{n−1/2} + Δt M⁻¹(f_int + f_ext − D v̄), u^{n+1} = u^n + Δt v^{n+1/2}
    /// (docs/physics.md §6.2).
    pub fn step(&mut self, left_force_n: f64, right_force_n: f64) {
        let dt = self.nodes.dt_s;
        let last = self.nodes.u.len() - 1;
        let f = self.nodes.ends.forces(left_force_n, right_force_n);
        let v_before = [self.nodes.v[0], self.nodes.v[last]];
        let interior = self.interior.get_mut();
        interior.add_end_forces(&mut self.nodes, f);
        interior.advance(&mut self.nodes);
        let v_after = [self.nodes.v[0], self.nodes.v[last]];
        self.ledger
            .book(self.nodes.ends.impedance, f, v_before, v_after, dt);
        self.nodes.ends.last_force = f;
        self.step_index += 1;
        self.update_free_rate();
    }

    /// Strain (u_{e+1} − u_e)/Δx of element e at the current level (tension positive).
    pub fn element_strain(&self, e: usize) -> f64 {
        let s = &self.segments[self.segment_of_element(e)];
        self.interior.get().stretch(&self.nodes, e) / s.dx_m
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
        let interior = self.interior.get();
        let strain = |e: usize| interior.stretch(&self.nodes, e) / dx;
        if t == 0.0 {
            return strain(e);
        }
        (1.0 - t) * strain(e) + t * strain(e + 1)
    }

    /// Axial stress E·ε at x with E of the segment there, Pa (tension positive).
    pub fn stress_at(&self, x_m: f64) -> f64 {
        self.segments[self.segment_at(x_m)].youngs_modulus_pa * self.strain_at(x_m)
    }

    /// [`Bar::stress_at`] at each of `x_m` found once (segment, element and weight), for
    /// [`Bar::sample_stress`] to read the bar at the same points step after step without the
    /// search (the x–t snapshots, docs/physics.md §6.2).
    pub fn stress_sampler(&self, x_m: &[f64]) -> StressSampler {
        let points = x_m
            .iter()
            .map(|&x| {
                let (k, element, weight) = self.strain_point(x);
                let s = &self.segments[k];
                StressPoint {
                    element,
                    weight,
                    dx_m: s.dx_m,
                    youngs_modulus_pa: s.youngs_modulus_pa,
                }
            })
            .collect();
        StressSampler { points }
    }

    /// The stresses [`Bar::stress_at`] gives at the points of `sampler` (made by
    /// [`Bar::stress_sampler`] for this bar), the same formula on the same operands: E·ε with
    /// ε = (1 − t) ε_e + t ε_{e+1} (ε_e alone where t = 0), ε_e = (u_{e+1} − u_e)/Δx, Pa.
    pub fn sample_stress(&self, sampler: &StressSampler) -> Vec<f64> {
        // One call per theory, so that each reads its elements without dynamic dispatch; a
        // plain delay line straight from its ring buffers (the values `stretch` gives).
        let (c, points) = (&self.nodes, &sampler.points);
        match &self.interior {
            Theory::Leapfrog(t) => sample_stress(|e| t.stretch(c, e), points),
            Theory::Love(t) => sample_stress(|e| t.stretch(c, e), points),
            Theory::DelayLine(t) => match t.rings() {
                Some((right, left, shift)) => {
                    let n = right.len();
                    sample_stress(
                        |e| {
                            let r = e + n - shift;
                            let l = e + shift;
                            right[if r >= n { r - n } else { r }]
                                + left[if l >= n { l - n } else { l }]
                        },
                        points,
                    )
                }
                None => sample_stress(|e| t.stretch(c, e), points),
            },
        }
    }

    /// The dispersive transit of a delay line, if the bar has one.
    fn transit(&self) -> Option<&Transit> {
        self.interior.get().transit()
    }

    /// The dispersion relation the bar's travelling waves carry, if it is a dispersive delay line.
    pub fn transit_model(&self) -> Option<TransitModel> {
        self.transit().map(|t| t.design.model())
    }

    /// Time t = nΔt of the current level, s.
    pub fn time_s(&self) -> f64 {
        self.step_index as f64 * self.nodes.dt_s
    }

    /// Number n of steps taken.
    pub fn step_index(&self) -> usize {
        self.step_index
    }
}

/// One point of a [`StressSampler`]: what [`Bar::strain_at`] finds for its x.
#[derive(Debug, Clone, Copy, PartialEq)]
struct StressPoint {
    /// Element e (strain = (1 − t) ε_e + t ε_{e+1}).
    element: usize,
    /// Weight t of element e + 1 (0: ε_e alone).
    weight: f64,
    /// Cell size Δx of the segment holding the point, m.
    dx_m: f64,
    /// Young's modulus E of that segment, Pa.
    youngs_modulus_pa: f64,
}

/// Points along a bar with their elements and weights found once ([`Bar::stress_sampler`]), read
/// by [`Bar::sample_stress`] (docs/physics.md §6.2).
#[derive(Debug, Clone, PartialEq)]
pub struct StressSampler {
    points: Vec<StressPoint>,
}

impl StressSampler {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether it has no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// [`Bar::sample_stress`] with `stretch(e)` the stretch s_e of element e: E·((1 − t) s_e/Δx +
/// t s_{e+1}/Δx), as [`Bar::strain_at`] and [`Bar::stress_at`] compute it, Pa.
fn sample_stress(stretch: impl Fn(usize) -> f64, points: &[StressPoint]) -> Vec<f64> {
    points
        .iter()
        .map(|p| {
            let strain = |e: usize| stretch(e) / p.dx_m;
            let strain = if p.weight == 0.0 {
                strain(p.element)
            } else {
                (1.0 - p.weight) * strain(p.element) + p.weight * strain(p.element + 1)
            };
            p.youngs_modulus_pa * strain
        })
        .collect()
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

#[cfg(test)]
mod tests {
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

    /// A steel (or aluminium) segment, 19.05 mm.
    fn segment(length_m: f64, youngs_modulus_pa: f64, density_kg_m3: f64) -> Segment {
        Segment {
            length_m,
            diameter_m: 0.01905,
            material: BarMaterial {
                density_kg_m3,
                youngs_modulus_pa,
                poisson_ratio: 0.29,
            },
        }
    }

    /// The x–t snapshots' sampler reads every theory as [`Bar::stress_at`] does, bit for bit (the
    /// same formula on the same operands, the search done once): a delay line plain and
    /// dispersive, the leapfrog, the Love rod and a two-segment bar (steel then aluminium, an
    /// interface between cells), each struck and pushed at its ends for a few hundred steps, at
    /// points before, on and beyond the ends, on nodes, element centres and the interface.
    #[test]
    fn sampled_stresses_are_stress_at() {
        let steel = segment(0.3, 200e9, 7850.0);
        let one = |dispersion| BarSpec {
            name: "probe".into(),
            segments: vec![steel],
            left_end: EndCondition::Free,
            right_end: EndCondition::Absorbing,
            dispersion,
        };
        let two = BarSpec {
            segments: vec![segment(0.17, 200e9, 7850.0), segment(0.13, 70e9, 2700.0)],
            ..one(Dispersion::None)
        };
        let dt = Bar::courant_time_step(&one(Dispersion::None), 300);
        let bars = [
            Bar::with_scheme(&one(Dispersion::None), dt, BarScheme::Auto).unwrap(),
            Bar::with_scheme(&one(Dispersion::PochhammerChree), dt, BarScheme::Auto).unwrap(),
            Bar::with_scheme(&one(Dispersion::None), dt, BarScheme::FiniteDifference).unwrap(),
            Bar::with_scheme(&one(Dispersion::LoveRod), dt, BarScheme::Auto).unwrap(),
            Bar::with_scheme(&two, dt, BarScheme::Auto).unwrap(),
        ];
        assert!(bars[0].is_delay_line() && bars[0].transit_model().is_none());
        assert!(bars[1].is_delay_line() && bars[1].transit_model().is_some());
        assert!(!bars[2].is_delay_line() && !bars[4].is_delay_line());
        let mut x_m: Vec<f64> = (-2..=62).map(|k| 0.3 * k as f64 / 60.0).collect();
        x_m.extend([
            0.0005,
            0.17,
            0.1699,
            0.1701,
            0.2995,
            0.3,
            1e-9,
            f64::MIN_POSITIVE,
        ]);
        for mut bar in bars {
            bar.set_initial_velocity(3.0);
            let sampler = bar.stress_sampler(&x_m);
            assert_eq!(sampler.len(), x_m.len());
            let mut compared = 0;
            for n in 0..700 {
                let push = 1e4 * (n as f64 * 0.05).sin().max(0.0);
                bar.step(push, -0.3 * push);
                if n % 7 == 0 {
                    let sampled = bar.sample_stress(&sampler);
                    for (x, s) in x_m.iter().zip(&sampled) {
                        let reference = bar.stress_at(*x);
                        assert_eq!(s.to_bits(), reference.to_bits(), "{} at {x}", bar.name());
                        compared += usize::from(reference != 0.0);
                    }
                }
            }
            assert!(
                compared > 1000,
                "{}: only {compared} loaded points",
                bar.name()
            );
        }
    }
}
