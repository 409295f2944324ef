//! The `shpb` binary end to end: bad input is refused with a message naming the file, the key
//! and what is allowed, and leaves no output (nor temporary file) behind; good input writes
//! HDF5 with units and provenance, CSV with a header, and a `curve` table on stdout.

use hdf5::types::VarLenUnicode;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use tempfile::TempDir;

const BIN: &str = env!("CARGO_BIN_EXE_shpb");

/// Exit code the CLI documents for bad input.
const BAD_INPUT: i32 = 2;

/// Outputs requested by every failing run; none of them may exist afterwards.
const OUTPUTS: [&str; 3] = ["out.h5", "out.csv", "out.png"];

/// The repository root (this crate is `crates/cli`): `bars/`, `scenes/`, `validation/`.
fn repo() -> String {
    format!("{}/../..", env!("CARGO_MANIFEST_DIR"))
}

/// The measured SS440c 10 psi force history shipped with the repository.
fn measured_force_csv() -> String {
    format!(
        "{}/validation/fig4-force-driven/data/ss440c_10psi_force10.csv",
        repo()
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write test input");
    p
}

fn shpb(dir: &Path, args: &[&str]) -> Output {
    Command::new(BIN)
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run the shpb binary")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Runs `shpb run <scene>` asking for HDF5, CSV and PNG output in `dir`.
fn run_scene(dir: &Path, scene: &Path) -> Output {
    let scene = scene.to_str().expect("UTF-8 temp path");
    shpb(
        dir,
        &[
            "run", scene, "-o", "out.h5", "--csv", "out.csv", "--plot", "out.png",
        ],
    )
}

/// Entries of `dir` whose names start with `.shpb-tmp-` (the atomic writer's temporary files).
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .expect("list temp dir")
        .map(|e| {
            e.expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|n| n.starts_with(".shpb-tmp-"))
        .collect()
}

/// Checks a refused run: non-zero exit (`code` if given), every `needle` in stderr, and no
/// output or temporary file in `dir`. Returns stderr.
fn assert_refused(dir: &Path, out: &Output, code: Option<i32>, needles: &[&str]) -> String {
    let err = text(&out.stderr);
    assert!(
        !out.status.success(),
        "expected failure, got success; stderr:\n{err}"
    );
    if let Some(c) = code {
        assert_eq!(out.status.code(), Some(c), "exit code; stderr:\n{err}");
    }
    for n in needles {
        assert!(err.contains(n), "stderr lacks `{n}`:\n{err}");
    }
    for o in OUTPUTS {
        assert!(!dir.join(o).exists(), "{o} was left behind; stderr:\n{err}");
    }
    assert_eq!(
        temporaries(dir),
        Vec::<String>::new(),
        "temporary files left"
    );
    err
}

/// Writes `text` as `scene.toml` in a fresh directory, runs it, and checks that it is refused as
/// bad input with a message naming the scene file and containing every needle.
fn assert_scene_refused(text: &str, needles: &[&str]) {
    let dir = TempDir::new().unwrap();
    let scene = write(dir.path(), "scene.toml", text);
    let out = run_scene(dir.path(), &scene);
    let mut all = vec![scene.to_str().unwrap()];
    all.extend_from_slice(needles);
    assert_refused(dir.path(), &out, Some(BAD_INPUT), &all);
}

const QUASISTATIC: &str = r#"
kind = "quasistatic"
max_displacement_m = 200e-6
points = 51

[specimen]
pair = "ss440c"
"#;

const CONSTANT_RATE: &str = r#"
kind = "constant-rate"
strain_rate_per_s = 1e4
max_displacement_m = 200e-6
points = 51

[specimen]
pair = "ss440c"
"#;

const COLLISION: &str = r#"
kind = "collision"
velocity1_m_s = 2.0

[specimen]
pair = "ss440c"
"#;

fn force_driven(csv: &str) -> String {
    format!(
        r#"
kind = "force-driven"
force_csv = "{csv}"

[specimen]
pair = "ss440c"
"#
    )
}

// ---------------------------------------------------------------- bad input

#[test]
fn unknown_key_in_scene_names_file_key_and_allowed_keys() {
    // A typo in a top-level key (it must sit before the [specimen] table).
    assert_scene_refused(
        &QUASISTATIC.replace("points = 51", "points = 51\nmax_displacment_m = 1e-4"),
        &[
            "max_displacment_m",
            "unknown field",
            // the allowed keys are listed
            "`max_displacement_m`",
            "`strain_rate_per_s`",
        ],
    );
}

#[test]
fn missing_scene_file_is_named() {
    let dir = TempDir::new().unwrap();
    let scene = dir.path().join("no-such-scene.toml");
    let out = run_scene(dir.path(), &scene);
    assert_refused(
        dir.path(),
        &out,
        Some(BAD_INPUT),
        &[scene.to_str().unwrap(), "No such file"],
    );
}

/// A missing input file is bad input (exit 2) wherever it is read: scene, record, set-up.
#[test]
fn a_missing_input_file_exits_2_in_every_command() {
    let dir = TempDir::new().unwrap();
    for args in [
        &["run", "nope.toml"][..],
        &["reduce", "nope.csv"][..],
        &["strain", "nope.csv"][..],
        &["incident", "nope.csv"][..],
        &["sweep", "nope.toml", "--set", "pressure=10psi"][..],
        &["convergence", "nope.toml"][..],
        &["gun", "--pressure", "10psi", "--bars", "nope.toml"][..],
        &["merge", "nope.h5", "-o", "m.h5"][..],
    ] {
        let out = shpb(dir.path(), args);
        assert_eq!(
            out.status.code(),
            Some(BAD_INPUT),
            "{args:?}: {}",
            text(&out.stderr)
        );
        assert!(
            text(&out.stderr).contains("nope"),
            "{args:?}: {}",
            text(&out.stderr)
        );
    }
}

#[test]
fn missing_force_csv_is_named() {
    let dir = TempDir::new().unwrap();
    let scene = write(dir.path(), "scene.toml", &force_driven("no-such-force.csv"));
    let out = run_scene(dir.path(), &scene);
    let csv = dir.path().join("no-such-force.csv");
    assert_refused(
        dir.path(),
        &out,
        Some(BAD_INPUT),
        &[csv.to_str().unwrap(), "No such file"],
    );
}

/// The message should also name the scene file and its `force_csv` key; that needs the
/// `force_csv` read in `Params::from_toml` (src/scene.rs) to map its I/O error to an input
/// error of the scene's validator.
#[test]
fn missing_force_csv_names_scene_and_key() {
    let dir = TempDir::new().unwrap();
    let scene = write(dir.path(), "scene.toml", &force_driven("no-such-force.csv"));
    let out = run_scene(dir.path(), &scene);
    assert_refused(
        dir.path(),
        &out,
        Some(BAD_INPUT),
        &[
            scene.to_str().unwrap(),
            "`force_csv`",
            "no-such-force.csv",
            "allowed:",
        ],
    );
}

#[test]
fn negative_radius_names_key_and_range() {
    assert_scene_refused(
        r#"
kind = "quasistatic"
max_displacement_m = 100e-6

[specimen.sphere1]
material = "ss440c"
radius_m = -1e-3

[specimen.sphere2]
material = "ss440c"
radius_m = 3e-3
"#,
        &[
            "`specimen.sphere1.radius_m`",
            "-1 mm is out of range",
            "allowed: greater than 0 and at most 5 m",
        ],
    );
}

#[test]
fn nan_velocity_names_key_and_range() {
    assert_scene_refused(
        &COLLISION.replace("velocity1_m_s = 2.0", "velocity1_m_s = nan"),
        &[
            "`velocity1_m_s`",
            "NaN is not a finite number",
            "allowed: -1e4 to 1e4 m/s",
        ],
    );
}

#[test]
fn non_monotonic_force_time_names_csv_column_and_row() {
    let dir = TempDir::new().unwrap();
    let csv = write(
        dir.path(),
        "force.csv",
        "# a force history whose clock runs backwards once\n\
         time_s,force_N\n\
         0,0\n\
         1e-6,100\n\
         3e-6,300\n\
         2e-6,200\n\
         4e-6,0\n",
    );
    let scene = write(dir.path(), "scene.toml", &force_driven("force.csv"));
    let out = run_scene(dir.path(), &scene);
    assert_refused(
        dir.path(),
        &out,
        Some(BAD_INPUT),
        &[
            csv.to_str().unwrap(),
            "`time_s`",
            "not strictly increasing at data row 4 (2e-6 after 3e-6)",
            "allowed: strictly increasing times",
        ],
    );
}

#[test]
fn unknown_material_names_key_and_builtin_materials() {
    assert_scene_refused(
        r#"
kind = "quasistatic"
max_displacement_m = 100e-6

[specimen.sphere1]
material = "unobtainium"
diameter_m = 6.35e-3

[specimen.sphere2]
material = "ss440c"
diameter_m = 6.35e-3
"#,
        &[
            "`specimen.sphere1.material`",
            "unknown material `unobtainium`",
            "allowed: ss440c, ss302, al2017, ofhc-copper, al6061-t6, al7075-t6, ti6al4v, steel4340 or a path to a material .toml file",
        ],
    );
}

#[test]
fn unknown_kind_names_key_and_all_kinds() {
    assert_scene_refused(
        &QUASISTATIC.replace("\"quasistatic\"", "\"teleport\""),
        &[
            "`kind`",
            "unknown scene kind `teleport`",
            "allowed: quasistatic, constant-rate, collision, force-driven",
        ],
    );
}

#[test]
fn existing_output_is_kept_without_force() {
    let dir = TempDir::new().unwrap();
    let scene = write(dir.path(), "scene.toml", QUASISTATIC);
    let h5 = write(dir.path(), "out.h5", "precious results\n");
    let out = shpb(
        dir.path(),
        &["run", scene.to_str().unwrap(), "-o", "out.h5"],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(BAD_INPUT), "stderr:\n{err}");
    assert!(err.contains("out.h5"), "stderr lacks the file:\n{err}");
    assert!(err.contains("--force"), "stderr lacks the remedy:\n{err}");
    assert_eq!(std::fs::read_to_string(&h5).unwrap(), "precious results\n");
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());

    // The same for a CSV output: an existing one stops the run before the HDF5 file is written.
    let csv = write(dir.path(), "out.csv", "precious,table\n");
    std::fs::remove_file(&h5).unwrap();
    let out = shpb(
        dir.path(),
        &[
            "run",
            scene.to_str().unwrap(),
            "-o",
            "out.h5",
            "--csv",
            "out.csv",
        ],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(BAD_INPUT), "stderr:\n{err}");
    assert!(err.contains("out.csv"), "stderr lacks the file:\n{err}");
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "precious,table\n");
    assert!(!h5.exists(), "out.h5 written although the run was refused");
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());
}

