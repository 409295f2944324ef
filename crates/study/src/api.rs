//! The commands of `shpb` as library calls, without printing and without output-path checks:
//! what the command line (`crates/cli/src/cmd/*.rs`) and the Python package (`crates/python`)
//! share, so that both load, run, reduce and sweep a scene through the same code.

use crate::sweep::{Axis, RunSummary};
use shpb_core::apparatus::Apparatus;
use shpb_core::contact::LawKind;
use shpb_core::fidelity::Fidelity;
use shpb_core::reduce::{
    ReducedSpecimen, Reduction, ReductionInput, ReductionOptions, ReductionSetup,
};
use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_core::solver::ContactSeries;
use shpb_input::files::{self, InputFile, Provenance};
use shpb_input::prelude::*;
use shpb_input::scene::Value;
use shpb_input::{Error, Result, Validator};
use std::path::Path;

/// The built-in set-up `--bars` names when not given.
pub const DEFAULT_BARS: &str = "authors";

/// An input error of the command line (`file = "command line"`) naming the flag or argument `key`.
pub fn input_err(key: &str, problem: impl Into<String>, allowed: impl Into<String>) -> Error {
    Error::Input {
        file: "command line".to_string(),
        key: key.to_string(),
        problem: problem.into(),
        allowed: allowed.into(),
    }
}

/// Names `--bars` and what is allowed when the set-up named on the command line is neither a
/// built-in set-up ([`shpb_input::builtin::SETUPS`]) nor an existing file.
pub fn require_bars(bars: &Path) -> Result<()> {
    let builtin = bars
        .to_str()
        .is_some_and(|name| shpb_input::builtin::setup(name).is_some());
    if !builtin && !bars.is_file() {
        return Err(input_err(
            "--bars",
            format!(
                "cannot read {}: not a built-in set-up and {}",
                bars.display(),
                shpb_input::files::not_a_file(bars)
            ),
            format!(
                "a built-in set-up ({}) or a bar set-up .toml file such as bars/authors.toml",
                shpb_input::builtin::setup_names()
            ),
        ));
    }
    Ok(())
}

/// The bar set-up named by `--bars`: a built-in set-up or a set-up file (relative to the current
/// directory).
pub fn load_apparatus(bars: &Path) -> Result<Apparatus> {
    require_bars(bars)?;
    match bars.to_str() {
        Some(reference) => Apparatus::resolve(reference, Path::new(".")),
        None => Apparatus::from_file(bars),
    }
}

/// The bar set-up of a reduction named by `--bars`: [`load_apparatus`]'s, or a lab's input deck
/// (`shpb_input::deck`, recognised by its content) with the specimen it names. A deck states no
/// gun, so only the reductions read it, not the commands that fire the gun.
pub fn load_record_apparatus(
    bars: &Path,
) -> Result<(
    Apparatus,
    Option<shpb_core::reduce_cylinder::CylinderGeometry>,
)> {
    if bars.is_file() && shpb_input::deck::Deck::is_deck_file(bars) {
        let deck = shpb_input::deck::Deck::read(bars)?;
        return Ok((deck.apparatus, Some(deck.specimen)));
    }
    Ok((load_apparatus(bars)?, None))
}

/// The `--pressure` option read and checked against the set-up's gun: (gauge pressure Pa,
/// striker velocity m/s).
pub fn gun_shot(apparatus: &Apparatus, pressure: &str) -> Result<(f64, f64)> {
    let p = shpb_input::units::cli_pressure(pressure)?;
    let v = apparatus
        .striker_velocity_m_s(p)
        .map_err(Validator::new("command line").core("--pressure"))?;
    Ok((p, v))
}

/// `shpb curve`: the loading curve F(δ) of a specimen (`--specimen`, `--rate`, `--to`,
/// `--points`, `--law`), checked as the command line checks it.
pub fn loading_curve(
    specimen: &str,
    rate: f64,
    to: f64,
    points: i64,
    law: LawKind,
) -> Result<ContactSeries> {
    let v = Validator::new("command line");
    let pair = shpb_input::specimen::resolve_pair(specimen, Path::new("."), &v, "--specimen")?;
    v.in_range("--rate", rate, 0.0, 1e9, "1/s")?;
    v.positive(
        "--to",
        to,
        0.5 * pair.sphere1.radius_m.min(pair.sphere2.radius_m),
        "m",
    )?;
    if !(2..=10_000_000).contains(&points) {
        return Err(v.error(
            "--points",
            format!("{points} is out of range"),
            "2 to 10000000",
        ));
    }
    let law = law.build(pair.contact_properties());
    Ok(shpb_core::solver::loading_curve(
        law.as_ref(),
        to,
        points as usize,
        rate,
    ))
}

/// Where a scene comes from.
#[derive(Debug, Clone, Copy)]
pub enum Scene<'a> {
    /// A scene file, or a run file (`.h5` written by `shpb run -o`) whose stored scene and
    /// inputs are run again.
    File(&'a Path),
    /// Scene TOML text named `name` (e.g. a scene given as a Python dict); relative paths in it
    /// are resolved against the working directory.
    Text {
        /// The scene's name in messages and in the provenance.
        name: &'a str,
        /// The TOML text.
        text: &'a str,
    },
}

