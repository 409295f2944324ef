//! `kind = "force-driven"`: the paper's Fig. 4 DEM, a measured force history (CSV) drives sphere 1
//! and sphere 2 rests on a medium of impedance Z.

use super::{
    Key, LAW, OUTPUT_EVERY, Parsed, REGION2, SPECIMEN, SceneKind, UNLOADING, check_every, one,
};
use crate::csv::{CsvTable, SignConvention};
use crate::error::{Error, Result, Validator};
use crate::toml_file::parse_as;
use shpb_core::error::format_si;
use shpb_core::fidelity::Fidelity;
use shpb_core::scene::{AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S, SceneParams};
use shpb_core::solver::{self, ForceDrivenSetup, ForceHistory};
use std::path::Path;

/// The registry entry.
pub(super) const KIND: SceneKind = SceneKind {
    name: "force-driven",
    help: "paper Fig. 4 DEM: a CSV force history drives sphere 1, sphere 2 rests on a medium of impedance Z",
    keys: &[
        SPECIMEN,
        LAW,
        REGION2,
        UNLOADING,
        Key {
            key: "force_csv",
            unit: "",
            default: "required",
            meaning: "CSV of the drive (time and force columns, optional displacement_m: the measured approach the model is compared with), relative to the scene file",
        },
        Key {
            key: "time_column",
            unit: "",
            default: "time_s",
            meaning: "name of the CSV's time column (s)",
        },
        Key {
            key: "force_column",
            unit: "",
            default: "force_N",
            meaning: "name of the CSV's force column (N)",
        },
        Key {
            key: "force_sign",
            unit: "",
            default: "compression-positive",
            meaning: "sign convention of the CSV's force and displacement_m columns: compression-positive (the project's) or tension-positive (both are negated on reading); a file whose largest force is negative under it is refused",
        },
        Key {
            key: "medium_impedance_kg_s",
            unit: "kg/s",
            default: "1.12e4 (the authors' transmission bar)",
            meaning: "impedance Z = ρc0A of the medium sphere 2 rests on, 0 to 1e9",
        },
        Key {
            key: "time_step_s",
            unit: "s",
            default: "from steps_per_period",
            meaning: "time step; at most the stability limit 1/ω of the contact at the peak drive force",
        },
        Key {
            key: "steps_per_period",
            unit: "",
            default: "fidelity: 200, 2000, 20000",
            meaning: "time steps per contact period, 10 to 1e8",
        },
        Key {
            key: "end_time_s",
            unit: "s",
            default: "the CSV's last time",
            meaning: "end of the run: greater than 0, at most 1 s and 5e8 time steps",
        },
        OUTPUT_EVERY,
    ],
    example: "kind = \"force-driven\"\nforce_csv = \"validation/fig4-force-driven/data/ss440c_10psi_force10.csv\"\nspecimen = { pair = \"ss440c\" }\n",
    example_dir: Some("."),
    parse,
};

super::sphere_scene_file! {
    struct ForceDrivenFile {
        force_csv: String,
        #[serde(default = "default_time_column")]
        time_column: String,
        #[serde(default = "default_force_column")]
        force_column: String,
        force_sign: Option<String>,
        #[serde(default = "default_impedance")]
        medium_impedance_kg_s: f64,
        time_step_s: Option<f64>,
        steps_per_period: Option<f64>,
        end_time_s: Option<f64>,
        #[serde(default = "one")]
        output_every: usize,
    }
}

fn default_time_column() -> String {
    "time_s".into()
}

/// The fewest time steps a force-driven run may take.
pub const MIN_RUN_STEPS: f64 = 16.0;

fn default_force_column() -> String {
    "force_N".into()
}

fn default_impedance() -> f64 {
    AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S
}

