"""`shpb.study` equals `shpb study`, locally and on a Dask cluster (issue 21)."""

import json

import numpy as np
import pytest

import distributed  # noqa: E402  (installed by `make venv`; `pip install shpb[dask]`)

import shpb

SCENE = "examples/study/ss440c-12p5psi.toml"  # pressure normal, shaper thickness uniform
SAMPLES, SEED = 6, 3


def stats_equal(study, quantities):
    for q in quantities:
        s = study.stats[q["quantity"]]
        assert s["unit"] == q["unit"] and s["n"] == q["n"], q["quantity"]
        for k in ["mean", "sd", "p5", "p50", "p95"]:
            # Bit for bit: the same runs and the same statistics code.
            assert s[k] == q[k] or (np.isnan(s[k]) and q[k] is None), (q["quantity"], k)
        assert s["S"] == q["first_order"], q["quantity"]


def same(a, b):
    """Equal, with NaN equal to NaN (a quantity no run produced has NaN statistics)."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b):
        return True
    return a == b


@pytest.fixture(scope="module")
def local():
    return shpb.study(SCENE, samples=SAMPLES, seed=SEED, jobs=2)


def test_study_equals_the_command(local, cli):
    out = json.loads(
        cli("study", SCENE, "--samples", SAMPLES, "--seed", SEED, "-j", "2", "--json").stdout
    )
    stats_equal(local, out["quantities"])
    assert local.inputs == out["study"]
    assert len(local.runs) == SAMPLES
    assert local.runs.units["pressure"] == "Pa"
    assert set(local.stats["peak_force"]["S"]) == {"pressure", "shaper.thickness_m"}


def test_dask_local_cluster_gives_the_same_study(local):
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        for shards in [None, 4]:
            s = shpb.study(SCENE, samples=SAMPLES, seed=SEED, client=client, shards=shards)
            assert same(s.stats, local.stats)
            for name in local.runs.keys():
                assert np.array_equal(s.runs[name], local.runs[name], equal_nan=True), name
            assert s.runs.labels == local.runs.labels


def test_rows_of_another_study_are_refused():
    rows = shpb._shpb.study_runs(SCENE, SAMPLES, SEED, 1, True, (1, 2))
    with pytest.raises(shpb.InputError, match="exactly once"):
        shpb._shpb.study_table(SCENE, SAMPLES, SEED, True, rows)


def test_fidelity_equals_the_command_and_names_the_preset(cli):
    """``fidelity=`` is ``shpb study --fidelity``: the same statistics bit for bit, on a Dask
    cluster too, and the study's description says which preset every run took; an unknown one
    is refused."""
    args = ("--samples", 4, "--seed", SEED, "--fidelity", "fast", "--json")
    out = json.loads(cli("study", SCENE, *args).stdout)
    s = shpb.study(SCENE, samples=4, seed=SEED, fidelity="fast")
    stats_equal(s, out["quantities"])
    assert s.inputs == out["study"]
    assert any("fidelity fast" in line for line in s.inputs), s.inputs
    default = shpb.study(SCENE, samples=4, seed=SEED)
    assert default.stats["peak_force"]["mean"] != s.stats["peak_force"]["mean"]
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        d = shpb.study(SCENE, samples=4, seed=SEED, fidelity="fast", client=client)
        assert same(d.stats, s.stats)
    with pytest.raises(shpb.InputError, match="fidelity"):
        shpb.study(SCENE, samples=4, seed=SEED, fidelity="quick")
