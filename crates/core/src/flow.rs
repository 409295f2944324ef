//! Flow-stress models of an elastoplastic specimen (docs/physics.md §6.12): J2 plasticity in
//! uniaxial stress reduces to |σ| ≤ σ_f(ε̄p, ε̇p, T). Johnson–Cook (G. R. Johnson, W. H. Cook,
//! Proc. 7th Int. Symp. Ballistics, The Hague (1983) 541–547), a tabulated true-stress curve, or
//! none (an elastic specimen); and the barrelling factor end friction puts on it. SI units; every
//! constructor validates its numbers.

use crate::error::{Named, Result};

/// Thermal softening of Johnson–Cook, (1 − T*ᵐ) with T* = (T − T_room)/(T_melt − T_room) clamped to
/// [0, 1], and the adiabatic heating ΔT = β σ Δε̄p/(ρ c_p) that drives it (§6.12).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalSoftening {
    /// Exponent m of T*ᵐ.
    pub m: f64,
    /// Room (reference) temperature T_room, K.
    pub room_temperature_k: f64,
    /// Melting temperature T_melt, K.
    pub melt_temperature_k: f64,
    /// Specific heat c_p, J/(kg·K).
    pub specific_heat_j_kg_k: f64,
    /// Taylor–Quinney factor β: the fraction of the plastic work that heats (0 to 1).
    pub taylor_quinney: f64,
}

impl ThermalSoftening {
    /// Checks every number (Error::Invalid naming `thermal.<key>` of `object`).
    pub fn validate(&self, object: &str) -> Result<()> {
        let v = Named::new(object).table("thermal");
        v.positive("m", self.m, 100.0, "")?;
        v.positive("room_temperature_k", self.room_temperature_k, 1e4, "K")?;
        v.positive("melt_temperature_k", self.melt_temperature_k, 1e4, "K")?;
        if self.melt_temperature_k <= self.room_temperature_k {
            return Err(v.error(
                "melt_temperature_k",
                format!(
                    "{} K is not above the room temperature {} K",
                    self.melt_temperature_k, self.room_temperature_k
                ),
                "above room_temperature_k",
            ));
        }
        v.positive(
            "specific_heat_j_kg_k",
            self.specific_heat_j_kg_k,
            1e5,
            "J/(kg·K)",
        )?;
        v.in_range("taylor_quinney", self.taylor_quinney, 0.0, 1.0, "")?;
        Ok(())
    }

    /// The softening factor 1 − T*ᵐ at temperature `temperature_k` (Johnson & Cook 1983, Eq. 1).
    pub fn factor(&self, temperature_k: f64) -> f64 {
        let t_star = ((temperature_k - self.room_temperature_k)
            / (self.melt_temperature_k - self.room_temperature_k))
            .clamp(0.0, 1.0);
        1.0 - t_star.powf(self.m)
    }
}

/// Johnson–Cook flow stress σ_f = (A + B ε̄pⁿ)(1 + C ln max(ε̇p/ε̇0, 1))(1 − T*ᵐ) (Johnson & Cook
/// 1983, Eq. 1; the rate term held at 1 below ε̇0, as codes commonly do).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JohnsonCook {
    /// Yield stress A, Pa.
    pub a_pa: f64,
    /// Hardening modulus B, Pa.
    pub b_pa: f64,
    /// Hardening exponent n.
    pub n: f64,
    /// Rate sensitivity C.
    pub c: f64,
    /// Reference plastic strain rate ε̇0, 1/s.
    pub reference_rate_per_s: f64,
    /// Thermal softening with adiabatic heating (None: isothermal, no softening).
    pub thermal: Option<ThermalSoftening>,
}

impl JohnsonCook {
    /// A validated Johnson–Cook law (Error::Invalid naming the constant of `object`).
    pub fn new(object: &str, law: JohnsonCook) -> Result<JohnsonCook> {
        law.validate(object)?;
        Ok(law)
    }

