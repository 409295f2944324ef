//! A measured incident wave driving the virtual test (`[incident_record]`, docs/physics.md §6.10):
//! the virtual incident gauge reads the record's incident wave again, on the record's own time
//! base shifted by the gauge's distance from the impact end over c0; the work the drive does is
//! the energy the recorded incident wave carries; the energy audit holds at every sample.

mod common;

use common::repo;
use shpb::apparatus::IncidentDrive;
use shpb::gauge::{RawRecord, foot_signal, pulse_foot};
use shpb::prelude::*;
use shpb::scene::{Params, SceneParams};
use shpb_input::gauges::RawRecordFile;

/// Where the compressive pulse of a strain series (tension positive) first rises through
/// `fraction` of its peak, after the timing's moving average.
fn crossing_s(t: &[f64], strain: &[f64], fraction: f64) -> f64 {
    pulse_foot(&foot_signal(strain, t[1] - t[0]), fraction)
        .unwrap()
        .time_s(t)
}

#[test]
fn a_recorded_incident_wave_drives_the_virtual_test() {
    let record = repo().join("validation/gauge-records/data/2013-05-22_sample1_ss440c.csv");
    let dir = tempfile::TempDir::new().unwrap();
    let scene = dir.path().join("driven.toml");
    std::fs::write(
        &scene,
        format!(
            "kind = \"shpb\"\nbars = \"authors\"\nlaw = \"burgoyne-daraio\"\n\
             specimen = {{ pair = \"ss440c\" }}\n[incident_record]\nfile = \"{}\"\n",
            record.display()
        ),
    )
    .unwrap();
    let params = Params::from_file(&scene).unwrap();
    let SceneParams::Pulse {
        apparatus, options, ..
    } = &params.params
    else {
        panic!("an shpb scene")
    };
    let drive = options.incident_drive.clone().expect("a driven test");
    let out = params.run().unwrap();

    // The audit: what the bars, the trap, the joints and the contact hold is the drive's work.
    let series = |name: &str| &out.energy.iter().find(|(n, _)| n == name).unwrap().1;
    let input = series("drive");
    for i in 0..input.len() {
        let held: f64 = ["bars", "absorbed", "shaper", "contact"]
            .iter()
            .map(|n| series(n)[i])
            .sum();
        assert!(
            (held - input[i]).abs() <= 1e-12 * input.last().unwrap(),
            "sample {i}: {held} vs {}",
            input[i]
        );
    }

    // The record's incident wave reaches the virtual gauge on the record's time base, shifted by
    // the gauge's distance from the impact end over c0: its 10 % and 50 % crossings (2 µs moving
    // average, as the timing reads feet) within half a record sample. (The 2 % foot itself sits
    // in the record's noise, which the 2 mm gauge and the resampling at the chain's 0.21 µs step
    // smooth differently: it moves by 0.3 µs.)
    let rec = RawRecord::read(&record).unwrap();
    let strains = shpb::reduce::record_strains(&rec, apparatus.as_ref(), 900).unwrap();
    let c0 = apparatus.material.wave_speed_m_s();
    let gauge = apparatus.gauges.channel("incident").unwrap();
    let x_g = apparatus.incident.length_m - gauge.distance_from_specimen_m;
    let t = out.time_s.as_ref().unwrap();
    let sim = &out
        .gauges
        .iter()
        .find(|g| g.name == "incident")
        .unwrap()
        .strain;
    for fraction in [0.1, 0.5] {
        let expected = crossing_s(&strains.time_s, &strains.incident_strain, fraction)
            - strains.time_s[0]
            + x_g / c0;
        let got = crossing_s(t, sim, fraction);
        assert!(
            (got - expected).abs() <= 0.05e-6,
            "{fraction} of the peak at {got:e} s, expected {expected:e} s"
        );
    }

    // After the drive has ended and before the reflected wave is back, the impact end is at
    // rest: no two-step oscillation of the end node is left there (the drive is band-limited
    // below the bars' Nyquist frequency, where such an oscillation would not travel away), to a
    // tenth of the record's own noise (RMS of its pre-trigger stress).
    let e_pa = apparatus.material.youngs_modulus_pa;
    let noise_rms = (strains.incident_strain[..900]
        .iter()
        .map(|x| (e_pa * x).powi(2))
        .sum::<f64>()
        / 900.0)
        .sqrt();
    let bar = out.bars.iter().find(|b| b.name == "incident").unwrap();
    // The drive's first sample, reflected at the specimen, is back at the impact end after 2 L/c0.
    let back = 2.0 * apparatus.incident.length_m / c0;
    let left = bar
        .time_s
        .iter()
        .zip(&bar.stress_pa)
        .filter(|(t, _)| **t > drive.duration_s() + 20e-6 && **t < back - 20e-6)
        .map(|(_, row)| row[0].abs())
        .fold(0.0, f64::max);
    assert!(
        left <= 0.1 * noise_rms,
        "{left:e} Pa left at the impact end (noise RMS {noise_rms:e} Pa)"
    );

    // The drive's work is the energy its samples carry, A/(ρ c0) ∫σ² dt (the same wave read
    // at the chain's steps: equal within the record's noise energy over the drive's window).
    let area = apparatus.incident.area_m2();
    let z = apparatus.material.density_kg_m3 * c0 * area;
    let energy = |d: &IncidentDrive| -> f64 {
        d.stress_pa.iter().map(|s| (s * area).powi(2)).sum::<f64>() * d.dt_s / z
    };
    let carried = energy(&drive);
    let noise = {
        let n = 900;
        let e = apparatus.material.youngs_modulus_pa;
        let var = strains.incident_strain[..n]
            .iter()
            .map(|x| (e * x).powi(2))
            .sum::<f64>()
            / n as f64;
        var * area * area * drive.duration_s() / z
    };
    let work = out.summary_value("drive_work").unwrap();
    assert!(
        (work - carried).abs() <= noise,
        "{work} J vs {carried} J (noise {noise} J)"
    );

    // The run keeps the force it applied (`/drive/{time,force}`): it starts and ends at rest
    // (tapered edges), its work on a bar at rest is Σ F² Δt / Z, the drive's
    // work the bar's ledger recorded, and the file holds it as the run did.
    let applied = out.drive.as_ref().expect("a driven run keeps its drive");
    let f = &applied.force_n;
    let dt = applied.time_s[1] - applied.time_s[0];
    assert_eq!(applied.time_s.len(), f.len());
    assert_eq!(applied.time_s[0], 0.0);
    let peak = f.iter().copied().fold(0.0, f64::max);
    // (The band limit leaves the first level at 6e-5 of the peak, under the record's noise.)
    assert!(f[0].abs().max(f[f.len() - 1].abs()) <= 1e-4 * peak);
    let on_bar_at_rest = f.iter().map(|x| x * x).sum::<f64>() * dt / z;
    assert!(
        (on_bar_at_rest - work).abs() <= 1e-9 * work,
        "{on_bar_at_rest} J vs {work} J"
    );
    let h5 = dir.path().join("driven.h5");
    shpb::io::write_hdf5(&h5, false, "kind = \"shpb\"", None, &out).unwrap();
    let back = shpb_output::run_file::read_run_file(&h5).unwrap();
    let read = |path: &str| -> Vec<f64> {
        back.datasets
            .iter()
            .find(|d| d.path == path)
            .unwrap_or_else(|| panic!("{path} in the run file"))
            .data
            .to_vec()
    };
    assert_eq!(&read("drive/force"), f);
    assert_eq!(&read("drive/time"), &applied.time_s);
}

