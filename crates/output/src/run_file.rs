//! A run file as data: the numeric datasets `shpb run -o` ([`crate::io::write_hdf5`]) writes for
//! a run, computed from the run without a file ([`run_datasets`]), and every numeric dataset,
//! summary value and attribute of a run or reduction file read back ([`read_run_file`]). The
//! Python package serves `Run[path]` from these; a test checks that both list the same paths.

use crate::h5::h5err;
use hdf5::types::VarLenUnicode;
use shpb_core::reduce::Reduction;
use shpb_core::run::RunOutput;
use shpb_input::Result;
use std::borrow::Cow;
use std::path::Path;

/// One numeric dataset of a run file: its path (`contact/force`), shape (`[]` for a scalar,
/// rows first), data in row-major order and units.
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset<'a> {
    /// Path in the file, without the leading `/`.
    pub path: String,
    /// Shape (empty for a scalar).
    pub shape: Vec<usize>,
    /// The values, row-major.
    pub data: Cow<'a, [f64]>,
    /// The `units` attribute.
    pub units: Cow<'a, str>,
}

fn one_d<'a>(path: String, data: &'a [f64], units: &'a str) -> Dataset<'a> {
    Dataset {
        path,
        shape: vec![data.len()],
        data: Cow::Borrowed(data),
        units: Cow::Borrowed(units),
    }
}

/// The numeric datasets [`crate::io::write_hdf5`] writes for `out`, in the order written:
/// `contact/*`, `chain/*`, `drive/{time,force}`, `time`, `gauges/<name>/{strain,voltage}`,
/// `bars/<name>/{x,time,snapshots}`,
/// `reduction/*`, `energy/*`, `summary/<key>` (scalars; a chain's `final_velocity_<k>` are the
/// elements of `chain/final_velocity`), `summary/bands/<key>` ([low, high]).
pub fn run_datasets(out: &RunOutput) -> Vec<Dataset<'_>> {
    let mut v = Vec::new();
    if let Some(contact) = &out.contact {
        for (name, data, units) in crate::io::contact_columns(contact) {
            v.push(one_d(format!("contact/{name}"), data, units));
        }
    }
    if let Some(c) = &out.chain {
        for (name, values, units) in crate::io::chain_columns(c) {
            v.push(Dataset {
                path: format!("chain/{name}"),
                shape: values.shape(),
                data: match values {
                    crate::io::ChainValues::Series(d) => Cow::Borrowed(d),
                    rows => Cow::Owned(rows.flat()),
                },
                units: Cow::Borrowed(units),
            });
        }
    }
    if let Some(d) = &out.drive {
        for (name, data, units) in crate::io::drive_columns(d) {
            v.push(one_d(format!("drive/{name}"), data, units));
        }
    }
    if let Some(t) = &out.time_s {
        v.push(one_d("time".into(), t, "s"));
    }
    for tr in &out.gauges {
        v.push(one_d(format!("gauges/{}/strain", tr.name), &tr.strain, "1"));
        v.push(one_d(
            format!("gauges/{}/voltage", tr.name),
            &tr.voltage_v,
            "V",
        ));
    }
    for b in &out.bars {
        v.push(one_d(format!("bars/{}/x", b.name), &b.x_m, "m"));
        v.push(one_d(format!("bars/{}/time", b.name), &b.time_s, "s"));
        v.push(Dataset {
            path: format!("bars/{}/snapshots", b.name),
            shape: vec![b.time_s.len(), b.x_m.len()],
            data: Cow::Owned(b.stress_pa.iter().flatten().copied().collect()),
            units: Cow::Borrowed("Pa"),
        });
    }
    if let Some(sp) = &out.specimen {
        for (name, data, units) in crate::io::specimen_columns(sp) {
            v.push(one_d(format!("specimen/{name}"), data, units));
        }
    }
    if let Some(r) = &out.reduction {
        v.extend(reduction_datasets(r));
    }
    if let Some(c) = &out.cylinder_reduction {
        v.extend(cylinder_datasets(c));
    }
    for (name, data) in &out.energy {
        v.push(one_d(format!("energy/{name}"), data, "J"));
    }
    // Each sphere's `final_velocity_<k>` is an element of `chain/final_velocity`, not a scalar.
    for it in &out.summary {
        if crate::io::is_per_sphere_item(out, &it.key, it.value) {
            continue;
        }
        v.push(Dataset {
            path: format!("summary/{}", it.key),
            shape: vec![],
            data: Cow::Owned(vec![it.value]),
            units: Cow::Borrowed(it.unit),
        });
    }
    for it in &out.summary {
        if let Some(band) = it.band_90 {
            v.push(Dataset {
                path: format!("summary/bands/{}", it.key),
                shape: vec![2],
                data: Cow::Owned(band.to_vec()),
                units: Cow::Borrowed(it.unit),
            });
        }
    }
    v
}