    /// Checks the constants: A > 0 (up to 1e16 Pa: a law that never yields is allowed), B ≥ 0,
    /// 0 ≤ n ≤ 10 (n > 0 when B > 0), 0 ≤ C ≤ 10, ε̇0 > 0, and the thermal part.
    pub fn validate(&self, object: &str) -> Result<()> {
        let v = Named::new(object);
        v.positive("a_pa", self.a_pa, 1e16, "Pa")?;
        v.in_range("b_pa", self.b_pa, 0.0, 1e16, "Pa")?;
        v.in_range("n", self.n, 0.0, 10.0, "")?;
        if self.b_pa > 0.0 && self.n == 0.0 {
            return Err(v.error(
                "n",
                "0 with B > 0 (B ε̄p⁰ is a second yield stress)",
                "greater than 0 when b_pa > 0",
            ));
        }
        v.in_range("c", self.c, 0.0, 10.0, "")?;
        v.positive(
            "reference_rate_per_s",
            self.reference_rate_per_s,
            1e9,
            "1/s",
        )?;
        if let Some(t) = &self.thermal {
            t.validate(object)?;
        }
        Ok(())
    }

    /// The law without its thermal term: the isothermal Johnson–Cook law the pulse shaper's
    /// crushed disc flows by ([`crate::shaper::JohnsonCook`]).
    pub fn isothermal(&self) -> crate::shaper::JohnsonCook {
        crate::shaper::JohnsonCook {
            a_pa: self.a_pa,
            b_pa: self.b_pa,
            n: self.n,
            c: self.c,
            reference_rate_per_s: self.reference_rate_per_s,
        }
    }

    /// σ_f(ε̄p, ε̇p, T), Pa (Johnson & Cook 1983, Eq. 1): the isothermal law times the thermal
    /// factor.
    pub fn flow_stress_pa(
        &self,
        plastic_strain: f64,
        plastic_rate_per_s: f64,
        temperature_k: f64,
    ) -> f64 {
        let thermal = self.thermal.map_or(1.0, |t| t.factor(temperature_k));
        self.isothermal()
            .flow_stress_pa(plastic_strain, plastic_rate_per_s)
            * thermal
    }
}

/// A tabulated flow curve: true stress against equivalent plastic strain, piecewise linear,
/// constant beyond the last point; the first point, at ε̄p = 0, is the yield stress.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowTable {
    plastic_strain: Vec<f64>,
    stress_pa: Vec<f64>,
}

impl FlowTable {
    /// A validated table: at least one point, strains strictly increasing from 0, stresses finite
    /// and positive (Error::Invalid naming `plastic_strain` or `stress_pa` of `object`).
    pub fn new(object: &str, plastic_strain: Vec<f64>, stress_pa: Vec<f64>) -> Result<FlowTable> {
        let v = Named::new(object);
        if plastic_strain.is_empty() || plastic_strain.len() != stress_pa.len() {
            return Err(v.error(
                "plastic_strain",
                format!(
                    "{} strains for {} stresses",
                    plastic_strain.len(),
                    stress_pa.len()
                ),
                "as many strains as stresses, at least one",
            ));
        }
        if plastic_strain[0] != 0.0 {
            return Err(v.error(
                "plastic_strain",
                format!("the first strain is {}", plastic_strain[0]),
                "0 (the first point is the yield stress)",
            ));
        }
        for (k, w) in plastic_strain.windows(2).enumerate() {
            if !(w[1] > w[0] && w[1].is_finite()) {
                return Err(v.error(
                    "plastic_strain",
                    format!(
                        "point {} ({}) does not exceed point {k} ({})",
                        k + 1,
                        w[1],
                        w[0]
                    ),
                    "strictly increasing finite strains",
                ));
            }
        }
        for &s in &stress_pa {
            v.positive("stress_pa", s, 1e16, "Pa")?;
        }
        Ok(FlowTable {
            plastic_strain,
            stress_pa,
        })
    }

