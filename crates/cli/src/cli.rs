//! The `shpb` command line (clap derive): `run`, `curve`. Errors go to stderr with a non-zero exit
//! code (2 bad input, 3 numerical instability, 1 other failures).

use shpb_core::contact::LawKind;
use shpb_core::fidelity::Fidelity;
use shpb_core::run::RunOutput;
use shpb_core::scene::{Params, SceneParams};
use shpb_input::prelude::*;
use shpb_input::specimen::resolve_pair;
use shpb_input::{Error, Result, Validator};
use shpb_output::io::check_output;
use shpb_output::writer::{Csv, Hdf5, Png, Writer};
use clap::{Parser, Subcommand, ValueEnum};
use std::io::Write;
use std::path::{Path, PathBuf};

const SCENES_HELP: &str = "\
SCENE KINDS (TOML files with a `kind` key; see README.md for full examples):
  quasistatic    F(δ) of the loading law up to max_displacement_m (paper Fig. 2)
  constant-rate  spheres pressed at constant approach speed, rate hardening on (Fig. 3)
  collision      two free spheres with initial velocities; reports coefficient of
                 restitution, contact time, peak force and energy dissipated
  force-driven   the paper's Fig. 4 DEM: a force history from CSV drives sphere 1,
                 sphere 2 rests on a linear medium of impedance Z (default: the
                 authors' transmission bar, 1.12e4 kg/s)
Every scene has a [specimen] table (pair = \"ss440c\" or sphere1/sphere2 tables) and an
optional law = \"burgoyne-daraio\" | \"rate-independent\" | \"hertz\".

EXIT CODES: 0 success, 1 I/O or HDF5 failure, 2 bad input (file, key and allowed range are
named), 3 numerical instability (step, time and quantity are named).";

/// shpb — split Hopkinson pressure bar virtual experiments (Burgoyne & Daraio 2014 contact law).
#[derive(Parser, Debug)]
#[command(name = "shpb", version, about, after_help = SCENES_HELP)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The contact laws selectable on the command line.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum LawArg {
    /// Eq. 1 with Johnson–Cook rate hardening (the paper's model).
    BurgoyneDaraio,
    /// Eq. 1 with the static yield stress.
    RateIndependent,
    /// Elastic Hertz.
    Hertz,
}

/// The fidelity presets selectable on the command line (`--fidelity`).
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum FidelityArg {
    /// Coarse grids: a first look in milliseconds.
    Fast,
    /// The default: converged to better than 0.1 % in peak force and displacement at peak.
    Standard,
    /// Fine grids and the Love-rod bars: the yardstick.
    Reference,
}

impl From<FidelityArg> for Fidelity {
    fn from(f: FidelityArg) -> Fidelity {
        match f {
            FidelityArg::Fast => Fidelity::Fast,
            FidelityArg::Standard => Fidelity::Standard,
            FidelityArg::Reference => Fidelity::Reference,
        }
    }
}

impl From<LawArg> for LawKind {
    fn from(l: LawArg) -> LawKind {
        match l {
            LawArg::BurgoyneDaraio => LawKind::BurgoyneDaraio,
            LawArg::RateIndependent => LawKind::RateIndependent,
            LawArg::Hertz => LawKind::Hertz,
        }
    }
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run a scene file and write its results (HDF5, optional CSV and PNG).
    #[command(after_help = SCENES_HELP)]
    Run {
        /// The scene TOML file.
        scene: PathBuf,
        /// HDF5 output file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Also write the contact history as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Also draw a PNG of force against displacement.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Overwrite existing output files.
        #[arg(long)]
        force: bool,
        /// Fidelity preset (wins over the scene's `fidelity`; explicit knobs in the scene win
        /// over both).
        #[arg(long, value_enum)]
        fidelity: Option<FidelityArg>,
    },
    /// Run a scene on a ladder of resolutions: error of each level against the finest, run
    /// time, observed order of convergence and Richardson extrapolation.
    Convergence {
        /// The scene TOML file (collision, force-driven, pulse or shpb).
        scene: PathBuf,
        /// CSV table output.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// PNG of error against run time.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Overwrite existing output files.
        #[arg(long)]
        force: bool,
    },
    /// Time the fidelity presets of a full test against `reference`, price the physics knobs,
    /// and measure memory against bar length: the table to pick a preset with.
    Bench {
        /// A `shpb` scene file.
        #[arg(default_value = "scenes/shpb-ss440c-10psi.toml")]
        scene: PathBuf,
        /// Runs per timing (median reported; `reference` runs once).
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Also write the tables as markdown to this file.
        #[arg(long)]
        report: Option<PathBuf>,
        /// Overwrite an existing report.
        #[arg(long)]
        force: bool,
    },
    /// Run a scene over the Cartesian product of swept parameters, in parallel, and write a
    /// summary table (peak force, displacement at peak, peak strain rate, equilibrium ratio,
    /// time to equilibrium) per run.
    Sweep {
        /// The scene TOML file.
        scene: PathBuf,
        /// A swept key: KEY=V1,V2,… or KEY=START:STOP:COUNT (units as in scenes; lengths of
        /// `_m` keys in mm/um/m), e.g. pressure=5psi:20psi:16. Repeat for a product.
        #[arg(long = "set", required = true)]
        set: Vec<String>,
        /// Worker threads.
        #[arg(short = 'j', long = "jobs", default_value_t = 1)]
        jobs: usize,
        /// Run only shard k of n (k/n): every n-th run from the k-th, deterministic.
        #[arg(long)]
        shard: Option<String>,
        /// HDF5 output: /summary table and one /runs/<index> group per run.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// CSV of the summary table.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Summary PNG: peak force and strain rate against the swept parameter (one) or as
        /// heat maps (two).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Continue an interrupted sweep from its checkpoint (`<output>.partial.csv`) without
        /// redoing finished runs.
        #[arg(long)]
        resume: bool,
        /// Overwrite existing output files.
        #[arg(long)]
        force: bool,
    },
    /// Join the HDF5 files of the shards of one sweep into one file.
    Merge {
        /// The shards' HDF5 files (written by `shpb sweep --shard k/n -o …`).
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// The merged HDF5 file.
        #[arg(short, long)]
        output: PathBuf,
        /// Also write the merged summary as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Overwrite existing output files.
        #[arg(long)]
        force: bool,
    },
    /// Print the loading curve F(δ) of a specimen as CSV on stdout.
    Curve {
        /// Built-in material (the paper's 6.35 mm pair of it) or a pair .toml file.
        #[arg(long, default_value = "ss440c")]
        specimen: String,
        /// Global strain rate for Johnson–Cook hardening, 1/s (0: quasi-static).
        // Negative numbers are parsed (not taken for options) so the range check can name them.
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        rate: f64,
        /// Largest approach δ, m.
        #[arg(long, default_value_t = 250e-6, allow_negative_numbers = true)]
        to: f64,
        /// Number of points.
        #[arg(long, default_value_t = 101)]
        points: usize,
        /// Contact law.
        #[arg(long, value_enum, default_value = "burgoyne-daraio")]
        law: LawArg,
    },
    /// Print the striker velocity the gas gun gives at a pressure (units psi, kPa, Pa, MPa, bar).
    Gun {
        /// Gauge pressure with unit, e.g. 10psi or 68.9kPa.
        #[arg(long, allow_hyphen_values = true)]
        pressure: String,
        /// Bar set-up file with the gun's parameters.
        #[arg(long, default_value = "bars/authors.toml")]
        bars: PathBuf,
    },
    /// Work out the incident pulse that loaded the spheres from a force–approach record.
    ///
    /// Reads a CSV with time_s, displacement_m and force_N (a Fig. 4 record, or `shpb run --csv`
    /// of a test) and prints the incident stress pulse at the specimen face it implies,
    /// σI = F/A + ρ c0 δ̇/2 (equal forces on both faces): peak, plateau, width, impulse, energy,
    /// and the unshaped striker that would give it. With --pressure, also whether the set-up's
    /// striker at the gun's velocity can deliver that impulse and energy at all.
    Incident {
        /// The force–approach CSV.
        record: PathBuf,
        /// Bar set-up file (bar material and diameter; striker and gun for --pressure).
        #[arg(long, default_value = "bars/authors.toml")]
        bars: PathBuf,
        /// Gas-gun pressure of the test, with unit (e.g. 10psi), to test the set-up's striker.
        #[arg(long, allow_hyphen_values = true)]
        pressure: Option<String>,
        /// Time span of the central difference for δ̇ and of the force average, µs.
        #[arg(long, default_value_t = 4.0, allow_hyphen_values = true)]
        smoothing_us: f64,
    },
    /// Reduce a gauge record like the lab: forces at both faces, sphere approach, strain rate.
    ///
    /// Accepts the authors' raw CSV (time_s, incident_V, transmission_V) or an HDF5 file written by
    /// `shpb run` (/time, /gauges/{incident,transmission}/strain). Writes /reduction/{time,
    /// displacement, force_front, force_back, force_3wave, strain_rate, equilibrium_ratio,
    /// approach_velocity}.
    Reduce {
        /// The record (.csv or .h5).
        record: PathBuf,
        /// Bar set-up file (bars, gauge distances, bridge, gain, polarity).
        #[arg(long, default_value = "bars/authors.toml")]
        bars: PathBuf,
        /// HDF5 output.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// CSV output.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Skip the Bancroft dispersion correction.
        #[arg(long)]
        no_dispersion: bool,
        /// Overwrite existing output files.
        #[arg(long)]
        force: bool,
    },
    /// Convert a raw gauge record (the authors' CSV: time_s, incident_V, transmission_V) to bar strain.
    Strain {
        /// The record.
        record: PathBuf,
        /// Bar set-up file whose gauge channels (bridge, gain, polarity) read the record.
        #[arg(long, default_value = "bars/authors.toml")]
        bars: PathBuf,
        /// HDF5 output (/time, /gauges/<name>/{strain,voltage}).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// CSV output.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Overwrite existing output files.
        #[arg(long)]
        force: bool,
    },
    /// Run the validation cases (paper Figs. 2–4, gauge records, Hertz, restitution): prints
    /// case, metric, value, threshold and pass/fail; exits non-zero if a check fails.
    Validate {
        /// Cases to run (default: all): fig2-quasistatic, fig3-rate, fig4-force-driven,
        /// fig4-virtual-shpb, gauge-records, hertz-analytic, restitution.
        cases: Vec<String>,
        /// Also write DIR/REPORT.md and one PNG per case.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
        /// Overwrite existing report files.
        #[arg(long)]
        force: bool,
    },
}

/// Parses the command line, runs it, prints errors; returns the process exit code.
pub fn main() -> i32 {
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("shpb: error: {e}");
            e.exit_code()
        }
    }
}

