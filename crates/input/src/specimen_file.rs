//! `shpb reduce --specimen FILE.toml`: the specimen a record is reduced for, a `[specimen]` table
//! exactly as in a scene ([`SpecimenSpec`]: `pair`, `sphere1`/`sphere2`, `count` with `material`
//! and `diameter_m`, `[[specimen.sphere]]`, or `shape = "cylinder"` with `length_m`,
//! `diameter_m`, `material`), validated into the core's [`ReducedSpecimen`]
//! (docs/physics.md §7.3, §7.8).

use crate::error::{Error, Result, Validator};
use crate::specimen::SpecimenSpec;
use serde::Deserialize;
use shpb_core::contact::LawSpec;
use shpb_core::reduce::ReducedSpecimen;
use shpb_core::specimen::{Seating, Specimen, SphereSpecimen};
use std::path::Path;

/// What a specimen file may hold, for messages.
pub const SPECIMEN_FILE_FORM: &str = "a [specimen] table as in a scene: pair = \"ss440c\" (or a pair .toml), [specimen.sphere1] and [specimen.sphere2], count = N with material and diameter_m, [[specimen.sphere]] tables, or shape = \"cylinder\" with length_m, diameter_m and material";

/// The whole file: one `[specimen]` table and nothing else.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecimenFileSpec {
    specimen: Option<SpecimenSpec>,
}

/// A specimen file read and validated.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecimenFile {
    /// The file as named (for messages and the command line a reduction stores).
    pub source: String,
    /// The specimen: spheres (their radii, for δ̇/Σrᵢ) or a cylinder (its geometry).
    pub specimen: ReducedSpecimen,
}

impl SpecimenFile {
    /// Reads `path`: its `[specimen]` table validated as a scene's (paths inside it relative to
    /// the file's directory). Spheres give the radii of the strain rate δ̇/Σrᵢ (a pair: r1 + r2;
    /// a chain: every sphere's radius, as `SphereSpecimen::strain_rate_radii_m`); a cylinder its
    /// length and diameter. A seating (`gap_m`, `preload_n`) is accepted and does not change a
    /// reduction. Errors name the file and the key (exit code 2).
    pub fn read(path: &Path) -> Result<SpecimenFile> {
        let file = path.display().to_string();
        if !crate::files::is_file(path) {
            return Err(Error::Input {
                file: "command line".into(),
                key: "--specimen".into(),
                problem: format!("cannot read {file}: {}", crate::files::not_a_file(path)),
                allowed: format!("a specimen .toml file: {SPECIMEN_FILE_FORM}"),
            });
        }
        let text = crate::files::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let raw: SpecimenFileSpec = crate::toml_file::parse_as(&text, &file)?;
        let v = Validator::new(file.clone());
        let Some(spec) = raw.specimen else {
            return Err(v.error("specimen", "missing", SPECIMEN_FILE_FORM));
        };
        let base = path.parent().unwrap_or(Path::new("."));
        let v = v.table("specimen");
        let specimen = if spec.is_cylinder(&v)? {
            Specimen::Cylinder(crate::cylinder::build(&spec, base, &v)?)
        } else {
            Specimen::Spheres(SphereSpecimen {
                chain: spec.spheres_only().build_chain(base, &v)?,
                law: LawSpec::default(),
                seating: Seating::Touching,
            })
        };
        let specimen = ReducedSpecimen::of(&specimen);
        Ok(SpecimenFile {
            source: file,
            specimen,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shpb_core::reduce_cylinder::CylinderGeometry;

    fn read(text: &str) -> Result<SpecimenFile> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static N: AtomicUsize = AtomicUsize::new(0);
        let dir = std::env::temp_dir().join(format!(
            "shpb-specimen-file-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("spec.toml");
        std::fs::write(&path, text).unwrap();
        let r = SpecimenFile::read(&path);
        std::fs::remove_dir_all(&dir).ok();
        r
    }

    #[test]
    fn spheres_of_any_diameter_give_their_radii_and_a_cylinder_its_geometry() {
        let pair = read("[specimen]\npair = \"ss440c\"\n").unwrap();
        assert_eq!(
            pair.specimen,
            ReducedSpecimen::Spheres {
                radii_m: (3.175e-3, 3.175e-3)
            }
        );
        let big =
            read("[specimen]\ncount = 2\nmaterial = \"ss440c\"\ndiameter_m = 12.7e-3\n").unwrap();
        assert_eq!(
            big.specimen,
            ReducedSpecimen::Spheres {
                radii_m: (6.35e-3, 6.35e-3)
            }
        );
        let chain =
            read("[specimen]\ncount = 4\nmaterial = \"ss440c\"\ndiameter_m = 6.35e-3\n").unwrap();
        let (r1, rest) = chain.specimen.radii_m().unwrap();
        assert_eq!(r1, 3.175e-3);
        assert!((rest - 3.0 * 3.175e-3).abs() < 1e-18);
        let cyl = read(
            "[specimen]\nshape = \"cylinder\"\nlength_m = 6e-3\ndiameter_m = 12e-3\nmaterial = \"al2017\"\n",
        )
        .unwrap();
        assert_eq!(
            cyl.specimen,
            ReducedSpecimen::Cylinder(CylinderGeometry {
                length_m: 6e-3,
                diameter_m: 12e-3
            })
        );
    }

    #[test]
    fn errors_name_the_file_and_the_key() {
        let e =
            read("[specimen]\ncount = 2\nmaterial = \"ss440c\"\ndiameter_m = -1e-3\n").unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("spec.toml") && msg.contains("`specimen.diameter_m`"),
            "{msg}"
        );
        assert_eq!(e.exit_code(), 2);
        let e = read("[specimen]\nshape = \"cube\"\n").unwrap_err();
        assert!(e.to_string().contains("`specimen.shape`"), "{e}");
        let e = read("pair = \"ss440c\"\n").unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let e = read("[other]\n").unwrap_err();
        assert!(e.to_string().contains("spec.toml"), "{e}");
        let e = read("").unwrap_err();
        assert!(e.to_string().contains("`specimen`"), "{e}");
    }
}