/// The `/reduction/*` datasets of a reduction (as `shpb reduce -o` and `shpb run -o` write them).
pub fn reduction_datasets(r: &Reduction) -> Vec<Dataset<'_>> {
    crate::reduction::reduction_columns(r)
        .into_iter()
        .map(|(name, data, units, _)| one_d(format!("reduction/{name}"), data, units))
        .collect()
}

/// The `/reduction/cylinder/<analysis>/<series>` datasets of a cylinder's reduction (as
/// `shpb reduce --specimen-length --specimen-diameter -o` writes them; docs/physics.md §7.8).
pub fn cylinder_datasets(c: &shpb_core::reduce_cylinder::CylinderReduction) -> Vec<Dataset<'_>> {
    crate::reduction::cylinder_analyses(c)
        .into_iter()
        .flat_map(|(group, a)| {
            crate::reduction::analysis_columns(a)
                .into_iter()
                .map(move |(name, data, units, _)| {
                    one_d(format!("reduction/cylinder/{group}/{name}"), data, units)
                })
        })
        .collect()
}

/// A run file (of `shpb run -o`) or reduction file (of `shpb reduce -o`) read back.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunFile {
    /// Root attribute `scene`: the scene text (or the `shpb reduce` command line).
    pub scene: String,
    /// Every numeric (f64) dataset, in path order.
    pub datasets: Vec<Dataset<'static>>,
    /// The `/summary` values (key, value, units), in the order of the `units` attribute, then
    /// those a dataset holds one per element (attribute `summary_key` = `NAME_<k>`: element
    /// k − 1 is `NAME_k`, as `/chain/final_velocity` holds `final_velocity_<k>`).
    pub summary: Vec<(String, f64, String)>,
    /// The `/summary` attribute `warnings`, one per line.
    pub warnings: Vec<String>,
    /// `/provenance`, when the file has one.
    pub provenance: Option<shpb_input::files::Provenance>,
}