#[test]
fn existing_output_is_replaced_with_force() {
    let dir = TempDir::new().unwrap();
    let scene = write(dir.path(), "scene.toml", QUASISTATIC);
    let h5 = write(dir.path(), "out.h5", "precious results\n");
    let out = shpb(
        dir.path(),
        &["run", scene.to_str().unwrap(), "-o", "out.h5", "--force"],
    );
    assert!(out.status.success(), "stderr:\n{}", text(&out.stderr));
    assert_ne!(std::fs::read(&h5).unwrap(), b"precious results\n");
    let f = hdf5::File::open(&h5).expect("replaced file is HDF5");
    assert_eq!(f.dataset("contact/force").unwrap().size(), 51);
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());
}

#[test]
fn curve_negative_to_names_option_and_range() {
    let dir = TempDir::new().unwrap();
    let out = shpb(dir.path(), &["curve", "--to", "-1"]);
    assert_refused(
        dir.path(),
        &out,
        Some(BAD_INPUT),
        &[
            "command line",
            "`--to`",
            "-1 m is out of range",
            "allowed: greater than 0 and at most 1.58 mm",
        ],
    );
    assert!(out.stdout.is_empty(), "no table on refusal");
}

#[test]
fn curve_nan_rate_names_option_and_range() {
    let dir = TempDir::new().unwrap();
    let out = shpb(dir.path(), &["curve", "--rate", "nan"]);
    assert_refused(
        dir.path(),
        &out,
        Some(BAD_INPUT),
        &[
            "command line",
            "`--rate`",
            "NaN is not a finite number",
            "allowed: 0 to 1e9 1/s",
        ],
    );
    assert!(out.stdout.is_empty(), "no table on refusal");
}

