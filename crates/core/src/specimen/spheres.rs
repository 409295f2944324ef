//! Spheres as a specimen: two (possibly dissimilar) spheres and their effective contact properties
//! (paper Sec. II: E*, r; docs/physics.md §1), a chain of N spheres ([`SphereChain`], §8), how
//! they sit before the test ([`Seating`]: touching, a gap or a preload; §6.11), and the three as
//! a scene's specimen with its contact law ([`SphereSpecimen`]).

use crate::material::Material;

/// One sphere of the specimen.
#[derive(Debug, Clone, PartialEq)]
pub struct Sphere {
    /// Its material.
    pub material: Material,
    /// Radius of curvature at the contact, m.
    pub radius_m: f64,
    /// Mass, kg (default: the full sphere, a fair approximation for the truncated ones, docs/physics.md §5).
    pub mass_kg: f64,
}

impl Sphere {
    /// A full sphere of `material` with radius `radius_m`.
    pub fn full(material: Material, radius_m: f64) -> Sphere {
        let mass_kg = material.density_kg_m3 * 4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3);
        Sphere {
            material,
            radius_m,
            mass_kg,
        }
    }
}

pub use crate::contact::ContactProperties;

/// Largest approach δ, as a fraction of the smaller sphere radius, over which the contact law
/// was fitted: the paper's quasi-static FEM (Fig. 2) compressed 3.175 mm hemispheres to at most
/// δ = 0.6 mm (0.19 R), its constant-rate FEM (Fig. 3) to 0.25 mm (0.08 R). Beyond 0.2 R the law
/// (and Hertz's small-strain theory) is extrapolated and a run says so (a warning, not an error).
pub const MODEL_APPROACH_LIMIT_OF_RADIUS: f64 = 0.2;

/// Two spheres in contact: sphere 1 is on the incident side, sphere 2 on the transmission side.
#[derive(Debug, Clone, PartialEq)]
pub struct SpherePair {
    /// Incident-side sphere.
    pub sphere1: Sphere,
    /// Transmission-side sphere.
    pub sphere2: Sphere,
}

impl SpherePair {
    /// The paper's specimen: two full spheres of `material`, 6.35 mm in diameter.
    pub fn paper(material: Material) -> SpherePair {
        let s = Sphere::full(material, 6.35e-3 / 2.0);
        SpherePair {
            sphere1: s.clone(),
            sphere2: s,
        }
    }

    /// Effective contact properties of the pair (docs/physics.md §1).
    pub fn contact_properties(&self) -> ContactProperties {
        let (a, b) = (&self.sphere1, &self.sphere2);
        let e_star_pa = 1.0
            / (1.0 / a.material.plane_strain_modulus_pa()
                + 1.0 / b.material.plane_strain_modulus_pa());
        let radius_m = 1.0 / (1.0 / a.radius_m + 1.0 / b.radius_m);
        let weaker = if a.material.yield_stress_pa <= b.material.yield_stress_pa {
            a
        } else {
            b
        };
        ContactProperties {
            e_star_pa,
            radius_m,
            sum_of_radii_m: a.radius_m + b.radius_m,
            yield_stress_pa: weaker.material.yield_stress_pa,
            rate: weaker.material.rate,
            wave_speed_m_s: a.material.wave_speed_m_s().min(b.material.wave_speed_m_s()),
        }
    }

    /// Reduced mass m1 m2 / (m1 + m2), kg.
    pub fn reduced_mass_kg(&self) -> f64 {
        let (m1, m2) = (self.sphere1.mass_kg, self.sphere2.mass_kg);
        m1 * m2 / (m1 + m2)
    }
}

/// Reduced mass m1 m2 / (m1 + m2) of two bodies, kg; an infinite mass (a fixed wall) gives the
/// other mass (docs/physics.md §8).
pub fn reduced_mass_kg(m1_kg: f64, m2_kg: f64) -> f64 {
    if m2_kg.is_infinite() {
        m1_kg
    } else if m1_kg.is_infinite() {
        m2_kg
    } else {
        m1_kg * m2_kg / (m1_kg + m2_kg)
    }
}

impl Sphere {
    /// Effective properties of this sphere pressed on a flat face (a wall or a striker) of
    /// `flat` (None: rigid), docs/physics.md §8: E* from both moduli (the rigid flat adds no
    /// compliance), r = the sphere's radius, the strain-rate length r (the sphere alone
    /// deforms over its radius), yield stress and rate hardening of the weaker material.
    pub fn against_flat(&self, flat: Option<&Material>) -> ContactProperties {
        let flat_compliance = flat.map_or(0.0, |m| 1.0 / m.plane_strain_modulus_pa());
        let e_star_pa = 1.0 / (1.0 / self.material.plane_strain_modulus_pa() + flat_compliance);
        let weaker = match flat {
            Some(m) if m.yield_stress_pa < self.material.yield_stress_pa => m,
            _ => &self.material,
        };
        ContactProperties {
            e_star_pa,
            radius_m: self.radius_m,
            sum_of_radii_m: self.radius_m,
            yield_stress_pa: weaker.yield_stress_pa,
            rate: weaker.rate,
            wave_speed_m_s: flat.map_or(self.material.wave_speed_m_s(), |m| {
                m.wave_speed_m_s().min(self.material.wave_speed_m_s())
            }),
        }
    }
}

