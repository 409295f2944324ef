"""Benchmark (not a test): the Python call overhead of `shpb.run` on a `fast` full test,
against the run itself. The run itself is the `shpb run` process time minus the process start
(`shpb --version`); each is the median of N repeats. Issue 16 asks for an overhead under 10 %.

    python examples/python/bench_overhead.py [N]      (from the repository root, SHPB_BIN or target/release/shpb)
"""

import os
import statistics
import subprocess
import sys
import time

import shpb

SCENE = "scenes/shpb-ss440c-10psi.toml"
N = int(sys.argv[1]) if len(sys.argv) > 1 else 20
BIN = os.environ.get("SHPB_BIN", "target/release/shpb")


def median_s(call):
    times = []
    for _ in range(N):
        t = time.perf_counter()
        call()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


python_s = median_s(lambda: shpb.run(SCENE, fidelity="fast"))
process_s = median_s(lambda: subprocess.run([BIN, "-q", "run", SCENE, "--fidelity", "fast"], check=True))
start_s = median_s(lambda: subprocess.run([BIN, "--version"], check=True, capture_output=True))
run_s = process_s - start_s
print(f"shpb.run (Python):           {1e3 * python_s:8.2f} ms")
print(f"shpb run (process):          {1e3 * process_s:8.2f} ms, of which start {1e3 * start_s:.2f} ms")
print(f"the run itself:              {1e3 * run_s:8.2f} ms")
print(f"Python overhead:             {100 * (python_s - run_s) / run_s:+8.1f} % of the run")