// ---------------------------------------------------------------- good input

fn string_attr(loc: &hdf5::Location, name: &str) -> String {
    loc.attr(name)
        .unwrap_or_else(|e| panic!("attribute `{name}`: {e}"))
        .read_scalar::<VarLenUnicode>()
        .unwrap_or_else(|e| panic!("attribute `{name}` as string: {e}"))
        .as_str()
        .to_string()
}

/// Runs `scene_text` with `-o` and checks the HDF5 layout: `/contact/*` with units (those in
/// `absent` missing), root provenance attributes, `/summary`. Returns the number of samples.
fn run_and_check_hdf5(scene_text: &str, present: &[(&str, &str)], absent: &[&str]) -> usize {
    let dir = TempDir::new().unwrap();
    let scene = write(dir.path(), "scene.toml", scene_text);
    let out = shpb(
        dir.path(),
        &["run", scene.to_str().unwrap(), "-o", "out.h5"],
    );
    assert!(out.status.success(), "stderr:\n{}", text(&out.stderr));
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());

    let f = hdf5::File::open(dir.path().join("out.h5")).expect("open output");
    assert_eq!(string_attr(&f, "shpb_version"), env!("CARGO_PKG_VERSION"));
    assert_eq!(string_attr(&f, "scene"), scene_text);
    assert!(f.group("summary").is_ok(), "no /summary group");

    let force = f.dataset("contact/force").expect("/contact/force");
    assert_eq!(string_attr(&force, "units"), "N");
    let n = force.size();
    assert!(n >= 2, "/contact/force has {n} samples");
    let values: Vec<f64> = force.read_raw().unwrap();
    assert!(values.iter().all(|v| v.is_finite()), "non-finite force");
    for (name, units) in present {
        let ds = f
            .dataset(&format!("contact/{name}"))
            .unwrap_or_else(|e| panic!("/contact/{name}: {e}"));
        assert_eq!(string_attr(&ds, "units"), *units, "/contact/{name} units");
        assert_eq!(ds.size(), n, "/contact/{name} length");
    }
    let contact = f.group("contact").unwrap();
    for name in absent {
        assert!(
            !contact.link_exists(name),
            "/contact/{name} written for a scene that does not produce it"
        );
    }
    n
}

