//! The `shpb` command line (clap derive): the subcommands' options, [`main`] and [`dispatch`];
//! each subcommand is implemented in its own file of [`crate::cmd`]. Errors go to stderr with a
//! non-zero exit code (2 bad input, 3 numerical instability, 4 a design search without a
//! solution, 5 a design whose solutions violate a `--require`, 130/143 stopped by SIGINT/SIGTERM,
//! 1 other failures).

use crate::cmd;
use clap::{Args, Parser, Subcommand, ValueEnum};
use shpb_core::contact::LawKind;
use shpb_core::fidelity::Fidelity;
use shpb_core::reduce::DispersionCorrection;
use shpb_input::Result;
use std::path::PathBuf;

use crate::cmd::common::DEFAULT_BARS;

/// The help text after the options of `shpb --help` and `shpb run --help`: the scene kinds (from
/// [`shpb_input::kinds::names_and_help`]), the built-in set-ups and the exit codes.
fn scenes_help() -> String {
    let kinds = shpb_input::kinds::names_and_help();
    let width = kinds
        .iter()
        .map(|(n, _)| n.chars().count())
        .max()
        .unwrap_or(0);
    let mut text = String::from(
        "SCENE KINDS (TOML files with a `kind` key; see README.md for full examples):\n",
    );
    for (name, help) in kinds {
        text.push_str(&format!("  {name:<width$}  {help}\n"));
    }
    text.push_str(
        "Every scene with spheres has a [specimen] table (pair = \"ss440c\" or sphere1/sphere2 \
         tables) and an\noptional law = \"burgoyne-daraio\" | \"rate-independent\" | \"hertz\". \
         Scenes with bars name their set-up\n",
    );
    text.push_str(&format!(
        "with bars = a built-in set-up ({}) or a set-up file.\n",
        shpb_input::builtin::setup_names()
    ));
    text.push_str("`shpb list` lists the built-in materials, set-ups and scene kinds.\n\n");
    text.push_str(
        "EXIT CODES: 0 success, 1 I/O or HDF5 failure, 2 bad input (file, key and allowed range are\n\
         named; a missing input file too), 3 numerical instability (step, time and quantity are named),\n\
         4 `shpb design` found no input meeting the target, 5 its solutions violate a --require.\n\
         OUTPUT: results on stdout (`--json`: one JSON object), messages, warnings and `wrote PATH`\n\
         on stderr; an output path `-` writes that file to stdout.",
    );
    text
}

/// shpb — split Hopkinson pressure bar virtual experiments (Burgoyne & Daraio 2014 contact law).
#[derive(Parser, Debug)]
#[command(name = "shpb", version, about, after_help = scenes_help())]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// No result table and no `wrote` lines (warnings and errors still go to stderr).
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// Print the result of `run`, `reduce`, `incident`, `sweep`, `study`, `design`, `calibrate` and `fit`
    /// as one JSON object on stdout (refused by the other commands).
    #[arg(long, global = true)]
    pub json: bool,
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

/// The dispersion corrections of `shpb reduce --dispersion`.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum DispersionArg {
    /// No correction.
    None,
    /// The authors' six-parameter Bancroft fit for ν = 0.31.
    Bancroft,
    /// The exact Pochhammer–Chree first mode for the bars' Poisson's ratio.
    PochhammerChree,
}

impl From<DispersionArg> for DispersionCorrection {
    fn from(d: DispersionArg) -> DispersionCorrection {
        match d {
            DispersionArg::None => DispersionCorrection::None,
            DispersionArg::Bancroft => DispersionCorrection::Bancroft,
            DispersionArg::PochhammerChree => DispersionCorrection::PochhammerChree,
        }
    }
}

/// The window alignments of `shpb reduce` (`--align`; docs/physics.md §7.6).
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum AlignArg {
    /// Delays from the gauge distances and c0 (the lab's rule).
    Geometric,
    /// Delays from the feet of the reflected and transmitted pulses in the record.
    Foot,
    /// Geometric delays shifted (each within --balance-bound) to balance front and back forces over
    /// the incident pulse.
    Balance,
}

impl From<AlignArg> for shpb_core::reduce::Alignment {
    fn from(a: AlignArg) -> Self {
        use shpb_core::reduce::Alignment;
        match a {
            AlignArg::Geometric => Alignment::Geometric,
            AlignArg::Foot => Alignment::Foot,
            AlignArg::Balance => Alignment::Balance,
        }
    }
}

/// The wave separations of `shpb reduce` (`--wave-separation`; docs/physics.md §7.11).
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum WaveSeparationArg {
    /// No separation: each wave cut from its gauge record in its own window.
    None,
    /// One gauge per bar, unrolling each bar's far-end echoes (free or absorbing far end).
    OneGauge,
    /// Two gauges per bar: the set-up's channels `incident_2` and `transmission_2`.
    TwoGauge,
}

impl From<WaveSeparationArg> for shpb_core::reduce::WaveSeparation {
    fn from(a: WaveSeparationArg) -> Self {
        use shpb_core::reduce::WaveSeparation;
        match a {
            WaveSeparationArg::None => WaveSeparation::None,
            WaveSeparationArg::OneGauge => WaveSeparation::OneGauge,
            WaveSeparationArg::TwoGauge => WaveSeparation::TwoGauge,
        }
    }
}