/// Runs one parsed command.
pub fn dispatch(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run {
            scene,
            output,
            csv,
            plot,
            force,
            fidelity,
        } => run(
            &scene,
            output.as_deref(),
            csv.as_deref(),
            plot.as_deref(),
            force,
            fidelity.map(Fidelity::from),
        ),
        Command::Bench {
            scene,
            repeats,
            report,
            force,
        } => {
            if let Some(p) = &report {
                check_output(p, force)?;
            }
            let b = shpb_study::bench::bench(&scene, repeats, |s| eprintln!("shpb: bench: {s}"))?;
            let md = shpb_study::bench::markdown(&b);
            say(&md)?;
            if let Some(p) = &report {
                shpb_output::io::write_text_atomically(p, force, &md)?;
                eprintln!("wrote {}", p.display());
            }
            Ok(())
        }
        Command::Sweep {
            scene,
            set,
            jobs,
            shard,
            output,
            csv,
            plot,
            resume,
            force,
        } => sweep(
            &scene,
            &set,
            jobs,
            shard.as_deref(),
            (output.as_deref(), csv.as_deref(), plot.as_deref()),
            resume,
            force,
        ),
        Command::Merge {
            inputs,
            output,
            csv,
            force,
        } => merge(&inputs, &output, csv.as_deref(), force),
        Command::Convergence {
            scene,
            output,
            plot,
            force,
        } => convergence(&scene, output.as_deref(), plot.as_deref(), force),
        Command::Curve {
            specimen,
            rate,
            to,
            points,
            law,
        } => curve(&specimen, rate, to, points, law.into()),
        Command::Gun { pressure, bars } => gun(&pressure, &bars),
        Command::Incident {
            record,
            bars,
            pressure,
            smoothing_us,
        } => incident(&record, &bars, pressure.as_deref(), smoothing_us),
        Command::Reduce {
            record,
            bars,
            output,
            csv,
            no_dispersion,
            force,
        } => {
            require_bars_file(&bars)?;
            crate::cmd::reduce::reduce_command(
                &record,
                &bars,
                output.as_deref(),
                csv.as_deref(),
                force,
                no_dispersion,
            )
        }
        Command::Strain {
            record,
            bars,
            output,
            csv,
            force,
        } => strain(&record, &bars, output.as_deref(), csv.as_deref(), force),
        Command::Validate {
            cases,
            report,
            force,
        } => validate(&cases, report.as_deref(), force),
    }
}