    /// The equivalent plastic strains of the points.
    pub fn plastic_strain(&self) -> &[f64] {
        &self.plastic_strain
    }

    /// The true stresses of the points, Pa.
    pub fn stress_pa(&self) -> &[f64] {
        &self.stress_pa
    }

    /// σ_f(ε̄p) by linear interpolation, the last stress beyond the last point, Pa.
    pub fn flow_stress_pa(&self, plastic_strain: f64) -> f64 {
        let (x, y) = (&self.plastic_strain, &self.stress_pa);
        let k = x.partition_point(|&e| e <= plastic_strain);
        if k == 0 {
            return y[0];
        }
        if k == x.len() {
            return y[k - 1];
        }
        let w = (plastic_strain - x[k - 1]) / (x[k] - x[k - 1]);
        y[k - 1] + w * (y[k] - y[k - 1])
    }
}

/// How a specimen's material flows (docs/physics.md §6.12).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum FlowModel {
    /// No yield: today's elastic specimen (σ_f = +∞).
    #[default]
    Elastic,
    /// Johnson–Cook (1983), optionally with thermal softening and adiabatic heating.
    JohnsonCook(JohnsonCook),
    /// A tabulated true-stress curve against equivalent plastic strain.
    Tabulated(FlowTable),
}

impl FlowModel {
    /// Checks the model's numbers (Error::Invalid naming the key of `object`).
    pub fn validate(&self, object: &str) -> Result<()> {
        match self {
            FlowModel::JohnsonCook(jc) => jc.validate(object),
            FlowModel::Tabulated(t) => {
                FlowTable::new(object, t.plastic_strain.clone(), t.stress_pa.clone()).map(|_| ())
            }
            FlowModel::Elastic => Ok(()),
        }
    }

    /// σ_f(ε̄p, ε̇p, T), Pa: +∞ for an elastic specimen, the table's value at ε̄p (rate and
    /// temperature do not enter), Johnson–Cook's (§6.12).
    pub fn flow_stress_pa(
        &self,
        plastic_strain: f64,
        plastic_rate_per_s: f64,
        temperature_k: f64,
    ) -> f64 {
        match self {
            FlowModel::Elastic => f64::INFINITY,
            FlowModel::JohnsonCook(jc) => {
                jc.flow_stress_pa(plastic_strain, plastic_rate_per_s, temperature_k)
            }
            FlowModel::Tabulated(t) => t.flow_stress_pa(plastic_strain),
        }
    }

    /// The thermal softening and heating, if the model has them.
    pub fn thermal(&self) -> Option<&ThermalSoftening> {
        match self {
            FlowModel::JohnsonCook(jc) => jc.thermal.as_ref(),
            _ => None,
        }
    }
}

/// How end friction raises the mean axial pressure needed to make a cylinder flow (§6.12).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrictionModel {
    /// Avitzur's upper bound for a cylinder flowing without bulging, with the constant friction
    /// factor m = min(√3 μ, 1): p̄/σ_f = 1 + m d/(3√3 h) (B. Avitzur, *Metal Forming: Processes
    /// and Analysis*, McGraw-Hill (1968), forging of a solid disc; = Siebel's 1 + μd/(3h) below
    /// sticking).
    Avitzur,
    /// The slab (Schroeder–Webster) solution with Coulomb sliding over the whole face:
    /// p̄/σ_f = 2(eᵇ − b − 1)/b², b = μ d/h (W. Schroeder, D. A. Webster, *J. Appl. Mech.* 16,
    /// 289 (1949)); its small-μ limit is Siebel's 1 + μd/(3h).
    Slab,
}

/// Coulomb friction at both faces of the specimen (§6.12).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Friction {
    /// Coulomb coefficient μ (0 to 10).
    pub coefficient: f64,
    /// The barrelling factor applied to the flow stress.
    pub model: FrictionModel,
}

