//! Property-based tests of the input readers (issue 9): scene TOML files and CSV inputs mutated at
//! random (unknown and dropped keys, NaN/inf, huge, negative and zero numbers, odd pressure units,
//! truncated, empty and non-UTF-8 files) are either accepted or refused with an error that names
//! the file — never a panic.
//!
//! Case counts are bounded (128 per property; `SHPB_PROPTEST_CASES=n` for a longer search) so the
//! file runs in well under a second in release; proptest turns any panic inside a property into a
//! failure and shrinks it.

use proptest::prelude::*;
use shpb::csv::CsvTable;
use shpb::error::Error;
use shpb::gauge::RawRecord;
use shpb::prelude::*;
use shpb::scene::{Params, SceneParams};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn scenes_dir() -> PathBuf {
    root().join("scenes")
}

/// The shipped scenes, in a fixed order.
fn shipped_scenes() -> Vec<String> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no shipped scenes");
    paths
        .iter()
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect()
}

/// The label passed as the scene's file name (it must appear in every error about the scene).
fn scene_label() -> String {
    scenes_dir()
        .join("proptest-mutated.toml")
        .display()
        .to_string()
}

/// Checks that an error from reading input `label` names a file: `label` itself, or another input
/// file the scene refers to (a CSV, a bar set-up, a material), and that its message is non-empty.
fn check_error(e: &Error, label: &str, also: &[&str]) -> Result<(), TestCaseError> {
    let shown = e.to_string();
    prop_assert!(!shown.trim().is_empty(), "empty error message");
    let file = match e {
        Error::Input { file, .. } | Error::Parse { file, .. } | Error::Io { file, .. } => {
            file.clone()
        }
        other => {
            return Err(TestCaseError::fail(format!(
                "unexpected error kind: {other}"
            )));
        }
    };
    prop_assert!(!file.is_empty(), "error names no file: {shown}");
    prop_assert!(
        shown.contains(&file),
        "message does not show the file: {shown}"
    );
    let file_path = file.rsplit_once(':').map_or(file.as_str(), |(f, line)| {
        if line.chars().all(|c| c.is_ascii_digit()) {
            f
        } else {
            file.as_str()
        }
    });
    let named = file_path == label || also.contains(&file_path) || Path::new(file_path).is_file();
    prop_assert!(
        named,
        "error does not name `{label}` or a referenced file: {shown}"
    );
    Ok(())
}

/// Values substituted for numbers: non-finite, huge, tiny, negative, zero, wrong types.
fn odd_value() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "nan",
            "+nan",
            "-nan",
            "inf",
            "+inf",
            "-inf",
            "0",
            "0.0",
            "-0.0",
            "-1",
            "-1.0e3",
            "1e308",
            "-1e308",
            "1e400",
            "1e-400",
            "5e-324",
            "9223372036854775807",
            "-9223372036854775808",
            "18446744073709551616",
            "1e9",
            "1e10",
            "3",
            "\"\"",
            "\"10\"",
            "true",
            "[1.0, 2.0]",
            "{ a = 1 }",
            "1979-05-27",
            "0x10",
            "1_000",
        ])
        .prop_map(str::to_string),
        any::<f64>().prop_map(|x| format!("{x:e}")),
        any::<i64>().prop_map(|x| x.to_string()),
        (-1e3f64..1e3).prop_map(|x| format!("{x:e}")),
    ]
}