/// Prints a line on stdout; a closed pipe (`shpb … | head`) is not an error.
fn say(line: &str) -> Result<()> {
    let stdout = std::io::stdout();
    let mut w = stdout.lock();
    match writeln!(w, "{line}") {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::io(Path::new("stdout"), e))
        }
        _ => Ok(()),
    }
}

/// Reads a bar set-up file named on the command line.
fn load_apparatus(bars: &Path) -> Result<shpb_core::apparatus::Apparatus> {
    require_bars_file(bars)?;
    shpb_core::apparatus::Apparatus::from_file(bars)
}

/// Names `--bars` and what is allowed when the set-up file named on the command line is missing.
fn require_bars_file(bars: &Path) -> Result<()> {
    if !bars.is_file() {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--bars".into(),
            problem: format!("cannot read {}: no such file", bars.display()),
            allowed: "a bar set-up .toml file such as bars/authors.toml".into(),
        });
    }
    Ok(())
}

/// The `--pressure` option read and checked against the set-up's gun: (gauge pressure Pa,
/// striker velocity m/s).
fn gun_shot(apparatus: &shpb_core::apparatus::Apparatus, pressure: &str) -> Result<(f64, f64)> {
    let p = shpb_input::units::cli_pressure(pressure)?;
    let v = apparatus
        .striker_velocity_m_s(p)
        .map_err(Validator::new("command line").core("--pressure"))?;
    Ok((p, v))
}

