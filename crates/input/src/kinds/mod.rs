//! The registry of scene kinds: one file per kind (in the style of ripgrep's flag definitions),
//! each giving its name, one-line help, the keys it accepts, a README example and the parser that
//! validates its TOML into the core's [`SceneParams`].
//!
//! [`crate::scene::SceneFile::from_toml`] reads the keys every scene shares (`kind`, `fidelity`)
//! and hands the text to the kind's [`SceneKind::parse`]; `shpb --help` ([`help_text`]), the
//! "unknown scene kind" error ([`names`]) and the README table ([`readme_table`]) are generated
//! from [`KINDS`], so a new kind is one new file plus one line in [`KINDS`].

use crate::error::{Result, Validator};
use serde::Deserialize;
use shpb_core::contact::{LawKind, LawSpec, Region2Form, Unloading};
use shpb_core::fidelity::Fidelity;
use shpb_core::scene::SceneParams;
use shpb_core::specimen::{Specimen, SpherePair, SphereSpecimen};
use std::path::Path;

mod chain;
mod collision;
mod constant_rate;
mod force_driven;
mod pulse;
mod quasistatic;
mod shpb;

/// The schema of a sphere scene file: the keys every sphere scene has (`kind`, `fidelity`,
/// `specimen`, `law`, `region2`), then the kind's own fields; unknown keys are refused. (serde's
/// `flatten` cannot be combined with `deny_unknown_fields`, so the common keys are written once
/// here instead.)
macro_rules! sphere_scene_file {
    ($(#[$meta:meta])* struct $name:ident { $($(#[$fmeta:meta])* $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$meta])*
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct $name {
            #[allow(dead_code)]
            kind: String,
            #[allow(dead_code)]
            fidelity: Option<String>,
            specimen: crate::specimen::SpecimenSpec,
            #[serde(default, with = "super::LawKindToml")]
            law: shpb_core::contact::LawKind,
            #[serde(default, with = "super::Region2Toml")]
            region2: shpb_core::contact::Region2Form,
            #[serde(default, with = "super::UnloadingToml")]
            unloading: shpb_core::contact::Unloading,
            $($(#[$fmeta])* $field: $ty,)*
        }

        impl $name {
            /// The scene's contact law with its own parameters (`law`, `region2`, `unloading`).
            fn law_spec(&self) -> shpb_core::contact::LawSpec {
                shpb_core::contact::LawSpec {
                    kind: self.law,
                    region2: self.region2,
                    unloading: self.unloading,
                }
            }
        }
    };
}
pub(crate) use sphere_scene_file;

/// What a kind's parser returns: the specimen with its own model (None for a `pulse` scene) and
/// the kind-specific parameters (the rest of [`shpb_core::scene::Params`] is common to all kinds).
pub type Parsed = (Option<Specimen>, SceneParams);

/// A pair of spheres touching at rest as a scene's specimen, with its contact law.
pub(crate) fn pair_specimen(pair: &SpherePair, law: LawSpec) -> Option<Specimen> {
    Some(Specimen::Spheres(SphereSpecimen::pair(pair, law)))
}

/// A kind's parser: `(text, file, base_dir, fidelity, v)` → validated parameters. `text` is the
/// whole scene TOML, `file` its name for messages, `base_dir` the directory relative paths are
/// resolved against, `fidelity` the preset already read from the scene, `v` a validator of `file`.
pub type ParseFn = fn(
    text: &str,
    file: &str,
    base_dir: &Path,
    fidelity: Fidelity,
    v: &Validator,
) -> Result<Parsed>;

/// One key a scene kind accepts, for the documentation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Key {
    /// The TOML key (a table such as `specimen` or `shaper` is one entry).
    pub key: &'static str,
    /// The unit of the value (`""` for names, counts and tables).
    pub unit: &'static str,
    /// The default (`"required"` when the key must be given).
    pub default: &'static str,
    /// What it sets and the allowed values.
    pub meaning: &'static str,
}

/// A scene kind: everything about one value of the `kind` key.
#[derive(Debug, Clone, Copy)]
pub struct SceneKind {
    /// The value of `kind`.
    pub name: &'static str,
    /// One line for `shpb --help` and the README table.
    pub help: &'static str,
    /// The keys the kind accepts besides the common [`COMMON_KEYS`], in the order documented.
    pub keys: &'static [Key],
    /// A complete minimal scene of this kind (shown in the README; a unit test parses it).
    pub example: &'static str,
    /// The directory, relative to the repository root, [`example`](Self::example) is written for
    /// (it names a file by a relative path); `None` when it uses only built-ins and so parses
    /// from any directory.
    pub example_dir: Option<&'static str>,
    /// Validates a scene of this kind.
    pub parse: ParseFn,
}

/// Every scene kind, in the order `shpb --help`, the errors and the README list them.
pub const KINDS: &[SceneKind] = &[
    quasistatic::KIND,
    constant_rate::KIND,
    collision::KIND,
    force_driven::KIND,
    pulse::KIND,
    shpb::KIND,
    chain::KIND,
];

/// The keys every scene accepts, whatever its kind (read by `from_toml` before dispatching).
pub const COMMON_KEYS: &[Key] = &[
    Key {
        key: "kind",
        unit: "",
        default: "required",
        meaning: "the scene kind",
    },
    Key {
        key: "fidelity",
        unit: "",
        default: "standard",
        meaning: "fast, standard or reference: the numerical knobs marked \"fidelity\" (an explicit key wins)",
    },
];

/// The kind named `name`, if registered.
pub fn find(name: &str) -> Option<&'static SceneKind> {
    KINDS.iter().find(|k| k.name == name)
}

/// The names of all scene kinds, in registry order.
pub fn names() -> Vec<&'static str> {
    KINDS.iter().map(|k| k.name).collect()
}

