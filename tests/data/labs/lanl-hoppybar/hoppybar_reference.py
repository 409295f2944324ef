#!/usr/bin/env python3
"""HopPyBar's mini-Kolsky reduction of PMMA-13 with its mouse picks scripted: the reference
numbers of crates/cli/tests/lanl_records.rs.

HopPyBar (lanl/HopPyBar, commit 6f3ae1a, HopPyBar.py) is interactive: the baseline span, the
incident pulse span, an optional transmitted span, the alignment sliders and the strain-rate span
are picked with the mouse. This script follows HopPyBar.py's `platform == 'mini'` branch step by
step with those picks fixed:

- files: the four `*Ch*` files sorted by name, time from Ch1's column 4 (s -> us), values from
  column 5 (V -> mV); the deck `*Input*` read as HopPyBar reads it (tab-separated, cp1252,
  blank lines skipped, rows by index);
- baseline: the mean of each channel over -80 to -5 us (the pre-trigger part), data before it
  dropped;
- ch_i = (ch1 + ch2)/2, ch_t = (ch3 + ch4)/2;
- incident span: from --incident-start-us over 20 us; reflected and transmitted windows
  dead-reckoned (HopPyBar's default when no transmitted span is picked): the reflected from
  2 d_I/c, the transmitted from d_I/c + d_T/c, all of the incident span's length;
- strain: si = -V*(2/GF)/(gain*Vex), sr = +V*(2/GF)/(gain*Vex), st = -V*(2/GF)/(gain*Vex);
- dispersion: none, or HopPyBar's default `Bragov2022` (dispersionLib_Bragov2022 imported from
  the HopPyBar checkout, each wave shifted by its gauge distance with backshift=True);
- alignment sliders at 0;
- 1-wave analysis as in HopPyBar.py: stress = A_bar/A_sample * E * st, strain = sum of
  2 c/L * sr * dt, rate = 2 c sr / L;
- the figures shpb reports, taken the same way from these curves: the peak 1-wave stress, the
  1-wave strain at that peak, and the mean 1-wave strain rate from the first sample at 10 % of
  the peak stress to the peak.

Usage (numpy, pandas; mpmath for Bragov2022):
    python3 hoppybar_reference.py --data PMMA-13 --hoppybar /path/to/HopPyBar \
        --dispersion none|Bragov2022 --incident-start-us -0.84
"""
import argparse
import glob
import os
import sys
import tempfile

import numpy as np
import pandas as pd

p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
p.add_argument("--data", required=True, help="the PMMA-13 folder (four *Ch* files, *Input* deck)")
p.add_argument("--hoppybar", help="a HopPyBar checkout (for --dispersion Bragov2022)")
p.add_argument("--dispersion", choices=["none", "Bragov2022"], default="none")
p.add_argument("--incident-start-us", type=float, default=-0.84)
p.add_argument("--baseline-us", type=float, nargs=2, default=(-80.0, -5.0))
p.add_argument("--span-us", type=float, default=20.0)
a = p.parse_args()

files = sorted(glob.glob(os.path.join(a.data, "*Ch*")), key=os.path.basename)
df = pd.read_csv(files[0], usecols=[3], names=["time"]) * 1e6
for i, f in enumerate(files):
    df["ch" + str(i + 1)] = pd.read_csv(f, usecols=[4], header=None)[4] * 1000
tp = pd.read_csv(glob.glob(os.path.join(a.data, "*Input*"))[0], delimiter="\t", usecols=[0, 1],
                 encoding="cp1252", header=None, skip_blank_lines=True,
                 names=["property", "data"]).dropna()
E_bi, E_bt = float(tp.data[29]), float(tp.data[46])
c_bi, c_bt = float(tp.data[31]), float(tp.data[48])
thick, d = float(tp.data[6]), float(tp.data[5])
d_bar_i, d_bar_t = float(tp.data[35]), float(tp.data[52])
A_ratio_t = d_bar_t ** 2 / d ** 2
exc_i, exc_t = float(tp.data[37]), float(tp.data[54])
gain_i, gain_t = float(tp.data[16]), float(tp.data[17])
gcf_i, gcf_t = 2 / float(tp.data[24]), 2 / float(tp.data[43])
ig, tg = float(tp.data[36]), float(tp.data[53])

sel = (df.time >= a.baseline_us[0]) & (df.time <= a.baseline_us[1])
avg = {c: df[c][sel].mean() for c in ["ch1", "ch2", "ch3", "ch4"]}
df = df[df.time > df.time[sel].max()]
T = df.time.values
VI = (((df.ch1 - avg["ch1"]) + (df.ch2 - avg["ch2"])) / 2).values
VT = (((df.ch3 - avg["ch3"]) + (df.ch4 - avg["ch4"])) / 2).values

span = (T >= a.incident_start_us) & (T <= a.incident_start_us + a.span_us)
start, window = T[span].min(), int(span.sum())
c_i, c_t = c_bi * 1e-3, c_bt * 1e-3  # mm/us
ii = np.searchsorted(T, start)
ir = np.searchsorted(T, start + 2 * ig / c_i)
it = np.searchsorted(T, start + ig / c_i + tg / c_t)
si = -VI[ii:ii + window] * gcf_i / (gain_i * exc_i * 1000)
sr = VI[ir:ir + window] * gcf_i / (gain_i * exc_i * 1000)
st = -VT[it:it + window] * gcf_t / (gain_t * exc_t * 1000)
tr = T[ir:ir + window] - T[ir]
tt = T[it:it + window] - T[it]
if a.dispersion == "Bragov2022":
    sys.path.insert(0, a.hoppybar)
    from dispersionLib_Bragov2022 import barWithDispersion
    bar = barWithDispersion(E=E_bi * 1e9, rho=float(tp.data[34]) * 1000,
                            nu=float(tp.data[30]), r0=(d_bar_i / 2) / 1000)
    bar.solve()
    # HopPyBar saves the solution and loads it back (its ksi as floats) before using it.
    with tempfile.TemporaryDirectory() as tmp:
        bar.save(os.path.join(tmp, "disp.txt"))
        bar.load(os.path.join(tmp, "disp.txt"))
    # Each wave on its own window's clock, as HopPyBar passes reflected.time, transmitted.time.
    sr = np.array(bar.disp_shift_wave(t=(tr / 1e6).tolist(), y=sr.tolist(), dz=-ig / 1000,
                                      backshift=True))
    st = np.array(bar.disp_shift_wave(t=(tt / 1e6).tolist(), y=st.tolist(), dz=-tg / 1000,
                                      backshift=True))
n = min(len(sr), len(st))
sr, st, tr = sr[:n], st[:n], tr[:n]
strain = np.concatenate([[0.0], np.cumsum((2.0 * c_i / thick) * sr[1:] * np.diff(tr))])
stress = A_ratio_t * (E_bt * 1000) * st  # MPa
k = int(np.argmax(stress))
k10 = int(np.argmax(stress[:k + 1] >= 0.1 * stress[k]))
rate = (strain[k] - strain[k10]) / ((tr[k] - tr[k10]) * 1e-6)
print(f"dispersion {a.dispersion}, incident start {start:.3f} us: peak 1-wave stress "
      f"{stress[k]:.2f} MPa at {tr[k]:.3f} us, strain at peak {strain[k]:.5f}, mean strain rate "
      f"(10 % of peak to peak) {rate:.1f} 1/s")
