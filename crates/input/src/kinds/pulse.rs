//! `kind = "pulse"`: striker, shaper and bars without a specimen (the gauge signals of the bar
//! set-up). Also the parser of [`super::shpb`], which is the same scene with spheres between the
//! bars: [`parse_bars`] with `is_test`.

use super::{Key, LawKindToml, Parsed, Region2Toml, SceneKind, UnloadingToml};
use crate::error::{Error, Result, Validator};
use crate::setup::{ApparatusFile, ShaperOverride};
use crate::specimen::SpecimenSpec;
use crate::toml_file::parse_as;
use serde::Deserialize;
use shpb_core::apparatus::{Apparatus, IncidentEnd, PulseOptions};
use shpb_core::bar::Dispersion;
use shpb_core::contact::{LawKind, LawSpec, Region2Form, Unloading};
use shpb_core::error::format_si;
use shpb_core::fidelity::Fidelity;
use shpb_core::loading::Loading;
use shpb_core::scene::SceneParams;
use shpb_core::specimen::{CYLINDER_MIN_CELLS, Specimen, SphereSpecimen};
use std::path::Path;

/// The registry entry.
pub(super) const KIND: SceneKind = SceneKind {
    name: "pulse",
    help: "striker, shaper and bars without specimen: the gauge signals of the bar set-up",
    keys: &[
        BARS,
        PRESSURE,
        STRIKER_VELOCITY,
        SHAPER,
        CELL_SIZE,
        Key {
            key: "incident_end",
            unit: "",
            default: "transmission",
            meaning: "what the incident bar's end meets: transmission (the transmission bar pressed against it), free or absorbing",
        },
        DISPERSION,
        END_TIME,
        GAUGE_LENGTH,
    ],
    example: "kind = \"pulse\"\nbars = \"authors\"\npressure = \"10psi\"\n",
    example_dir: None,
    parse,
};

/// `bars = "..."` (pulse and shpb).
pub(super) const BARS: Key = Key {
    key: "bars",
    unit: "",
    default: "required",
    meaning: "the bar set-up: a built-in one (authors, authors-20cm-striker) or a set-up .toml file, relative to the scene file",
};

/// `pressure = "..."` (pulse and shpb).
pub(super) const PRESSURE: Key = Key {
    key: "pressure",
    unit: "psi, Pa, kPa, MPa or bar",
    default: "required, unless striker_velocity_m_s (shpb: or [incident_record])",
    meaning: "gas-gun gauge pressure with its unit, e.g. \"10psi\" (within the set-up gun's range)",
};

/// `striker_velocity_m_s` (pulse and shpb).
pub(super) const STRIKER_VELOCITY: Key = Key {
    key: "striker_velocity_m_s",
    unit: "m/s",
    default: "none: the gun gives it from pressure",
    meaning: "the striker's impact velocity, given instead of pressure (the set-up's gun is not used), greater than 0, at most 100 m/s",
};

/// `[shaper]` (pulse and shpb).
pub(super) const SHAPER: Key = Key {
    key: "shaper",
    unit: "",
    default: "the set-up's shaper",
    meaning: "overrides of the set-up's copper pulse shaper: enabled (false: none), model (frew, crushed-disc, exponential), diameter_m, thickness_m, sigma0_pa, n, m (frew), youngs_modulus_pa, friction, face_compliance_factor (crushed-disc), stiffening_length_m, onset_force_n (exponential; with crushed-disc: its cushion)",
};

/// `cell_size_m` (pulse and shpb).
pub(super) const CELL_SIZE: Key = Key {
    key: "cell_size_m",
    unit: "m",
    default: "fidelity: 4e-3, 1e-3, 1e-3 (reference falls back to 1.25e-4)",
    meaning: "cell size of the bar grid (Δt = Δx/c0, Courant 1), 1e-5 to 0.05",
};

/// `dispersion` (pulse and shpb).
pub(super) const DISPERSION: Key = Key {
    key: "dispersion",
    unit: "",
    default: "fidelity: none, none, pochhammer-chree (reference falls back to love-rod)",
    meaning: "bar theory: none (elementary), love-rod (lateral inertia, finite differences), rayleigh-love or pochhammer-chree (that relation carried by the travelling waves of a delay line: uniform bars a whole number of cells long)",
};

