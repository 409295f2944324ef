"""Issue 42, categories 7 and 8 on the Python side: Ctrl-C during `shpb.sweep` / `shpb.study`
raises KeyboardInterrupt promptly (the main thread looks for it every 20 ms while the runs go
on in worker threads; a bar run stops at its next 1 %) and keeps the rows finished before it on
the exception (`e.table`, a `shpb.Table` in sweep order; `e.finished`, their count); a missing
scene is a FileNotFoundError, as python/README promises."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import shpb

from conftest import ROOT

SCENE = "scenes/shpb-ss440c-10psi.toml"

CHILD = textwrap.dedent(
    """
    import sys, time, shpb
    what = sys.argv[1]
    print("started", flush=True)
    try:
        if what == "sweep":
            shpb.sweep({scene!r}, set={{"pressure": "8psi:14psi:400", "fidelity": ["fast"]}})
        else:
            shpb.study({scene!r}, samples=400, fidelity="fast")
        print("finished without interruption", flush=True)
    except KeyboardInterrupt as e:
        t = e.table
        print("interrupted", e.finished, len(t), list(t.keys())[:1], flush=True)
        if what == "sweep":
            # The rows kept are runs of the sweep's points, in order.
            p = list(t.inputs["pressure"])
            assert p == sorted(p), p
        sys.exit(7)
    """
).format(scene=SCENE)


def one_run_seconds() -> float:
    t = time.monotonic()
    shpb.run(SCENE, fidelity="fast")
    return time.monotonic() - t


@pytest.mark.parametrize("what", ["sweep", "study"])
def test_ctrl_c_raises_promptly_and_keeps_the_finished_rows(what):
    run = one_run_seconds()
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, what],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert child.stdout.readline().strip() == "started"
    # Long enough for a few runs to finish (400 runs take 400 times as long, so the job is
    # still going on a fast machine).
    time.sleep(max(1.0, 4 * run))
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=60)
    waited = time.monotonic() - sent
    assert child.returncode == 7, (out, err)
    words = out.split()
    assert words[0] == "interrupted", out
    finished, rows = int(words[1]), int(words[2])
    assert finished == rows and 1 <= rows < 400, out
    # Promptly: within one run (a bar run stops at its next 1 % of steps) and 1 s of slack.
    assert waited < run + 1.0, f"KeyboardInterrupt {waited:.2f} s after SIGINT (a run takes {run:.2f} s)"


@pytest.mark.parametrize("call", [
    lambda p: shpb.sweep(p, set={"pressure": ["8psi"]}),
    lambda p: shpb.study(p, samples=4),
])
def test_a_missing_scene_is_file_not_found(call, tmp_path):
    missing = tmp_path / "no-such-scene.toml"
    with pytest.raises(FileNotFoundError) as e:
        call(missing)
    assert "no such file" in str(e.value)
    assert e.value.errno == 2
