//! The calibration shots of `shpb calibrate`: a small TOML manifest naming each shot's record and
//! what was known about it (gun pressure and/or measured striker velocity, optional layout).
//!
//! ```toml
//! fitted_on = "2013-05-22 incident records, samples 1-8"  # free text (default: the file names)
//! layout = "my-layout.toml"          # optional: how every record reads (`shpb reduce --layout`)
//! calibrate = ["gun", "shaper"]      # optional: only these calibrations (default: every one
//!                                    # whose data the shots carry)
//! [[shot]]
//! file = "shot1.csv"                 # relative to the manifest
//! pressure = "10psi"                 # optional: gauge pressure of the gun, with its unit
//! striker_velocity_m_s = 5.8         # optional: the striker's measured velocity
//! bars_together = false              # optional: no specimen, the bars pressed together
//! label = "sample 1"                 # optional: the shot's name in messages and tables
//! layout = "other.toml"              # optional: this shot's layout
//! scene = "shot1-test.toml"          # optional: the shot's virtual test (its specimen, its
//!                                    # pressure); when shots name one, `shpb calibrate` states
//!                                    # the shots' scatter about the calibrated model
//! ```

use crate::error::{Error, Result, Validator};
use crate::layout::RecordLayout;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// One calibration shot.
#[derive(Debug, Clone)]
pub struct Shot {
    /// The record (resolved relative to the manifest).
    pub file: PathBuf,
    /// The shot's name: `label`, else the record's file name.
    pub label: String,
    /// Gauge pressure of the gun, Pa.
    pub pressure_pa: Option<f64>,
    /// The striker's measured velocity, m/s.
    pub velocity_m_s: Option<f64>,
    /// The bars were pressed together without a specimen: the transmitted foot dates the
    /// transmission gauge (else it includes the specimen's transit).
    pub bars_together: bool,
    /// How the record reads when it is not the authors' CSV.
    pub layout: Option<RecordLayout>,
    /// The shot's virtual test (a scene file with bars, resolved relative to the manifest).
    pub scene: Option<PathBuf>,
}

