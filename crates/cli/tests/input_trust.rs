//! Issue 15 ("Trustworthy outputs"), the input side, end to end through the `shpb` binary: runs
//! too large for the machine are refused before they start (item 5), a force record with
//! compression negative (item 8) and a gauge record with inverted polarity (item 9) are refused
//! naming the file and column, runs outside the model's range of validity say so (item 10), the
//! `result:` line compares like with like (item 13), CSV readers take a byte-order mark and CRLF
//! and refuse binary files plainly (item 17), and numbers in messages read as a person writes
//! them, negative option values included (item 19).

mod common;

use common::{repo, shpb, shpb_env, stderr, stdout};
use shpb::prelude::*;
use shpb::run::RunOutput;
use shpb::scene::Params;
use std::path::{Path, PathBuf};
use std::process::Output;
use tempfile::TempDir;

/// Exit code the CLI documents for bad input.
const BAD_INPUT: i32 = 2;

/// The measured SS440c 10 psi force history (time_s, displacement_m, force_N).
fn fig4_csv() -> PathBuf {
    repo().join("validation/fig4-force-driven/data/ss440c_10psi_force10.csv")
}

/// The authors' raw record of sample 2 (time_s, incident_V, transmission_V).
fn record_csv() -> PathBuf {
    repo().join("validation/gauge-records/data/2013-05-22_sample2_ss440c.csv")
}

/// Checks a refusal: exit code 2, every needle in stderr, nothing on stdout, no output file.
fn assert_refused(dir: &Path, out: &Output, needles: &[&str]) -> String {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(BAD_INPUT), "stderr:\n{err}");
    for n in needles {
        assert!(err.contains(n), "stderr lacks `{n}`:\n{err}");
    }
    assert!(stdout(out).is_empty(), "stdout on refusal: {}", stdout(out));
    assert!(!dir.join("out.h5").exists(), "output written on refusal");
    err
}