/// (name, one-line help) of every scene kind, in registry order: what `shpb --help`, `shpb list`,
/// the "unknown kind" error and the README table show.
pub fn names_and_help() -> Vec<(&'static str, &'static str)> {
    KINDS.iter().map(|k| (k.name, k.help)).collect()
}

/// (name, one-line help) of every scene kind, derived from [`KINDS`] at compile time.
///
/// Kept only for callers that have not switched to [`names`] or [`names_and_help`] yet
/// (`crates/cli/tests/cli.rs`); remove it once they have.
pub const SCENE_KINDS: &[(&str, &str)] = &{
    let mut out = [("", ""); KINDS.len()];
    let mut i = 0;
    while i < KINDS.len() {
        out[i] = (KINDS[i].name, KINDS[i].help);
        i += 1;
    }
    out
};

/// The kind names joined for the "allowed:" part of an error about `kind`.
pub(crate) fn allowed() -> String {
    names().join(", ")
}

/// The scene-kinds section of `shpb --help`: each kind with its help and its keys.
pub fn help_text() -> String {
    const WIDTH: usize = 90;
    const INDENT: usize = 17;
    let mut out = String::from(
        "SCENE KINDS (TOML files with a `kind` key; see README.md for full examples):\n",
    );
    for k in KINDS {
        let first = format!("  {:<width$}", k.name, width = INDENT - 2);
        wrap_into(&mut out, &first, k.help, WIDTH, INDENT);
        let keys: Vec<&str> = k.keys.iter().map(|key| key.key).collect();
        wrap_into(
            &mut out,
            &" ".repeat(INDENT),
            &format!("keys: {}", keys.join(", ")),
            WIDTH,
            INDENT,
        );
    }
    out.push_str(
        "Every scene may set fidelity = \"fast\" | \"standard\" | \"reference\" (default \"standard\");\n\
         relative paths in a scene are resolved against the scene file's directory.",
    );
    out
}

/// Appends `text` after `first` (a prefix of `indent` columns), word-wrapped at `width` columns
/// with continuation lines indented by `indent`.
fn wrap_into(out: &mut String, first: &str, text: &str, width: usize, indent: usize) {
    let mut line = first.to_string();
    let mut len = first.chars().count();
    let mut empty = true;
    for word in text.split_whitespace() {
        let w = word.chars().count();
        if !empty && len + 1 + w > width {
            out.push_str(&line);
            out.push('\n');
            line = " ".repeat(indent);
            len = indent;
            empty = true;
        }
        if !empty {
            line.push(' ');
            len += 1;
        }
        line.push_str(word);
        len += w;
        empty = false;
    }
    out.push_str(&line);
    out.push('\n');
}

