//! Scene files: one TOML file per virtual test, with a `kind` key, parsed once into validated
//! [`Params`] (physics code never sees unchecked input), and run into a [`RunOutput`].

use crate::apparatus::{Apparatus, IncidentEnd, PulseOptions, ShaperOverride};
use crate::bar::Dispersion;
use crate::contact::{ContactLaw, Degenerate, LawKind, LoadingCurve, Region2Form};
use crate::error::{Error, Result, Validator};
use crate::fidelity::Fidelity;
use crate::io::{CsvTable, RunOutput, SummaryItem, item};
use crate::solver::{self, CollisionSetup, ContactSeries, ForceDrivenSetup, ForceHistory};
use crate::specimen::{SpecimenSpec, SpherePair};
use serde::Deserialize;
use serde::de::DeserializeOwned;
use std::path::{Path, PathBuf};

/// Impedance Z = ρ c0 A of the authors' transmission bar (ρ 8110 kg/m³, c0 4865.5 m/s,
/// radius 9.525 mm; physics.md §5), kg/s.
pub const AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S: f64 =
    8110.0 * 4865.5 * std::f64::consts::PI * 9.525e-3 * 9.525e-3;

/// The scene kinds with a one-line description each (shown by `shpb --help`).
pub const SCENE_KINDS: &[(&str, &str)] = &[
    (
        "quasistatic",
        "F(δ) of the loading law up to max_displacement_m (paper Fig. 2)",
    ),
    (
        "constant-rate",
        "spheres pressed at constant approach speed with rate hardening (paper Fig. 3)",
    ),
    (
        "collision",
        "two free spheres with initial velocities: restitution, contact time, peak force, dissipation",
    ),
    (
        "force-driven",
        "paper Fig. 4 DEM: a CSV force history drives sphere 1, sphere 2 rests on a medium of impedance Z",
    ),
];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct QuasistaticFile {
    #[allow(dead_code)]
    kind: String,
    #[allow(dead_code)]
    fidelity: Option<String>,
    specimen: SpecimenSpec,
    #[serde(default)]
    law: LawKind,
    #[serde(default)]
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
    #[serde(default)]
    law: LawKind,
    #[serde(default)]
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
    #[serde(default)]
    law: LawKind,
    #[serde(default)]
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
    #[serde(default)]
    law: LawKind,
    #[serde(default)]
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
    #[serde(default)]
    law: LawKind,
    #[serde(default)]
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

/// Validated parameters of a scene, by kind.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneParams {
    /// Loading law F(δ) on a grid (Fig. 2).
    Quasistatic {
        /// Largest approach, m.
        max_displacement_m: f64,
        /// Number of grid points.
        points: usize,
        /// Strain rate at which the curve is evaluated (0: static), 1/s.
        strain_rate_per_s: f64,
    },
    /// Constant approach speed (Fig. 3).
    ConstantRate {
        /// Global strain rate of paper Eq. 3, 1/s.
        strain_rate_per_s: f64,
        /// Largest approach, m.
        max_displacement_m: f64,
        /// Number of samples.
        points: usize,
    },
    /// Free collision.
    Collision(CollisionSetup),
    /// Striker, shaper and bars: the gauge signals of a bar test without specimen.
    Pulse {
        /// The bar set-up.
        apparatus: Box<Apparatus>,
        /// Gas-gun gauge pressure, Pa.
        pressure_pa: f64,
        /// Solver options (striker velocity from the gun).
        options: Box<PulseOptions>,
    },
    /// Fig. 4 force-driven DEM; `measured` holds the CSV's displacement column when present.
    ForceDriven {
        /// Solver inputs.
        setup: ForceDrivenSetup,
        /// Measured approach at the drive's sample times, if the CSV has `displacement_m`.
        measured_displacement_m: Option<Vec<f64>>,
    },
}

/// A parsed, validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// The scene file (or label).
    pub source: String,
    /// The TOML text, stored in the output for provenance.
    pub text: String,
    /// Scene kind name.
    pub kind: String,
    /// The specimen.
    pub pair: SpherePair,
    /// The contact law selected.
    pub law: LawKind,
    /// The fidelity preset the numerical knobs were taken from (explicit keys win).
    pub fidelity: Fidelity,
    /// Form of region II of the loading law (`smooth` C¹ default, or `published`).
    pub region2: Region2Form,
    /// Kind-specific parameters.
    pub params: SceneParams,
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

