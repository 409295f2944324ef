"""`shpb.fit` (issue 44) gives the answer of `shpb fit --json`: the same parameters, sampler
statistics and records for the same seed, whatever the thread count; bad input raises
`InputError` (a ValueError) naming the key or argument; the output files are the command's and
are refused when they exist, unless `force`; Ctrl-C raises KeyboardInterrupt with the fit of the
steps done.

Fast: the force-driven Fig. 4 scene (≈ 10 ms a run), two free keys, 4 walkers × 40 steps."""

import json
import signal
import subprocess
import sys
import textwrap
import time

import h5py
import numpy as np
import pytest

import shpb

from conftest import ROOT

SCENE = "scenes/force-driven-ss440c-10psi.toml"
FREE = {"specimen.yield_stress_pa": (1.2e9, 2.6e9), "specimen.jc_c": (0, 0.1)}
FREE_FLAGS = ["--free", "specimen.yield_stress_pa=1.2e9:2.6e9", "--free", "specimen.jc_c=0:0.1"]
WALKERS, STEPS, SEED = 4, 40, 3


def without_run_details(j):
    """The JSON of a fit without what differs between two calls of the same fit: the command
    line that asked for it and the seconds it took."""
    return {k: v for k, v in j.items() if k not in ("command_line", "seconds")}


@pytest.fixture(scope="module")
def two_threads():
    return shpb.fit(SCENE, FREE, walkers=WALKERS, steps=STEPS, seed=SEED, jobs=2)


def test_fit_equals_the_command(two_threads, cli):
    out = json.loads(
        cli(
            "fit", SCENE, *FREE_FLAGS, "--walkers", WALKERS, "--steps", STEPS,
            "--seed", SEED, "-j", "2", "--json",
        ).stdout
    )
    # Exactly: the same library calls with the same seed (one forward model, one sampler).
    assert two_threads.parameters == out["parameters"]
    assert without_run_details(two_threads.to_json()) == without_run_details(out)
    assert two_threads.keys == list(FREE)
    assert two_threads.warnings == out["warnings"]


def test_the_fit_does_not_depend_on_the_thread_count_nor_on_how_bounds_are_written(two_threads):
    # The sampler draws every random number on one thread; the runs of a step are only
    # evaluated in parallel, each a deterministic function of its point. The bounds as `--free`
    # texts, one with its unit, are the same numbers as the dict's (1200 MPa = 1.2e9 Pa exactly).
    one = shpb.fit(
        SCENE,
        ["specimen.yield_stress_pa=1200MPa:2600MPa", "specimen.jc_c=0:0.1"],
        walkers=WALKERS, steps=STEPS, seed=SEED, jobs=1,
    )
    assert without_run_details(one.to_json()) == without_run_details(two_threads.to_json())
    assert np.array_equal(one.chain, two_threads.chain)
    assert np.array_equal(one.log_prob, two_threads.log_prob)


def test_arrays_have_the_fit_file_layout(two_threads):
    f, p = two_threads, len(FREE)
    j = f.to_json()
    burn = j["burn_in"]
    assert burn == STEPS // 4 and f.burn_in == burn
    assert f.chain.shape == (STEPS, WALKERS, p)
    assert f.log_prob.shape == (STEPS, WALKERS)
    # The samples are the chain after the burn-in, step by step.
    assert np.array_equal(f.samples, f.chain[burn:].reshape(-1, p))
    assert f.correlations.shape == (p, p)
    assert np.allclose(np.diag(f.correlations), 1.0)
    assert np.allclose(f.correlations, f.correlations.T)
    # Pearson's r of the samples, computed here by numpy (a code of its own).
    assert np.allclose(f.correlations, np.corrcoef(f.samples.T), rtol=0, atol=1e-9)
    for i, key in enumerate(f.keys):
        q = f.parameters[key]
        lo, hi = FREE[key]
        assert lo <= q["band_90"][0] <= q["median"] <= q["band_90"][1] <= hi, key
        assert lo <= q["value"] <= hi, key
        assert q["unit"] == ("Pa" if key.endswith("_pa") else "1")
        assert np.all((f.samples[:, i] >= lo) & (f.samples[:, i] <= hi)), key
    assert np.all(np.isfinite(f.log_prob[burn:]))
    (rec,) = f.records
    assert rec["name"] == "the scene's own record"
    n = len(rec["x"])
    assert n == j["records"][0]["points"] > 10
    for k in ["y", "best", "band_low", "band_high"]:
        assert isinstance(rec[k], np.ndarray) and rec[k].shape == (n,), k
    assert np.all(rec["band_low"] <= rec["band_high"])
    assert rec["noise_sd"] == j["records"][0]["noise_sd"] > 0
    # The best fit follows the record to within its noise: the mean square residual is the
    # noise model's variance (it is estimated from these residuals).
    assert np.sqrt(np.mean((rec["y"] - rec["best"]) ** 2)) < 3 * rec["noise_sd"]


