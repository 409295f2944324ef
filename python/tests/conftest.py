"""Fixtures of the shpb Python suite: the repository root (the tests run from it, as the scenes'
relative paths expect) and the `shpb` binary the package is compared with."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def shpb_binary() -> pathlib.Path:
    env = os.environ.get("SHPB_BIN")
    if env:
        return pathlib.Path(env)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "release" / "shpb"


@pytest.fixture(scope="session")
def shpb_bin() -> pathlib.Path:
    b = shpb_binary()
    if not b.is_file():
        pytest.fail(f"{b} not found: build it with `cargo build --release -p shpb` (or set SHPB_BIN)")
    return b


@pytest.fixture(autouse=True)
def at_root(monkeypatch):
    monkeypatch.chdir(ROOT)


@pytest.fixture
def cli(shpb_bin):
    """Runs `shpb ARGS` from the repository root; returns the CompletedProcess."""

    def call(*args, check=True):
        p = subprocess.run(
            [str(shpb_bin), "--quiet", *map(str, args)], cwd=ROOT, capture_output=True, text=True
        )
        if check and p.returncode != 0:
            raise AssertionError(f"shpb {' '.join(map(str, args))} failed: {p.stderr}")
        return p

    return call