/// The fewest recorder samples and time steps a `pulse` or `shpb` run may hold (the reduction
/// needs 16 samples of a record).
pub const MIN_RUN_SAMPLES: f64 = 16.0;

/// `end_time_s` (pulse and shpb).
pub(super) const END_TIME: Key = Key {
    key: "end_time_s",
    unit: "s",
    default: "until the incident pulse has passed its gauge, reflected and passed it again",
    meaning: "end of the run: greater than 0, at most 0.1 s",
};

/// `gauge_length_m` (pulse and shpb).
pub(super) const GAUGE_LENGTH: Key = Key {
    key: "gauge_length_m",
    unit: "m",
    default: "2e-3",
    meaning: "grid length of the strain gauges (they read the mean strain over it), 0 to 0.05",
};

/// `loading` (shpb only): compression or tension (docs/physics.md §6.13).
pub(super) const LOADING: Key = Key {
    key: "loading",
    unit: "",
    default: "compression",
    meaning: "compression (a pressure bar) or tension (a tension bar, SHTB: the striker tube on the incident bar's flange, a tensile incident pulse, the specimen bonded to both bars; a cylinder specimen only, without friction or [incident_record]; docs/physics.md §6.13)",
};

/// `[incident_record]` (shpb only).
pub(super) const INCIDENT_RECORD: Key = Key {
    key: "incident_record",
    unit: "",
    default: "none: the gun, striker and shaper make the incident pulse",
    meaning: "a measured incident wave drives the incident bar instead (docs/physics.md §6.10): file = a gauge record (time_s, incident_V, transmission_V, read through the set-up's incident gauge channel) relative to the scene file; layout = a record layout .toml for another file format, as `shpb reduce --layout`; baseline_samples (default 900). Exclusive with pressure and striker_velocity_m_s; bars: none or pochhammer-chree (which takes the recorded dispersion back)",
};

/// `smooth_s` (shpb only).
pub(super) const SMOOTH: Key = Key {
    key: "smooth_s",
    unit: "s",
    default: "none: the default filter of `shpb reduce` (Butterworth at the bars' band)",
    meaning: "width of a moving average applied to the simulated gauge records before the lab's reduction instead of the default filter, as `shpb reduce --smooth` applies it to real ones; 0 (no filter) to 1e-4",
};

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
    #[serde(default, with = "UnloadingToml")]
    unloading: Unloading,
    bars: String,
    pressure: Option<String>,
    striker_velocity_m_s: Option<f64>,
    incident_record: Option<IncidentRecordFile>,
    shaper: Option<ShaperOverride>,
    cell_size_m: Option<f64>,
    #[serde(default = "default_incident_end")]
    incident_end: String,
    dispersion: Option<String>,
    end_time_s: Option<f64>,
    #[serde(default = "default_gauge_length")]
    gauge_length_m: f64,
    smooth_s: Option<f64>,
    loading: Option<String>,
}

/// `[incident_record]`: a gauge record whose incident wave drives the incident bar.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IncidentRecordFile {
    file: String,
    layout: Option<String>,
    baseline_samples: Option<usize>,
}

fn default_gauge_length() -> f64 {
    2e-3
}

fn default_incident_end() -> String {
    "transmission".into()
}

fn parse(
    text: &str,
    file: &str,
    base_dir: &Path,
    fidelity: Fidelity,
    v: &Validator,
) -> Result<Parsed> {
    parse_bars(text, file, base_dir, fidelity, v, false)
}

