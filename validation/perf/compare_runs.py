#!/usr/bin/env python3
"""Compares two directories of run files (`shpb run SCENE -o DIR/NAME.h5`) dataset by dataset.

Usage: compare_runs.py BEFORE_DIR AFTER_DIR [--tolerance 1e-9]

Every numeric dataset of every file in BEFORE_DIR must exist in AFTER_DIR with the same shape and
differ by at most `tolerance` times the largest magnitude of the series (a scalar: of itself;
`summary/energy_balance_max_relative_error`, already a fraction of the striker's energy and itself
at rounding level, by `tolerance` in absolute terms); string datasets and attributes must be equal. Prints one line per file (datasets compared, how
many are bit-identical, the largest difference relative to its series maximum and where), then
the scalars of /summary that are not bit-identical. Exit status 1 if any dataset is missing,
differs in shape or lies beyond the tolerance. Needs numpy and h5py.
"""
import argparse
import pathlib
import sys

import h5py
import numpy as np

# Scalars that are already fractions of a scale of the run: compared in absolute terms.
ABSOLUTE = {"summary/energy_balance_max_relative_error"}


def datasets(f):
    """Every dataset of an open HDF5 file, by path."""
    out = {}
    f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--tolerance", type=float, default=1e-9)
    ap.add_argument("-v", "--verbose", action="store_true", help="list every dataset that is not bit-identical")
    a = ap.parse_args()
    failed = False
    summary_changes = []
    files = sorted(pathlib.Path(a.before).glob("*.h5"))
    if not files:
        print(f"no run files in {a.before}")
        return 1
    for path in files:
        other = pathlib.Path(a.after) / path.name
        if not other.exists():
            print(f"{path.name}: MISSING in {a.after}")
            failed = True
            continue
        with h5py.File(path, "r") as fb, h5py.File(other, "r") as fa:
            db, da = datasets(fb), datasets(fa)
            if dict(fb.attrs) != dict(fa.attrs):
                print(f"{path.name}: root attributes differ")
                failed = True
        worst, where, identical = 0.0, "", 0
        for name, x in db.items():
            if name not in da:
                print(f"{path.name}: {name} MISSING")
                failed = True
                continue
            y = da[name]
            if np.shape(x) != np.shape(y):
                print(f"{path.name}: {name} shape {np.shape(x)} vs {np.shape(y)}")
                failed = True
                continue
            x, y = np.asarray(x), np.asarray(y)
            if x.dtype.kind not in "fiu":
                if not np.array_equal(x, y):
                    print(f"{path.name}: {name} (text) differs")
                    failed = True
                else:
                    identical += 1
                continue
            if np.array_equal(x, y, equal_nan=True):
                identical += 1
                continue
            scale = 1.0 if name in ABSOLUTE else (np.nanmax(np.abs(x)) if x.size else 0.0)
            diff = np.nanmax(np.abs(x.astype(float) - y.astype(float)))
            rel = diff / scale if scale > 0 else np.inf
            if name.startswith("summary/"):
                summary_changes.append((path.name, name, float(x), float(y), rel))
            if a.verbose:
                print(f"  {path.name}: {name}: max |diff| {diff:.3e}, relative to its maximum {rel:.3e}")
            if rel > worst:
                worst, where = rel, name
            if not rel <= a.tolerance:
                failed = True
        verdict = "ok" if worst <= a.tolerance else "BEYOND TOLERANCE"
        print(f"{path.name}: {len(db)} datasets, {identical} identical, "
              f"max |diff|/max|series| = {worst:.3e} {('(' + where + ')') if where else ''} {verdict}")
    if summary_changes:
        print("\nsummary scalars not bit-identical (before, after, relative difference):")
        for f, n, x, y, r in summary_changes:
            print(f"  {f} {n}: {x:.17g} {y:.17g} {r:.3e}")
    print(f"\n{len(files)} files; tolerance {a.tolerance:g}: {'FAILED' if failed else 'all within'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
