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


# Issue 45: the default number of shards is fixed by the points and the workers requested, not
# by the workers registered when the shards are submitted.


def test_the_shard_plan_is_a_function_of_points_and_workers_requested():
    plan = shpb._plan_shards
    # Four shards per worker requested while the shards hold at most 16 runs ...
    assert plan(256, 2) == 16  # ⌈256 / 16⌉ = 16 > 4 × 2
    assert plan(256, 8) == 32  # 4 × 8 = 32 > 16
    assert plan(64, 1) == 4
    # ... one per 16 runs beyond that, so a large sweep spreads over workers that arrive later.
    assert plan(100_000, 4) == 6250
    # Never more shards than runs, never fewer than one.
    assert plan(6, 2) == 6
    assert plan(1, 64) == 1
    assert plan(0, 3) == 1
    # A cluster whose workers are not there yet (0 requested) still gets ⌈points / 16⌉.
    assert plan(256, 0) == 16
    for points in range(1, 300):
        for workers in (1, 2, 3, 64):
            n = plan(points, workers)
            assert 1 <= n <= points
            # Every shard holds at most 16 runs unless 4 per worker already split finer.
            assert -(-points // n) <= max(16, -(-points // (4 * workers)))


def test_the_sweep_points_are_counted_as_shpb_sweep_expands_them():
    assert shpb._sweep_points(["pressure=8psi:10psi:3", "specimen.pair=ss440c,ss302"]) == 6
    assert shpb._sweep_points(["pressure=7psi"]) == 1
    assert shpb._sweep_points(["a=1:2:16", "b=1,2,3,4", "fidelity=fast"]) == 64


class _Cluster:
    def __init__(self, plan):
        self.plan = plan
        self.requested = set()  # launched: none yet


class _Client:
    def __init__(self, requested, registered):
        self.cluster = None if requested is None else _Cluster(requested)
        self._registered = registered

    def scheduler_info(self):
        return {"workers": {f"w{i}": {} for i in range(self._registered)}}


def test_workers_requested_count_before_they_register():
    # A SLURM cluster with 8 workers asked for and none launched or registered yet: 8, not 0.
    assert shpb._workers_requested(_Client({f"w{i}" for i in range(8)}, 0)) == 8
    # More registered than asked for (workers started by hand): those registered.
    assert shpb._workers_requested(_Client({"a"}, 3)) == 3
    # A client of a scheduler alone: the workers registered; none: 1.
    assert shpb._workers_requested(_Client(None, 3)) == 3
    assert shpb._workers_requested(_Client(None, 0)) == 1
    assert shpb._workers_requested(_Client(set(), 0)) == 1


def test_a_sweep_submitted_before_its_workers_register_runs_in_planned_shards():
    # A cluster asked for two workers that have not registered yet when the sweep is submitted:
    # the sweep is still cut into the planned shards (4 × 2 = 8 for 6 runs → 6), not into one
    # shard for the one worker or none present, and the table is the local one.
    local = shpb.sweep(SCENE, SET, jobs=1)
    with distributed.LocalCluster(
        n_workers=0, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as c:
        cluster.scale(2)
        submitted = []
        submit = c.submit

        def counting_submit(fn, *args, **kwargs):
            submitted.append(args[-2:])
            return submit(fn, *args, **kwargs)

        c.submit = counting_submit
        table = shpb.sweep(SCENE, SET, client=c)
    assert sorted(submitted) == [(k, 6) for k in range(1, 7)]
    for name in local.keys():
        assert np.array_equal(table[name], local[name]), name