/// Escapes `|` for a Markdown table cell.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The README's table of scene kinds (Markdown): kind, what it runs, and a minimal example
/// scene, one line of TOML per `<br>`.
pub fn readme_table() -> String {
    let mut out = String::from("| kind | what it runs | example |\n|---|---|---|\n");
    for k in KINDS {
        let example = k
            .example
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| format!("`{}`", cell(l)))
            .collect::<Vec<_>>()
            .join("<br>");
        out.push_str(&format!(
            "| `{}` | {} | {} |\n",
            k.name,
            cell(k.help),
            example
        ));
    }
    let placed: Vec<String> = KINDS
        .iter()
        .filter_map(|k| {
            k.example_dir.map(|d| match d {
                "" | "." => format!(
                    "`{}`, written for a scene saved in the repository root",
                    k.name
                ),
                d => format!("`{}`, written for a scene saved in `{d}/`", k.name),
            })
        })
        .collect();
    if !placed.is_empty() {
        out.push_str(&format!(
            "\nRelative paths in a scene are resolved against the scene file's directory. The examples \
             use built-in materials and set-ups and work from any directory, except {}.\n",
            placed.join("; ")
        ));
    }
    out
}

/// The keys of every kind as Markdown tables (key, unit, default, meaning), for the README.
pub fn readme_keys() -> String {
    let mut out = String::new();
    let mut table = |title: String, keys: &[Key]| {
        out.push_str(&format!(
            "{title}\n\n| key | unit | default | meaning |\n|---|---|---|---|\n"
        ));
        for key in keys {
            out.push_str(&format!(
                "| `{}` | {} | {} | {} |\n",
                key.key,
                cell(key.unit),
                cell(key.default),
                cell(key.meaning)
            ));
        }
        out.push('\n');
    };
    table("Every scene:".to_string(), COMMON_KEYS);
    for k in KINDS {
        table(format!("`kind = \"{}\"`:", k.name), k.keys);
    }
    out.truncate(out.trim_end().len());
    out.push('\n');
    out
}

// ---- Shared by the kinds' files ----

/// `[specimen]` of a scene with spheres.
const SPECIMEN: Key = Key {
    key: "specimen",
    unit: "",
    default: "required",
    meaning: "the two spheres: pair = \"ss440c\" (a built-in material's 6.35 mm pair, or a pair .toml file), or [specimen.sphere1] and [specimen.sphere2] tables with material, diameter_m or radius_m, optional mass_kg; yield_stress_pa (Pa), jc_c and jc_reference_rate_per_s (1/s) replace both spheres' material constants (σy, C, ε̇0 of paper Eq. 2)",
};

/// `[specimen]` of a scene with a chain of spheres (`chain`, `shpb`).
const CHAIN_SPECIMEN: Key = Key {
    key: "specimen",
    unit: "",
    default: "required",
    meaning: "the spheres in a line, sphere 1 first: count = N (2 to 100000) with material (built-in or .toml) and diameter_m, or one [[specimen.sphere]] table per sphere (material, diameter_m or radius_m, optional mass_kg), or a pair as in the other scenes (pair = \"ss440c\", or sphere1/sphere2); yield_stress_pa (Pa), jc_c and jc_reference_rate_per_s (1/s) replace every sphere's material constants (σy, C, ε̇0 of paper Eq. 2)",
};

/// `law = "..."`.
const LAW: Key = Key {
    key: "law",
    unit: "",
    default: "burgoyne-daraio",
    meaning: "contact law: burgoyne-daraio (Eq. 1, Johnson–Cook rate hardening), rate-independent (static yield stress) or hertz (elastic)",
};

/// `region2 = "..."`.
const REGION2: Key = Key {
    key: "region2",
    unit: "",
    default: "smooth",
    meaning: "region II of the loading law: smooth (C¹ at the yield point) or published (as printed in the paper)",
};

/// `unloading = "..."`.
const UNLOADING: Key = Key {
    key: "unloading",
    unit: "",
    default: "dynamic",
    meaning: "unloading after yield: dynamic (from the largest force reached and the rate-hardened yield stress, less vibration loss), static (from the static curve at the largest approach) or authors (as the authors' code)",
};

/// `output_every = n`.
const OUTPUT_EVERY: Key = Key {
    key: "output_every",
    unit: "",
    default: "1",
    meaning: "keep every n-th step in the output (1 or more)",
};

/// `law = "..."`: the scene names of [`LawKind`].
#[derive(Deserialize)]
#[serde(remote = "LawKind", rename_all = "kebab-case")]
enum LawKindToml {
    BurgoyneDaraio,
    RateIndependent,
    Hertz,
}

