"""Design a test: which gas-gun pressure gives a 10 kN peak contact force on two 6.35 mm SS440c
spheres with the authors' bars and copper shaper, and is the specimen in force equilibrium?

Run from the repository root: python examples/python/design_a_test.py
"""
import numpy as np

import shpb

SCENE = "scenes/shpb-ss440c-10psi.toml"
TARGET_N = 10e3

# A coarse sweep of the gun pressure (runs in parallel, GIL released)...
table = shpb.sweep(SCENE, set={"pressure": [f"{p}psi" for p in range(7, 16, 2)]}, jobs=2)
pressure_pa, peak_n = table.inputs["pressure"], table["peak_force"]
assert np.all(np.diff(peak_n) > 0), "peak force should grow with the pressure"

# ...then the pressure that reaches the target, checked by a run at that pressure.
p = float(np.interp(TARGET_N, peak_n, pressure_pa))
r = shpb.run(SCENE, set={"pressure": f"{p:.1f}Pa"})
eq = r.summary["reduced_equilibrium_ratio_at_peak"]

print(f"pressure for {TARGET_N / 1e3:.0f} kN: {p / 6894.757:.2f} psi ({p / 1e3:.1f} kPa)")
print(f"check run: peak contact force {r.summary['peak_contact_force'] / 1e3:.2f} kN, "
      f"striker {r.summary['striker_velocity']:.2f} m/s")
print(f"equilibrium ratio at peak {eq:.3f}: "
      + ("equilibrium reached (< 0.05)" if eq < 0.05 else "NOT in equilibrium (>= 0.05)"))
for w in r.warnings:
    print("warning:", w)