/// The fidelity presets selectable on the command line (`--fidelity`).
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum FidelityArg {
    /// Coarse grids: a first look in milliseconds.
    Fast,
    /// The default: converged to better than 0.1 % in peak force and displacement at peak.
    Standard,
    /// Exact first-mode dispersion on delay lines at 1 mm (the Love-rod chain at 0.125 mm where
    /// the bars cannot be delay lines): the yardstick.
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

/// A whole number for a count option (`--samples`, `--repeats`, ...), with `allow_hyphen_values`
/// so that `-4` reaches it: clap's own messages ("unexpected argument '-4' found", "invalid digit
/// found in string") name no range, this one names `allowed`. The range itself is checked where
/// the option is used (`allowed` repeats it).
fn whole_number<T: std::str::FromStr>(
    allowed: &'static str,
) -> impl Fn(&str) -> std::result::Result<T, String> + Clone + Send + Sync + 'static {
    move |text: &str| {
        text.trim().parse::<T>().map_err(|_| {
            let what = if text.trim().parse::<i128>().is_ok_and(|v| v < 0) {
                "negative"
            } else {
                "not a whole number"
            };
            format!("`{text}` is {what}; allowed: {allowed}")
        })
    }
}

/// `-j/--jobs`: worker threads of `sweep` and `study` (one definition for both).
#[derive(Args, Debug, Clone, Copy)]
pub struct Jobs {
    /// Worker threads: 1 up to 4 per core of the machine (more is refused, exit 2)
    #[arg(
        short = 'j',
        long = "jobs",
        default_value_t = 1,
        allow_hyphen_values = true,
        value_parser = whole_number::<usize>("1 up to 4 worker threads per core of the machine")
    )]
    pub jobs: usize,
}

