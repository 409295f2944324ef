//! A validated virtual test ([`Params`]: specimen with its contact law, fidelity and the kind-specific
//! [`SceneParams`]) and how it runs into a [`RunOutput`]. Scene files are parsed into it by
//! `shpb-input`; nothing here reads a file.

use crate::apparatus::{Apparatus, PulseOptions};
use crate::bar::Dispersion;
use crate::contact::{Contact, Degenerate, LawKind, LawSpec, LoadingCurve};
use crate::error::{Error, Result, format_si};
use crate::fidelity::Fidelity;
use crate::material::JOHNSON_COOK_RATE_LIMIT_PER_S;
use crate::numeric::resample;
use crate::run::{Outputs, RunOutput, SummaryItem, item};
use crate::solver::{self, CollisionSetup, ContactSeries, ForceDrivenSetup, ForceHistory};
use crate::specimen::{MODEL_APPROACH_LIMIT_OF_RADIUS, Specimen, SpherePair};

/// Impedance Z = ρ c0 A of the authors' transmission bar (ρ 8110 kg/m³, c0 4865.5 m/s,
/// radius 9.525 mm; docs/physics.md §5), kg/s.
pub const AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S: f64 =
    8110.0 * 4865.5 * std::f64::consts::PI * 9.525e-3 * 9.525e-3;

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
    /// A free chain of N ≥ 2 spheres struck by its first sphere or a striker (docs/physics.md §8).
    Chain(Box<solver::FreeChainSetup>),
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
    /// The specimen with its own model (spheres with their contact law, or a cylinder); None
    /// for a `pulse` scene, which has none.
    pub specimen: Option<Specimen>,
    /// The fidelity preset the numerical knobs were taken from (explicit keys win).
    pub fidelity: Fidelity,
    /// Kind-specific parameters.
    pub params: SceneParams,
}

impl Params {
    /// The first pair of a sphere specimen and its contact law (None for a cylinder or no
    /// specimen).
    pub fn sphere_pair(&self) -> Option<(SpherePair, LawSpec)> {
        let sp = self.specimen.as_ref()?.spheres()?;
        Some((sp.first_pair(), sp.law))
    }

    /// The first pair and law of a sphere scene, or an error naming the scene.
    pub fn pair_and_law(&self) -> Result<(SpherePair, LawSpec)> {
        self.sphere_pair().ok_or_else(|| {
            crate::error::Named::new(self.source.clone()).error(
                "specimen",
                format!("a `{}` scene needs two spheres", self.kind),
                "a pair of spheres",
            )
        })
    }

    /// The contact law of this scene's first pair of spheres (None without spheres).
    pub fn contact_law(&self) -> Option<Box<dyn Contact>> {
        self.sphere_pair()
            .map(|(pair, law)| law.build(pair.contact_properties()))
    }

