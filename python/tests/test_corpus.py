"""The shared bad-input corpus from Python: every ``[[case]]`` of ``tests/corpus/bad/cases/*.toml``
with a ``python`` statement runs it in a fresh temporary working directory (its ``files`` made
there first) and must raise ``python_raises`` (the class or one of its bases) with a message
containing ``python_message`` (default: the case's ``stderr`` fragment, the command line's
message). The format is in ``tests/corpus/bad/README.md``; ``crates/cli/tests/bad_corpus.rs``
runs the same cases' command lines and validates the files in full. ``SHPB_CORPUS_FILE=<area>``
runs only ``cases/<area>.toml``."""

import os
import pathlib
import tomllib

import pytest

import shpb

ROOT = pathlib.Path(__file__).resolve().parents[2]
CASES_DIR = ROOT / "tests/corpus/bad/cases"
KEYS = {
    "name", "category", "args", "exit", "stderr", "stdout", "stdout_empty", "files", "env",
    "tmp_empty_after", "python", "python_raises", "python_message",
}


def _load():
    """(area, case) for every case of every case file, and the problems found in the files."""
    cases, problems, seen = [], [], {}
    for path in sorted(CASES_DIR.glob("*.toml")):
        area = path.stem
        try:
            doc = tomllib.loads(path.read_text(encoding="utf-8"))
        except (OSError, tomllib.TOMLDecodeError) as e:
            problems.append(f"{path.name}: {e}")
            continue
        for i, case in enumerate(doc.get("case", [])):
            name = case.get("name", f"#{i + 1}")
            unknown = set(case) - KEYS
            if unknown:
                problems.append(f"{path.name} `{name}`: unknown keys {sorted(unknown)}")
            if name in seen:
                problems.append(f"{path.name}: duplicate case name `{name}` (also in {seen[name]})")
            seen[name] = path.name
            if ("python" in case) != ("python_raises" in case):
                problems.append(f"{path.name} `{name}`: `python` and `python_raises` go together")
            cases.append((area, case))
    return cases, problems


ALL_CASES, PROBLEMS = _load()
ONLY = os.environ.get("SHPB_CORPUS_FILE")
PYTHON_CASES = [
    (area, c) for area, c in ALL_CASES if "python" in c and (ONLY is None or area == ONLY)
]


def substitute(text: str, tmp: pathlib.Path, nonutf8: str) -> str:
    """``{corpus}``, ``{data}``, ``{repo}``, ``{tmp}`` as paths; ``{nonutf8}`` as ``nonutf8``."""
    repo = ROOT.resolve()
    return (
        text.replace("{corpus}", str(repo / "tests/corpus/bad"))
        .replace("{data}", str(repo / "tests/data"))
        .replace("{repo}", str(repo))
        .replace("{tmp}", str(tmp))
        .replace("{nonutf8}", nonutf8)
    )


# `{nonutf8}` in a `python` statement: the escapes a string literal turns into the
# surrogate-escaped bytes b"\xff\xfe" (what os.fsdecode gives for them), so the path handed to
# shpb is not valid UTF-8 on disk.
NONUTF8_LITERAL = "\\udcff\\udcfe"
NONUTF8_NAME = os.fsdecode(b"\xff\xfe")


def make_files(case, tmp: pathlib.Path):
    """Makes the case's ``files`` in ``tmp``; returns every path made, relative to it."""
    made = set()
    for name, text in case.get("files", {}).items():
        rel = pathlib.Path(substitute(name, tmp, NONUTF8_NAME))
        made.update(p for p in rel.parents if str(p) != ".")
        made.add(rel)
        path = tmp / rel
        if name.endswith("/"):
            path.mkdir(parents=True, exist_ok=True)
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(os.fsencode(substitute(text, tmp, NONUTF8_NAME)))
    return made


def test_the_case_files_are_well_formed():
    assert not PROBLEMS, "\n".join(PROBLEMS)
    assert CASES_DIR.is_dir()


@pytest.mark.parametrize(
    "area,case", PYTHON_CASES, ids=[c["name"] for _, c in PYTHON_CASES]
)
def test_a_corpus_case_raises_what_it_expects_from_python(area, case, tmp_path, monkeypatch):
    tmp = tmp_path.resolve()
    made = make_files(case, tmp)
    monkeypatch.chdir(tmp)
    code = substitute(case["python"], tmp, NONUTF8_LITERAL)
    expected = case["python_raises"]
    try:
        exec(compile(code, f"<{area}.toml {case['name']}>", "exec"), {"shpb": shpb})
    except BaseException as e:  # noqa: BLE001 - the case names the class expected
        names = [c.__name__ for c in type(e).__mro__]
        if expected not in names:
            raise AssertionError(
                f"{case['name']}: {code!r} raised {type(e).__name__} ({e}), expected {expected}"
            ) from e
        fragment = case.get("python_message", case.get("stderr"))
        if fragment is not None:
            assert fragment in str(e), f"{case['name']}: `{fragment}` not in {str(e)!r}"
    else:
        raise AssertionError(f"{case['name']}: {code!r} raised nothing, expected {expected}")
    if case.get("tmp_empty_after"):
        left = {p.relative_to(tmp) for p in tmp.rglob("*")} - made
        assert not left, f"{case['name']}: left in {{tmp}}: {sorted(map(str, left))}"
