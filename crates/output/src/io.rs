//! Input and output: CSV tables in, HDF5 and CSV results out, written atomically
//! (temporary name, then a hard link that never replaces an existing file, or a rename with
//! `--force`; [`crate::atomic`]).

use shpb_core::run::{ChainSeries, RunOutput};
use shpb_core::solver::ContactSeries;
use shpb_input::{Error, Result};

pub use crate::atomic::{check_output, write_atomically, write_text_atomically};
pub use crate::h5::{h5err, string_attr, vlu, write_dataset};
use std::path::Path;

/// The `/drive` columns of a driven run (name, data, units), as both writers list them.
pub fn drive_columns(d: &shpb_core::run::DriveSeries) -> [(&'static str, &[f64], &'static str); 2] {
    [("time", &d.time_s, "s"), ("force", &d.force_n, "N")]
}

/// The `/contact` datasets of a series: (name, data, units), absent ones skipped.
pub fn contact_columns(s: &ContactSeries) -> Vec<(&'static str, &[f64], &'static str)> {
    let mut cols = Vec::new();
    if let Some(t) = &s.time_s {
        cols.push(("time", t.as_slice(), "s"));
    }
    cols.push(("displacement", s.displacement_m.as_slice(), "m"));
    cols.push(("force", s.force_n.as_slice(), "N"));
    if let Some(v) = &s.yield_stress_pa {
        cols.push(("yield_stress", v.as_slice(), "Pa"));
    }
    if let Some(v) = &s.strain_rate_per_s {
        cols.push(("strain_rate", v.as_slice(), "1/s"));
    }
    cols
}

/// The values of one `/chain` dataset: a series, or rows of one length (a 2-D dataset, row-major).
#[derive(Debug, Clone, Copy)]
pub enum ChainValues<'a> {
    /// A 1-D dataset.
    Series(&'a [f64]),
    /// A 2-D dataset: one row per contact or sphere, one column per time of `/chain/time`.
    Rows(&'a [Vec<f64>]),
}

impl ChainValues<'_> {
    /// The dataset's shape (rows first).
    pub fn shape(&self) -> Vec<usize> {
        match self {
            ChainValues::Series(d) => vec![d.len()],
            ChainValues::Rows(r) => vec![r.len(), r.first().map_or(0, Vec::len)],
        }
    }

    /// The values, row-major (a copy of one dataset: the writer holds one at a time).
    pub fn flat(&self) -> Vec<f64> {
        match self {
            ChainValues::Series(d) => d.to_vec(),
            ChainValues::Rows(r) => r.concat(),
        }
    }
}

/// The `/chain` datasets of a chain run, borrowed: (name, values, units). 2-D ones have one row
/// per contact (`contact_force`, `contact_approach`: contact k between spheres k and k + 1) or
/// per sphere (`velocity`), one column per time of `time`; `final_velocity` has one value per
/// sphere (issue 45: per-sphere values as one dataset each, not a value per sphere).
pub fn chain_columns(c: &ChainSeries) -> Vec<(&str, ChainValues<'_>, &'static str)> {
    let mut v = vec![
        ("time", ChainValues::Series(&c.time_s), "s"),
        ("contact_force", ChainValues::Rows(&c.contact_force_n), "N"),
        (
            "contact_approach",
            ChainValues::Rows(&c.contact_approach_m),
            "m",
        ),
        ("velocity", ChainValues::Rows(&c.velocity_m_s), "m/s"),
        (
            "final_velocity",
            ChainValues::Series(&c.final_velocity_m_s),
            "m/s",
        ),
    ];
    for (name, data, units) in &c.extra {
        v.push((name.as_str(), ChainValues::Series(data), *units));
    }
    v
}

/// The summary items a chain run's summary holds one per sphere (`final_velocity_<k>`, k from
/// 1), which its file keeps as the elements of `/chain/final_velocity` (attribute
/// `summary_key` = [`FINAL_VELOCITY_SUMMARY_KEY`]) instead of an attribute and a dataset each:
/// true for the item `key` = `final_velocity_<k>` whose value is element k − 1 of the chain's
/// final velocities (issue 45: HDF5 attribute insertion is quadratic in their number).
pub fn is_per_sphere_item(out: &RunOutput, key: &str, value: f64) -> bool {
    let Some(c) = &out.chain else { return false };
    key.strip_prefix("final_velocity_")
        .and_then(|k| k.parse::<usize>().ok())
        .and_then(|k| c.final_velocity_m_s.get(k.checked_sub(1)?))
        .is_some_and(|v| v.to_bits() == value.to_bits())
}