impl Params {
    /// Reads and validates a scene file.
    pub fn from_file(path: &Path) -> Result<Params> {
        Params::from_file_overridden(path, &[])
    }

    /// Validates scene TOML text; relative paths inside it are resolved against `base_dir`.
    pub fn from_toml(text: &str, file: &str, base_dir: &Path) -> Result<Params> {
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
                    (Some(spec), true) => Some(crate::apparatus::SpecimenSetup {
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
                if !set_up.is_file() {
                    return Err(v.error("bars", format!("cannot read {}: no such file", set_up.display()), "a bar set-up .toml file (e.g. bars/authors.toml), relative to the scene file"));
                }
                let apparatus = Apparatus::from_file(&set_up)?;
                let pressure_pa = crate::striker::pressure_from_text(&f.pressure, &v, "pressure")?;
                let velocity = apparatus.striker_velocity_m_s(pressure_pa, &v, "pressure")?;
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
                    crate::bar::Bar::new(spec, cell / c0)?;
                }
                // A pulse scene has no spheres: its `pair` is a placeholder that nothing reads.
                let pair = match specimen {
                    Some(sp) => sp.pair,
                    None => SpherePair::paper(
                        crate::material::Material::builtin("ss440c").expect("built-in"),
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
    pub fn from_file_with(path: &Path, fidelity: Option<Fidelity>) -> Result<Params> {
        let overrides: Vec<(String, toml::Value)> = fidelity
            .map(|f| ("fidelity".to_string(), toml::Value::String(f.name().into())))
            .into_iter()
            .collect();
        Params::from_file_overridden(path, &overrides)
    }

    /// Reads a scene file with some keys replaced (dotted paths such as `shaper.thickness_m`
    /// reach into tables); the stored scene text is the modified TOML.
    pub fn from_file_overridden(
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

    /// The contact law of this scene.
    pub fn contact_law(&self) -> Box<dyn ContactLaw> {
        self.law
            .build_with(self.pair.contact_properties(), self.region2)
    }

    /// Warnings about the scene that do not stop it (e.g. a pair whose law has no region II).
    pub fn warnings(&self) -> Vec<String> {
        let p = self.pair.contact_properties();
        let c = LoadingCurve::new(p.e_star_pa, p.radius_m, p.yield_stress_pa);
        let q = p.e_star_pa / p.yield_stress_pa;
        match c.degenerate {
            Degenerate::No => vec![],
            Degenerate::HertzToPlasticAt(d) => vec![format!(
                "{}: δp ≤ δy for this pair (q = E*/σy = {q:.3}): region II does not exist; the law goes from Hertz to region III at δ = {d:.4e} m",
                self.source
            )],
            Degenerate::HertzOnly => vec![format!(
                "{}: δp ≤ δy for this pair (q = E*/σy = {q:.3}) and region III never crosses Hertz: the law stays elastic (Hertz)",
                self.source
            )],
        }
    }

    /// Runs the scene.
    pub fn run(&self) -> Result<RunOutput> {
        let law = self.contact_law();
        let law = law.as_ref();
        match &self.params {
            SceneParams::Quasistatic {
                max_displacement_m,
                points,
                strain_rate_per_s,
            } => {
                let s =
                    solver::loading_curve(law, *max_displacement_m, *points, *strain_rate_per_s);
                let summary = vec![item("max_force", *s.force_n.last().unwrap_or(&0.0), "N")];
                Ok(RunOutput::contact_only(s, summary))
            }
            SceneParams::ConstantRate {
                strain_rate_per_s,
                max_displacement_m,
                points,
            } => {
                let s = solver::constant_rate(
                    law,
                    &self.pair,
                    *strain_rate_per_s,
                    *max_displacement_m,
                    *points,
                );
                let summary = vec![
                    item("max_force", *s.force_n.last().unwrap_or(&0.0), "N"),
                    item(
                        "approach_speed",
                        strain_rate_per_s
                            * (self.pair.sphere1.radius_m + self.pair.sphere2.radius_m),
                        "m/s",
                    ),
                ];
                Ok(RunOutput::contact_only(s, summary))
            }
            SceneParams::Collision(setup) => {
                let r = solver::collision(law, &self.pair, setup)?;
                let p = self.pair.contact_properties();
                let tc = solver::hertz_impact_duration(
                    self.pair.reduced_mass_kg(),
                    p.e_star_pa,
                    p.radius_m,
                    setup.velocity1_m_s - setup.velocity2_m_s,
                );
                let summary = vec![
                    item("restitution", r.restitution, "1"),
                    item("contact_time", r.contact_time_s, "s"),
                    item("hertz_contact_time", tc, "s"),
                    item("peak_force", r.peak_force_n, "N"),
                    item("max_approach", r.max_approach_m, "m"),
                    item("residual_approach", r.residual_approach_m, "m"),
                    item("kinetic_energy_before", r.kinetic_energy_before_j, "J"),
                    item("kinetic_energy_after", r.kinetic_energy_after_j, "J"),
                    item("energy_dissipated", r.dissipated_j, "J"),
                    item("time_step", setup.dt_s, "s"),
                ];
                Ok(RunOutput::contact_only(r.series, summary))
            }
            SceneParams::Pulse {
                apparatus,
                pressure_pa,
                options,
            } => run_pulse(apparatus, *pressure_pa, options),
            SceneParams::ForceDriven {
                setup,
                measured_displacement_m,
            } => {
                let r = solver::force_driven(law, &self.pair, setup)?;
                let mut summary = force_driven_summary(
                    &r.series,
                    &setup.drive,
                    measured_displacement_m.as_deref(),
                );
                summary.push(item("time_step", setup.dt_s, "s"));
                summary.push(item("energy_radiated", r.energy.radiated_j, "J"));
                summary.push(item("external_work", r.energy.external_work_j, "J"));
                summary.push(item("contact_work", r.energy.contact_work_j, "J"));
                summary.push(item("kinetic_energy_end", r.kinetic_energy_j, "J"));
                Ok(RunOutput::contact_only(r.series, summary))
            }
        }
    }
}

/// Comparison of a force-driven run with the measured displacement (paper Fig. 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fig4Comparison {
    /// Peak contact force of the model, N.
    pub model_peak_force_n: f64,
    /// Model approach at its peak force, m.
    pub model_displacement_at_peak_m: f64,
    /// Peak measured force, N.
    pub measured_peak_force_n: f64,
    /// Measured approach at the peak measured force, m.
    pub measured_displacement_at_peak_m: f64,
    /// Measured approach at t = 0 (the reduction's offset; the model starts at δ = 0), m.
    pub measured_initial_displacement_m: f64,
}

impl Fig4Comparison {
    /// Relative error of the model's displacement at peak force against the measured one,
    /// both counted from t = 0 (the measured offset δ(0) removed).
    pub fn relative_error(&self) -> f64 {
        let measured = self.measured_displacement_at_peak_m - self.measured_initial_displacement_m;
        (self.model_displacement_at_peak_m - measured) / measured
    }
}

/// Compares a force-driven series with the measured displacement sampled at the drive's times.
pub fn compare_fig4(
    series: &ContactSeries,
    drive: &ForceHistory,
    measured_displacement_m: &[f64],
) -> Fig4Comparison {
    let k = series.peak_index();
    let j = solver::argmax(&drive.force_n);
    Fig4Comparison {
        model_peak_force_n: series.force_n[k],
        model_displacement_at_peak_m: series.displacement_m[k],
        measured_peak_force_n: drive.force_n[j],
        measured_displacement_at_peak_m: measured_displacement_m[j],
        measured_initial_displacement_m: measured_displacement_m[0],
    }
}

fn force_driven_summary(
    series: &ContactSeries,
    drive: &ForceHistory,
    measured: Option<&[f64]>,
) -> Vec<SummaryItem> {
    let k = series.peak_index();
    let mut out = vec![
        item("peak_force", series.force_n[k], "N"),
        item("displacement_at_peak_force", series.displacement_m[k], "m"),
        item(
            "time_of_peak_force",
            series.time_s.as_ref().map(|t| t[k]).unwrap_or(0.0),
            "s",
        ),
        item(
            "max_displacement",
            series.displacement_m.iter().cloned().fold(0.0, f64::max),
            "m",
        ),
    ];
    if let Some(d) = measured {
        let c = compare_fig4(series, drive, d);
        out.push(item("measured_peak_force", c.measured_peak_force_n, "N"));
        out.push(item(
            "measured_displacement_at_peak_force",
            c.measured_displacement_at_peak_m,
            "m",
        ));
        out.push(item(
            "measured_initial_displacement",
            c.measured_initial_displacement_m,
            "m",
        ));
        out.push(item(
            "displacement_at_peak_relative_error",
            c.relative_error(),
            "1",
        ));
    }
    out
}

/// Runs a `pulse` scene: simulates the chain, digitises every gauge, and summarises each pulse.
fn run_pulse(apparatus: &Apparatus, pressure_pa: f64, options: &PulseOptions) -> Result<RunOutput> {
    let chain = apparatus.pulse_chain(options);
    let r = crate::solver::pulse::simulate_chain(&chain)?;
    let e = apparatus.material.youngs_modulus_pa;
    let mut summary = vec![
        item("pressure", pressure_pa, "Pa"),
        item("striker_velocity", options.striker_velocity_m_s, "m/s"),
        item("striker_energy", r.striker_energy_j, "J"),
        item(
            "striker_final_velocity",
            r.striker_final_velocity_m_s,
            "m/s",
        ),
        item("time_step", chain.dt_s, "s"),
    ];
    let mut gauges = Vec::new();
    let mut time = None;
    for (k, probe) in chain.gauges.iter().enumerate() {
        let ch = apparatus
            .gauges
            .channel(&probe.name)
            .expect("probes come from the gauge set-up");
        let n = (options.end_time_s * ch.digitiser.sample_rate_hz).floor() as usize;
        let (t, v) = ch.record(&r.time_s, &r.strain[k], 0.0, n);
        let strain = resample(&r.time_s, &r.strain[k], &t);
        if let Some(m) = crate::gauge::pulse_metrics(&t, &strain, true) {
            summary.push(item(
                &format!("{}_peak_stress", probe.name),
                -e * m.peak,
                "Pa",
            ));
            summary.push(item(
                &format!("{}_rise_10_90", probe.name),
                m.rise_10_90_s,
                "s",
            ));
            summary.push(item(
                &format!("{}_duration_10", probe.name),
                m.duration_10_s,
                "s",
            ));
            summary.push(item(&format!("{}_start_10", probe.name), m.start_10_s, "s"));
        }
        gauges.push(crate::io::GaugeTrace {
            name: probe.name.clone(),
            strain,
            voltage_v: v,
        });
        time = Some(t);
    }
    let t = time.unwrap_or_else(|| r.time_s.clone());
    let striker = vec![r.striker_energy_j; t.len()];
    let bars = resample(&r.time_s, &r.bar_energy_j, &t);
    let absorbed = resample(&r.time_s, &r.absorbed_energy_j, &t);
    let shaper = resample(&r.time_s, &r.shaper_energy_j, &t);
    let contact_work = resample(&r.time_s, &r.contact_energy_j, &t);
    let total: Vec<f64> = (0..t.len())
        .map(|i| bars[i] + absorbed[i] + shaper[i] + contact_work[i])
        .collect();
    if let Some(c) = &r.contact {
        let k = c.peak_index();
        summary.push(item("peak_contact_force", c.force_n[k], "N"));
        summary.push(item(
            "displacement_at_peak_contact_force",
            c.displacement_m[k],
            "m",
        ));
        summary.push(item(
            "time_of_peak_contact_force",
            c.time_s.as_ref().map(|t| t[k]).unwrap_or(0.0),
            "s",
        ));
        summary.push(item(
            "max_displacement",
            c.displacement_m.iter().cloned().fold(0.0, f64::max),
            "m",
        ));
        summary.push(item(
            "contact_work_end",
            *r.contact_energy_j.last().unwrap_or(&0.0),
            "J",
        ));
    }
    let worst = total
        .iter()
        .map(|x| (x - r.striker_energy_j).abs())
        .fold(0.0, f64::max)
        / r.striker_energy_j;
    summary.push(item("energy_balance_max_relative_error", worst, "1"));
    let mut energy = vec![
        ("striker".into(), striker),
        ("bars".into(), bars),
        ("absorbed".into(), absorbed),
        ("shaper".into(), shaper),
    ];
    if r.contact.is_some() {
        energy.push(("contact".into(), contact_work));
    }
    energy.push(("total".into(), total));
    let mut warnings = Vec::new();
    let reduction = match &options.specimen {
        Some(spec) => match reduce_simulated_records(apparatus, options, spec, &t, &gauges) {
            Ok(red) => {
                summary.extend(reduced_summary(&red));
                warnings.extend(red.warnings.iter().map(|w| format!("reduction: {w}")));
                Some(red)
            }
            Err(e) => {
                warnings.push(format!("reduction of the simulated records failed: {e}"));
                None
            }
        },
        None => None,
    };
    Ok(RunOutput {
        contact: r.contact,
        time_s: Some(t),
        gauges,
        energy,
        bars: r.snapshots,
        summary,
        reduction,
        warnings,
    })
}

/// Moving-average width applied to simulated records before their reduction, s: 2 µs (20
/// samples at 10 MHz) cuts the digitiser noise √20-fold and changes a pulse rising in ≥ 40 µs by
/// < 0.02 % of its peak.
pub const SIMULATED_RECORD_SMOOTHING_S: f64 = 2e-6;

/// The lab's reduction of a simulated test: the digitised voltages read back through each
/// channel's bridge (as the lab gets them), dispersion correction only when the bars disperse.
fn reduce_simulated_records(
    apparatus: &Apparatus,
    options: &PulseOptions,
    spec: &crate::apparatus::SpecimenSetup,
    time_s: &[f64],
    gauges: &[crate::io::GaugeTrace],
) -> Result<crate::reduce::Reduction> {
    let strain = |name: &str| -> Result<Vec<f64>> {
        let trace = gauges.iter().find(|g| g.name == name);
        let channel = apparatus.gauges.channel(name);
        match (trace, channel) {
            (Some(g), Some(ch)) => Ok(ch.strains_from_voltages(&g.voltage_v)),
            _ => Err(Error::Input {
                file: apparatus.source.clone(),
                key: "gauges".into(),
                problem: format!("no `{name}` gauge channel to reduce"),
                allowed: "channels named incident and transmission".into(),
            }),
        }
    };
    let input = crate::reduce::ReductionInput {
        time_s: time_s.to_vec(),
        incident_strain: strain("incident")?,
        transmission_strain: strain("transmission")?,
    };
    let reduction_options = crate::reduce::ReductionOptions {
        dispersion_correction: options.dispersion != Dispersion::None,
        specimen_radii_m: Some((spec.pair.sphere1.radius_m, spec.pair.sphere2.radius_m)),
        smoothing_window_s: SIMULATED_RECORD_SMOOTHING_S,
        ..Default::default()
    };
    crate::reduce::reduce(
        &input,
        &crate::reduce::ReductionSetup::from_apparatus(apparatus)?,
        &reduction_options,
    )
}

/// Summary items of the reduction of a simulated test (`reduced_*`).
fn reduced_summary(r: &crate::reduce::Reduction) -> Vec<SummaryItem> {
    let mut v = vec![
        item("reduced_peak_back_force", r.peak_back_force_n, "N"),
        item("reduced_peak_front_force", r.peak_front_force_n, "N"),
        item(
            "reduced_displacement_at_peak_force",
            r.displacement_at_peak_force_m,
            "m",
        ),
        item(
            "reduced_equilibrium_ratio_at_peak",
            r.equilibrium_ratio_at_peak,
            "1",
        ),
    ];
    if let Some(rate) = &r.strain_rate_per_s {
        v.push(item(
            "reduced_peak_strain_rate",
            rate.iter().copied().fold(0.0, f64::max),
            "1/s",
        ));
    }
    v
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

/// Linear interpolation of (t, y) at the times `at` (end values held outside).
pub fn resample(t: &[f64], y: &[f64], at: &[f64]) -> Vec<f64> {
    let mut j = 0usize;
    at.iter()
        .map(|&x| {
            if x <= t[0] {
                return y[0];
            }
            if x >= t[t.len() - 1] {
                return y[y.len() - 1];
            }
            while t[j + 1] <= x {
                j += 1;
            }
            let w = (x - t[j]) / (t[j + 1] - t[j]);
            y[j] + w * (y[j + 1] - y[j])
        })
        .collect()
}