/// Strings substituted for string values (pressures with odd units, names, paths).
fn odd_string() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "NaNpsi",
            "nanpsi",
            "infpsi",
            "-infbar",
            "-5bar",
            "1e400kPa",
            "1e-400Pa",
            "10 psi",
            "10PSI",
            "psi",
            "",
            " ",
            "10",
            "0psi",
            "-0psi",
            "1e308MPa",
            "10psipsi",
            "10 kPa ",
            "ss440c",
            "al2017",
            "ss302",
            "unobtainium",
            "fast",
            "standard",
            "reference",
            "burgoyne-daraio",
            "hertz",
            "collision",
            "quasistatic",
            "pulse",
            "shpb",
            "force-driven",
            "constant-rate",
            "free",
            "absorbing",
            "transmission",
            "none",
            "love-rod",
            "../bars/authors.toml",
            "../bars/gauges-authors.toml",
            "/",
            ".",
            "../specimens/ss440c.toml",
            "../specimens/pair-6.35mm-al2017.toml",
            "nope.toml",
            "../validation/fig4-force-driven/data/ss440c_10psi_force10.csv",
            "x.csv",
            "\u{0}",
            "é",
            "\u{1F600}psi",
        ])
        .prop_map(str::to_string),
        "[-+]?[0-9]{0,3}(\\.[0-9]{0,3})?([eE][-+]?[0-9]{1,3})? ?(psi|bar|kPa|MPa|GPa|Pa|atm|NaN|)",
        "[a-zA-Z0-9 ._/-]{0,12}",
    ]
}

/// Key names inserted into a scene: known keys (to reach deeper validation) and unknown ones.
fn some_key() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "kind",
            "fidelity",
            "law",
            "region2",
            "points",
            "max_displacement_m",
            "strain_rate_per_s",
            "velocity1_m_s",
            "velocity2_m_s",
            "time_step_s",
            "steps_per_contact",
            "output_every",
            "force_csv",
            "time_column",
            "force_column",
            "medium_impedance_kg_s",
            "steps_per_period",
            "end_time_s",
            "bars",
            "pressure",
            "incident_end",
            "dispersion",
            "cell_size_m",
            "gauge_length_m",
            "pair",
            "material",
            "diameter_m",
            "radius_m",
            "mass_kg",
            "specimen",
            "shaper",
        ])
        .prop_map(str::to_string),
        "[a-z_][a-z0-9_]{0,10}",
    ]
}

#[derive(Debug, Clone)]
enum Mutation {
    /// Replace the value of the `i`-th `key = value` line with a number-like value.
    Value(usize, String),
    /// Replace the value of the `i`-th `key = value` line with a quoted string.
    Str(usize, String),
    /// Drop line `i`.
    Drop(usize),
    /// Insert `key = value` before line `i`.
    Insert(usize, String, String),
    /// Insert a table header before line `i`.
    Table(usize, String),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        3 => (any::<usize>(), odd_value()).prop_map(|(i, v)| Mutation::Value(i, v)),
        2 => (any::<usize>(), odd_string()).prop_map(|(i, s)| Mutation::Str(i, s)),
        1 => any::<usize>().prop_map(Mutation::Drop),
        2 => (any::<usize>(), some_key(), prop_oneof![odd_value(), odd_string().prop_map(|s| quote(&s))])
            .prop_map(|(i, k, v)| Mutation::Insert(i, k, v)),
        1 => (any::<usize>(), prop::sample::select(vec![
            "specimen", "specimen.sphere1", "specimen.sphere2", "shaper", "bars", "x", "specimen.x",
        ]))
            .prop_map(|(i, t)| Mutation::Table(i, t.to_string())),
    ]
}