/// Checks `max_displacement_m` of a loading scene: positive and at most half the smaller sphere
/// radius, the bound both loading scenes (quasistatic, constant-rate) apply.
fn check_max_displacement(v: &Validator, value_m: f64, pair: &SpherePair) -> Result<f64> {
    v.positive(
        "max_displacement_m",
        value_m,
        0.5 * pair.sphere1.radius_m.min(pair.sphere2.radius_m),
        "m",
    )
}

/// `unloading = "..."`: the scene names of [`Unloading`].
#[derive(Deserialize)]
#[serde(remote = "Unloading", rename_all = "kebab-case")]
enum UnloadingToml {
    Dynamic,
    Static,
    Authors,
    DynamicContinuous,
}

/// `region2 = "..."`: the scene names of [`Region2Form`].
#[derive(Deserialize)]
#[serde(remote = "Region2Form", rename_all = "kebab-case")]
enum Region2Toml {
    Smooth,
    Published,
}

fn default_points() -> usize {
    1001
}

fn one() -> usize {
    1
}

fn check_points(v: &Validator, points: usize) -> Result<usize> {
    if !(2..=10_000_000).contains(&points) {
        return Err(v.error(
            "points",
            format!("{points} is out of range"),
            "2 to 10000000",
        ));
    }
    Ok(points)
}

fn check_every(v: &Validator, n: usize) -> Result<usize> {
    if n == 0 {
        return Err(v.error("output_every", "0 is out of range", "1 or more"));
    }
    Ok(n)
}

/// The checks every kind's own unit test runs on its registry entry: a kebab-case name and a
/// one-line help, an example of this kind that parses (from any directory when `example_dir` is
/// `None`), and documented keys that are exactly the keys the parser accepts (`undocumented`:
/// keys the parser accepts but this kind ignores or refuses).
/// Parses a kind's README example from a directory holding no file (built-ins only) at `fidelity`.
#[cfg(test)]
fn parse_example(kind: &SceneKind, fidelity: Fidelity) -> Parsed {
    let v = Validator::new("example.toml");
    (kind.parse)(
        kind.example,
        "example.toml",
        Path::new("/nowhere"),
        fidelity,
        &v,
    )
    .unwrap_or_else(|e| panic!("{}: {e}", kind.name))
}

