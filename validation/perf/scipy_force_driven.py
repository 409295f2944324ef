#!/usr/bin/env python3
"""SciPy reference for the force-driven Fig. 4 DEM (scenes/force-driven-ss440c-10psi.toml).

Independent re-implementation of shpb's force-driven scene with scipy.integrate.solve_ivp
(method="RK45"), integrated on a ladder of tolerances; for each it prints the runtime (best
of 3, time.perf_counter), the approach delta at the peak contact force and its relative
difference from shpb's converged value. See validation/perf/SCIPY.md.

Model (mirrors src/contact.rs, src/specimen.rs, src/solver/mod.rs):
  * two full 6.35 mm SS440c spheres, m = rho 4/3 pi R^3 (shpb's default Sphere::full),
    E* = [2 (1 - nu^2)/E]^-1, r = R/2, r1 + r2 = 2R;
  * sphere 1: m1 x1'' = F_drive(t) - F;  sphere 2: m2 x2'' = F - Z x2';  delta = x1 - x2;
  * F_drive linearly interpolated from the CSV (0 outside its span), as ForceHistory::at;
  * loading (delta >= delta_max): Burgoyne-Daraio Eq. 1 with the default C^1 ("smooth")
    region II, F = delta(alpha + beta ln delta) + gamma (delta - delta_y)(delta_p - delta),
    evaluated at sigma_y* = sigma_y (1 + C ln(rate/rate0)) for rate = delta'/(r1+r2) > rate0;
  * unloading / reloading below delta_max: Thornton, Hertz with radius Rp from (delta_max,
    F_static(delta_max)) and residual approach delta_r, exactly as BurgoyneDaraio::evaluate.
    (The drive makes the contact unload and reload once before the peak force, at
    t ~ 26.7-31.6 us, so a loading-only law would not reproduce shpb's run.)
Switches loading -> unloading at delta' = 0 and unloading -> loading at delta = delta_max are
located with solve_ivp events and the integration is restarted there.

Run from the repository root:  python3 validation/perf/scipy_force_driven.py
"""

import math
import os
import subprocess
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CSV = os.path.join(REPO, "validation/fig4-force-driven/data/ss440c_10psi_force10.csv")
SCENE = "scenes/force-driven-ss440c-10psi.toml"
SHPB = os.path.join(REPO, "target/release/shpb")

from dem_law import (  # noqa: E402  (the model shared with numpy_force_driven.py)
    E_STAR, M1, M2, MASS, R_EFF, STATIC, SY, YIELD_ONSET, Z, curve_force, hertz, loading_force,
)

# End of integration: past the peak contact force (~83.4 us) and before the next turning point
# (delta_max at ~91.5 us). Everything after the peak is irrelevant for the metric.
T_END = 88e-6


def thornton(dmax):
    """(Rp, delta_r) at a turning point (BurgoyneDaraio::evaluate / thornton_unloading)."""
    fmax = curve_force(STATIC, dmax)
    if dmax <= STATIC[0]:  # never left region I: elastic Hertz unloading
        return R_EFF, 0.0
    fy = (1.0 / 6.0) * (R_EFF / E_STAR) ** 2 * (YIELD_ONSET * math.pi * SY) ** 3
    rp = 4.0 * E_STAR * ((2.0 * fmax + fy) / (2.0 * math.pi * YIELD_ONSET * SY)) ** 1.5 / (3.0 * fmax)
    dr = dmax - (3.0 * fmax / (4.0 * E_STAR * math.sqrt(rp))) ** (2.0 / 3.0)
    return rp, max(dr, 0.0)


# --- drive ---------------------------------------------------------------------------------
_data = np.genfromtxt(CSV, delimiter=",", skip_header=3)
T_DRIVE = _data[:, 0].tolist()
F_DRIVE = _data[:, 2].tolist()
T0, T1 = T_DRIVE[0], T_DRIVE[-1]
DT_DRIVE = (T1 - T0) / (len(T_DRIVE) - 1)
_uniform = np.allclose(np.diff(_data[:, 0]), DT_DRIVE, rtol=1e-6, atol=0.0)


def drive(t):
    if t < T0 or t > T1:
        return 0.0
    if _uniform:
        i = min(max(int((t - T0) / DT_DRIVE) + 1, 1), len(T_DRIVE) - 1)
        # guard against rounding at a sample
        while i > 1 and T_DRIVE[i - 1] > t:
            i -= 1
        while i < len(T_DRIVE) - 1 and T_DRIVE[i] <= t:
            i += 1
    else:
        i = min(max(int(np.searchsorted(T_DRIVE, t, side="right")), 1), len(T_DRIVE) - 1)
    t0, t1 = T_DRIVE[i - 1], T_DRIVE[i]
    w = (t - t0) / (t1 - t0)
    return F_DRIVE[i - 1] * (1.0 - w) + F_DRIVE[i] * w


# --- equations of motion; y = [x1, v1, x2, v2] ---------------------------------------------
def rhs_loading(t, y):
    f = loading_force(y[0] - y[2], y[1] - y[3])
    return [y[1], (drive(t) - f) / M1, y[3], (f - Z * y[3]) / M2]


def make_rhs_unloading(rp, dr):
    def rhs(t, y):
        f = hertz(rp, y[0] - y[2] - dr)
        return [y[1], (drive(t) - f) / M1, y[3], (f - Z * y[3]) / M2]

    return rhs


def ev_turn(t, y):  # loading -> unloading where delta' falls through 0
    return y[1] - y[3]


ev_turn.terminal, ev_turn.direction = True, -1


