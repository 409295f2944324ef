#!/usr/bin/env python3
"""Accuracy of the `reference` preset against finer runs of its own bar theory (issue 20).

Runs the SS440c 10 psi test (scenes/shpb-ss440c-10psi.toml) on ladders of bar cells:
  * `pochhammer-chree` delay lines (today's `reference`: 1 mm) down to 1/64 mm,
  * elementary delay lines (`none`, the bars of `standard`) down to 1/64 mm: the same joints on
    bars whose transport is exact, so what remains at 1 mm is the joints' step
    (validation/perf/REPORT.md, issue-20 table),
  * the `love-rod` finite-difference chain (the `reference` before it: 0.125 mm) down to 1/64 mm,
each under the default `dynamic` unloading, and the `pochhammer-chree` and `love-rod` ladders again
under `dynamic-continuous` (where the signals converge: like against like for the old and the new
`reference`); then compares every run with the finest run of its ladder and every run with
the next finer one (docs/physics.md §3, "A continuous turn"; validation/perf/REPORT.md).
Last, under each unloading, the old and the new `reference` and `standard` against one converged
solution, the finest `pochhammer-chree` run (the first mode of the elastic cylinder, exact
dispersion): the accuracy a user gets, model error and discretisation together.

Metrics, each relative: peak contact force and the approach at it (parabola through the three
samples around the largest force before the largest approach), and the RMS differences of the transmission-gauge strain, the
incident-gauge strain and the contact force over the run, each over its series' largest magnitude
(signals interpolated linearly onto the finer run's samples).

Usage: reference_accuracy.py [--shpb target/release/shpb] [--out validation/perf/reference-accuracy.txt]
Needs numpy and h5py; about 10 minutes on two cores (the 1/64 mm Love-rod chain takes most of it).
"""

import argparse
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
LADDER_MM = [1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125, 0.015625]
LADDERS = [
    ("pochhammer-chree", "dynamic", LADDER_MM),
    ("none", "dynamic", LADDER_MM),
    ("love-rod", "dynamic", LADDER_MM[3:]),
    ("pochhammer-chree", "dynamic-continuous", LADDER_MM),
    ("love-rod", "dynamic-continuous", LADDER_MM[3:]),
]


# The presets compared with the converged solution: (label, dispersion, cell in mm).
CROSS = [
    ("reference (pochhammer-chree, 1 mm)", "pochhammer-chree", 1.0),
    ("old reference (love-rod, 0.125 mm)", "love-rod", 0.125),
    ("standard (none, 1 mm)", "none", 1.0),
]


def run(shpb, work, dispersion, unloading, cell_mm, env=None):
    """Runs one rung (with the environment `env`, default this process's); returns its series."""
    name = f"{dispersion}-{unloading}-{cell_mm}"
    scene = os.path.join(work, name + ".toml")
    out = os.path.join(work, name + ".h5")
    with open(scene, "w") as f:
        f.write(
            f'kind = "shpb"\nbars = "{ROOT}/bars/authors.toml"\npressure = "10psi"\n'
            f'law = "burgoyne-daraio"\nunloading = "{unloading}"\ndispersion = "{dispersion}"\n'
            f"cell_size_m = {cell_mm * 1e-3!r}\n[specimen]\npair = \"ss440c\"\n"
        )
    subprocess.run([shpb, "run", scene, "-o", out, "--force", "-q"], check=True, env=env)
    with h5py.File(out) as h:
        return {
            "t": h["time"][:],
            "trans": h["gauges/transmission/strain"][:],
            "inc": h["gauges/incident/strain"][:],
            "tc": h["contact/time"][:],
            "force": h["contact/force"][:],
            "delta": h["contact/displacement"][:],
        }