/// Subcommands.
// One value, parsed once per process: `reduce`'s many flags make it the largest variant, and
// boxing them would buy nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run a scene file and write its results (HDF5, optional CSV and PNG).
    #[command(after_help = scenes_help())]
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
        /// Set a scene key for this run: KEY=VALUE, as one value of `shpb sweep --set` (units
        /// as in scenes; lengths of `_m` keys in mm/um/m), e.g. pressure=12.5psi. Repeatable;
        /// `striker_velocity_m_s` replaces the scene's `pressure` and `pressure` its
        /// `striker_velocity_m_s`. The run file stores the scene with the values set.
        #[arg(long = "set")]
        set: Vec<String>,
        /// Skip the 90 % bands a set-up with an `[uncertainty]` table (or a gun
        /// `velocity_scatter`) gives the summary: two more summary-only runs per uncertain
        /// input (docs/physics.md §10.6).
        #[arg(long)]
        no_bands: bool,
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
        /// Runs per timing (median reported), 1 to 1000.
        #[arg(long, default_value_t = 5, allow_hyphen_values = true,
              value_parser = whole_number::<usize>("1 to 1000 runs per timing"))]
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
        /// Fidelity preset of every run, as `shpb run --fidelity` (the same as `--set
        /// fidelity=NAME`, whose column the summary then carries).
        #[arg(long, value_enum)]
        fidelity: Option<FidelityArg>,
        /// Worker threads (`-j`).
        #[command(flatten)]
        jobs: Jobs,
        /// Run only shard k of n (k/n): every n-th run from the k-th, deterministic.
        #[arg(long, allow_hyphen_values = true)]
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
    /// Propagate the scene's uncertainties: draw its distributions (`{ mean = "12.5psi", sd =
    /// "0.6psi" }`, `{ min, max }`, `{ median, gsd }`, `{ values = [..] }`) and the gun's
    /// shot-to-shot scatter by a seeded Latin hypercube, run each sample, and print each summary
    /// quantity's mean, sd, 5/50/95 % percentiles and first-order sensitivity indices.
    Study {
        /// The scene TOML file.
        scene: PathBuf,
        /// Samples (runs), 2 to 1000000.
        #[arg(long, default_value_t = 32, allow_hyphen_values = true,
              value_parser = whole_number::<usize>("2 to 1000000 samples"))]
        samples: usize,
        /// Seed of the Latin hypercube: the same seed gives the same samples and files.
        #[arg(long, default_value_t = 1, allow_hyphen_values = true,
              value_parser = whole_number::<u64>("a whole number from 0 to 18446744073709551615"))]
        seed: u64,
        /// Worker threads (`-j`).
        #[command(flatten)]
        jobs: Jobs,
        /// Do not draw the gun's shot-to-shot scatter (the set-up's `[gun] velocity_scatter`,
        /// applied by default when the scene's pressure is one value).
        #[arg(long)]
        no_gun_scatter: bool,
        /// Fidelity preset of every run, as `shpb run --fidelity` (wins over the scene's
        /// `fidelity`; explicit knobs in the scene win over both).
        #[arg(long, value_enum)]
        fidelity: Option<FidelityArg>,
        /// HDF5 output: the runs (/summary table, /runs/<index>), the study in its `sweep` attribute.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// CSV of the runs: the inputs drawn (SI units) and the summary of each run.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// CSV of the statistics: quantity, unit, n, mean, sd, p5, p50, p95, S_<input>.
        #[arg(long)]
        summary: Option<PathBuf>,
        /// PNG of the bands (5 / 50 / 95 %): contact force against approach on loading, reduced
        /// back force and transmission gauge strain against time.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Overwrite existing output files.
        #[arg(long)]
        force: bool,
    },
    /// Find the input of a scene that meets a target summary quantity: the target bracketed at
    /// the bounds and solved at the `fast` preset (Illinois method), confirmed and polished at
    /// `standard` (secant); with a second --vary, the first is solved at a grid of the second.
    /// Exit 4: no input within the bounds meets the target; 5: the solutions violate a --require.
    Design {
        /// The scene TOML file.
        scene: PathBuf,
        /// QUANTITY=VALUE[unit], a summary quantity of `shpb sweep` (peak_force,
        /// displacement_at_peak, peak_strain_rate, equilibrium_ratio_at_peak,
        /// time_to_equilibrium), e.g. peak_force=10kN.
        #[arg(long, allow_hyphen_values = true)]
        target: String,
        /// KEY=LO:HI, the input searched (units and aliases as `shpb sweep --set`), e.g.
        /// pressure=7psi:20psi; a second --vary is set on a grid (--grid) and the first solved
        /// at each value.
        #[arg(long = "vary", required = true, allow_hyphen_values = true)]
        vary: Vec<String>,
        /// A constraint checked at each solution: QUANTITY<VALUE (<, <=, >, >=), e.g.
        /// 'equilibrium_ratio<0.05'. Repeat for several.
        #[arg(long, allow_hyphen_values = true)]
        require: Vec<String>,
        /// Accepted |quantity − target|, relative to the target: a percentage or a fraction.
        #[arg(long, default_value = "0.2%", allow_hyphen_values = true)]
        tol: String,
        /// Values of the second --vary (bounds included) at which the first is solved, 2 to 50
        /// [default: 5]; only with a second --vary.
        #[arg(long, allow_hyphen_values = true,
              value_parser = whole_number::<usize>("2 to 50 values of the second --vary"))]
        grid: Option<usize>,
        /// The most runs one 1-D search may use (fast and standard together), 3 to 1000.
        #[arg(long, default_value_t = 20, allow_hyphen_values = true,
              value_parser = whole_number::<usize>("3 to 1000 runs per 1-D search"))]
        max_runs: usize,
    },
    /// Fit free scene keys (a specimen's constants, nuisance values) to records: least squares,
    /// then posterior samples of an affine-invariant ensemble sampler, with a noise model
    /// estimated from the records (docs/physics.md §11). Prints each key's best fit and 90 %
    /// interval; writes the samples, correlations and predictive bands with -o.
    Fit {
        /// The scene TOML file (its own measured record, or the set-up that reduces --record).
        scene: PathBuf,
        /// KEY=MIN:MAX, a key `--set` reaches and its bounds (uniform prior), e.g.
        /// specimen.yield_stress_pa=1.5e9:2.3e9, pressure=8psi:12psi, or time_shift_s=-2e-6:2e-6
        /// (the model's time axis against the records'). Repeat for several.
        #[arg(long = "free", required = true, allow_hyphen_values = true)]
        free: Vec<String>,
        /// KEY=normal:MEAN:SD, a normal prior on a --free key (SI units), on top of its bounds.
        #[arg(long, allow_hyphen_values = true)]
        prior: Vec<String>,
        /// A record: a raw gauge record or run file (reduced through the scene's set-up), or a
        /// reduced curve as CSV (time_s with force_N, displacement_m, stress_Pa and strain, or
        /// reflected_strain and transmitted_strain). None: the scene's own (a force-driven
        /// scene whose CSV has displacement_m). Repeat for several.
        #[arg(long)]
        record: Vec<PathBuf>,
        /// What is compared: force-time, force-approach, stress-strain or strains [default:
        /// force-approach for a force-driven or contact scene, stress-strain for a cylinder
        /// test, force-time for spheres between bars].
        #[arg(long)]
        residual: Option<String>,
        /// HDF5 output: best fit, posterior samples, correlations, effective sample sizes,
        /// predictive bands.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// PNG of each record with the best fit and its 90 % posterior-predictive band.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// PNG of the posterior: each key's marginal and every pair's samples.
        #[arg(long)]
        corner: Option<PathBuf>,
        /// Walkers of the ensemble: even, at least twice the free keys [default: max(16, 4 × keys)].
        #[arg(long, allow_hyphen_values = true,
              value_parser = whole_number::<usize>("an even number of walkers, at least twice the free keys"))]
        walkers: Option<usize>,
        /// Sampler steps (each runs every walker once).
        #[arg(long, default_value_t = 200, allow_hyphen_values = true,
              value_parser = whole_number::<usize>("4 sampler steps or more"))]
        steps: usize,
        /// Steps dropped as burn-in [default: a quarter of --steps].
        #[arg(long, allow_hyphen_values = true,
              value_parser = whole_number::<usize>("fewer burn-in steps than --steps"))]
        burn_in: Option<usize>,
        /// Seed of the sampler.
        #[arg(long, default_value_t = 1, allow_hyphen_values = true,
              value_parser = whole_number::<u64>("a seed from 0 up"))]
        seed: u64,
        /// Worker threads [default: one per core]: 1 up to 4 per core of the machine.
        #[arg(short = 'j', long = "jobs", allow_hyphen_values = true,
              value_parser = whole_number::<usize>("1 up to 4 worker threads per core of the machine"))]
        jobs: Option<usize>,
        /// Continue a stopped fit from its checkpoint (FIT.h5.partial.h5, kept with -o every
        /// twentieth of the steps): the same command line with --resume.
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
        /// Built-in material or material .toml file (the paper's 6.35 mm pair of it), or a pair
        /// .toml file ([sphere1] and [sphere2]).
        #[arg(long, default_value = "ss440c")]
        specimen: String,
        /// Global strain rate for Johnson–Cook hardening, 1/s (0: quasi-static).
        // Values starting with `-` (-1, -1e-4, -.5) are taken as values, not options, so the
        // range check can name them (`allow_negative_numbers` misses `-1e-4` and `-.5`).
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        rate: f64,
        /// Largest approach δ, m.
        #[arg(long, default_value_t = 250e-6, allow_hyphen_values = true)]
        to: f64,
        /// Number of points.
        #[arg(long, default_value_t = 101, allow_hyphen_values = true)]
        points: i64,
        /// Contact law.
        #[arg(long, value_enum, default_value = "burgoyne-daraio")]
        law: LawArg,
    },
    /// Fit a set-up's constants to a lab's own shots and write the calibrated set-up.
    ///
    /// SHOTS is a TOML manifest: one [[shot]] table per record (`file`, and `pressure` with its
    /// unit and/or `striker_velocity_m_s`; optional `bars_together`, `label`, `layout`). Every
    /// calibration whose data the shots carry runs: wave speed and gauge distances from the
    /// pulses' arrivals, the incident strain factor from measured velocities (no shaper), the gun
    /// line from velocities against pressure, the Frew shaper (and the gun line, without
    /// velocities) from incident pulses at several pressures. Prints each constant with its
    /// 1-sigma and what it was fitted on; writes the --bars set-up with those values replaced
    /// (comments kept), an [uncertainty] table, and its gauge file beside it
    /// (SETUP-gauges.toml).
    Calibrate {
        /// The shots manifest (.toml); may be left out with `--paired`.
        shots: Option<PathBuf>,
        /// A shot's record in volts and the same shot in strain (e.g. a lab's raw_voltage and
        /// raw_microstrain files): each channel's strain per volt, written as a linear channel.
        #[arg(long, num_args = 2, value_names = ["VOLTS", "STRAINS"])]
        paired: Option<Vec<PathBuf>>,
        /// The base set-up whose other constants are kept: a built-in set-up or a set-up file.
        #[arg(long, default_value = DEFAULT_BARS)]
        bars: PathBuf,
        /// The calibrated set-up to write (.toml); its gauge file goes beside it.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// Overwrite existing files.
        #[arg(long)]
        force: bool,
    },
    /// Print the striker velocity the gas gun gives at a pressure (units psi, kPa, Pa, MPa, bar).
    ///
    /// The gas does the same work W(p) on any striker (½ m v² = W, docs/physics.md §6.4): also
    /// prints W, the striker's energy and momentum, the unshaped pulse, the same gun firing half
    /// and twice the set-up's striker, and the gun's constants.
    Gun {
        /// Gauge pressure with unit, e.g. 10psi or 68.9kPa.
        #[arg(long, allow_hyphen_values = true)]
        pressure: String,
        /// Bar set-up with the gun's parameters: a built-in set-up (`shpb list`) or a set-up file.
        #[arg(long, default_value = DEFAULT_BARS)]
        bars: PathBuf,
    },
    /// Work out the incident pulse that loaded the spheres from a force–approach record.
    ///
    /// Reads a CSV with time_s, displacement_m and force_N (a Fig. 4 record, or `shpb run --csv`
    /// of a test; or force_3wave_N, `shpb reduce --csv` of a gauge record, which gives the
    /// measured incident pulse) and prints the incident stress pulse at the specimen face it
    /// implies, σI = F/A + ρ c0 δ̇/2 (equal forces on both faces): peak, plateau, width, impulse,
    /// energy, the unshaped striker that would give it, and which striker its shape points to
    /// (rise over width: shaped, unshaped, inconclusive, or edge missing). With --pressure, also
    /// the pulse's energy over the gun's work (shaped or unshaped), whether the set-up's striker
    /// at the gun's velocity can deliver that impulse and energy at all, and what the gun gives
    /// the unshaped striker (docs/physics.md §6.4).
    Incident {
        /// The force–approach CSV.
        record: PathBuf,
        /// Bar set-up (bar material and diameter; striker and gun for --pressure): a built-in
        /// set-up (`shpb list`) or a set-up file.
        #[arg(long, default_value = DEFAULT_BARS)]
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
    /// Accepts the authors' raw CSV (time_s, incident_V, transmission_V), any text record with
    /// --layout, or an HDF5 file written by `shpb run` (its digitised /gauges/*/voltage read
    /// through the run's own bridges; a file without voltages by its /gauges/*/strain). Writes
    /// /reduction/{time, displacement, force_front, force_back, force_3wave, strain_rate,
    /// equilibrium_ratio, approach_velocity}; several records make a batch.
    Reduce {
        /// The records (.csv or .h5); several reduce as a batch (see --summary, --report).
        #[arg(required_unless_present = "channel", num_args = 1..)]
        record: Vec<PathBuf>,
        /// A record kept one file per oscilloscope channel, each with a header block (record
        /// length, sample interval, trigger, horizontal offset): ROLE=FILE, ROLE incident or
        /// transmission, repeated; a gauge's several files are averaged (e.g. gauges on opposite
        /// faces). Instead of RECORD.
        #[arg(long, value_name = "ROLE=FILE", conflicts_with_all = ["record", "layout"])]
        channel: Vec<std::ffi::OsString>,
        /// Bar set-up (bars, gauge distances, bridge, gain, polarity): a built-in set-up
        /// (`shpb list`) or a set-up file [default: a run file's own set-up, else `authors`].
        /// For a run file, a set-up that differs from the one it was simulated with is refused.
        #[arg(long)]
        bars: Option<PathBuf>,
        /// HDF5 output.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// CSV output.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Dispersion correction between gauges and faces: the Bancroft fit for ν = 0.31 (the
        /// authors'), the exact Pochhammer–Chree first mode for the bars' ν, or none.
        #[arg(long, value_enum, default_value_t = DispersionArg::Bancroft)]
        dispersion: DispersionArg,
        /// Deprecated: the same as `--dispersion none`.
        #[arg(long, conflicts_with = "dispersion")]
        no_dispersion: bool,
        /// Also apply the Tyas–Pope amplitude factors M1·M2 (exact first mode; needs a
        /// dispersion correction).
        #[arg(long)]
        tyas_pope: bool,
        /// Length of a cylindrical specimen, m (with --specimen-diameter): also its 1/2/3-wave
        /// stress, strain, strain rate and true stress/strain (/reduction/cylinder) [default: a
        /// run file's own cylinder, if it has one].
        #[arg(long, value_name = "L", allow_hyphen_values = true)]
        specimen_length: Option<f64>,
        /// Diameter of a cylindrical specimen, m (with --specimen-length).
        #[arg(long, value_name = "D", allow_hyphen_values = true)]
        specimen_diameter: Option<f64>,
        /// The specimen: a TOML file with a `[specimen]` table as in a scene (spheres of any
        /// diameter, a chain, or shape = "cylinder"): spheres give the strain rate δ̇/Σrᵢ over
        /// their radii, a cylinder its 1/2/3-wave curves [default: a run file's own specimen,
        /// else two 6.35 mm spheres]. Not with --specimen-length/--specimen-diameter.
        #[arg(long, value_name = "FILE.toml")]
        specimen: Option<PathBuf>,
        /// Figure of the reduction (one record): waves at the faces, forces, equilibrium, and
        /// force–approach with the strain rate (spheres) or stress–strain and strain rate (a
        /// cylinder).
        #[arg(long, value_name = "FILE.png")]
        plot: Option<PathBuf>,
        /// How the reflected and transmitted windows are placed: from the gauge distances, the
        /// record's pulse feet, or a bounded force-balance search (docs/physics.md §7.6).
        #[arg(long, value_enum, default_value = "geometric")]
        align: AlignArg,
        /// Width of the moving average applied to both records before the reduction, s (0: no
        /// filter): without --filter, `--filter moving-average` of this width (docs/physics.md
        /// §7.12).
        #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
        smooth: Option<f64>,
        /// Bound of `--align balance`'s search on each window shift, s (docs/physics.md §7.6)
        /// [default: 6e-5]; only with `--align balance`.
        #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
        balance_bound: Option<f64>,
        /// Incident window start on the record clock, s (overrides the detected foot).
        #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
        incident_start: Option<f64>,
        /// Reflected window start after the incident start, s (overrides --align for it).
        #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
        reflected_delay: Option<f64>,
        /// Transmitted window start after the incident start, s (overrides --align for it).
        #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
        transmitted_delay: Option<f64>,
        /// Window length, s (default: the longest clean window the record holds).
        #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
        duration: Option<f64>,
        /// How to read a text record that is not the authors' CSV: a layout file (header lines,
        /// delimiter, time column or sample rate, channel columns, units, polarities; README,
        /// "Record layouts"), e.g. layouts/authors-lvm.toml.
        #[arg(long, value_name = "FILE.toml")]
        layout: Option<PathBuf>,
        /// Batch summary: one CSV row per record (forces, δ at peak, strain rate, equilibrium
        /// verdict, windows, pulse metrics, warnings).
        #[arg(long, value_name = "FILE.csv")]
        summary: Option<PathBuf>,
        /// Batch report: Markdown with a table of the records and one figure per record
        /// (FILE-<record>.png beside it).
        #[arg(long, value_name = "FILE.md")]
        report: Option<PathBuf>,
        /// Overwrite existing output files.
        #[arg(long)]
        force: bool,
        /// A tension test (split Hopkinson tension bar, docs/physics.md §7.8.1): the incident
        /// pulse tensile, forces, stresses and strains reported tension positive; needs a
        /// cylinder specimen [default: a run file's own loading].
        #[arg(long)]
        tension: bool,
        /// Separate the waves travelling toward and away from the specimen at each face, for
        /// records whose pulses overlap at the gauges (docs/physics.md §7.11): from one gauge
        /// per bar and the bars' far-end echoes, or from two gauges per bar (the set-up's
        /// channels `incident_2`, `transmission_2`; a run file of that set-up records them).
        #[arg(long, value_enum, default_value = "none")]
        wave_separation: WaveSeparationArg,
        /// The zero-phase filter of both records (docs/physics.md §7.12) [default: butterworth,
        /// 4th order forward and backward at the bars' dispersion band, f a/c0 = 0.4]
        #[arg(long, value_name = "NAME",
              value_parser = ["none", "butterworth", "savitzky-golay", "moving-average"])]
        filter: Option<String>,
        /// Butterworth cut-off, Hz (one pass's gain 1/√2 there) [default: the bars' dispersion
        /// band, 0.4 c0/a]; only with --filter butterworth.
        #[arg(long, value_name = "HZ", allow_hyphen_values = true)]
        filter_cutoff: Option<f64>,
        /// Butterworth order per pass (1–12) [default: 4] or Savitzky–Golay polynomial order
        /// (0–8) [default: 3].
        #[arg(long, value_name = "N", allow_hyphen_values = true,
              value_parser = whole_number::<usize>("1 to 12 (butterworth) or 0 to 8 (savitzky-golay)"))]
        filter_order: Option<usize>,
        /// Savitzky–Golay window, s [default: 5e-6], or the moving average's width (as --smooth).
        #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
        filter_window: Option<f64>,
        /// How each record's baseline is removed: the mean of its pre-trigger samples, or a line
        /// through them and as many samples of its quiet tail (docs/physics.md §7.12).
        #[arg(long, value_name = "NAME", default_value = "start-mean",
              value_parser = ["start-mean", "linear-drift"])]
        baseline: String,
    },
    /// Convert a raw gauge record (the authors' CSV: time_s, incident_V, transmission_V) to bar strain.
    Strain {
        /// The record.
        record: PathBuf,
        /// Bar set-up whose gauge channels (bridge, gain, polarity) read the record: a built-in
        /// set-up (`shpb list`) or a set-up file.
        #[arg(long, default_value = DEFAULT_BARS)]
        bars: PathBuf,
        /// HDF5 output (/time, /gauges/<name>/{strain,voltage}).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// How to read a text record that is not the authors' CSV (see `shpb reduce --layout`).
        #[arg(long, value_name = "FILE.toml")]
        layout: Option<PathBuf>,
        /// Samples at the start of each channel whose mean is removed (the pre-trigger baseline,
        /// as `shpb reduce` removes it); 0 keeps the record's offsets.
        #[arg(long, value_name = "N", default_value_t = shpb_core::reduce::ReductionOptions::default().baseline_samples,
              allow_hyphen_values = true,
              value_parser = whole_number::<usize>("0 (keep the offsets) up to half the record's samples"))]
        baseline_samples: usize,
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
        /// Reference data: a directory holding `validation/` and `bars/` (a checkout of the
        /// repository); default: the copy built into the program.
        #[arg(long, value_name = "DIR")]
        data: Option<PathBuf>,
        /// Also write DIR/REPORT.md and one PNG per case.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
        /// Overwrite existing report files.
        #[arg(long)]
        force: bool,
    },
    /// List the built-in materials, the built-in bar set-ups and the scene kinds.
    List,
    /// Set-up files: `shpb setup new` writes one from the numbers a lab states.
    Setup {
        /// What to do.
        #[command(subcommand)]
        action: SetupAction,
    },
}

