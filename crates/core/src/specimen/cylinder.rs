//! A cylindrical specimen between the bars (docs/physics.md §6.9): its geometry and material,
//! and its resolution on the bars' time step.

use crate::bar::{BarMaterial, BarSpec, Dispersion, EndCondition, Segment};

/// Fewest cells the chain gives a cylindrical specimen (docs/physics.md §6.9): its lowest
/// longitudinal mode (half a wavelength over L_s) on ≥ 4 cells, and its Courant number
/// n c_s Δt/L_s ≥ 0.8, so its ring-up (a few transits L_s/c_s) is resolved in time and space.
pub const CYLINDER_MIN_CELLS: usize = 4;

/// An elastic cylindrical specimen between the bars (docs/physics.md §6.9): a bar segment of its
/// own material and diameter, pressed on both bars (or inserts) by compression-only butt joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderSpecimen {
    /// Material (E, ν, ρ), as for bars and inserts.
    pub material: BarMaterial,
    /// Diameter d_s, m.
    pub diameter_m: f64,
    /// Length L_s along the bar axis, m.
    pub length_m: f64,
}

impl CylinderSpecimen {
    /// The specimen as one uniform bar segment.
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

    /// Cells the chain gives the specimen at time step `dt_s`: ⌊L_s/(c_s Δt)⌋ (Courant ≤ 1, as
    /// every bar segment, docs/physics.md §6.2).
    pub fn cells_at(&self, dt_s: f64) -> usize {
        let s = self.segment();
        BarSpec {
            name: "specimen".into(),
            segments: vec![s],
            left_end: EndCondition::Free,
            right_end: EndCondition::Free,
            dispersion: Dispersion::None,
        }
        .cells_for_time_step(dt_s)[0]
    }

    /// Largest bar cell (Δx = c0 Δt, Courant 1 in bars of speed `bar_wave_speed_m_s`) that gives
    /// the specimen at least `cells` cells: c0 L_s/(c_s · cells), m.
    pub fn largest_bar_cell_m(&self, bar_wave_speed_m_s: f64, cells: usize) -> f64 {
        bar_wave_speed_m_s * self.transit_s() / cells as f64
    }
}
