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


def test_ctrl_c_on_a_cluster_stops_promptly_and_keeps_finished_shards(client):
    # 1000 runs (about 15 ms each) in 100 shards on two workers: Ctrl-C after 1.5 s is seen
    # within a fraction of a second (the gather is polled every 20 ms, not blocked until a shard
    # ends), the unfinished shards are cancelled and the rows of the finished ones come back as
    # e.table, each the same run as made locally.
    import _thread
    import threading
    import time

    axes = {"pressure": "8psi:12psi:1000"}
    timer = threading.Timer(1.5, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt) as info:
        shpb.sweep(SCENE, axes, client=client, shards=100)
    waited = time.monotonic() - start - 1.5
    timer.cancel()
    assert waited < 0.5, f"KeyboardInterrupt {waited:.2f} s after Ctrl-C"
    e = info.value
    finished = getattr(e, "finished", 0)
    assert 0 <= finished < 1000
    if finished:
        assert len(e.table) == finished
        p = list(e.table.inputs["pressure"][:3])
        local = shpb.sweep(SCENE, {"pressure": ",".join(f"{float(x)!r}Pa" for x in p)})
        assert np.allclose(local["peak_force"], e.table["peak_force"][:3], rtol=1e-9, atol=0)
