//! The result of one run ([`RunOutput`]): contact series, gauge traces, energies, bar
//! snapshots, scalar summary, the lab's reduction of simulated records, and warnings. Plain data:
//! the writers of `shpb-output` turn it into HDF5, CSV and PNG.

use crate::reduce::ReductionInput;
use crate::solver::ContactSeries;

/// What a run records beyond what its summary, its reduction and its warnings read (issue 45):
/// the bars' x–t snapshots are written only into a run file and drawn only by a figure, and
/// cost a sample per point every snapshot interval (40 % of a `standard` run), so the runs whose
/// only product is their summary leave them out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Outputs {
    /// Every series the scene asks for, the x–t snapshots at its `snapshot_interval_s` included
    /// (`shpb run -o`/`--plot`, the Python `shpb.run`).
    #[default]
    Full,
    /// The summary, the reduction, the warnings and the series they are computed from (gauges,
    /// energies, contact, specimen, chain), without the x–t snapshots: sweeps, studies, fits,
    /// designs, band runs, and `shpb run` writing neither a run file nor a figure.
    Summary,
}

impl Outputs {
    /// The outputs `shpb run` needs: [`Outputs::Full`] when it writes a run file (`-o`, which
    /// stores `/bars/*/snapshots`) or a figure (`--plot`, which draws the x–t diagram), else
    /// [`Outputs::Summary`] (the summary table, `--json`, `--csv`: none reads the snapshots).
    pub fn for_files(run_file: bool, figure: bool) -> Outputs {
        if run_file || figure {
            Outputs::Full
        } else {
            Outputs::Summary
        }
    }
}

/// A scalar result of a run (peak force, restitution, …) with its unit.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryItem {
    /// Name, snake_case (used as HDF5 attribute name).
    pub key: String,
    /// Value in SI units.
    pub value: f64,
    /// Unit (`N`, `m`, `1`, …).
    pub unit: &'static str,
    /// The 90 % band [low, high] the set-up's uncertainty gives the value (docs/physics.md
    /// §10.6), in the same unit; None: not computed.
    pub band_90: Option<[f64; 2]>,
}

/// Shorthand constructor of a [`SummaryItem`].
pub fn item(key: &str, value: f64, unit: &'static str) -> SummaryItem {
    SummaryItem {
        key: key.to_string(),
        value,
        unit,
        band_90: None,
    }
}

/// The output of one scene run, ready to be written.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// The `/contact` time series (absent for scenes without spheres).
    pub contact: Option<ContactSeries>,
    /// The `/time` axis of the gauge and energy series, s.
    pub time_s: Option<Vec<f64>>,
    /// `/gauges/<name>/{strain,voltage}`.
    pub gauges: Vec<GaugeTrace>,
    /// `/energy/<name>`, J, on the `/time` axis.
    pub energy: Vec<(String, Vec<f64>)>,
    /// `/bars/<name>/{snapshots,x,time}`: decimated x–t stress fields.
    pub bars: Vec<crate::solver::BarSnapshots>,
    /// Scalar results (attributes of `/summary`).
    pub summary: Vec<SummaryItem>,
    /// The lab's reduction of the simulated gauge records (`/reduction/*`), full SHPB tests only.
    pub reduction: Option<crate::reduce::Reduction>,
    /// Things the user should know about the run (`/summary` attribute `warnings`, one per line).
    pub warnings: Vec<String>,
    /// `/chain/*`: every contact and sphere of a chain of spheres (chain scenes).
    pub chain: Option<ChainSeries>,
    /// `/drive/{time,force}`: the force a recorded incident wave applied at the incident bar's
    /// impact end (`[incident_record]` scenes, docs/physics.md §6.10).
    pub drive: Option<DriveSeries>,
    /// A cylinder's own true stress, strain and strain rate, its plastic and friction work
    /// (docs/physics.md §6.12), beside the lab's reduction of it.
    pub specimen: Option<crate::solver::SpecimenSeries>,
    /// The lab's 1/2/3-wave reduction of a cylinder (docs/physics.md §7.8).
    pub cylinder_reduction: Option<crate::reduce_cylinder::CylinderReduction>,
}

