#!/usr/bin/env python3
"""A straightforward NumPy implementation of the force-driven Fig. 4 DEM
(`validation/perf/force-driven-125.toml`: SS440c spheres, the measured 10 psi force on sphere 1,
sphere 2 on a dashpot of the transmission bar's impedance), for the whole-process speed
comparison of issue 20 (validation/perf/REPORT.md). Run only on request, not by `make test`:

    python3 validation/perf/numpy_force_driven.py          # from the repo root; needs numpy

The same scheme as shpb's `PairStepper` (docs/physics.md §5.2): velocity Verlet with the dashpot
implicit, the rate-dependent contact force at the end of the step solved for the approach speed
by the same bracketed Illinois iteration, the Burgoyne–Daraio loading curve (Eq. 1, C¹ region II,
Johnson–Cook σy*) and Thornton unloading from the static curve at a turning point; the time step
shpb uses at 125 steps a contact period (4.648965e-8 s, printed by `shpb run` of the scene),
over the drive record's 192 µs. The drive is read with numpy and interpolated per step. Prints
the peak force, its approach and the steps, to check against `shpb run` of the same scene (the
comparison asks for 1 % on the peak force).
"""
import math
import os

import numpy as np

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CSV = os.path.join(REPO, "validation/fig4-force-driven/data/ss440c_10psi_force10.csv")
DT = 4.648965e-8

from dem_law import (  # noqa: E402  (the model shared with scipy_force_driven.py)
    E_STAR, M1, M2, R_EFF, STATIC, SUM_R, SY, Z, curve_force, loading_force,
)


def approach_speed(d, a, b):
    """Root of u = a − b F(d, u) by bracketed Illinois iteration (solver::solve_approach_speed)."""
    u_hi = a - b * loading_force(d, 0.0)
    f_hi = loading_force(d, max(u_hi, 0.0))
    u_lo = a - b * f_hi
    lo, hi = min(u_lo, u_hi), max(u_lo, u_hi)
    g = lambda u: u - a + b * loading_force(d, u)
    glo, ghi = g(lo), g(hi)
    if glo >= 0.0:
        return lo
    if ghi <= 0.0:
        return hi
    side = 0
    for _ in range(100):
        u = (lo * ghi - hi * glo) / (ghi - glo)
        gu = g(u)
        if gu == 0.0 or hi - lo <= 1e-13 * (abs(hi) + abs(lo)) + 1e-18:
            return u
        if gu < 0.0:
            lo, glo = u, gu
            if side == -1:
                ghi *= 0.5
            side = -1
        else:
            hi, ghi = u, gu
            if side == 1:
                glo *= 0.5
            side = 1
    return 0.5 * (lo + hi)


def main():
    data = np.loadtxt(CSV, delimiter=",", skiprows=3)
    t_drive, f_drive = data[:, 0], data[:, 2]
    steps = int(math.ceil(t_drive[-1] / DT))
    drive = np.interp(np.arange(steps + 1) * DT, t_drive, f_drive, right=0.0)
    x1, v1, x2, v2 = 0.0, 0.0, SUM_R, 0.0
    f = 0.0
    dmax, rp, dr, unloading = 0.0, 0.0, 0.0, False
    peak, d_at_peak = 0.0, 0.0
    k2 = 1.0 + 0.5 * DT * Z / M2
    for n in range(steps):
        fe, fe_next = drive[n], drive[n + 1]
        v1h = v1 + 0.5 * DT * (fe - f) / M1
        v2h = v2 + 0.5 * DT * (f - Z * v2) / M2
        x1 += DT * v1h
        x2 += DT * v2h
        d = SUM_R - (x2 - x1)
        if d >= dmax and d > 0.0:
            if unloading:
                unloading = False
            a = (v1h + 0.5 * DT * fe_next / M1) - v2h / k2
            b = 0.5 * DT / M1 + 0.5 * DT / (M2 * k2)
            u = approach_speed(d, a, b)
            f = loading_force(d, u)
            dmax = d
        else:
            if not unloading:
                # Thornton unloading from the static curve at the turning point.
                fmax = curve_force(STATIC, dmax)
                fy = (1.0 / 6.0) * (R_EFF / E_STAR) ** 2 * (1.6 * math.pi * SY) ** 3
                rp = 4.0 * E_STAR * ((2.0 * fmax + fy) / (2.0 * 1.6 * math.pi * SY)) ** 1.5 / (3.0 * fmax)
                dr = max(dmax - (3.0 * fmax / (4.0 * E_STAR * math.sqrt(rp))) ** (2.0 / 3.0), 0.0)
                unloading = True
            e = d - dr
            f = 4.0 / 3.0 * E_STAR * math.sqrt(rp) * e * math.sqrt(e) if e > 0.0 else 0.0
        v1 = v1h + 0.5 * DT * (fe_next - f) / M1
        v2 = (v2h + 0.5 * DT * f / M2) / k2
        if f > peak:
            peak, d_at_peak = f, d
    print(f"{steps} steps of {DT:e} s; peak force {peak:.6e} N at approach {d_at_peak:.6e} m")


if __name__ == "__main__":
    main()
