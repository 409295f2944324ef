//! Scene files: one TOML file per virtual test, with a `kind` key, parsed once into a validated
//! [`Params`] of the core (physics code never sees unchecked input).

use crate::csv::CsvTable;
use crate::error::{Error, Result, Validator};
use crate::material::MaterialFile;
use crate::kinds::SCENE_KINDS;
use crate::setup::ShaperOverride;
use crate::specimen::SpecimenSpec;
use serde::Deserialize;
use serde::de::DeserializeOwned;
use shpb_core::apparatus::{IncidentEnd, PulseOptions};
use shpb_core::bar::Dispersion;
use shpb_core::contact::{LawKind, Region2Form};
use shpb_core::fidelity::Fidelity;
use shpb_core::scene::{AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S, Params, SceneParams};
use shpb_core::apparatus::Apparatus;
use shpb_core::solver::{self, CollisionSetup, ForceDrivenSetup, ForceHistory};
use shpb_core::specimen::SpherePair;
use crate::setup::ApparatusFile;
use std::path::{Path, PathBuf};

/// A TOML value, as given to [`SceneFile::from_file_overridden`] and [`with_overrides`].
pub use toml::Value;

/// `law = "..."`: the scene names of [`LawKind`].
#[derive(Deserialize)]
#[serde(remote = "LawKind", rename_all = "kebab-case")]
enum LawKindToml {
    BurgoyneDaraio,
    RateIndependent,
    Hertz,
}