/// The prescribed force on the incident bar's impact end, one value per time step (the force of
/// level n acts at t = n Δt), as the solver applied it: the recorded incident wave after its
/// edge taper and band limit (docs/physics.md §6.10).
#[derive(Debug, Clone, PartialEq)]
pub struct DriveSeries {
    /// Times of the levels, s.
    pub time_s: Vec<f64>,
    /// Force toward +x (compression of the bar) at each level, N.
    pub force_n: Vec<f64>,
}

pub use crate::solver::record::ChainSeries;

/// One recorded gauge channel: bar strain and the digitised voltage on the `/time` axis.
#[derive(Debug, Clone, PartialEq)]
pub struct GaugeTrace {
    /// Channel name.
    pub name: String,
    /// Bar strain at the gauge (positive in tension), noise-free.
    pub strain: Vec<f64>,
    /// Recorded voltage: bridge, amplifier, noise and quantisation, V.
    pub voltage_v: Vec<f64>,
}

impl RunOutput {
    /// An output with only a contact series and a summary.
    pub fn contact_only(contact: ContactSeries, summary: Vec<SummaryItem>) -> RunOutput {
        RunOutput {
            contact: Some(contact),
            time_s: None,
            gauges: Vec::new(),
            energy: Vec::new(),
            bars: Vec::new(),
            summary,
            reduction: None,
            warnings: Vec::new(),
            chain: None,
            drive: None,
            specimen: None,
            cylinder_reduction: None,
        }
    }
}

/// The true contact of a simulated test and the lab's reduction of its records, compared over
/// the same window: the reduction's (the first loading pulse, from the incident foot's arrival at
/// the specimen face for the window's length). A run longer than that window (`end_time_s =
/// 10e-3`) loads the spheres again when the waves come back; those later impacts are outside
/// both sides of the comparison.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeakComparison {
    /// Largest true contact force within the window, N.
    pub true_peak_force_n: f64,
    /// True approach at that force, m.
    pub true_displacement_at_peak_m: f64,
    /// Simulation time of that force, s.
    pub true_peak_time_s: f64,
    /// Largest reduced back (transmitted) force, N.
    pub reduced_peak_force_n: f64,
    /// Reduced approach at that force, m.
    pub reduced_displacement_at_peak_m: f64,
    /// Reduced equilibrium ratio at that force.
    pub equilibrium_ratio_at_peak: f64,
    /// The window on the simulation clock (start, end), s.
    pub window_s: (f64, f64),
}

impl RunOutput {
    /// The value of the summary item `key` (`shpb run`'s summary lines), if the run has it.
    pub fn summary_value(&self, key: &str) -> Option<f64> {
        self.summary.iter().find(|i| i.key == key).map(|i| i.value)
    }

    /// The true and the reduced peak force of a full test over the same window (the reduction's
    /// window, [`PeakComparison`]); None without a reduction or a timed contact history.
    pub fn peak_comparison(&self) -> Option<PeakComparison> {
        let r = self.reduction.as_ref()?;
        let c = self.contact.as_ref()?;
        let t = c.time_s.as_ref()?;
        let start = r.face_time_offset_s;
        let end = start + r.windows.duration_s;
        let k = (0..t.len())
            .filter(|&i| t[i] >= start && t[i] <= end)
            .max_by(|&a, &b| c.force_n[a].total_cmp(&c.force_n[b]))?;
        Some(PeakComparison {
            true_peak_force_n: c.force_n[k],
            true_displacement_at_peak_m: c.displacement_m[k],
            true_peak_time_s: t[k],
            reduced_peak_force_n: r.peak_back_force_n,
            reduced_displacement_at_peak_m: r.displacement_at_peak_force_m,
            equilibrium_ratio_at_peak: r.equilibrium_ratio_at_peak,
            window_s: (start, end),
        })
    }
}

// The reduction input of a run lives with the run, so that `reduce` does not depend on `run`.
impl ReductionInput {
    /// The noise-free gauge strains of a simulated test (`/gauges/{incident,transmission}/strain`
    /// of `shpb run`), if it recorded both channels.
    pub fn from_noise_free_gauges(out: &RunOutput) -> Option<ReductionInput> {
        let strain = |name: &str| {
            out.gauges
                .iter()
                .find(|g| g.name == name)
                .map(|g| g.strain.clone())
        };
        Some(ReductionInput {
            time_s: out.time_s.clone()?,
            incident_strain: strain("incident")?,
            transmission_strain: strain("transmission")?,
        })
    }
}