/// The same record as bar strains in a lab's own layout (`shpb strain --csv`, read back through a
/// strain layout, as `shpb reduce --layout` reads it) drives the test with the same wave. The
/// strain path removes the strains' pre-trigger mean once more; what the bridge's nonlinearity
/// left of the voltages' baseline in them is below 1e-4 of the noise RMS
/// (`reduce_batch::shpb_strain_removes_the_baseline_…`), itself about 1 % of the peak, so the
/// two drives agree within 1e-6 of the peak.
#[test]
fn a_record_in_a_lab_layout_drives_the_test_as_the_raw_record() {
    let dir = tempfile::TempDir::new().unwrap();
    let record = repo().join("validation/gauge-records/data/2013-05-22_sample1_ss440c.csv");
    let out = common::shpb(
        dir.path(),
        &[
            "-q",
            "strain",
            record.to_str().unwrap(),
            "--bars",
            "authors",
            "--csv",
            "strain.csv",
        ],
    );
    assert!(out.status.success(), "{}", common::stderr(&out));
    std::fs::write(
        dir.path().join("strain.toml"),
        "skip_lines = 1\ntime_column = 1\n[incident]\ncolumn = 2\nunit = \"strain\"\n\
         [transmission]\ncolumn = 4\nunit = \"strain\"\n",
    )
    .unwrap();
    let drive = |table: &str| {
        let scene = dir.path().join("s.toml");
        std::fs::write(
            &scene,
            format!(
                "kind = \"shpb\"\nbars = \"authors\"\nspecimen = {{ pair = \"ss440c\" }}\n\
                 [incident_record]\n{table}"
            ),
        )
        .unwrap();
        match Params::from_file(&scene).unwrap().params {
            SceneParams::Pulse { options, .. } => options.incident_drive.unwrap(),
            _ => panic!("an shpb scene"),
        }
    };
    let raw = drive(&format!("file = \"{}\"\n", record.display()));
    let via = drive("file = \"strain.csv\"\nlayout = \"strain.toml\"\n");
    assert_eq!(raw.dt_s, via.dt_s);
    assert_eq!(raw.stress_pa.len(), via.stress_pa.len());
    let peak = raw.stress_pa.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    let worst = raw
        .stress_pa
        .iter()
        .zip(&via.stress_pa)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-6 * peak, "{:e} of the peak", worst / peak);
}

