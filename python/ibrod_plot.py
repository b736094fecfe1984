#!/usr/bin/python3
"""Total energy, kinetic energy (log scale) and writhe against time for one ibrod run or several
overlaid, as one figure: PNG, or vector PDF/SVG chosen by the output's extension.

    python/ibrod_plot.py RUN_DIR [RUN_DIR...] -o out.png|out.pdf|out.svg [--logt] [--title TEXT]

Each RUN_DIR is an output directory of `ibrod run` (timeseries.csv, config.toml). When
`ibrod analyze RUN_DIR` has been run, its summary.json adds the writhe convergence time (dotted
line on the writhe panel), the transient states (circles on the energy panels) and the fitted
exponential final approach of E_K (dashed); each of these marks has its own legend entry. Runs are
labelled by ΔLk, Cs and grid from config.toml (what all runs share goes into the title), with the
run name when two runs share a label, and "not finished" when summary.json's stop_reason is not
"equilibrium" (their writhe convergence time and τ are null, so neither is drawn). Every run is
its own line, also two runs at the same (ΔLk, Cs). A log axis always carries at least two
labelled ticks (1-2-5 ticks or a widened range when the data span less than a decade).
Needs numpy and matplotlib (Debian: python3-numpy python3-matplotlib); use /usr/bin/python3.
"""
import argparse
import io
import json
import os
import sys
import tomllib
import warnings

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullFormatter  # noqa: E402

FORMATS = ("png", "pdf", "svg")


def output_format(path, fmt=None):
    """The figure format of `path`: `fmt` when given, else its extension; one of FORMATS."""
    f = (fmt or os.path.splitext(path)[1].lstrip(".")).lower()
    if f not in FORMATS:
        raise SystemExit(f"ibrod_plot: output format '{f or path}' of {path} is not supported "
                         f"(allowed: {', '.join(FORMATS)}; by extension or --format)")
    return f


def save(fig, path, dpi=120):
    """Saves `fig` as PNG (at `dpi`) or as vector PDF/SVG, by the extension of `path`."""
    fmt = output_format(path)
    fig.savefig(path, format=fmt, dpi=dpi if fmt == "png" else None)


def _ticks_125(lo, hi):
    """The 1-2-5 values ×10^k in [lo, hi]."""
    out = []
    for k in range(int(np.floor(np.log10(lo))) - 1, int(np.ceil(np.log10(hi))) + 1):
        out += [m * 10.0 ** k for m in (1, 2, 5) if lo <= m * 10.0 ** k <= hi]
    return out


def log_axis(ax, which="y"):
    """Log scale on `which` ("x" or "y") with labelled major ticks at every decade (at 1, 2 and 5
    ×10^k when the view spans under two decades) and unlabelled minor ticks at 2–9 ×10^k; the
    view is widened to the neighbouring 1-2-5 values when it would hold fewer than two labelled
    ticks. Call after plotting."""
    axis = ax.yaxis if which == "y" else ax.xaxis
    getlim, setlim = (ax.get_ylim, ax.set_ylim) if which == "y" else (ax.get_xlim, ax.set_xlim)
    (ax.set_yscale if which == "y" else ax.set_xscale)("log")
    lo, hi = sorted(getlim())
    if not (lo > 0 and np.isfinite(hi)):
        return
    if np.log10(hi / lo) < 2:
        if len(_ticks_125(lo, hi)) < 2:  # widen to the 1-2-5 values around the data
            below = [v for v in _ticks_125(lo / 10, lo) if v <= lo]
            above = [v for v in _ticks_125(hi, hi * 10) if v >= hi]
            lo, hi = below[-1], above[0]
            if len(_ticks_125(lo, hi)) < 2:
                hi = _ticks_125(hi * 1.0001, hi * 10)[0]
            setlim(lo, hi)
        axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        axis.set_minor_locator(LogLocator(base=10, subs=(3.0, 4.0, 6.0, 7.0, 8.0, 9.0)))
    else:
        axis.set_major_locator(LogLocator(base=10, numticks=12))
        axis.set_minor_locator(LogLocator(base=10, subs=np.arange(2, 10) * 1.0, numticks=12))
    axis.set_major_formatter(LogFormatterSciNotation(base=10, labelOnlyBase=False))
    axis.set_minor_formatter(NullFormatter())


def grid_text(config):
    """"16³ grid, box 200 Å" from a config.toml dict, or None."""
    g = config.get("grid", {})
    if "n" not in g:
        return None
    text = f"{g['n']}³ grid"
    return text + (f", box {g['box_A']:g} Å" if "box_A" in g else "")


