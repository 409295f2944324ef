//! The SHPB set-up: bar material, incident and transmission bars, striker, gas gun, pulse shaper
//! and gauge channels ([`Apparatus`]), and the bar chain a test runs on (docs/physics.md §5–§6).

use crate::bar::{BarMaterial, BarSpec, Dispersion, EndCondition, Segment};
use crate::error::Result;
use crate::gauge::GaugeSetup;
use crate::shaper::PulseShaper;
use crate::striker::Gun;

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

/// An insert (platen) pressed between a bar end and the specimen (docs/physics.md §6.8): a short
/// elastic cylinder joined to its bar by a compression-only butt joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Insert {
    /// Material (the bars' own unless stated).
    pub material: BarMaterial,
    /// Diameter, m.
    pub diameter_m: f64,
    /// Length along the bar axis, m (1/4" = 6.35 mm in the authors' tests).
    pub length_m: f64,
}

impl Insert {
    /// The insert as one uniform bar segment.
    pub fn segment(&self) -> Segment {
        Segment {
            length_m: self.length_m,
            diameter_m: self.diameter_m,
            material: self.material,
        }
    }

    /// Mass ρ A L, kg.
    pub fn mass_kg(&self) -> f64 {
        self.material.density_kg_m3 * self.segment().area_m2() * self.length_m
    }

    /// One-way wave transit L/c0 of the insert, s (docs/physics.md §6.8).
    pub fn transit_s(&self) -> f64 {
        self.length_m / self.material.wave_speed_m_s()
    }

    /// Whether the insert is shorter than one cell of time step `dt_s` (L < c0 Δt): it is then a
    /// rigid mass, since a sub-cell bar segment would need a smaller step (bar.rs, "Stability").
    pub fn is_rigid_at(&self, dt_s: f64) -> bool {
        self.length_m < self.material.wave_speed_m_s() * dt_s * (1.0 - 1e-12)
    }
}

/// The inserts of a set-up, on the incident and transmission sides (None: the bar touches the
/// specimen).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Inserts {
    /// Between the incident bar and the specimen.
    pub incident: Option<Insert>,
    /// Between the specimen and the transmission bar.
    pub transmission: Option<Insert>,
}

impl Inserts {
    /// Extra one-way transit of each side's insert, each as the length of bar of speed
    /// `c0_m_s` it equals (L_ins c0/c_ins), m: what the reduction adds to the gauge distances.
    pub fn equivalent_bar_lengths_m(&self, c0_m_s: f64) -> (f64, f64) {
        let eq = |i: &Option<Insert>| i.map_or(0.0, |i| i.transit_s() * c0_m_s);
        (eq(&self.incident), eq(&self.transmission))
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
    /// The gauge pressures (lowest, highest) the gun (and shaper) were calibrated at, Pa; a run
    /// outside them is warned about (the striker velocity is extrapolated). None: not stated.
    pub gun_calibrated_pa: Option<(f64, f64)>,
    /// The gun's shot-to-shot scatter: relative standard deviation of the striker velocity at one
    /// pressure (docs/physics.md §10.4); `shpb study` draws it by default. None: not stated.
    pub gun_velocity_scatter: Option<f64>,
    /// Default pulse shaper (None: no shaper).
    pub shaper: Option<PulseShaper>,
    /// Gauge channels.
    pub gauges: GaugeSetup,
    /// Inserts (platens) between the bars and the specimen.
    pub inserts: Inserts,
    /// What the calibrated constants are uncertain by and the outputs' shot-to-shot scatter (the
    /// set-up's `[uncertainty]`, docs/physics.md §10.6); None: not stated.
    pub uncertainty: Option<crate::uncertainty::Uncertainty>,
}

impl Apparatus {
    /// Striker mass, kg.
    pub fn striker_mass_kg(&self) -> f64 {
        self.material.density_kg_m3 * self.striker.area_m2() * self.striker.length_m
    }

