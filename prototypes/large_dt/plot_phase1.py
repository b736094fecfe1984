#!/usr/bin/python3
# Figure of docs/large_dt.md from the time series that phase1.sh writes (copied next to it).
import glob, os, sys
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

here = os.path.dirname(os.path.abspath(__file__))
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "../../docs/figures/large_dt_phase1.png")
runs = [("ld_series_explicit.txt", "explicit Stokes Euler, 0.1 ns", "k-"),
        ("ld_series_imex_0.5.txt", "IMEX β=8, 0.5 ns", "C0-"),
        ("ld_series_imex_1.txt", "IMEX β=8, 1 ns", "C1-"),
        ("ld_series_imex_2.txt", "IMEX β=8, 2 ns", "C2-"),
        ("ld_series_adaptive.txt", "IMEX β=8, adaptive ≤ 4 ns", "C3o-")]
fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
for f, label, style in runs:
    d = np.loadtxt([l for l in open(os.path.join(here, f)) if l[0] not in "#S"])
    ms = 2 if "o" in style else None
    ax[0].plot(d[:, 0], d[:, 1], style, label=label, ms=ms)
    ax[1].plot(d[:, 0], d[:, 3], style, label=label, ms=ms)
    if "adaptive" in f:
        ax[2].plot(d[:, 0], d[:, 10], style, ms=ms, label="adaptive Δt")
ax[2].axhline(0.15, color="k", ls="--", label="explicit limit (0.15-0.2 ns)")
ax[0].set_ylabel("writhe"); ax[1].set_ylabel("potential energy (kT)"); ax[2].set_ylabel("Δt (ns)")
ax[2].set_yscale("log")
for a in ax:
    a.set_xlabel("t (ns)")
ax[0].legend(fontsize=7); ax[2].legend(fontsize=7)
fig.suptitle("32³, 150 bp, ΔLk = 3, 0.1 M (prototypes/large_dt/phase1.sh)", fontsize=9)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(out)