/// N ≥ 2 spheres in a line, touching, sphere 1 first (docs/physics.md §8): each neighbouring
/// two form a contact with the effective properties of a [`SpherePair`].
#[derive(Debug, Clone, PartialEq)]
pub struct SphereChain {
    /// The spheres, in order (sphere 1 first: the struck or incident-side end).
    pub spheres: Vec<Sphere>,
}

impl SphereChain {
    /// The chain of a pair: sphere 1, then sphere 2.
    pub fn from_pair(pair: &SpherePair) -> SphereChain {
        SphereChain {
            spheres: vec![pair.sphere1.clone(), pair.sphere2.clone()],
        }
    }

    /// Number of spheres.
    pub fn len(&self) -> usize {
        self.spheres.len()
    }

    /// Whether the chain has no sphere (never for a validated chain).
    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }

    /// Number of sphere–sphere contacts, N − 1.
    pub fn contacts(&self) -> usize {
        self.spheres.len().saturating_sub(1)
    }

    /// Contact `k` (0-based: between spheres k + 1 and k + 2) as a pair.
    pub fn pair(&self, k: usize) -> SpherePair {
        SpherePair {
            sphere1: self.spheres[k].clone(),
            sphere2: self.spheres[k + 1].clone(),
        }
    }

    /// Effective properties of contact `k`, exactly as the pair of its two spheres (§1).
    pub fn contact_properties(&self, k: usize) -> ContactProperties {
        self.pair(k).contact_properties()
    }

    /// Σ rᵢ: half the chain's length, the length of the global strain rate δ̇/Σ rᵢ of the whole
    /// specimen (r1 + r2 for a pair, paper Eq. 3), m.
    pub fn half_length_m(&self) -> f64 {
        self.spheres.iter().map(|s| s.radius_m).sum()
    }

    /// The smallest sphere radius, m.
    pub fn min_radius_m(&self) -> f64 {
        self.spheres
            .iter()
            .map(|s| s.radius_m)
            .fold(f64::INFINITY, f64::min)
    }
}

/// How the spheres of a test sit between the bars before the incident wave arrives
/// (docs/physics.md §6.11): applied to every sphere–sphere contact of the specimen.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Seating {
    /// Touching at rest, carrying no force (the default).
    #[default]
    Touching,
    /// Each contact open by `gap_m` (m, > 0): it carries force once its closure exceeds the gap.
    Gap {
        /// The gap, m.
        gap_m: f64,
    },
    /// Each contact pressed by a static force `force_n` (N, > 0), bars and spheres at rest in
    /// equilibrium under it; the test is the change from that state (linear bars: the static
    /// state superposes), the contact law starting from its quasi-static loading to that force.
    Preload {
        /// The static force, N.
        force_n: f64,
    },
}

/// Spheres in a line as the specimen of a scene (docs/physics.md §8, §6.11): the chain (a pair is
/// the chain of two), the contact law of every contact and how each contact sits.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereSpecimen {
    /// The spheres, sphere 1 first (on the incident bar in a bar test).
    pub chain: SphereChain,
    /// Contact law of every contact, with its own parameters.
    pub law: crate::contact::LawSpec,
    /// How every sphere–sphere contact sits before the test.
    pub seating: Seating,
}

impl SphereSpecimen {
    /// A pair touching at rest with the law `law`.
    pub fn pair(pair: &SpherePair, law: crate::contact::LawSpec) -> SphereSpecimen {
        SphereSpecimen {
            chain: SphereChain::from_pair(pair),
            law,
            seating: Seating::Touching,
        }
    }

    /// The first pair (spheres 1 and 2).
    pub fn first_pair(&self) -> SpherePair {
        self.chain.pair(0)
    }

    /// The two lengths whose sum divides the approach rate into the global strain rate
    /// (paper Eq. 3): (r1, r2) of a pair; for a longer chain (r1, r2 + … + rN), so that the rate
    /// is δ̇/Σ rᵢ over the whole specimen (docs/physics.md §8).
    pub fn strain_rate_radii_m(&self) -> (f64, f64) {
        let r = &self.chain.spheres;
        (r[0].radius_m, r[1..].iter().map(|s| s.radius_m).sum())
    }
}