/// The `summary_key` attribute of `/chain/final_velocity`: element k − 1 is the summary item
/// `final_velocity_<k>` ([`is_per_sphere_item`]; [`crate::run_file::read_run_file`] lists them).
pub const FINAL_VELOCITY_SUMMARY_KEY: &str = "final_velocity_<k>";

/// True when `out`'s summary holds every sphere's `final_velocity_<k>` (a `chain` scene): its
/// file then marks `/chain/final_velocity` with [`FINAL_VELOCITY_SUMMARY_KEY`].
pub fn summary_has_final_velocities(out: &RunOutput) -> bool {
    let Some(c) = &out.chain else { return false };
    !c.final_velocity_m_s.is_empty()
        && out
            .summary
            .iter()
            .filter(|it| is_per_sphere_item(out, &it.key, it.value))
            .count()
            == c.final_velocity_m_s.len()
}

/// Origin of `/time` and `/contact/time` (both on the simulation clock).
pub const TIME_ORIGIN: &str = "the striker's impact (t = 0 of the simulation)";

/// Writes a run to HDF5: the series with their units, `/summary` (each value as an attribute
/// and as a scalar dataset carrying its own `units`), root `shpb_version` and `scene`, and
/// `/provenance` (module [`crate::provenance`]) when given. Every time axis states its origin
/// and its offset from `/time` (attributes `origin`, `offset_from_time_s`).
pub fn write_hdf5(
    path: &Path,
    force: bool,
    scene_text: &str,
    provenance: Option<&shpb_input::files::Provenance>,
    out: &RunOutput,
) -> Result<()> {
    write_atomically(path, force, |tmp| {
        let f = crate::h5::create(tmp).map_err(h5err(path))?;
        string_attr(&f, "shpb_version", env!("CARGO_PKG_VERSION"), path)?;
        string_attr(&f, "scene", scene_text, path)?;
        let origin = |g: &hdf5::Group, name: &str, origin: &str, offset_s: f64| -> Result<()> {
            let ds = g.dataset(name).map_err(h5err(path))?;
            string_attr(&ds, "origin", origin, path)?;
            ds.new_attr::<f64>()
                .shape(())
                .create("offset_from_time_s")
                .and_then(|a| a.write_scalar(&offset_s))
                .map_err(h5err(path))
        };
        if let Some(contact) = &out.contact {
            let g = f.create_group("contact").map_err(h5err(path))?;
            for (name, data, units) in contact_columns(contact) {
                write_dataset(&g, name, data, units, path)?;
            }
            if contact.time_s.is_some() {
                origin(&g, "time", TIME_ORIGIN, 0.0)?;
            }
        }
        if let Some(c) = &out.chain {
            let g = f.create_group("chain").map_err(h5err(path))?;
            for (name, values, units) in chain_columns(c) {
                match values {
                    ChainValues::Rows(_) => {
                        let shape = values.shape();
                        let field =
                            ndarray::Array2::from_shape_vec((shape[0], shape[1]), values.flat())
                                .map_err(|e| Error::Hdf5 {
                                    file: path.display().to_string(),
                                    message: format!("/chain/{name}: {e}"),
                                })?;
                        let ds = g
                            .new_dataset_builder()
                            .with_data(&field)
                            .create(name)
                            .map_err(h5err(path))?;
                        string_attr(&ds, "units", units, path)?;
                        let what = if name == "velocity" {
                            "sphere"
                        } else {
                            "contact (k: spheres k and k + 1)"
                        };
                        string_attr(
                            &ds,
                            "description",
                            &format!("rows: {what}, columns: /chain/time"),
                            path,
                        )?;
                    }
                    ChainValues::Series(data) => write_dataset(&g, name, data, units, path)?,
                }
            }
            if summary_has_final_velocities(out) {
                let ds = g.dataset("final_velocity").map_err(h5err(path))?;
                string_attr(&ds, "summary_key", FINAL_VELOCITY_SUMMARY_KEY, path)?;
                string_attr(
                    &ds,
                    "description",
                    "each sphere's velocity at the end (sphere k at index k - 1): the summary \
                     items final_velocity_<k>",
                    path,
                )?;
            }
            origin(&g, "time", TIME_ORIGIN, 0.0)?;
        }
        if let Some(d) = &out.drive {
            let g = f.create_group("drive").map_err(h5err(path))?;
            for (name, data, units) in drive_columns(d) {
                write_dataset(&g, name, data, units, path)?;
            }
            origin(
                &g,
                "time",
                "the drive's first level (t = 0 of the simulation)",
                0.0,
            )?;
            let force = g.dataset("force").map_err(h5err(path))?;
            string_attr(
                &force,
                "description",
                "force on the incident bar's impact end (compression positive), one value per \
                 time step: the recorded incident wave after its edge taper and band limit",
                path,
            )?;
        }
        if let Some(t) = &out.time_s {
            let root = f.group("/").map_err(h5err(path))?;
            write_dataset(&root, "time", t, "s", path)?;
            origin(&root, "time", TIME_ORIGIN, 0.0)?;
        }
        if !out.gauges.is_empty() {
            let g = f.create_group("gauges").map_err(h5err(path))?;
            for tr in &out.gauges {
                let c = g.create_group(&tr.name).map_err(h5err(path))?;
                write_dataset(&c, "strain", &tr.strain, "1", path)?;
                write_dataset(&c, "voltage", &tr.voltage_v, "V", path)?;
            }
        }
        if !out.bars.is_empty() {
            let g = f.create_group("bars").map_err(h5err(path))?;
            for b in &out.bars {
                let c = g.create_group(&b.name).map_err(h5err(path))?;
                write_dataset(&c, "x", &b.x_m, "m", path)?;
                write_dataset(&c, "time", &b.time_s, "s", path)?;
                let flat: Vec<f64> = b.stress_pa.iter().flatten().copied().collect();
                let field = ndarray::Array2::from_shape_vec((b.time_s.len(), b.x_m.len()), flat)
                    .map_err(|e| Error::Hdf5 {
                        file: path.display().to_string(),
                        message: e.to_string(),
                    })?;
                let ds = c
                    .new_dataset_builder()
                    .with_data(&field)
                    .create("snapshots")
                    .map_err(h5err(path))?;
                string_attr(&ds, "units", "Pa", path)?;
                string_attr(
                    &ds,
                    "description",
                    "axial stress (tension positive), rows: time, columns: x",
                    path,
                )?;
            }
        }
        if let Some(sp) = &out.specimen {
            let g = f.create_group("specimen").map_err(h5err(path))?;
            for (name, data, units) in specimen_columns(sp) {
                write_dataset(&g, name, data, units, path)?;
            }
            origin(&g, "time", TIME_ORIGIN, 0.0)?;
            string_attr(
                &g,
                "description",
                "the cylinder's own state (compression positive): true stress (face forces over the \
                 current area), true strain −ln(h/L0) and its rate, as the model has them, beside \
                 /reduction/cylinder, what the lab's reduction reads; docs/physics.md §6.12",
                path,
            )?;
        }
        if let Some(r) = &out.reduction {
            let g = f.create_group("reduction").map_err(h5err(path))?;
            for (name, data, units, _) in crate::reduction::reduction_columns(r) {
                write_dataset(&g, name, data, units, path)?;
            }
            if let Some(c) = &out.cylinder_reduction {
                crate::reduction::write_cylinder_group(&g, c, path)?;
            }
            origin(
                &g,
                "time",
                "the incident pulse's foot at the specimen face (record clock: /time + offset_from_time_s)",
                r.face_time_offset_s,
            )?;
        }
        if !out.energy.is_empty() {
            let g = f.create_group("energy").map_err(h5err(path))?;
            for (name, data) in &out.energy {
                write_dataset(&g, name, data, "J", path)?;
            }
        }
        let s = f.create_group("summary").map_err(h5err(path))?;
        // The scalar items: each sphere's `final_velocity_<k>` is in `/chain/final_velocity`.
        let scalars: Vec<_> = out
            .summary
            .iter()
            .filter(|it| !is_per_sphere_item(out, &it.key, it.value))
            .collect();
        for it in &scalars {
            let a = s
                .new_attr::<f64>()
                .shape(())
                .create(it.key.as_str())
                .map_err(h5err(path))?;
            a.write_scalar(&it.value).map_err(h5err(path))?;
            let ds = s
                .new_dataset::<f64>()
                .shape(())
                .create(it.key.as_str())
                .map_err(h5err(path))?;
            ds.write_scalar(&it.value).map_err(h5err(path))?;
            string_attr(&ds, "units", it.unit, path)?;
        }
        string_attr(
            &s,
            "units",
            &scalars
                .iter()
                .map(|i| format!("{}={}", i.key, i.unit))
                .collect::<Vec<_>>()
                .join(", "),
            path,
        )?;
        string_attr(&s, "warnings", &out.warnings.join("\n"), path)?;
        // docs/physics.md §10.6: the 90 % band of a summary value, `/summary/bands/<key>` =
        // [low, high] with the value and its band as attributes.
        if out.summary.iter().any(|it| it.band_90.is_some()) {
            let g = s.create_group("bands").map_err(h5err(path))?;
            for it in &out.summary {
                let Some(band) = it.band_90 else { continue };
                let ds = g
                    .new_dataset_builder()
                    .with_data(&band)
                    .create(it.key.as_str())
                    .map_err(h5err(path))?;
                string_attr(&ds, "units", it.unit, path)?;
                for (name, x) in [("value", it.value), ("low", band[0]), ("high", band[1])] {
                    ds.new_attr::<f64>()
                        .shape(())
                        .create(name)
                        .and_then(|a| a.write_scalar(&x))
                        .map_err(h5err(path))?;
                }
                string_attr(&ds, "unit", it.unit, path)?;
            }
        }
        if let Some(p) = provenance {
            crate::provenance::write_provenance(&f, p, path)?;
        }
        f.close().map_err(h5err(path))
    })
}

