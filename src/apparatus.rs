//! The bar set-up file (`bars/*.toml`): bar material, incident and transmission bars, striker,
//! gas gun, pulse shaper and gauge channels, parsed once into a validated [`Apparatus`].

use crate::bar::{BarMaterial, BarSpec, Dispersion, EndCondition, Segment};
use crate::error::{Error, Result, Validator};
use crate::gauge::GaugeSetup;
use crate::shaper::PulseShaper;
use crate::striker::{GasGun, Gun, LinearGun};
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialToml {
    density_kg_m3: f64,
    youngs_modulus_pa: f64,
    poisson_ratio: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BarToml {
    length_m: f64,
    diameter_m: f64,
    #[serde(default)]
    far_end: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GunToml {
    model: String,
    k_m2_per_s2_per_pa: Option<f64>,
    loss_pressure_pa: Option<f64>,
    reservoir_volume_m3: Option<f64>,
    barrel_length_m: Option<f64>,
    friction_n: Option<f64>,
    gamma: Option<f64>,
    min_pressure_pa: f64,
    max_pressure_pa: f64,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
struct ShaperToml {
    diameter_m: f64,
    thickness_m: f64,
    sigma0_pa: f64,
    n: f64,
    m: f64,
    youngs_modulus_pa: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ApparatusToml {
    gauges: String,
    material: MaterialToml,
    incident: BarToml,
    transmission: BarToml,
    striker: BarToml,
    gun: GunToml,
    shaper: Option<ShaperToml>,
}

/// One bar's geometry: a uniform cylinder of the set-up's material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarGeometry {
    /// Length, m.
    pub length_m: f64,
    /// Diameter, m.
    pub diameter_m: f64,
}

impl BarGeometry {
    /// Cross-section area, m².
    pub fn area_m2(&self) -> f64 {
        std::f64::consts::PI * 0.25 * self.diameter_m * self.diameter_m
    }
}

/// A validated SHPB set-up.
#[derive(Debug, Clone, PartialEq)]
pub struct Apparatus {
    /// The file it came from.
    pub source: String,
    /// Bar material (all bars and the striker).
    pub material: BarMaterial,
    /// Incident bar.
    pub incident: BarGeometry,
    /// Transmission bar.
    pub transmission: BarGeometry,
    /// Whether the transmission bar's far end is absorbing (momentum trap) rather than free.
    pub transmission_absorbing: bool,
    /// Striker.
    pub striker: BarGeometry,
    /// Gas gun.
    pub gun: Gun,
    /// Default pulse shaper (None: no shaper).
    pub shaper: Option<PulseShaper>,
    /// Gauge channels.
    pub gauges: GaugeSetup,
}

fn bar_geometry(b: &BarToml, v: &Validator) -> Result<BarGeometry> {
    Ok(BarGeometry {
        length_m: v.positive("length_m", b.length_m, 100.0, "m")?,
        diameter_m: v.positive("diameter_m", b.diameter_m, 1.0, "m")?,
    })
}

/// Validates a shaper table (shared by set-up files and scenes).
fn shaper_from(s: &ShaperToml, v: &Validator) -> Result<PulseShaper> {
    Ok(PulseShaper {
        diameter_m: v.positive("diameter_m", s.diameter_m, 0.1, "m")?,
        thickness_m: v.positive("thickness_m", s.thickness_m, 0.05, "m")?,
        sigma0_pa: v.positive("sigma0_pa", s.sigma0_pa, 1e11, "Pa")?,
        n: v.in_range("n", s.n, 0.01, 1.0, "")?,
        m: v.in_range("m", s.m, 0.5, 50.0, "")?,
        youngs_modulus_pa: v.positive("youngs_modulus_pa", s.youngs_modulus_pa, 1e13, "Pa")?,
    })
}

impl Apparatus {
    /// Reads and validates a set-up file; its `gauges` file is resolved relative to it.
    pub fn from_file(path: &Path) -> Result<Apparatus> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let file = path.display().to_string();
        let raw: ApparatusToml = toml::from_str(&text).map_err(|e| Error::Parse {
            file: file.clone(),
            message: e.to_string(),
        })?;
        let v = Validator::new(file.clone());
        let mv = v.table("material");
        let material = BarMaterial {
            density_kg_m3: mv.positive(
                "density_kg_m3",
                raw.material.density_kg_m3,
                1e5,
                "kg/m³",
            )?,
            youngs_modulus_pa: mv.positive(
                "youngs_modulus_pa",
                raw.material.youngs_modulus_pa,
                1e13,
                "Pa",
            )?,
            poisson_ratio: mv.in_range(
                "poisson_ratio",
                raw.material.poisson_ratio,
                0.0,
                0.4999,
                "",
            )?,
        };
        let transmission_absorbing = match raw.transmission.far_end.as_deref() {
            None | Some("absorbing") => true,
            Some("free") => false,
            Some(other) => {
                return Err(v.table("transmission").error(
                    "far_end",
                    format!("unknown end `{other}`"),
                    "absorbing, free",
                ));
            }
        };
        if raw.incident.far_end.is_some() || raw.striker.far_end.is_some() {
            return Err(v.error(
                "incident.far_end",
                "only the transmission bar has a far end to choose",
                "far_end in [transmission] only",
            ));
        }
        let gv = v.table("gun");
        let g = &raw.gun;
        let (pmin, pmax) = (
            gv.positive("min_pressure_pa", g.min_pressure_pa, 1e8, "Pa")?,
            gv.positive("max_pressure_pa", g.max_pressure_pa, 1e8, "Pa")?,
        );
        if pmin >= pmax {
            return Err(gv.error(
                "min_pressure_pa",
                "not below max_pressure_pa",
                "min_pressure_pa < max_pressure_pa",
            ));
        }
        let need = |key: &str, x: Option<f64>| {
            x.ok_or_else(|| {
                gv.error(
                    key,
                    format!("missing for model = \"{}\"", g.model),
                    "a positive number",
                )
            })
        };
        let gun = match g.model.as_str() {
            "linear" => Gun::Linear(LinearGun {
                k_m2_per_s2_per_pa: gv.positive(
                    "k_m2_per_s2_per_pa",
                    need("k_m2_per_s2_per_pa", g.k_m2_per_s2_per_pa)?,
                    1.0,
                    "m²/s²/Pa",
                )?,
                loss_pressure_pa: gv.in_range(
                    "loss_pressure_pa",
                    need("loss_pressure_pa", g.loss_pressure_pa)?,
                    0.0,
                    pmin,
                    "Pa (below min_pressure_pa)",
                )?,
                min_pressure_pa: pmin,
                max_pressure_pa: pmax,
            }),
            "adiabatic" => Gun::Adiabatic(GasGun {
                reservoir_volume_m3: gv.positive(
                    "reservoir_volume_m3",
                    need("reservoir_volume_m3", g.reservoir_volume_m3)?,
                    10.0,
                    "m³",
                )?,
                barrel_length_m: gv.positive(
                    "barrel_length_m",
                    need("barrel_length_m", g.barrel_length_m)?,
                    100.0,
                    "m",
                )?,
                friction_n: gv.in_range(
                    "friction_n",
                    g.friction_n.unwrap_or(0.0),
                    0.0,
                    1e6,
                    "N",
                )?,
                gamma: gv.in_range("gamma", g.gamma.unwrap_or(1.4), 1.01, 1.67, "")?,
                atmospheric_pa: crate::striker::ATMOSPHERE_PA,
                min_pressure_pa: pmin,
                max_pressure_pa: pmax,
            }),
            other => {
                return Err(gv.error(
                    "model",
                    format!("unknown gun model `{other}`"),
                    "linear, adiabatic",
                ));
            }
        };
        let shaper = match &raw.shaper {
            Some(s) => Some(shaper_from(s, &v.table("shaper"))?),
            None => None,
        };
        let base = path.parent().unwrap_or(Path::new("."));
        let gauges = GaugeSetup::from_file(base.join(&raw.gauges))?;
        Ok(Apparatus {
            source: file,
            material,
            incident: bar_geometry(&raw.incident, &v.table("incident"))?,
            transmission: bar_geometry(&raw.transmission, &v.table("transmission"))?,
            transmission_absorbing,
            striker: bar_geometry(&raw.striker, &v.table("striker"))?,
            gun,
            shaper,
            gauges,
        })
    }

    /// Striker mass, kg.
    pub fn striker_mass_kg(&self) -> f64 {
        self.material.density_kg_m3 * self.striker.area_m2() * self.striker.length_m
    }

    /// Striker velocity at gauge pressure `p_pa`; `v`/`key` name the input in errors.
    pub fn striker_velocity_m_s(&self, p_pa: f64, v: &Validator, key: &str) -> Result<f64> {
        self.gun
            .striker_velocity_m_s(p_pa, self.striker_mass_kg(), self.striker.area_m2(), v, key)
    }

    /// A uniform bar spec of this set-up's material.
    pub fn bar_spec(
        &self,
        name: &str,
        g: BarGeometry,
        left: EndCondition,
        right: EndCondition,
        dispersion: Dispersion,
    ) -> BarSpec {
        BarSpec {
            name: name.to_string(),
            segments: vec![Segment {
                length_m: g.length_m,
                diameter_m: g.diameter_m,
                material: self.material,
            }],
            left_end: left,
            right_end: right,
            dispersion,
        }
    }
}

/// A scene's shaper override table (same keys as the set-up file's `[shaper]`, all optional).
#[derive(Debug, Clone, Copy, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct ShaperOverride {
    /// Use a shaper at all (default: if the set-up has one).
    pub enabled: Option<bool>,
    /// Diameter, m.
    pub diameter_m: Option<f64>,
    /// Thickness, m.
    pub thickness_m: Option<f64>,
    /// σ0, Pa.
    pub sigma0_pa: Option<f64>,
    /// n.
    pub n: Option<f64>,
    /// m.
    pub m: Option<f64>,
    /// Young's modulus, Pa.
    pub youngs_modulus_pa: Option<f64>,
}

impl ShaperOverride {
    /// Applies the override to the set-up's shaper; errors name the scene keys.
    pub fn apply(&self, base: Option<PulseShaper>, v: &Validator) -> Result<Option<PulseShaper>> {
        if self.enabled == Some(false) {
            return Ok(None);
        }
        let b = match base {
            Some(b) => b,
            None if self.enabled == Some(true)
                || self.diameter_m.is_some()
                || self.thickness_m.is_some() =>
            {
                PulseShaper {
                    diameter_m: f64::NAN,
                    thickness_m: f64::NAN,
                    sigma0_pa: 0.75e9,
                    n: 0.37,
                    m: 4.25,
                    youngs_modulus_pa: 117e9,
                }
            }
            None => return Ok(None),
        };
        let s = ShaperToml {
            diameter_m: self.diameter_m.unwrap_or(b.diameter_m),
            thickness_m: self.thickness_m.unwrap_or(b.thickness_m),
            sigma0_pa: self.sigma0_pa.unwrap_or(b.sigma0_pa),
            n: self.n.unwrap_or(b.n),
            m: self.m.unwrap_or(b.m),
            youngs_modulus_pa: self.youngs_modulus_pa.unwrap_or(b.youngs_modulus_pa),
        };
        shaper_from(&s, v).map(Some)
    }
}

/// What the incident bar's far end (the specimen face) touches in a `pulse` run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IncidentEnd {
    /// The transmission bar is pressed against it (no specimen).
    Transmission,
    /// A free end.
    Free,
    /// A non-reflecting end.
    Absorbing,
    /// The two-sphere specimen, then the transmission bar (a full SHPB test).
    Specimen,
}

