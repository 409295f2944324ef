//! Shared test fixtures of the core's unit tests (one copy).

use crate::material::{JohnsonCook, Material};
use crate::specimen::SpherePair;

/// SS440c as in `specimens/ss440c.toml` (paper Table I; ν assumed, docs/physics.md §4).
pub fn ss440c() -> Material {
    Material {
        name: "ss440c".into(),
        density_kg_m3: 7800.0,
        youngs_modulus_pa: 204e9,
        poisson_ratio: 0.28,
        yield_stress_pa: 1900e6,
        rate: JohnsonCook {
            c: 0.035,
            reference_rate_per_s: 1e-3,
        },
    }
}

/// The paper's pair: two 6.35 mm SS440c spheres.
pub fn ss440c_pair() -> SpherePair {
    SpherePair::paper(ss440c())
}