/// A TOML basic string holding `s`.
fn quote(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Applies mutations to scene text, line by line.
fn mutate(text: &str, mutations: &[Mutation]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for m in mutations {
        let assignments: Vec<usize> = lines
            .iter()
            .enumerate()
            .filter(|(_, l)| !l.trim_start().starts_with('#') && l.contains('='))
            .map(|(i, _)| i)
            .collect();
        match m {
            Mutation::Value(i, v) | Mutation::Str(i, v) if !assignments.is_empty() => {
                let at = assignments[i % assignments.len()];
                let key = lines[at].split('=').next().unwrap().trim_end().to_string();
                let value = match m {
                    Mutation::Str(..) => quote(v),
                    _ => v.clone(),
                };
                lines[at] = format!("{key} = {value}");
            }
            Mutation::Drop(i) if !lines.is_empty() => {
                let at = i % lines.len();
                lines.remove(at);
            }
            Mutation::Insert(i, k, v) => {
                let at = i % (lines.len() + 1);
                lines.insert(at, format!("{k} = {v}"));
            }
            Mutation::Table(i, t) => {
                let at = i % (lines.len() + 1);
                lines.insert(at, format!("[{t}]"));
            }
            _ => {}
        }
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out
}

/// Cuts `text` at the char boundary at or below `frac` of its length.
fn truncate(text: &str, frac: f64) -> &str {
    let mut at = ((text.len() as f64) * frac.clamp(0.0, 1.0)) as usize;
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    &text[..at]
}

/// Runs an accepted scene when the run is cheap (the DEM kinds on a modest grid); the bar kinds
/// and force-driven runs take 10–60 ms each and are left to the scene tests.
fn run_if_cheap(p: &Params) -> Result<(), TestCaseError> {
    let cheap = match &p.params {
        SceneParams::Quasistatic { points, .. } | SceneParams::ConstantRate { points, .. } => {
            *points <= 200_000
        }
        SceneParams::Collision(setup) => {
            let pair = p.sphere_pair().unwrap().0;
            let c = pair.contact_properties();
            let tc = shpb::solver::hertz_impact_duration(
                pair.reduced_mass_kg(),
                c.e_star_pa,
                c.radius_m,
                setup.velocity1_m_s - setup.velocity2_m_s,
            );
            tc.is_finite() && tc / setup.dt_s <= 5e4
        }
        SceneParams::Pulse { .. } | SceneParams::ForceDriven { .. } | SceneParams::Chain(_) => {
            false
        }
    };
    if cheap && let Err(e) = p.run() {
        prop_assert!(!e.to_string().trim().is_empty(), "empty run error");
    }
    Ok(())
}

/// Checks what `Params::from_toml` makes of `text`: no panic, and an error names the scene (or a
/// file the scene refers to).
fn check_scene(text: &str) -> Result<(), TestCaseError> {
    let label = scene_label();
    match Params::from_toml(text, &label, &scenes_dir()) {
        Ok(p) => {
            if let SceneParams::ForceDriven { setup, .. } = &p.params {
                prop_assert!(
                    setup.dt_s.is_finite() && setup.dt_s > 0.0,
                    "accepted force-driven time step {}",
                    setup.dt_s
                );
                prop_assert!(setup.end_time_s.is_finite() && setup.end_time_s > 0.0);
            }
            if let SceneParams::Collision(setup) = &p.params {
                prop_assert!(setup.dt_s.is_finite() && setup.dt_s > 0.0);
            }
            run_if_cheap(&p)
        }
        Err(e) => check_error(&e, &label, &[]),
    }
}

/// A shipped scene's text and a list of mutations.
fn mutated_scene() -> impl Strategy<Value = String> {
    let scenes = shipped_scenes();
    let n = scenes.len();
    (0..n, prop::collection::vec(mutation(), 1..5)).prop_map(move |(k, ms)| mutate(&scenes[k], &ms))
}

// ---------------------------------------------------------------- CSV generators

/// A CSV cell: numbers of every kind, non-finite values, garbage and blanks.
fn csv_cell() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-1e3f64..1e3).prop_map(|x| format!("{x:e}")),
        1 => any::<f64>().prop_map(|x| x.to_string()),
        1 => prop::sample::select(vec![
            "nan", "NaN", "inf", "-inf", "infinity", "1e400", "-1e400", "1e-400", "1e308",
            "-1e308", "", " ", "abc", "1,2", "0x10", "1_0", "--1", "+1", ".5", "5.", "e5",
            "\u{FFFD}", "é",
        ])
        .prop_map(str::to_string),
    ]
}