/// Reads every numeric dataset, the summary, the warnings and the provenance of a run or
/// reduction file.
pub fn read_run_file(path: &Path) -> Result<RunFile> {
    let f = crate::h5::open(path).map_err(h5err(path))?;
    let text_attr = |loc: &hdf5::Location, name: &str| -> Option<String> {
        loc.attr(name)
            .and_then(|a| a.read_scalar::<VarLenUnicode>())
            .ok()
            .map(|s| s.as_str().to_string())
    };
    let mut file = RunFile {
        scene: text_attr(&f, "scene").unwrap_or_default(),
        ..RunFile::default()
    };
    let mut per_element = Vec::new();
    let mut groups = vec![(String::new(), f.group("/").map_err(h5err(path))?)];
    while let Some((prefix, g)) = groups.pop() {
        for name in g.member_names().map_err(h5err(path))? {
            let full = format!("{prefix}{name}");
            if let Ok(sub) = g.group(&name) {
                groups.push((format!("{full}/"), sub));
                continue;
            }
            let Ok(ds) = g.dataset(&name) else { continue };
            if !ds.dtype().is_ok_and(|t| t.is::<f64>()) {
                continue;
            }
            let data = ds.read_raw::<f64>().map_err(h5err(path))?;
            let units = text_attr(&ds, "units").unwrap_or_default();
            if let Some(name) = text_attr(&ds, "summary_key")
                .as_deref()
                .and_then(|k| k.strip_suffix("<k>"))
            {
                per_element.push((full.clone(), name.to_string(), data.clone(), units.clone()));
            }
            file.datasets.push(Dataset {
                path: full,
                shape: ds.shape(),
                data: Cow::Owned(data),
                units: Cow::Owned(units),
            });
        }
    }
    file.datasets.sort_by(|a, b| a.path.cmp(&b.path));
    if let Ok(s) = f.group("summary") {
        let units = text_attr(&s, "units").unwrap_or_default();
        for entry in units.split(", ").filter(|e| !e.is_empty()) {
            let (key, unit) = entry.split_once('=').unwrap_or((entry, ""));
            if let Ok(value) = s.attr(key).and_then(|a| a.read_scalar::<f64>()) {
                file.summary
                    .push((key.to_string(), value, unit.to_string()));
            }
        }
        per_element.sort_by(|a, b| a.0.cmp(&b.0));
        for (_, name, data, units) in per_element {
            file.summary.extend(
                data.iter()
                    .enumerate()
                    .map(|(k, &x)| (format!("{name}{}", k + 1), x, units.clone())),
            );
        }
        file.warnings = text_attr(&s, "warnings")
            .unwrap_or_default()
            .lines()
            .map(str::to_string)
            .collect();
    }
    if f.group("provenance").is_ok() {
        file.provenance = Some(crate::provenance::read_provenance(path)?);
    }
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shpb_core::run::{GaugeTrace, item};
    use shpb_core::solver::ContactSeries;

    #[test]
    fn the_datasets_of_a_run_are_those_its_file_holds() {
        let out = RunOutput {
            contact: Some(ContactSeries {
                time_s: Some(vec![0.0, 1e-6, 2e-6]),
                displacement_m: vec![0.0, 1e-6, 2e-6],
                force_n: vec![0.0, 5.0, 7.5],
                yield_stress_pa: None,
                strain_rate_per_s: Some(vec![1.0, 2.0, 3.0]),
            }),
            time_s: Some(vec![0.0, 1e-6]),
            gauges: vec![GaugeTrace {
                name: "incident".into(),
                strain: vec![1e-4, 2e-4],
                voltage_v: vec![0.1, 0.2],
            }],
            energy: vec![("total".into(), vec![1.0, 1.0])],
            bars: vec![],
            summary: vec![item("peak_contact_force", 7.5, "N")],
            reduction: None,
            warnings: vec!["a warning".into()],
            chain: None,
            drive: Some(shpb_core::run::DriveSeries {
                time_s: vec![0.0, 1e-7, 2e-7],
                force_n: vec![0.0, 3.0, 0.0],
            }),
            specimen: Some({
                let mut s = shpb_core::solver::SpecimenSeries::default();
                let sample = shpb_core::solver::cylinder::SpecimenSample {
                    face_stress_pa: 1e8,
                    true_strain: 0.1,
                    ..Default::default()
                };
                s.push(0.0, &sample);
                s.push(1e-6, &sample);
                s
            }),
            cylinder_reduction: None,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.h5");
        crate::io::write_hdf5(&path, false, "kind = \"x\"\n", None, &out).unwrap();
        let back = read_run_file(&path).unwrap();
        let mut expected = run_datasets(&out);
        expected.sort_by(|a, b| a.path.cmp(&b.path));
        assert_eq!(back.datasets, expected);
        assert_eq!(
            back.summary,
            vec![("peak_contact_force".to_string(), 7.5, "N".to_string())]
        );
        assert_eq!(back.warnings, vec!["a warning".to_string()]);
        assert_eq!(back.scene, "kind = \"x\"\n");
        assert!(back.provenance.is_none());
    }

    /// A chain run of `n` spheres over `nt` times (values are only labels: force k·t, …).
    fn chain_run(n: usize, nt: usize) -> RunOutput {
        let t: Vec<f64> = (0..nt).map(|i| i as f64 * 1e-9).collect();
        let rows = |m: usize, scale: f64| -> Vec<Vec<f64>> {
            (0..m)
                .map(|k| t.iter().map(|x| scale * (k + 1) as f64 * x).collect())
                .collect()
        };
        let final_velocity: Vec<f64> = (0..n).map(|k| 0.5 + k as f64 * 1e-3).collect();
        let mut summary = vec![item("peak_force", 7.5, "N"), item("output_every", 1.0, "1")];
        for (k, v) in final_velocity.iter().enumerate() {
            summary.push(item(&format!("final_velocity_{}", k + 1), *v, "m/s"));
        }
        RunOutput {
            chain: Some(shpb_core::run::ChainSeries {
                contact_force_n: rows(n - 1, 1e9),
                contact_approach_m: rows(n - 1, 1.0),
                velocity_m_s: rows(n, 1e3),
                final_velocity_m_s: final_velocity,
                extra: vec![("wall_contact_force".into(), t.clone(), "N")],
                time_s: t,
            }),
            ..RunOutput::contact_only(
                ContactSeries {
                    time_s: Some(vec![0.0, 1e-9]),
                    displacement_m: vec![0.0, 1e-9],
                    force_n: vec![0.0, 1.0],
                    yield_stress_pa: None,
                    strain_rate_per_s: Some(vec![0.0, 1.0]),
                },
                summary,
            )
        }
    }

    /// Issue 45: a chain's per-sphere values are one dataset each, not an attribute and a
    /// dataset per sphere: `/summary` holds the same objects whatever the number of spheres,
    /// each sphere's `final_velocity_<k>` is element k − 1 of `/chain/final_velocity` (marked
    /// `summary_key`), and the file reads back as the run: same datasets, same summary.
    #[test]
    fn a_chain_s_per_sphere_values_are_datasets_not_attributes() {
        let dir = tempfile::tempdir().unwrap();
        let mut objects = Vec::new();
        for n in [3, 2000] {
            let out = chain_run(n, 5);
            let path = dir.path().join(format!("chain{n}.h5"));
            crate::io::write_hdf5(&path, false, "kind = \"chain\"\n", None, &out).unwrap();
            let back = read_run_file(&path).unwrap();
            let mut expected = run_datasets(&out);
            expected.sort_by(|a, b| a.path.cmp(&b.path));
            assert_eq!(back.datasets, expected);
            let summary: Vec<(String, f64, String)> = out
                .summary
                .iter()
                .map(|i| (i.key.clone(), i.value, i.unit.to_string()))
                .collect();
            assert_eq!(back.summary, summary);
            let f = hdf5::File::open(&path).unwrap();
            let s = f.group("summary").unwrap();
            objects.push((s.attr_names().unwrap(), s.member_names().unwrap()));
            assert!(s.attr("final_velocity_1").is_err());
            let fv = f.dataset("chain/final_velocity").unwrap();
            assert_eq!(fv.shape(), vec![n]);
            let key = fv.attr("summary_key").unwrap();
            assert_eq!(
                key.read_scalar::<VarLenUnicode>().unwrap().as_str(),
                "final_velocity_<k>"
            );
            assert_eq!(
                f.dataset("chain/velocity").unwrap().shape(),
                vec![n, 5],
                "sphere × time"
            );
        }
        assert_eq!(
            objects[0], objects[1],
            "/summary independent of the sphere count"
        );
        let (attrs, members) = &objects[0];
        assert_eq!(attrs.len(), 4, "{attrs:?}: two values, units and warnings");
        assert_eq!(members.len(), 2, "{members:?}");
    }

    /// Files written before issue 45 keep each `final_velocity_<k>` as a `/summary` attribute
    /// (listed in `units`) and a scalar dataset, and `/chain/final_velocity` unmarked: they read
    /// as they did, the summary from the attributes alone (not twice).
    #[test]
    fn a_chain_file_of_the_old_layout_reads_as_before() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("old.h5");
        let f = hdf5::File::create(&path).unwrap();
        let c = f.create_group("chain").unwrap();
        crate::h5::write_dataset(&c, "final_velocity", &[0.25, 0.5], "m/s", &path).unwrap();
        let s = f.create_group("summary").unwrap();
        let mut units = Vec::new();
        for (key, value, unit) in [
            ("restitution", 0.9, "1"),
            ("final_velocity_1", 0.25, "m/s"),
            ("final_velocity_2", 0.5, "m/s"),
        ] {
            let a = s.new_attr::<f64>().shape(()).create(key).unwrap();
            a.write_scalar(&value).unwrap();
            let ds = s.new_dataset::<f64>().shape(()).create(key).unwrap();
            ds.write_scalar(&value).unwrap();
            crate::h5::string_attr(&ds, "units", unit, &path).unwrap();
            units.push(format!("{key}={unit}"));
        }
        crate::h5::string_attr(&s, "units", &units.join(", "), &path).unwrap();
        crate::h5::string_attr(&s, "warnings", "", &path).unwrap();
        f.close().unwrap();
        let back = read_run_file(&path).unwrap();
        assert_eq!(
            back.summary,
            vec![
                ("restitution".to_string(), 0.9, "1".to_string()),
                ("final_velocity_1".to_string(), 0.25, "m/s".to_string()),
                ("final_velocity_2".to_string(), 0.5, "m/s".to_string()),
            ]
        );
        assert!(
            back.datasets
                .iter()
                .any(|d| d.path == "summary/final_velocity_2")
        );
    }
}
