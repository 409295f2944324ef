//! The specimen a scene tests, one variant per kind ([`Specimen`]): spheres in a line with their
//! contact law (docs/physics.md §1–§3, §8, §6.11) or a cylinder (§6.9). Each kind lives in its own
//! module and brings what the rest of the code asks of a specimen: its model, the lengths its
//! strain rate is reduced over, and its warnings. Its place in the bar chain is
//! `Apparatus::pulse_chain`'s (this module sits below the solver, which uses the sphere data).

pub mod cylinder;
pub mod spheres;

pub use cylinder::{
    ASPECT_RATIO_RANGE, CYLINDER_MIN_CELLS, CylinderSpecimen, DEFAULT_DESIGN_TRUE_STRAIN,
};
pub use spheres::{
    ContactProperties, MODEL_APPROACH_LIMIT_OF_RADIUS, Seating, Sphere, SphereChain, SpherePair,
    SphereSpecimen, reduced_mass_kg,
};

/// The specimen of a scene (docs/physics.md §1, §6.9, §8).
#[derive(Debug, Clone, PartialEq)]
pub enum Specimen {
    /// Two or more spheres in a line (a pair is the chain of two) with their contact law.
    Spheres(SphereSpecimen),
    /// A cylinder between the bars (docs/physics.md §6.9).
    Cylinder(CylinderSpecimen),
}

impl Specimen {
    /// The spheres, if the specimen is spheres.
    pub fn spheres(&self) -> Option<&SphereSpecimen> {
        match self {
            Specimen::Spheres(s) => Some(s),
            Specimen::Cylinder(_) => None,
        }
    }

    /// The cylinder, if the specimen is one.
    pub fn cylinder(&self) -> Option<&CylinderSpecimen> {
        match self {
            Specimen::Cylinder(c) => Some(c),
            Specimen::Spheres(_) => None,
        }
    }
}