/// `shpb setup` subcommands.
#[derive(Subcommand, Debug)]
pub enum SetupAction {
    /// Write a complete, commented set-up file (bars, inline gauge channels, no gun) from a
    /// lab's stated numbers, in SI units; `--bars FILE` then reads it. Without a gauge factor or
    /// --strain-per-volt the channels read records in strain or microstrain only.
    New(SetupNewArgs),
}

/// The flags of `shpb setup new` (SI values).
#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct SetupNewArgs {
    /// The set-up file to write (.toml).
    #[arg(short, long)]
    output: PathBuf,
    /// Overwrite an existing file.
    #[arg(long)]
    force: bool,
    /// Bar diameter, m (incident, transmission and striker).
    #[arg(long)]
    diameter: f64,
    /// Bar Young's modulus, Pa.
    #[arg(long)]
    modulus: f64,
    /// Bar density, kg/m³.
    #[arg(long)]
    density: f64,
    /// Bar Poisson's ratio (default 0.3, said in the file).
    #[arg(long)]
    poisson: Option<f64>,
    /// Incident bar length, m.
    #[arg(long)]
    incident_length: f64,
    /// Transmission bar length, m.
    #[arg(long)]
    transmission_length: f64,
    /// Incident gauge distance from the specimen face, m.
    #[arg(long)]
    incident_gauge: f64,
    /// Transmission gauge distance from the specimen face, m.
    #[arg(long)]
    transmission_gauge: f64,
    /// Striker length, m (without it: a placeholder, said in the file).
    #[arg(long)]
    striker_length: Option<f64>,
    /// Bridge of both channels: quarter-axial, half-poisson, full-poisson (with --gauge-factor
    /// and --excitation) or linear (with --strain-per-volt).
    #[arg(long)]
    bridge: Option<String>,
    /// Gauge factor of the gauges.
    #[arg(long)]
    gauge_factor: Option<f64>,
    /// Bridge excitation, V.
    #[arg(long)]
    excitation: Option<f64>,
    /// Amplifier gain between bridge and recorder.
    #[arg(long)]
    gain: Option<f64>,
    /// Strain per volt at the recorder, tension positive (a linear channel).
    #[arg(long)]
    strain_per_volt: Option<f64>,
    /// Recorder sample rate, Hz (only virtual tests use it).
    #[arg(long)]
    sample_rate: Option<f64>,
}