#[cfg(test)]
fn check_kind(kind: &SceneKind, undocumented: &[&str]) {
    use crate::scene::SceneFile;
    use shpb_core::scene::Params;
    use std::collections::BTreeSet;

    let name = kind.name;
    assert!(
        !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
        "`{name}` is not kebab-case"
    );
    assert_eq!(
        find(name).map(|k| k.help),
        Some(kind.help),
        "{name} is not registered"
    );
    assert!(
        !kind.help.is_empty() && !kind.help.contains('\n') && kind.help.len() < 120,
        "{name}: help must be one short line"
    );

    // The example is of this kind and parses.
    assert_eq!(
        kind.example.lines().next(),
        Some(format!("kind = \"{name}\"").as_str()),
        "{name}: the example starts with its kind"
    );
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let base = match kind.example_dir {
        Some(d) => repo.join(d),
        None => Path::new("/nonexistent-directory-of-shpb-examples").to_path_buf(),
    };
    let p = Params::from_toml(kind.example, "example.toml", &base)
        .unwrap_or_else(|e| panic!("{name}: README example does not parse: {e}"));
    assert_eq!(p.kind, name);
    // …and through the registry entry itself.
    let v = Validator::new("example.toml");
    (kind.parse)(kind.example, "example.toml", &base, Fidelity::default(), &v).unwrap();

    // Documented keys == accepted keys (read from the parser's unknown-field message).
    let documented: Vec<&str> = kind.keys.iter().map(|k| k.key).collect();
    let unique: BTreeSet<&str> = documented.iter().copied().collect();
    assert_eq!(
        unique.len(),
        documented.len(),
        "{name}: a key is documented twice"
    );
    for k in kind.keys.iter().chain(COMMON_KEYS) {
        assert!(
            !k.meaning.is_empty() && !k.default.is_empty(),
            "{name}: `{}` undocumented",
            k.key
        );
    }
    let err = Params::from_toml(
        &format!("zz_not_a_key = 1\n{}", kind.example),
        "example.toml",
        &base,
    )
    .unwrap_err()
    .to_string();
    let list = err
        .split("expected one of ")
        .nth(1)
        .unwrap_or_else(|| panic!("{name}: no field list in: {err}"))
        .lines()
        .next()
        .unwrap();
    let accepted: BTreeSet<&str> = list.split(", ").map(|f| f.trim_matches('`')).collect();
    let expected: BTreeSet<&str> = documented
        .iter()
        .chain(COMMON_KEYS.iter().map(|k| &k.key))
        .chain(undocumented)
        .copied()
        .collect();
    assert_eq!(
        accepted, expected,
        "{name}: documented keys differ from accepted ones"
    );
    for u in undocumented {
        assert!(
            !unique.contains(u),
            "{name}: `{u}` is both documented and undocumented"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneFile;
    use shpb_core::scene::Params;

    #[test]
    fn names_are_unique_and_in_registry_order() {
        let n = names();
        let mut sorted = n.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), n.len(), "duplicate kind in {n:?}");
        assert_eq!(
            n,
            [
                "quasistatic",
                "constant-rate",
                "collision",
                "force-driven",
                "pulse",
                "shpb",
                "chain"
            ]
        );
        assert_eq!(names_and_help(), SCENE_KINDS.to_vec());
        assert_eq!(allowed(), n.join(", "));
        for k in KINDS {
            assert_eq!(find(k.name).map(|f| f.help), Some(k.help));
        }
        assert!(find("teleport").is_none());
    }

    #[test]
    fn kind_errors_list_every_registered_kind() {
        let all =
            "allowed: quasistatic, constant-rate, collision, force-driven, pulse, shpb, chain";
        let base = Path::new(".");
        for (text, problem) in [
            (
                "kind = \"teleport\"\n",
                "s.toml: `kind`: unknown scene kind `teleport`; ",
            ),
            ("max_displacement_m = 1e-4\n", "s.toml: `kind`: missing; "),
            ("kind = 3\n", "s.toml: `kind`: not a string; "),
        ] {
            let e = Params::from_toml(text, "s.toml", base)
                .unwrap_err()
                .to_string();
            assert_eq!(e, format!("{problem}{all}"));
            for name in names() {
                assert!(e.contains(name), "{e} lacks {name}");
            }
        }
        // The preset is checked before the kind's name, as it always was.
        let e = Params::from_toml("kind = \"teleport\"\nfidelity = \"slow\"", "s.toml", base)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "s.toml: `fidelity`: unknown preset `slow`; allowed: fast, standard, reference"
        );
    }

    #[test]
    fn help_and_readme_show_every_kind() {
        let help = help_text();
        let table = readme_table();
        for k in KINDS {
            assert!(
                help.contains(&format!("  {:<15}", k.name)),
                "help lacks {}",
                k.name
            );
            assert!(help.contains(k.keys[0].key));
            assert!(
                table.contains(&format!("| `{}` |", k.name)),
                "table lacks {}",
                k.name
            );
            for line in k.example.lines() {
                assert!(table.contains(&format!("`{line}`")), "table lacks {line}");
            }
        }
        for line in help.lines() {
            assert!(line.chars().count() <= 90, "help line too long: {line}");
        }
        // Header, separator and one row per kind.
        assert_eq!(
            table.lines().take_while(|l| l.starts_with('|')).count(),
            KINDS.len() + 2
        );
        let keys = readme_keys();
        for k in KINDS.iter().flat_map(|k| k.keys).chain(COMMON_KEYS) {
            assert!(keys.contains(&format!("| `{}` |", k.key)));
        }
    }

    /// Once the README carries the generated table, it must stay the generated one.
    #[test]
    fn readme_table_is_current() {
        let readme = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md");
        let Ok(text) = std::fs::read_to_string(readme) else {
            return;
        };
        let table = readme_table();
        let header = table.lines().next().unwrap();
        if text.contains(header) {
            assert!(
                text.contains(&table),
                "README.md's scene-kind table is stale; paste kinds::readme_table():\n{table}"
            );
        }
    }

    #[test]
    fn shared_key_docs_match_the_parsers() {
        for (name, _) in LawKind::ALL {
            assert!(LAW.meaning.contains(name), "law doc lacks {name}");
        }
        for f in Fidelity::ALL {
            assert!(COMMON_KEYS[1].meaning.contains(f.name()));
        }
        assert_eq!(COMMON_KEYS[1].default, Fidelity::default().name());
        assert_eq!(OUTPUT_EVERY.default, one().to_string());
    }
}
