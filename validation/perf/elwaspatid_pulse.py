#!/usr/bin/env python3
"""The elastic striker-bar pulse of `validation/perf/pulse-elastic-1mm.toml` computed with
elwaspatid (Brizard; Bacon 1993's travelling-wave scheme, pip install elwaspatid), at the same
1 mm resolution: the speed comparison of issue 20 (validation/perf/REPORT.md), run only on
request, not by `make test`.

    python3 -m venv /tmp/elw && /tmp/elw/bin/pip install elwaspatid
    /tmp/elw/bin/python validation/perf/elwaspatid_pulse.py        # from the repo root

Set-up as bars/authors.toml: one steel (E = 192 GPa, rho = 8110 kg/m3, d = 19.05 mm) striker
0.10 m at the gun's 10 psi velocity (5.813816 m/s, `shpb run` of the scene prints it), incident
bar 1.21 m and transmission bar 1.02 m, butt contacts, the far end non-reflecting ('infinite',
the scene's clay trap); 1 mm cells (nmin = 100 elements in the striker) for 663.2 us, the
scene's recorded duration. Prints the incident bar's peak compressive stress next to the
analytic rho c0 v / 2 as a check that the two programs solve the same problem.
"""
import contextlib
import io

import numpy as np
from elwaspatid import BarSet, WP2

E, RHO, D = 192e9, 8110.0, 0.01905
V = 5.813816
C0 = (E / RHO) ** 0.5
bar = BarSet(E=[E] * 3, rho=[RHO] * 3, L=[0.10, 1.21, 1.02], d=[D] * 3, nmin=100)
steps = int(round(663.2e-6 / bar.dt))
with contextlib.redirect_stdout(io.StringIO()):
    prop = WP2(bar, nstep=steps, left="free", right="infinite", Vinit=V)
area = np.pi * D * D / 4
force = prop.Force  # time x cross-sections of striker, incident and transmission bars
incident = slice(bar.ind[1], bar.ind[2] + 1)
peak = np.abs(force[:, incident]).max() / area
print(f"dx = {bar.dx[0] * 1e3:.4f} mm, dt = {bar.dt:.6e} s, {steps} steps")
print(f"incident bar peak stress {peak:.6e} Pa, rho c0 v / 2 = {RHO * C0 * V / 2:.6e} Pa")