/// On bars carrying the exact first mode the recorded wave is dispersed again on its way from the
/// impact end to the gauge, so the drive takes the mode's dispersion over that distance back
/// first (`Apparatus::drive_at_impact_end`). Round trip: the incident gauge of a `reference`
/// test (noise-free, point gauge) drives a second `reference` test, whose gauge reads it back
/// within 1e-3 of the peak (3.8e-4), as close as elementary bars read it (4.9e-4: the band
/// limit and the resampling onto the bars' steps and back, all that is left there), while the
/// dispersion the drive took back is larger by far (1.0e-2 of the peak) — without it the wave
/// would reach the gauge dispersed twice.
#[test]
fn on_dispersive_bars_the_drive_takes_the_recorded_dispersion_back() {
    let scene = repo().join("scenes/shpb-ss440c-10psi.toml");
    let load = || {
        let mut p =
            Params::from_file_with(&scene, Some(shpb::fidelity::Fidelity::Reference)).unwrap();
        if let SceneParams::Pulse { options, .. } = &mut p.params {
            options.gauge_length_m = 0.0;
        }
        p
    };
    let first = load().run().unwrap();
    let incident = |out: &shpb::run::RunOutput| {
        out.gauges
            .iter()
            .find(|g| g.name == "incident")
            .unwrap()
            .strain
            .clone()
    };
    let t = first.time_s.clone().unwrap();
    let recorded = incident(&first);
    let p = load();
    let SceneParams::Pulse { apparatus, .. } = &p.params else {
        panic!("an shpb scene")
    };
    let (c0, e) = (
        apparatus.material.wave_speed_m_s(),
        apparatus.material.youngs_modulus_pa,
    );
    let x_g = apparatus.incident.length_m
        - apparatus
            .gauges
            .channel("incident")
            .unwrap()
            .distance_from_specimen_m;
    let drive = IncidentDrive::from_incident_gauge(&t, &recorded, e).unwrap();
    let peak = recorded.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let replay = |dispersion: shpb::bar::Dispersion| {
        let mut p = load();
        if let SceneParams::Pulse { options, .. } = &mut p.params {
            options.dispersion = dispersion;
            options.incident_drive = Some(drive.clone());
        }
        let out = p.run().unwrap();
        let (t2, read) = (out.time_s.clone().unwrap(), incident(&out));
        // The drive's samples (up to its end) against the second gauge x_g/c0 later.
        (0..drive.stress_pa.len())
            .map(|k| {
                let at = t[k] + x_g / c0;
                let j = t2.partition_point(|&x| x < at).min(t2.len() - 1);
                let w = if j == 0 {
                    0.0
                } else {
                    (at - t2[j - 1]) / (t2[j] - t2[j - 1])
                };
                let v = if j == 0 {
                    read[0]
                } else {
                    read[j - 1] + w * (read[j] - read[j - 1])
                };
                (v - recorded[k]).abs()
            })
            .fold(0.0, f64::max)
            / peak
    };
    let exact = replay(shpb::bar::Dispersion::PochhammerChree);
    // Elementary bars carry the drive to the gauge unchanged: their error is the resampling's
    // alone (the record's 0.1 µs samples onto the bars' 0.21 µs steps and back).
    let resampling = replay(shpb::bar::Dispersion::None);
    // What the drive took back: the mode's dispersion over x_g.
    let SceneParams::Pulse { options, .. } = &p.params else {
        unreachable!()
    };
    let dt = options.cell_size_m / c0;
    let undone = apparatus.drive_at_impact_end(&drive, shpb::bar::Dispersion::PochhammerChree, dt);
    let stress_peak = drive.stress_pa.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let taken_back = drive
        .stress_pa
        .iter()
        .zip(&undone.stress_pa)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / stress_peak;
    assert!(exact <= 1e-3, "read back within {exact:e} of the peak");
    assert!(
        exact <= 1.2 * resampling,
        "{exact:e} vs the resampling's {resampling:e}"
    );
    assert!(taken_back >= 10.0 * exact, "{taken_back:e} vs {exact:e}");
}
