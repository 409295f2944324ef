//! The bad-input corpus (`tests/corpus/bad/`, one scene per defect, its first line
//! `# expect: EXIT | FRAGMENT`): `shpb run` refuses each with that exit code and a one-line
//! message containing the fragment, before anything runs (nothing on stdout). The Python suite
//! runs the same corpus through `shpb.run`.

mod common;

use common::{repo, shpb, stderr, stdout};
use tempfile::TempDir;

#[test]
fn every_scene_of_the_bad_input_corpus_is_refused_as_it_expects() {
    let corpus = repo().join("tests/corpus/bad");
    let dir = TempDir::new().unwrap();
    let mut checked = 0;
    for entry in std::fs::read_dir(&corpus).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let expect = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{}: no `# expect:` line", path.display()));
        let (code, fragment) = expect.split_once(" | ").expect("EXIT | FRAGMENT");
        let out = shpb(dir.path(), &["run", path.to_str().unwrap()]);
        assert_eq!(
            out.status.code(),
            Some(code.parse().unwrap()),
            "{}: {}",
            path.display(),
            stderr(&out)
        );
        let err = stderr(&out);
        assert!(
            err.starts_with("shpb: error: "),
            "{}: {err}",
            path.display()
        );
        assert!(
            err.contains(fragment),
            "{}: `{fragment}` not in {err}",
            path.display()
        );
        assert!(stdout(&out).is_empty(), "{}: ran", path.display());
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} corpus scenes");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "wrote a file"
    );
}