/// Reads a scene (recording every input it reads for the run file's `/provenance`), or a run
/// file's stored scene and inputs, with `overrides` (dotted keys, as `shpb sweep --set`) and the
/// `fidelity` preset applied. When `overrides` are given, the provenance stores the overridden
/// scene text, so that the run file reruns the test that was run.
pub fn load_scene(
    scene: Scene,
    fidelity: Option<Fidelity>,
    overrides: &[(String, Value)],
    command_line: String,
) -> Result<(Params, Provenance)> {
    // A run file is rerun with its stored inputs and, unless given, its stored fidelity.
    let stored = match scene {
        Scene::File(path) if path.is_file() && shpb_output::reduction::is_hdf5(path)? => {
            Some((path, shpb_output::provenance::read_provenance(path)?))
        }
        _ => None,
    };
    let fidelity = match (fidelity, stored.as_ref()) {
        (Some(f), _) => Some(f),
        (None, Some((path, s))) => match s.fidelity_override.as_deref() {
            Some(name) => Some(Fidelity::parse(name).ok_or_else(|| Error::Input {
                file: path.display().to_string(),
                key: "/provenance fidelity_override".into(),
                problem: format!("unknown fidelity `{name}`"),
                allowed: "fast, standard, reference".into(),
            })?),
            None => None,
        },
        (None, None) => None,
    };
    let mut all = overrides.to_vec();
    if let Some(f) = fidelity {
        all.push(("fidelity".to_string(), Value::String(f.name().into())));
    }
    let stored_scene = |params: &Params, name: &str, inputs: &mut Vec<InputFile>| {
        if !overrides.is_empty()
            && let Some(f) = inputs.iter_mut().find(|f| f.name == name)
        {
            f.text = params.text.clone();
        }
    };
    match (scene, stored) {
        (_, Some((_, stored))) => {
            let params = files::replay(&stored.inputs, || {
                Params::from_file_overridden(Path::new(&stored.scene_file), &all)
            })?;
            let mut provenance = Provenance {
                fidelity_override: fidelity.map(|f| f.name().to_string()),
                command_line,
                ..stored
            };
            let name = provenance.scene_file.clone();
            stored_scene(&params, &name, &mut provenance.inputs);
            Ok((params, provenance))
        }
        (Scene::File(scene), None) => {
            let (params, mut inputs) = files::capture(|| Params::from_file_overridden(scene, &all));
            let params = params?;
            let name = scene.display().to_string();
            stored_scene(&params, &name, &mut inputs);
            Ok((
                params,
                Provenance {
                    scene_file: name,
                    fidelity_override: fidelity.map(|f| f.name().to_string()),
                    command_line,
                    inputs,
                },
            ))
        }
        (Scene::Text { name, text }, None) => {
            let (params, mut inputs) = files::capture(|| {
                let text = if all.is_empty() {
                    text.to_string()
                } else {
                    shpb_input::scene::with_overrides(text, name, &all)?
                };
                // The base of a scene file named without directory, as a rerun resolves it.
                Params::from_toml(&text, name, Path::new(""))
            });
            let params = params?;
            inputs.retain(|f| f.name != name);
            inputs.insert(
                0,
                InputFile {
                    name: name.to_string(),
                    text: params.text.clone(),
                },
            );
            Ok((
                params,
                Provenance {
                    scene_file: name.to_string(),
                    fidelity_override: fidelity.map(|f| f.name().to_string()),
                    command_line,
                    inputs,
                },
            ))
        }
    }
}

/// Runs a loaded scene as `shpb run` does (`progress` gets the fraction done): the output's
/// warnings start with the scene's own ([`Params::warnings`]).
pub fn run_scene(params: &Params, progress: &mut dyn FnMut(f64) -> bool) -> Result<RunOutput> {
    let mut out = params.run_with_progress(progress)?;
    out.warnings.splice(0..0, params.warnings());
    Ok(out)
}

