#!/usr/bin/env python3
"""Compares two run files of one `chain` scene across the issue-45 layout change.

Usage: compare_chain.py BEFORE.h5 AFTER.h5 [--tolerance 1e-9]

Before issue 45 each sphere's `final_velocity_<k>` was a `/summary` attribute and a dataset
`/summary/final_velocity_<k>`; after it, element k - 1 of `/chain/final_velocity` (attribute
`summary_key`). Every numeric dataset of BEFORE is compared with the same quantity of AFTER
(`summary/final_velocity_<k>` with `chain/final_velocity[k - 1]`), as are the `/summary`
attributes; a difference is relative to the largest magnitude of the series (a scalar: of
itself). AFTER may have more (the new summary item `output_every`). With `--every N` the 2-D
`/chain` series and `/chain/time`, `/contact/*` of BEFORE are compared at the columns AFTER kept
(every N-th step and the last), for a run whose `output_every` was chosen by the budget.
Exit status 1 on a missing quantity, a shape mismatch or a difference beyond the tolerance.
"""
import argparse
import re
import sys

import h5py
import numpy as np

FINAL = re.compile(r"^summary/final_velocity_(\d+)$")


def datasets(f):
    out = {}
    f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
    return out


def kept(n, every):
    """The indices a run at output_every = `every` keeps of `n` every-step samples."""
    steps = n - 1
    return [i for i in range(n) if i % every == 0 or i == steps]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--tolerance", type=float, default=1e-9)
    ap.add_argument("--every", type=int, default=1)
    a = ap.parse_args()
    with h5py.File(a.before, "r") as fb, h5py.File(a.after, "r") as fa:
        db, da = datasets(fb), datasets(fa)
        sb = {k: v for k, v in fb["summary"].attrs.items() if k not in ("units", "warnings")}
        sa = {k: v for k, v in fa["summary"].attrs.items() if k not in ("units", "warnings")}
        key = fa["chain/final_velocity"].attrs.get("summary_key")
    final_after = da["chain/final_velocity"]
    failed, worst, where, compared, identical = False, 0.0, "", 0, 0

    def compare(name, x, y):
        nonlocal failed, worst, where, compared, identical
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if x.shape != y.shape:
            print(f"{name}: shape {x.shape} before, {y.shape} after")
            failed = True
            return
        compared += 1
        if np.array_equal(x, y, equal_nan=True):
            identical += 1
            return
        scale = np.nanmax(np.abs(x)) if x.size else 0.0
        d = np.nanmax(np.abs(x - y)) / (scale if scale > 0 else 1.0)
        if d > worst:
            worst, where = d, name
        if d > a.tolerance:
            print(f"{name}: differs by {d:.3e} of its largest value")
            failed = True

    decimated = {"chain/time", "chain/contact_force", "chain/contact_approach", "chain/velocity"}
    for name, x in sorted(db.items()):
        if not np.issubdtype(np.asarray(x).dtype, np.number):
            continue
        m = FINAL.match(name)
        if m:
            compare(name, x, final_after[int(m.group(1)) - 1])
            continue
        if name not in da:
            print(f"{name}: MISSING after")
            failed = True
            continue
        y = da[name]
        if a.every > 1 and (name in decimated or name.startswith("contact/") or name.startswith("chain/") and np.ndim(x) == 1 and np.size(x) == np.size(db["chain/time"])):
            idx = kept(np.shape(x)[-1], a.every)
            x = np.asarray(x)[..., idx]
        compare(name, x, y)
    for k, v in sorted(sb.items()):
        m = re.match(r"^final_velocity_(\d+)$", k)
        compare(f"summary attribute {k}", v, final_after[int(m.group(1)) - 1] if m else sa.get(k, np.nan))
    print(
        f"{compared} quantities compared, {identical} bit-identical, largest difference {worst:.3e}"
        + (f" ({where})" if where else "")
        + f"; /chain/final_velocity summary_key = {key!r}; new summary items: {sorted(set(sa) - set(sb))}"
    )
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
