#!/usr/bin/python3
# Figure of docs/large_dt.md from the time series that reference64.sh writes next to it.
import os, sys
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

here = os.path.dirname(os.path.abspath(__file__))
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "../../docs/figures/large_dt_reference64.png")
def load(f):
    return np.loadtxt([l for l in open(os.path.join(here, f)) if l[0] not in "#ST"])
runs = [("ref64_explicit_0.1.txt", "explicit, Δt = 0.1 ns (20000 steps, 110 s)", "k-"),
        ("ref64_implicit_2.txt", "implicit, Δt ≤ 2 ns (1000 steps, 7.3 s)", "C0--"),
        ("ref64_implicit_4.4.txt", "implicit, Δt ≤ 4.4 ns (468 steps, 3.9 s)", "C3:")]
fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
for f, label, style in runs:
    d = load(f)
    ax[0].plot(d[:, 0] / 1e3, d[:, 1], style, label=label)
    ax[1].plot(d[:, 0] / 1e3, d[:, 3], style, label=label)
    ax[2].plot(d[:, 0] / 1e3, d[:, 4], style, label=label)
ax[0].set_ylabel("writhe"); ax[1].set_ylabel("potential energy (kT)")
ax[2].set_ylabel("closest approach (Å)")
for a in ax:
    a.set_xlabel("t (µs)")
ax[0].legend(fontsize=7)
fig.suptitle("64³, 600 bp, ΔLk = 6, 0.1 M, 2 threads (prototypes/large_dt/reference64.sh)", fontsize=9)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(out)
