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
/// `reduction/*`, `energy/*`, `summary/<key>` (scalars), `summary/bands/<key>` ([low, high]).
pub fn run_datasets(out: &RunOutput) -> Vec<Dataset<'_>> {
    let mut v = Vec::new();
    if let Some(contact) = &out.contact {
        for (name, data, units) in crate::io::contact_columns(contact) {
            v.push(one_d(format!("contact/{name}"), data, units));
        }
    }
    if let Some(c) = &out.chain {
        for (name, shape, data, units) in crate::io::chain_datasets(c) {
            v.push(Dataset {
                path: format!("chain/{name}"),
                shape,
                data: Cow::Owned(data),
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
    for it in &out.summary {
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
    /// The `/summary` values (key, value, units), in the order of the `units` attribute.
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
            file.datasets.push(Dataset {
                path: full,
                shape: ds.shape(),
                data: Cow::Owned(data),
                units: Cow::Owned(text_attr(&ds, "units").unwrap_or_default()),
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
}
