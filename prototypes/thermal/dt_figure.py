#!/usr/bin/env python3
"""Issue 16 (docs/thermal.md, "Which suspect it was"): writhe width, radius of gyration and the
stretch/shear energy of the thermal IB runs of ΔLk = 0 against the time step, without and with the
stochastic drift, next to the Monte-Carlo values, as one figure; the numbers are printed too.

    /usr/bin/python3 prototypes/thermal/dt_figure.py --mc MC.csv \\
        --nodrift 0.1:RUN[,RUN…] 0.05:RUN … --drift 0.1:RUN[,RUN…] … --figure PNG

Each DT:RUNS group is summarised by compare.py (same skip, blocks and errors)."""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402

KEYS = [("writhe", "std", "std(Wr)"), ("rg_A", "mean", "Rg (Å)"), ("E_stretch_kT", "mean", "E_stretch+shear (kT)")]


def parse(groups, skip):
    out = []
    for g in groups or []:
        dt, runs = g.split(":", 1)
        ib = [compare.read_ib(r, skip) for r in runs.split(",")]
        row = {"dt": float(dt)}
        for k, what, _ in KEYS:
            s = compare.summarize([x[k] for x, _ in ib], [d[k] for _, d in ib])
            row[k] = (s[what], s[what + "_err"])
        out.append(row)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mc", required=True)
    ap.add_argument("--nodrift", nargs="*")
    ap.add_argument("--drift", nargs="*")
    ap.add_argument("--skip-us", type=float, default=0.1)
    ap.add_argument("--figure")
    a = ap.parse_args()
    mc_ser, mc_dt = compare.read_mc(a.mc)
    mc = {}
    for k, what, _ in KEYS:
        s = compare.summarize([mc_ser[k]], [mc_dt[k]])
        mc[k] = (s[what], s[what + "_err"])
    sets = [("without drift", parse(a.nodrift, a.skip_us), "o", "C3"),
            ("with drift", parse(a.drift, a.skip_us), "s", "C0")]
    print("| Δt (ns) | drift | " + " | ".join(lab for _, _, lab in KEYS) + " |")
    print("|---|---|" + "---|" * len(KEYS))
    for name, rows, _, _ in sets:
        for r in rows:
            print(f"| {r['dt']:g} | {'yes' if name == 'with drift' else 'no'} | "
                  + " | ".join(f"{r[k][0]:.4g} ± {r[k][1]:.2g}" for k, _, _ in KEYS) + " |")
    print("| MC | | " + " | ".join(f"{mc[k][0]:.4g} ± {mc[k][1]:.2g}" for k, _, _ in KEYS) + " |")
    if not a.figure:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    for ax, (k, _, lab) in zip(axes, KEYS):
        ax.axhspan(mc[k][0] - mc[k][1], mc[k][0] + mc[k][1], color="0.8")
        ax.axhline(mc[k][0], color="k", lw=1, label="Monte Carlo")
        for j, (name, rows, mk, col) in enumerate(sets):
            if rows:
                x = np.array([r["dt"] for r in rows]) * (1 + 0.04 * (2 * j - 1))
                ax.errorbar(x, [r[k][0] for r in rows], [r[k][1] for r in rows], fmt=mk, color=col,
                            capsize=3, label="IB " + name)
        ax.set_xscale("log")
        ax.set_xticks([0.025, 0.05, 0.1])
        ax.set_xticklabels(["0.025", "0.05", "0.1"])
        ax.minorticks_off()
        ax.set_xlabel("Δt (ns)")
        ax.set_title(lab)
    axes[0].legend(fontsize=8)
    fig.suptitle("100 bp ring, ΔLk = 0, 16³ (h = 12.5 Å = 3.7 Δs): thermal IB against Monte Carlo")
    fig.tight_layout()
    fig.savefig(a.figure, dpi=110)


if __name__ == "__main__":
    main()