fn parse(
    text: &str,
    file: &str,
    base_dir: &Path,
    fidelity: Fidelity,
    v: &Validator,
) -> Result<Parsed> {
    let sv = v.table("specimen");
    let f: ForceDrivenFile = parse_as(text, file)?;
    let pair = f.specimen.build(base_dir, &sv)?;
    let csv_path = base_dir.join(&f.force_csv);
    let table = CsvTable::read(&csv_path).map_err(|e| match e {
        Error::Io { source, .. } => v.error(
            "force_csv",
            format!("cannot read {}: {source}", csv_path.display()),
            "a readable CSV file, absolute or relative to the scene file's directory",
        ),
        other => other,
    })?;
    let sign = match f.force_sign.as_deref() {
        None => SignConvention::CompressionPositive,
        Some(name) => SignConvention::parse(name).ok_or_else(|| {
            v.error(
                "force_sign",
                format!("unknown sign convention `{name}`"),
                "compression-positive, tension-positive",
            )
        })?,
    };
    let remedy = match sign {
        SignConvention::CompressionPositive => format!(
            "if the file's compression is negative, set force_sign = \"tension-positive\" in {file}"
        ),
        SignConvention::TensionPositive => format!(
            "remove force_sign = \"tension-positive\" from {file} if compression is positive in the file"
        ),
    };
    let t = table.time_column(&f.time_column)?.to_vec();
    let force = table.compression_column(&f.force_column, sign, &remedy)?;
    let measured_displacement_m = match table.optional_column("displacement_m") {
        Some(_) => Some(table.compression_column("displacement_m", sign, &remedy)?),
        None => None,
    };
    // Issue 42: the drive starts at t = 0, so rows before it were dropped without a word, and
    // a force that is zero throughout ran to an all-zero summary.
    // (A record that ends at or before 0 is refused below, naming its end.)
    if let Some(row) = t.iter().position(|&x| x < 0.0)
        && t.last().is_some_and(|&last| last > 0.0)
    {
        return Err(Error::Input {
            file: csv_path.display().to_string(),
            key: f.time_column.clone(),
            problem: format!(
                "{:e} s at data row {} is before the run's start t = 0: the drive would drop \
                 every row before it",
                t[row],
                row + 1
            ),
            allowed: "times from 0 s (shift the time column so that the loading starts at 0)"
                .into(),
        });
    }
    if force.iter().all(|&x| x == 0.0) {
        return Err(Error::Input {
            file: csv_path.display().to_string(),
            key: f.force_column.clone(),
            problem: "every force is 0 N: nothing drives the spheres".into(),
            allowed: "a force record with a non-zero loading, N".into(),
        });
    }
    let drive = ForceHistory {
        time_s: t,
        force_n: force,
    };
    let z = v.in_range(
        "medium_impedance_kg_s",
        f.medium_impedance_kg_s,
        0.0,
        1e9,
        "kg/s",
    )?;
    let n = v.in_range(
        "steps_per_period",
        f.steps_per_period.unwrap_or(fidelity.dem_steps()),
        10.0,
        1e8,
        "",
    )?;
    let peak = drive.peak_n().max(1e-3);
    let limit = solver::stability_limit(&pair, peak);
    let dt = match f.time_step_s {
        Some(dt) => v.positive("time_step_s", dt, limit, "s (the stability limit 1/ω of this contact at the peak drive force, solver::stability_limit)")?,
        None => solver::default_time_step(&pair, peak, z, n),
    };
    let last = *drive
        .time_s
        .last()
        .expect("time column has at least two samples");
    let end = match f.end_time_s {
        Some(e) => v.positive("end_time_s", e, 1.0, "s")?,
        // The drive starts at t = 0: a record that ends there has nothing to run.
        None if last <= 0.0 => {
            return Err(Error::Input {
                file: csv_path.display().to_string(),
                key: f.time_column.clone(),
                problem: format!("ends at {last:e} s, at or before the run's start t = 0"),
                allowed: format!(
                    "times reaching past 0 s (the drive starts at t = 0), or end_time_s in {file}"
                ),
            });
        }
        None => last,
    };
    // Times in µs under `time_s` are named as such, not as an end time the scene never gave.
    table.check_time_span(&f.time_column, &drive.time_s)?;
    // Issue 42: an end time shorter than a few steps ran to a summary of nothing.
    if end < MIN_RUN_STEPS * dt {
        return Err(v.error(
            "end_time_s",
            format!(
                "{end:e} s holds fewer than {MIN_RUN_STEPS} time steps of {dt:e} s, too few for \
                 any result"
            ),
            format!("at least {:e} s", MIN_RUN_STEPS * dt),
        ));
    }
    if end / dt > 5e8 {
        return Err(v.error(
            "end_time_s",
            format!(
                "{} needs {} steps of {}",
                format_si(end, "s"),
                format_si(end / dt, ""),
                format_si(dt, "s")
            ),
            "at most 5e8 steps",
        ));
    }
    let setup = ForceDrivenSetup {
        drive,
        medium_impedance_kg_s: z,
        dt_s: dt,
        end_time_s: end,
        output_every: check_every(v, f.output_every)?,
    };
    Ok((
        super::pair_specimen(&pair, f.law_spec()),
        SceneParams::ForceDriven {
            setup,
            measured_displacement_m,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn repo() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
    }

    #[test]
    fn registry_entry() {
        super::super::check_kind(&KIND, &[]);
        let steps = Fidelity::ALL.map(|f| f.dem_steps().to_string()).join(", ");
        assert_eq!(KIND.keys[10].default, format!("fidelity: {steps}"));
        assert!(
            KIND.keys[8]
                .default
                .starts_with(&format!("{:.2e} ", default_impedance()))
        );
        assert_eq!(KIND.keys[5].default, default_time_column());
        assert_eq!(KIND.keys[6].default, default_force_column());
        assert_eq!(KIND.keys[7].default, SignConvention::NAMES[0].0);
        for (name, _) in SignConvention::NAMES {
            assert!(KIND.keys[7].meaning.contains(name));
        }
    }

    /// Issue 15, item 8: a force CSV with compression negative ran (peak force 0, NaN error,
    /// 482 J of kinetic energy); it is refused, naming the file and column, unless the scene
    /// says the file is tension-positive, which negates the force and displacement columns.
    #[test]
    fn a_drive_with_compression_negative_is_refused_unless_declared() {
        let dir = std::env::temp_dir().join(format!("shpb-fd-sign-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let source = CsvTable::read(
            &repo().join("validation/fig4-force-driven/data/ss440c_10psi_force10.csv"),
        )
        .unwrap();
        let mut text = String::from("time_s,displacement_m,force_N\n");
        let col = |n: &str| source.column(n).unwrap();
        for i in 0..col("time_s").len() {
            text.push_str(&format!(
                "{:e},{:e},{:e}\n",
                col("time_s")[i],
                -col("displacement_m")[i],
                -col("force_N")[i]
            ));
        }
        std::fs::write(dir.join("negative.csv"), text).unwrap();
        let v = Validator::new("f.toml");
        let scene = "kind = \"force-driven\"\nforce_csv = \"negative.csv\"\nspecimen = { pair = \"ss440c\" }\n";
        let e = parse(scene, "f.toml", &dir, Fidelity::Fast, &v).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let msg = e.to_string();
        assert!(
            msg.starts_with(&format!(
                "{}: `force_N`: the value of largest magnitude, -12.3 kN (data row ",
                dir.join("negative.csv").display()
            )),
            "{msg}"
        );
        assert!(
            msg.ends_with("set force_sign = \"tension-positive\" in f.toml"),
            "{msg}"
        );
        // Declared: read as the original file.
        let declared = format!("{scene}force_sign = \"tension-positive\"\n");
        let (_, p) = parse(&declared, "f.toml", &dir, Fidelity::Fast, &v).unwrap();
        let SceneParams::ForceDriven {
            setup,
            measured_displacement_m,
        } = p
        else {
            panic!("not force-driven")
        };
        assert_eq!(setup.drive.force_n, col("force_N"));
        assert_eq!(
            measured_displacement_m.as_deref(),
            Some(col("displacement_m"))
        );
        // An unknown convention names the key.
        let bad = format!("{scene}force_sign = \"up\"\n");
        let e = parse(&bad, "f.toml", &dir, Fidelity::Fast, &v).unwrap_err();
        assert_eq!(
            e.to_string(),
            "f.toml: `force_sign`: unknown sign convention `up`; allowed: compression-positive, tension-positive"
        );
    }

    #[test]
    fn example_reads_the_whole_csv() {
        let v = Validator::new("example.toml");
        let (_, p) = parse(
            KIND.example,
            "example.toml",
            &repo(),
            Fidelity::Standard,
            &v,
        )
        .unwrap();
        let SceneParams::ForceDriven {
            setup,
            measured_displacement_m,
        } = p
        else {
            panic!("not force-driven: {p:?}")
        };
        let csv = CsvTable::read(
            &repo().join("validation/fig4-force-driven/data/ss440c_10psi_force10.csv"),
        )
        .unwrap();
        assert_eq!(setup.drive.time_s, csv.time_column("time_s").unwrap());
        assert_eq!(setup.drive.force_n, csv.column("force_N").unwrap());
        assert_eq!(
            measured_displacement_m.as_deref(),
            csv.optional_column("displacement_m")
        );
        assert_eq!(setup.end_time_s, *setup.drive.time_s.last().unwrap());
        assert_eq!(
            setup.medium_impedance_kg_s,
            AUTHORS_TRANSMISSION_BAR_IMPEDANCE_KG_S
        );
    }

    #[test]
    fn a_missing_csv_names_the_key() {
        let v = Validator::new("f.toml");
        let e = parse(
            KIND.example,
            "f.toml",
            Path::new("/nonexistent"),
            Fidelity::Fast,
            &v,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("f.toml: `force_csv`: cannot read /nonexistent/validation/"),
            "{e}"
        );
    }

    /// A record whose times end at or before t = 0 (the drive's start) is refused naming the CSV
    /// and its time column (found by `proptest_inputs::force_driven_csv_never_panics`: it gave a
    /// run of end time 0).
    #[test]
    fn a_record_ending_before_the_start_is_refused() {
        let dir = std::env::temp_dir().join(format!("shpb-force-end-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let csv = dir.join("f.csv");
        std::fs::write(&csv, "a,time_s,force_N\n0e0,-638.2,1.0\n1e-6,0e0,1.0\n").unwrap();
        let text = format!(
            "kind = \"force-driven\"\nforce_csv = \"{}\"\nspecimen = {{ pair = \"ss440c\" }}\n",
            csv.display()
        );
        let v = Validator::new("f.toml");
        let e = parse(&text, "f.toml", &dir, Fidelity::Fast, &v)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!("{}: `time_s`: ends at 0e0 s", csv.display())),
            "{e}"
        );
    }
}