# Reload threshold above delta_max: the contact creeps (delta' ~ 0) near t ~ 26.66 us, where a
# turn event followed by an immediate reload at g = 0 would chatter forever (Zeno). A hysteresis
# of 1e-10 delta_max (~1e-14 m) is far below every tolerance of the ladder.
RELOAD_EPS = 1e-10


def make_ev_reload(dmax):
    def ev(t, y):
        return (y[0] - y[2]) - dmax * (1.0 + RELOAD_EPS)

    ev.terminal, ev.direction = True, 1
    return ev


def simulate(tol):
    """Integrates to T_END; returns [(phase, OdeSolution, t0, t1, params)], nfev, events."""
    atol = [tol * 1e-4, tol * 1.0, tol * 1e-4, tol * 1.0]  # m, m/s (delta ~2e-4 m, v ~1 m/s)
    t, y = 0.0, np.zeros(4)
    segments, nfev, dmax, loading, switches = [], 0, 0.0, True, 0
    while t < T_END:
        if loading:
            sol = solve_ivp(rhs_loading, (t, T_END), y, method="RK45", rtol=tol, atol=atol,
                            dense_output=True, events=ev_turn)
            segments.append(("load", sol.sol, t, sol.t[-1], None))
        else:
            rp, dr = thornton(dmax)
            sol = solve_ivp(make_rhs_unloading(rp, dr), (t, T_END), y, method="RK45", rtol=tol,
                            atol=atol, dense_output=True, events=make_ev_reload(dmax))
            segments.append(("unload", sol.sol, t, sol.t[-1], (rp, dr)))
        nfev += sol.nfev
        if sol.status == -1:
            raise RuntimeError(sol.message)
        t, y = sol.t[-1], sol.y[:, -1].copy()
        if sol.status == 1:  # an event stopped it: switch branch
            switches += 1
            if os.environ.get("SCIPY_FD_DEBUG"):
                print(f"  switch {'turn' if loading else 'reload'} t={t:.9e} delta={y[0]-y[2]:.9e} "
                      f"ddot={y[1]-y[3]:.3e}", file=sys.stderr)
            if loading:
                dmax = y[0] - y[2]
            loading = not loading
            if switches > 2000:
                raise RuntimeError("too many branch switches")
    return segments, nfev, switches


def contact_force(seg, t):
    phase, sol, _, _, p = seg
    x1, v1, x2, v2 = sol(t)
    if phase == "load":
        return loading_force(x1 - x2, v1 - v2)
    return hertz(p[0], x1 - x2 - p[1])


def peak(segments):
    """(t, F, delta) at the largest contact force: dense output scan, then bounded Brent."""
    best = None
    for seg in segments:
        _, sol, a, b, _ = seg
        if b <= a:
            continue
        grid = np.union1d(np.linspace(a, b, 64), sol.ts[(sol.ts >= a) & (sol.ts <= b)])
        f = [contact_force(seg, s) for s in grid]
        k = int(np.argmax(f))
        if best is None or f[k] > best[1]:
            best = (seg, f[k], grid, k)
    seg, _, grid, k = best
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    r = minimize_scalar(lambda s: -contact_force(seg, s), bounds=(lo, hi), method="bounded",
                        options={"xatol": 1e-14})
    tp = r.x
    x = seg[1](tp)
    return tp, -r.fun, x[0] - x[2]


def shpb_reference():
    """shpb's finest-level delta at peak from `shpb convergence` (None if the binary is missing)."""
    if not os.path.exists(SHPB):
        return None
    out = subprocess.run([SHPB, "convergence", SCENE], cwd=REPO, capture_output=True,
                         text=True, check=True).stdout
    rows = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 7:
            try:
                rows.append([float(v) for v in parts])
            except ValueError:
                pass
    return rows


def main():
    print(f"m1 = m2 = {MASS:.6e} kg, E* = {E_STAR:.6e} Pa, r = {R_EFF:.6e} m, Z = {Z:.6e} kg/s")
    rows = shpb_reference()
    ref = None
    if rows:
        print("shpb convergence (steps_per_period, in-process runtime s, delta at peak m):")
        for r in rows:
            print(f"  {r[0]:8.0f}  {r[1]:.4f}  {r[4]:.9e}")
        ref = rows[-1][4]
    results = []
    for e in range(3, 11):
        tol = 10.0 ** -e
        times = []
        for _ in range(3):
            t0 = time.perf_counter()
            segs, nfev, nsw = simulate(tol)
            t1 = time.perf_counter()
            tp, fp, dp = peak(segs)
            t2 = time.perf_counter()
            times.append((t1 - t0, t2 - t0))
        solve_t = min(s for s, _ in times)
        total_t = min(s for _, s in times)
        results.append((tol, solve_t, total_t, nfev, nsw, tp, fp, dp))
    finest = results[-1][7]
    print()
    print(f"reference delta at peak: shpb finest level {ref!r}, SciPy finest (tol 1e-10) {finest:.9e}")
    hdr = (f"{'tol':>7} {'solve_s':>9} {'total_s':>9} {'nfev':>8} {'switch':>6} {'t_peak_s':>13}"
           f" {'F_peak_N':>13} {'delta_peak_m':>16} {'err_vs_shpb':>11} {'err_vs_scipy':>12}")
    print(hdr)
    for tol, st, tt, nfev, nsw, tp, fp, dp in results:
        es = (dp - ref) / ref if ref else float("nan")
        ec = (dp - finest) / finest
        print(f"{tol:7.0e} {st:9.4f} {tt:9.4f} {nfev:8d} {nsw:6d} {tp:13.6e} {fp:13.6e}"
              f" {dp:16.9e} {es:11.2e} {ec:12.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
