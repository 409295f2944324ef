//! The workspace's structure, checked: no import cycle between the modules of any crate (crate
//! cycles are refused by cargo itself), a physics core free of I/O and configuration crates, and
//! HDF5 used by the output layer only.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            if p.file_name().unwrap() != "bin" {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Top-level module of `file` in the crate whose sources are in `src`.
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_string_lossy();
    first.trim_end_matches(".rs").to_string()
}

/// The `crate::<module>` names a source text uses outside its unit tests and comments.
fn used_modules(text: &str) -> BTreeSet<String> {
    let code: String = text
        .split("#[cfg(test)]")
        .next()
        .unwrap_or("")
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    let mut used = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + 7..];
        if rest.starts_with('{') {
            let group = &rest[1..rest.find('}').unwrap_or(rest.len())];
            for item in group.split(',') {
                let name = item.trim().split("::").next().unwrap_or("").trim();
                if !name.is_empty() {
                    used.insert(name.to_string());
                }
            }
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            used.insert(name);
        }
    }
    used
}

fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        u: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(u.to_string(), 1);
        stack.push(u.to_string());
        for v in &graph[u] {
            match state.get(v.as_str()) {
                Some(1) => {
                    let k = stack.iter().position(|s| s == v).unwrap();
                    let mut cycle = stack[k..].to_vec();
                    cycle.push(v.clone());
                    return Some(cycle);
                }
                None => {
                    if let Some(c) = visit(v, graph, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(u.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for u in graph.keys() {
        if !state.contains_key(u.as_str())
            && let Some(c) = visit(u, graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

#[test]
fn no_module_of_any_crate_imports_in_a_cycle() {
    let crates = std::fs::read_dir(workspace().join("crates")).unwrap();
    let mut checked = 0;
    for c in crates {
        let src = c.unwrap().path().join("src");
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for f in &files {
            let m = module_of(&src, f);
            let used = used_modules(&std::fs::read_to_string(f).unwrap());
            graph.entry(m.clone()).or_default().extend(used);
        }
        let names: BTreeSet<String> = graph.keys().cloned().collect();
        for (m, deps) in graph.iter_mut() {
            deps.retain(|d| d != m && names.contains(d));
        }
        assert_eq!(
            find_cycle(&graph),
            None,
            "import cycle in {}",
            src.display()
        );
        checked += 1;
    }
    assert!(checked >= 6, "expected the six crates, found {checked}");
}

#[test]
fn a_made_up_cycle_is_found() {
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    g.insert("a".into(), ["b".to_string()].into());
    g.insert("b".into(), ["a".to_string()].into());
    assert!(find_cycle(&g).is_some());
    assert_eq!(
        used_modules("use crate::{bar::Bar, error};\nlet x = crate::solver::f();"),
        ["bar", "error", "solver"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    );
}

/// The `[dependencies]` section of `crates/<name>/Cargo.toml`.
fn dependencies(name: &str) -> String {
    let manifest =
        std::fs::read_to_string(workspace().join("crates").join(name).join("Cargo.toml")).unwrap();
    manifest
        .split("[dependencies]")
        .nth(1)
        .unwrap()
        .split("\n[")
        .next()
        .unwrap()
        .to_string()
}

#[test]
fn the_core_depends_on_no_io_or_configuration_crate() {
    let deps = dependencies("core");
    for banned in ["serde", "toml", "clap", "hdf5", "plotters", "shpb-"] {
        assert!(
            !deps.contains(banned),
            "shpb-core depends on {banned}:\n{deps}"
        );
    }
}

/// HDF5 is a file format, so it belongs to shpb-output: the other library crates write and read
/// their files through it (the study file: `shpb_output::study`).
#[test]
fn only_the_output_layer_depends_on_hdf5() {
    for name in ["core", "input", "study", "validate"] {
        let deps = dependencies(name);
        assert!(
            !deps.contains("hdf5"),
            "crates/{name} depends on hdf5 (file formats belong to shpb-output):\n{deps}"
        );
    }
    assert!(dependencies("output").contains("hdf5"));
}
