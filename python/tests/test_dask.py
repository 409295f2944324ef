"""`shpb.sweep(client=...)` on a Dask cluster gives the table of `shpb sweep -j 2` (issue 21)."""

import json

import numpy as np
import pytest

import shpb

import distributed  # noqa: E402  (installed by `make venv`; `pip install shpb[dask]`)

SCENE = "scenes/shpb-ss440c-10psi.toml"
# Two axes (one a name, so a non-numeric input column) and a count of runs (6) that three shards
# do not divide evenly in the order they are run.
SET = {"pressure": "8psi:10psi:3", "specimen.pair": ["ss440c", "ss302"]}
CLI_SET = ["--set", "pressure=8psi:10psi:3", "--set", "specimen.pair=ss440c,ss302"]


@pytest.fixture(scope="module")
def client():
    # Two worker processes, one thread each: the runs really leave this process.
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as c:
        yield c


def test_local_cluster_equals_cli_sweep_with_two_jobs(client, cli):
    table = shpb.sweep(SCENE, SET, client=client)
    out = json.loads(cli("sweep", SCENE, *CLI_SET, "-j", "2", "--json").stdout)
    runs = sorted(out["runs"], key=lambda r: r["run"])
    assert len(table) == len(runs) == 6
    for name in table.keys():
        expected = np.array([r["results"][name]["value"] for r in runs])
        # Bit for bit: the same runs, only executed elsewhere.
        assert np.array_equal(table[name], expected), name
        assert table.units[name] == runs[0]["results"][name]["unit"]
    assert table.labels["specimen.pair"] == [r["inputs"]["specimen.pair"] for r in runs]
    assert np.array_equal(
        table.inputs["pressure"], [r["inputs"]["pressure"]["value"] for r in runs]
    )
    assert table.units["pressure"] == "Pa"


@pytest.mark.parametrize("shards", [1, 3, 8])
def test_any_number_of_shards_gives_the_local_table(client, shards):
    local = shpb.sweep(SCENE, SET, jobs=2)
    table = shpb.sweep(SCENE, SET, client=client, shards=shards)
    assert table.keys() == local.keys()
    for name in local.keys():
        assert np.array_equal(table[name], local[name]), (shards, name)
    assert table.labels == local.labels


def test_bad_shard_count_is_an_input_error(client):
    with pytest.raises(shpb.InputError, match="shards"):
        shpb.sweep(SCENE, SET, client=client, shards=0)


def test_rows_of_one_shard_alone_are_refused():
    keys, rows = shpb._shpb.sweep_runs(SCENE, CLI_SET[1::2], 1, (1, 2))
    with pytest.raises(shpb.InputError, match="exactly once"):
        shpb._shpb.sweep_table(keys, rows)