#[test]
fn run_quasistatic_writes_hdf5() {
    let n = run_and_check_hdf5(
        QUASISTATIC,
        &[("displacement", "m")],
        &["time", "yield_stress", "strain_rate"],
    );
    assert_eq!(n, 51);
}

#[test]
fn run_constant_rate_writes_hdf5() {
    let n = run_and_check_hdf5(
        CONSTANT_RATE,
        &[
            ("time", "s"),
            ("displacement", "m"),
            ("yield_stress", "Pa"),
            ("strain_rate", "1/s"),
        ],
        &[],
    );
    assert_eq!(n, 51);
}

#[test]
fn run_collision_writes_hdf5() {
    run_and_check_hdf5(
        COLLISION,
        &[
            ("time", "s"),
            ("displacement", "m"),
            ("yield_stress", "Pa"),
            ("strain_rate", "1/s"),
        ],
        &[],
    );
}

#[test]
fn run_force_driven_writes_hdf5() {
    run_and_check_hdf5(
        &force_driven(&measured_force_csv()),
        &[
            ("time", "s"),
            ("displacement", "m"),
            ("yield_stress", "Pa"),
            ("strain_rate", "1/s"),
        ],
        &[],
    );
}

#[test]
fn csv_output_has_a_header_line() {
    let dir = TempDir::new().unwrap();
    for (name, scene_text, header, rows) in [
        (
            "quasistatic",
            QUASISTATIC,
            "displacement_m,force_N",
            Some(51),
        ),
        (
            "collision",
            COLLISION,
            "time_s,displacement_m,force_N,yield_stress_Pa,strain_rate_per_s",
            None,
        ),
    ] {
        let scene = write(dir.path(), &format!("{name}.toml"), scene_text);
        let csv = format!("{name}.csv");
        let out = shpb(dir.path(), &["run", scene.to_str().unwrap(), "--csv", &csv]);
        assert!(out.status.success(), "stderr:\n{}", text(&out.stderr));
        let body = std::fs::read_to_string(dir.path().join(&csv)).unwrap();
        let mut lines = body.lines();
        assert_eq!(lines.next(), Some(header), "{name}: header");
        let data: Vec<&str> = lines.collect();
        if let Some(r) = rows {
            assert_eq!(data.len(), r, "{name}: rows");
        }
        let columns = header.split(',').count();
        for row in &data {
            let cells: Vec<&str> = row.split(',').collect();
            assert_eq!(cells.len(), columns, "{name}: row `{row}`");
            for c in cells {
                c.parse::<f64>()
                    .unwrap_or_else(|_| panic!("{name}: `{c}` is not a number"));
            }
        }
    }
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());
}

