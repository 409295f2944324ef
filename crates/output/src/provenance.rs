//! A run file's `/provenance`: the shpb version, the command line, the scene as named, the
//! `--fidelity` override and the text of every input the run read (scene, set-up, gauge,
//! material and specimen files, CSV records, built-ins), enough to rerun the test from the
//! file alone (`shpb run RUN.h5`, [`shpb_input::files::replay`]).

use crate::h5::{h5err, string_attr, vlu};
use hdf5::types::VarLenUnicode;
use shpb_input::files::{InputFile, Provenance};
use shpb_input::{Error, Result};
use std::path::Path;

/// Writes `/provenance` into the open file `f` (written as `path`).
pub fn write_provenance(f: &hdf5::File, p: &Provenance, path: &Path) -> Result<()> {
    let g = f.create_group("provenance").map_err(h5err(path))?;
    string_attr(&g, "shpb_version", env!("CARGO_PKG_VERSION"), path)?;
    string_attr(&g, "scene_file", &p.scene_file, path)?;
    string_attr(&g, "command_line", &p.command_line, path)?;
    string_attr(
        &g,
        "fidelity_override",
        p.fidelity_override.as_deref().unwrap_or(""),
        path,
    )?;
    let names: Vec<VarLenUnicode> = p.inputs.iter().map(|i| vlu(&i.name)).collect();
    let texts: Vec<VarLenUnicode> = p.inputs.iter().map(|i| vlu(&i.text)).collect();
    for (name, data, what) in [
        (
            "input_names",
            &names,
            "path of each input as read, or built-in:<name>",
        ),
        (
            "input_texts",
            &texts,
            "text of each input, in the order of input_names",
        ),
    ] {
        let ds = g
            .new_dataset_builder()
            .with_data(data.as_slice())
            .create(name)
            .map_err(h5err(path))?;
        string_attr(&ds, "description", what, path)?;
    }
    Ok(())
}

/// Reads the `/provenance` of a run file written by `shpb run -o`.
pub fn read_provenance(path: &Path) -> Result<Provenance> {
    let bad = |problem: String| Error::Input {
        file: path.display().to_string(),
        key: "/provenance".into(),
        problem,
        allowed: "a run file written by `shpb run -o` (shpb 0.1.0 or later, with /provenance)"
            .into(),
    };
    let f = crate::h5::open(path).map_err(|e| bad(format!("cannot open as HDF5: {e}")))?;
    let g = f
        .group("provenance")
        .map_err(|_| bad("no /provenance group: this file cannot be rerun".into()))?;
    let text = |name: &str| -> Result<String> {
        g.attr(name)
            .and_then(|a| a.read_scalar::<VarLenUnicode>())
            .map(|s| s.as_str().to_string())
            .map_err(|e| bad(format!("attribute {name}: {e}")))
    };
    let strings = |name: &str| -> Result<Vec<String>> {
        g.dataset(name)
            .and_then(|d| d.read_raw::<VarLenUnicode>())
            .map(|v| v.iter().map(|s| s.as_str().to_string()).collect())
            .map_err(|e| bad(format!("dataset {name}: {e}")))
    };
    let (names, texts) = (strings("input_names")?, strings("input_texts")?);
    if names.len() != texts.len() {
        return Err(bad(format!(
            "{} input names but {} texts",
            names.len(),
            texts.len()
        )));
    }
    let fidelity = text("fidelity_override")?;
    Ok(Provenance {
        scene_file: text("scene_file")?,
        fidelity_override: (!fidelity.is_empty()).then_some(fidelity),
        command_line: text("command_line")?,
        inputs: names
            .into_iter()
            .zip(texts)
            .map(|(name, text)| InputFile { name, text })
            .collect(),
    })
}