/// [`run_scene`], then, with `bands` and a set-up that states its uncertainty (or a gun scatter
/// the scene uses), the 90 % bands of the summary ([`crate::band::predict`], docs/physics.md
/// §10.6) written into its items' `band_90`: what `shpb run` (unless `--no-bands`) and
/// `shpb.run` do. `provenance` is what [`load_scene`] returned with `params`.
pub fn run_scene_with_bands(
    params: &Params,
    provenance: &Provenance,
    bands: bool,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<RunOutput> {
    let mut out = run_scene(params, progress)?;
    if bands && let Some(p) = crate::band::predict(params, &out, provenance) {
        crate::band::apply(&mut out, &p);
    }
    Ok(out)
}

/// A reduction of `shpb reduce` with what it was made from.
#[derive(Debug, Clone)]
pub struct Reduced {
    /// The lab's reduction.
    pub reduction: Reduction,
    /// The set-up whose bars and gauges reduced the record.
    pub apparatus: Apparatus,
    /// Whether the record was a run file's gauge strains (else raw gauge voltages).
    pub hdf5_input: bool,
    /// A cylindrical specimen's 1/2/3-wave stress and strain, when its geometry was given
    /// (docs/physics.md §7.8).
    pub cylinder: Option<shpb_core::reduce_cylinder::CylinderReduction>,
    /// The specimen the record was reduced for (`--specimen`, the cylinder flags, a run file's
    /// own, else the paper's two 6.35 mm spheres).
    pub specimen: ReducedSpecimen,
}

/// The cylinder of `shpb reduce --specimen-length L --specimen-diameter D` (both or neither;
/// `keys` name the two options in messages): each greater than 0, at most 1 m.
pub fn cylinder_geometry(
    length_m: Option<f64>,
    diameter_m: Option<f64>,
    keys: (&str, &str),
) -> Result<Option<shpb_core::reduce_cylinder::CylinderGeometry>> {
    let (length_m, diameter_m) = match (length_m, diameter_m) {
        (None, None) => return Ok(None),
        (Some(l), Some(d)) => (l, d),
        (l, _) => {
            let (given, missing) = if l.is_some() {
                (keys.0, keys.1)
            } else {
                (keys.1, keys.0)
            };
            return Err(input_err(
                missing,
                format!("missing: {given} is given"),
                format!(
                    "both {} and {} (a cylinder's length and diameter, m), or neither",
                    keys.0, keys.1
                ),
            ));
        }
    };
    for (key, v) in [(keys.0, length_m), (keys.1, diameter_m)] {
        if !(v.is_finite() && v > 0.0 && v <= 1.0) {
            return Err(input_err(
                key,
                format!("{v} m is out of range"),
                "greater than 0, at most 1 (m)",
            ));
        }
    }
    Ok(Some(shpb_core::reduce_cylinder::CylinderGeometry {
        length_m,
        diameter_m,
    }))
}

/// `shpb reduce`: reduces a raw record (the authors' CSV) or a run file of `shpb run`
/// (recognised by its signature, reduced with its own set-up and spheres) with the set-up
/// `bars_flag` (default [`DEFAULT_BARS`]; for a run file, a set-up that differs from the run's
/// is refused); with `cylinder`, also that specimen's 1/2/3-wave stress and strain
/// (`shpb_core::reduce_cylinder`) — for a run file of a cylinder, its own cylinder by default.
pub fn reduce_record(
    record: &Path,
    bars_flag: Option<&Path>,
    dispersion: shpb_core::reduce::DispersionCorrection,
    tyas_pope: bool,
    cylinder: Option<shpb_core::reduce_cylinder::CylinderGeometry>,
) -> Result<Reduced> {
    reduce_record_with(
        record,
        bars_flag,
        &RecordOptions {
            dispersion,
            tyas_pope,
            cylinder,
            ..RecordOptions::default()
        },
    )
}

/// The choices of `shpb reduce` beyond the record and set-up (its flags; docs/physics.md §7).
#[derive(Debug, Clone, PartialEq)]
pub struct RecordOptions {
    /// Dispersion correction (`--dispersion`, default Bancroft; `--no-dispersion` is `none`).
    pub dispersion: shpb_core::reduce::DispersionCorrection,
    /// Apply the Tyas–Pope amplitude factors (`--tyas-pope`).
    pub tyas_pope: bool,
    /// Window alignment (`--align`, default geometric).
    pub alignment: shpb_core::reduce::Alignment,
    /// Moving-average width applied to both channels, s (`--smooth`, default
    /// [`shpb_core::reduce::DEFAULT_SMOOTHING_S`], as `shpb run` smooths simulated records).
    pub smoothing_s: f64,
    /// Bound of the balance search on each window shift, s (`--balance-bound`, default
    /// [`shpb_core::reduce::DEFAULT_BALANCE_BOUND_S`]; used by `--align balance` only).
    pub balance_bound_s: f64,
    /// Manual windows (`--incident-start`, `--reflected-delay`, `--transmitted-delay`,
    /// `--duration`).
    pub window: Option<shpb_core::reduce::WindowOverride>,
    /// A cylindrical specimen's geometry (`--specimen-length`, `--specimen-diameter`; default: a
    /// run file's own cylinder, if it has one).
    pub cylinder: Option<shpb_core::reduce_cylinder::CylinderGeometry>,
    /// How to read a text record that is not the authors' CSV (`--layout`).
    pub layout: Option<shpb_input::layout::RecordLayout>,
    /// The specimen of a specimen file (`--specimen FILE.toml`: spheres of any diameter, a chain,
    /// or a cylinder; for a run file it overrides the run's own). Not with `cylinder`.
    pub specimen: Option<shpb_input::specimen_file::SpecimenFile>,
    /// A record kept one file per channel (`--channel ROLE=FILE`); the record argument is then
    /// its name ([`shpb_input::channel_file::ChannelSet::name`]).
    pub channels: Option<shpb_input::channel_file::ChannelSet>,
    /// A tension test (`--tension`, docs/physics.md §7.8.1): forces, stresses and strains tension
    /// positive; a cylinder specimen needed. A run file of a tension scene is one without it.
    pub tension: bool,
    /// Wave separation of overlapping pulses (`--wave-separation`, default none; docs/physics.md
    /// §7.11); two gauges read the set-up's `incident_2` and `transmission_2` channels.
    pub wave_separation: shpb_core::reduce::WaveSeparation,
    /// The zero-phase filter of both records (`--filter`, docs/physics.md §7.12; default
    /// [`shpb_core::reduce::Filter::DEFAULT`]); [`filter_choice`] makes it from the flags.
    pub filter: shpb_core::reduce::Filter,
    /// How the baselines are removed (`--baseline`, default start-mean).
    pub baseline: shpb_core::reduce::Baseline,
}

impl RecordOptions {
    /// The `shpb reduce` flags that make these choices (provenance of a reduction, for the CLI
    /// and Python alike): `--dispersion` and `--tyas-pope` when not the default, `--align` and
    /// `--smooth`, `--balance-bound` with `--align balance`, the manual windows given, and a
    /// cylinder's geometry. Each flag is preceded by a space.
    pub fn command_flags(&self) -> String {
        let mut c = String::new();
        if self.dispersion != shpb_core::reduce::DispersionCorrection::Bancroft {
            c.push_str(&format!(" --dispersion {}", self.dispersion.name()));
        }
        if self.tyas_pope {
            c.push_str(" --tyas-pope");
        }
        c.push_str(&format!(" --align {}", self.alignment.name()));
        c.push_str(&filter_flags(self.filter, self.smoothing_s));
        if self.baseline != shpb_core::reduce::Baseline::StartMean {
            c.push_str(&format!(" --baseline {}", self.baseline.name()));
        }
        if self.alignment == shpb_core::reduce::Alignment::Balance {
            c.push_str(&format!(" --balance-bound {:e}", self.balance_bound_s));
        }
        if let Some(w) = self.window {
            for (flag, v) in [
                ("--incident-start", w.incident_start_s),
                ("--reflected-delay", w.reflected_delay_s),
                ("--transmitted-delay", w.transmitted_delay_s),
                ("--duration", w.duration_s),
            ] {
                if let Some(v) = v {
                    c.push_str(&format!(" {flag} {v:e}"));
                }
            }
        }
        if let Some(g) = &self.cylinder {
            c.push_str(&format!(
                " --specimen-length {:e} --specimen-diameter {:e}",
                g.length_m, g.diameter_m
            ));
        }
        if let Some(s) = &self.specimen {
            c.push_str(&format!(" --specimen {}", s.source));
        }
        if let Some(set) = &self.channels {
            c.push_str(&set.command_flags());
        }
        if self.tension {
            c.push_str(" --tension");
        }
        if self.wave_separation != shpb_core::reduce::WaveSeparation::None {
            c.push_str(&format!(
                " --wave-separation {}",
                self.wave_separation.name()
            ));
        }
        c
    }
}

impl Default for RecordOptions {
    fn default() -> Self {
        RecordOptions {
            dispersion: shpb_core::reduce::DispersionCorrection::Bancroft,
            tyas_pope: false,
            alignment: shpb_core::reduce::Alignment::Geometric,
            smoothing_s: shpb_core::reduce::DEFAULT_SMOOTHING_S,
            balance_bound_s: shpb_core::reduce::DEFAULT_BALANCE_BOUND_S,
            window: None,
            cylinder: None,
            layout: None,
            specimen: None,
            channels: None,
            tension: false,
            wave_separation: shpb_core::reduce::WaveSeparation::None,
            filter: shpb_core::reduce::Filter::DEFAULT,
            baseline: shpb_core::reduce::Baseline::StartMean,
        }
    }
}

/// The `shpb reduce` flags of a filter (each preceded by a space): `--filter NAME` and its
/// parameters, a moving average's width as `--smooth`.
fn filter_flags(filter: shpb_core::reduce::Filter, smoothing_s: f64) -> String {
    use shpb_core::reduce::Filter;
    let mut c = format!(" --filter {}", filter.name());
    match filter {
        Filter::None => {}
        Filter::MovingAverage { width_s } => {
            c.push_str(&format!(" --smooth {:e}", width_s.unwrap_or(smoothing_s)))
        }
        Filter::Butterworth { order, cutoff_hz } => {
            c.push_str(&format!(" --filter-order {order}"));
            if let Some(f) = cutoff_hz {
                c.push_str(&format!(" --filter-cutoff {f:e}"));
            }
        }
        Filter::SavitzkyGolay { window_s, order } => {
            c.push_str(&format!(
                " --filter-window {window_s:e} --filter-order {order}"
            ));
        }
    }
    c
}

/// The names `--filter` accepts.
pub const FILTER_NAMES: [&str; 4] = ["none", "butterworth", "savitzky-golay", "moving-average"];

/// The filter and the moving-average width of `shpb reduce`'s flags (and of Python's
/// `shpb.reduce`; docs/physics.md §7.12): `--filter NAME` (default butterworth) with
/// `--filter-cutoff HZ` and `--filter-order N` (butterworth), `--filter-window S` and
/// `--filter-order N` (savitzky-golay), `--smooth S` or `--filter-window S` (moving-average).
/// `--smooth S` without `--filter` is the moving average of width S (0: no filter), as before
/// the filters. A parameter the chosen filter does not take is refused, naming its flag.
/// `names` gives the flags' names as the caller spells them (`--filter`, `--filter-cutoff`,
/// `--filter-order`, `--filter-window`, `--smooth`).
pub fn filter_choice(
    filter: Option<&str>,
    smooth_s: Option<f64>,
    cutoff_hz: Option<f64>,
    order: Option<usize>,
    window_s: Option<f64>,
    names: [&str; 5],
) -> Result<(shpb_core::reduce::Filter, f64)> {
    use shpb_core::reduce::Filter;
    use shpb_core::reduce::filter::{
        DEFAULT_BUTTERWORTH_ORDER, DEFAULT_SAVGOL_ORDER, DEFAULT_SAVGOL_WINDOW_S,
    };
    let [f_flag, cutoff_flag, order_flag, window_flag, smooth_flag] = names;
    let name = match (filter, smooth_s) {
        (Some(n), _) => n,
        (None, Some(_)) => "moving-average",
        (None, None) => Filter::DEFAULT.name(),
    };
    let refuse = |flag: &str, what: &str| -> Error {
        input_err(
            flag,
            format!("{flag} given with {f_flag} {name}, which has no {what}"),
            match name {
                "butterworth" => format!("with {f_flag} butterworth: {cutoff_flag}, {order_flag}"),
                "savitzky-golay" => {
                    format!("with {f_flag} savitzky-golay: {window_flag}, {order_flag}")
                }
                "moving-average" => {
                    format!("with {f_flag} moving-average: {smooth_flag} or {window_flag}")
                }
                _ => format!("with {f_flag} none: no filter parameter"),
            },
        )
    };
    let smoothing_default = shpb_core::reduce::DEFAULT_SMOOTHING_S;
    match name {
        "none" => {
            if let Some(s) = smooth_s
                && s != 0.0
            {
                return Err(refuse(smooth_flag, "width"));
            }
            for (flag, given) in [
                (cutoff_flag, cutoff_hz.is_some()),
                (order_flag, order.is_some()),
                (window_flag, window_s.is_some()),
            ] {
                if given {
                    return Err(refuse(flag, "parameter"));
                }
            }
            Ok((Filter::None, smooth_s.unwrap_or(smoothing_default)))
        }
        "moving-average" => {
            if cutoff_hz.is_some() {
                return Err(refuse(cutoff_flag, "cut-off"));
            }
            if order.is_some() {
                return Err(refuse(order_flag, "order"));
            }
            let width = match (smooth_s, window_s) {
                (Some(a), Some(b)) if a != b => {
                    return Err(input_err(
                        window_flag,
                        format!(
                            "{window_flag} {b:e} and {smooth_flag} {a:e} both give the moving average's width"
                        ),
                        format!("one of {smooth_flag} S or {window_flag} S"),
                    ));
                }
                (Some(a), _) | (None, Some(a)) => a,
                (None, None) => smoothing_default,
            };
            Ok((Filter::MovingAverage { width_s: None }, width))
        }
        "butterworth" => {
            if smooth_s.is_some() {
                return Err(refuse(smooth_flag, "moving-average width"));
            }
            if window_s.is_some() {
                return Err(refuse(window_flag, "window"));
            }
            Ok((
                Filter::Butterworth {
                    order: order.unwrap_or(DEFAULT_BUTTERWORTH_ORDER),
                    cutoff_hz,
                },
                smoothing_default,
            ))
        }
        "savitzky-golay" => {
            if smooth_s.is_some() {
                return Err(refuse(smooth_flag, "moving-average width"));
            }
            if cutoff_hz.is_some() {
                return Err(refuse(cutoff_flag, "cut-off"));
            }
            Ok((
                Filter::SavitzkyGolay {
                    window_s: window_s.unwrap_or(DEFAULT_SAVGOL_WINDOW_S),
                    order: order.unwrap_or(DEFAULT_SAVGOL_ORDER),
                },
                smoothing_default,
            ))
        }
        other => Err(input_err(
            f_flag,
            format!("unknown filter `{other}`"),
            FILTER_NAMES.join(", "),
        )),
    }
}

/// The baseline of `--baseline NAME` (`start-mean`, `linear-drift`; docs/physics.md §7.12).
pub fn baseline_choice(name: &str, flag: &str) -> Result<shpb_core::reduce::Baseline> {
    use shpb_core::reduce::Baseline;
    [Baseline::StartMean, Baseline::LinearDrift]
        .into_iter()
        .find(|b| b.name() == name)
        .ok_or_else(|| {
            input_err(
                flag,
                format!("unknown baseline `{name}`"),
                "start-mean, linear-drift",
            )
        })
}

/// The `shpb reduce` flag of each quantity of [`ReductionOptions`] (the core's name otherwise).
fn reduce_flag(quantity: &str) -> &str {
    match quantity {
        "smoothing_window_s" => "--smooth",
        "filter.width_s" => "--smooth",
        "filter.order" => "--filter-order",
        "filter.cutoff_hz" => "--filter-cutoff",
        "filter.window_s" => "--filter-window",
        "baseline" => "--baseline",
        "balance_bound_s" => "--balance-bound",
        "tyas_pope" => "--tyas-pope",
        "window.incident_start_s" => "--incident-start",
        "window.reflected_delay_s" => "--reflected-delay",
        "window.transmitted_delay_s" => "--transmitted-delay",
        "window.duration_s" => "--duration",
        "tension" => "--tension",
        "wave_separation" => "--wave-separation",
        other => other,
    }
}

/// A core error of [`ReductionOptions::validate`] as an input error naming the flag at fault
/// (as [`shpb_input::Validator::core`] names a file's key).
fn flag_err(e: shpb_core::Error) -> Error {
    match e {
        shpb_core::Error::Invalid {
            quantity,
            problem,
            allowed,
            ..
        } => input_err(reduce_flag(&quantity), problem, allowed),
        other => other.into(),
    }
}

/// A record that is one oscilloscope channel with a header block: say how to give its files.
fn channel_file_hint(record: &Path, e: Error) -> Error {
    let text = std::fs::read(record).unwrap_or_default();
    if shpb_input::channel_file::is_channel_file(&String::from_utf8_lossy(&text)) {
        input_err(
            "RECORD",
            format!(
                "{} is one oscilloscope channel with a header block (a record kept one file per channel)",
                record.display()
            ),
            "the record's channel files as --channel incident=FILE --channel transmission=FILE (a gauge's several files are averaged)",
        )
    } else {
        e
    }
}

/// The core's reduction options of `shpb reduce`'s choices, checked once by the core (its
/// errors reported as the flags).
pub fn reduction_options(choices: &RecordOptions) -> Result<ReductionOptions> {
    let options = ReductionOptions {
        tension: choices.tension,
        dispersion: choices.dispersion,
        tyas_pope: choices.tyas_pope,
        alignment: choices.alignment,
        smoothing_window_s: choices.smoothing_s,
        balance_bound_s: choices.balance_bound_s,
        window: choices.window,
        wave_separation: choices.wave_separation,
        filter: choices.filter,
        baseline: choices.baseline,
        ..ReductionOptions::default()
    };
    options.validate().map_err(flag_err)?;
    Ok(options)
}

/// The gauge strains of a run as the lab reads its record: the digitised voltages through the
/// set-up's bridges ([`record_input`] of a run file, without the file).
pub fn run_input(out: &RunOutput, apparatus: &Apparatus) -> Option<ReductionInput> {
    let strains = |name: &str| {
        let ch = apparatus.gauges.channel(name)?;
        let g = out.gauges.iter().find(|g| g.name == name)?;
        Some(ch.strains_from_voltages(&g.voltage_v))
    };
    Some(ReductionInput {
        time_s: out.time_s.clone()?,
        incident_strain: strains("incident")?,
        transmission_strain: strains("transmission")?,
    })
}

/// [`reduce_record`] with every choice of `shpb reduce` ([`RecordOptions`]).
pub fn reduce_record_with(
    record: &Path,
    bars_flag: Option<&Path>,
    choices: &RecordOptions,
) -> Result<Reduced> {
    let mut options = reduction_options(choices)?;
    if let (Some(file), Some(_)) = (&choices.specimen, choices.cylinder) {
        return Err(input_err(
            "--specimen",
            format!(
                "{} gives the specimen, and so do --specimen-length/--specimen-diameter",
                file.source
            ),
            "either --specimen FILE.toml (spheres or shape = \"cylinder\") or --specimen-length L --specimen-diameter D, not both",
        ));
    }
    let bars = bars_flag.unwrap_or(Path::new(DEFAULT_BARS));
    require_bars(bars)?;
    if !record.is_file() {
        return Err(input_err(
            "RECORD",
            format!(
                "cannot read {}: {}",
                record.display(),
                shpb_input::files::not_a_file(record)
            ),
            "a raw gauge record (.csv: time_s,incident_V,transmission_V) or an HDF5 file of `shpb run`",
        ));
    }
    let hdf5_input = shpb_output::reduction::is_hdf5(record)?;
    if hdf5_input && let Some(layout) = &choices.layout {
        return Err(input_err(
            "--layout",
            format!(
                "{} is a run file (HDF5); the layout {} reads text exports",
                record.display(),
                layout.source
            ),
            "--layout only with text records",
        ));
    }
    if let Some(set) = &choices.channels {
        if hdf5_input || choices.layout.is_some() {
            return Err(input_err(
                "--channel",
                "a record of channel files is read from their header blocks",
                "--channel files without --layout, and no run file (HDF5) among them",
            ));
        }
        if set.name() != record {
            return Err(input_err(
                "--channel",
                format!(
                    "the record {} is not the set's first incident file {}",
                    record.display(),
                    set.name().display()
                ),
                "the set's name (ChannelSet::name) as the record",
            ));
        }
    }
    let run = if hdf5_input { run_setup(record)? } else { None };
    let own_set_up = run.is_some();
    // A run file of a tension scene is reduced as a tension test (docs/physics.md §7.8.1).
    let run_tension = run.as_ref().is_some_and(|r| r.2);
    let (apparatus, run_specimen) = match run {
        Some((run_apparatus, run_specimen, _)) => {
            if let Some(flag) = bars_flag {
                let (given, _) = load_record_apparatus(flag)?;
                if ReductionSetup::from_apparatus(&given)?
                    != ReductionSetup::from_apparatus(&run_apparatus)?
                {
                    return Err(input_err(
                        "--bars",
                        format!(
                            "{} was simulated with the set-up {} ({}); --bars {} differs ({})",
                            record.display(),
                            run_apparatus.source,
                            describe(&run_apparatus),
                            flag.display(),
                            describe(&given)
                        ),
                        "no --bars (the run file's own set-up is used), or a set-up with the same bars and gauge distances",
                    ));
                }
            }
            (run_apparatus, run_specimen)
        }
        None => {
            // A lab's deck names its specimen, the default of a record reduced with it.
            let (apparatus, deck_specimen) = load_record_apparatus(bars)?;
            (
                apparatus,
                deck_specimen.map_or_else(ReducedSpecimen::default, ReducedSpecimen::Cylinder),
            )
        }
    };
    // The specimen: a specimen file's, the cylinder flags', else the run file's own (a cylinder
    // or its spheres), else the paper's spheres. A cylinder's rate is its own (its 1/2/3-wave
    // analysis); the spheres' is δ̇/Σrᵢ.
    let specimen = match (&choices.specimen, choices.cylinder) {
        (Some(file), _) => file.specimen,
        (None, Some(g)) => ReducedSpecimen::Cylinder(g),
        (None, None) => run_specimen,
    };
    options.specimen_radii_m = specimen.radii_m();
    options.tension = choices.tension || run_tension;
    if options.tension && specimen.cylinder().is_none() {
        return Err(input_err(
            "--tension",
            "a tension test reduced for spheres, which carry no tension",
            "--tension with a cylinder: --specimen FILE.toml (shape = \"cylinder\", length_m or gauge_length_m, diameter_m) or --specimen-length L --specimen-diameter D",
        ));
    }
    let input = match &choices.channels {
        // A record kept one file per oscilloscope channel (`--channel ROLE=FILE`).
        Some(set) => {
            shpb_core::reduce::record_strains(&set.read()?, &apparatus, options.baseline_samples)?
        }
        None => record_input(
            record,
            &apparatus,
            choices.layout.as_ref(),
            own_set_up,
            options.baseline_samples,
        )?,
    };
    let setup = ReductionSetup::from_apparatus(&apparatus)?;
    let name = record.display().to_string();
    // The record checked for plausibility before it is reduced, and what the reduction made of
    // it against the specimen (shpb_core::reduce::plausibility).
    shpb_core::reduce::plausibility::check_input(&input, &setup, &options, &name).map_err(|e| {
        match e {
            // A check on a reduction option names its flag.
            shpb_core::Error::Invalid { ref quantity, .. } if quantity == "smoothing_window_s" => {
                flag_err(e)
            }
            other => other.into(),
        }
    })?;
    let second = match options.wave_separation {
        shpb_core::reduce::WaveSeparation::TwoGauge => {
            second_gauges(record, &apparatus, hdf5_input, own_set_up)?
        }
        _ => None,
    };
    let reduction =
        shpb_core::reduce::reduce_separated(&input, second.as_ref(), &setup, &options, &name)
            .map_err(|e| match e {
                // A filter the record's sample step cannot take names its flag.
                shpb_core::Error::Invalid { ref quantity, .. }
                    if quantity.starts_with("filter.") =>
                {
                    flag_err(e)
                }
                other => other.into(),
            })?;
    shpb_core::reduce::plausibility::check_reduction(
        &reduction,
        shpb_core::reduce::plausibility::SpecimenSize::of(&specimen),
        &name,
    )?;
    let cylinder = specimen.reduce(&reduction, &setup)?;
    Ok(Reduced {
        reduction,
        apparatus,
        hdf5_input,
        cylinder,
        specimen,
    })
}

/// The second gauge on each bar of a record, for the two-gauge wave separation (docs/physics.md
/// §7.11): the set-up's channels `incident_2` and `transmission_2`
/// ([`shpb_core::reduce::SECOND_GAUGE_CHANNELS`]) as a run file recorded them (its digitised
/// voltages through their bridges when `run_voltages`, else its strains). A text record holds
/// two channels only: refused, naming the flag.
fn second_gauges(
    record: &Path,
    apparatus: &Apparatus,
    hdf5_input: bool,
    run_voltages: bool,
) -> Result<Option<shpb_core::reduce::SecondGauges>> {
    let [inc, tra] = shpb_core::reduce::SECOND_GAUGE_CHANNELS;
    let need = "a set-up with channels `incident_2` and `transmission_2` (bar incident and \
                transmission, farther from the specimen than the first gauges) and a run file of \
                it, or --wave-separation one-gauge";
    let channel = |name: &str| {
        apparatus.gauges.channel(name).ok_or_else(|| {
            input_err(
                "--wave-separation",
                format!(
                    "two-gauge separation: {} has no `{name}` gauge channel",
                    apparatus.source
                ),
                need,
            )
        })
    };
    let (ci, ct) = (channel(inc)?, channel(tra)?);
    if !hdf5_input {
        return Err(input_err(
            "--wave-separation",
            format!(
                "two-gauge separation reads the second gauges from a run file; {} is a text \
                 record of two channels",
                record.display()
            ),
            need,
        ));
    }
    let read = |ch: &shpb_core::gauge::GaugeChannel| -> Result<Vec<f64>> {
        if run_voltages
            && let Some(v) = shpb_output::reduction::read_hdf5_series(
                record,
                &format!("gauges/{}/voltage", ch.name),
            )?
        {
            return Ok(ch.strains_from_voltages(&v));
        }
        shpb_output::reduction::read_hdf5_series(record, &format!("gauges/{}/strain", ch.name))?
            .ok_or_else(|| {
                input_err(
                    "--wave-separation",
                    format!("{} has no /gauges/{}/strain", record.display(), ch.name),
                    need,
                )
            })
    };
    let (ins_i, ins_t) = apparatus
        .inserts
        .equivalent_bar_lengths_m(apparatus.material.wave_speed_m_s());
    Ok(Some(shpb_core::reduce::SecondGauges {
        incident_gauge_m: ci.distance_from_specimen_m + ins_i,
        transmission_gauge_m: ct.distance_from_specimen_m + ins_t,
        incident_strain: read(ci)?,
        transmission_strain: read(ct)?,
    }))
}

/// The gauge strains of a record, the one way every command reads one (`shpb reduce`,
/// `shpb calibrate`): an HDF5 file of `shpb run` (its digitised voltages through `apparatus`'s
/// bridges when `run_voltages`, else its strains), or a text or spreadsheet record through
/// `shpb_input::sheet::read_record` (a layout, the authors' CSV, columns named with their units);
/// voltage baselines are the mean of the first
/// `baseline_samples` samples.
pub fn record_input(
    record: &Path,
    apparatus: &Apparatus,
    layout: Option<&shpb_input::layout::RecordLayout>,
    run_voltages: bool,
    baseline_samples: usize,
) -> Result<ReductionInput> {
    if shpb_output::reduction::is_hdf5(record)? {
        // A run file with its own set-up is read as the lab reads a record: its digitised
        // voltages through the set-up's bridges, exactly as the run reduced them; otherwise (a
        // file of `shpb strain`, or without voltages) its strains.
        let voltages = if run_voltages {
            shpb_output::reduction::read_hdf5_voltages(record)?
        } else {
            None
        };
        return match voltages {
            Some(shpb_core::gauge::RawRecord {
                time_s,
                incident_v,
                transmission_v,
            }) => {
                let channel = |name: &str| {
                    apparatus.gauges.channel(name).ok_or_else(|| {
                        input_err(
                            "RECORD",
                            format!("the set-up {} has no `{name}` gauge", apparatus.source),
                            "a set-up with incident and transmission gauges",
                        )
                    })
                };
                Ok(ReductionInput {
                    time_s,
                    incident_strain: channel("incident")?.strains_from_voltages(&incident_v),
                    transmission_strain: channel("transmission")?
                        .strains_from_voltages(&transmission_v),
                })
            }
            None => shpb_output::reduction::read_hdf5_strains(record),
        };
    }
    // Every text or spreadsheet record through the one reader (a layout, the authors' CSV, or
    // columns named with their units).
    Ok(shpb_input::sheet::read_record(record, layout)
        .map_err(|e| channel_file_hint(record, e))?
        .into_strains(apparatus, baseline_samples)?)
}

/// The set-up and specimen a run file was simulated with (its spheres' radii or its cylinder;
/// the paper's spheres for a pulse run), from the scene and inputs stored in its `/provenance`
/// (None for a file without a stored bar scene, e.g. `shpb strain`'s).
fn run_setup(record: &Path) -> Result<Option<(Apparatus, ReducedSpecimen, bool)>> {
    let Ok(stored) = shpb_output::provenance::read_provenance(record) else {
        return Ok(None);
    };
    if stored.scene_file.is_empty() {
        return Ok(None);
    }
    // The run's own scene, inputs and fidelity, as `shpb run RUN.h5` reruns it.
    let (params, _) = load_scene(Scene::File(record), None, &[], String::new())?;
    Ok(match params.params {
        // A chain specimen's strain rate is δ̇/Σ rᵢ, as the run's own reduction took it.
        SceneParams::Pulse {
            apparatus, options, ..
        } => Some((
            *apparatus,
            params
                .specimen
                .as_ref()
                .map_or_else(ReducedSpecimen::default, ReducedSpecimen::of),
            options.loading.is_tension(),
        )),
        _ => None,
    })
}

/// The bar diameters and gauge distances of a set-up, for messages.
fn describe(a: &Apparatus) -> String {
    let gauge = |n: &str| {
        a.gauges.channel(n).map_or("none".to_string(), |c| {
            format!("{} m", c.distance_from_specimen_m)
        })
    };
    format!(
        "bars {} / {} mm, gauges at {} / {}",
        a.incident.diameter_m * 1e3,
        a.transmission.diameter_m * 1e3,
        gauge("incident"),
        gauge("transmission")
    )
}

/// A whole sweep of `scene` over the `--set` specifications `set`, on `jobs` threads, without
/// checkpoint or outputs: every point is validated first, then run; the rows come back in point
/// order.
pub fn sweep_rows(
    scene: &Path,
    set: &[String],
    jobs: usize,
) -> Result<(Vec<Axis>, Vec<RunSummary>)> {
    sweep_shard_rows(scene, set, (1, 1), jobs)
}

/// Runs shard `k` of `n` of the sweep (`shpb sweep --shard k/n`, without checkpoint or files):
/// every n-th run of the product from k − 1, each row carrying its index in the whole sweep, so
/// shards run anywhere (a Dask worker, a job array) combine into [`sweep_rows`]' table.
pub fn sweep_shard_rows(
    scene: &Path,
    set: &[String],
    (k, n): (usize, usize),
    jobs: usize,
) -> Result<(Vec<Axis>, Vec<RunSummary>)> {
    let (axes, finished) = sweep_shard_rows_until(scene, set, (k, n), jobs, &|| true)?;
    Ok((axes, finished.rows))
}

/// [`sweep_shard_rows`] that `keep_going` may stop (asked before each run and every 1 % of one,
/// [`crate::sweep::run_until`]): the rows finished and whether it was stopped.
pub fn sweep_shard_rows_until(
    scene: &Path,
    set: &[String],
    (k, n): (usize, usize),
    jobs: usize,
    keep_going: &(dyn Fn() -> bool + Sync),
) -> Result<(Vec<Axis>, crate::sweep::Finished<RunSummary>)> {
    crate::sweep::check_jobs(jobs)?;
    crate::sweep::require_scene(scene)?;
    let (k, n) = crate::sweep::check_shard(k, n)?;
    let axes = crate::sweep::parse_axes(set)?;
    // Before anything is allocated: can the sweep finish on this machine? (as `shpb sweep`)
    crate::sweep::estimate(&axes, (k, n), crate::sweep::Outputs::default())
        .check(&crate::sweep::Limits::of_machine(&[]))?;
    let points = crate::sweep::shard_points(&axes, k, n);
    // One pool validates the points (in parallel) and runs them.
    let pool = crate::sweep::thread_pool(jobs)?;
    crate::sweep::check_points_on(&pool, scene, &axes, &points)?;
    let rows = crate::sweep::run_points_on(&pool, scene, &axes, &points, |_| {}, keep_going)?;
    Ok((axes, rows))
}

/// A whole uncertainty study of `scene` (`shpb study` without outputs): the plan's samples drawn
/// by a Latin hypercube seeded with its seed from the scene's distributions and, with its gun
/// scatter, the set-up's, run at its fidelity on `jobs` threads ([`crate::uq::study_rows`]);
/// [`crate::uq::Study::statistics`] gives each quantity's mean, sd, percentiles and indices.
pub fn study_rows(
    scene: &Path,
    plan: &crate::uq::StudyPlan,
    jobs: usize,
) -> Result<crate::uq::Study> {
    crate::uq::study_rows(scene, plan, jobs, false, |_| {})
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The provenance flags name every non-default choice and only those: the default
    /// correction unsaid, the bound only with `--align balance`, a cylinder's geometry when
    /// given.
    #[test]
    fn the_filter_flags_map_to_one_filter_and_refuse_what_it_does_not_take() {
        use shpb_core::reduce::Filter;
        let names = [
            "--filter",
            "--filter-cutoff",
            "--filter-order",
            "--filter-window",
            "--smooth",
        ];
        let choose = |f, s, c, o, w| filter_choice(f, s, c, o, w, names);
        // No flag: the default; --smooth alone: the moving average of that width (0: none).
        assert_eq!(
            choose(None, None, None, None, None).unwrap().0,
            Filter::DEFAULT
        );
        assert_eq!(
            choose(None, Some(3e-6), None, None, None).unwrap(),
            (Filter::MovingAverage { width_s: None }, 3e-6)
        );
        assert_eq!(
            choose(Some("butterworth"), None, Some(1e5), Some(2), None)
                .unwrap()
                .0,
            Filter::Butterworth {
                order: 2,
                cutoff_hz: Some(1e5)
            }
        );
        // A parameter the filter does not take is named.
        for (args, flag) in [
            (
                (Some("butterworth"), Some(2e-6), None, None, None),
                "--smooth",
            ),
            (
                (Some("savitzky-golay"), None, Some(1e5), None, None),
                "--filter-cutoff",
            ),
            ((Some("none"), None, None, Some(3), None), "--filter-order"),
            (
                (Some("moving-average"), Some(1e-6), None, None, Some(2e-6)),
                "--filter-window",
            ),
            ((Some("kalman"), None, None, None, None), "--filter"),
        ] {
            let (f, s, c, o, w) = args;
            match choose(f, s, c, o, w) {
                Err(Error::Input { key, .. }) => assert_eq!(key, flag, "{args:?}"),
                other => panic!("{args:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn command_flags_name_the_choices_made() {
        let default = RecordOptions::default().command_flags();
        // The filter is always named (provenance), with its parameters.
        assert_eq!(
            default,
            " --align geometric --filter butterworth --filter-order 4"
        );
        let smoothed = RecordOptions {
            filter: shpb_core::reduce::Filter::MovingAverage { width_s: None },
            smoothing_s: 2e-6,
            baseline: shpb_core::reduce::Baseline::LinearDrift,
            ..RecordOptions::default()
        }
        .command_flags();
        assert_eq!(
            smoothed,
            " --align geometric --filter moving-average --smooth 2e-6 --baseline linear-drift"
        );
        let balance = RecordOptions {
            dispersion: shpb_core::reduce::DispersionCorrection::PochhammerChree,
            alignment: shpb_core::reduce::Alignment::Balance,
            balance_bound_s: 3e-5,
            cylinder: Some(shpb_core::reduce_cylinder::CylinderGeometry {
                length_m: 6e-3,
                diameter_m: 1.2e-2,
            }),
            ..RecordOptions::default()
        }
        .command_flags();
        assert_eq!(
            balance,
            " --dispersion pochhammer-chree --align balance --filter butterworth --filter-order 4 \
             --balance-bound 3e-5 \
             --specimen-length 6e-3 --specimen-diameter 1.2e-2"
        );
    }
}
