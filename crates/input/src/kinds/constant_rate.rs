//! `kind = "constant-rate"`: the spheres pressed together at a constant approach speed, with rate
//! hardening (paper Fig. 3).

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
    name: "constant-rate",
    help: "spheres pressed at constant approach speed with rate hardening (paper Fig. 3)",
    keys: &[
        SPECIMEN,
        LAW,
        REGION2,
        Key {
            key: "strain_rate_per_s",
            unit: "1/s",
            default: "required",
            meaning: "global strain rate of paper Eq. 3 (approach speed = rate × (r1 + r2)): greater than 0, at most 1e9",
        },
        Key {
            key: "max_displacement_m",
            unit: "m",
            default: "required",
            meaning: "largest approach δ: greater than 0, at most half the smaller sphere radius",
        },
        Key {
            key: "points",
            unit: "",
            default: "1001",
            meaning: "number of samples, 2 to 10000000",
        },
    ],
    example: "kind = \"constant-rate\"\nstrain_rate_per_s = 1e4\nmax_displacement_m = 250e-6\nspecimen = { pair = \"ss440c\" }\n",
    example_dir: None,
    parse,
};

super::sphere_scene_file! {
    struct ConstantRateFile {
        strain_rate_per_s: f64,
        max_displacement_m: f64,
        #[serde(default = "default_points")]
        points: usize,
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
    let f: ConstantRateFile = parse_as(text, file)?;
    let pair = f.specimen.build(base_dir, &sv)?;
    let p = SceneParams::ConstantRate {
        strain_rate_per_s: v.positive("strain_rate_per_s", f.strain_rate_per_s, 1e9, "1/s")?,
        max_displacement_m: check_max_displacement(v, f.max_displacement_m, &pair)?,
        points: check_points(v, f.points)?,
    };
    Ok((super::pair_specimen(&pair, f.law_spec()), p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registry_entry() {
        // A loading scene never unloads: `unloading` is accepted (common to sphere scenes) but unused.
        super::super::check_kind(&KIND, &["unloading"]);
        assert_eq!(KIND.keys[5].default, default_points().to_string());
    }

    #[test]
    fn example_values() {
        let (_, p) = super::super::parse_example(&KIND, Fidelity::Fast);
        assert_eq!(
            p,
            SceneParams::ConstantRate {
                strain_rate_per_s: 1e4,
                max_displacement_m: 250e-6,
                points: 1001,
            }
        );
    }

    #[test]
    fn errors_name_the_key() {
        let v = Validator::new("c.toml");
        let text = KIND.example.replace("1e4", "0");
        let e = parse(&text, "c.toml", Path::new("."), Fidelity::Standard, &v).unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.toml: `strain_rate_per_s`: 0 1/s is out of range; allowed: greater than 0 and at most 1e9 1/s"
        );
    }
}
