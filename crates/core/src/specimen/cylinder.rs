//! A cylindrical specimen between the bars (docs/physics.md §6.9, §6.12): its geometry, its
//! elastic material and how it flows (elastic, Johnson–Cook or a table; end friction; radial
//! inertia), and its resolution on the bars' time step. The chain steps it as
//! `solver::cylinder::PlasticCylinder`.

use crate::bar::{BarMaterial, BarSpec, Dispersion, EndCondition, Segment};
use crate::error::{Named, Result};
use crate::flow::{FlowModel, Friction};

/// Fewest cells the chain gives a cylindrical specimen (docs/physics.md §6.9): its lowest
/// longitudinal mode (half a wavelength over L_s) on ≥ 4 cells, and its Courant number
/// n c_s Δt/L_s ≥ 0.8, so its ring-up (a few transits L_s/c_s) is resolved in time and space.
pub const CYLINDER_MIN_CELLS: usize = 4;

/// Compressive true strain a flowing cylinder's grid is built for by default
/// ([`CylinderSpecimen::design_true_strain`], docs/physics.md §6.12): the element stiffness grows
/// as e^{2ε}, so cells sized for the initial length would leave the stable range as it shortens.
pub const DEFAULT_DESIGN_TRUE_STRAIN: f64 = 0.5;

/// Aspect ratios L/D outside which a run warns (docs/physics.md §6.12): below 0.5 end friction,
/// above 2 the specimen's own inertia and equilibrium time dominate what the reduction reads
/// (Gray, ASM Handbook 8 (2000), "Classic split-Hopkinson pressure bar testing").
pub const ASPECT_RATIO_RANGE: (f64, f64) = (0.5, 2.0);

/// A cylindrical specimen between the bars (docs/physics.md §6.9, §6.12): a short cylinder of its
/// own material pressed on both bars (or inserts) by compression-only butt joints. With
/// [`FlowModel::Elastic`], no friction and no radial inertia it is a bar segment of its material.
#[derive(Debug, Clone, PartialEq)]
pub struct CylinderSpecimen {
    /// Material (E, ν, ρ), as for bars and inserts.
    pub material: BarMaterial,
    /// Initial diameter d₀, m.
    pub diameter_m: f64,
    /// Initial length L₀ along the bar axis, m.
    pub length_m: f64,
    /// The flow stress ([`FlowModel::Elastic`]: an elastic cylinder).
    pub flow: FlowModel,
    /// Radial inertia (Davies & Hunter 1963): the lateral kinetic energy ½ρν_eff²J(u̇')².
    pub radial_inertia: bool,
    /// End friction (None: frictionless faces).
    pub friction: Option<Friction>,
    /// Initial temperature, K.
    pub initial_temperature_k: f64,
    /// Compressive true strain the grid is built to carry stably: the cells are those of a
    /// segment of length L₀ e^{−ε_d} (0: exactly a bar segment's).
    pub design_true_strain: f64,
}

impl CylinderSpecimen {
    /// The name of the specimen's body in the chain (and of its errors).
    pub const NAME: &'static str = "specimen";

    /// An elastic cylinder at 293 K: today's bar segment of its material (docs/physics.md §6.9).
    pub fn elastic(material: BarMaterial, diameter_m: f64, length_m: f64) -> CylinderSpecimen {
        CylinderSpecimen {
            material,
            diameter_m,
            length_m,
            flow: FlowModel::Elastic,
            radial_inertia: false,
            friction: None,
            initial_temperature_k: 293.0,
            design_true_strain: 0.0,
        }
    }

    /// Checks every number (Error::Invalid naming the key).
    pub fn validate(&self) -> Result<()> {
        let v = Named::new(Self::NAME);
        v.positive("length_m", self.length_m, 10.0, "m")?;
        v.positive("diameter_m", self.diameter_m, 10.0, "m")?;
        let m = v.table("material");
        m.positive("density_kg_m3", self.material.density_kg_m3, 1e5, "kg/m³")?;
        m.positive(
            "youngs_modulus_pa",
            self.material.youngs_modulus_pa,
            1e13,
            "Pa",
        )?;
        m.in_range(
            "poisson_ratio",
            self.material.poisson_ratio,
            -0.99,
            0.4999,
            "",
        )?;
        self.flow.validate(Self::NAME)?;
        if let Some(f) = &self.friction {
            v.table("friction")
                .in_range("coefficient", f.coefficient, 0.0, 10.0, "")?;
        }
        v.positive(
            "initial_temperature_k",
            self.initial_temperature_k,
            1e4,
            "K",
        )?;
        v.in_range("design_true_strain", self.design_true_strain, 0.0, 2.0, "")?;
        Ok(())
    }

    /// The specimen as one uniform bar segment (its initial geometry).
    pub fn segment(&self) -> Segment {
        Segment {
            length_m: self.length_m,
            diameter_m: self.diameter_m,
            material: self.material,
        }
    }

    /// Cross-section A_s = π d_s²/4, m².
    pub fn area_m2(&self) -> f64 {
        self.segment().area_m2()
    }

    /// One-way wave transit L_s/c_s, s (c_s = √(E_s/ρ_s), docs/physics.md §6.9).
    pub fn transit_s(&self) -> f64 {
        self.length_m / self.material.wave_speed_m_s()
    }

    /// The length the grid is built on, L₀ e^{−ε_d}, m.
    fn design_length_m(&self) -> f64 {
        self.length_m * (-self.design_true_strain).exp()
    }

    /// Cells the chain gives the specimen at time step `dt_s`: ⌊L₀ e^{−ε_d}/(c_s Δt)⌋ (Courant
    /// ≤ 1, as every bar segment, docs/physics.md §6.2), exactly a bar segment's for ε_d = 0.
    pub fn cells_at(&self, dt_s: f64) -> usize {
        let mut s = self.segment();
        s.length_m = self.design_length_m();
        BarSpec {
            name: Self::NAME.into(),
            segments: vec![s],
            left_end: EndCondition::Free,
            right_end: EndCondition::Free,
            dispersion: Dispersion::None,
        }
        .cells_for_time_step(dt_s)[0]
    }

    /// Largest bar cell (Δx = c0 Δt, Courant 1 in bars of speed `bar_wave_speed_m_s`) that gives
    /// the specimen at least `cells` cells: c0 L₀ e^{−ε_d}/(c_s · cells), m.
    pub fn largest_bar_cell_m(&self, bar_wave_speed_m_s: f64, cells: usize) -> f64 {
        bar_wave_speed_m_s * self.design_length_m() / self.material.wave_speed_m_s() / cells as f64
    }

    /// Length over diameter, L₀/d₀.
    pub fn aspect_ratio(&self) -> f64 {
        self.length_m / self.diameter_m
    }

    /// Warnings about the specimen before it runs (docs/physics.md §6.12): an aspect ratio
    /// outside [`ASPECT_RATIO_RANGE`].
    pub fn warnings(&self) -> Vec<String> {
        let (lo, hi) = ASPECT_RATIO_RANGE;
        let r = self.aspect_ratio();
        if (lo..=hi).contains(&r) {
            return vec![];
        }
        vec![format!(
            "the cylinder's L/D = {r:.3} is outside {lo}–{hi}: {} (docs/physics.md §6.12)",
            if r < lo {
                "end friction raises the stress the bars read (set friction_coefficient to model it)"
            } else {
                "the specimen's inertia and its time to equilibrium grow as L², and a long specimen buckles"
            }
        )]
    }
}