    /// How much later than a disc's the pulse of `shaper` may start at striker speed
    /// `striker_velocity_m_s`, s: [`PulseShaper::onset_delay_s`] against the incident bar's
    /// impedance (docs/physics.md §6.5.3); a run's default end time adds it.
    pub fn shaper_onset_delay_s(&self, shaper: &PulseShaper, striker_velocity_m_s: f64) -> f64 {
        let incident = self.bar_segment(self.incident);
        shaper.onset_delay_s(striker_velocity_m_s, incident.impedance_kg_s())
    }

    /// Striker velocity at gauge pressure `p_pa` (an out-of-range pressure is an error naming the
    /// gun's range).
    pub fn striker_velocity_m_s(&self, p_pa: f64) -> Result<f64> {
        self.gun
            .striker_velocity_m_s(p_pa, self.striker_mass_kg(), self.striker.area_m2())
    }

    /// A bar of this set-up as one uniform segment of its material.
    pub fn bar_segment(&self, g: BarGeometry) -> Segment {
        Segment {
            length_m: g.length_m,
            diameter_m: g.diameter_m,
            material: self.material,
        }
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
            segments: vec![self.bar_segment(g)],
            left_end: left,
            right_end: right,
            dispersion,
        }
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
    /// The specimen (spheres or a cylinder), then the transmission bar (a full SHPB test).
    Specimen,
}

/// Options of a bar run (what a `pulse` or `shpb` scene sets).
#[derive(Debug, Clone, PartialEq)]
pub struct PulseOptions {
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
    /// Width of the moving average applied to the simulated records before their reduction, s
    /// (scene key `smooth_s`; `crate::gauge::DEFAULT_SMOOTHING_S` unless set), as
    /// `shpb reduce --smooth` applies it to any record.
    pub reduction_smoothing_s: f64,
    /// A measured incident wave driving the incident bar's impact end in place of gun, striker
    /// and shaper (docs/physics.md §6.10); None: the striker.
    pub incident_drive: Option<IncidentDrive>,
    /// Compression (a pressure bar) or tension (a tension bar: the striker on the flange, the
    /// specimen bonded; docs/physics.md §6.13). Default compression.
    pub loading: crate::loading::Loading,
    /// The filter of the simulated records before their reduction (docs/physics.md §7.12):
    /// [`crate::filter::Filter::DEFAULT`] unless the scene sets `smooth_s`, which makes it a
    /// moving average of `reduction_smoothing_s` (0: none), as `shpb reduce --smooth` does.
    pub reduction_filter: crate::filter::Filter,
}

/// A prescribed incident wave (docs/physics.md §6.10): the compressive stress the incident gauge
/// recorded, sampled every `dt_s` from t = 0, Pa. The run pushes the incident bar's impact end
/// with it ([`Apparatus::drive_at_impact_end`]: on dispersive bars with the dispersion over the
/// gauge's distance taken back), so that the gauge reads it again, delayed by that distance over
/// c0.
#[derive(Debug, Clone, PartialEq)]
pub struct IncidentDrive {
    /// Sample interval, s.
    pub dt_s: f64,
    /// Time of the incident wave's foot in the drive (2 % of its peak), s: where a striker's
    /// impact would be.
    pub foot_s: f64,
    /// Compressive stress at the incident gauge, Pa.
    pub stress_pa: Vec<f64>,
}

/// Margin kept between the end of a recorded incident wave taken as a drive and the foot of the
/// reflected wave on the same channel ([`IncidentDrive::from_incident_gauge`]), s.
pub const DRIVE_MARGIN_S: f64 = 10e-6;

/// Length over which a drive is brought to zero at its start and end before its band limit
/// ([`Apparatus::drive_at_impact_end`]), s: a fraction of the margin before the reflected wave.
pub const DRIVE_EDGE_S: f64 = 2e-6;

impl IncidentDrive {
    /// The incident wave of an incident-gauge record (docs/physics.md §6.10): its compressive
    /// stress −E ε (`strain` tension positive, baseline removed, on the uniform times `time_s`)
    /// from the first sample up to [`DRIVE_MARGIN_S`] before the reflected wave's foot — the
    /// first tensile excursion through 2 % of the incident peak after it (2 µs moving average,
    /// as [`crate::gauge::pulse_foot`] reads feet) — or the whole record if it has none. None
    /// if the record has no compressive pulse or fewer than two samples.
    pub fn from_incident_gauge(
        time_s: &[f64],
        strain: &[f64],
        youngs_modulus_pa: f64,
    ) -> Option<IncidentDrive> {
        let dt_s = time_s.get(1)? - time_s[0];
        if dt_s.is_nan() || dt_s <= 0.0 {
            return None;
        }
        let compression = crate::gauge::foot_signal(strain, dt_s);
        let foot = crate::gauge::pulse_foot(&compression, crate::gauge::FOOT_FRACTION)?;
        let level = -crate::gauge::FOOT_FRACTION * compression[foot.peak_index];
        let margin = (DRIVE_MARGIN_S / dt_s).round() as usize;
        let end = (foot.peak_index..compression.len())
            .find(|&k| compression[k] < level)
            .map_or(strain.len(), |k| {
                k.saturating_sub(margin).max(foot.peak_index)
            });
        Some(IncidentDrive {
            dt_s,
            foot_s: foot.time_s(time_s) - time_s[0],
            stress_pa: strain[..end]
                .iter()
                .map(|e| -youngs_modulus_pa * e)
                .collect(),
        })
    }