/// `region2 = "..."`: the scene names of [`Region2Form`].
#[derive(Deserialize)]
#[serde(remote = "Region2Form", rename_all = "kebab-case")]
enum Region2Toml {
    Smooth,
    Published,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct QuasistaticFile {
    #[allow(dead_code)]
    kind: String,
    #[allow(dead_code)]
    fidelity: Option<String>,
    specimen: SpecimenSpec,
    #[serde(default, with = "LawKindToml")]
    law: LawKind,
    #[serde(default, with = "Region2Toml")]
    region2: Region2Form,
    max_displacement_m: f64,
    #[serde(default = "default_points")]
    points: usize,
    #[serde(default)]
    strain_rate_per_s: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConstantRateFile {
    #[allow(dead_code)]
    kind: String,
    #[allow(dead_code)]
    fidelity: Option<String>,
    specimen: SpecimenSpec,
    #[serde(default, with = "LawKindToml")]
    law: LawKind,
    #[serde(default, with = "Region2Toml")]
    region2: Region2Form,
    strain_rate_per_s: f64,
    max_displacement_m: f64,
    #[serde(default = "default_points")]
    points: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CollisionFile {
    #[allow(dead_code)]
    kind: String,
    #[allow(dead_code)]
    fidelity: Option<String>,
    specimen: SpecimenSpec,
    #[serde(default, with = "LawKindToml")]
    law: LawKind,
    #[serde(default, with = "Region2Toml")]
    region2: Region2Form,
    velocity1_m_s: f64,
    #[serde(default)]
    velocity2_m_s: f64,
    time_step_s: Option<f64>,
    steps_per_contact: Option<f64>,
    #[serde(default = "one")]
    output_every: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ForceDrivenFile {
    #[allow(dead_code)]
    kind: String,
    #[allow(dead_code)]
    fidelity: Option<String>,
    specimen: SpecimenSpec,
    #[serde(default, with = "LawKindToml")]
    law: LawKind,
    #[serde(default, with = "Region2Toml")]
    region2: Region2Form,
    force_csv: String,
    #[serde(default = "default_time_column")]
    time_column: String,
    #[serde(default = "default_force_column")]
    force_column: String,
    #[serde(default = "default_impedance")]
    medium_impedance_kg_s: f64,
    time_step_s: Option<f64>,
    steps_per_period: Option<f64>,
    end_time_s: Option<f64>,
    #[serde(default = "one")]
    output_every: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PulseFile {
    #[allow(dead_code)]
    kind: String,
    #[allow(dead_code)]
    fidelity: Option<String>,
    specimen: Option<SpecimenSpec>,
    #[serde(default, with = "LawKindToml")]
    law: LawKind,
    #[serde(default, with = "Region2Toml")]
    region2: Region2Form,
    bars: String,
    pressure: String,
    #[serde(default)]
    shaper: ShaperOverride,
    cell_size_m: Option<f64>,
    #[serde(default = "default_incident_end")]
    incident_end: String,
    dispersion: Option<String>,
    end_time_s: Option<f64>,
    #[serde(default = "default_gauge_length")]
    gauge_length_m: f64,
}

fn default_gauge_length() -> f64 {
    2e-3
}

fn default_incident_end() -> String {
    "transmission".into()
}

fn default_points() -> usize {
    1001
}
fn one() -> usize {
    1
}
fn default_time_column() -> String {
    "time_s".into()
}
fn default_force_column() -> String {
    "force_N".into()
}
fn default_impedance() -> f64 {
    AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S
}

fn parse_as<T: DeserializeOwned>(text: &str, file: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| Error::Parse {
        file: file.to_string(),
        message: e.to_string(),
    })
}

fn check_points(v: &Validator, points: usize) -> Result<usize> {
    if !(2..=10_000_000).contains(&points) {
        return Err(v.error(
            "points",
            format!("{points} is out of range"),
            "2 to 10000000",
        ));
    }
    Ok(points)
}

fn check_every(v: &Validator, n: usize) -> Result<usize> {
    if n == 0 {
        return Err(v.error("output_every", "0 is out of range", "1 or more"));
    }
    Ok(n)
}

/// Reading and validating scene files into the core's [`Params`].
pub trait SceneFile: Sized {
    /// Reads and validates a scene file.
    fn from_file(path: &Path) -> Result<Self>;
    /// Validates scene TOML text; relative paths inside it are resolved against `base_dir`.
    fn from_toml(text: &str, file: &str, base_dir: &Path) -> Result<Self>;
    /// Reads a scene file with its `fidelity` replaced by `fidelity` (when given): what
    /// `--fidelity` does. The stored scene text is the file's with the preset set.
    fn from_file_with(path: &Path, fidelity: Option<Fidelity>) -> Result<Self>;
    /// Reads a scene file with some keys replaced (dotted paths such as `shaper.thickness_m`
    /// reach into tables); the stored scene text is the modified TOML.
    fn from_file_overridden(path: &Path, overrides: &[(String, toml::Value)]) -> Result<Self>;
}

impl SceneFile for Params {
    /// Reads and validates a scene file.
    fn from_file(path: &Path) -> Result<Params> {
        Params::from_file_overridden(path, &[])
    }

    /// Validates scene TOML text; relative paths inside it are resolved against `base_dir`.
    fn from_toml(text: &str, file: &str, base_dir: &Path) -> Result<Params> {
        let v = Validator::new(file);
        let table: toml::Table = parse_as(text, file)?;
        let kinds = SCENE_KINDS
            .iter()
            .map(|(k, _)| *k)
            .collect::<Vec<_>>()
            .join(", ");
        let kind = match table.get("kind") {
            Some(toml::Value::String(k)) => k.clone(),
            Some(_) => return Err(v.error("kind", "not a string", kinds)),
            None => return Err(v.error("kind", "missing", kinds)),
        };
        let fidelity = match table.get("fidelity") {
            None => Fidelity::default(),
            Some(toml::Value::String(name)) => Fidelity::parse(name).ok_or_else(|| {
                v.error(
                    "fidelity",
                    format!("unknown preset `{name}`"),
                    "fast, standard, reference",
                )
            })?,
            Some(_) => {
                return Err(v.error("fidelity", "not a string", "fast, standard, reference"));
            }
        };
        let sv = v.table("specimen");
        let (pair, law, region2, params) = match kind.as_str() {
            "quasistatic" => {
                let f: QuasistaticFile = parse_as(text, file)?;
                let pair = f.specimen.build(base_dir, &sv)?;
                let p = SceneParams::Quasistatic {
                    max_displacement_m: v.positive(
                        "max_displacement_m",
                        f.max_displacement_m,
                        0.5 * pair.sphere1.radius_m.min(pair.sphere2.radius_m),
                        "m",
                    )?,
                    points: check_points(&v, f.points)?,
                    strain_rate_per_s: v.in_range(
                        "strain_rate_per_s",
                        f.strain_rate_per_s,
                        0.0,
                        1e9,
                        "1/s",
                    )?,
                };
                (pair, f.law, f.region2, p)
            }
            "constant-rate" => {
                let f: ConstantRateFile = parse_as(text, file)?;
                let pair = f.specimen.build(base_dir, &sv)?;
                let p = SceneParams::ConstantRate {
                    strain_rate_per_s: v.positive(
                        "strain_rate_per_s",
                        f.strain_rate_per_s,
                        1e9,
                        "1/s",
                    )?,
                    max_displacement_m: v.positive(
                        "max_displacement_m",
                        f.max_displacement_m,
                        0.5 * pair.sphere1.radius_m.min(pair.sphere2.radius_m),
                        "m",
                    )?,
                    points: check_points(&v, f.points)?,
                };
                (pair, f.law, f.region2, p)
            }
            "collision" => {
                let f: CollisionFile = parse_as(text, file)?;
                let pair = f.specimen.build(base_dir, &sv)?;
                let v1 = v.in_range("velocity1_m_s", f.velocity1_m_s, -1e4, 1e4, "m/s")?;
                let v2 = v.in_range("velocity2_m_s", f.velocity2_m_s, -1e4, 1e4, "m/s")?;
                if v1 <= v2 {
                    return Err(v.error("velocity1_m_s", format!("{v1} m/s does not exceed velocity2_m_s = {v2} m/s, so the spheres never meet"), "velocity1_m_s > velocity2_m_s"));
                }
                let speed = v1 - v2;
                let p = pair.contact_properties();
                let tc = solver::hertz_impact_duration(
                    pair.reduced_mass_kg(),
                    p.e_star_pa,
                    p.radius_m,
                    speed,
                );
                if !(tc.is_finite() && tc > 0.0) {
                    // A closing speed so small (subnormal) that the Hertz contact time overflows.
                    return Err(v.error(
                        "velocity1_m_s",
                        format!("closing speed {speed:e} m/s gives no finite contact time"),
                        "velocity1_m_s - velocity2_m_s a normal (not subnormal) positive number of m/s",
                    ));
                }
                let n = v.in_range(
                    "steps_per_contact",
                    f.steps_per_contact.unwrap_or(fidelity.dem_steps()),
                    20.0,
                    1e8,
                    "",
                )?;
                let limit = solver::stability_limit(&pair, solver::hertz_peak_force(&pair, speed));
                let dt = match f.time_step_s {
                    Some(dt) => v.positive(
                        "time_step_s",
                        dt,
                        limit,
                        "s (the stability limit 1/ω of this contact, solver::stability_limit)",
                    )?,
                    None => tc / n,
                };
                let setup = CollisionSetup {
                    velocity1_m_s: v1,
                    velocity2_m_s: v2,
                    dt_s: dt,
                    max_time_s: 1000.0 * tc,
                    output_every: check_every(&v, f.output_every)?,
                };
                (pair, f.law, f.region2, SceneParams::Collision(setup))
            }
            "force-driven" => {
                let f: ForceDrivenFile = parse_as(text, file)?;
                let pair = f.specimen.build(base_dir, &sv)?;
                let csv_path = base_dir.join(&f.force_csv);
                let table = CsvTable::read(&csv_path).map_err(|e| match e {
                    Error::Io { source, .. } => v.error(
                        "force_csv",
                        format!("cannot read {}: {source}", csv_path.display()),
                        "a readable CSV file, absolute or relative to the scene file's directory",
                    ),
                    other => other,
                })?;
                let t = table.time_column(&f.time_column)?.to_vec();
                let force = table.column(&f.force_column)?.to_vec();
                let measured_displacement_m =
                    table.optional_column("displacement_m").map(<[f64]>::to_vec);
                let drive = ForceHistory {
                    time_s: t,
                    force_n: force,
                };
                let z = v.in_range(
                    "medium_impedance_kg_s",
                    f.medium_impedance_kg_s,
                    0.0,
                    1e9,
                    "kg/s",
                )?;
                let n = v.in_range(
                    "steps_per_period",
                    f.steps_per_period.unwrap_or(fidelity.dem_steps()),
                    10.0,
                    1e8,
                    "",
                )?;
                let peak = drive.peak_n().max(1e-3);
                let limit = solver::stability_limit(&pair, peak);
                let dt = match f.time_step_s {
                    Some(dt) => v.positive("time_step_s", dt, limit, "s (the stability limit 1/ω of this contact at the peak drive force, solver::stability_limit)")?,
                    None => solver::default_time_step(&pair, peak, z, n),
                };
                let last = *drive
                    .time_s
                    .last()
                    .expect("time column has at least two samples");
                let end = match f.end_time_s {
                    Some(e) => v.positive("end_time_s", e, 1.0, "s")?,
                    None => last,
                };
                if end / dt > 5e8 {
                    return Err(v.error(
                        "end_time_s",
                        format!("{end:e} s needs {:.1e} steps of {dt:e} s", end / dt),
                        "at most 5e8 steps",
                    ));
                }
                let setup = ForceDrivenSetup {
                    drive,
                    medium_impedance_kg_s: z,
                    dt_s: dt,
                    end_time_s: end,
                    output_every: check_every(&v, f.output_every)?,
                };
                (
                    pair,
                    f.law,
                    f.region2,
                    SceneParams::ForceDriven {
                        setup,
                        measured_displacement_m,
                    },
                )
            }
            "pulse" | "shpb" => {
                let f: PulseFile = parse_as(text, file)?;
                let is_test = kind == "shpb";
                let specimen = match (&f.specimen, is_test) {
                    (Some(spec), true) => Some(shpb_core::apparatus::SpecimenSetup {
                        pair: spec.build(base_dir, &sv)?,
                        law: f.law,
                        region2: f.region2,
                    }),
                    (None, true) => {
                        return Err(v.error(
                            "specimen",
                            "missing",
                            "a [specimen] table (pair = \"ss440c\", or sphere1/sphere2)",
                        ));
                    }
                    (Some(_), false) => {
                        return Err(v.error(
                            "specimen",
                            "a pulse scene has no specimen",
                            "kind = \"shpb\" for a test with spheres",
                        ));
                    }
                    (None, false) => None,
                };
                let set_up = base_dir.join(&f.bars);
                if crate::builtin::setup(&f.bars).is_none() && !set_up.is_file() {
                    return Err(v.error(
                        "bars",
                        format!("cannot read {}: no such file", set_up.display()),
                        format!(
                            "a built-in set-up ({}) or a bar set-up .toml file, relative to the scene file",
                            crate::builtin::setup_names()
                        ),
                    ));
                }
                let apparatus = Apparatus::resolve(&f.bars, base_dir)?;
                let pressure_pa = crate::units::pressure_from_text(&f.pressure, &v, "pressure")?;
                let velocity = apparatus
                    .striker_velocity_m_s(pressure_pa)
                    .map_err(v.core("pressure"))?;
                let shaper = f.shaper.apply(apparatus.shaper, &v.table("shaper"))?;
                let end = match f.incident_end.as_str() {
                    _ if is_test => IncidentEnd::Specimen,
                    "transmission" => IncidentEnd::Transmission,
                    "free" => IncidentEnd::Free,
                    "absorbing" => IncidentEnd::Absorbing,
                    other => {
                        return Err(v.error(
                            "incident_end",
                            format!("unknown end `{other}`"),
                            "transmission, free, absorbing",
                        ));
                    }
                };
                let knobs = fidelity.bar_knobs();
                let dispersion = match f.dispersion.as_deref() {
                    None => knobs.dispersion,
                    Some("none") => Dispersion::None,
                    Some("love-rod") => Dispersion::LoveRod,
                    Some(other) => {
                        return Err(v.error(
                            "dispersion",
                            format!("unknown model `{other}`"),
                            "none, love-rod",
                        ));
                    }
                };
                let cell = v.in_range(
                    "cell_size_m",
                    f.cell_size_m.unwrap_or(knobs.cell_size_m),
                    1e-5,
                    0.05,
                    "m",
                )?;
                let c0 = apparatus.material.wave_speed_m_s();
                let gauge_d = apparatus
                    .gauges
                    .channels
                    .iter()
                    .map(|c| c.distance_from_specimen_m)
                    .fold(0.0, f64::max);
                // Default: the incident pulse passes its gauge, reflects and passes it again.
                let default_end = (apparatus.incident.length_m + gauge_d) / c0
                    + 4.0 * apparatus.striker.length_m / c0
                    + 200e-6;
                let end_time_s = match f.end_time_s {
                    Some(e) => v.positive("end_time_s", e, 0.1, "s")?,
                    None => default_end,
                };
                let gauge_length_m =
                    v.in_range("gauge_length_m", f.gauge_length_m, 0.0, 0.05, "m")?;
                let options = PulseOptions {
                    specimen: specimen.clone(),
                    striker_velocity_m_s: velocity,
                    shaper,
                    end,
                    cell_size_m: cell,
                    dispersion,
                    end_time_s,
                    gauge_length_m,
                    snapshot_interval_s: is_test.then_some(knobs.snapshot_interval_s),
                };
                // Refuse a grid the bars cannot run (time step over the stability limit) now, not mid-run.
                for spec in &apparatus.pulse_chain(&options).bars {
                    shpb_core::bar::Bar::new(spec, cell / c0).map_err(v.core("cell_size_m"))?;
                }
                // A pulse scene has no spheres: its `pair` is a placeholder that nothing reads.
                let pair = match specimen {
                    Some(sp) => sp.pair,
                    None => SpherePair::paper(
                        shpb_core::material::Material::builtin("ss440c").expect("built-in"),
                    ),
                };
                (
                    pair,
                    f.law,
                    f.region2,
                    SceneParams::Pulse {
                        apparatus: Box::new(apparatus),
                        pressure_pa,
                        options: Box::new(options),
                    },
                )
            }
            other => return Err(v.error("kind", format!("unknown scene kind `{other}`"), kinds)),
        };
        Ok(Params {
            source: file.to_string(),
            text: text.to_string(),
            kind,
            pair,
            law,
            region2,
            fidelity,
            params,
        })
    }

    /// Reads a scene file with its `fidelity` replaced by `fidelity` (when given): what
    /// `--fidelity` does. The stored scene text is the file's with the preset set.
    fn from_file_with(path: &Path, fidelity: Option<Fidelity>) -> Result<Params> {
        let overrides: Vec<(String, toml::Value)> = fidelity
            .map(|f| ("fidelity".to_string(), toml::Value::String(f.name().into())))
            .into_iter()
            .collect();
        Params::from_file_overridden(path, &overrides)
    }

    /// Reads a scene file with some keys replaced (dotted paths such as `shaper.thickness_m`
    /// reach into tables); the stored scene text is the modified TOML.
    fn from_file_overridden(
        path: &Path,
        overrides: &[(String, toml::Value)],
    ) -> Result<Params> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let file = path.display().to_string();
        let text = if overrides.is_empty() {
            text
        } else {
            with_overrides(&text, &file, overrides)?
        };
        let base = path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        Params::from_toml(&text, &file, &base)
    }
}

/// Scene TOML `text` with `overrides` applied: each dotted key path (`pressure`,
/// `shaper.thickness_m`) set to its value, creating tables on the way; an error names `file`
/// when a path runs through a non-table value.
pub fn with_overrides(
    text: &str,
    file: &str,
    overrides: &[(String, toml::Value)],
) -> Result<String> {
    let v = Validator::new(file);
    let mut table: toml::Table = parse_as(text, file)?;
    for (path, value) in overrides {
        let parts: Vec<&str> = path.split('.').collect();
        let (last, tables) = parts.split_last().expect("split yields at least one part");
        let mut t = &mut table;
        for part in tables {
            let entry = t
                .entry(part.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            t = match entry {
                toml::Value::Table(inner) => inner,
                _ => {
                    return Err(v.error(
                        path,
                        format!("`{part}` is not a table"),
                        "a key path through tables, e.g. shaper.thickness_m",
                    ));
                }
            };
        }
        t.insert(last.to_string(), value.clone());
    }
    toml::to_string(&table).map_err(|e| Error::Parse {
        file: file.to_string(),
        message: e.to_string(),
    })
}

