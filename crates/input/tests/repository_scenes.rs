//! Every scene shipped in the repository (`scenes/*.toml`, `validation/*/*.toml` with a `kind`
//! key) parses through the registry of scene kinds, with the values its file states; the README
//! example of each kind is the shipped scene it abbreviates.

use shpb_core::apparatus::IncidentEnd;
use shpb_core::scene::{Params, SceneParams};
use shpb_input::csv::CsvTable;
use shpb_input::kinds;
use shpb_input::prelude::*;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The scene files of `scenes/` and `validation/*/` (material files have no `kind` and are skipped).
fn scene_files() -> Vec<(PathBuf, toml::Table)> {
    let mut dirs = vec![repo().join("scenes")];
    for e in std::fs::read_dir(repo().join("validation")).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            dirs.push(p);
        }
    }
    let mut files = vec![];
    for d in dirs {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "toml") {
                let table: toml::Table = std::fs::read_to_string(&p).unwrap().parse().unwrap();
                if table.contains_key("kind") {
                    files.push((p, table));
                }
            }
        }
    }
    files.sort_by(|a, b| a.0.cmp(&b.0));
    files
}

fn float(t: &toml::Table, key: &str) -> Option<f64> {
    t.get(key).map(|v| match v {
        toml::Value::Float(f) => *f,
        toml::Value::Integer(i) => *i as f64,
        other => panic!("`{key}` = {other} is not a number"),
    })
}

fn string<'a>(t: &'a toml::Table, key: &str) -> Option<&'a str> {
    t.get(key).map(|v| v.as_str().expect("a string"))
}

