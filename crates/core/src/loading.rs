//! How a bar test loads its specimen (docs/physics.md §6.13, §7.8.1): in compression (a split
//! Hopkinson pressure bar, the striker pushing the incident bar) or in tension (a split Hopkinson
//! tension bar, SHTB: a tensile incident pulse, the specimen threaded or bonded to both bars).
//!
//! The tension bar is modelled as the flange bar: a striker tube sliding along the incident bar
//! strikes a flange on its far end and the tube's compression enters the bar as tension. Mirrored
//! through the flange, the tube is a striker moving away from the incident bar whose joint carries
//! tension only ([`crate::solver::Joint::Flange`]); for a tube of the bar's impedance the incident
//! pulse is the compression bar's pulse with its sign turned. The specimen's faces are bonded
//! ([`crate::solver::Joint::Bonded`]), and the reduction reads the records in the loading's sense
//! ([`Loading::sign`]): tension positive for a tension test's forces, stresses and strains.

/// The sense in which a bar test loads its specimen (scene key `loading`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Loading {
    /// Split Hopkinson pressure bar: a compressive incident pulse, butt joints at the faces.
    #[default]
    Compression,
    /// Split Hopkinson tension bar: a tensile incident pulse, the specimen bonded to the bars.
    Tension,
}

impl Loading {
    /// Every loading, in the order the scene key lists them.
    pub const ALL: [Loading; 2] = [Loading::Compression, Loading::Tension];

    /// The scene key's value (`compression`, `tension`).
    pub fn name(self) -> &'static str {
        match self {
            Loading::Compression => "compression",
            Loading::Tension => "tension",
        }
    }

    /// The loading of a scene key's value, None if unknown.
    pub fn parse(name: &str) -> Option<Loading> {
        Loading::ALL.into_iter().find(|l| l.name() == name)
    }

    /// Whether the test is a tension test.
    pub fn is_tension(self) -> bool {
        self == Loading::Tension
    }

    /// The sign s that turns a gauge strain (tension positive) into the loading's sense in which
    /// a compression reduction reads it: +1 in compression, −1 in tension (docs/physics.md §7.8.1).
    pub fn sign(self) -> f64 {
        match self {
            Loading::Compression => 1.0,
            Loading::Tension => -1.0,
        }
    }

    /// The loading of a reduction's `tension` flag.
    pub fn of_tension(tension: bool) -> Loading {
        if tension {
            Loading::Tension
        } else {
            Loading::Compression
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_the_default_is_compression() {
        for l in Loading::ALL {
            assert_eq!(Loading::parse(l.name()), Some(l));
        }
        assert_eq!(Loading::parse("shear"), None);
        assert_eq!(Loading::default(), Loading::Compression);
        assert_eq!(Loading::Tension.sign(), -1.0);
        assert_eq!(Loading::of_tension(true), Loading::Tension);
    }
}
