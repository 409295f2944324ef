//! Bar set-up files (`bars/*.toml`: bar material, incident and transmission bars, striker, gas
//! gun, pulse shaper and the gauge file) and the built-in set-ups, validated into the core's
//! [`Apparatus`]; a scene's `[shaper]` override.

use crate::error::{Error, Result, Validator};
use crate::gauges::GaugeSetupFile;
use serde::Deserialize;
use shpb_core::apparatus::{Apparatus, BarGeometry, Insert, Inserts};
use shpb_core::bar::BarMaterial;
use shpb_core::gauge::GaugeSetup;
use shpb_core::shaper::{CrushedDisc, ExponentialSpring, JohnsonCook, PulseShaper, ShaperModel};
use shpb_core::striker::PSI_PA;
use shpb_core::striker::{GasGun, Gun, LinearGun};
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
    calibration_striker_length_m: Option<f64>,
    reservoir_volume_m3: Option<f64>,
    barrel_length_m: Option<f64>,
    friction_n: Option<f64>,
    gamma: Option<f64>,
    min_pressure_pa: f64,
    max_pressure_pa: f64,
    calibrated_min_pressure_pa: Option<f64>,
    calibrated_max_pressure_pa: Option<f64>,
    velocity_scatter: Option<f64>,
}

#[derive(Deserialize, Clone)]
#[serde(deny_unknown_fields)]
struct ShaperToml {
    /// "frew" (default), "crushed-disc" or "exponential".
    model: Option<String>,
    diameter_m: Option<f64>,
    thickness_m: Option<f64>,
    sigma0_pa: Option<f64>,
    n: Option<f64>,
    m: Option<f64>,
    youngs_modulus_pa: Option<f64>,
    stiffening_length_m: Option<f64>,
    onset_force_n: Option<f64>,
    friction: Option<f64>,
    face_compliance_factor: Option<f64>,
    jc_a_pa: Option<f64>,
    jc_b_pa: Option<f64>,
    jc_n: Option<f64>,
    jc_c: Option<f64>,
    jc_reference_rate_per_s: Option<f64>,
    calibrated_pressure_psi: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InsertToml {
    length_m: f64,
    diameter_m: Option<f64>,
    material: Option<MaterialToml>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct InsertsToml {
    incident: Option<InsertToml>,
    transmission: Option<InsertToml>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ApparatusToml {
    #[serde(default)]
    inserts: InsertsToml,
    /// A gauge file, or …
    gauges: Option<String>,
    /// … the channels inline (`[[channel]]` tables, as in a gauge file): exactly one of the two.
    channel: Option<Vec<crate::gauges::ChannelSpec>>,
    #[serde(default)]
    #[allow(dead_code)]
    description: Option<String>,
    material: MaterialToml,
    incident: BarToml,
    transmission: BarToml,
    striker: BarToml,
    /// The gas gun; without it, scenes give the striker's velocity (`striker_velocity_m_s`).
    gun: Option<GunToml>,
    shaper: Option<ShaperToml>,
    /// Read by [`crate::uncertainty::read`] once the rest is validated.
    uncertainty: Option<toml::Value>,
}

/// Validates a bar material given as a TOML value (a cylindrical specimen's `material` table),
/// with the keys and ranges of a set-up's `[material]`; `v` is the table holding `material`.
pub(crate) fn bar_material_value(value: &toml::Value, v: &Validator) -> Result<BarMaterial> {
    let m: MaterialToml = value.clone().try_into().map_err(|e: toml::de::Error| {
        v.error(
            "material",
            e.message().trim().to_string(),
            "a table of density_kg_m3, youngs_modulus_pa and poisson_ratio",
        )
    })?;
    bar_material(&m, &v.table("material"))
}

/// Validates a bar material table (`[material]`, an insert's `material`).
fn bar_material(m: &MaterialToml, mv: &Validator) -> Result<BarMaterial> {
    Ok(BarMaterial {
        density_kg_m3: mv.positive("density_kg_m3", m.density_kg_m3, 1e5, "kg/m³")?,
        youngs_modulus_pa: mv.positive("youngs_modulus_pa", m.youngs_modulus_pa, 1e13, "Pa")?,
        poisson_ratio: mv.in_range("poisson_ratio", m.poisson_ratio, 0.0, 0.4999, "")?,
    })
}

fn bar_geometry(b: &BarToml, v: &Validator) -> Result<BarGeometry> {
    Ok(BarGeometry {
        length_m: v.positive("length_m", b.length_m, 100.0, "m")?,
        diameter_m: v.positive("diameter_m", b.diameter_m, 1.0, "m")?,
    })
}

/// Validates a shaper table (shared by set-up files and scenes); `face_modulus_pa` is the
/// plane-strain modulus E/(1 − ν²) of the bars the disc sits between.
fn shaper_from(s: &ShaperToml, face_modulus_pa: f64, v: &Validator) -> Result<PulseShaper> {
    let model_name = s.model.as_deref().unwrap_or("frew");
    let frew = model_name == "frew";
    let need = |key: &str, x: Option<f64>| {
        x.ok_or_else(|| {
            v.error(
                key,
                format!("missing for model = \"{model_name}\""),
                "a positive number",
            )
        })
    };
    // The exponential law's two constants (also a crushed disc's cushion).
    let spring = || -> Result<ExponentialSpring> {
        Ok(ExponentialSpring {
            stiffening_length_m: v.positive(
                "stiffening_length_m",
                need("stiffening_length_m", s.stiffening_length_m)?,
                0.01,
                "m",
            )?,
            onset_force_n: v.positive(
                "onset_force_n",
                need("onset_force_n", s.onset_force_n)?,
                1e6,
                "N",
            )?,
        })
    };
    let model = match model_name {
        "frew" => ShaperModel::Frew,
        "crushed-disc" => {
            let jc = JohnsonCook::OFHC_COPPER;
            ShaperModel::CrushedDisc(CrushedDisc {
                flow: JohnsonCook {
                    a_pa: v.in_range("jc_a_pa", s.jc_a_pa.unwrap_or(jc.a_pa), 0.0, 1e10, "Pa")?,
                    b_pa: v.in_range("jc_b_pa", s.jc_b_pa.unwrap_or(jc.b_pa), 0.0, 1e10, "Pa")?,
                    n: v.in_range("jc_n", s.jc_n.unwrap_or(jc.n), 0.01, 1.0, "")?,
                    c: v.in_range("jc_c", s.jc_c.unwrap_or(jc.c), 0.0, 1.0, "")?,
                    reference_rate_per_s: v.positive(
                        "jc_reference_rate_per_s",
                        s.jc_reference_rate_per_s.unwrap_or(jc.reference_rate_per_s),
                        1e9,
                        "1/s",
                    )?,
                },
                friction: v.in_range("friction", s.friction.unwrap_or(0.0), 0.0, 1.0, "")?,
                face_modulus_pa,
                cushion: if s.stiffening_length_m.is_some() || s.onset_force_n.is_some() {
                    Some(spring()?)
                } else {
                    None
                },
                face_compliance_factor: v.in_range(
                    "face_compliance_factor",
                    s.face_compliance_factor.unwrap_or(1.0),
                    0.0,
                    1e3,
                    "",
                )?,
            })
        }
        "exponential" => ShaperModel::Exponential(spring()?),
        other => {
            return Err(v.error(
                "model",
                format!("unknown shaper model `{other}`"),
                "frew, crushed-disc, exponential",
            ));
        }
    };
    let calibrated_pressure_pa = match s.calibrated_pressure_psi {
        None => None,
        Some([lo, hi]) => {
            let lo = v.positive("calibrated_pressure_psi", lo, 1e4, "psi")?;
            let hi = v.in_range("calibrated_pressure_psi", hi, lo, 1e4, "psi")?;
            Some((lo * PSI_PA, hi * PSI_PA))
        }
    };
    if let ShaperModel::Exponential(spring) = model {
        // The law has no disc: its geometry and moduli would be silently unused.
        for (key, x) in [
            ("diameter_m", s.diameter_m),
            ("thickness_m", s.thickness_m),
            ("youngs_modulus_pa", s.youngs_modulus_pa),
            ("sigma0_pa", s.sigma0_pa),
            ("n", s.n),
            ("m", s.m),
            ("friction", s.friction),
            ("face_compliance_factor", s.face_compliance_factor),
        ] {
            if x.is_some() {
                return Err(v.error(
                    key,
                    "not a constant of model = \"exponential\"",
                    "stiffening_length_m, onset_force_n",
                ));
            }
        }
        let mut shaper = PulseShaper::exponential(spring);
        shaper.calibrated_pressure_pa = calibrated_pressure_pa;
        return Ok(shaper);
    }
    for (key, given) in [
        ("stiffening_length_m", s.stiffening_length_m),
        ("onset_force_n", s.onset_force_n),
    ] {
        // The crushed disc takes them as its cushion.
        if given.is_some() && model_name != "crushed-disc" {
            return Err(v.error(
                key,
                format!("not a constant of model = \"{model_name}\""),
                "model = \"exponential\" or \"crushed-disc\"",
            ));
        }
    }
    Ok(PulseShaper {
        diameter_m: v.positive("diameter_m", need("diameter_m", s.diameter_m)?, 0.1, "m")?,
        thickness_m: v.positive(
            "thickness_m",
            need("thickness_m", s.thickness_m)?,
            0.05,
            "m",
        )?,
        sigma0_pa: if frew {
            v.positive("sigma0_pa", need("sigma0_pa", s.sigma0_pa)?, 1e11, "Pa")?
        } else {
            s.sigma0_pa.unwrap_or(f64::NAN)
        },
        n: if frew {
            v.in_range("n", need("n", s.n)?, 0.01, 1.0, "")?
        } else {
            s.n.unwrap_or(f64::NAN)
        },
        m: if frew {
            v.in_range("m", need("m", s.m)?, 0.5, 50.0, "")?
        } else {
            s.m.unwrap_or(f64::NAN)
        },
        youngs_modulus_pa: v.positive(
            "youngs_modulus_pa",
            need("youngs_modulus_pa", s.youngs_modulus_pa)?,
            1e13,
            "Pa",
        )?,
        model,
        calibrated_pressure_pa,
    })
}

/// Reading and validating bar set-up files.
pub trait ApparatusFile: Sized {
    /// Reads and validates a set-up file; its `gauges` file is resolved relative to it.
    fn from_file(path: &Path) -> Result<Self>;
    /// Validates set-up TOML text named `file`; `gauges` reads the gauge file it names.
    fn from_toml(
        text: &str,
        file: &str,
        gauges: &dyn Fn(&str) -> Result<GaugeSetup>,
    ) -> Result<Self>;
    /// A built-in set-up by name (`authors`, `authors-20cm-striker`), or a set-up file path.
    fn resolve(reference: &str, base_dir: &Path) -> Result<Self>;
}

impl ApparatusFile for Apparatus {
    /// Reads and validates a set-up file; its `gauges` file is resolved relative to it.
    fn from_file(path: &Path) -> Result<Apparatus> {
        let text = crate::files::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let file = path.display().to_string();
        let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        Apparatus::from_toml(&text, &file, &|g: &str| GaugeSetup::from_file(base.join(g)))
    }

    fn resolve(reference: &str, base_dir: &Path) -> Result<Apparatus> {
        match crate::builtin::setup(reference) {
            Some(text) => Apparatus::from_toml(
                text,
                &format!("built-in set-up `{reference}`"),
                &|g: &str| match crate::builtin::gauges(g) {
                    Some(t) => GaugeSetup::from_toml(t, &format!("built-in gauges `{g}`")),
                    None => Err(Error::Input {
                        file: format!("built-in set-up `{reference}`"),
                        key: "gauges".into(),
                        problem: format!("no built-in gauge file `{g}`"),
                        allowed: crate::builtin::GAUGES
                            .iter()
                            .map(|(n, _)| *n)
                            .collect::<Vec<_>>()
                            .join(", "),
                    }),
                },
            ),
            None => Apparatus::from_file(&base_dir.join(reference)),
        }
    }

    fn from_toml(
        text: &str,
        file: &str,
        gauges: &dyn Fn(&str) -> Result<GaugeSetup>,
    ) -> Result<Apparatus> {
        let file = file.to_string();
        let raw: ApparatusToml = toml::from_str(text).map_err(|e| Error::Parse {
            file: file.clone(),
            message: e.to_string(),
        })?;
        let v = Validator::new(file.clone());
        let material = bar_material(&raw.material, &v.table("material"))?;
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
        let striker = bar_geometry(&raw.striker, &v.table("striker"))?;
        let (gun, gun_calibrated_pa, gun_velocity_scatter) = match &raw.gun {
            None => (Gun::None, None, None),
            Some(g) => {
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
                let gun_calibrated_pa = match (
                    g.calibrated_min_pressure_pa,
                    g.calibrated_max_pressure_pa,
                ) {
                    (None, None) => None,
                    (Some(lo), Some(hi)) => {
                        let lo = gv.in_range("calibrated_min_pressure_pa", lo, pmin, pmax, "Pa")?;
                        let hi = gv.in_range("calibrated_max_pressure_pa", hi, lo, pmax, "Pa")?;
                        Some((lo, hi))
                    }
                    (lo, _) => {
                        let key = if lo.is_none() {
                            "calibrated_min_pressure_pa"
                        } else {
                            "calibrated_max_pressure_pa"
                        };
                        return Err(gv.error(
                        key,
                        "missing",
                        "both calibrated_min_pressure_pa and calibrated_max_pressure_pa, or neither",
                    ));
                    }
                };
                let gun_velocity_scatter = g
                    .velocity_scatter
                    .map(|s| gv.in_range("velocity_scatter", s, 0.0, 0.5, "1"))
                    .transpose()?;
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
                        // The striker the line was measured with (same material and bore as [striker]);
                        // without the key, the set-up's own striker (docs/physics.md §6.4).
                        calibration_mass_kg: material.density_kg_m3
                            * striker.area_m2()
                            * match g.calibration_striker_length_m {
                                Some(l) => {
                                    gv.positive("calibration_striker_length_m", l, 100.0, "m")?
                                }
                                None => striker.length_m,
                            },
                        min_pressure_pa: pmin,
                        max_pressure_pa: pmax,
                    }),
                    "adiabatic" if g.calibration_striker_length_m.is_some() => {
                        return Err(gv.error(
                        "calibration_striker_length_m",
                        "only a calibration line (model = \"linear\") has a calibration striker",
                        "no calibration_striker_length_m with model = \"adiabatic\"",
                    ));
                    }
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
                        atmospheric_pa: shpb_core::striker::ATMOSPHERE_PA,
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
                (gun, gun_calibrated_pa, gun_velocity_scatter)
            }
        };
        let shaper = match &raw.shaper {
            Some(s) => Some(shaper_from(
                s,
                material.youngs_modulus_pa / (1.0 - material.poisson_ratio.powi(2)),
                &v.table("shaper"),
            )?),
            None => None,
        };
        let gauge_setup = match (&raw.gauges, &raw.channel) {
            (Some(g), None) => gauges(g)?,
            (None, Some(channels)) => crate::gauges::gauge_setup(channels, &v)?,
            (Some(_), Some(_)) => {
                return Err(v.error(
                    "gauges",
                    "given with [[channel]] tables",
                    "either gauges = \"FILE\" or the [[channel]] tables inline, not both",
                ));
            }
            (None, None) => {
                return Err(v.error(
                    "gauges",
                    "missing",
                    "gauges = \"FILE\" (a gauge file) or [[channel]] tables inline",
                ));
            }
        };
        let incident = bar_geometry(&raw.incident, &v.table("incident"))?;
        let insert = |side: &str, t: &Option<InsertToml>| -> Result<Option<Insert>> {
            let Some(t) = t else { return Ok(None) };
            let iv = v.table(&format!("inserts.{side}"));
            Ok(Some(Insert {
                length_m: iv.positive("length_m", t.length_m, 1.0, "m")?,
                diameter_m: match t.diameter_m {
                    Some(d) => iv.positive("diameter_m", d, 1.0, "m")?,
                    None => incident.diameter_m,
                },
                material: match &t.material {
                    Some(m) => bar_material(m, &iv.table("material"))?,
                    None => material,
                },
            }))
        };
        let inserts = Inserts {
            incident: insert("incident", &raw.inserts.incident)?,
            transmission: insert("transmission", &raw.inserts.transmission)?,
        };
        let mut apparatus = Apparatus {
            inserts,
            source: file,
            material,
            incident,
            transmission: bar_geometry(&raw.transmission, &v.table("transmission"))?,
            transmission_absorbing,
            striker,
            gun,
            gun_calibrated_pa,
            gun_velocity_scatter,
            shaper,
            gauges: gauge_setup,
            uncertainty: None,
        };
        check_gauges_on_bars(&apparatus, raw.gauges.as_deref(), &v)?;
        if let Some(u) = &raw.uncertainty {
            let read = crate::uncertainty::read(u, text, &apparatus.source, &apparatus, &|t| {
                Apparatus::from_toml(t, &apparatus.source, gauges)
            })?;
            apparatus.uncertainty = Some(read);
        }
        Ok(apparatus)
    }
}

/// Refuses a gauge placed beyond its bar's far end (`distance_from_specimen_m` longer than the
/// bar): it would record nothing of the test, or the far end's reflections, and its delays
/// would place every window wrong. `gauges` is the set-up's gauge file (None: inline channels).
fn check_gauges_on_bars(a: &Apparatus, gauges: Option<&str>, v: &Validator) -> Result<()> {
    for (i, ch) in a.gauges.channels.iter().enumerate() {
        let length_m = match ch.bar.as_str() {
            "incident" => a.incident.length_m,
            "transmission" => a.transmission.length_m,
            _ => continue,
        };
        if ch.distance_from_specimen_m > length_m {
            let key = format!("channel[{i}].distance_from_specimen_m");
            return Err(v.error(
                &match gauges {
                    Some(g) => format!("gauges` ({g}): `{key}"),
                    None => key,
                },
                format!(
                    "the `{}` gauge sits {} from the specimen, beyond the end of the {} bar, \
                     which is {} long",
                    ch.name,
                    shpb_core::error::format_si(ch.distance_from_specimen_m, "m"),
                    ch.bar,
                    shpb_core::error::format_si(length_m, "m")
                ),
                format!(
                    "a gauge on its bar: 0 to {} from the specimen face",
                    shpb_core::error::format_si(length_m, "m")
                ),
            ));
        }
    }
    Ok(())
}

/// A scene's shaper override table (same keys as the set-up file's `[shaper]`, all optional).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct ShaperOverride {
    /// Use a shaper at all (default: if the set-up has one).
    pub enabled: Option<bool>,
    /// Force law: "frew", "crushed-disc" or "exponential".
    pub model: Option<String>,
    /// Diameter, m.
    pub diameter_m: Option<f64>,
    /// Thickness, m.
    pub thickness_m: Option<f64>,
    /// σ0, Pa (frew).
    pub sigma0_pa: Option<f64>,
    /// n (frew).
    pub n: Option<f64>,
    /// m (frew).
    pub m: Option<f64>,
    /// Young's modulus, Pa.
    pub youngs_modulus_pa: Option<f64>,
    /// Coulomb friction coefficient (crushed-disc).
    pub friction: Option<f64>,
    /// Multiplier of the Boussinesq face compliance (crushed-disc).
    pub face_compliance_factor: Option<f64>,
    /// Stiffening length λ, m (exponential; crushed-disc: its cushion).
    pub stiffening_length_m: Option<f64>,
    /// Onset force F0, N (exponential; crushed-disc: its cushion).
    pub onset_force_n: Option<f64>,
}