def read_csv(path):
    """A run's CSV (timeseries.csv) as a numpy structured array. A last row cut short by a killed
    run (no newline at its end) is dropped, as `ibrod analyze` drops it; a file that still cannot
    be read stops with a message naming it."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise SystemExit(f"ibrod_plot: cannot read {path}: {e}")
    if text and not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # a header without rows: an empty table
            a = np.atleast_1d(np.genfromtxt(io.StringIO(text), delimiter=",", names=True))
    except ValueError as e:
        raise SystemExit(f"ibrod_plot: cannot read {path}: {e}")
    if a.dtype.names is None:
        raise SystemExit(f"ibrod_plot: cannot read {path}: no header line of column names")
    return a


class Run:
    """One run directory: its time series, config and (possibly analysed) summary."""

    def __init__(self, path):
        self.path = path
        self.name = os.path.basename(os.path.normpath(path))
        ts_path = os.path.join(path, "timeseries.csv")
        if not os.path.isfile(ts_path):
            raise SystemExit(f"ibrod_plot: {ts_path} not found (is {path} an ibrod run directory?)")
        self.ts = read_csv(ts_path)
        self.config = {}
        cfg_path = os.path.join(path, "config.toml")
        if os.path.isfile(cfg_path):
            try:
                with open(cfg_path, "rb") as f:
                    self.config = tomllib.load(f)
            except (OSError, ValueError) as e:
                raise SystemExit(f"ibrod_plot: cannot read {cfg_path}: {e}")
        self.summary = {}
        sum_path = os.path.join(path, "summary.json")
        if os.path.isfile(sum_path):
            try:
                with open(sum_path) as f:
                    self.summary = json.load(f)
            except (OSError, ValueError) as e:
                raise SystemExit(f"ibrod_plot: cannot read {sum_path}: {e}")

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

    @property
    def grid(self):
        return grid_text(self.config)

    def label_parts(self):
        parts = []
        if self.excess_link is not None:
            parts.append(f"ΔLk = {self.excess_link}")
        if self.salt_M is not None:
            parts.append(f"Cs = {self.salt_M:g} M")
        if self.grid is not None:
            parts.append(self.grid)
        return parts

    def label(self, with_name=False, leave_out=()):
        parts = [p for p in self.label_parts() if p not in leave_out]
        text = ", ".join(parts) or self.name
        text = f"{text} ({self.name})" if with_name and parts else text
        return text if self.finished is not False else text + " — not finished"


def plot_runs(runs, out, logt=False, title=None):
    """Writes the three-panel figure of `runs` (a list of Run) to `out` (PNG, PDF or SVG)."""
    fig = figure_runs(runs, logt=logt, title=title)
    save(fig, out)
    plt.close(fig)


def figure_runs(runs, logt=False, title=None):
    """The three-panel figure of `runs`: E_total, E_K (log) and writhe against time."""
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True, constrained_layout=True)
    ax_e, ax_k, ax_w = axes
    # what every run shares (ΔLk, Cs, grid) goes into the title, the rest into the labels
    shared = set(runs[0].label_parts()).intersection(*(r.label_parts() for r in runs[1:]))
    shared = [p for p in runs[0].label_parts() if p in shared] if len(runs) > 1 else []
    labels = [r.label(leave_out=shared) for r in runs]
    duplicate = len(set(labels)) < len(labels)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    marks = {}  # legend entries of the marks (not the runs): label -> handle
    for i, run in enumerate(runs):
        c = colors[i % len(colors)]
        ts = run.ts
        t = ts["time_us"]
        ax_e.plot(t, ts["E_total_kT"], color=c, label=run.label(duplicate, leave_out=shared))
        positive = ts["E_kinetic_kT"] > 0
        ax_k.plot(t[positive], ts["E_kinetic_kT"][positive], color=c)
        ax_w.plot(t, ts["writhe"], color=c)

        s = run.summary
        tc = s.get("writhe_convergence_time_us")  # null for a run that did not finish
        if tc is not None:
            ax_w.axvline(tc, color=c, linestyle=":", linewidth=1)
            marks["writhe convergence time"] = Line2D([], [], color="k", linestyle=":",
                                                              linewidth=1)
        for tr in s.get("transients") or []:
            ax_e.plot(tr["time_us"], tr["E_total_kT"], "o", mfc="none", color=c)
            ax_k.plot(tr["time_us"], tr["E_kinetic_kT"], "o", mfc="none", color=c)
            marks["transient state"] = Line2D([], [], color="k", marker="o", mfc="none",
                                                linestyle="none")
        tau, fit = s.get("relaxation_time_us"), s.get("relaxation_fit")
        if tau and fit:
            # the fitted E_K = A exp(−2t/τ) over its window, anchored at the window's last sample
            tw = np.linspace(fit["t_start_us"], fit["t_end_us"], 50)
            last = np.argmin(np.abs(t - fit["t_end_us"]))
            ek_end = ts["E_kinetic_kT"][last]
            if ek_end > 0:
                ax_k.plot(tw, ek_end * np.exp(-2 * (tw - t[last]) / tau), "--", color=c,
                          linewidth=1, label=f"E_K ∝ exp(−2t/τ), τ = {tau:.3g} µs")

    ax_e.set_ylabel("total energy (kT)")
    ax_k.set_ylabel("kinetic energy (kT)")
    log_axis(ax_k, "y")
    ax_w.set_ylabel("writhe")
    ax_w.set_xlabel("time (µs)")
    if logt:
        log_axis(ax_w, "x")
    handles, texts = ax_e.get_legend_handles_labels()
    handles += list(marks.values())
    texts += list(marks.keys())
    ax_e.legend(handles, texts, fontsize="small")
    if ax_k.get_legend_handles_labels()[0]:
        ax_k.legend(fontsize="small")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.grid(True, which="minor", alpha=0.1)
    heading = [title] if title else []
    if shared:
        heading.append(", ".join(shared))
    if heading:
        fig.suptitle("\n".join(heading))
    return fig


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", nargs="+", metavar="RUN_DIR", help="output directories of ibrod run")
    p.add_argument("-o", "--output", required=True,
                   help="figure to write: .png, or vector .pdf / .svg")
    p.add_argument("--logt", action="store_true", help="logarithmic time axis")
    p.add_argument("--title", help="figure title")
    a = p.parse_args(argv)
    output_format(a.output)
    plot_runs([Run(d) for d in a.runs], a.output, logt=a.logt, title=a.title)
    print(a.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