/// The specimen of a full test: the sphere pair and its contact law.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecimenSetup {
    /// The spheres (sphere 1 on the incident bar).
    pub pair: crate::specimen::SpherePair,
    /// Contact law.
    pub law: crate::contact::LawKind,
    /// Form of region II of the loading law.
    pub region2: crate::contact::Region2Form,
}

/// Options of a bar run (what a `pulse` or `shpb` scene sets).
#[derive(Debug, Clone, PartialEq)]
pub struct PulseOptions {
    /// The specimen, when `end` is `IncidentEnd::Specimen`.
    pub specimen: Option<SpecimenSetup>,
    /// Striker impact velocity, m/s.
    pub striker_velocity_m_s: f64,
    /// Pulse shaper (None: striker on bar).
    pub shaper: Option<PulseShaper>,
    /// What the incident bar's far end touches.
    pub end: IncidentEnd,
    /// Cell size in the bars, m (Δt = Δx/c0, Courant number 1).
    pub cell_size_m: f64,
    /// Bar dispersion model.
    pub dispersion: Dispersion,
    /// End of the run, s.
    pub end_time_s: f64,
    /// Gauge grid length over which strain is averaged, m.
    pub gauge_length_m: f64,
    /// Interval of the x–t stress snapshots of the bars, s (None: none).
    pub snapshot_interval_s: Option<f64>,
}