/// Parses the command line, runs it, prints errors; returns the process exit code.
pub fn main() -> i32 {
    // First, before any thread starts: SIGINT/SIGTERM remove temporary files and say what stopped.
    crate::interrupt::install();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(&e),
    };
    match dispatch(cli) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("shpb: error: {e}");
            e.exit_code()
        }
    }
}

/// Prints a command-line parse error as every other error (`shpb: error: ` first, clap's usage
/// and tip lines after it) and returns its exit code (2); `--help` and `--version` print to
/// stdout with exit code 0, and a missing subcommand prints the help to stderr, then the error.
fn usage_error(e: &clap::Error) -> i32 {
    use clap::error::ErrorKind;
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            0
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            eprint!("{}", e.render());
            eprintln!(
                "shpb: error: no subcommand given; allowed: one of the commands listed above"
            );
            2
        }
        ErrorKind::InvalidUtf8 => {
            // clap names neither the argument nor the option: name both.
            eprintln!(
                "shpb: error: {}",
                invalid_utf8_argument(std::env::args_os())
            );
            2
        }
        _ => {
            // Rust's parse errors name no range: say what a value of the option looks like.
            let text = e
                .render()
                .to_string()
                .replace(
                    ": invalid float literal",
                    ": not a number; allowed: a plain number in the option's SI unit, without \
                     the unit (e.g. 0.019 for 19 mm; see the option's --help)",
                )
                .replace(
                    ": invalid digit found in string",
                    ": not a whole number; allowed: a whole number (see the option's --help)",
                );
            let text = text.strip_prefix("error: ").unwrap_or(&text);
            eprint!("shpb: error: {text}");
            if !text.ends_with('\n') {
                eprintln!();
            }
            2
        }
    }
}