@pytest.mark.parametrize(
    "kwargs, error, names",
    [
        (dict(free={"specimen.no_such_key": (0, 1)}), shpb.InputError, "no_such_key"),
        (dict(free={"specimen.jc_c": (0.1, 0)}), shpb.InputError, "--free specimen.jc_c"),
        (dict(free={"specimen.jc_c": (0, 1, 2)}), shpb.InputError, "free specimen.jc_c"),
        (dict(free={"specimen.jc_c": (0, None)}), shpb.InputError, "free specimen.jc_c"),
        (dict(free={}), shpb.InputError, "free"),
        (dict(prior={"specimen.yield_stress_pa": ("normal", 2e9, 1e8)}), shpb.InputError,
         "specimen.yield_stress_pa"),
        (dict(prior={"specimen.jc_c": ("normal", 0.05, -1)}), shpb.InputError,
         "--prior specimen.jc_c"),
        (dict(walkers=3), shpb.InputError, "--walkers"),
        (dict(steps=2), shpb.InputError, "--steps"),
        (dict(steps=8, burn_in=8), shpb.InputError, "--burn-in"),
        (dict(steps=2.5), shpb.InputError, "steps"),
        (dict(residual="energy"), shpb.InputError, "--residual"),
        (dict(record="no-such-record.csv"), FileNotFoundError, "no-such-record.csv"),
        (dict(scene="no-such-scene.toml"), FileNotFoundError, "no-such-scene.toml"),
        (dict(scene={"kind": "force-driven"}), TypeError, "scene"),
    ],
)
def test_bad_input_names_the_key_or_argument(kwargs, error, names):
    args = dict(scene=SCENE, free={"specimen.jc_c": (0, 0.1)}, walkers=4, steps=4, jobs=1)
    args.update(kwargs)
    scene = args.pop("scene")
    free = args.pop("free")
    with pytest.raises(error) as e:
        shpb.fit(scene, free, **args)
    assert names in str(e.value)
    if error is shpb.InputError:
        assert isinstance(e.value, ValueError)


def test_outputs_are_written_and_refused_without_force(tmp_path):
    out, plot, corner = tmp_path / "fit.h5", tmp_path / "fit.png", tmp_path / "corner.png"
    small = dict(walkers=4, steps=8, seed=SEED, jobs=2)
    f = shpb.fit(SCENE, {"specimen.jc_c": (0, 0.1)}, output=out, plot=plot, corner=corner, **small)
    for p in (plot, corner):
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", p
    with h5py.File(out, "r") as h:
        g = h["fit/parameters/specimen.jc_c"]
        q = f.parameters["specimen.jc_c"]
        assert g.attrs["value"] == q["value"] and g.attrs["median"] == q["median"]
        assert [g.attrs["band_90_low"], g.attrs["band_90_high"]] == q["band_90"]
        assert np.array_equal(h["fit/chain"][()], f.chain)
        assert np.array_equal(h["fit/samples"][()], f.samples)
        assert np.array_equal(h["fit/records/0/best"][()], f.records[0]["best"])
    before = {p: p.stat().st_mtime_ns for p in (out, plot, corner)}
    # Each existing output is refused before the fit runs, naming the file.
    for name, path in [("output", out), ("plot", plot), ("corner", corner)]:
        with pytest.raises(shpb.InputError, match=f"{path.name}: output file exists"):
            shpb.fit(SCENE, {"specimen.jc_c": (0, 0.1)}, **{name: path}, **small)
    assert {p: p.stat().st_mtime_ns for p in before} == before
    # The fit file is HDF5: another extension is refused, naming the argument.
    with pytest.raises(shpb.InputError, match="output.*h5"):
        shpb.fit(SCENE, {"specimen.jc_c": (0, 0.1)}, output=tmp_path / "x.png", **small)
    g = shpb.fit(SCENE, {"specimen.jc_c": (0, 0.1)}, output=out, force=True, **small)
    with h5py.File(out, "r") as h:
        assert np.array_equal(h["fit/chain"][()], g.chain)
    # Fit.save writes the same file; refuses an existing one without force.
    again = tmp_path / "again.h5"
    g.save(again)
    with pytest.raises(shpb.InputError, match="exists"):
        g.save(again)
    with h5py.File(again, "r") as a, h5py.File(out, "r") as b:
        assert np.array_equal(a["fit/samples"][()], b["fit/samples"][()])


CHILD = textwrap.dedent(
    """
    import shpb, sys
    print("started", flush=True)
    try:
        shpb.fit({scene!r}, {{"specimen.jc_c": (0, 0.1)}}, walkers=4, steps=100000, jobs=1)
        print("finished without interruption", flush=True)
    except KeyboardInterrupt as e:
        f = e.fit
        print("interrupted", f.chain.shape[0], f.warnings[0], flush=True)
        sys.exit(7)
    """
).format(scene=SCENE)


def test_ctrl_c_stops_between_sampler_steps_and_keeps_the_fit():
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD], cwd=ROOT, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True,
    )
    assert child.stdout.readline().strip() == "started"
    # During the least squares (≈ 160 runs of ≈ 10 ms, run to their end) or the sampler: the
    # sampler stops after its step, the predictive band is drawn from the steps done.
    time.sleep(2.0)
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=120)
    assert child.returncode == 7, (out, err)
    words = out.split(maxsplit=2)
    assert words[0] == "interrupted"
    assert 1 <= int(words[1]) < 100000
    assert "interrupted after" in words[2]
