#!/usr/bin/python3
"""A report on a sweep of ibrod runs (MODEL §7): final shapes, energies, writhe and closest
approach against ΔLk, time series, and tables of writhe convergence and relaxation times.

    python/ibrod_report.py RUN_DIR... -o REPORT_DIR [--view oblique] [--ibrod BINARY]

Writes into REPORT_DIR:
  report.md         the runs, and tables (rows ΔLk, columns Cs) of the writhe convergence time,
                    the relaxation time τ and the transient states, with the figures below
  runs.csv          one row per run: directory, ΔLk, Cs, stop reason, final observables and the
                    analysis numbers
  shapes.png        contact sheet of the final shapes: rows ΔLk, columns Cs (the PNG that
                    `ibrod render` wrote for --view if there is one, else a 3-D line drawing of
                    final_state.csv)
  vs_excess_link.png  final total and elastic energy, writhe and closest approach against ΔLk,
                    one line per Cs
  timeseries_Cs<c>.png  total energy, kinetic energy and writhe against time, one per Cs

ΔLk and Cs come from each run's config.toml (rod.excess_link, solvent.salt_M); the writhe
convergence and relaxation times from summary.json after `ibrod analyze` (with --ibrod BINARY the
script runs `BINARY analyze` on runs not yet analysed and `BINARY render` on runs without a
picture). Needs numpy and matplotlib; use /usr/bin/python3.
"""
import argparse
import csv
import glob
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ibrod_plot import Run, plot_runs  # noqa: E402

DASH = "—"
NOT_ANALYSED = "not analysed"


def fmt(v, digits=3):
    if v is None:
        return DASH
    if isinstance(v, float):
        if not np.isfinite(v):
            return DASH
        return f"{v:.{digits}g}"
    return str(v)


def final_picture(run, view):
    """The latest DIR/render/rod_<view>_t<time>.png, or None."""
    best, best_t = None, -1.0
    for f in glob.glob(os.path.join(run.path, "render", f"rod_{view}_t*.png")):
        m = re.search(r"_t([0-9.eE+-]+)\.png$", f)
        if m:
            try:
                t = float(m.group(1))
            except ValueError:
                continue
            if t > best_t:
                best, best_t = f, t
    return best


def draw_final_state_3d(ax, run):
    """The centreline of final_state.csv as a thick 3-D line (when no rendered PNG exists)."""
    path = os.path.join(run.path, "final_state.csv")
    if not os.path.isfile(path):
        ax.text2D(0.5, 0.5, "no final_state.csv", ha="center", transform=ax.transAxes)
        ax.set_axis_off()
        return
    s = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))
    x, y, z = (np.append(s[c], s[c][0]) for c in ("x_A", "y_A", "z_A"))
    ax.plot(x, y, z, linewidth=3, color="#3c69c8")
    c = np.array([x.mean(), y.mean(), z.mean()])
    r = max(np.ptp(x), np.ptp(y), np.ptp(z)) / 2 or 1.0
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=35, azim=-55)
    ax.set_axis_off()


def contact_sheet(grid, dlks, css, view, out):
    nr, nc = len(dlks), len(css)
    fig = plt.figure(figsize=(2.6 * nc + 0.8, 2.6 * nr + 0.6))
    for i, dlk in enumerate(dlks):
        for j, cs in enumerate(css):
            runs = grid.get((dlk, cs), [])
            idx = i * nc + j + 1
            pic = final_picture(runs[0], view) if runs else None
            if runs and pic is None:
                ax = fig.add_subplot(nr, nc, idx, projection="3d")
                draw_final_state_3d(ax, runs[0])
            else:
                ax = fig.add_subplot(nr, nc, idx)
                ax.set_xticks([])
                ax.set_yticks([])
                for sp in ax.spines.values():
                    sp.set_visible(False)
                if pic is not None:
                    ax.imshow(mpimg.imread(pic))
                else:
                    ax.text(0.5, 0.5, DASH, ha="center", va="center", transform=ax.transAxes)
            title = f"ΔLk = {dlk}, Cs = {cs:g} M"
            if len(runs) > 1:
                title += f" (+{len(runs) - 1})"
            ax.set_title(title, fontsize="small")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)