fn assert_ok(out: &Output) {
    assert!(out.status.success(), "failed:\n{}", stderr(out));
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// A CSV with the columns of `source` transformed row by row by `f` (header and comments kept).
fn transformed_csv(source: &Path, f: impl Fn(&[f64]) -> Vec<f64>) -> String {
    let text = std::fs::read_to_string(source).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let values: Option<Vec<f64>> = line.split(',').map(|c| c.trim().parse().ok()).collect();
        match values {
            Some(v) if !line.starts_with('#') => {
                let row: Vec<String> = f(&v).iter().map(|x| format!("{x:e}")).collect();
                out.push_str(&row.join(","));
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

/// The summary lines of `shpb run` (scene line dropped: it names the file).
fn summary(out: &Output) -> Vec<String> {
    stdout(out)
        .lines()
        .filter(|l| !l.starts_with("scene:"))
        .map(str::to_string)
        .collect()
}

fn force_driven_scene(dir: &Path, csv: &str, extra: &str) -> PathBuf {
    write(
        dir,
        "fd.toml",
        format!(
            "kind = \"force-driven\"\nforce_csv = \"{csv}\"\nfidelity = \"fast\"\n{extra}\
             specimen = {{ pair = \"ss440c\" }}\n"
        )
        .as_bytes(),
    )
}

// ---------------------------------------------------------------------------------------------
// Item 5: runs that cannot finish are refused before they start.

#[test]
fn a_femtosecond_collision_step_is_refused_before_it_allocates() {
    let dir = TempDir::new().unwrap();
    let scene = write(
        dir.path(),
        "c.toml",
        b"kind = \"collision\"\nvelocity1_m_s = 5.0\ntime_step_s = 1e-15\nspecimen = { pair = \"ss440c\" }\n",
    );
    let started = std::time::Instant::now();
    let out = shpb(
        dir.path(),
        &["run", scene.to_str().unwrap(), "-o", "out.h5"],
    );
    assert_refused(
        dir.path(),
        &out,
        &[
            // 3 Hertz contact times (14.03 µs at 5 m/s) of 1 fs steps (issue 42: the estimate
            // took the 100 t_c time limit, 1.4e12 steps).
            "c.toml: the run cannot finish on this machine: it needs 4.21e10 time steps",
            "TB of memory",
            "limit: 1e10 time steps, 1e12 node updates, ",
            "of memory (",
            "a larger time_step_s",
        ],
    );
    assert!(started.elapsed().as_secs_f64() < 5.0, "refused at once");
}

#[test]
fn a_run_larger_than_the_memory_limit_is_refused_with_both_numbers() {
    let dir = TempDir::new().unwrap();
    let scene = repo().join("scenes/collision-ss440c-5ms.toml");
    let scene = scene.to_str().unwrap();
    // 100 kB: less than this run's 720 kB (6000 samples of 5 numbers, 3 for growth).
    let out = shpb_env(
        dir.path(),
        &["run", scene, "-o", "out.h5"],
        &[("SHPB_MEMORY_LIMIT", "1e5")],
    );
    assert_refused(
        dir.path(),
        &out,
        &[
            "the run cannot finish on this machine: it needs 6001 time steps",
            "kB of memory",
            "limit: 1e10 time steps, 1e12 node updates, 100 kB of memory (SHPB_MEMORY_LIMIT in the environment)",
        ],
    );
    // With the machine's memory it runs.
    assert_ok(&shpb(dir.path(), &["run", scene]));
    // A malformed limit names the variable.
    let out = shpb_env(
        dir.path(),
        &["run", scene],
        &[("SHPB_MEMORY_LIMIT", "lots")],
    );
    assert_refused(dir.path(), &out, &["environment: `SHPB_MEMORY_LIMIT`"]);
}

/// The data a run keeps, bytes (8 per number): what its HDF5 file holds.
fn data_bytes(out: &RunOutput) -> (f64, usize) {
    let mut numbers = 0usize;
    let mut longest = 0usize;
    let mut add = |n: usize| {
        numbers += n;
        longest = longest.max(n);
    };
    if let Some(c) = &out.contact {
        for s in [
            c.time_s.as_ref(),
            Some(&c.displacement_m),
            Some(&c.force_n),
            c.yield_stress_pa.as_ref(),
            c.strain_rate_per_s.as_ref(),
        ]
        .into_iter()
        .flatten()
        {
            add(s.len());
        }
    }
    if let Some(t) = &out.time_s {
        add(t.len());
    }
    for g in &out.gauges {
        add(g.strain.len());
        add(g.voltage_v.len());
    }
    for (_, e) in &out.energy {
        add(e.len());
    }
    for b in &out.bars {
        numbers += b.x_m.len() + b.time_s.len() + b.stress_pa.iter().map(Vec::len).sum::<usize>();
    }
    if let Some(r) = &out.reduction {
        numbers += 13 * r.time_s.len();
    }
    (8.0 * numbers as f64, longest)
}

#[test]
fn the_estimate_bounds_what_every_shipped_scene_keeps() {
    for entry in std::fs::read_dir(repo().join("scenes")).unwrap() {
        let path = entry.unwrap().path();
        let p = Params::from_file_with(&path, Some(shpb::fidelity::Fidelity::Fast)).unwrap();
        let e = p.estimate();
        let out = p.run().unwrap();
        let (bytes, longest) = data_bytes(&out);
        println!(
            "{}: {} steps, {} samples, memory {:.3e} B, output {:.3e} B (data {bytes:.3e} B)",
            path.display(),
            e.steps,
            e.samples_stored,
            e.memory_bytes,
            e.output_bytes
        );
        assert!(e.output_bytes >= bytes, "{}: output", path.display());
        assert!(e.memory_bytes >= bytes, "{}: memory", path.display());
        assert!(
            e.samples_stored >= longest as f64,
            "{}: samples",
            path.display()
        );
        // An upper estimate, not a wild one.
        assert!(
            e.output_bytes <= 30.0 * bytes.max(1e5),
            "{}: too pessimistic",
            path.display()
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Item 8: force records with compression negative.

#[test]
fn a_force_csv_with_compression_negative_is_refused_naming_file_and_column() {
    let dir = TempDir::new().unwrap();
    let negative = transformed_csv(&fig4_csv(), |r| vec![r[0], -r[1], -r[2]]);
    let csv = write(dir.path(), "negative.csv", negative.as_bytes());
    let scene = force_driven_scene(dir.path(), "negative.csv", "");
    let out = shpb(
        dir.path(),
        &["run", scene.to_str().unwrap(), "-o", "out.h5"],
    );
    assert_refused(
        dir.path(),
        &out,
        &[
            &format!(
                "{}: `force_N`: the value of largest magnitude, -12.3 kN",
                csv.display()
            ),
            "this file holds compression negative",
            "set force_sign = \"tension-positive\" in",
        ],
    );
    // Declared tension-positive, it runs as the original file does.
    let declared = force_driven_scene(
        dir.path(),
        "negative.csv",
        "force_sign = \"tension-positive\"\n",
    );
    let flipped = shpb(dir.path(), &["run", declared.to_str().unwrap()]);
    assert_ok(&flipped);
    let plain = force_driven_scene(dir.path(), fig4_csv().to_str().unwrap(), "");
    let original = shpb(dir.path(), &["run", plain.to_str().unwrap()]);
    assert_ok(&original);
    assert_eq!(summary(&flipped), summary(&original));
}

#[test]
fn incident_refuses_a_record_with_compression_negative() {
    let dir = TempDir::new().unwrap();
    let negative = transformed_csv(&fig4_csv(), |r| vec![r[0], r[1], -r[2]]);
    let csv = write(dir.path(), "negative.csv", negative.as_bytes());
    let out = shpb(dir.path(), &["incident", csv.to_str().unwrap()]);
    assert_refused(
        dir.path(),
        &out,
        &[
            &format!(
                "{}: `force_N`: the value of largest magnitude, -12.3 kN",
                csv.display()
            ),
            "compression negative",
        ],
    );
    assert_ok(&shpb(
        dir.path(),
        &["incident", fig4_csv().to_str().unwrap()],
    ));
}

// ---------------------------------------------------------------------------------------------
// Item 9: gauge records with inverted polarity.

#[test]
fn reduce_refuses_a_record_with_inverted_polarity() {
    let dir = TempDir::new().unwrap();
    let inverted = transformed_csv(&record_csv(), |r| vec![r[0], -r[1], -r[2]]);
    let rec = write(dir.path(), "inverted.csv", inverted.as_bytes());
    let out = shpb(
        dir.path(),
        &["reduce", rec.to_str().unwrap(), "-o", "out.h5"],
    );
    assert_refused(
        dir.path(),
        &out,
        &[
            &format!(
                "{}: `incident_strain`: the first pulse on the incident gauge is tensile",
                rec.display()
            ),
            "the channel's polarity is inverted",
            "flip the sign of `polarity` of the incident channel",
        ],
    );
    assert_ok(&shpb(
        dir.path(),
        &["reduce", record_csv().to_str().unwrap()],
    ));
}

// ---------------------------------------------------------------------------------------------
// Item 10: warnings outside the model's range of validity.

#[test]
fn a_force_record_times_10_warns_that_the_approach_left_the_model() {
    let dir = TempDir::new().unwrap();
    // Ten times the force: 0.63 R of approach (a hundred times overlapped the spheres by 6 R,
    // which issue 42 refuses: crates/cli/tests/results_trust.rs).
    let big = transformed_csv(&fig4_csv(), |r| vec![r[0], r[1], 10.0 * r[2]]);
    write(dir.path(), "big.csv", big.as_bytes());
    let scene = force_driven_scene(dir.path(), "big.csv", "");
    let out = shpb(dir.path(), &["run", scene.to_str().unwrap()]);
    assert_ok(&out);
    let err = stderr(&out);
    assert!(
        err.contains("shpb: warning: the sphere approach reaches ")
            && err.contains("of the sphere radius 3.175 mm), beyond 635 µm (0.2 R)"),
        "{err}"
    );
    // The measured record itself stays inside: no warning.
    let plain = force_driven_scene(dir.path(), fig4_csv().to_str().unwrap(), "");
    let out = shpb(dir.path(), &["run", plain.to_str().unwrap()]);
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
}

#[test]
fn a_fast_collision_warns_about_the_strain_rate() {
    let dir = TempDir::new().unwrap();
    let scene = write(
        dir.path(),
        "c.toml",
        b"kind = \"collision\"\nvelocity1_m_s = 200.0\nfidelity = \"fast\"\nspecimen = { pair = \"ss440c\" }\n",
    );
    let out = shpb(dir.path(), &["run", scene.to_str().unwrap()]);
    assert_ok(&out);
    let err = stderr(&out);
    assert!(
        err.contains("warning: the global strain rate reaches 3.15e4 1/s, beyond 1e4 1/s"),
        "{err}"
    );
    // Without rate hardening the constants do not enter: no rate warning.
    let hertz = write(
        dir.path(),
        "h.toml",
        b"kind = \"collision\"\nvelocity1_m_s = 200.0\nlaw = \"hertz\"\nfidelity = \"fast\"\nspecimen = { pair = \"ss440c\" }\n",
    );
    let out = shpb(dir.path(), &["run", hertz.to_str().unwrap()]);
    assert!(!stderr(&out).contains("strain rate"), "{}", stderr(&out));
}

#[test]
fn a_gun_pressure_outside_the_calibration_warns() {
    let dir = TempDir::new().unwrap();
    let scene = |p: &str| {
        write(
            dir.path(),
            "p.toml",
            format!(
                "kind = \"pulse\"\nbars = \"authors\"\npressure = \"{p}\"\nfidelity = \"fast\"\n"
            )
            .as_bytes(),
        )
    };
    let out = shpb(dir.path(), &["run", scene("20psi").to_str().unwrap()]);
    assert_ok(&out);
    let err = stderr(&out);
    assert!(
        err.contains("warning: gun pressure 20 psi is outside 10 to 15 psi, the pressures the gun of built-in set-up `authors` was calibrated at"),
        "{err}"
    );
    assert!(
        err.contains("warning: gun pressure 20 psi is outside 10 to 15 psi, the pressures the pulse shaper of built-in set-up `authors` was calibrated at"),
        "{err}"
    );
    // Without the shaper, or with its constants overridden, no shaper calibration is claimed.
    let bare = write(
        dir.path(),
        "b.toml",
        b"kind = \"pulse\"\nbars = \"authors\"\npressure = \"20psi\"\nfidelity = \"fast\"\n[shaper]\nenabled = false\n",
    );
    let out = shpb(dir.path(), &["run", bare.to_str().unwrap()]);
    assert!(!stderr(&out).contains("pulse shaper"), "{}", stderr(&out));
    for p in ["10psi", "12.5psi", "15psi"] {
        let out = shpb(dir.path(), &["run", scene(p).to_str().unwrap()]);
        assert!(!stderr(&out).contains("warning"), "{p}: {}", stderr(&out));
    }
}

// ---------------------------------------------------------------------------------------------
// Item 13: the result line compares like with like.

/// (true peak kN, reduced peak kN, true displacement µm) of the `result:` line.
fn result_line(out: &Output) -> (f64, f64, f64) {
    let text = stdout(out);
    let line = text
        .lines()
        .find(|l| l.starts_with("result: "))
        .unwrap_or_else(|| panic!("no result line:\n{text}"));
    let numbers: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|w| w.parse().ok())
        .collect();
    (numbers[0], numbers[1], numbers[2])
}

#[test]
fn a_long_run_compares_the_first_pulse_with_its_reduction() {
    let dir = TempDir::new().unwrap();
    let scene = |extra: &str| {
        write(
            dir.path(),
            "s.toml",
            format!(
                "kind = \"shpb\"\nbars = \"authors\"\npressure = \"10psi\"\nfidelity = \"fast\"\n{extra}\
                 specimen = {{ pair = \"ss440c\" }}\n"
            )
            .as_bytes(),
        )
    };
    let default = shpb(dir.path(), &["run", scene("").to_str().unwrap()]);
    assert_ok(&default);
    let long = shpb(
        dir.path(),
        &["run", scene("end_time_s = 10e-3\n").to_str().unwrap()],
    );
    assert_ok(&long);
    let (true_default, reduced_default, d_default) = result_line(&default);
    let (true_long, reduced_long, d_long) = result_line(&long);
    // The second impact (the bars' reflected pulse re-loading the spheres) is outside the
    // reduction's window: both sides of the line are the first pulse, as in the default run.
    assert_eq!((true_long, d_long), (true_default, d_default));
    assert_eq!(reduced_long, reduced_default);
    assert!((true_long - reduced_long).abs() < 0.02 * reduced_long);
    // The whole-run peak is still reported as such in the summary: the second impact is the
    // harder one here, so the summary's peak exceeds the first pulse's.
    let summary_peak = |out: &Output| -> f64 {
        let text = stdout(out);
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with("peak_contact_force "))
            .unwrap_or_else(|| panic!("no peak_contact_force:\n{text}"));
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    assert!((summary_peak(&default) - 1e3 * true_default).abs() < 1e-3 * summary_peak(&default));
    assert!(summary_peak(&long) > 1.02e3 * true_long);
}

// ---------------------------------------------------------------------------------------------
// Item 17: byte-order marks, CRLF, binary files.

#[test]
fn csv_inputs_accept_a_byte_order_mark_and_crlf() {
    let dir = TempDir::new().unwrap();
    let crlf = |path: &Path| {
        let text = std::fs::read_to_string(path).unwrap().replace('\n', "\r\n");
        let mut bytes = b"\xef\xbb\xbf".to_vec();
        bytes.extend_from_slice(text.as_bytes());
        bytes
    };
    // A force-driven drive.
    write(dir.path(), "excel.csv", &crlf(&fig4_csv()));
    let excel = force_driven_scene(dir.path(), "excel.csv", "");
    let plain = force_driven_scene(dir.path(), fig4_csv().to_str().unwrap(), "");
    let a = shpb(dir.path(), &["run", excel.to_str().unwrap()]);
    assert_ok(&a);
    let b = shpb(dir.path(), &["run", plain.to_str().unwrap()]);
    assert_eq!(summary(&a), summary(&b));
    // `shpb incident` on the same file.
    let csv = dir.path().join("excel.csv");
    let a = shpb(dir.path(), &["incident", csv.to_str().unwrap()]);
    let b = shpb(dir.path(), &["incident", fig4_csv().to_str().unwrap()]);
    assert_ok(&a);
    assert_eq!(
        stdout(&a).lines().skip(1).collect::<Vec<_>>(),
        stdout(&b).lines().skip(1).collect::<Vec<_>>()
    );
    // A raw gauge record for `shpb reduce`.
    let rec = write(dir.path(), "record.csv", &crlf(&record_csv()));
    let a = shpb(dir.path(), &["reduce", rec.to_str().unwrap()]);
    let b = shpb(dir.path(), &["reduce", record_csv().to_str().unwrap()]);
    assert_ok(&a);
    assert_eq!(
        stdout(&a).lines().skip(1).collect::<Vec<_>>(),
        stdout(&b).lines().skip(1).collect::<Vec<_>>()
    );
}

#[test]
fn a_binary_file_is_not_a_text_csv() {
    let dir = TempDir::new().unwrap();
    let binary: Vec<u8> = (0..=255u8).cycle().take(4096).collect();
    let bin = write(dir.path(), "drive.csv", &binary);
    let scene = force_driven_scene(dir.path(), "drive.csv", "");
    let named = format!("{}: not a text CSV", bin.display());
    let out = shpb(
        dir.path(),
        &["run", scene.to_str().unwrap(), "-o", "out.h5"],
    );
    let err = assert_refused(dir.path(), &out, &[&named]);
    assert!(!err.contains("did not contain valid UTF-8"), "{err}");
    let out = shpb(dir.path(), &["incident", bin.to_str().unwrap()]);
    assert_refused(dir.path(), &out, &[&named]);
    let out = shpb(dir.path(), &["reduce", bin.to_str().unwrap()]);
    assert_refused(dir.path(), &out, &[&named]);
}

// ---------------------------------------------------------------------------------------------
// Item 19: numbers as a person writes them; negative option values.

#[test]
fn range_messages_write_numbers_with_si_prefixes() {
    let dir = TempDir::new().unwrap();
    let scene = write(
        dir.path(),
        "c.toml",
        b"kind = \"collision\"\nvelocity1_m_s = 5.0\ntime_step_s = 0\nlaw = \"hertz\"\nspecimen = { pair = \"ss440c\" }\n",
    );
    let out = shpb(dir.path(), &["run", scene.to_str().unwrap()]);
    assert_refused(
        dir.path(),
        &out,
        &[
            "`time_step_s`: 0 s is out of range; allowed: greater than 0 and at most 3.48 µs (the stability limit",
        ],
    );
    let out = shpb(dir.path(), &["gun", "--pressure", "-0.00001psi"]);
    let err = assert_refused(
        dir.path(),
        &out,
        &[
            "`--pressure`: -1e-5 psi is outside the gun's range; allowed: 6.5 to 29.9 psi (44.8 kPa to 206.8 kPa gauge)",
        ],
    );
    assert!(!err.contains("-0.0000"), "{err}");
}

#[test]
fn negative_option_values_reach_the_range_check() {
    let dir = TempDir::new().unwrap();
    for (args, needle) in [
        (
            &["curve", "--to", "-1e-4"][..],
            "command line: `--to`: -100 µm is out of range; allowed: greater than 0 and at most 1.58 mm",
        ),
        (
            &["curve", "--to", "-.5"][..],
            "command line: `--to`: -500 mm is out of range",
        ),
        (
            &["curve", "--rate", "-1e3"][..],
            "command line: `--rate`: -1000 1/s is out of range; allowed: 0 to 1e9 1/s",
        ),
        (
            &["curve", "--points", "-5"][..],
            "command line: `--points`: -5 is out of range; allowed: 2 to 10000000",
        ),
        (
            &["incident", "x.csv", "--smoothing-us", "-1e-1"][..],
            "command line: `--smoothing-us`: -0.1 µs is out of range",
        ),
    ] {
        let out = shpb(dir.path(), args);
        assert_refused(dir.path(), &out, &[needle]);
    }
    // Options that take counts: clap names the option and the value, not "unexpected argument".
    for args in [
        &["bench", "--repeats", "-1"][..],
        &["sweep", "s.toml", "--set", "pressure=10psi", "-j", "-2"][..],
    ] {
        let out = shpb(dir.path(), args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(BAD_INPUT), "{err}");
        assert!(err.contains("invalid value '-"), "{err}");
    }
}

/// The library route of item 5: `Params::estimate` is public and allocation-free, and
/// `resources::check` compares it with given limits.
#[test]
fn the_estimate_is_public_on_the_validated_scene() {
    let p = Params::from_file(&repo().join("scenes/shpb-ss440c-10psi.toml")).unwrap();
    let e: shpb::estimate::RunEstimate = p.estimate();
    let limits = shpb::resources::Limits {
        memory_bytes: e.memory_bytes,
        ..shpb::resources::Limits::of_machine().unwrap()
    };
    assert_eq!(shpb::resources::check(&p, &limits).unwrap(), e);
    let tight = shpb::resources::Limits {
        memory_bytes: 0.5 * e.memory_bytes,
        ..limits
    };
    assert_eq!(
        shpb::resources::check(&p, &tight).unwrap_err().exit_code(),
        2
    );
    assert!(e.steps > 1e3 && e.degrees_of_freedom > 2000.0 && e.output_bytes > 1e5);
    assert!(e.updates() == e.steps * e.degrees_of_freedom);
}