/// A manifest of calibration shots.
#[derive(Debug, Clone)]
pub struct ShotManifest {
    /// The manifest file, as named.
    pub source: String,
    /// What the shots are (written as `[uncertainty] fitted_on`).
    pub fitted_on: String,
    /// The shots, in file order.
    pub shots: Vec<Shot>,
    /// The calibrations asked for (`calibrate`; None: every one whose data is given).
    pub only: Option<Vec<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawManifest {
    fitted_on: Option<String>,
    layout: Option<String>,
    calibrate: Option<Vec<String>>,
    #[serde(default)]
    shot: Vec<RawShot>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawShot {
    file: String,
    label: Option<String>,
    pressure: Option<String>,
    striker_velocity_m_s: Option<f64>,
    #[serde(default)]
    bars_together: bool,
    layout: Option<String>,
    scene: Option<String>,
}

/// Largest striker velocity a shot may state, m/s (a gas-gun SHPB stays far below).
const MAX_VELOCITY_M_S: f64 = 200.0;

impl ShotManifest {
    /// Reads and validates a manifest: every record must exist, pressures carry a unit,
    /// velocities are in (0, 200] m/s; relative paths are resolved against the manifest.
    pub fn from_file(path: &Path) -> Result<ShotManifest> {
        let text = crate::files::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        ShotManifest::from_toml(&text, &path.display().to_string(), dir)
    }

    /// Validates manifest TOML `text` named `file`, paths relative to `dir`.
    pub fn from_toml(text: &str, file: &str, dir: &Path) -> Result<ShotManifest> {
        let raw: RawManifest = crate::toml_file::parse_as(text, file)?;
        let v = Validator::new(file);
        let read_layout = |key: &str, name: &str| -> Result<RecordLayout> {
            let p = dir.join(name);
            if !crate::files::is_file(&p) {
                return Err(v.error(
                    key,
                    format!(
                        "cannot read {}: {}",
                        p.display(),
                        crate::files::not_a_file(&p)
                    ),
                    "a record layout .toml file (relative to the manifest)",
                ));
            }
            RecordLayout::from_file(&p)
        };
        let common_layout = match &raw.layout {
            Some(name) => Some(read_layout("layout", name)?),
            None => None,
        };
        if raw.shot.is_empty() {
            return Err(v.error(
                "shot",
                "no shots",
                "one [[shot]] table per shot, each with at least `file`",
            ));
        }
        let mut shots = Vec::with_capacity(raw.shot.len());
        for (i, s) in raw.shot.iter().enumerate() {
            let t = v.table(&format!("shot[{}]", i + 1));
            let file = dir.join(&s.file);
            if !crate::files::is_file(&file) {
                return Err(t.error(
                    "file",
                    format!(
                        "cannot read {}: {}",
                        file.display(),
                        crate::files::not_a_file(&file)
                    ),
                    "a gauge record (relative to the manifest)",
                ));
            }
            let pressure_pa = match &s.pressure {
                Some(p) => Some(crate::units::pressure_from_text(p, &t, "pressure")?)
                    .filter(|p| *p > 0.0)
                    .ok_or_else(|| {
                        t.error(
                            "pressure",
                            format!("{p} is not above zero"),
                            "a gauge pressure above zero",
                        )
                    })
                    .map(Some)?,
                None => None,
            };
            let velocity_m_s = match s.striker_velocity_m_s {
                Some(x) => Some(t.positive("striker_velocity_m_s", x, MAX_VELOCITY_M_S, "m/s")?),
                None => None,
            };
            let layout = match &s.layout {
                Some(name) => Some(read_layout(&t.key("layout"), name)?),
                None => common_layout.clone(),
            };
            let scene = match &s.scene {
                Some(name) => {
                    let p = dir.join(name);
                    if !crate::files::is_file(&p) {
                        return Err(t.error(
                            "scene",
                            format!("cannot read {}: no such file", p.display()),
                            "the shot's virtual test, a scene .toml with bars (relative to the \
                             manifest)",
                        ));
                    }
                    Some(p)
                }
                None => None,
            };
            let label = s.label.clone().unwrap_or_else(|| {
                Path::new(&s.file)
                    .file_name()
                    .map_or(s.file.clone(), |n| n.to_string_lossy().into_owned())
            });
            shots.push(Shot {
                file,
                label,
                pressure_pa,
                velocity_m_s,
                bars_together: s.bars_together,
                layout,
                scene,
            });
        }
        let fitted_on = raw.fitted_on.unwrap_or_else(|| {
            shots
                .iter()
                .map(|s| s.label.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        });
        Ok(ShotManifest {
            source: file.to_string(),
            fitted_on,
            shots,
            only: raw.calibrate,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir_with(files: &[&str]) -> tempfile::TempDir {
        let d = tempfile::tempdir().unwrap();
        for f in files {
            std::fs::write(d.path().join(f), "x").unwrap();
        }
        d
    }

    #[test]
    fn a_manifest_reads_pressures_velocities_and_labels() {
        let d = dir_with(&["a.csv", "b.csv"]);
        let m = ShotManifest::from_toml(
            "[[shot]]\nfile = \"a.csv\"\npressure = \"10psi\"\n\
             [[shot]]\nfile = \"b.csv\"\nstriker_velocity_m_s = 5.5\nlabel = \"B\"\nbars_together = true\n",
            "m.toml",
            d.path(),
        )
        .unwrap();
        assert_eq!(m.shots.len(), 2);
        assert!((m.shots[0].pressure_pa.unwrap() - 10.0 * crate::units::PSI_PA).abs() < 1e-9);
        assert_eq!(m.shots[1].velocity_m_s, Some(5.5));
        assert_eq!(m.shots[1].label, "B");
        assert!(m.shots[1].bars_together && !m.shots[0].bars_together);
        assert_eq!(m.fitted_on, "a.csv, B");
    }

    #[test]
    fn errors_name_the_file_and_the_shot_key() {
        let d = dir_with(&["a.csv"]);
        let err = |text: &str| {
            ShotManifest::from_toml(text, "m.toml", d.path())
                .unwrap_err()
                .to_string()
        };
        let e = err("[[shot]]\nfile = \"missing.csv\"\n");
        assert!(e.contains("m.toml") && e.contains("shot[1].file"), "{e}");
        let e = err("[[shot]]\nfile = \"a.csv\"\npressure = \"10\"\n");
        assert!(e.contains("shot[1].pressure") && e.contains("unit"), "{e}");
        let e = err("[[shot]]\nfile = \"a.csv\"\nstriker_velocity_m_s = -1.0\n");
        assert!(e.contains("shot[1].striker_velocity_m_s"), "{e}");
        let e = err("fitted_on = \"x\"\n");
        assert!(e.contains("`shot`"), "{e}");
        let e = err("[[shot]]\nfile = \"a.csv\"\nspeed = 3\n");
        assert!(e.contains("m.toml") && e.contains("speed"), "{e}");
    }
}