/// The `/specimen/*` series of a simulated cylinder (name, data, units; docs/physics.md §6.12).
pub fn specimen_columns(
    s: &shpb_core::solver::SpecimenSeries,
) -> [(&'static str, &[f64], &'static str); 11] {
    [
        ("time", &s.time_s, "s"),
        ("true_stress", &s.face_stress_pa, "Pa"),
        ("element_stress", &s.element_stress_pa, "Pa"),
        ("true_strain", &s.true_strain, "1"),
        ("true_strain_rate", &s.true_strain_rate_per_s, "1/s"),
        ("plastic_strain", &s.plastic_strain, "1"),
        ("temperature", &s.temperature_k, "K"),
        ("friction_stress", &s.friction_stress_pa, "Pa"),
        ("inertia_stress", &s.inertia_stress_pa, "Pa"),
        ("plastic_work", &s.plastic_work_j, "J"),
        ("friction_work", &s.friction_work_j, "J"),
    ]
}

/// Writes a run as CSV with one header line (units in the column names): the contact series,
/// for chains the time with every contact's force and every sphere's velocity, or for bar
/// scenes the time axis with each gauge's strain and voltage.
pub fn write_csv(path: &Path, force: bool, out: &RunOutput) -> Result<()> {
    let mut cols: Vec<(String, &[f64])> = Vec::new();
    if let Some(c) = &out.chain {
        // A chain: time, the force of every contact, the velocity of every sphere.
        cols.push(("time_s".into(), &c.time_s));
        for (k, f) in c.contact_force_n.iter().enumerate() {
            cols.push((format!("contact{}_force_N", k + 1), f));
        }
        for (k, v) in c.velocity_m_s.iter().enumerate() {
            cols.push((format!("sphere{}_velocity_m_s", k + 1), v));
        }
    } else if let Some(c) = &out.contact {
        for (n, d, u) in contact_columns(c) {
            cols.push((csv_name(n, u), d));
        }
    } else if let Some(t) = &out.time_s {
        cols.push(("time_s".into(), t));
        for g in &out.gauges {
            cols.push((format!("{}_strain", g.name), &g.strain));
            cols.push((format!("{}_voltage_V", g.name), &g.voltage_v));
        }
    }
    let rows = cols.iter().map(|(_, d)| d.len()).min().unwrap_or(0);
    let mut text = cols
        .iter()
        .map(|(n, _)| n.as_str())
        .collect::<Vec<_>>()
        .join(",");
    text.push('\n');
    for i in 0..rows {
        let row: Vec<String> = cols.iter().map(|(_, d)| format!("{:e}", d[i])).collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    write_text_atomically(path, force, &text)
}

/// CSV column name with unit, e.g. `force_N`, `strain_rate_per_s`.
pub fn csv_name(name: &str, unit: &str) -> String {
    let u = match unit {
        "1/s" => "per_s",
        u => u,
    };
    format!("{name}_{u}")
}
