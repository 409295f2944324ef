//! `kind = "quasistatic"`: the loading curve F(δ) of the contact law on a grid (paper Fig. 2).

use super::{
    Key, LAW, Parsed, REGION2, SPECIMEN, SceneKind, check_max_displacement, check_points,
    default_points,
};
use crate::error::{Result, Validator};
use crate::toml_file::parse_as;
use shpb_core::fidelity::Fidelity;
use shpb_core::scene::SceneParams;
use std::path::Path;

/// The registry entry.
pub(super) const KIND: SceneKind = SceneKind {
    name: "quasistatic",
    help: "F(δ) of the loading law up to max_displacement_m (paper Fig. 2)",
    keys: &[
        SPECIMEN,
        LAW,
        REGION2,
        Key {
            key: "max_displacement_m",
            unit: "m",
            default: "required",
            meaning: "largest approach δ of the curve: greater than 0, at most half the smaller sphere radius",
        },
        Key {
            key: "points",
            unit: "",
            default: "1001",
            meaning: "number of points of the curve, 2 to 10000000",
        },
        Key {
            key: "strain_rate_per_s",
            unit: "1/s",
            default: "0",
            meaning: "global strain rate the curve is evaluated at (0: static), 0 to 1e9",
        },
    ],
    example: "kind = \"quasistatic\"\nmax_displacement_m = 250e-6\nspecimen = { pair = \"ss440c\" }\n",
    example_dir: None,
    parse,
};

super::sphere_scene_file! {
    struct QuasistaticFile {
        max_displacement_m: f64,
        #[serde(default = "default_points")]
        points: usize,
        #[serde(default)]
        strain_rate_per_s: f64,
    }
}

fn parse(
    text: &str,
    file: &str,
    base_dir: &Path,
    _fidelity: Fidelity,
    v: &Validator,
) -> Result<Parsed> {
    let sv = v.table("specimen");
    let f: QuasistaticFile = parse_as(text, file)?;
    let pair = f.specimen.build(base_dir, &sv)?;
    let p = SceneParams::Quasistatic {
        max_displacement_m: check_max_displacement(v, f.max_displacement_m, &pair)?,
        points: check_points(v, f.points)?,
        strain_rate_per_s: v.in_range("strain_rate_per_s", f.strain_rate_per_s, 0.0, 1e9, "1/s")?,
    };
    Ok((super::pair_specimen(&pair, f.law_spec()), p))
}

#[cfg(test)]
mod tests {
    use super::*;
    use shpb_core::contact::{LawKind, Region2Form};

    #[test]
    fn registry_entry() {
        // A loading scene never unloads: `unloading` is accepted (common to sphere scenes) but unused.
        super::super::check_kind(&KIND, &["unloading"]);
        assert_eq!(KIND.keys[4].default, default_points().to_string());
    }

    #[test]
    fn example_values() {
        let (specimen, p) = super::super::parse_example(&KIND, Fidelity::Fast);
        let spheres = specimen.unwrap().spheres().unwrap().clone();
        assert_eq!(spheres.first_pair().sphere1.radius_m, 3.175e-3);
        assert_eq!(
            (spheres.law.kind, spheres.law.region2),
            (LawKind::default(), Region2Form::default())
        );
        assert_eq!(
            p,
            SceneParams::Quasistatic {
                max_displacement_m: 250e-6,
                points: 1001,
                strain_rate_per_s: 0.0,
            }
        );
    }

    #[test]
    fn errors_name_the_key() {
        let v = Validator::new("q.toml");
        let text = format!("points = 1\n{}", KIND.example);
        let e = parse(&text, "q.toml", Path::new("."), Fidelity::Standard, &v).unwrap_err();
        assert_eq!(
            e.to_string(),
            "q.toml: `points`: 1 is out of range; allowed: 2 to 10000000"
        );
    }
}