impl Apparatus {
    /// The chain striker → (shaper) → incident (→ transmission) at Courant 1 in the bars.
    pub fn pulse_chain(&self, o: &PulseOptions) -> crate::solver::pulse::ChainSetup {
        use crate::solver::pulse::{ChainSetup, GaugeProbe, Joint};
        let c0 = self.material.wave_speed_m_s();
        let dt = o.cell_size_m / c0;
        let (shaper, end, dispersion) = (o.shaper, o.end, o.dispersion);
        let incident_right = match end {
            IncidentEnd::Absorbing => EndCondition::Absorbing,
            _ => EndCondition::Free,
        };
        let with_transmission = matches!(end, IncidentEnd::Transmission | IncidentEnd::Specimen);
        let mut bars = vec![
            self.bar_spec(
                "striker",
                self.striker,
                EndCondition::Free,
                EndCondition::Free,
                dispersion,
            ),
            self.bar_spec(
                "incident",
                self.incident,
                EndCondition::Free,
                incident_right,
                dispersion,
            ),
        ];
        let mut joints = vec![match shaper {
            Some(s) => Joint::Shaper(s),
            None => Joint::Butt,
        }];
        let mut end_masses = Vec::new();
        if with_transmission {
            let far = if self.transmission_absorbing {
                EndCondition::Absorbing
            } else {
                EndCondition::Free
            };
            bars.push(self.bar_spec(
                "transmission",
                self.transmission,
                EndCondition::Free,
                far,
                dispersion,
            ));
            match &o.specimen {
                Some(sp) if end == IncidentEnd::Specimen => {
                    joints.push(Joint::Spheres {
                        props: sp.pair.contact_properties(),
                        law: sp.law,
                        region2: sp.region2,
                    });
                    // Each sphere's mass joins its bar's end node (the paper's DEM).
                    end_masses.push((1, true, sp.pair.sphere1.mass_kg));
                    end_masses.push((2, false, sp.pair.sphere2.mass_kg));
                }
                _ => joints.push(Joint::Butt),
            }
        }
        let mut gauges = Vec::new();
        for ch in &self.gauges.channels {
            let (bar, x) = match ch.bar.as_str() {
                "incident" => (1, self.incident.length_m - ch.distance_from_specimen_m),
                "transmission" if with_transmission => (2, ch.distance_from_specimen_m),
                _ => continue,
            };
            gauges.push(GaugeProbe {
                name: ch.name.clone(),
                bar,
                x_m: x,
                length_m: o.gauge_length_m,
            });
        }
        let record_every = ((1.0 / 10e6) / dt).floor().max(1.0) as usize;
        ChainSetup {
            bars,
            joints,
            striker_velocity_m_s: o.striker_velocity_m_s,
            dt_s: dt,
            end_time_s: o.end_time_s,
            gauges,
            record_every,
            end_masses,
            snapshot_every: o
                .snapshot_interval_s
                .map(|i| ((i / dt).round() as usize).max(1)),
            snapshot_spacing_m: 5e-3,
        }
    }
}