/// The parser of `pulse` (`is_test` false: no specimen allowed, `incident_end` chosen) and of
/// `shpb` (`is_test` true: a specimen required, the incident bar ends at it, x–t snapshots).
pub(super) fn parse_bars(
    text: &str,
    file: &str,
    base_dir: &Path,
    fidelity: Fidelity,
    v: &Validator,
    is_test: bool,
) -> Result<Parsed> {
    let sv = v.table("specimen");
    let f: PulseFile = parse_as(text, file)?;
    let specimen = match (&f.specimen, is_test) {
        (Some(spec), true) if spec.is_cylinder(&sv)? => Some(Specimen::Cylinder(
            crate::cylinder::build(spec, base_dir, &sv)?,
        )),
        (Some(spec), true) => Some(Specimen::Spheres(SphereSpecimen {
            chain: spec.spheres_only().build_chain(base_dir, &sv)?,
            law: LawSpec {
                kind: f.law,
                region2: f.region2,
                unloading: f.unloading,
            },
            seating: spec.build_seating(&sv)?,
        })),
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
    let cylinder = specimen.as_ref().and_then(Specimen::cylinder).cloned();
    let set_up = base_dir.join(&f.bars);
    if crate::builtin::setup(&f.bars).is_none() && !crate::files::is_file(&set_up) {
        return Err(v.error(
            "bars",
            format!(
                "cannot read {}: {}",
                set_up.display(),
                crate::files::not_a_file(&set_up)
            ),
            format!(
                "a built-in set-up ({}) or a bar set-up .toml file, relative to the scene file",
                crate::builtin::setup_names()
            ),
        ));
    }
    let apparatus = Apparatus::resolve(&f.bars, base_dir)?;
    // The incident wave: the gun at a pressure, or a measured record (docs/physics.md §6.10).
    // Exactly one of pressure, striker_velocity_m_s and [incident_record].
    let given: Vec<&str> = [
        ("pressure", f.pressure.is_some()),
        ("striker_velocity_m_s", f.striker_velocity_m_s.is_some()),
        ("incident_record", f.incident_record.is_some()),
    ]
    .into_iter()
    .filter_map(|(k, g)| g.then_some(k))
    .collect();
    let one_of = if is_test {
        "exactly one of pressure (the gun fires the striker), striker_velocity_m_s (the striker's impact velocity) or [incident_record] (a measured incident wave drives the bar)"
    } else {
        "exactly one of pressure (the gun fires the striker) or striker_velocity_m_s (the striker's impact velocity)"
    };
    if given.len() > 1 {
        return Err(v.error(given[1], format!("given with {}", given[0]), one_of));
    }
    let (pressure_pa, velocity, drive) =
        match (&f.pressure, f.striker_velocity_m_s, &f.incident_record) {
            (Some(p), _, _) => {
                let pressure_pa = crate::units::pressure_from_text(p, v, "pressure")?;
                let velocity = apparatus
                    .striker_velocity_m_s(pressure_pa)
                    .map_err(v.core("pressure"))?;
                (pressure_pa, velocity, None)
            }
            // No gun: no pressure (NaN, as a record-driven run has none).
            (None, Some(speed), _) => (
                f64::NAN,
                v.positive("striker_velocity_m_s", speed, 100.0, "m/s")?,
                None,
            ),
            (None, None, Some(r)) if is_test => (
                f64::NAN,
                0.0,
                Some(incident_drive(r, &apparatus, base_dir, v)?),
            ),
            (None, None, Some(_)) => {
                return Err(v.error(
                "incident_record",
                "given in a pulse scene, whose incident pulse is the gun's",
                "[incident_record] only in shpb scenes (or pressure or striker_velocity_m_s here)",
            ));
            }
            (None, None, None) => {
                return Err(v.error("pressure", "missing (and no striker_velocity_m_s)", one_of));
            }
        };
    let face_modulus_pa =
        apparatus.material.youngs_modulus_pa / (1.0 - apparatus.material.poisson_ratio.powi(2));
    if drive.is_some() && f.shaper.is_some() {
        return Err(v.error(
            "shaper",
            "given with [incident_record], which replaces the gun, striker and shaper",
            "no [shaper] table in a test driven by a record",
        ));
    }
    let loading = parse_loading(&f, specimen.as_ref(), v, is_test)?;
    let shaper = f.shaper.unwrap_or_default().apply(
        apparatus.shaper,
        face_modulus_pa,
        &v.table("shaper"),
    )?;
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
    // A preset's knobs, or its fallback where its delay lines cannot run (no dispersion chosen in
    // the scene, and bars no cell of at most the preset's divides). Inserts stay elementary
    // beside dispersive delay lines and a cylinder is elementary (docs/physics.md §6.2.1, §6.9),
    // so neither needs the fallback.
    let bar_lengths_m = [
        apparatus.incident.length_m,
        apparatus.striker.length_m,
        apparatus.transmission.length_m,
    ];
    let knobs = match fidelity.fallback_bar_knobs() {
        Some(fallback) if f.dispersion.is_none() => {
            let preset = fidelity.bar_knobs();
            let cell = f.cell_size_m.unwrap_or(preset.cell_size_m);
            let whole = shpb_core::bar::delay_line_cell_m(&bar_lengths_m, cell)
                .is_some_and(|c| f.cell_size_m.is_none() || (c - cell).abs() <= 1e-9 * cell);
            if whole { preset } else { fallback }
        }
        _ => fidelity.bar_knobs(),
    };
    let dispersion = match f.dispersion.as_deref() {
        // A recorded wave is already dispersed over its path from the impact end to the gauge,
        // which only the exact first mode can take back (docs/physics.md §6.10): a drive runs on
        // those bars or on elementary ones, whatever the preset's fallback.
        None if drive.is_some() => match knobs.dispersion {
            Dispersion::PochhammerChree => Dispersion::PochhammerChree,
            _ => Dispersion::None,
        },
        None => knobs.dispersion,
        Some(name) => Dispersion::parse(name).ok_or_else(|| {
            v.error(
                "dispersion",
                format!("unknown model `{name}`"),
                Dispersion::ALL.map(Dispersion::name).join(", "),
            )
        })?,
    };
    if drive.is_some() && !matches!(dispersion, Dispersion::None | Dispersion::PochhammerChree) {
        return Err(v.error(
            "dispersion",
            format!(
                "`{}` with [incident_record]: the recorded wave is already dispersed over its path from the impact end to the gauge, and only the exact first mode can take that back",
                dispersion.name()
            ),
            "none or pochhammer-chree (or leave dispersion out)",
        ));
    }
    let c0 = apparatus.material.wave_speed_m_s();
    // A cylinder gets at least CYLINDER_MIN_CELLS cells (docs/physics.md §6.9): the default
    // cell is refined to it, an explicit one that cannot is refused.
    let cylinder_cell = cylinder
        .as_ref()
        .map(|c| c.largest_bar_cell_m(c0, CYLINDER_MIN_CELLS));
    let default_cell = cylinder_cell.map_or(knobs.cell_size_m, |c| c.min(knobs.cell_size_m));
    // Dispersion on the travelling waves needs bars of whole cells (docs/physics.md §6.2.1):
    // the preset's cell is refined to the largest that divides every bar (10/3 mm for the
    // authors' bars at `fast`); an explicit cell that does not is refused by the bars.
    let default_cell = match dispersion.transit_model() {
        Some(_) => {
            shpb_core::bar::delay_line_cell_m(&bar_lengths_m, default_cell).unwrap_or(default_cell)
        }
        None => default_cell,
    };
    let cell = v.in_range(
        "cell_size_m",
        f.cell_size_m.unwrap_or(default_cell),
        1e-5,
        0.05,
        "m",
    )?;
    // Issue 42: a bar shorter than one cell was reported as a time step over the stability
    // limit of `cell_size_m`; it is the set-up's bar length (or the cell) that is wrong.
    for (table, bar) in [
        ("incident", &apparatus.incident),
        ("transmission", &apparatus.transmission),
        ("striker", &apparatus.striker),
    ] {
        // (A record-driven scene has no striker on its grid.)
        if bar.length_m < cell && !(table == "striker" && drive.is_some()) {
            return Err(Error::Input {
                file: apparatus.source.clone(),
                key: format!("{table}.length_m"),
                problem: format!(
                    "the {table} bar, {}, is shorter than one cell of the bars' grid ({} in \
                     {file}{})",
                    format_si(bar.length_m, "m"),
                    format_si(cell, "m"),
                    if f.cell_size_m.is_some() {
                        ": its cell_size_m"
                    } else {
                        ": its fidelity's cell size"
                    },
                ),
                allowed: format!(
                    "a bar at least one cell long (at least {}), or a cell_size_m in {file} no \
                     longer than the bar (1e-5 m at least)",
                    format_si(cell, "m"),
                ),
            });
        }
    }
    if let (Some(c), Some(largest)) = (&cylinder, cylinder_cell)
        && c.cells_at(cell / c0) < CYLINDER_MIN_CELLS
    {
        return Err(v.error(
            "cell_size_m",
            format!(
                "{cell} m gives the cylindrical specimen {} cell(s)",
                c.cells_at(cell / c0)
            ),
            format!(
                "1e-5 to {largest:.4e} m (at least {CYLINDER_MIN_CELLS} cells in the specimen, or leave cell_size_m out)"
            ),
        ));
    }
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
    // A drive starts with the record's own lead before its incident wave's foot.
    let default_end = default_end + drive.as_ref().map_or(0.0, |d| d.foot_s);
    // An exponential shaper closes a while before its force rises (docs/physics.md §6.5.3).
    let default_end =
        default_end + shaper.map_or(0.0, |s| apparatus.shaper_onset_delay_s(&s, velocity));
    let end_time_s = match f.end_time_s {
        Some(e) => v.positive("end_time_s", e, 0.1, "s")?,
        None => default_end,
    };
    let gauge_length_m = v.in_range("gauge_length_m", f.gauge_length_m, 0.0, 0.05, "m")?;
    let reduction_smoothing_s = match (f.smooth_s, is_test) {
        (None, _) => shpb_core::reduce::DEFAULT_SMOOTHING_S,
        (Some(w), true) => v.in_range("smooth_s", w, 0.0, 1e-4, "s")?,
        (Some(_), false) => {
            return Err(v.error(
                "smooth_s",
                "given in a pulse scene, which has no reduction",
                "smooth_s only in shpb scenes",
            ));
        }
    };
    let options = PulseOptions {
        striker_velocity_m_s: velocity,
        shaper,
        end,
        cell_size_m: cell,
        dispersion,
        end_time_s,
        gauge_length_m,
        snapshot_interval_s: is_test.then_some(knobs.snapshot_interval_s),
        reduction_smoothing_s,
        incident_drive: drive,
        loading,
        // `smooth_s` is the moving average of `shpb reduce --smooth` (0: no filter).
        reduction_filter: match f.smooth_s {
            Some(_) => shpb_core::reduce::Filter::MovingAverage { width_s: None },
            None => shpb_core::reduce::Filter::DEFAULT,
        },
    };
    // Refuse a run too large for this machine before its bars are built (below), then a grid
    // the bars cannot run (time step over the stability limit) now, not mid-run.
    crate::resources::check_estimate(
        file,
        if is_test { "shpb" } else { "pulse" },
        &shpb_core::estimate::bar_run(&apparatus, &options, specimen.as_ref()),
        &crate::resources::Limits::of_machine()?,
    )?;
    let chain = apparatus.pulse_chain(&options, specimen.as_ref());
    for spec in &chain.bodies {
        shpb_core::solver::Body::new(spec, cell / c0).map_err(v.core("cell_size_m"))?;
    }
    // Issue 42: an end time shorter than a few samples ran to NaN summaries with exit 0.
    let rate = apparatus.gauges.max_sample_rate_hz();
    let shortest = (MIN_RUN_SAMPLES / rate).max(MIN_RUN_SAMPLES * chain.dt_s);
    if end_time_s < shortest {
        return Err(v.error(
            "end_time_s",
            format!(
                "{} holds fewer than {MIN_RUN_SAMPLES} samples of the recorders ({}) or time \
                 steps ({}), too few for any result",
                format_si(end_time_s, "s"),
                format_si(rate, "Hz"),
                format_si(chain.dt_s, "s"),
            ),
            format!("at least {} (and at most 0.1 s)", format_si(shortest, "s")),
        ));
    }
    Ok((
        specimen,
        SceneParams::Pulse {
            apparatus: Box::new(apparatus),
            pressure_pa,
            options: Box::new(options),
        },
    ))
}

/// The scene's `loading` (docs/physics.md §6.13): compression unless `tension` is given; a
/// tension test needs a cylinder without end friction, loaded by the striker (not a record).
fn parse_loading(
    f: &PulseFile,
    specimen: Option<&Specimen>,
    v: &Validator,
    is_test: bool,
) -> Result<Loading> {
    let allowed = Loading::ALL.map(Loading::name).join(", ");
    let loading = match f.loading.as_deref() {
        None => return Ok(Loading::Compression),
        Some(name) => Loading::parse(name)
            .ok_or_else(|| v.error("loading", format!("unknown loading `{name}`"), &allowed))?,
    };
    if !is_test {
        return Err(v.error(
            "loading",
            "given in a pulse scene, which has no specimen to load",
            "loading only in shpb scenes",
        ));
    }
    if !loading.is_tension() {
        return Ok(loading);
    }
    match specimen {
        Some(Specimen::Cylinder(c)) if c.friction.is_some() => Err(v.error(
            "loading",
            "tension with specimen.friction_coefficient: a tension specimen is threaded or bonded to the bars, whose faces do not slide",
            "loading = \"tension\" without friction_coefficient (or loading = \"compression\")",
        )),
        Some(Specimen::Cylinder(_)) if f.incident_record.is_some() => Err(v.error(
            "loading",
            "tension with [incident_record]: a recorded incident wave drives a compression test",
            "loading = \"tension\" with pressure or striker_velocity_m_s",
        )),
        Some(Specimen::Cylinder(_)) => Ok(loading),
        _ => Err(v.error(
            "loading",
            "tension with spheres: spheres in contact carry no tension",
            "loading = \"tension\" with a cylinder specimen (shape = \"cylinder\"), or loading = \"compression\"",
        )),
    }
}

/// Checks of the key documentation shared by pulse and shpb.
/// Reads `[incident_record]`: the record (owning its file errors), its incident channel through
/// the set-up's gauge file with the first `baseline_samples` samples' mean removed, and the
/// incident wave cut before its reflection ([`IncidentDrive::from_incident_gauge`]).
fn incident_drive(
    r: &IncidentRecordFile,
    apparatus: &Apparatus,
    base_dir: &Path,
    v: &Validator,
) -> Result<shpb_core::apparatus::IncidentDrive> {
    let rv = v.table("incident_record");
    let path = base_dir.join(&r.file);
    if !crate::files::is_file(&path) {
        return Err(rv.error(
            "file",
            format!(
                "cannot read {}: {}",
                path.display(),
                crate::files::not_a_file(&path)
            ),
            "a gauge record (time_s, incident_V, transmission_V) relative to the scene file",
        ));
    }
    // The record as bridge voltages (through the set-up's bridges) or, through a layout, as
    // voltages or bar strains.
    let mut record = match &r.layout {
        None => crate::sheet::read_record(&path, None)?,
        Some(l) => {
            let layout_path = base_dir.join(l);
            if !crate::files::is_file(&layout_path) {
                return Err(rv.error(
                    "layout",
                    format!(
                        "cannot read {}: {}",
                        layout_path.display(),
                        crate::files::not_a_file(&layout_path)
                    ),
                    "a record layout .toml (README, *Record layouts*) relative to the scene file",
                ));
            }
            let layout = crate::layout::RecordLayout::from_file(&layout_path)?;
            crate::sheet::read_record(&path, Some(&layout))?
        }
    };
    let samples = record.samples();
    let baseline = match r.baseline_samples {
        Some(n) => rv.in_range(
            "baseline_samples",
            n as f64,
            1.0,
            (samples / 2).max(1) as f64,
            "samples",
        )? as usize,
        None => shpb_core::reduce::ReductionOptions::default()
            .baseline_samples
            .min(samples / 2),
    };
    // Voltages lose their baseline on the way to strains; strains as read lose it here (no
    // reduction follows to take it).
    if let crate::layout::LayoutRecord::Strains(s) = &mut record {
        s.incident_strain = shpb_core::gauge::remove_baseline(&s.incident_strain, baseline);
    }
    let input = record
        .into_strains(apparatus, baseline)
        .map_err(rv.core("file"))?;
    // The incident channel checked for plausibility as `shpb reduce` checks it (dead, clipped,
    // beyond the bar's elastic limit, inverted), before it drives anything.
    shpb_core::reduce::plausibility::check_channels(
        &[shpb_core::reduce::plausibility::Channel {
            name: "incident",
            time_s: &input.time_s,
            strain: &input.incident_strain,
            volts: false,
            youngs_modulus_pa: Some(apparatus.material.youngs_modulus_pa),
            baseline_samples: baseline,
            smoothing_window_s: shpb_core::reduce::DEFAULT_SMOOTHING_S,
            pulse_due_s: None,
        }],
        &path.display().to_string(),
    )?;
    shpb_core::apparatus::IncidentDrive::from_incident_gauge(
        &input.time_s,
        &input.incident_strain,
        apparatus.material.youngs_modulus_pa,
    )
    .ok_or_else(|| {
        rv.error(
            "file",
            format!(
                "{}: no compressive incident pulse in its incident channel",
                path.display()
            ),
            "a record whose incident channel holds the incident pulse",
        )
    })
}

#[cfg(test)]
pub(super) fn check_bar_key_docs() {
    let fmt = |f: Fidelity| {
        let k = f.bar_knobs();
        (format!("{:e}", k.cell_size_m), k.dispersion.name())
    };
    let (cells, dispersions): (Vec<String>, Vec<&str>) = Fidelity::ALL.map(fmt).into_iter().unzip();
    let fallback = Fidelity::Reference
        .fallback_bar_knobs()
        .expect("reference has a fallback");
    assert_eq!(
        CELL_SIZE.default,
        format!(
            "fidelity: {} (reference falls back to {:e})",
            cells.join(", "),
            fallback.cell_size_m
        )
    );
    assert_eq!(
        DISPERSION.default,
        format!(
            "fidelity: {} (reference falls back to {})",
            dispersions.join(", "),
            fallback.dispersion.name()
        )
    );
    assert_eq!(
        GAUGE_LENGTH.default,
        format!("{:e}", default_gauge_length())
    );
    for (name, _, _) in crate::builtin::SETUPS {
        assert!(BARS.meaning.contains(name), "bars doc lacks {name}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registry_entry() {
        // A pulse scene accepts but refuses `specimen`, `smooth_s`, `incident_record` and `loading`, and
        // has no use for `law`, `region2` and `unloading`.
        super::super::check_kind(
            &KIND,
            &[
                "specimen",
                "law",
                "region2",
                "unloading",
                "smooth_s",
                "incident_record",
                "loading",
            ],
        );
        check_bar_key_docs();
        let incident_end = KIND.keys.iter().find(|k| k.key == "incident_end").unwrap();
        assert_eq!(incident_end.default, default_incident_end());
    }

    #[test]
    fn example_values() {
        let (specimen, p) = super::super::parse_example(&KIND, Fidelity::Standard);
        let SceneParams::Pulse {
            pressure_pa,
            options,
            apparatus,
        } = p
        else {
            panic!("not a pulse: {p:?}")
        };
        assert_eq!(pressure_pa, 10.0 * crate::units::PSI_PA);
        assert_eq!(options.end, IncidentEnd::Transmission);
        assert_eq!(specimen, None);
        assert_eq!(options.snapshot_interval_s, None);
        assert_eq!(options.cell_size_m, 1e-3);
        assert_eq!(options.gauge_length_m, 2e-3);
        assert_eq!(options.shaper, apparatus.shaper);
    }

    /// Issue 15, item 5: the size check comes before the bars are built (a 100 m set-up at
    /// 10 µm cells is 2e7 nodes, gigabytes of grid, before a step is taken).
    #[test]
    fn a_run_too_large_is_refused_before_its_bars_are_built() {
        let dir = std::env::temp_dir().join(format!("shpb-long-bars-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let setup = crate::builtin::setup("authors")
            .unwrap()
            .replace("length_m = 1.21", "length_m = 100.0")
            .replace("length_m = 1.02", "length_m = 100.0")
            .replace("gauges = \"gauges-authors.toml\"", "gauges = \"g.toml\"");
        std::fs::write(dir.join("long.toml"), setup).unwrap();
        std::fs::write(
            dir.join("g.toml"),
            crate::builtin::gauges("gauges-authors.toml").unwrap(),
        )
        .unwrap();
        let v = Validator::new("p.toml");
        let text = "kind = \"pulse\"\nbars = \"long.toml\"\npressure = \"10psi\"\ncell_size_m = 1e-5\nend_time_s = 0.1\n";
        // The kind's own parser refuses it: `from_toml`'s check of the finished scene comes later.
        let e = parse(text, "p.toml", &dir, Fidelity::Standard, &v).unwrap_err();
        assert!(matches!(e, crate::Error::TooLarge { .. }), "{e}");
        assert!(
            e.to_string().starts_with(
                "p.toml: the run cannot finish on this machine: it needs 4.87e7 time steps (9.74e14 node updates)"
            ),
            "{e}"
        );
    }

    #[test]
    fn a_specimen_is_refused() {
        let v = Validator::new("p.toml");
        let text = format!("{}specimen = {{ pair = \"ss440c\" }}\n", KIND.example);
        let e = parse(&text, "p.toml", Path::new("."), Fidelity::Standard, &v).unwrap_err();
        assert_eq!(
            e.to_string(),
            "p.toml: `specimen`: a pulse scene has no specimen; allowed: kind = \"shpb\" for a test with spheres"
        );
    }
}