/// A column name: the ones the readers look for, and others.
fn csv_name() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => prop::sample::select(vec![
            "time_s", "force_N", "displacement_m", "incident_V", "transmission_V",
        ])
        .prop_map(str::to_string),
        1 => prop::sample::select(vec!["", " ", "Time_s", "time_s ", "force_n", "#x"])
            .prop_map(str::to_string),
        1 => "[a-zA-Z_]{1,8}",
    ]
}

/// A CSV text: optional comments, a header, rows of (possibly ragged) cells, blank lines, and
/// a time column that is increasing, constant or shuffled.
fn csv_text() -> impl Strategy<Value = String> {
    (
        prop::collection::vec(csv_name(), 1..5),
        prop::collection::vec(prop::collection::vec(csv_cell(), 0..6), 0..8),
        any::<bool>(),
        0usize..3,
        any::<bool>(),
    )
        .prop_map(|(names, rows, comment, time_mode, crlf)| {
            let nl = if crlf { "\r\n" } else { "\n" };
            let mut s = String::new();
            if comment {
                s.push_str("# a comment line");
                s.push_str(nl);
            }
            s.push_str(&names.join(","));
            s.push_str(nl);
            for (r, row) in rows.iter().enumerate() {
                let mut cells = row.clone();
                // Mostly well-formed rows with an increasing/constant/decreasing first column.
                if r % 3 != 2 {
                    cells.resize(names.len(), "1.0".to_string());
                    cells[0] = match time_mode {
                        0 => format!("{:e}", r as f64 * 1e-6),
                        1 => "0".to_string(),
                        _ => format!("{:e}", -(r as f64)),
                    };
                }
                s.push_str(&cells.join(","));
                s.push_str(nl);
                if r % 4 == 3 {
                    s.push_str(nl);
                }
            }
            s
        })
}

/// The shipped force history with mutations: cells replaced, rows dropped, truncation.
fn mutated_force_csv() -> impl Strategy<Value = String> {
    let text = std::fs::read_to_string(
        root().join("validation/fig4-force-driven/data/ss440c_10psi_force10.csv"),
    )
    .unwrap();
    // Keep the mutation cheap: the first 200 lines are enough to exercise every path.
    let text: String = text.lines().take(200).collect::<Vec<_>>().join("\n") + "\n";
    (
        prop::collection::vec((any::<usize>(), any::<usize>(), csv_cell()), 0..4),
        prop::option::of(0.0f64..1.0),
        prop::option::of(csv_name()),
    )
        .prop_map(move |(edits, cut, rename)| {
            let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
            for (row, col, cell) in edits {
                let at = row % lines.len();
                let mut cells: Vec<String> = lines[at].split(',').map(str::to_string).collect();
                let c = col % cells.len();
                cells[c] = cell;
                lines[at] = cells.join(",");
            }
            if let Some(name) = rename
                && let Some(h) = lines.iter().position(|l| l.starts_with("time_s"))
            {
                lines[h] = lines[h].replacen("time_s", &name, 1);
            }
            let mut s = lines.join("\n") + "\n";
            if let Some(f) = cut {
                s = truncate(&s, f).to_string();
            }
            s
        })
}

/// A force-driven scene pointing at `csv` (absolute path), with optional extra keys.
fn force_driven_scene(csv: &Path, extra: &str) -> String {
    format!(
        "kind = \"force-driven\"\nlaw = \"burgoyne-daraio\"\nforce_csv = {}\n{extra}\n[specimen]\npair = \"ss440c\"\n",
        quote(&csv.display().to_string())
    )
}

fn check_csv_error(e: &Error, label: &str) -> Result<(), TestCaseError> {
    check_error(e, label, &[])
}