    /// Warnings about the scene that do not stop it (e.g. a pair whose law has no region II).
    pub fn warnings(&self) -> Vec<String> {
        if let Some(c) = self.specimen.as_ref().and_then(Specimen::cylinder) {
            return c
                .warnings()
                .into_iter()
                .map(|w| format!("{}: {w}", self.source))
                .collect();
        }
        let Some((pair, _)) = self.sphere_pair() else {
            return vec![];
        };
        let p = pair.contact_properties();
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

    /// Runs the scene; the output's warnings say where the run left the model's range of
    /// validity ([`Params::validity_warnings`]).
    pub fn run(&self) -> Result<RunOutput> {
        self.run_with_progress(&mut |_| true)
    }

    /// Runs the scene, calling `progress` with the fraction done (0 to 1) now and then during
    /// long solves (bar scenes: every 1 % of the steps); `progress` returning false stops the
    /// run with [`crate::Error::Cancelled`].
    pub fn run_with_progress(&self, progress: &mut dyn FnMut(f64) -> bool) -> Result<RunOutput> {
        let mut out = self.run_kind(progress)?;
        let validity = self.validity_warnings(&out);
        out.warnings.extend(validity);
        self.refuse_overlap(&out)?;
        explain_unavailable(&mut out);
        Ok(out)
    }

    /// Refuses a run whose spheres overlapped by the smaller sphere radius or more (issue 42:
    /// a 9999 m/s collision reached 27 mm of approach between 6.35 mm spheres): no contact law
    /// describes such an overlap, so every result of the run would be wrong. The scene readers
    /// refuse such closing speeds up front where they can (`solver::check_impact_speed`); this
    /// catches the drives they cannot bound (a force record, a gun, a yielding law that
    /// approaches further than Hertz).
    fn refuse_overlap(&self, out: &RunOutput) -> Result<()> {
        let radius = match &self.specimen {
            Some(Specimen::Spheres(sp)) => sp
                .chain
                .spheres
                .iter()
                .map(|s| s.radius_m)
                .fold(f64::INFINITY, f64::min),
            _ => return Ok(()),
        };
        let series = out
            .contact
            .iter()
            .flat_map(|c| c.displacement_m.iter().copied());
        let chain = out
            .chain
            .iter()
            .flat_map(|c| c.contact_approach_m.iter().flatten().copied());
        let approach = series.chain(chain).fold(0.0f64, f64::max);
        if approach >= radius {
            return Err(Error::Invalid {
                object: self.source.clone(),
                quantity: "sphere approach".into(),
                problem: format!(
                    "the run reached {} ({:.2} of the smaller sphere radius {}): spheres \
                     overlapping by a radius or more are outside every contact law, so no \
                     result of this run can be right",
                    format_si(approach, "m"),
                    approach / radius,
                    format_si(radius, "m"),
                ),
                allowed: "an approach below the smaller sphere radius: a lower drive \
                          (velocity1_m_s, pressure, striker_velocity_m_s or the force_csv \
                          record) or larger spheres"
                    .into(),
            });
        }
        Ok(())
    }

    /// Where a run of this scene left the range the model was fitted or calibrated over (each a
    /// warning, not an error): the sphere approach beyond
    /// [`MODEL_APPROACH_LIMIT_OF_RADIUS`] of the smaller sphere radius (the paper's FEM range);
    /// the global strain rate beyond [`JOHNSON_COOK_RATE_LIMIT_PER_S`] with rate hardening on;
    /// a gun pressure outside the pressures the set-up's gun, or its shaper's constants, were
    /// calibrated at.
    pub fn validity_warnings(&self, out: &RunOutput) -> Vec<String> {
        let mut w = Vec::new();
        let (pair, law) = match &self.params {
            SceneParams::Pulse {
                apparatus,
                pressure_pa,
                options,
            } => {
                let driven = options.incident_drive.is_some();
                if let Some((lo, hi)) = apparatus.gun_calibrated_pa
                    && !driven
                    && (*pressure_pa < lo || *pressure_pa > hi)
                {
                    let psi = crate::striker::PSI_PA;
                    w.push(format!(
                        "gun pressure {} is outside {}, the pressures the gun of {} was calibrated \
                         at (validation/pulse/REPORT.md): the striker velocity {} is extrapolated",
                        format_si(pressure_pa / psi, "psi"),
                        crate::error::format_range(lo / psi, hi / psi, "psi"),
                        apparatus.source,
                        format_si(options.striker_velocity_m_s, "m/s"),
                    ));
                }
                // A striker velocity given in the scene (no gun, pressure NaN): the shaper's
                // calibrated pressures as the striker velocities the set-up's gun gives at them.
                if let Some((lo, hi)) = options.shaper.and_then(|s| s.calibrated_pressure_pa)
                    && !driven
                    && pressure_pa.is_nan()
                    && let (Ok(v_lo), Ok(v_hi)) = (
                        apparatus.striker_velocity_m_s(lo),
                        apparatus.striker_velocity_m_s(hi),
                    )
                    && (options.striker_velocity_m_s < v_lo || options.striker_velocity_m_s > v_hi)
                {
                    w.push(format!(
                        "striker velocity {} is outside {}, the striker velocities the gun of {} \
                         gives at the pressures its pulse shaper was calibrated at \
                         (validation/pulse/REPORT.md): the incident pulse is an extrapolation of \
                         the shaper model",
                        format_si(options.striker_velocity_m_s, "m/s"),
                        crate::error::format_range(v_lo, v_hi, "m/s"),
                        apparatus.source,
                    ));
                }
                if let Some((lo, hi)) = options.shaper.and_then(|s| s.calibrated_pressure_pa)
                    && !driven
                    && (*pressure_pa < lo || *pressure_pa > hi)
                {
                    let psi = crate::striker::PSI_PA;
                    w.push(format!(
                        "gun pressure {} is outside {}, the pressures the pulse shaper of {} was \
                         calibrated at (validation/pulse/REPORT.md): the incident pulse is an \
                         extrapolation of the shaper model",
                        format_si(pressure_pa / psi, "psi"),
                        crate::error::format_range(lo / psi, hi / psi, "psi"),
                        apparatus.source,
                    ));
                }
                match self.sphere_pair() {
                    Some(p) => p,
                    None => return w,
                }
            }
            _ => match self.sphere_pair() {
                Some(p) => p,
                None => return w,
            },
        };
        let law = law.kind;
        let Some(contact) = &out.contact else {
            return w;
        };
        let radius = pair.sphere1.radius_m.min(pair.sphere2.radius_m);
        let limit = MODEL_APPROACH_LIMIT_OF_RADIUS * radius;
        let approach = contact
            .displacement_m
            .iter()
            .copied()
            .fold(0.0f64, f64::max);
        if approach > limit {
            w.push(format!(
                "the sphere approach reaches {} ({:.2} of the sphere radius {}), beyond {} \
                 ({MODEL_APPROACH_LIMIT_OF_RADIUS} R), the range of the finite-element runs the \
                 contact law was fitted to (paper Figs. 2–3: δ ≤ 0.19 R): the model is \
                 extrapolated",
                format_si(approach, "m"),
                approach / radius,
                format_si(radius, "m"),
                format_si(limit, "m"),
            ));
        }
        let rate_hardening =
            law == LawKind::BurgoyneDaraio && pair.contact_properties().rate.c > 0.0;
        let rate = match (&contact.strain_rate_per_s, &self.params) {
            (Some(r), _) => r.iter().copied().fold(0.0f64, f64::max),
            (
                None,
                SceneParams::Quasistatic {
                    strain_rate_per_s, ..
                },
            ) => *strain_rate_per_s,
            (None, _) => 0.0,
        };
        if rate_hardening && rate > JOHNSON_COOK_RATE_LIMIT_PER_S {
            w.push(format!(
                "the global strain rate reaches {}, beyond {}, the highest rate at which the \
                 Johnson–Cook constants were fitted or used (paper Fig. 4 tests up to 5.2e3 1/s, \
                 Fig. 3 FEM up to 1e4 1/s): the rate hardening is extrapolated",
                format_si(rate, "1/s"),
                format_si(JOHNSON_COOK_RATE_LIMIT_PER_S, "1/s"),
            ));
        }
        w
    }

    /// Runs the scene's kind (without the validity warnings).
    fn run_kind(&self, progress: &mut dyn FnMut(f64) -> bool) -> Result<RunOutput> {
        let contact = || -> Result<(SpherePair, Box<dyn Contact>)> {
            let (pair, law) = self.pair_and_law()?;
            let built = law.build(pair.contact_properties());
            Ok((pair, built))
        };
        match &self.params {
            SceneParams::Quasistatic {
                max_displacement_m,
                points,
                strain_rate_per_s,
            } => {
                let (_, law) = contact()?;
                let s = solver::loading_curve(
                    law.as_ref(),
                    *max_displacement_m,
                    *points,
                    *strain_rate_per_s,
                );
                let summary = vec![item("max_force", *s.force_n.last().unwrap_or(&0.0), "N")];
                Ok(RunOutput::contact_only(s, summary))
            }
            SceneParams::ConstantRate {
                strain_rate_per_s,
                max_displacement_m,
                points,
            } => {
                let (pair, law) = contact()?;
                let s = solver::constant_rate(
                    law.as_ref(),
                    &pair,
                    *strain_rate_per_s,
                    *max_displacement_m,
                    *points,
                );
                let summary = vec![
                    item("max_force", *s.force_n.last().unwrap_or(&0.0), "N"),
                    item(
                        "approach_speed",
                        strain_rate_per_s * (pair.sphere1.radius_m + pair.sphere2.radius_m),
                        "m/s",
                    ),
                ];
                Ok(RunOutput::contact_only(s, summary))
            }
            SceneParams::Collision(setup) => {
                let (pair, law) = contact()?;
                let r = solver::collision(law.as_ref(), &pair, setup)?;
                let p = pair.contact_properties();
                let tc = solver::hertz_impact_duration(
                    pair.reduced_mass_kg(),
                    p.e_star_pa,
                    p.radius_m,
                    setup.velocity1_m_s - setup.velocity2_m_s,
                );
                let mut warnings = Vec::new();
                let restitution = physical_restitution(r.restitution, "", &mut warnings);
                let summary = vec![
                    item("restitution", restitution, "1"),
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
                let mut out = RunOutput::contact_only(r.series, summary);
                out.warnings.extend(warnings);
                Ok(out)
            }
            SceneParams::Pulse {
                apparatus,
                pressure_pa,
                options,
            } => run_pulse(
                apparatus,
                *pressure_pa,
                options,
                self.specimen.as_ref(),
                progress,
            ),
            SceneParams::Chain(setup) => run_free_chain(setup, progress),
            SceneParams::ForceDriven {
                setup,
                measured_displacement_m,
            } => {
                let (pair, law) = contact()?;
                let r = solver::force_driven(law.as_ref(), &pair, setup)?;
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
                // Issue 42: a run that ends before the measured peak force compared its own
                // early approach with the measured one at peak (relative error −0.99999).
                let ran_to = r.series.time_s.as_ref().and_then(|t| t.last().copied());
                let peak_t = setup.drive.time_s[solver::argmax(&setup.drive.force_n)];
                let mut warnings = Vec::new();
                if measured_displacement_m.is_some() && ran_to.is_some_and(|t| t < peak_t) {
                    for s in summary.iter_mut().filter(|s| {
                        s.key.ends_with("relative_error") || s.key.ends_with("relative_error_paper")
                    }) {
                        s.value = f64::NAN;
                        warnings.push(format!(
                            "`{}` is not available (NaN): the run ends at {}, before the \
                             measured peak force at {}; raise end_time_s",
                            s.key,
                            format_si(ran_to.unwrap_or(0.0), "s"),
                            format_si(peak_t, "s"),
                        ));
                    }
                }
                let mut out = RunOutput::contact_only(r.series, summary);
                out.warnings.extend(warnings);
                Ok(out)
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
    /// Model approach at the time of the measured peak force (linear between samples), m.
    pub model_displacement_at_measured_peak_time_m: f64,
}

impl Fig4Comparison {
    /// Relative error of the model's displacement at peak force against the measured one,
    /// both counted from t = 0 (the measured offset δ(0) removed).
    pub fn relative_error(&self) -> f64 {
        let measured = self.measured_displacement_at_peak_m - self.measured_initial_displacement_m;
        (self.model_displacement_at_peak_m - measured) / measured
    }

    /// The same error in the paper's convention (its Fig. 4 comparison): the model's approach
    /// at the time of the measured peak force against the measured approach there, both counted
    /// from zero (the measured offset kept).
    pub fn paper_relative_error(&self) -> f64 {
        (self.model_displacement_at_measured_peak_time_m - self.measured_displacement_at_peak_m)
            / self.measured_displacement_at_peak_m
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
    let at_measured_peak = match &series.time_s {
        Some(t) => crate::numeric::resample(t, &series.displacement_m, &[drive.time_s[j]])[0],
        None => f64::NAN,
    };
    Fig4Comparison {
        model_peak_force_n: series.force_n[k],
        model_displacement_at_peak_m: series.displacement_m[k],
        measured_peak_force_n: drive.force_n[j],
        measured_displacement_at_peak_m: measured_displacement_m[j],
        measured_initial_displacement_m: measured_displacement_m[0],
        model_displacement_at_measured_peak_time_m: at_measured_peak,
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
        out.push(item(
            "displacement_at_measured_peak_relative_error_paper",
            c.paper_relative_error(),
            "1",
        ));
    }
    out
}

/// Runs a `pulse` scene: simulates the chain, digitises every gauge, and summarises each pulse.
fn run_pulse(
    apparatus: &Apparatus,
    pressure_pa: f64,
    options: &PulseOptions,
    specimen: Option<&Specimen>,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<RunOutput> {
    let chain = apparatus.pulse_chain(options, specimen);
    let spheres_specimen = specimen.and_then(Specimen::spheres);
    let cylinder = specimen.and_then(Specimen::cylinder);
    let steps = (chain.end_time_s / chain.dt_s).ceil() as usize;
    let mut report = crate::solver::record::Progress::new(steps, progress);
    // A chain specimen of three or more spheres also gets its `/chain` series (a pair's output
    // stays as it was: `/contact` holds its one contact).
    let spheres = spheres_specimen.map_or(0, |sp| sp.chain.len());
    let mut spheres_rec = (spheres >= 3).then(|| {
        crate::solver::record::SphereChainRecorder::new(
            &chain.joints,
            chain.record_every,
            chain.dt_s,
        )
    });
    let mut recorders: Vec<&mut dyn crate::solver::Recorder> = vec![&mut report];
    if let Some(rec) = spheres_rec.as_mut() {
        recorders.push(rec);
    }
    let mut r = crate::solver::simulate_chain_with(&chain, &mut recorders)?;
    // A tension test reports its specimen tension positive (docs/physics.md §6.13).
    let loading = options.loading;
    r.specimen = r.specimen.map(|s| s.in_loading_sense(loading));
    let e = apparatus.material.youngs_modulus_pa;
    let driven = options.incident_drive.is_some();
    let mut summary = if driven {
        // No gun and no striker: the energy put in is the drive's work (§6.10).
        vec![item(
            "drive_work",
            r.drive_work_j.last().copied().unwrap_or(0.0),
            "J",
        )]
    } else {
        // A striker velocity given in the scene: no gun, no pressure (NaN) to print.
        let pressure = (!pressure_pa.is_nan()).then(|| item("pressure", pressure_pa, "Pa"));
        pressure
            .into_iter()
            .chain([
                item("striker_velocity", options.striker_velocity_m_s, "m/s"),
                item("striker_energy", r.striker_energy_j, "J"),
                item(
                    "striker_final_velocity",
                    r.striker_final_velocity_m_s,
                    "m/s",
                ),
            ])
            .collect()
    };
    summary.push(item("time_step", chain.dt_s, "s"));
    // A seated specimen says how (§6.11): with a preload, `/contact` holds the whole force and
    // the gauges and the reduction the change from it.
    match spheres_specimen.map(|sp| sp.seating) {
        Some(crate::specimen::Seating::Gap { gap_m }) => {
            summary.push(item("seating_gap", gap_m, "m"));
        }
        Some(crate::specimen::Seating::Preload { force_n }) => {
            summary.push(item("seating_preload", force_n, "N"));
        }
        _ => {}
    }
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
        // The pulse of the loading's sign, its stress in the loading's sense (tension positive
        // in a tension test).
        if let Some(m) = crate::gauge::pulse_metrics(&t, &strain, !loading.is_tension()) {
            summary.push(item(
                &format!("{}_peak_stress", probe.name),
                -loading.sign() * e * m.peak,
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
        gauges.push(crate::run::GaugeTrace {
            name: probe.name.clone(),
            strain,
            voltage_v: v,
        });
        time = Some(t);
    }
    let t = time.unwrap_or_else(|| r.time_s.clone());
    // The energy put in so far: the striker's at the start, or the drive's work to date.
    let input = if driven {
        resample(&r.time_s, &r.drive_work_j, &t)
    } else {
        vec![r.striker_energy_j; t.len()]
    };
    let bars = resample(&r.time_s, &r.bar_energy_j, &t);
    let absorbed = resample(&r.time_s, &r.absorbed_energy_j, &t);
    let shaper = resample(&r.time_s, &r.shaper_energy_j, &t);
    let contact_work = resample(&r.time_s, &r.contact_energy_j, &t);
    // A cylinder's dissipation (docs/physics.md §6.12): plastic and friction work, less the
    // kinetic energy its changing radial inertia exchanged (zero without it).
    let dissipation = cylinder.map(|_| {
        (
            resample(&r.time_s, &r.plastic_work_j, &t),
            resample(&r.time_s, &r.friction_work_j, &t),
            resample(&r.time_s, &r.inertia_exchange_j, &t),
        )
    });
    let total: Vec<f64> = (0..t.len())
        .map(|i| {
            let held = bars[i] + absorbed[i] + shaper[i] + contact_work[i];
            match &dissipation {
                Some((p, f, x)) => held + p[i] + f[i] - x[i],
                None => held,
            }
        })
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
    let scale = input.iter().copied().fold(0.0, f64::max);
    let no_energy_balance = t.is_empty() || scale <= 0.0;
    let worst = total
        .iter()
        .zip(&input)
        .map(|(x, i)| (x - i).abs())
        .fold(0.0, f64::max)
        / scale;
    summary.push(item("energy_balance_max_relative_error", worst, "1"));
    let mut energy = vec![
        (if driven { "drive" } else { "striker" }.into(), input),
        ("bars".into(), bars),
        ("absorbed".into(), absorbed),
        ("shaper".into(), shaper),
    ];
    if r.contact.is_some() {
        energy.push(("contact".into(), contact_work));
    }
    if let Some((plastic, friction, exchange)) = dissipation {
        energy.push(("plastic".into(), plastic));
        energy.push(("friction".into(), friction));
        energy.push(("inertia_exchange".into(), exchange));
    }
    energy.push(("total".into(), total));
    let mut warnings = clipping_warnings(apparatus, cylinder, &gauges);
    if no_energy_balance {
        warnings.push(
            "`energy_balance_max_relative_error` is not available (NaN): the run recorded no \
             sample with energy put in (end_time_s shorter than a sample of the recorders)"
                .to_string(),
        );
    }
    // Spheres: the strain rate over their radii; a cylinder: its stress and strain (§7.8).
    let radii = spheres_specimen.map(|sp| sp.strain_rate_radii_m());
    let mut cylinder_reduction = None;
    if let (Some(c), Some(series)) = (cylinder, &r.specimen) {
        summary.extend(specimen_summary(c, series));
    }
    let reduction = match (radii, cylinder) {
        (Some(_), _) | (None, Some(_)) => {
            match reduce_simulated_records(apparatus, options, radii, &t, &gauges) {
                Ok(red) => {
                    summary.extend(reduced_summary(&red, apparatus));
                    if let Some(c) = cylinder {
                        summary.push(item("specimen_cells", c.cells_at(chain.dt_s) as f64, "1"));
                        match reduced_cylinder_summary(apparatus, c, &red) {
                            Ok((items, cyl)) => {
                                summary.extend(items);
                                if let Some(series) = &r.specimen {
                                    summary.extend(true_and_reduced_summary(series, &cyl));
                                }
                                cylinder_reduction = Some(cyl);
                            }
                            Err(e) => warnings.push(format!("cylinder reduction failed: {e}")),
                        }
                    }
                    warnings.extend(red.warnings.iter().map(|w| format!("reduction: {w}")));
                    Some(red)
                }
                Err(e) => {
                    warnings.push(format!("reduction of the simulated records failed: {e}"));
                    None
                }
            }
        }
        (None, None) => None,
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
        chain: spheres_rec.map(|rec| rec.into_series()),
        specimen: r.specimen,
        cylinder_reduction,
        drive: driven.then(|| crate::run::DriveSeries {
            time_s: (0..chain.drive_force_n.len())
                .map(|k| k as f64 * chain.dt_s)
                .collect(),
            force_n: chain.drive_force_n.clone(),
        }),
    })
}

/// Runs a `chain` scene: the free chain, its `/chain` series and its summary (restitution of
/// the first contact, kinetic-energy ratio, final velocities, the energy ledger).
fn run_free_chain(
    setup: &solver::FreeChainSetup,
    progress: &mut dyn FnMut(f64) -> bool,
) -> Result<RunOutput> {
    let r = solver::spheres::free_chain_with_progress(setup, progress)?;
    let first = setup.first_sphere();
    let n = setup.chain.len();
    let spheres = first..first + n - 1;
    let (peak_contact, peak) =
        r.peak_force_n[spheres.clone()]
            .iter()
            .enumerate()
            .fold(
                (0, 0.0f64),
                |(k, f), (j, &g)| if g > f { (j, g) } else { (k, f) },
            );
    let max_approach = r.max_approach_m[spheres.clone()]
        .iter()
        .copied()
        .fold(0.0f64, f64::max);
    let dissipated: f64 = r.contact_work_j[spheres].iter().sum();
    let mut warnings = Vec::new();
    // Issue 42: at end_time_s = 5 µs the first contact of the 10-sphere chain was still closing
    // and its "restitution" came out as −0.52.
    let first_force = r.first_contact.force_n.last().copied().unwrap_or(0.0);
    let closing = r.final_velocity_m_s[0] - r.final_velocity_m_s[1];
    let restitution = if first_force > 0.0 || closing > 0.0 {
        warnings.push(format!(
            "`restitution` is not available (NaN): the first contact has not ended at \
             end_time_s = {} (force {}, closing at {}); raise end_time_s past its end",
            format_si(setup.end_time_s, "s"),
            format_si(first_force, "N"),
            format_si(closing.max(0.0), "m/s"),
        ));
        f64::NAN
    } else {
        physical_restitution(
            r.first_restitution(),
            "of the first contact ",
            &mut warnings,
        )
    };
    // The contacts' work is dissipated only once they have unloaded: a contact still loaded at
    // the end holds elastic energy in it.
    let loaded = r
        .contact_force_n
        .iter()
        .filter(|f| f.last().is_some_and(|&x| x > 0.0))
        .count();
    let dissipated = if loaded > 0 {
        warnings.push(format!(
            "`energy_dissipated` is not available (NaN): {loaded} contact(s) still loaded at \
             end_time_s = {}, whose work holds elastic energy not yet returned; raise end_time_s",
            format_si(setup.end_time_s, "s"),
        ));
        f64::NAN
    } else {
        dissipated
    };
    let mut summary = vec![
        item("restitution", restitution, "1"),
        item("kinetic_energy_ratio", r.kinetic_energy_ratio(), "1"),
        item("peak_force", peak, "N"),
        item("peak_force_contact", (peak_contact + 1) as f64, "1"),
        item("max_approach", max_approach, "m"),
        item("kinetic_energy_before", r.kinetic_energy_before_j, "J"),
        item("kinetic_energy_after", r.kinetic_energy_after_j, "J"),
        item("energy_dissipated", dissipated, "J"),
    ];
    if setup.striker.is_some() {
        summary.push(item("striker_contact_work", r.contact_work_j[0], "J"));
        summary.push(item(
            "striker_final_velocity",
            r.final_velocity_m_s[0],
            "m/s",
        ));
    }
    if setup.wall.is_some() {
        let w = *r.contact_work_j.last().unwrap_or(&0.0);
        summary.push(item("wall_work", w, "J"));
        let f = *r.peak_force_n.last().unwrap_or(&0.0);
        summary.push(item("wall_peak_force", f, "N"));
    }
    summary.push(item(
        "energy_balance_max_relative_error",
        r.energy_balance_max_relative_error,
        "1",
    ));
    if setup.wall.is_none() {
        summary.push(item(
            "momentum_max_relative_drift",
            r.momentum_max_relative_drift,
            "1",
        ));
    }
    summary.push(item("time_step", setup.dt_s, "s"));
    summary.push(item("output_every", setup.output_every as f64, "1"));
    if setup.output_every_by_budget && setup.output_every > 1 {
        warnings.push(format!(
            "output_every = {} (the scene does not set it): one step in {} of the {} is kept, \
             {} samples of {} numbers, within the budget of {:e} numbers ({}) a chain's series \
             keep; set output_every to keep more",
            setup.output_every,
            setup.output_every,
            setup.steps(),
            r.time_s.len(),
            setup.numbers_per_sample(),
            solver::spheres::CHAIN_OUTPUT_BUDGET_NUMBERS,
            format_si(8.0 * solver::spheres::CHAIN_OUTPUT_BUDGET_NUMBERS, "B"),
        ));
    }
    let final_velocity: Vec<f64> = r.final_velocity_m_s[first..].to_vec();
    for (k, v) in final_velocity.iter().enumerate() {
        summary.push(item(&format!("final_velocity_{}", k + 1), *v, "m/s"));
    }
    let mut extra = Vec::new();
    if let Some(v) = &r.striker_velocity_m_s {
        extra.push(("striker_velocity".to_string(), v.clone(), "m/s"));
    }
    if let Some(f) = &r.striker_force_n {
        extra.push(("striker_contact_force".to_string(), f.clone(), "N"));
    }
    if let Some(f) = &r.wall_force_n {
        extra.push(("wall_contact_force".to_string(), f.clone(), "N"));
    }
    let chain = crate::run::ChainSeries {
        time_s: r.time_s,
        contact_force_n: r.contact_force_n,
        contact_approach_m: r.contact_approach_m,
        velocity_m_s: r.velocity_m_s,
        final_velocity_m_s: final_velocity,
        extra,
    };
    let mut out = RunOutput::contact_only(r.first_contact, summary);
    out.chain = Some(chain);
    out.warnings.extend(warnings);
    Ok(out)
}

/// The lab's reduction of a simulated test: the digitised voltages read back through each
/// channel's bridge (as the lab gets them), dispersion correction only when the bars disperse.
fn reduce_simulated_records(
    apparatus: &Apparatus,
    options: &PulseOptions,
    specimen_radii: Option<(f64, f64)>,
    time_s: &[f64],
    gauges: &[crate::run::GaugeTrace],
) -> Result<crate::reduce::Reduction> {
    let strain = |name: &str| -> Result<Vec<f64>> {
        let trace = gauges.iter().find(|g| g.name == name);
        let channel = apparatus.gauges.channel(name);
        match (trace, channel) {
            // A linear channel whose factor is not stated (nan) records no volts: its
            // noise-free gauge strain is reduced, as a lab's record in strain would be.
            (Some(g), Some(ch))
                if ch.bridge.kind == crate::gauge::BridgeKind::Linear
                    && ch.bridge.strain_per_volt.is_nan() =>
            {
                Ok(g.strain.clone())
            }
            (Some(g), Some(ch)) => Ok(ch.strains_from_voltages(&g.voltage_v)),
            _ => Err(crate::error::Named::new(apparatus.source.clone()).error(
                "gauges",
                format!("no `{name}` gauge channel to reduce"),
                "channels named incident and transmission",
            )),
        }
    };
    let input = crate::reduce::ReductionInput {
        time_s: time_s.to_vec(),
        incident_strain: strain("incident")?,
        transmission_strain: strain("transmission")?,
    };
    let reduction_options = crate::reduce::ReductionOptions {
        // The correction that undoes the bars' own theory: none for elementary bars, the exact
        // first mode for bars that carry it, the lab's Bancroft fit for the Love rods.
        dispersion: match options.dispersion {
            Dispersion::None => crate::reduce::DispersionCorrection::None,
            Dispersion::PochhammerChree => crate::reduce::DispersionCorrection::PochhammerChree,
            Dispersion::LoveRod | Dispersion::RayleighLove => {
                crate::reduce::DispersionCorrection::Bancroft
            }
        },
        specimen_radii_m: specimen_radii,
        smoothing_window_s: options.reduction_smoothing_s,
        tension: options.loading.is_tension(),
        filter: options.reduction_filter,
        ..Default::default()
    };
    crate::reduce::reduce(
        &input,
        &crate::reduce::ReductionSetup::from_apparatus(apparatus)?,
        &reduction_options,
    )
}

/// Summary items of a simulated cylinder's reduction (docs/physics.md §7.8): 1-wave peak
/// stress, strain at peak, mean strain rate, and the modulus fitted to the 3-wave curve on
/// 30–90 % of its peak (`reduce_cylinder::MODULUS_WINDOW`).
fn reduced_cylinder_summary(
    apparatus: &Apparatus,
    c: &crate::specimen::CylinderSpecimen,
    red: &crate::reduce::Reduction,
) -> Result<(Vec<SummaryItem>, crate::reduce_cylinder::CylinderReduction)> {
    use crate::reduce_cylinder::{CylinderGeometry, loading_modulus, reduce_cylinder};
    let g = CylinderGeometry {
        length_m: c.length_m,
        diameter_m: c.diameter_m,
    };
    let setup = crate::reduce::ReductionSetup::from_apparatus(apparatus)?;
    let cyl = reduce_cylinder(red, &setup, &g)?;
    let mut v = vec![
        item("reduced_peak_stress", cyl.peak_stress_pa, "Pa"),
        item("reduced_strain_at_peak_stress", cyl.strain_at_peak, "1"),
        item(
            "reduced_mean_strain_rate",
            cyl.mean_strain_rate_per_s,
            "1/s",
        ),
    ];
    if let Ok(fit) = loading_modulus(
        &cyl.three_wave,
        &red.equilibrium_ratio,
        crate::reduce_cylinder::MODULUS_WINDOW.0,
        crate::reduce_cylinder::MODULUS_WINDOW.1,
    ) {
        v.push(item("reduced_loading_modulus", fit.modulus_pa, "Pa"));
    }
    Ok((v, cyl))
}

/// A warning for every gauge record that reaches its digitiser's full scale: the reduction cannot
/// resolve what lies beyond it. On the transmission bar of a cylinder test it is said as the
/// specimen stress the full scale stands for, E_b A_b ε_full / A_s (docs/physics.md §7.1, §7.8).
fn clipping_warnings(
    apparatus: &Apparatus,
    cylinder: Option<&crate::specimen::CylinderSpecimen>,
    gauges: &[crate::run::GaugeTrace],
) -> Vec<String> {
    let mut w = Vec::new();
    for g in gauges {
        let Some(ch) = apparatus.gauges.channel(&g.name) else {
            continue;
        };
        let full = ch.digitiser.range_v - ch.digitiser.quantisation_step_v();
        if !g.voltage_v.iter().any(|v| v.abs() >= full) {
            continue;
        }
        let strain = ch.strains_from_voltages(&[full])[0].abs();
        let mut msg = format!(
            "the {} record reaches its digitiser's full scale (±{} V, strain {:.3e}): the \
             reduction cannot resolve the wave beyond it",
            g.name, ch.digitiser.range_v, strain
        );
        if let (Some(c), "transmission") = (cylinder, g.name.as_str()) {
            let bar = &apparatus.transmission;
            let stress =
                apparatus.material.youngs_modulus_pa * strain * bar.area_m2() / c.area_m2();
            msg.push_str(&format!(
                "; the specimen's stress passes {}, the most the transmission record can show",
                format_si(stress, "Pa")
            ));
        }
        w.push(msg);
    }
    w
}

/// Lowest true strain from which a cylinder's reduced flow stress is compared with its true one
/// ([`true_and_reduced_summary`]): below it the specimen rings up and yields (docs/physics.md
/// §6.12).
pub const FLOW_COMPARISON_FROM_STRAIN: f64 = 0.02;

/// Summary items of a simulated cylinder (docs/physics.md §6.12): its peak true stress, largest
/// true strain, peak true strain rate, plastic and friction work, and the largest stress its end
/// friction and radial inertia add while it flows (from [`FLOW_COMPARISON_FROM_STRAIN`] to the end
/// of loading, its peak stress: before, the faces differ by the waves still ringing up).
fn specimen_summary(
    c: &crate::specimen::CylinderSpecimen,
    s: &crate::solver::SpecimenSeries,
) -> Vec<SummaryItem> {
    let max = |v: &[f64]| v.iter().copied().fold(0.0f64, f64::max);
    let last = |v: &[f64]| v.last().copied().unwrap_or(0.0);
    let end = crate::numeric::argmax(&s.face_stress_pa);
    let flowing = |v: &[f64]| {
        (0..=end.min(v.len().saturating_sub(1)))
            .filter(|&k| s.true_strain[k] >= FLOW_COMPARISON_FROM_STRAIN)
            .fold(0.0f64, |a, k| a.max(v[k].abs()))
    };
    let mut v = vec![
        item("true_peak_stress", max(&s.face_stress_pa), "Pa"),
        item("true_max_strain", max(&s.true_strain), "1"),
        item(
            "true_peak_strain_rate",
            max(&s.true_strain_rate_per_s),
            "1/s",
        ),
    ];
    if !matches!(c.flow, crate::flow::FlowModel::Elastic) {
        v.push(item("plastic_work", last(&s.plastic_work_j), "J"));
        v.push(item("max_plastic_strain", max(&s.plastic_strain), "1"));
        v.push(item("max_temperature", max(&s.temperature_k), "K"));
    }
    if c.friction.is_some() {
        v.push(item("friction_work", last(&s.friction_work_j), "J"));
        v.push(item(
            "friction_peak_stress",
            flowing(&s.friction_stress_pa),
            "Pa",
        ));
    }
    if c.radial_inertia {
        v.push(item(
            "inertia_peak_stress",
            flowing(&s.inertia_stress_pa),
            "Pa",
        ));
    }
    v
}

/// How far the lab's 1-wave reduction of a simulated cylinder lies from its true flow stress
/// (docs/physics.md §6.12): the largest |σ_reduced/σ_true − 1| over its loading from the true
/// strain [`FLOW_COMPARISON_FROM_STRAIN`] to the end of loading (the peak stress), σ_true the
/// specimen's face stress at the same true strain on its own loading branch. Empty when the
/// specimen never reaches that strain while loading.
fn true_and_reduced_summary(
    s: &crate::solver::SpecimenSeries,
    cyl: &crate::reduce_cylinder::CylinderReduction,
) -> Vec<SummaryItem> {
    match reduced_flow_error(s, &cyl.one_wave) {
        Some(e) => vec![item("reduced_true_stress_max_relative_error", e, "1")],
        None => vec![],
    }
}

/// The largest |σ_reduced/σ_true − 1| of [`true_and_reduced_summary`] for one analysis.
pub fn reduced_flow_error(
    s: &crate::solver::SpecimenSeries,
    a: &crate::reduce_cylinder::WaveAnalysis,
) -> Option<f64> {
    // The loading branches, each up to its peak stress (the end of loading), where the strain
    // increases.
    let peak = crate::numeric::argmax(&s.face_stress_pa);
    let mut strain = Vec::new();
    let mut stress = Vec::new();
    for k in 0..=peak {
        if strain.last().is_none_or(|&e| s.true_strain[k] > e) {
            strain.push(s.true_strain[k]);
            stress.push(s.face_stress_pa[k]);
        }
    }
    let end = *strain.last()?;
    if end <= FLOW_COMPARISON_FROM_STRAIN {
        return None;
    }
    let reduced_peak = crate::numeric::argmax(&a.true_stress_pa);
    let window: Vec<usize> = (0..=reduced_peak)
        .filter(|&k| (FLOW_COMPARISON_FROM_STRAIN..=end).contains(&a.true_strain[k]))
        .collect();
    if window.is_empty() {
        return None;
    }
    let at: Vec<f64> = window.iter().map(|&k| a.true_strain[k]).collect();
    let truth = resample(&strain, &stress, &at);
    Some(
        window
            .iter()
            .zip(&truth)
            .map(|(&k, t)| (a.true_stress_pa[k] / t - 1.0).abs())
            .fold(0.0, f64::max),
    )
}

/// Summary items of the reduction of a simulated test (`reduced_*`).
/// The reduction's summary items: peak back and front force, the approach and equilibrium ratio
/// at the peak, the peak strain rate; the energy of the incident wave at the face over its
/// window, E A c0 ∫ε² dt (`reduce::wave_metrics`, as `shpb reduce` reports it); and the delays
/// of the reflected and transmitted pulses' feet after the incident foot at the gauges, by the
/// reduction's own foot rule (docs/physics.md §7.6: `shpb reduce`'s measured delays), when found.
fn reduced_summary(r: &crate::reduce::Reduction, apparatus: &Apparatus) -> Vec<SummaryItem> {
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
    if let Ok(setup) = crate::reduce::ReductionSetup::from_apparatus(apparatus)
        && let Some(m) =
            crate::reduce::wave_metrics(&r.time_s, &r.incident_strain, &setup.incident_bar, true)
    {
        v.push(item("incident_energy", m.energy_j, "J"));
    }
    if let Some(d) = r.alignment.measured_reflected_delay_s {
        v.push(item("reflected_delay", d, "s"));
    }
    if let Some(d) = r.alignment.measured_transmitted_delay_s {
        v.push(item("transmitted_delay", d, "s"));
    }
    v
}

/// Largest restitution a stepped impact may report above 1 and still be taken as 1 plus
/// round-off: an elastic Hertz impact steps to 1 ± 1e-11 (issue 42 measurements), a gain of
/// 1e-6 is energy the stepper made.
pub const RESTITUTION_ROUND_OFF: f64 = 1e-6;

/// A restitution as reported: NaN with a warning (pushed on `warnings`) when it is above 1 by
/// more than [`RESTITUTION_ROUND_OFF`] or negative, which no passive contact can give.
fn physical_restitution(e: f64, what: &str, warnings: &mut Vec<String>) -> f64 {
    if !(0.0..=1.0 + RESTITUTION_ROUND_OFF).contains(&e) {
        warnings.push(format!(
            "`restitution` is not available (NaN): the stepped restitution {what}came out as \
             {e}, outside 0 to 1 where a passive contact keeps it (the time step or the \
             closing speed is outside what the stepper resolves)"
        ));
        f64::NAN
    } else {
        e
    }
}

/// Gives every summary value that is not a finite number (NaN: not available) a warning saying
/// so, unless a warning already names it in backquotes (issue 42: NaN summaries came out with
/// exit 0 and no word); the reason is the run's, named where a specific check knows it.
pub fn explain_unavailable(out: &mut RunOutput) {
    let missing: Vec<String> = out
        .summary
        .iter()
        .filter(|s| !s.value.is_finite())
        .map(|s| s.key.clone())
        .filter(|k| {
            let quoted = format!("`{k}`");
            !out.warnings.iter().any(|w| w.contains(&quoted))
        })
        .collect();
    for k in missing {
        out.warnings.push(format!(
            "`{k}` is not available (NaN): the run gave it no value (a run shorter than the \
             events it measures, or a record with too few samples); raise end_time_s"
        ));
    }
}

impl Params {
    /// This scene set to record `outputs` ([`Outputs`]): [`Outputs::Summary`] clears the bars'
    /// snapshot interval, [`Outputs::Full`] keeps the scene's. Every summary item, the reduction
    /// and the warnings are the same either way.
    pub fn with_outputs(mut self, outputs: Outputs) -> Params {
        self.set_outputs(outputs);
        self
    }

    /// [`Params::with_outputs`] in place.
    pub fn set_outputs(&mut self, outputs: Outputs) {
        if let (Outputs::Summary, SceneParams::Pulse { options, .. }) = (outputs, &mut self.params)
        {
            options.snapshot_interval_s = None;
        }
    }

    /// This scene as a summary-only run (`with_outputs(Outputs::Summary)`): what sweeps,
    /// studies, fits and designs run.
    pub fn summary_only(self) -> Params {
        self.with_outputs(Outputs::Summary)
    }

    /// Whether a run of this scene records the bars' x–t snapshots.
    pub fn records_snapshots(&self) -> bool {
        matches!(&self.params, SceneParams::Pulse { options, .. }
            if options.snapshot_interval_s.is_some())
    }
}

#[cfg(test)]
mod fig4_tests {
    use super::*;

    /// Model δ = v t peaking at 40 µs; measured peak force at 50 µs with a 10 µm offset at t = 0:
    /// the two conventions give their analytic values.
    #[test]
    fn the_displacement_error_in_both_conventions() {
        let v = 2.0; // m/s
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 1e-6).collect();
        let series = ContactSeries {
            time_s: Some(t.clone()),
            displacement_m: t.iter().map(|&x| v * x).collect(),
            force_n: t.iter().map(|&x| 1.0 - (x - 40e-6).abs() * 1e4).collect(),
            yield_stress_pa: None,
            strain_rate_per_s: None,
        };
        let drive = ForceHistory {
            time_s: t.clone(),
            force_n: t.iter().map(|&x| 1.0 - (x - 50e-6).abs() * 1e4).collect(),
        };
        let measured: Vec<f64> = t.iter().map(|&x| 10e-6 + 1.5 * x).collect();
        let c = compare_fig4(&series, &drive, &measured);
        // Today's: model at its own peak (80 µm) against the measured rise from t = 0 (75 µm).
        assert!((c.relative_error() - (80e-6 - 75e-6) / 75e-6).abs() < 1e-12);
        // The paper's: model at the measured peak time (100 µm) against 85 µm counted from zero.
        assert!((c.paper_relative_error() - (100e-6 - 85e-6) / 85e-6).abs() < 1e-12);
    }
}