    /// Duration of the drive, s.
    pub fn duration_s(&self) -> f64 {
        self.stress_pa.len() as f64 * self.dt_s
    }

    /// The stress at time `t_s`, linearly interpolated (0 outside the samples), Pa.
    pub fn stress_at_pa(&self, t_s: f64) -> f64 {
        let x = t_s / self.dt_s;
        if x.is_nan() || x < 0.0 {
            return 0.0;
        }
        let k = x.floor() as usize;
        match (self.stress_pa.get(k), self.stress_pa.get(k + 1)) {
            (Some(&a), Some(&b)) => a + (x - k as f64) * (b - a),
            (Some(&a), None) if x == k as f64 => a,
            _ => 0.0,
        }
    }
}

impl Apparatus {
    /// The chain striker → (shaper) → incident (→ specimen) (→ transmission) at Courant 1 in the
    /// bars; `specimen` sits between the bars when `o.end` is [`IncidentEnd::Specimen`].
    pub fn pulse_chain(
        &self,
        o: &PulseOptions,
        specimen: Option<&crate::specimen::Specimen>,
    ) -> crate::solver::ChainSetup {
        use crate::solver::{ChainSetup, GaugeProbe, Joint};
        let c0 = self.material.wave_speed_m_s();
        let dt = o.cell_size_m / c0;
        let (shaper, end, dispersion) = (o.shaper, o.end, o.dispersion);
        let incident_right = match end {
            IncidentEnd::Absorbing => EndCondition::Absorbing,
            _ => EndCondition::Free,
        };
        let with_transmission = matches!(end, IncidentEnd::Transmission | IncidentEnd::Specimen);
        // A drive replaces the striker and its joint: the incident bar is then the first body.
        let driven = o.incident_drive.is_some();
        let mut bars = Vec::new();
        let mut joints = Vec::new();
        if !driven {
            bars.push(self.bar_spec(
                "striker",
                self.striker,
                EndCondition::Free,
                EndCondition::Free,
                dispersion,
            ));
            // A tension bar: the striker tube on the flange, mirrored (docs/physics.md §6.13).
            joints.push(match (o.loading, shaper) {
                (crate::loading::Loading::Tension, s) => Joint::Flange(s),
                (_, Some(s)) => Joint::Shaper(s),
                (_, None) => Joint::Butt,
            });
        }
        let incident_index = bars.len();
        bars.push(self.bar_spec(
            "incident",
            self.incident,
            EndCondition::Free,
            incident_right,
            dispersion,
        ));
        let mut end_masses = Vec::new();
        let mut transmission_index = incident_index + 1;
        let mut chain_bodies = None;
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
            // Inserts: a body each between the bar and the specimen (or the other bar), joined to
            // its bar by a butt joint; a bar segment, or a rigid mass when shorter than a cell.
            // Under dispersion carried by delay lines an insert stays elementary: a transit
            // filter needs about a hundred cells of path before its precursor is whole
            // (docs/physics.md §6.2.1, "Causality") and an insert is a few cells long, over which
            // the first mode lags c0 by 13 ns at 50 kHz for 1/4" (§6.2.1, "Where it applies"). (A Love
            // rod there would meet the delay line's elementary end with another impedance at
            // high frequency.)
            let insert_dispersion = match dispersion.transit_model() {
                Some(_) => Dispersion::None,
                None => dispersion,
            };
            let insert_body = |name: &str, i: &Insert| -> crate::solver::BodySpec {
                if i.is_rigid_at(dt) {
                    crate::solver::BodySpec::Mass(crate::solver::MassSpec {
                        name: name.to_string(),
                        mass_kg: i.mass_kg(),
                    })
                } else {
                    crate::solver::BodySpec::Bar(BarSpec {
                        name: name.to_string(),
                        segments: vec![i.segment()],
                        left_end: EndCondition::Free,
                        right_end: EndCondition::Free,
                        dispersion: insert_dispersion,
                    })
                }
            };
            let transmission = bars.pop().expect("the transmission bar was pushed");
            let mut bodies: Vec<crate::solver::BodySpec> = bars.drain(..).map(Into::into).collect();
            if let Some(i) = &self.inserts.incident {
                bodies.push(insert_body("incident insert", i));
                joints.push(Joint::Butt);
            }
            let mut tail = Vec::new();
            let mut tail_joints = Vec::new();
            if let Some(i) = &self.inserts.transmission {
                tail.push(insert_body("transmission insert", i));
                tail_joints.push(Joint::Butt);
            }
            tail.push(transmission.into());
            // The specimen brings its own bodies and joints (docs/physics.md §6.9, §8).
            let sphere_masses = match specimen {
                Some(sp) if end == IncidentEnd::Specimen => {
                    join_specimen(sp, o.loading, &mut bodies, &mut joints)
                }
                _ => {
                    joints.push(Joint::Butt);
                    Vec::new()
                }
            };
            bodies.extend(tail);
            // A sphere on a rigid insert adds to its mass; on a bar, to its end node.
            for (k, right, m) in sphere_masses {
                match &mut bodies[k] {
                    crate::solver::BodySpec::Mass(body) => body.mass_kg += m,
                    _ => end_masses.push((k, right, m)),
                }
            }
            joints.extend(tail_joints);
            // A tension bar's specimen is threaded or bonded to its bars and inserts: every
            // butt joint after the striker's holds in tension too (docs/physics.md §6.13).
            if o.loading.is_tension() {
                for j in joints.iter_mut().skip(usize::from(!driven)) {
                    if *j == Joint::Butt {
                        *j = Joint::Bonded;
                    }
                }
            }
            transmission_index = bodies.len() - 1;
            chain_bodies = Some(bodies);
        }
        let mut gauges = Vec::new();
        for ch in &self.gauges.channels {
            let (bar, x) = match ch.bar.as_str() {
                "incident" => (
                    incident_index,
                    self.incident.length_m - ch.distance_from_specimen_m,
                ),
                "transmission" if with_transmission => {
                    (transmission_index, ch.distance_from_specimen_m)
                }
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
            bodies: chain_bodies.unwrap_or_else(|| bars.into_iter().map(Into::into).collect()),
            joints,
            // The mirrored tube of a tension bar moves away from the incident bar (§6.13).
            striker_velocity_m_s: if driven {
                0.0
            } else {
                o.loading.sign() * o.striker_velocity_m_s
            },
            dt_s: dt,
            end_time_s: o.end_time_s,
            gauges,
            record_every,
            end_masses,
            snapshot_every: o
                .snapshot_interval_s
                .map(|i| ((i / dt).round() as usize).max(1)),
            snapshot_spacing_m: 5e-3,
            drive_force_n: o
                .incident_drive
                .as_ref()
                .map(|d| {
                    let d = self.drive_at_impact_end(d, dispersion, dt);
                    let area = self.incident.area_m2();
                    let steps = (d.stress_pa.len() as f64 * d.dt_s / dt).ceil() as usize;
                    (0..=steps)
                        .map(|n| area * d.stress_at_pa(n as f64 * dt))
                        .collect()
                })
                .unwrap_or_default(),
        }
    }
}

impl Apparatus {
    /// The wave to push the incident bar's impact end with so that its incident gauge reads
    /// `drive` (docs/physics.md §6.10), on the recorded time base shifted by the gauge's distance
    /// x_g from that end over c0, for bars of step `dt_s`. Its spectrum is first limited to the
    /// band the bars carry as waves, Ω = 2π f Δt ≤ π/2, with the delay lines' smooth step to 0 at
    /// Ω = π: a drive with content at the bars' Nyquist frequency (a record's noise, or the steps
    /// where the record is cut, which are first brought to zero over [`DRIVE_EDGE_S`]) would
    /// excite the end node's two-step oscillation, which at Courant 1 does not travel. On bars carrying
    /// the exact first mode (`pochhammer-chree`) each component is also advanced by
    /// x_g (1/c(f) − 1/c0), taking back the dispersion the wave gathered on its way to the gauge,
    /// which the delay lines then apply again. A set-up without an incident gauge channel takes
    /// the wave as it is, band-limited.
    pub fn drive_at_impact_end(
        &self,
        drive: &IncidentDrive,
        dispersion: Dispersion,
        dt_s: f64,
    ) -> IncidentDrive {
        use std::f64::consts::PI;
        let gauge = self.gauges.channel("incident");
        let x_g = gauge.map_or(0.0, |g| self.incident.length_m - g.distance_from_specimen_m);
        let mode = match dispersion {
            Dispersion::PochhammerChree if x_g > 0.0 => crate::dispersion::PochhammerChree::new(
                self.material.poisson_ratio,
                0.5 * self.incident.diameter_m,
                self.material.wave_speed_m_s(),
            )
            .ok(),
            _ => None,
        };
        // The record starts and ends at its noise level or its tail, steps the band limit below
        // would smear into a ringing across the cut: both ends are brought to zero over
        // DRIVE_EDGE_S first, and the end is followed by zeros for the filtered wave to settle.
        let edge = ((DRIVE_EDGE_S / drive.dt_s).ceil() as usize).min(drive.stress_pa.len() / 2);
        let mut padded = drive.stress_pa.clone();
        let n = padded.len();
        for k in 0..edge {
            let w = 0.5 * (1.0 - (PI * (k as f64 + 0.5) / edge as f64).cos());
            padded[k] *= w;
            padded[n - 1 - k] *= w;
        }
        padded.resize(n + 2 * edge, 0.0);
        let stress_pa = crate::numeric::spectral_filter(&padded, drive.dt_s, |bin| {
            let gain = crate::transit::taper(2.0 * PI * bin.frequency_hz * dt_s, 0.5 * PI, PI);
            let advance = match (&mode, gain > 0.0) {
                (Some(m), true) => m.delay_for_bin_s(bin.index, bin.length, drive.dt_s, x_g),
                _ => 0.0,
            };
            (-advance, gain)
        });
        IncidentDrive {
            stress_pa,
            ..drive.clone()
        }
    }
}

/// The incident gauge of a pulse run as the digitiser samples it: compressive stress −E ε.
#[derive(Debug, Clone, PartialEq)]
pub struct IncidentSignal {
    /// Sample times at the digitiser's rate from 0, s.
    pub time_s: Vec<f64>,
    /// Bar stress at the incident gauge, compression positive, Pa.
    pub stress_pa: Vec<f64>,
    /// The whole chain run (energies, striker's final velocity).
    pub chain: crate::solver::ChainResult,
}

impl Apparatus {
    /// The incident gauge signal of a pulse run without specimen, transmission bar pressed on and
    /// no dispersion, as `pulse` scenes compute it: `cell_size_m` cells, a `gauge_length_m` grid,
    /// sampled at the incident channel's digitiser rate up to `end_time_s`.
    pub fn incident_signal(
        &self,
        striker_velocity_m_s: f64,
        shaper: Option<PulseShaper>,
        cell_size_m: f64,
        gauge_length_m: f64,
        end_time_s: f64,
    ) -> Result<IncidentSignal> {
        let ch = self.gauges.channel("incident").ok_or_else(|| {
            crate::Error::invalid(
                "gauges",
                "no channel named incident",
                "a set-up with an incident gauge",
            )
        })?;
        let setup = self.pulse_chain(
            &PulseOptions {
                striker_velocity_m_s,
                shaper,
                end: IncidentEnd::Transmission,
                cell_size_m,
                dispersion: Dispersion::None,
                end_time_s,
                gauge_length_m,
                snapshot_interval_s: None,
                reduction_smoothing_s: crate::gauge::DEFAULT_SMOOTHING_S,
                incident_drive: None,
                loading: crate::loading::Loading::Compression,
                reduction_filter: crate::filter::Filter::DEFAULT,
            },
            None,
        );
        let k = setup
            .gauges
            .iter()
            .position(|g| g.name == "incident")
            .expect("the incident channel sits on the incident bar");
        let chain = crate::solver::simulate_chain(&setup)?;
        let dt = ch.digitiser.sample_interval_s();
        let time_s: Vec<f64> = (0..(end_time_s / dt) as usize)
            .map(|i| i as f64 * dt)
            .collect();
        let e = self.material.youngs_modulus_pa;
        let stress_pa = crate::numeric::resample(&chain.time_s, &chain.strain[k], &time_s)
            .iter()
            .map(|x| -e * x)
            .collect();
        Ok(IncidentSignal {
            time_s,
            stress_pa,
            chain,
        })
    }
}

/// Puts a specimen into a bar chain after the last of `bodies` (the incident bar or its insert)
/// and before the transmission side; returns the masses to add to the end nodes of bodies, as
/// (body index, right end, mass in kg). In tension a cylinder is bonded to both bars
/// (docs/physics.md §6.13).
fn join_specimen(
    specimen: &crate::specimen::Specimen,
    loading: crate::loading::Loading,
    bodies: &mut Vec<crate::solver::BodySpec>,
    joints: &mut Vec<crate::solver::Joint>,
) -> Vec<(usize, bool, f64)> {
    use crate::solver::{BodySpec, Joint, MassSpec};
    use crate::specimen::Specimen;
    match specimen {
        // The first and last spheres' masses join the end nodes of the bodies they touch (the
        // paper's DEM); the spheres between are rigid masses, every two neighbours joined by a
        // contact (docs/physics.md §8).
        Specimen::Spheres(sp) => {
            let front = bodies.len() - 1;
            let n = sp.chain.len();
            for k in 0..n - 1 {
                joints.push(Joint::Spheres {
                    props: sp.chain.contact_properties(k),
                    law: sp.law,
                    seating: sp.seating,
                });
                if k + 2 < n {
                    bodies.push(BodySpec::Mass(MassSpec {
                        name: format!("sphere {}", k + 2),
                        mass_kg: sp.chain.spheres[k + 1].mass_kg,
                    }));
                }
            }
            let back = bodies.len();
            vec![
                (front, true, sp.chain.spheres[0].mass_kg),
                (back, false, sp.chain.spheres[n - 1].mass_kg),
            ]
        }
        // A cylinder is a body of its own between two butt joints, as an insert; elastic without
        // friction or radial inertia it is a bar segment step for step (docs/physics.md §6.9,
        // §6.12).
        Specimen::Cylinder(c) => {
            bodies.push(BodySpec::Cylinder(c.clone()));
            let face = match loading {
                crate::loading::Loading::Compression => Joint::Butt,
                crate::loading::Loading::Tension => Joint::Bonded,
            };
            joints.push(face);
            joints.push(face);
            Vec::new()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record with a raised-cosine incident pulse (compression: negative strain) from 20 µs
    /// to 70 µs and a tensile reflected pulse from 200 µs, at 0.1 µs.
    fn record() -> (Vec<f64>, Vec<f64>) {
        let bump = |t: f64, t0: f64, width: f64| {
            let s = (t - t0) / width;
            if (0.0..=1.0).contains(&s) {
                0.5 * (1.0 - (2.0 * std::f64::consts::PI * s).cos())
            } else {
                0.0
            }
        };
        let t: Vec<f64> = (0..3000).map(|k| k as f64 * 1e-7).collect();
        let strain = t
            .iter()
            .map(|&t| -4e-4 * bump(t, 20e-6, 50e-6) + 3e-4 * bump(t, 200e-6, 50e-6))
            .collect();
        (t, strain)
    }

    /// The drive is the compressive stress −E ε from the first sample to DRIVE_MARGIN_S before
    /// the reflected wave first passes 2 % of the incident peak in tension (on the 2 µs average),
    /// its foot where the incident wave first passes 2 %; without a reflected wave, the whole
    /// record.
    #[test]
    fn a_drive_is_the_incident_wave_cut_before_its_reflection() {
        let (t, strain) = record();
        let e = 200e9;
        let d = IncidentDrive::from_incident_gauge(&t, &strain, e).unwrap();
        assert_eq!(d.dt_s, 1e-7);
        assert_eq!(d.stress_pa[300], -e * strain[300]);
        // 2 % of a raised cosine of width w is reached at s = acos(1 − 0.04)/(2π) of it.
        let s = (1.0f64 - 0.04).acos() / (2.0 * std::f64::consts::PI);
        let foot = 20e-6 + s * 50e-6;
        // The 2 µs moving average moves a crossing on this slope by well under 0.1 µs.
        assert!((d.foot_s - foot).abs() < 0.1e-6, "{} vs {foot}", d.foot_s);
        // Tension through 2 % of the incident peak (4e-4 · 0.02 = 8e-6): the reflected bump
        // reaches 8e-6 of its 3e-4 at s' with 0.5 (1 − cos 2πs') = 8e-6/3e-4.
        let s_r = (1.0f64 - 2.0 * 8e-6 / 3e-4).acos() / (2.0 * std::f64::consts::PI);
        let reflected = 200e-6 + s_r * 50e-6;
        assert!(
            (d.duration_s() - (reflected - DRIVE_MARGIN_S)).abs() < 0.2e-6,
            "{} vs {}",
            d.duration_s(),
            reflected - DRIVE_MARGIN_S
        );
        // No reflected wave: the whole record.
        let only: Vec<f64> = strain.iter().map(|&x| x.min(0.0)).collect();
        let whole = IncidentDrive::from_incident_gauge(&t, &only, e).unwrap();
        assert_eq!(whole.stress_pa.len(), t.len());
        // Nothing compressive: no drive.
        let tensile: Vec<f64> = strain.iter().map(|&x| x.max(0.0)).collect();
        assert!(IncidentDrive::from_incident_gauge(&t, &tensile, e).is_none());
    }

    /// Between samples the drive is linear; before its first sample and after its last, zero.
    #[test]
    fn a_drive_is_linear_between_its_samples_and_zero_outside() {
        let d = IncidentDrive {
            dt_s: 1e-6,
            foot_s: 0.0,
            stress_pa: vec![0.0, 10.0, 30.0],
        };
        assert_eq!(d.stress_at_pa(0.5e-6), 5.0);
        assert!((d.stress_at_pa(1.25e-6) - 15.0).abs() < 1e-12);
        assert_eq!(d.stress_at_pa(2e-6), 30.0);
        assert_eq!(d.stress_at_pa(-1e-9), 0.0);
        assert_eq!(d.stress_at_pa(2.5e-6), 0.0);
        assert_eq!(d.stress_at_pa(f64::NAN), 0.0);
    }
}
