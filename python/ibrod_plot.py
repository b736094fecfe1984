#!/usr/bin/python3
"""Total energy, kinetic energy (log scale) and writhe against time for one ibrod run or several
overlaid, as one PNG.

    python/ibrod_plot.py RUN_DIR [RUN_DIR...] -o out.png [--logt] [--title TEXT]

Each RUN_DIR is an output directory of `ibrod run` (timeseries.csv, config.toml). When
`ibrod analyze RUN_DIR` has been run, its summary.json adds the writhe convergence time (dotted
line on the writhe panel), the transient states (circles on the energy panels) and the fitted
exponential final approach of E_K (dashed). Runs are labelled by ΔLk and Cs from config.toml, and
"not finished" when summary.json's stop_reason is not "equilibrium" (their writhe convergence
time and τ are null, so neither is drawn).
Needs numpy and matplotlib (Debian: python3-numpy python3-matplotlib); use /usr/bin/python3.
"""
import argparse
import json
import os
import sys
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


class Run:
    """One run directory: its time series, config and (possibly analysed) summary."""

    def __init__(self, path):
        self.path = path
        self.name = os.path.basename(os.path.normpath(path))
        ts_path = os.path.join(path, "timeseries.csv")
        if not os.path.isfile(ts_path):
            raise SystemExit(f"ibrod_plot: {ts_path} not found (is {path} an ibrod run directory?)")
        self.ts = np.atleast_1d(np.genfromtxt(ts_path, delimiter=",", names=True))
        self.config = {}
        cfg_path = os.path.join(path, "config.toml")
        if os.path.isfile(cfg_path):
            with open(cfg_path, "rb") as f:
                self.config = tomllib.load(f)
        self.summary = {}
        sum_path = os.path.join(path, "summary.json")
        if os.path.isfile(sum_path):
            with open(sum_path) as f:
                self.summary = json.load(f)

    @property
    def excess_link(self):
        return self.config.get("rod", {}).get("excess_link")

    @property
    def salt_M(self):
        return self.config.get("solvent", {}).get("salt_M")

    @property
    def finished(self):
        """True when the run reached equilibrium (summary.json stop_reason), None when unknown."""
        if "stop_reason" not in self.summary:
            return None
        return self.summary["stop_reason"] == "equilibrium"

    def label(self, with_name=False):
        parts = []
        if self.excess_link is not None:
            parts.append(f"ΔLk = {self.excess_link}")
        if self.salt_M is not None:
            parts.append(f"Cs = {self.salt_M:g} M")
        text = ", ".join(parts) or self.name
        text = f"{text} ({self.name})" if with_name and parts else text
        return text if self.finished is not False else text + " — not finished"


def plot_runs(runs, out, logt=False, title=None):
    """Writes the three-panel figure of `runs` (a list of Run) to the PNG `out`."""
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True, constrained_layout=True)
    ax_e, ax_k, ax_w = axes
    labels = [r.label() for r in runs]
    duplicate = len(set(labels)) < len(labels)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, run in enumerate(runs):
        c = colors[i % len(colors)]
        ts = run.ts
        t = ts["time_us"]
        ax_e.plot(t, ts["E_total_kT"], color=c, label=run.label(duplicate))
        positive = ts["E_kinetic_kT"] > 0
        ax_k.plot(t[positive], ts["E_kinetic_kT"][positive], color=c)
        ax_w.plot(t, ts["writhe"], color=c)

        s = run.summary
        tc = s.get("writhe_convergence_time_us")  # null for a run that did not finish
        if tc is not None:
            ax_w.axvline(tc, color=c, linestyle=":", linewidth=1)
        for tr in s.get("transients") or []:
            ax_e.plot(tr["time_us"], tr["E_total_kT"], "o", mfc="none", color=c)
            ax_k.plot(tr["time_us"], tr["E_kinetic_kT"], "o", mfc="none", color=c)
        tau, fit = s.get("relaxation_time_us"), s.get("relaxation_fit")
        if tau and fit:
            # the fitted E_K = A exp(−2t/τ) over its window, anchored at the window's last sample
            tw = np.linspace(fit["t_start_us"], fit["t_end_us"], 50)
            last = np.argmin(np.abs(t - fit["t_end_us"]))
            ek_end = ts["E_kinetic_kT"][last]
            if ek_end > 0:
                ax_k.plot(tw, ek_end * np.exp(-2 * (tw - t[last]) / tau), "--", color=c,
                          linewidth=1, label=f"τ = {tau:.3g} µs")

    ax_e.set_ylabel("total energy (kT)")
    ax_k.set_ylabel("kinetic energy (kT)")
    ax_k.set_yscale("log")
    ax_w.set_ylabel("writhe")
    ax_w.set_xlabel("time (µs)")
    if logt:
        ax_w.set_xscale("log")
    ax_e.legend(fontsize="small")
    if any(r.summary.get("relaxation_time_us") for r in runs):
        ax_k.legend(fontsize="small")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", nargs="+", metavar="RUN_DIR", help="output directories of ibrod run")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--logt", action="store_true", help="logarithmic time axis")
    p.add_argument("--title", help="figure title")
    a = p.parse_args(argv)
    plot_runs([Run(d) for d in a.runs], a.output, logt=a.logt, title=a.title)
    print(a.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