fn gun(pressure: &str, bars: &Path) -> Result<()> {
    let apparatus = load_apparatus(bars)?;
    let (p, v) = gun_shot(&apparatus, pressure)?;
    let e = 0.5 * apparatus.striker_mass_kg() * v * v;
    let z = apparatus.material.density_kg_m3 * apparatus.material.wave_speed_m_s();
    say(&format!(
        "pressure            {:.4} psi = {:.1} kPa (gauge)",
        p / shpb_core::striker::PSI_PA,
        p / 1e3
    ))?;
    say(&format!("striker velocity    {v:.4} m/s"))?;
    say(&format!(
        "striker energy      {e:.4} J (mass {:.4} kg)",
        apparatus.striker_mass_kg()
    ))?;
    say(&format!(
        "elastic bar stress  {:.2} MPa (ρ c0 v / 2, without shaper)",
        0.5 * z * v / 1e6
    ))?;
    Ok(())
}

/// `shpb incident`: the incident pulse a force–approach record implies (reduce::implied_incident).
fn incident(record: &Path, bars: &Path, pressure: Option<&str>, smoothing_us: f64) -> Result<()> {
    let apparatus = load_apparatus(bars)?;
    let smoothing_s = Validator::new("command line").in_range(
        "--smoothing-us",
        smoothing_us,
        0.0,
        1000.0,
        "µs",
    )? * 1e-6;
    // Every input is checked before anything is printed.
    let gun_velocity = match pressure {
        Some(text) => Some(gun_shot(&apparatus, text)?.1),
        None => None,
    };
    let table = shpb_input::csv::CsvTable::read(record)?;
    let time = table.time_column("time_s")?;
    let bar = shpb_core::reduce::ReductionSetup::from_apparatus(&apparatus)?.incident_bar;
    let pulse = shpb_core::reduce::implied_incident(
        time,
        table.column("displacement_m")?,
        table.column("force_N")?,
        &bar,
        smoothing_s,
    )
    .ok_or_else(|| Error::Input {
        file: table.file.clone(),
        key: "force_N".into(),
        problem: "the record implies no compressive incident pulse".into(),
        allowed: "a loading record: force and approach growing from the start".into(),
    })?;
    let c0 = bar.wave_speed_m_s;
    let rho_c = bar.youngs_modulus_pa / c0;
    say(&format!(
        "record              {} ({} samples, {:.3} µs apart)",
        record.display(),
        time.len(),
        (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64 * 1e6
    ))?;
    say(&format!(
        "incident peak       {:.1} MPa at {:.1} µs",
        pulse.peak_pa / 1e6,
        pulse.peak_time_s * 1e6
    ))?;
    say(&format!(
        "plateau             {:.1} MPa (mean over the width at half peak)",
        pulse.mean_over_half_pa / 1e6
    ))?;
    say(&format!(
        "width at half peak  {:.1} µs",
        pulse.duration_half_s * 1e6
    ))?;
    say(&format!("impulse             {:.4} N s", pulse.impulse_n_s))?;
    say(&format!("energy              {:.3} J", pulse.energy_j))?;
    // An unshaped striker of the bar's impedance gives a square pulse: ρ c0 v / 2 for 2 L / c0.
    let length_m = 0.5 * c0 * pulse.duration_half_s;
    let velocity = 2.0 * pulse.mean_over_half_pa / rho_c;
    let mass = apparatus.material.density_kg_m3 * bar.area_m2 * length_m;
    say(&format!(
        "unshaped striker    {:.3} m at {:.2} m/s would give that plateau and width \
         (momentum {:.3} N s, energy {:.2} J)",
        length_m,
        velocity,
        mass * velocity,
        0.5 * mass * velocity * velocity
    ))?;
    if let Some(v0) = gun_velocity {
        let m = apparatus.striker_mass_kg();
        let most = shpb_core::striker::most_pulse_energy_j(m, v0, pulse.impulse_n_s);
        say(&format!(
            "set-up's striker    {:.3} m, {:.4} kg at {v0:.3} m/s: momentum {:.3} N s, energy {:.2} J",
            apparatus.striker.length_m,
            m,
            m * v0,
            0.5 * m * v0 * v0
        ))?;
        say(&format!(
            "  giving this impulse it can put at most {most:.2} J into the bar: {}",
            if pulse.energy_j > most {
                "the record's pulse is NOT possible with this striker at this pressure"
            } else {
                "possible"
            }
        ))?;
    }
    Ok(())
}

fn strain(
    record: &Path,
    bars: &Path,
    output: Option<&Path>,
    csv: Option<&Path>,
    force: bool,
) -> Result<()> {
    for p in [output, csv].into_iter().flatten() {
        check_output(p, force)?;
    }
    let apparatus = load_apparatus(bars)?;
    let rec = shpb_core::gauge::RawRecord::read(record)?;
    let mut gauges = Vec::new();
    for (name, volts) in [
        ("incident", &rec.incident_v),
        ("transmission", &rec.transmission_v),
    ] {
        let ch = apparatus.gauges.channel(name).ok_or_else(|| Error::Input {
            file: apparatus.source.clone(),
            key: "gauges".into(),
            problem: format!("no `{name}` channel in the gauge set-up"),
            allowed: "channels named incident and transmission".into(),
        })?;
        gauges.push(shpb_core::run::GaugeTrace {
            name: name.to_string(),
            strain: ch.strains_from_voltages(volts),
            voltage_v: volts.clone(),
        });
    }
    let out = RunOutput {
        contact: None,
        time_s: Some(rec.time_s.clone()),
        gauges,
        energy: Vec::new(),
        bars: Vec::new(),
        summary: Vec::new(),
        reduction: None,
        warnings: Vec::new(),
    };
    let text = format!(
        "record = \"{}\"\nbars = \"{}\"\n",
        record.display(),
        bars.display()
    );
    if let Some(p) = output {
        shpb_output::io::write_hdf5(p, force, &text, &out)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = csv {
        shpb_output::io::write_csv(p, force, &out)?;
        eprintln!("wrote {}", p.display());
    }
    if output.is_none() && csv.is_none() {
        let peak = |s: &[f64]| s.iter().cloned().fold(0.0, f64::min);
        say(&format!(
            "{} samples; most compressive strain: incident {:.4e}, transmission {:.4e}",
            rec.time_s.len(),
            peak(&out.gauges[0].strain),
            peak(&out.gauges[1].strain)
        ))?;
    }
    Ok(())
}

fn run(
    scene: &Path,
    output: Option<&Path>,
    csv: Option<&Path>,
    plot: Option<&Path>,
    force: bool,
    fidelity: Option<Fidelity>,
) -> Result<()> {
    for p in [output, csv, plot].into_iter().flatten() {
        check_output(p, force)?;
    }
    let params = Params::from_file_with(scene, fidelity)?;
    let mut out = params.run()?;
    out.warnings.splice(0..0, params.warnings());
    for w in &out.warnings {
        eprintln!("shpb: warning: {w}");
    }
    print_summary(&params, &out)?;
    if let Some(p) = output {
        Hdf5.write_run(p, force, &params, &out)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = csv {
        Csv.write_run(p, force, &params, &out)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = plot {
        Png.write_run(p, force, &params, &out)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// Prints the run summary; a closed pipe (`shpb run … | head`) is not an error.
fn print_summary(params: &Params, out: &RunOutput) -> Result<()> {
    let stdout = std::io::stdout();
    let mut w = stdout.lock();
    let mut text = if matches!(&params.params, SceneParams::Pulse { options, .. } if options.specimen.is_none())
    {
        format!("scene: {} (kind {})\n", params.source, params.kind)
    } else {
        format!(
            "scene: {} (kind {}, law {})\n",
            params.source,
            params.kind,
            params.contact_law().name()
        )
    };
    for it in &out.summary {
        text.push_str(&format!(
            "  {:<40} {:>14.6e} {}\n",
            it.key, it.value, it.unit
        ));
    }
    if let (Some(c), Some(r)) = (&out.contact, &out.reduction) {
        let k = c.peak_index();
        text.push_str(&format!(
            "result: peak force {:.3} kN (true contact) / {:.3} kN (reduced back force); \
             displacement at peak force {:.1} µm / {:.1} µm; equilibrium ratio at peak {:.3}\n",
            c.force_n[k] * 1e-3,
            r.peak_back_force_n * 1e-3,
            c.displacement_m[k] * 1e6,
            r.displacement_at_peak_force_m * 1e6,
            r.equilibrium_ratio_at_peak
        ));
    }
    match w.write_all(text.as_bytes()).and_then(|_| w.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::io(Path::new("stdout"), e))
        }
        _ => Ok(()),
    }
}

fn curve(specimen: &str, rate: f64, to: f64, points: usize, law: LawKind) -> Result<()> {
    let v = Validator::new("command line");
    let pair = resolve_pair(specimen, Path::new("."), &v, "--specimen")?;
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
    let s = shpb_core::solver::loading_curve(law.as_ref(), to, points, rate);
    let stdout = std::io::stdout();
    let mut w = std::io::BufWriter::new(stdout.lock());
    let written = (|| -> std::io::Result<()> {
        writeln!(w, "displacement_m,force_N")?;
        for (d, f) in s.displacement_m.iter().zip(&s.force_n) {
            writeln!(w, "{d:e},{f:e}")?;
        }
        w.flush()
    })();
    match written {
        // A closed pipe (`shpb curve | head`) is not an error.
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::io(Path::new("stdout"), e))
        }
        _ => Ok(()),
    }
}

/// `shpb convergence`: runs the ladder with a progress line per level, prints the table, writes
/// the CSV and the error-against-run-time plot.
fn convergence(
    scene: &Path,
    output: Option<&Path>,
    plot: Option<&Path>,
    force: bool,
) -> Result<()> {
    for p in [output, plot].into_iter().flatten() {
        check_output(p, force)?;
    }
    let study = shpb_study::convergence::study(scene, |i, value| {
        eprintln!("shpb: convergence level {} ({value:e})", i + 1);
    })?;
    let table = shpb_study::convergence::table_text(&study);
    say(&table)?;
    if let Some(p) = output {
        shpb_study::convergence::write_csv(p, force, &study)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = plot {
        shpb_study::convergence::plot(p, force, &study)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// `shpb validate [CASE…] [--report DIR] [--force]` (issue 7): see [`shpb_validate::command`].
fn validate(cases: &[String], report: Option<&Path>, force: bool) -> Result<()> {
    shpb_validate::command(cases, report, force)
}

/// `shpb sweep`: validates every point first, runs the unfinished ones with a progress bar and a
/// checkpoint, prints and writes the summary table.
fn sweep(
    scene: &Path,
    set: &[String],
    jobs: usize,
    shard: Option<&str>,
    (output, csv, plot): (Option<&Path>, Option<&Path>, Option<&Path>),
    resume: bool,
    force: bool,
) -> Result<()> {
    use shpb_study::sweep::{Checkpoint, check_points, parse_axis, parse_shard, product, run_points};
    if !resume {
        for p in [output, csv, plot].into_iter().flatten() {
            check_output(p, force)?;
        }
    }
    if !scene.is_file() {
        return Err(Error::Input {
            file: "command line".into(),
            key: "SCENE".into(),
            problem: format!("cannot read {}: no such file", scene.display()),
            allowed: "a scene .toml file".into(),
        });
    }
    let axes = set
        .iter()
        .map(|s| parse_axis(s))
        .collect::<Result<Vec<_>>>()?;
    if plot.is_some() && axes.len() > 2 {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--plot".into(),
            problem: format!("{} swept parameters", axes.len()),
            allowed: "one (line plot) or two (heat map) --set parameters".into(),
        });
    }
    let mut points = product(&axes);
    let mut spec = set.to_vec();
    if let Some(s) = shard {
        let (k, n) = parse_shard(s)?;
        points = shpb_study::sweep::shard(points, k, n);
        spec.push(format!("shard {k}/{n}"));
    }
    check_points(scene, &axes, &points)?;
    let anchor = output.or(csv);
    if resume && anchor.is_none() {
        return Err(Error::Input {
            file: "command line".into(),
            key: "--resume".into(),
            problem: "no output to resume".into(),
            allowed: "the same -o/--csv as the interrupted sweep".into(),
        });
    }
    let checkpoint = match anchor {
        Some(a) => Some(Checkpoint::open(
            a,
            scene,
            &spec,
            axes.len(),
            resume,
            force,
        )?),
        None => None,
    };
    let mut rows = checkpoint.as_ref().map(|c| c.1.clone()).unwrap_or_default();
    let finished: std::collections::HashSet<usize> = rows.iter().map(|r| r.index).collect();
    let todo: Vec<_> = points
        .into_iter()
        .filter(|p| !finished.contains(&p.index))
        .collect();
    if resume {
        eprintln!(
            "shpb: resuming: {} runs done, {} to go",
            rows.len(),
            todo.len()
        );
    }
    let bar = indicatif::ProgressBar::new(todo.len() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} runs, ETA {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    let failed = std::sync::Mutex::new(None);
    let new_rows = run_points(scene, &axes, &todo, jobs, |row| {
        if let Some((c, _)) = &checkpoint
            && let Err(e) = c.record(row)
        {
            *failed.lock().unwrap_or_else(|e| e.into_inner()) = Some(e);
        }
        bar.inc(1);
    })?;
    bar.finish_and_clear();
    if let Some(e) = failed.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    rows.extend(new_rows);
    rows.sort_by_key(|r| r.index);
    let keys: Vec<String> = axes.iter().map(|a| a.key.clone()).collect();
    let table = shpb_study::sweep::summary_csv_keys(&keys, &rows);
    say(table.trim_end())?;
    let scene_text = std::fs::read_to_string(scene).map_err(|e| Error::io(scene, e))?;
    write_study(&scene_text, &spec, &keys, &rows, &table, (output, csv))?;
    if let Some(p) = plot {
        sweep_plot(p, resume || force, &axes, &rows)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some((c, _)) = checkpoint {
        c.finish()?;
    }
    Ok(())
}

/// Writes a study's summary `table` as CSV and its HDF5 (atomically; the outputs were checked
/// before the runs, so they are replaced here).
fn write_study(
    scene_text: &str,
    spec: &[String],
    keys: &[String],
    rows: &[shpb_study::sweep::RunSummary],
    table: &str,
    (output, csv): (Option<&Path>, Option<&Path>),
) -> Result<()> {
    if let Some(p) = csv {
        shpb_output::io::write_text_atomically(p, true, table)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = output {
        shpb_study::file::write_sweep_hdf5(p, true, scene_text, spec, keys, rows)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// `shpb merge`: joins shard files of one sweep (same scene and `--set`), sorted by run index.
fn merge(inputs: &[PathBuf], output: &Path, csv: Option<&Path>, force: bool) -> Result<()> {
    for p in [Some(output), csv].into_iter().flatten() {
        check_output(p, force)?;
    }
    let mut merged: Option<shpb_study::file::SweepFile> = None;
    for p in inputs {
        let part = shpb_study::file::read_sweep_hdf5(p)?;
        merged = Some(match merged {
            None => part,
            Some(mut m) => {
                if m.scene != part.scene
                    || m.sweep_without_shard() != part.sweep_without_shard()
                    || m.keys != part.keys
                {
                    return Err(Error::Input {
                        file: p.display().to_string(),
                        key: "sweep".into(),
                        problem: "not a shard of the same sweep as the first file (scene or --set differ)".into(),
                        allowed: "shards of one `shpb sweep` (same scene and --set, different --shard)".into(),
                    });
                }
                m.rows.extend(part.rows);
                m
            }
        });
    }
    let mut m = merged.expect("clap requires at least one input");
    m.rows.sort_by_key(|r| r.index);
    m.rows.dedup_by_key(|r| r.index);
    let table = shpb_study::sweep::summary_csv_keys(&m.keys, &m.rows);
    let spec = m.sweep_without_shard();
    write_study(
        &m.scene,
        &spec,
        &m.keys,
        &m.rows,
        &table,
        (Some(output), csv),
    )?;
    eprintln!("merged {} runs", m.rows.len());
    Ok(())
}

/// The summary plot of a finished sweep (rows of a sharded sweep that are missing stay blank).
fn sweep_plot(
    path: &Path,
    force: bool,
    axes: &[shpb_study::sweep::Axis],
    rows: &[shpb_study::sweep::RunSummary],
) -> Result<()> {
    let numeric = |a: &shpb_study::sweep::Axis| -> Result<Vec<f64>> {
        a.labels
            .iter()
            .map(|l| {
                shpb_study::sweep::number_and_unit(l)
                    .map(|(v, _)| v)
                    .ok_or_else(|| Error::Input {
                        file: "command line".into(),
                        key: "--plot".into(),
                        problem: format!("`{l}` of {} is not a number", a.key),
                        allowed: "numeric swept values".into(),
                    })
            })
            .collect()
    };
    let label = |a: &shpb_study::sweep::Axis| {
        let unit = a
            .labels
            .first()
            .and_then(|l| shpb_study::sweep::number_and_unit(l))
            .map(|(_, u)| u)
            .unwrap_or_default();
        if unit.is_empty() {
            a.key.clone()
        } else {
            format!("{} ({unit})", a.key)
        }
    };
    let nx = axes[0].labels.len();
    let ny = axes.get(1).map(|a| a.labels.len()).unwrap_or(1);
    let mut f = vec![vec![f64::NAN; ny]; nx];
    let mut r = vec![vec![f64::NAN; ny]; nx];
    for row in rows {
        let (i, j) = (row.index / ny, row.index % ny);
        f[i][j] = row.peak_force_n;
        r[i][j] = row.peak_strain_rate_per_s;
    }
    let xv = numeric(&axes[0])?;
    let xl = label(&axes[0]);
    match axes.get(1) {
        None => shpb_output::plot::sweep_figure(path, force, (&xl, &xv), None, &f, &r),
        Some(a) => {
            let yv = numeric(a)?;
            let yl = label(a);
            shpb_output::plot::sweep_figure(path, force, (&xl, &xv), Some((&yl, &yv)), &f, &r)
        }
    }
}