/// Cases per property: 128 (bounded for `make test`), or `SHPB_PROPTEST_CASES` for a longer search.
fn cases() -> u32 {
    std::env::var("SHPB_PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(128)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    /// Mutated shipped scenes: accepted (and, for the cheap kinds, run) or refused naming the file.
    #[test]
    fn mutated_scenes_never_panic(text in mutated_scene()) {
        check_scene(&text)?;
    }

    /// Mutated scenes cut at a random byte.
    #[test]
    fn truncated_scenes_never_panic(text in mutated_scene(), frac in 0.0f64..1.0) {
        check_scene(truncate(&text, frac))?;
    }

    /// Pulse and SHPB scenes with random pressure strings: every unit, sign and magnitude.
    #[test]
    fn pulse_pressures_never_panic(shpb in any::<bool>(), pressure in odd_string()) {
        let name = if shpb { "shpb-ss440c-10psi.toml" } else { "pulse-10psi.toml" };
        let text = std::fs::read_to_string(scenes_dir().join(name)).unwrap();
        let text = text.replace("\"10psi\"", &quote(&pressure));
        check_scene(&text)?;
    }

    /// Arbitrary text and lossy-decoded random bytes as a scene.
    #[test]
    fn garbage_scenes_never_panic(
        text in prop_oneof![
            ".{0,200}",
            prop::collection::vec(any::<u8>(), 0..200)
                .prop_map(|b| String::from_utf8_lossy(&b).into_owned()),
            (some_key(), odd_value()).prop_map(|(k, v)| format!("{k} = {v}\n")),
        ]
    ) {
        check_scene(&text)?;
    }

    /// Generated CSV texts: parsed or refused naming the file (with the line).
    #[test]
    fn csv_tables_never_panic(text in csv_text(), frac in prop::option::of(0.0f64..1.0)) {
        let label = "/proptest/table.csv";
        let text = match frac { Some(f) => truncate(&text, f), None => &text };
        match CsvTable::parse(text, label) {
            Ok(t) => {
                prop_assert_eq!(t.names.len(), t.columns.len());
                prop_assert!(t.columns.iter().flatten().all(|v| v.is_finite()));
                for name in ["time_s", "force_N"] {
                    if let Err(e) = t.time_column(name) {
                        check_csv_error(&e, label)?;
                    }
                }
            }
            Err(e) => check_csv_error(&e, label)?,
        }
    }

    /// Raw gauge records from generated CSV texts, including the sampling interval of accepted ones.
    #[test]
    fn raw_records_never_panic(text in csv_text(), frac in prop::option::of(0.0f64..1.0)) {
        let label = "/proptest/record.csv";
        let text = match frac { Some(f) => truncate(&text, f), None => &text };
        match RawRecord::parse(text, label) {
            Ok(r) => {
                prop_assert!(r.time_s.len() >= 2);
                prop_assert!(r.time_s.windows(2).all(|w| w[1] > w[0]));
                prop_assert!(r.sample_interval_s() > 0.0);
            }
            Err(e) => check_csv_error(&e, label)?,
        }
    }

    /// CSV and gauge-record files of random bytes (mostly not UTF-8) read from disk.
    #[test]
    fn binary_csv_files_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bytes.csv");
        std::fs::write(&path, &bytes).unwrap();
        let label = path.display().to_string();
        if let Err(e) = CsvTable::read(&path) {
            check_csv_error(&e, &label)?;
        }
        if let Err(e) = RawRecord::read(&path) {
            check_csv_error(&e, &label)?;
        }
    }

    /// A force-driven scene over a mutated copy of the Fig. 4 force history (and odd keys).
    #[test]
    fn force_driven_csv_never_panics(
        csv in prop_oneof![
            4 => mutated_force_csv().prop_map(String::into_bytes),
            1 => csv_text().prop_map(String::into_bytes),
            1 => prop::collection::vec(any::<u8>(), 0..100),
        ],
        extra in prop::option::of((prop::sample::select(vec![
            "time_column", "force_column", "medium_impedance_kg_s", "time_step_s",
            "steps_per_period", "end_time_s", "output_every",
        ]), prop_oneof![odd_value(), odd_string().prop_map(|s| quote(&s))]))
    ) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("force.csv");
        std::fs::write(&path, &csv).unwrap();
        let extra = extra.map(|(k, v)| format!("{k} = {v}")).unwrap_or_default();
        let text = force_driven_scene(&path, &extra);
        let label = scene_label();
        let csv_label = path.display().to_string();
        match Params::from_toml(&text, &label, &scenes_dir()) {
            Ok(p) => {
                if let SceneParams::ForceDriven { setup, .. } = &p.params {
                    prop_assert!(setup.dt_s.is_finite() && setup.dt_s > 0.0, "time step {}", setup.dt_s);
                    prop_assert!(setup.end_time_s.is_finite() && setup.end_time_s > 0.0);
                }
            }
            Err(e) => check_error(&e, &label, &[csv_label.as_str()])?,
        }
    }
}