#[test]
fn every_repository_scene_parses_with_the_values_of_its_file() {
    let files = scene_files();
    assert!(files.len() >= 40, "only {} scene files found", files.len());
    let mut seen = vec![];
    for (path, t) in &files {
        let p = Params::from_file(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let kind = string(t, "kind").unwrap();
        assert_eq!(p.kind, kind);
        assert!(
            kinds::find(kind).is_some(),
            "{}: unregistered kind",
            path.display()
        );
        seen.push(kind.to_string());
        assert_eq!(
            p.fidelity.name(),
            string(t, "fidelity").unwrap_or("standard"),
            "{}",
            path.display()
        );
        let dir = path.parent().unwrap();
        match &p.params {
            SceneParams::Quasistatic {
                max_displacement_m,
                points,
                strain_rate_per_s,
            } => {
                assert_eq!(Some(*max_displacement_m), float(t, "max_displacement_m"));
                assert_eq!(*points as f64, float(t, "points").unwrap_or(1001.0));
                assert_eq!(
                    *strain_rate_per_s,
                    float(t, "strain_rate_per_s").unwrap_or(0.0)
                );
            }
            SceneParams::ConstantRate {
                strain_rate_per_s,
                max_displacement_m,
                points,
            } => {
                assert_eq!(Some(*strain_rate_per_s), float(t, "strain_rate_per_s"));
                assert_eq!(Some(*max_displacement_m), float(t, "max_displacement_m"));
                assert_eq!(*points as f64, float(t, "points").unwrap_or(1001.0));
            }
            SceneParams::Collision(s) => {
                assert_eq!(Some(s.velocity1_m_s), float(t, "velocity1_m_s"));
                assert_eq!(s.velocity2_m_s, float(t, "velocity2_m_s").unwrap_or(0.0));
                if let Some(dt) = float(t, "time_step_s") {
                    assert_eq!(s.dt_s, dt);
                }
            }
            SceneParams::Chain(s) => {
                if let Some(v1) = float(t, "velocity1_m_s") {
                    assert_eq!(s.velocity1_m_s, v1);
                }
                if let Some(end) = float(t, "end_time_s") {
                    assert_eq!(s.end_time_s, end);
                }
                assert!(s.chain.len() >= 2);
            }
            SceneParams::ForceDriven {
                setup,
                measured_displacement_m,
            } => {
                let csv = CsvTable::read(&dir.join(string(t, "force_csv").unwrap())).unwrap();
                let time = string(t, "time_column").unwrap_or("time_s");
                let force = string(t, "force_column").unwrap_or("force_N");
                assert_eq!(setup.drive.time_s, csv.time_column(time).unwrap());
                assert_eq!(setup.drive.force_n, csv.column(force).unwrap());
                assert_eq!(
                    measured_displacement_m.as_deref(),
                    csv.optional_column("displacement_m")
                );
                assert_eq!(
                    setup.end_time_s,
                    float(t, "end_time_s").unwrap_or(*setup.drive.time_s.last().unwrap())
                );
                if let Some(z) = float(t, "medium_impedance_kg_s") {
                    assert_eq!(setup.medium_impedance_kg_s, z);
                }
            }
            SceneParams::Pulse {
                pressure_pa,
                options,
                ..
            } => {
                // The gun's pressure, or a recorded incident wave in its place.
                match string(t, "pressure") {
                    Some(pressure) => assert_eq!(
                        *pressure_pa,
                        shpb_input::units::parse_pressure(pressure).unwrap()
                    ),
                    None => {
                        assert!(t.contains_key("incident_record") && pressure_pa.is_nan());
                        assert!(options.incident_drive.is_some());
                    }
                }
                assert_eq!(p.specimen.is_some(), kind == "shpb");
                match kind {
                    "shpb" => assert_eq!(options.end, IncidentEnd::Specimen),
                    _ => assert_ne!(options.end, IncidentEnd::Specimen),
                }
                if let Some(cell) = float(t, "cell_size_m") {
                    assert_eq!(options.cell_size_m, cell);
                }
                assert_eq!(
                    options.loading.name(),
                    string(t, "loading").unwrap_or("compression"),
                    "{}",
                    path.display()
                );
            }
        }
    }
    // The repository has a scene of every registered kind.
    for name in kinds::names() {
        assert!(
            seen.iter().any(|k| k == name),
            "no repository scene of kind {name}"
        );
    }
}

/// Parses `text` as if it were a file in `dir` and drops what names the sources (the scene's
/// and its bar set-up's: a built-in one or a file).
fn parsed(text: &str, dir: &Path) -> Params {
    let mut p = Params::from_toml(text, "x.toml", dir).unwrap();
    p.source.clear();
    p.text.clear();
    if let SceneParams::Pulse { apparatus, .. } = &mut p.params {
        apparatus.source.clear();
    }
    p
}

#[test]
fn readme_examples_are_the_shipped_scenes_they_abbreviate() {
    // (kind, shipped scene, lines the example leaves at their defaults or does not set)
    let cases = [
        (
            "quasistatic",
            "scenes/quasistatic-fig2.toml",
            "points = 501\n",
        ),
        (
            "constant-rate",
            "scenes/constant-rate-ss440c-1e4.toml",
            "points = 501\n",
        ),
        ("collision", "scenes/collision-ss440c-5ms.toml", ""),
        ("force-driven", "scenes/force-driven-ss440c-10psi.toml", ""),
        ("pulse", "scenes/pulse-10psi.toml", ""),
        ("shpb", "scenes/shpb-ss440c-10psi.toml", ""),
        ("chain", "scenes/chain-ss440c-10.toml", ""),
    ];
    assert_eq!(cases.map(|c| c.0).to_vec(), kinds::names());
    for (name, scene, extra) in cases {
        let kind = kinds::find(name).unwrap();
        let dir = match kind.example_dir {
            Some(d) => repo().join(d),
            None => PathBuf::from("/nonexistent"),
        };
        let example = parsed(&format!("{}{extra}", kind.example), &dir);
        let path = repo().join(scene);
        let shipped = parsed(
            &std::fs::read_to_string(&path).unwrap(),
            path.parent().unwrap(),
        );
        assert_eq!(example, shipped, "{name}: example differs from {scene}");
    }
}
