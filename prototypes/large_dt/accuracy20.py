#!/usr/bin/env python3
"""Issue 14 accuracy at the reference grid: the implicit scheme (time.dt_ns = 2, adaptive) against
the explicit one at 0.1 ns, from two run directories each for (ΔLk, Cs) = (4, 0.1 M) and
(6, 0.01 M). Compares at the latest time both reached (the explicit runs may still be running).
Usage: accuracy20.py EXPLICIT_DIR IMPLICIT_DIR [...pairs]"""
import csv
import sys

import numpy as np


def load(d):
    r = list(csv.DictReader(open(d + "/timeseries.csv")))
    return {k: np.array([float(x[k]) for x in r]) for k in r[0]}


def first_cross(t, wr, level=1.0):
    i = np.argmax(wr >= level)
    return t[i] if wr[i] >= level else float("nan")


for ex_dir, im_dir in zip(sys.argv[1::2], sys.argv[2::2]):
    ex, im = load(ex_dir), load(im_dir)
    tc = min(ex["time_us"][-1], im["time_us"][-1])
    ie = np.searchsorted(ex["time_us"], tc - 1e-9)
    ii = np.searchsorted(im["time_us"], tc - 1e-9)
    print(f"== {ex_dir} vs {im_dir}: compared at t = {tc:.3f} us "
          f"(explicit row {ie}, t = {ex['time_us'][ie]:.4f}; implicit row {ii}, t = {im['time_us'][ii]:.4f})")
    te, ti = first_cross(ex["time_us"], ex["writhe"]), first_cross(im["time_us"], im["writhe"])
    print(f"  t(Wr first >= 1): explicit {te:.3f} us, implicit {ti:.3f} us, ratio {ti / te:.3f}")
    for k, fmt in [("writhe", ".4f"), ("E_total_kT", ".2f"), ("closest_approach_A", ".2f"),
                   ("E_bend_kT", ".2f"), ("E_twist_kT", ".2f"), ("E_stretch_kT", ".2f"),
                   ("E_electro_kT", ".2f"), ("link", ".6f")]:
        a, b = ex[k][ie], im[k][ii]
        print(f"  {k:20s} explicit {a:{fmt}}  implicit {b:{fmt}}  diff {b - a:+{fmt}}")
    for name, s in (("explicit", ex), ("implicit", im)):
        Ep = s["E_total_kT"]
        print(f"  {name}: max |Lk - Lk0| = {np.max(np.abs(s['link'] - s['link'][0])):.1e}, "
              f"largest rise of E_total between rows = {max(0, np.max(np.diff(Ep))):.3g} kT, "
              f"last row t = {s['time_us'][-1]:.3f} us Wr = {s['writhe'][-1]:.4f} "
              f"E_total = {Ep[-1]:.2f} kT closest = {s['closest_approach_A'][-1]:.2f} A")