#[test]
fn help_mentions_all_scene_kinds() {
    let dir = TempDir::new().unwrap();
    for args in [&["--help"][..], &["run", "--help"][..]] {
        let out = shpb(dir.path(), args);
        assert!(out.status.success(), "shpb {args:?} failed");
        let help = text(&out.stdout);
        for kind in ["quasistatic", "constant-rate", "collision", "force-driven"] {
            assert!(
                help.contains(kind),
                "`shpb {args:?}` lacks `{kind}`:\n{help}"
            );
        }
        // …and every kind the scene parser knows.
        for (kind, _) in shpb::kinds::SCENE_KINDS {
            assert!(
                help.contains(kind),
                "`shpb {args:?}` lacks `{kind}`:\n{help}"
            );
        }
    }
}

#[test]
fn curve_prints_header_and_101_rows() {
    let dir = TempDir::new().unwrap();
    let out = shpb(
        dir.path(),
        &[
            "curve",
            "--specimen",
            "ss440c",
            "--rate",
            "1000",
            "--to",
            "250e-6",
        ],
    );
    assert!(out.status.success(), "stderr:\n{}", text(&out.stderr));
    let body = text(&out.stdout);
    let mut lines = body.lines();
    assert_eq!(lines.next(), Some("displacement_m,force_N"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let (d, f) = l.split_once(',').unwrap_or_else(|| panic!("row `{l}`"));
            (d.parse().unwrap(), f.parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), 101);
    assert_eq!(rows[0], (0.0, 0.0));
    assert!(
        (rows[100].0 - 250e-6).abs() < 1e-15,
        "last δ {}",
        rows[100].0
    );
    assert!(
        rows.windows(2).all(|w| w[1].0 > w[0].0 && w[1].1 >= w[0].1),
        "the loading curve is not increasing"
    );
    assert!(rows[100].1 > 0.0);
}

/// Every dataset under `group`, recursively, as (path, dataset).
/// Every numeric dataset under `group` (`/provenance` holds the input texts, not data).
fn datasets(group: &hdf5::Group, prefix: &str, out: &mut Vec<(String, hdf5::Dataset)>) {
    for name in group.member_names().unwrap() {
        let path = format!("{prefix}/{name}");
        if path == "/provenance" {
            continue;
        }
        if let Ok(ds) = group.dataset(&name) {
            out.push((path, ds));
        } else if let Ok(g) = group.group(&name) {
            datasets(&g, &path, out);
        }
    }
}

/// The full SS440c test writes the documented HDF5 layout (README, "HDF5 layout"): every
/// dataset with a `units` attribute, the reduction of the simulated records beside the true
/// contact (round trip through bridge, amplifier, noise and digitiser within 2 %), the energy
/// ledger and the x–t snapshots; `/summary` carries `warnings`.
#[test]
fn full_test_writes_the_documented_hdf5_layout() {
    let dir = TempDir::new().unwrap();
    let scene = format!("{}/scenes/shpb-ss440c-10psi.toml", repo());
    let out = shpb(
        dir.path(),
        &["run", &scene, "-o", "out.h5", "--plot", "out.png"],
    );
    assert!(out.status.success(), "stderr:\n{}", text(&out.stderr));
    assert!(dir.path().join("out.png").is_file());
    let f = hdf5::File::open(dir.path().join("out.h5")).expect("open output");
    assert_eq!(string_attr(&f, "shpb_version"), env!("CARGO_PKG_VERSION"));
    assert_eq!(
        string_attr(&f, "scene"),
        std::fs::read_to_string(&scene).unwrap()
    );
    let mut all = Vec::new();
    datasets(&f.group("/").unwrap(), "", &mut all);
    let names: Vec<&str> = all.iter().map(|(p, _)| p.as_str()).collect();
    for required in [
        "/time",
        "/gauges/incident/strain",
        "/gauges/incident/voltage",
        "/gauges/transmission/strain",
        "/gauges/transmission/voltage",
        "/contact/time",
        "/contact/displacement",
        "/contact/force",
        "/reduction/time",
        "/reduction/displacement",
        "/reduction/force_front",
        "/reduction/force_back",
        "/reduction/strain_rate",
        "/energy/striker",
        "/energy/bars",
        "/energy/shaper",
        "/energy/contact",
        "/energy/total",
        "/bars/incident/snapshots",
        "/bars/transmission/snapshots",
    ] {
        assert!(
            names.contains(&required),
            "{required} missing from {names:?}"
        );
    }
    for (path, ds) in &all {
        let units = string_attr(ds, "units");
        assert!(!units.is_empty(), "{path} has empty units");
        let v: Vec<f64> = ds.read_raw().unwrap();
        assert!(!v.is_empty() && v.iter().all(|x| x.is_finite()), "{path}");
    }
    let n_time = f.dataset("time").unwrap().size();
    for g in ["incident", "transmission"] {
        assert_eq!(
            f.dataset(&format!("gauges/{g}/voltage")).unwrap().size(),
            n_time
        );
    }
    let snap = f.dataset("bars/incident/snapshots").unwrap();
    assert_eq!(snap.ndim(), 2, "snapshots are a time × x field");
    let summary = f.group("summary").unwrap();
    let _ = string_attr(&summary, "warnings");
    let attr = |k: &str| -> f64 { summary.attr(k).unwrap().read_scalar().unwrap() };
    let (f_true, d_true) = (
        attr("peak_contact_force"),
        attr("displacement_at_peak_contact_force"),
    );
    let (f_red, d_red) = (
        attr("reduced_peak_back_force"),
        attr("reduced_displacement_at_peak_force"),
    );
    assert!((f_red / f_true - 1.0).abs() < 0.02, "{f_red} vs {f_true}");
    assert!((d_red / d_true - 1.0).abs() < 0.02, "{d_red} vs {d_true}");
}

#[test]
fn incident_tells_which_striker_a_record_was_shot_with() {
    // The Fig. 4 SS440c 10 psi record carries more energy, for its impulse, than the 10 cm striker
    // at the calibrated gun's 10 psi velocity can give (momentum and energy conservation), and
    // fits the 20 cm striker of bars/authors-20cm-striker.toml (validation/fig4-virtual-shpb).
    let tmp = TempDir::new().unwrap();
    let root = repo();
    let record = measured_force_csv();
    let run = |bars: &str| {
        let out = shpb(
            tmp.path(),
            &[
                "incident",
                &record,
                "--bars",
                &format!("{root}/bars/{bars}"),
                "--pressure",
                "10psi",
            ],
        );
        assert!(out.status.success(), "{}", text(&out.stderr));
        text(&out.stdout)
    };
    let short = run("authors.toml");
    assert!(short.contains("NOT possible"), "{short}");
    // The width of the flat pulse is 2 L / c0 of a 20 cm striker, within 2 %.
    let line = short
        .lines()
        .find(|l| l.starts_with("unshaped striker"))
        .unwrap();
    let length: f64 = line.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!((length / 0.20 - 1.0).abs() < 0.02, "{line}");
    let long = run("authors-20cm-striker.toml");
    assert!(long.contains(": possible"), "{long}");
    // Energy conservation: a simulated shaped test's own pulse is always possible for its striker.
    let out = shpb(
        tmp.path(),
        &[
            "run",
            &format!("{root}/scenes/shpb-ss440c-10psi.toml"),
            "-o",
            "sim.h5",
            "--csv",
            "sim.csv",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let sim = tmp.path().join("sim.csv");
    let out = shpb(
        tmp.path(),
        &[
            "incident",
            sim.to_str().unwrap(),
            "--bars",
            &format!("{root}/bars/authors.toml"),
            "--pressure",
            "10psi",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains(": possible"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn incident_refuses_bad_input_naming_file_and_key() {
    let tmp = TempDir::new().unwrap();
    let bars = format!("{}/bars/authors.toml", repo());
    let csv = write(tmp.path(), "f.csv", "time_s,force_N\n0,1\n1e-6,2\n");
    let run = |args: &[&str]| {
        let mut all = vec!["incident"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--bars", &bars]);
        shpb(tmp.path(), &all)
    };
    let out = run(&[csv.to_str().unwrap()]);
    assert_refused(
        tmp.path(),
        &out,
        Some(BAD_INPUT),
        &["f.csv", "displacement_m"],
    );
    let record = measured_force_csv();
    let out = run(&[&record, "--smoothing-us", "-1"]);
    assert_refused(
        tmp.path(),
        &out,
        Some(BAD_INPUT),
        &["--smoothing-us", "allowed"],
    );
    let out = run(&[&record, "--pressure", "90psi"]);
    assert_refused(
        tmp.path(),
        &out,
        Some(BAD_INPUT),
        &["--pressure", "allowed"],
    );
    assert!(
        out.stdout.is_empty(),
        "printed before refusing: {}",
        text(&out.stdout)
    );
    let out = shpb(tmp.path(), &["incident", &record, "--bars", "nothere.toml"]);
    assert_refused(
        tmp.path(),
        &out,
        Some(BAD_INPUT),
        &["--bars", "nothere.toml"],
    );
}

/// Runs `shpb ARGS` in `dir` and asserts it succeeds; returns stdout.
fn succeeds(dir: &Path, args: &[&str]) -> String {
    let out = shpb(dir, args);
    assert!(
        out.status.success(),
        "`shpb {}` failed ({:?}):\n{}",
        args.join(" "),
        out.status.code(),
        text(&out.stderr)
    );
    text(&out.stdout)
}

#[test]
fn gun_runs_outside_the_repository_with_the_built_in_setup() {
    let tmp = TempDir::new().unwrap();
    let out = succeeds(tmp.path(), &["gun", "--pressure", "10psi"]);
    assert!(out.contains("striker velocity"), "{out}");
    // The built-in set-up by name gives the same as the default.
    let named = succeeds(
        tmp.path(),
        &["gun", "--pressure", "10psi", "--bars", "authors"],
    );
    assert_eq!(named, out);
    // …and the same as the repository's file.
    let file = format!("{}/bars/authors.toml", repo());
    let from_file = succeeds(tmp.path(), &["gun", "--pressure", "10psi", "--bars", &file]);
    assert_eq!(from_file, out);
}

#[test]
fn list_names_every_builtin_material_setup_and_kind() {
    let tmp = TempDir::new().unwrap();
    let out = succeeds(tmp.path(), &["list"]);
    for (name, _) in shpb_input::material::BUILTIN_MATERIALS {
        assert!(out.contains(name), "material `{name}` missing:\n{out}");
    }
    for (name, _, description) in shpb_input::builtin::SETUPS {
        assert!(out.contains(name), "set-up `{name}` missing:\n{out}");
        assert!(
            out.contains(description),
            "set-up `{name}` undescribed:\n{out}"
        );
    }
    for (name, help) in shpb_input::kinds::names_and_help() {
        assert!(out.contains(name), "kind `{name}` missing:\n{out}");
        assert!(out.contains(help), "kind `{name}` undescribed:\n{out}");
    }
}

#[test]
fn validate_runs_outside_the_repository_on_the_embedded_data() {
    let tmp = TempDir::new().unwrap();
    let case = "hertz-analytic";
    assert!(shpb::validate::CASES.iter().any(|(n, _)| *n == case));
    let out = succeeds(tmp.path(), &["validate", case]);
    assert!(out.contains(case) && out.contains("checks pass"), "{out}");
    // Nothing is left in the working directory…
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
    // …and the same case on the repository's data gives the same table.
    let repo = repo();
    let with_data = succeeds(tmp.path(), &["validate", case, "--data", &repo]);
    assert_eq!(with_data, out);
    // --data without the reference data is refused, naming the option.
    let out = shpb(tmp.path(), &["validate", case, "--data", "."]);
    assert_refused(tmp.path(), &out, Some(BAD_INPUT), &["--data", "validation"]);
}

#[test]
fn run_a_scene_naming_the_built_in_setup_outside_the_repository() {
    let tmp = TempDir::new().unwrap();
    let original =
        std::fs::read_to_string(format!("{}/scenes/shpb-ss440c-10psi.toml", repo())).unwrap();
    assert!(original.lines().any(|l| l.starts_with("bars =")));
    let scene: String = original
        .lines()
        .map(|l| {
            if l.starts_with("bars =") {
                "bars = \"authors\"".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    write(tmp.path(), "scene.toml", &scene);
    let out = succeeds(
        tmp.path(),
        &["run", "scene.toml", "--fidelity", "fast", "-o", "out.h5"],
    );
    assert!(out.contains("kind shpb"), "{out}");
    assert!(tmp.path().join("out.h5").is_file());
}

#[test]
fn reduce_a_record_with_the_built_in_setup_outside_the_repository() {
    let tmp = TempDir::new().unwrap();
    std::fs::copy(
        format!(
            "{}/validation/gauge-records/data/2013-05-22_sample1_ss440c.csv",
            repo()
        ),
        tmp.path().join("record.csv"),
    )
    .unwrap();
    let out = succeeds(
        tmp.path(),
        &[
            "reduce",
            "record.csv",
            "--bars",
            "authors",
            "--csv",
            "out.csv",
        ],
    );
    assert!(out.contains("peak back force"), "{out}");
    assert!(tmp.path().join("out.csv").is_file());
    // The default set-up is the built-in one.
    let default = succeeds(tmp.path(), &["reduce", "record.csv"]);
    assert_eq!(default, out);
}

#[test]
fn unknown_bars_is_refused_naming_the_option_and_the_builtin_setups() {
    let tmp = TempDir::new().unwrap();
    let record = measured_force_csv();
    let raw = format!(
        "{}/validation/gauge-records/data/2013-05-22_sample1_ss440c.csv",
        repo()
    );
    let runs: [&[&str]; 4] = [
        &["gun", "--pressure", "10psi"],
        &["incident", &record],
        &["reduce", &raw],
        &["strain", &raw],
    ];
    for args in runs {
        let mut all = args.to_vec();
        all.extend_from_slice(&["--bars", "nonexistent"]);
        let out = shpb(tmp.path(), &all);
        let err = assert_refused(
            tmp.path(),
            &out,
            Some(BAD_INPUT),
            &["--bars", "nonexistent"],
        );
        for (name, _, _) in shpb_input::builtin::SETUPS {
            assert!(err.contains(name), "`{name}` not offered:\n{err}");
        }
    }
}

#[test]
fn reduce_names_the_dispersion_correction_it_used() {
    let tmp = TempDir::new().unwrap();
    let raw = format!(
        "{}/validation/gauge-records/data/2013-05-22_sample1_ss440c.csv",
        repo()
    );
    let json = |args: &[&str]| -> serde_json::Value {
        let mut all = vec!["--json", "reduce", raw.as_str()];
        all.extend_from_slice(args);
        serde_json::from_str(&succeeds(tmp.path(), &all)).unwrap()
    };
    let default = json(&[]);
    assert_eq!(default["dispersion"], "bancroft");
    assert_eq!(default["tyas_pope"], false);
    let exact = json(&["--dispersion", "pochhammer-chree", "--tyas-pope"]);
    assert_eq!(exact["dispersion"], "pochhammer-chree");
    assert_eq!(exact["tyas_pope"], true);
    assert_eq!(exact["dispersion_corrected"], true);
    // The deprecated flag is `--dispersion none`.
    let off = json(&["--no-dispersion"]);
    assert_eq!(off["dispersion"], "none");
    assert_eq!(off, json(&["--dispersion", "none"]));
    let summary = succeeds(
        tmp.path(),
        &["reduce", &raw, "--dispersion", "pochhammer-chree"],
    );
    assert!(
        summary.contains("dispersion correction pochhammer-chree"),
        "{summary}"
    );
    // The two spellings conflict; an unknown name lists the allowed ones; the amplitude factors
    // need a phase correction.
    let out = shpb(
        tmp.path(),
        &[
            "reduce",
            &raw,
            "--no-dispersion",
            "--dispersion",
            "bancroft",
        ],
    );
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("--no-dispersion"),
        "{}",
        text(&out.stderr)
    );
    let out = shpb(tmp.path(), &["reduce", &raw, "--dispersion", "love"]);
    let err = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("none") && err.contains("bancroft") && err.contains("pochhammer-chree"),
        "{err}"
    );
    let out = shpb(
        tmp.path(),
        &["reduce", &raw, "--dispersion", "none", "--tyas-pope"],
    );
    assert_eq!(out.status.code(), Some(BAD_INPUT), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("tyas_pope"),
        "{}",
        text(&out.stderr)
    );
}