// ---------------------------------------------------------------- fixed cases

#[test]
fn empty_scene_names_the_file() {
    let label = scene_label();
    let e = Params::from_toml("", &label, &scenes_dir()).unwrap_err();
    assert!(e.to_string().contains(&label), "{e}");
}

#[test]
fn empty_and_comment_only_csv_name_the_file() {
    for text in ["", "\n\n", "# only a comment\n", "time_s,force_N\n"] {
        let e = CsvTable::parse(text, "/x/empty.csv").unwrap_err();
        assert!(e.to_string().contains("/x/empty.csv"), "{e}");
        let e = RawRecord::parse(text, "/x/empty.csv").unwrap_err();
        assert!(e.to_string().contains("/x/empty.csv"), "{e}");
    }
}

#[test]
fn non_utf8_csv_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.csv");
    std::fs::write(&path, b"time_s,force_N\n0,1\n1,\xe9\n").unwrap();
    let e = CsvTable::read(&path).unwrap_err();
    assert!(e.to_string().contains(&path.display().to_string()), "{e}");
}

#[test]
fn odd_pressures_are_refused_naming_the_file() {
    let label = scene_label();
    let text = std::fs::read_to_string(scenes_dir().join("pulse-10psi.toml")).unwrap();
    for p in [
        "NaNpsi", "-5bar", "1e400kPa", "infpsi", "", "psi", "10", "1e308MPa",
    ] {
        let t = text.replace("\"10psi\"", &quote(p));
        let e = Params::from_toml(&t, &label, &scenes_dir()).unwrap_err();
        let s = e.to_string();
        assert!(s.contains(&label) && s.contains("pressure"), "{p}: {s}");
    }
}

/// Regression (found by `pulse_pressures_never_panic`): a pressure whose last non-letter is a
/// multi-byte character (`é`, `10µpsi`) made `parse_pressure` slice inside the character and panic.
#[test]
fn non_ascii_pressure_is_an_error_not_a_panic() {
    for p in ["é", "10é", "10µpsi", "10\u{1F600}", "\u{1F600}psi", "½bar"] {
        assert!(shpb::units::parse_pressure(p).is_err(), "{p}");
        let e = shpb::units::cli_pressure(p).unwrap_err();
        assert!(e.to_string().contains("--pressure"), "{e}");
    }
    let label = scene_label();
    let text = std::fs::read_to_string(scenes_dir().join("pulse-10psi.toml")).unwrap();
    let e =
        Params::from_toml(&text.replace("\"10psi\"", "\"é\""), &label, &scenes_dir()).unwrap_err();
    assert!(e.to_string().contains(&label), "{e}");
}

/// Regression (found by `mutated_scenes_never_panic`): a subnormal closing speed made the Hertz
/// contact time, and so the default time step, infinite, and the scene was accepted.
#[test]
fn subnormal_collision_speed_is_refused() {
    let label = scene_label();
    let text = std::fs::read_to_string(scenes_dir().join("collision-dissimilar.toml")).unwrap();
    let text = text.replace(
        "velocity1_m_s = 2.0",
        "velocity1_m_s = 6.052751140807466e-309",
    );
    let e = Params::from_toml(&text, &label, &scenes_dir()).unwrap_err();
    let s = e.to_string();
    assert!(s.contains(&label) && s.contains("velocity1_m_s"), "{s}");
}
