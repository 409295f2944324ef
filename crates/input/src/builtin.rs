//! The built-in set-ups: the authors' bars and gauges (`bars/` of the repository), compiled into
//! the program so that `bars = "authors"` and `--bars authors` work from any directory, as the
//! built-in materials do (`specimens/`, [`crate::material::BUILTIN_MATERIALS`]).

/// Built-in bar set-ups: (name, TOML text). Their `gauges` key names a [`GAUGES`] entry.
pub const SETUPS: &[(&str, &str, &str)] = &[
    (
        "authors",
        include_str!("../../../bars/authors.toml"),
        "the authors' bars (Burgoyne & Daraio 2014): 10 cm striker, copper shaper, 19.05 mm maraging-steel bars",
    ),
    (
        "authors-20cm-striker",
        include_str!("../../../bars/authors-20cm-striker.toml"),
        "the authors' bars with a 20 cm striker and no shaper (how the Fig. 4 SS440c 10 and 12.5 psi tests were shot)",
    ),
];

/// Built-in gauge files: (file name as a set-up names it, TOML text).
pub const GAUGES: &[(&str, &str)] = &[(
    "gauges-authors.toml",
    include_str!("../../../bars/gauges-authors.toml"),
)];

/// The text of the built-in set-up `name` (also accepted: `bars/<name>.toml`, `<name>.toml`, as
/// the repository's copies are written in scenes).
pub fn setup(name: &str) -> Option<&'static str> {
    SETUPS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(n, t, _)| crate::files::builtin(n, t))
}

/// The text of the built-in gauge file `name`.
pub fn gauges(name: &str) -> Option<&'static str> {
    GAUGES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, t)| crate::files::builtin(n, t))
}

/// The built-in set-up names joined for messages.
pub fn setup_names() -> String {
    SETUPS
        .iter()
        .map(|(n, _, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::*;
    use shpb_core::apparatus::Apparatus;
    use std::path::Path;

    #[test]
    fn every_builtin_setup_parses_and_equals_its_repository_file() {
        let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bars");
        for (name, _, _) in SETUPS {
            let built_in = Apparatus::resolve(name, Path::new("/nonexistent")).unwrap();
            let file = Apparatus::from_file(&repo.join(format!("{name}.toml"))).unwrap();
            assert_eq!(built_in.gauges, file.gauges, "{name}");
            assert_eq!(built_in.gun, file.gun, "{name}");
            assert_eq!(built_in.striker, file.striker, "{name}");
            assert_eq!(built_in.shaper, file.shaper, "{name}");
        }
    }
}