def peak(r):
    """Peak force of the loading and approach at it, by a parabola through the three samples
    around it. The loading ends at the largest approach: under the `dynamic` unloading the force
    jumps back to the largest one reached there, which must not be taken for the peak."""
    f, d = r["force"], r["delta"]
    k = int(np.argmax(f[: int(np.argmax(d)) + 1]))
    k = min(max(k, 1), len(f) - 2)
    a, b, c = f[k - 1], f[k], f[k + 1]
    denom = a - 2 * b + c
    s = 0.5 * (a - c) / denom if denom != 0 else 0.0
    fp = b - 0.25 * (a - c) * s
    dp = d[k] + s * 0.5 * (d[k + 1] - d[k - 1]) + 0.5 * s * s * (d[k + 1] - 2 * d[k] + d[k - 1])
    return fp, dp


def rms(x_t, x, y_t, y):
    """RMS of x − y on y's samples (x interpolated), over max |y|."""
    xi = np.interp(y_t, x_t, x)
    return float(np.sqrt(np.mean((xi - y) ** 2)) / np.max(np.abs(y)))


def compare(a, b):
    pa, pb = peak(a), peak(b)
    return (
        abs(pa[0] / pb[0] - 1),
        abs(pa[1] / pb[1] - 1),
        rms(a["t"], a["trans"], b["t"], b["trans"]),
        rms(a["t"], a["inc"], b["t"], b["inc"]),
        rms(a["tc"], a["force"], b["tc"], b["force"]),
    )


HEADER = "    cell_mm      peak     delta     trans       inc     force"


def row(cell_mm, metrics):
    """One line of a ladder's table: the cell and the metrics of `compare`."""
    return f"  {cell_mm:9.6f} " + " ".join(f"{x:9.2e}" for x in metrics)


def write(path, lines):
    """Writes the report's lines to `path` and echoes them."""
    text = "\n".join(lines) + "\n"
    with open(path, "w") as f:
        f.write(text)
    sys.stdout.write(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--shpb", default=os.path.join(ROOT, "target", "release", "shpb"))
    ap.add_argument("--out", default=os.path.join(ROOT, "validation", "perf", "reference-accuracy.txt"))
    args = ap.parse_args()
    lines = [
        "Accuracy of the reference preset against finer runs of its own bar theory",
        "(generated by validation/perf/reference_accuracy.py; SS440c 10 psi, scenes/shpb-ss440c-10psi.toml)",
        "columns: relative peak force, approach at peak, RMS of the transmission gauge, the incident gauge",
        "and the contact force (each over its series' largest magnitude)",
    ]
    kept = {}
    with tempfile.TemporaryDirectory() as work:
        for dispersion, unloading, ladder in LADDERS:
            runs = {}
            for cell in ladder:
                print(f"{dispersion} {unloading} {cell} mm", file=sys.stderr, flush=True)
                runs[cell] = run(args.shpb, work, dispersion, unloading, cell)
            finest = ladder[-1]
            lines.append("")
            lines.append(f"{dispersion}, unloading = {unloading}")
            lines.append(f"  against the finest run ({finest} mm):")
            lines.append(HEADER)
            for cell in ladder[:-1]:
                lines.append(row(cell, compare(runs[cell], runs[finest])))
            lines.append("  each run against the next finer one:")
            for a, b in zip(ladder[:-1], ladder[1:]):
                lines.append(row(a, compare(runs[a], runs[b])))
            # Only the runs the cross table reads: the converged one and the presets'.
            needed = {ladder[-1]} | {cell for _, d, cell in CROSS if d == dispersion}
            kept[(dispersion, unloading)] = {c: runs[c] for c in needed if c in runs}
        for unloading in dict.fromkeys(u for _, u, _ in LADDERS):
            converged = kept[("pochhammer-chree", unloading)][LADDER_MM[-1]]
            lines.append("")
            lines.append(
                f"against the converged solution (pochhammer-chree at {LADDER_MM[-1]} mm), "
                f"unloading = {unloading}:"
            )
            lines.append("  preset                                " + HEADER.strip())
            for label, dispersion, cell in CROSS:
                if (dispersion, unloading) in kept:
                    r = kept[(dispersion, unloading)][cell]
                    lines.append(f"  {label:<36}" + row(cell, compare(r, converged)))
    write(args.out, lines)


if __name__ == "__main__":
    main()