def final(run, key):
    ts = run.ts
    return float(ts[key][-1]) if key in ts.dtype.names else None


def against_excess_link(grid, dlks, css, out):
    panels = [
        ("total energy (kT)", lambda r: final(r, "E_total_kT")),
        ("bend + twist energy (kT)",
         lambda r: final(r, "E_bend_kT") + final(r, "E_twist_kT")),
        ("writhe", lambda r: final(r, "writhe")),
        ("closest approach (Å)", lambda r: final(r, "closest_approach_A")),
    ]
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), constrained_layout=True)
    for ax, (ylabel, value) in zip(axes.flat, panels):
        for cs in css:
            xs, ys = [], []
            for dlk in dlks:
                for run in grid.get((dlk, cs), []):
                    v = value(run)
                    if v is not None and np.isfinite(v):
                        xs.append(dlk)
                        ys.append(v)
            if xs:
                ax.plot(xs, ys, "o-", label=f"Cs = {cs:g} M")
        ax.set_xlabel("ΔLk")
        ax.set_ylabel(ylabel)
        ax.set_xticks(dlks)
        ax.grid(True, alpha=0.3)
    axes.flat[0].legend(fontsize="small")
    fig.savefig(out, dpi=110)
    plt.close(fig)


def table(grid, dlks, css, cell):
    head = "| ΔLk | " + " | ".join(f"Cs = {cs:g} M" for cs in css) + " |"
    rule = "|---|" + "---|" * len(css)
    rows = [head, rule]
    for dlk in dlks:
        cells = []
        for cs in css:
            runs = grid.get((dlk, cs), [])
            cells.append("<br>".join(cell(r) if "writhe_convergence_time_us" in r.summary
                                     else NOT_ANALYSED for r in runs) if runs else DASH)
        rows.append(f"| {dlk} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def maybe_run(binary, args):
    r = subprocess.run([binary] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        print(f"ibrod_report: '{' '.join([binary] + args)}' failed ({r.returncode}): {r.stderr.strip()}",
              file=sys.stderr)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", nargs="+", metavar="RUN_DIR", help="output directories of ibrod run")
    p.add_argument("-o", "--output", required=True, metavar="REPORT_DIR", help="directory to write")
    p.add_argument("--view", default="oblique", help="which rendered view goes into the contact sheet")
    p.add_argument("--ibrod", metavar="BINARY",
                   help="ibrod binary: analyse and render the runs that lack it first")
    a = p.parse_args(argv)

    if a.ibrod:
        for d in a.runs:
            sp = os.path.join(d, "summary.json")
            analysed = False
            if os.path.isfile(sp):
                with open(sp) as f:
                    analysed = '"writhe_convergence_time_us"' in f.read()
            if not analysed:
                maybe_run(a.ibrod, ["analyze", "--quiet", d])
            if not glob.glob(os.path.join(d, "render", f"rod_{a.view}_t*.png")):
                maybe_run(a.ibrod, ["render", d, "--views", a.view, "--size", "400x400"])

    runs = [Run(d) for d in a.runs]
    os.makedirs(a.output, exist_ok=True)
    grid = {}
    for r in runs:
        if r.excess_link is None or r.salt_M is None:
            print(f"ibrod_report: {r.path}: no rod.excess_link / solvent.salt_M in config.toml; "
                  "left out of the ΔLk × Cs tables", file=sys.stderr)
            continue
        grid.setdefault((r.excess_link, r.salt_M), []).append(r)
    dlks = sorted({k[0] for k in grid})
    css = sorted({k[1] for k in grid})

    figures = []
    if grid:
        contact_sheet(grid, dlks, css, a.view, os.path.join(a.output, "shapes.png"))
        against_excess_link(grid, dlks, css, os.path.join(a.output, "vs_excess_link.png"))
        figures += [("Final shapes (rows ΔLk, columns Cs)", "shapes.png"),
                    ("Final energies, writhe and closest approach against ΔLk", "vs_excess_link.png")]
        for cs in css:
            members = [r for dlk in dlks for r in grid.get((dlk, cs), [])]
            name = f"timeseries_Cs{cs:g}.png"
            plot_runs(members, os.path.join(a.output, name), title=f"Cs = {cs:g} M")
            figures.append((f"Energy, kinetic energy and writhe against time, Cs = {cs:g} M", name))

    # runs.csv
    fields = ["run", "excess_link", "salt_M", "stop_reason", "time_us", "writhe", "twist",
              "E_total_kT", "E_kinetic_kT", "closest_approach_A", "writhe_convergence_time_us",
              "relaxation_time_us", "relaxation_fit_r2", "transients", "kinetic_power_law_exponent"]
    with open(os.path.join(a.output, "runs.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(fields)
        for r in runs:
            s = r.summary
            fit = s.get("relaxation_fit") or {}
            tr = s.get("transients")
            w.writerow([r.path, r.excess_link, r.salt_M, s.get("stop_reason"), final(r, "time_us"),
                        final(r, "writhe"), final(r, "twist"), final(r, "E_total_kT"),
                        final(r, "E_kinetic_kT"), final(r, "closest_approach_A"),
                        s.get("writhe_convergence_time_us"), s.get("relaxation_time_us"),
                        fit.get("r2"), len(tr) if tr is not None else None,
                        s.get("kinetic_power_law_exponent")])

    # report.md
    unanalysed = [r.path for r in runs if "writhe_convergence_time_us" not in r.summary]

    def tau_cell(r):
        s = r.summary
        tau = s.get("relaxation_time_us")
        if tau is None:
            return DASH
        fit = s.get("relaxation_fit") or {}
        star = "" if s.get("stop_reason") == "equilibrium" else "*"
        return f"{fmt(tau)}{star} (R² {fmt(fit.get('r2'), 4)})"

    def transients_cell(r):
        tr = r.summary.get("transients")
        if tr is None:
            return DASH
        if not tr:
            return "none"
        return "; ".join(f"{fmt(x['time_us'])} µs, {fmt(x['E_total_kT'], 5)} kT" for x in tr)

    md = ["# ibrod sweep report", ""]
    md.append(f"{len(runs)} runs. ΔLk = {', '.join(map(str, dlks)) or DASH}; "
              f"Cs = {', '.join(f'{c:g}' for c in css) or DASH} M.")
    md.append("")
    md.append("| run | ΔLk | Cs (M) | stop | t (µs) | Wr | closest approach (Å) | E_total (kT) |")
    md.append("|---|---|---|---|---|---|---|---|")
    for r in runs:
        md.append(f"| {r.name} | {fmt(r.excess_link)} | {fmt(r.salt_M)} | "
                  f"{r.summary.get('stop_reason', DASH)} | {fmt(final(r, 'time_us'))} | "
                  f"{fmt(final(r, 'writhe'), 4)} | {fmt(final(r, 'closest_approach_A'), 4)} | "
                  f"{fmt(final(r, 'E_total_kT'), 5)} |")
    md += ["", "## Writhe convergence time (µs)", "",
           "Largest t with |Wr(t) − Wr(∞)| > δ, Wr(∞) the final writhe (docs/analysis.md).", "",
           table(grid, dlks, css, lambda r: fmt(r.summary.get("writhe_convergence_time_us"))),
           "", "## Relaxation time τ (µs)", "",
           "E_K ∝ exp(−2t/τ) fitted on the final approach; R² of the log-linear fit. "
           "* the run stopped before reaching equilibrium (E_K above time.stop_kinetic_kT): τ "
           "describes its last stretch only.", "",
           table(grid, dlks, css, tau_cell),
           "", "## Transient states", "",
           "Local minima of E_K on plateaus of the total energy: time and plateau energy.", "",
           table(grid, dlks, css, transients_cell), ""]
    if unanalysed:
        md += ["Not analysed (run `ibrod analyze DIR`, or pass `--ibrod BINARY`): " +
               ", ".join(unanalysed), ""]
    for caption, name in figures:
        md += [f"## {caption}", "", f"![{caption}]({name})", ""]
    with open(os.path.join(a.output, "report.md"), "w") as f:
        f.write("\n".join(md))
    print(os.path.join(a.output, "report.md"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