impl Friction {
    /// The factor p̄/σ_f ≥ 1 of [`FrictionModel`] for a cylinder of diameter `diameter_m` and
    /// height `height_m` (§6.12).
    pub fn factor(&self, diameter_m: f64, height_m: f64) -> f64 {
        let aspect = diameter_m / height_m;
        match self.model {
            FrictionModel::Avitzur => {
                let m = (3f64.sqrt() * self.coefficient).min(1.0);
                1.0 + m * aspect / (3.0 * 3f64.sqrt())
            }
            FrictionModel::Slab => {
                let b = self.coefficient * aspect;
                if b < 1e-3 {
                    1.0 + b / 3.0 + b * b / 12.0 + b * b * b / 60.0
                } else {
                    2.0 * (b.exp_m1() - b) / (b * b)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    fn copper() -> JohnsonCook {
        JohnsonCook {
            a_pa: 90e6,
            b_pa: 292e6,
            n: 0.31,
            c: 0.025,
            reference_rate_per_s: 1.0,
            thermal: Some(ThermalSoftening {
                m: 1.09,
                room_temperature_k: 298.0,
                melt_temperature_k: 1356.0,
                specific_heat_j_kg_k: 383.0,
                taylor_quinney: 0.9,
            }),
        }
    }

    #[test]
    fn johnson_cook_is_its_three_factors() {
        let jc = copper();
        // At ε̄p = 0, the reference rate and room temperature: A.
        assert_eq!(jc.flow_stress_pa(0.0, 1.0, 298.0), 90e6);
        // Below the reference rate the rate factor is 1; below room temperature T* = 0.
        assert_eq!(jc.flow_stress_pa(0.0, 1e-3, 200.0), 90e6);
        let s = jc.flow_stress_pa(0.2, 1e3, 500.0);
        let t_star: f64 = (500.0 - 298.0) / (1356.0 - 298.0);
        let expected = (90e6 + 292e6 * 0.2f64.powf(0.31))
            * (1.0 + 0.025 * 1e3f64.ln())
            * (1.0 - t_star.powf(1.09));
        assert!((s - expected).abs() <= 1e-12 * expected);
        // Melted: no strength.
        assert_eq!(jc.flow_stress_pa(0.2, 1e3, 2000.0), 0.0);
    }

    #[test]
    fn a_table_interpolates_and_holds_its_last_stress() {
        let t = FlowTable::new("t", vec![0.0, 0.1, 0.3], vec![100e6, 200e6, 260e6]).unwrap();
        assert_eq!(t.flow_stress_pa(0.0), 100e6);
        assert!((t.flow_stress_pa(0.05) - 150e6).abs() < 1e-6);
        assert!((t.flow_stress_pa(0.2) - 230e6).abs() < 1e-6);
        assert_eq!(t.flow_stress_pa(0.3), 260e6);
        assert_eq!(t.flow_stress_pa(5.0), 260e6);
        assert!(FlowTable::new("t", vec![0.1], vec![1e6]).is_err());
        assert!(FlowTable::new("t", vec![0.0, 0.1, 0.1], vec![1e6; 3]).is_err());
        assert!(FlowTable::new("t", vec![0.0, 0.1], vec![1e6, -1.0]).is_err());
    }

    #[test]
    fn bad_constants_are_refused_by_name() {
        let mut jc = copper();
        jc.c = -0.1;
        match JohnsonCook::new("specimen", jc).unwrap_err() {
            Error::Invalid { quantity, .. } => assert_eq!(quantity, "c"),
            e => panic!("{e}"),
        }
        let mut jc = copper();
        jc.thermal.as_mut().unwrap().melt_temperature_k = 250.0;
        match JohnsonCook::new("specimen", jc).unwrap_err() {
            Error::Invalid { quantity, .. } => {
                assert_eq!(quantity, "thermal.melt_temperature_k")
            }
            e => panic!("{e}"),
        }
        assert_eq!(
            FlowModel::Elastic.flow_stress_pa(1.0, 1.0, 1.0),
            f64::INFINITY
        );
    }
}