impl ShaperOverride {
    /// Whether the override changes any constant of the set-up's shaper.
    fn changes_constants(&self) -> bool {
        self.model.is_some()
            || self.diameter_m.is_some()
            || self.thickness_m.is_some()
            || self.sigma0_pa.is_some()
            || self.n.is_some()
            || self.m.is_some()
            || self.youngs_modulus_pa.is_some()
            || self.friction.is_some()
            || self.face_compliance_factor.is_some()
            || self.stiffening_length_m.is_some()
            || self.onset_force_n.is_some()
    }

    /// Applies the override to the set-up's shaper (bars of plane-strain modulus
    /// `face_modulus_pa`); errors name the scene keys. A shaper whose constants are overridden
    /// carries no calibrated pressure range.
    pub fn apply(
        &self,
        base: Option<PulseShaper>,
        face_modulus_pa: f64,
        v: &Validator,
    ) -> Result<Option<PulseShaper>> {
        if self.enabled == Some(false) {
            return Ok(None);
        }
        let b = match base {
            Some(b) => b,
            None if self.enabled == Some(true)
                || self.diameter_m.is_some()
                || self.thickness_m.is_some()
                || self.stiffening_length_m.is_some() =>
            {
                PulseShaper {
                    diameter_m: f64::NAN,
                    thickness_m: f64::NAN,
                    sigma0_pa: 0.75e9,
                    n: 0.37,
                    m: 4.25,
                    youngs_modulus_pa: 117e9,
                    model: ShaperModel::Frew,
                    calibrated_pressure_pa: None,
                }
            }
            None => return Ok(None),
        };
        if !self.changes_constants() {
            return Ok(Some(b));
        }
        let (base_model, disc, spring) = match b.model {
            ShaperModel::Frew => ("frew", None, None),
            ShaperModel::CrushedDisc(d) => ("crushed-disc", Some(d), None),
            ShaperModel::Exponential(e) => ("exponential", None, Some(e)),
        };
        let model = self.model.clone().unwrap_or_else(|| base_model.to_string());
        let disc_keys = model != "exponential";
        // The base's constants carry over only to a model that has them.
        let opt = |x: f64| (disc_keys && x.is_finite()).then_some(x);
        let (disc, spring) = match model.as_str() {
            "exponential" => (None, spring),
            // A crushed disc's cushion carries over to a crushed disc.
            "crushed-disc" => (disc, disc.and_then(|d| d.cushion)),
            _ => (disc, None),
        };
        let s = ShaperToml {
            diameter_m: self.diameter_m.or(opt(b.diameter_m)),
            thickness_m: self.thickness_m.or(opt(b.thickness_m)),
            sigma0_pa: self
                .sigma0_pa
                .or(opt(b.sigma0_pa))
                .or(disc_keys.then_some(0.75e9)),
            n: self.n.or(opt(b.n)).or(disc_keys.then_some(0.37)),
            m: self.m.or(opt(b.m)).or(disc_keys.then_some(4.25)),
            youngs_modulus_pa: self.youngs_modulus_pa.or(opt(b.youngs_modulus_pa)),
            stiffening_length_m: self
                .stiffening_length_m
                .or(spring.map(|e| e.stiffening_length_m)),
            onset_force_n: self.onset_force_n.or(spring.map(|e| e.onset_force_n)),
            model: Some(model),
            friction: self.friction.or(disc.map(|d| d.friction)),
            face_compliance_factor: self
                .face_compliance_factor
                .or(disc.map(|d| d.face_compliance_factor)),
            jc_a_pa: disc.map(|d| d.flow.a_pa),
            jc_b_pa: disc.map(|d| d.flow.b_pa),
            jc_n: disc.map(|d| d.flow.n),
            jc_c: disc.map(|d| d.flow.c),
            jc_reference_rate_per_s: disc.map(|d| d.flow.reference_rate_per_s),
            calibrated_pressure_psi: None,
        };
        let face = disc.map_or(face_modulus_pa, |d| d.face_modulus_pa);
        shaper_from(&s, face, v).map(Some)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The authors' set-up with its gauge file's channels written inline instead.
    fn inline_channels() -> String {
        let text = crate::builtin::setup("authors").unwrap();
        let channels = crate::builtin::gauges("gauges-authors.toml")
            .unwrap()
            .replace("description = ", "# description = ");
        format!(
            "{}\n{channels}",
            text.replace("gauges = \"gauges-authors.toml\"", "")
        )
    }

    #[test]
    fn inline_channels_read_as_the_gauge_file_and_exactly_one_of_the_two() {
        let gauges =
            |g: &str| GaugeSetup::from_toml(crate::builtin::gauges(g).unwrap(), "gauges.toml");
        let from_file =
            Apparatus::from_toml(crate::builtin::setup("authors").unwrap(), "a.toml", &gauges)
                .unwrap();
        let inline = Apparatus::from_toml(&inline_channels(), "a.toml", &gauges).unwrap();
        assert_eq!(inline.gauges, from_file.gauges);
        let both = format!("gauges = \"gauges-authors.toml\"\n{}", inline_channels());
        let e = Apparatus::from_toml(&both, "a.toml", &gauges)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`gauges`") && e.contains("not both"), "{e}");
        let neither = crate::builtin::setup("authors")
            .unwrap()
            .replace("gauges = \"gauges-authors.toml\"", "");
        let e = Apparatus::from_toml(&neither, "a.toml", &gauges)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`gauges`: missing"), "{e}");
    }

    #[test]
    fn a_linear_channel_takes_its_factor_and_only_that() {
        let gauges = |_: &str| -> Result<GaugeSetup> { unreachable!() };
        // Both channels' bridge keys replaced by `keys` (the rest of the line commented out).
        let linear = |keys: &str| {
            let bridge = "bridge = \"full-poisson\"\ngauge_factor = 2.12\nexcitation_v = 15.0\n\
                          poisson_ratio = 0.31";
            let text = inline_channels();
            assert_eq!(text.matches(bridge).count(), 2);
            text.replace(bridge, &format!("bridge = \"linear\"\n{keys}#"))
        };
        let a = Apparatus::from_toml(&linear("strain_per_volt = 4.96e-4\n"), "a.toml", &gauges)
            .unwrap();
        let c = a.gauges.channel("incident").unwrap();
        assert_eq!(c.bridge.kind, shpb_core::gauge::BridgeKind::Linear);
        assert_eq!(c.bridge.strain_per_volt, 4.96e-4);
        let err = |keys: &str| {
            Apparatus::from_toml(&linear(keys), "a.toml", &gauges)
                .unwrap_err()
                .to_string()
        };
        let e = err("strain_per_volt = 4.96e-4\npoisson_ratio = 0.31\n");
        assert!(
            e.contains("`channel[0].poisson_ratio`") && e.contains("linear"),
            "{e}"
        );
        let e = err("");
        assert!(e.contains("`channel[0].strain_per_volt`: missing"), "{e}");
        let e = err("strain_per_volt = 0.0\n");
        assert!(e.contains("non-zero"), "{e}");
        let wheatstone = inline_channels().replace(
            "excitation_v = 15.0\n",
            "excitation_v = 15.0\nstrain_per_volt = 1e-3\n",
        );
        let e = Apparatus::from_toml(&wheatstone, "a.toml", &gauges)
            .unwrap_err()
            .to_string();
        assert!(e.contains("only with bridge = \"linear\""), "{e}");
    }

    #[test]
    fn a_set_up_without_gun_loads_and_refuses_a_pressure() {
        let gauges =
            |g: &str| GaugeSetup::from_toml(crate::builtin::gauges(g).unwrap(), "gauges.toml");
        let text = crate::builtin::setup("authors").unwrap();
        let start = text.find("[gun]").unwrap();
        let end = text.find("# Copper pulse shaper").unwrap();
        // Without the gun, its constants' [uncertainty] goes too (it would name missing keys).
        let certain = text.find("\n[uncertainty]").unwrap();
        let no_gun = format!("{}{}", &text[..start], &text[end..certain]);
        let a = Apparatus::from_toml(&no_gun, "a.toml", &gauges).unwrap();
        assert_eq!(a.gun, Gun::None);
        let e = a.striker_velocity_m_s(1e5).unwrap_err().to_string();
        assert!(e.contains("no [gun]"), "{e}");
    }

    #[test]
    fn editing_the_striker_length_shares_the_gun_work_with_the_new_striker() {
        // ½ m v² = W(p) whatever the mass (docs/physics.md §6.4): doubling the striker's length
        // in the authors' file divides v by √2 and keeps the energy; the calibration striker
        // still gets the calibrated line (5.81 m/s at 10 psi, bars/authors.toml).
        let text = crate::builtin::setup("authors").unwrap();
        let gauges =
            |g: &str| GaugeSetup::from_toml(crate::builtin::gauges(g).unwrap(), "gauges.toml");
        let p = 10.0 * shpb_core::striker::PSI_PA;
        let short = Apparatus::from_toml(text, "a.toml", &gauges).unwrap();
        let long_text = text.replacen("length_m = 0.10\n", "length_m = 0.20\n", 1);
        assert_ne!(long_text, text);
        let long = Apparatus::from_toml(&long_text, "a.toml", &gauges).unwrap();
        assert!((long.striker_mass_kg() / short.striker_mass_kg() - 2.0).abs() < 1e-12);
        let (v1, v2) = (
            short.striker_velocity_m_s(p).unwrap(),
            long.striker_velocity_m_s(p).unwrap(),
        );
        assert!((v1 / v2 - 2f64.sqrt()).abs() < 1e-12, "{v1} {v2}");
        let e = |a: &Apparatus, v: f64| 0.5 * a.striker_mass_kg() * v * v;
        assert!((e(&long, v2) / e(&short, v1) - 1.0).abs() < 1e-12);
        // The shipped 20 cm set-up is that same gun.
        let shipped = Apparatus::resolve("authors-20cm-striker", Path::new(".")).unwrap();
        assert!((shipped.striker_velocity_m_s(p).unwrap() / v2 - 1.0).abs() < 1e-12);
        // A file without the key: the line belongs to its own striker (old files keep working).
        let old = text.replace("calibration_striker_length_m = 0.10", "");
        let old = Apparatus::from_toml(&old, "a.toml", &gauges).unwrap();
        assert!((old.striker_velocity_m_s(p).unwrap() / v1 - 1.0).abs() < 1e-12);
        // The key names itself when it does not apply or is not a length.
        let bad = text.replace(
            "calibration_striker_length_m = 0.10",
            "calibration_striker_length_m = -1",
        );
        let e = Apparatus::from_toml(&bad, "a.toml", &gauges).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("a.toml: `gun.calibration_striker_length_m`"),
            "{e}"
        );
        let adiabatic = text.replace(
            "model = \"linear\"",
            "model = \"adiabatic\"\nreservoir_volume_m3 = 3.2e-4\nbarrel_length_m = 0.353",
        );
        let e = Apparatus::from_toml(&adiabatic, "a.toml", &gauges).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("a.toml: `gun.calibration_striker_length_m`: only a calibration line"),
            "{e}"
        );
    }

    #[test]
    fn the_gun_calibration_is_read_and_checked() {
        let authors = Apparatus::resolve("authors", Path::new(".")).unwrap();
        let psi = shpb_core::striker::PSI_PA;
        let (lo, hi) = authors.gun_calibrated_pa.unwrap();
        assert!((lo / psi - 10.0).abs() < 1e-6 && (hi / psi - 15.0).abs() < 1e-6);
        assert_eq!(
            Apparatus::resolve("authors-20cm-striker", Path::new("."))
                .unwrap()
                .gun_calibrated_pa,
            Some((lo, hi))
        );
        let text = crate::builtin::setup("authors").unwrap();
        let gauges =
            |g: &str| GaugeSetup::from_toml(crate::builtin::gauges(g).unwrap(), "gauges.toml");
        // Neither key: no calibration stated.
        let none = text
            .lines()
            .filter(|l| !l.starts_with("calibrated_"))
            .collect::<Vec<_>>()
            .join("\n");
        let a = Apparatus::from_toml(&none, "a.toml", &gauges).unwrap();
        assert_eq!(a.gun_calibrated_pa, None);
        // One without the other, or outside the gun's range, names the key.
        let one = text.replace("calibrated_max_pressure_pa = 103421.36", "");
        let e = Apparatus::from_toml(&one, "a.toml", &gauges).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("a.toml: `gun.calibrated_max_pressure_pa`: missing"),
            "{e}"
        );
        let wide = text.replace(
            "calibrated_max_pressure_pa = 103421.36",
            "calibrated_max_pressure_pa = 3e5",
        );
        let e = Apparatus::from_toml(&wide, "a.toml", &gauges).unwrap_err();
        assert!(
            e.to_string().starts_with(
                "a.toml: `gun.calibrated_max_pressure_pa`: 300 kPa is out of range; allowed: 69 kPa to 206.8 kPa"
            ),
            "{e}"
        );
    }

    /// The authors' set-up with its `[shaper]` table replaced by `shaper`.
    fn with_shaper(shaper: &str) -> Result<Apparatus> {
        let text = crate::builtin::setup("authors").unwrap();
        let head = &text[..text.find("\n[shaper]").unwrap() + 1];
        let gauges =
            |g: &str| GaugeSetup::from_toml(crate::builtin::gauges(g).unwrap(), "gauges.toml");
        Apparatus::from_toml(&format!("{head}{shaper}"), "a.toml", &gauges)
    }

    #[test]
    fn the_shaper_model_and_its_calibrated_range_are_read_and_checked() {
        let read = with_shaper;
        let disc = read(
            "[shaper]\nmodel = \"crushed-disc\"\ndiameter_m = 4e-3\nthickness_m = 5e-4\n\
             youngs_modulus_pa = 117e9\nfriction = 0.1\ncalibrated_pressure_psi = [10.0, 15.0]\n",
        )
        .unwrap();
        let s = disc.shaper.unwrap();
        let ShaperModel::CrushedDisc(d) = s.model else {
            panic!("{:?}", s.model)
        };
        // Johnson & Cook's OFHC copper unless stated; faces of the set-up's bars, E/(1 − ν²).
        assert_eq!(d.flow, JohnsonCook::OFHC_COPPER);
        assert_eq!(d.friction, 0.1);
        assert_eq!(d.face_compliance_factor, 1.0);
        assert!((d.face_modulus_pa - 192e9 / (1.0 - 0.31 * 0.31)).abs() < 1.0);
        let (lo, hi) = s.calibrated_pressure_pa.unwrap();
        assert!((lo / PSI_PA - 10.0).abs() < 1e-9 && (hi / PSI_PA - 15.0).abs() < 1e-9);
        // Frew needs its three constants; an unknown model or a reversed range names the key.
        let e = read("[shaper]\ndiameter_m = 4e-3\nthickness_m = 5e-4\nyoungs_modulus_pa = 1e9\n")
            .unwrap_err();
        assert!(e.to_string().contains("`shaper.sigma0_pa`: missing"), "{e}");
        let e = read(
            "[shaper]\nmodel = \"rubber\"\ndiameter_m = 4e-3\nthickness_m = 5e-4\nyoungs_modulus_pa = 1e9\n",
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("`shaper.model`: unknown shaper model `rubber`"),
            "{e}"
        );
        let e = read(
            "[shaper]\nmodel = \"crushed-disc\"\ndiameter_m = 4e-3\nthickness_m = 5e-4\n\
             youngs_modulus_pa = 117e9\ncalibrated_pressure_psi = [15.0, 10.0]\n",
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("`shaper.calibrated_pressure_psi`"),
            "{e}"
        );
        // A scene overriding a constant drops the calibrated range; one that does not keeps it.
        let v = Validator::new("scene.toml");
        let kept = ShaperOverride::default()
            .apply(Some(s), 1e11, &v)
            .unwrap()
            .unwrap();
        assert_eq!(kept.calibrated_pressure_pa, s.calibrated_pressure_pa);
        let thicker = ShaperOverride {
            thickness_m: Some(1e-3),
            ..Default::default()
        };
        let t = thicker.apply(Some(s), 1e11, &v).unwrap().unwrap();
        assert_eq!(t.calibrated_pressure_pa, None);
        assert_eq!(
            t.model, s.model,
            "the override keeps the model and its faces"
        );
    }

    #[test]
    fn the_exponential_shaper_takes_its_two_constants_and_refuses_a_disc_s_constants() {
        let read = with_shaper;
        let a = read(
            "[shaper]\nmodel = \"exponential\"\nstiffening_length_m = 1e-4\nonset_force_n = 100\n\
             calibrated_pressure_psi = [10.0, 15.0]\n",
        )
        .unwrap();
        let s = a.shaper.unwrap();
        assert_eq!(
            s.model,
            ShaperModel::Exponential(ExponentialSpring {
                stiffening_length_m: 1e-4,
                onset_force_n: 100.0
            })
        );
        assert!(s.calibrated_pressure_pa.is_some());
        for (bad, key) in [
            (
                "model = \"exponential\"\nstiffening_length_m = 1e-4\n",
                "`shaper.onset_force_n`: missing",
            ),
            (
                "model = \"exponential\"\nstiffening_length_m = -1e-4\nonset_force_n = 100\n",
                "`shaper.stiffening_length_m`",
            ),
            (
                "model = \"exponential\"\nstiffening_length_m = 1e-4\nonset_force_n = 100\nthickness_m = 5e-4\n",
                "`shaper.thickness_m`: not a constant of model = \"exponential\"",
            ),
            (
                "diameter_m = 4e-3\nthickness_m = 5e-4\nyoungs_modulus_pa = 1e9\nsigma0_pa = 7.5e8\n\
                 n = 0.37\nm = 4.25\nonset_force_n = 100\n",
                "`shaper.onset_force_n`: not a constant of model = \"frew\"",
            ),
            ("model = \"frew\"\n", "`shaper.diameter_m`: missing"),
        ] {
            let e = read(&format!("[shaper]\n{bad}")).unwrap_err().to_string();
            assert!(e.contains(key), "{bad}: {e}");
        }
        // A scene may switch the set-up's shaper to the exponential law and back; the other
        // model's constants do not carry over.
        let v = Validator::new("scene.toml");
        let frew = read(
            "[shaper]\ndiameter_m = 4e-3\nthickness_m = 5e-4\nyoungs_modulus_pa = 1e9\n\
             sigma0_pa = 7.5e8\nn = 0.37\nm = 4.25\n",
        )
        .unwrap()
        .shaper
        .unwrap();
        let to_exp = ShaperOverride {
            model: Some("exponential".into()),
            stiffening_length_m: Some(1e-4),
            onset_force_n: Some(100.0),
            ..Default::default()
        };
        let x = to_exp.apply(Some(frew), 1e11, &v).unwrap().unwrap();
        assert_eq!(x.model, s.model);
        let longer = ShaperOverride {
            stiffening_length_m: Some(2e-4),
            ..Default::default()
        };
        let y = longer.apply(Some(x), 1e11, &v).unwrap().unwrap();
        let ShaperModel::Exponential(e) = y.model else {
            panic!("{:?}", y.model)
        };
        assert_eq!((e.stiffening_length_m, e.onset_force_n), (2e-4, 100.0));
        let back = ShaperOverride {
            model: Some("frew".into()),
            ..Default::default()
        };
        let e = back.apply(Some(x), 1e11, &v).unwrap_err().to_string();
        assert!(e.contains("`diameter_m`: missing"), "{e}");
    }

    #[test]
    fn a_crushed_disc_takes_an_exponential_cushion_from_both_its_keys() {
        let read = with_shaper;
        let disc = "[shaper]\nmodel = \"crushed-disc\"\ndiameter_m = 6e-3\nthickness_m = 3e-4\n\
                    youngs_modulus_pa = 117e9\n";
        let bare = read(disc).unwrap().shaper.unwrap();
        let ShaperModel::CrushedDisc(d) = bare.model else {
            panic!("{:?}", bare.model)
        };
        assert_eq!(d.cushion, None);
        let a = read(&format!(
            "{disc}stiffening_length_m = 6e-5\nonset_force_n = 10\n"
        ))
        .unwrap();
        let s = a.shaper.unwrap();
        let ShaperModel::CrushedDisc(c) = s.model else {
            panic!("{:?}", s.model)
        };
        let spring = ExponentialSpring {
            stiffening_length_m: 6e-5,
            onset_force_n: 10.0,
        };
        assert_eq!(c.cushion, Some(spring));
        // One of the two is not a cushion.
        let e = read(&format!("{disc}stiffening_length_m = 6e-5\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("`shaper.onset_force_n`: missing"), "{e}");
        // A scene's override of λ keeps the disc and its F0; switching to frew keeps the disc's
        // geometry and drops the cushion.
        let v = Validator::new("scene.toml");
        let longer = ShaperOverride {
            stiffening_length_m: Some(9e-5),
            ..Default::default()
        };
        let y = longer.apply(Some(s), 1e11, &v).unwrap().unwrap();
        let ShaperModel::CrushedDisc(yd) = y.model else {
            panic!("{:?}", y.model)
        };
        assert_eq!(
            yd.cushion.map(|e| (e.stiffening_length_m, e.onset_force_n)),
            Some((9e-5, 10.0))
        );
        assert_eq!((y.diameter_m, y.thickness_m), (6e-3, 3e-4));
        let to_frew = ShaperOverride {
            model: Some("frew".into()),
            ..Default::default()
        };
        let f = to_frew.apply(Some(s), 1e11, &v).unwrap().unwrap();
        assert_eq!(f.model, ShaperModel::Frew);
        assert_eq!((f.diameter_m, f.thickness_m), (6e-3, 3e-4));
    }
}