/// The message for a command line with an argument that is not UTF-8: which argument, after
/// which option, shown lossily, and what is allowed (file names of scenes, records and outputs
/// may be any bytes; values and names of built-ins are text).
fn invalid_utf8_argument(args: impl Iterator<Item = std::ffi::OsString>) -> String {
    let args: Vec<std::ffi::OsString> = args.collect();
    let Some(i) = args.iter().position(|a| a.to_str().is_none()) else {
        return "an argument is not valid UTF-8; allowed: UTF-8 text".to_string();
    };
    let shown = args[i].to_string_lossy();
    let option = args[..i]
        .last()
        .and_then(|a| a.to_str())
        .filter(|a| a.starts_with('-'))
        .map(|o| format!(" (the value of `{o}`)"))
        .unwrap_or_default();
    format!(
        "argument {i} `{shown}`{option} is not valid UTF-8; allowed: UTF-8 text for option \
         values, names and keys (file names of scenes, records and outputs may be any bytes)"
    )
}

/// Runs one parsed command.
pub fn dispatch(cli: Cli) -> Result<()> {
    cmd::common::set_output_mode(cli.quiet, cli.json);
    // Standard output holds one thing: a command without a JSON result does not print its
    // table (or CSV) where JSON was asked for.
    let without_json = match &cli.command {
        Command::Convergence { .. } => Some("convergence"),
        Command::Bench { .. } => Some("bench"),
        Command::Merge { .. } => Some("merge"),
        Command::Curve { .. } => Some("curve"),
        Command::Gun { .. } => Some("gun"),
        Command::Strain { .. } => Some("strain"),
        Command::Validate { .. } => Some("validate"),
        Command::List => Some("list"),
        Command::Setup { .. } => Some("setup new"),
        _ => None,
    };
    if cli.json
        && let Some(name) = without_json
    {
        return Err(cmd::common::input_err(
            "command line",
            "--json",
            format!("`shpb {name}` has no JSON result"),
            "--json with run, reduce, incident, sweep, study, design, calibrate or fit",
        ));
    }
    match cli.command {
        Command::Setup {
            action: SetupAction::New(a),
        } => cmd::setup::new(
            &cmd::setup::SetupNew {
                diameter_m: a.diameter,
                modulus_pa: a.modulus,
                density_kg_m3: a.density,
                poisson: a.poisson,
                incident_length_m: a.incident_length,
                transmission_length_m: a.transmission_length,
                incident_gauge_m: a.incident_gauge,
                transmission_gauge_m: a.transmission_gauge,
                striker_length_m: a.striker_length,
                bridge: a.bridge,
                gauge_factor: a.gauge_factor,
                excitation_v: a.excitation,
                gain: a.gain,
                strain_per_volt: a.strain_per_volt,
                sample_rate_hz: a.sample_rate,
            },
            &a.output,
            a.force,
        ),
        Command::Run {
            scene,
            output,
            csv,
            plot,
            force,
            fidelity,
            set,
            no_bands,
        } => cmd::run::run(
            &scene,
            output.as_deref(),
            csv.as_deref(),
            plot.as_deref(),
            force,
            fidelity.map(Fidelity::from),
            &set,
            !no_bands,
        ),
        Command::Bench {
            scene,
            repeats,
            report,
            force,
        } => {
            if !(1..=1000).contains(&repeats) {
                return Err(shpb_study::api::input_err(
                    "--repeats",
                    format!("{repeats}"),
                    "1 to 1000 runs per timing",
                ));
            }
            cmd::bench::bench(&scene, repeats, report.as_deref(), force)
        }
        Command::Sweep {
            scene,
            mut set,
            fidelity,
            jobs,
            shard,
            output,
            csv,
            plot,
            resume,
            force,
        } => {
            // `--fidelity NAME` is the one-value axis `--set fidelity=NAME`.
            set.extend(fidelity.map(|f| format!("fidelity={}", Fidelity::from(f).name())));
            cmd::sweep::sweep(
                &scene,
                &set,
                jobs.jobs,
                shard.as_deref(),
                (output.as_deref(), csv.as_deref(), plot.as_deref()),
                resume,
                force,
            )
        }
        Command::Study {
            scene,
            samples,
            seed,
            jobs,
            no_gun_scatter,
            fidelity,
            output,
            csv,
            summary,
            plot,
            force,
        } => cmd::study::study(
            &scene,
            &shpb_study::uq::StudyPlan {
                samples,
                seed,
                gun_scatter: !no_gun_scatter,
                fidelity: fidelity.map(Fidelity::from),
            },
            jobs.jobs,
            cmd::study::StudyOutputs {
                output: output.as_deref(),
                csv: csv.as_deref(),
                summary: summary.as_deref(),
                plot: plot.as_deref(),
            },
            force,
        ),
        Command::Design {
            scene,
            target,
            vary,
            require,
            tol,
            grid,
            max_runs,
        } => {
            // A grid without a second --vary would be ignored without a word.
            if let Some(g) = grid
                && vary.len() < 2
            {
                return Err(shpb_study::api::input_err(
                    "--grid",
                    format!("{g} given with one --vary"),
                    "--grid N with a second --vary (the input set on the grid)",
                ));
            }
            cmd::design::design(
                &scene,
                &cmd::design::DesignOptions {
                    target: &target,
                    vary: &vary,
                    require: &require,
                    tol: &tol,
                    grid: grid.unwrap_or(5),
                    max_runs,
                },
            )
        }
        Command::Fit {
            scene,
            free,
            prior,
            record,
            residual,
            output,
            plot,
            corner,
            walkers,
            steps,
            burn_in,
            seed,
            jobs,
            resume,
            force,
        } => cmd::fit::fit(
            &scene,
            &cmd::fit::FitOptions {
                free: &free,
                prior: &prior,
                record: &record,
                residual: residual.as_deref(),
                output: output.as_deref(),
                plot: plot.as_deref(),
                corner: corner.as_deref(),
                force,
                resume,
                settings: shpb_study::fit::Settings {
                    walkers: walkers.unwrap_or(0),
                    steps,
                    burn_in,
                    seed,
                    jobs: jobs.unwrap_or_else(|| {
                        std::thread::available_parallelism().map_or(1, |n| n.get())
                    }),
                    ..shpb_study::fit::Settings::default()
                },
            },
        ),
        Command::Merge {
            inputs,
            output,
            csv,
            force,
        } => {
            // A missing shard or a directory: named as such, not by the HDF5 library's errno.
            if let Some(p) = inputs.iter().find(|p| !p.is_file()) {
                return Err(shpb_study::api::input_err(
                    "INPUTS",
                    format!(
                        "cannot read {}: {}",
                        p.display(),
                        shpb_input::files::not_a_file(p)
                    ),
                    "HDF5 files written by `shpb sweep --shard k/n -o`",
                ));
            }
            cmd::merge::merge(&inputs, &output, csv.as_deref(), force)
        }
        Command::Convergence {
            scene,
            output,
            plot,
            force,
        } => cmd::convergence::convergence(&scene, output.as_deref(), plot.as_deref(), force),
        Command::Curve {
            specimen,
            rate,
            to,
            points,
            law,
        } => cmd::curve::curve(&specimen, rate, to, points, law.into()),
        Command::Calibrate {
            shots,
            paired,
            bars,
            output,
            force,
        } => cmd::calibrate::calibrate(
            shots.as_deref(),
            paired.as_deref().map(|p| (p[0].as_path(), p[1].as_path())),
            &bars,
            &output,
            force,
        ),
        Command::Gun { pressure, bars } => cmd::gun::gun(&pressure, &bars),
        Command::Incident {
            record,
            bars,
            pressure,
            smoothing_us,
        } => cmd::incident::incident(&record, &bars, pressure.as_deref(), smoothing_us),
        Command::Reduce {
            record,
            bars,
            output,
            csv,
            dispersion,
            no_dispersion,
            tyas_pope,
            align,
            smooth,
            balance_bound,
            incident_start,
            reflected_delay,
            transmitted_delay,
            duration,
            summary,
            report,
            layout,
            specimen_length,
            specimen_diameter,
            specimen,
            plot,
            force,
            channel,
            tension,
            wave_separation,
            filter,
            filter_cutoff,
            filter_order,
            filter_window,
            baseline,
        } => {
            let channels = (!channel.is_empty())
                .then(|| shpb_input::channel_file::ChannelSet::from_specs(&channel, "--channel"))
                .transpose()?;
            let record = match &channels {
                Some(set) => vec![set.name()],
                None => record,
            };
            // A bound without the search it bounds would be ignored without a word.
            if let Some(b) = balance_bound
                && !matches!(align, AlignArg::Balance)
            {
                return Err(shpb_study::api::input_err(
                    "--balance-bound",
                    format!("{b} s given without --align balance"),
                    "--balance-bound SECONDS with --align balance",
                ));
            }
            let balance_bound = balance_bound.unwrap_or(shpb_core::reduce::DEFAULT_BALANCE_BOUND_S);
            let (reduction_filter, smoothing_s) = shpb_study::api::filter_choice(
                filter.as_deref(),
                smooth,
                filter_cutoff,
                filter_order,
                filter_window,
                [
                    "--filter",
                    "--filter-cutoff",
                    "--filter-order",
                    "--filter-window",
                    "--smooth",
                ],
            )?;
            let window = shpb_core::reduce::WindowOverride {
                incident_start_s: incident_start,
                reflected_delay_s: reflected_delay,
                transmitted_delay_s: transmitted_delay,
                duration_s: duration,
            };
            cmd::reduce::reduce_command(
                &record,
                bars.as_deref(),
                cmd::reduce::Outputs {
                    output: output.as_deref(),
                    csv: csv.as_deref(),
                    summary: summary.as_deref(),
                    report: report.as_deref(),
                    plot: plot.as_deref(),
                    force,
                },
                &shpb_study::api::RecordOptions {
                    dispersion: if no_dispersion {
                        DispersionCorrection::None
                    } else {
                        dispersion.into()
                    },
                    tyas_pope,
                    alignment: align.into(),
                    smoothing_s,
                    balance_bound_s: balance_bound,
                    window: (window != Default::default()).then_some(window),
                    layout: layout
                        .as_deref()
                        .map(shpb_input::layout::RecordLayout::from_file)
                        .transpose()?,
                    cylinder: shpb_study::api::cylinder_geometry(
                        specimen_length,
                        specimen_diameter,
                        ("--specimen-length", "--specimen-diameter"),
                    )?,
                    specimen: specimen
                        .as_deref()
                        .map(shpb_input::specimen_file::SpecimenFile::read)
                        .transpose()?,
                    channels,
                    tension,
                    wave_separation: wave_separation.into(),
                    filter: reduction_filter,
                    baseline: shpb_study::api::baseline_choice(&baseline, "--baseline")?,
                },
            )
        }
        Command::Strain {
            record,
            bars,
            output,
            layout,
            baseline_samples,
            csv,
            force,
        } => cmd::strain::strain(
            &record,
            &bars,
            cmd::strain::StrainOptions {
                layout: layout.as_deref(),
                baseline_samples,
            },
            output.as_deref(),
            csv.as_deref(),
            force,
        ),
        Command::Validate {
            cases,
            data,
            report,
            force,
        } => cmd::validate::validate(&cases, data.as_deref(), report.as_deref(), force),
        Command::List => cmd::list::list(),
    }
}
