#!/usr/bin/python3
"""The report of a sweep of ibrod runs (MODEL §7), one markdown page with figures (PNG, or
vector PDF/SVG with --format) in the layout of a paper.

    python/ibrod_report.py RUN_DIR... -o REPORT_DIR [--view oblique] [--ibrod BINARY] [--frames]
                           [--tau-window US] [--format png|pdf|svg] [--html [--html-frames N]]

Writes into REPORT_DIR:
  report.md           the runs; tables with rows ΔLk and columns Cs of the writhe convergence
                      time, the relaxation time τ, the final shapes (class, loops, Wr, closest
                      approach) and the transient states; the figures below
  runs.csv            one row per run: ΔLk, Cs, stop reason, final observables, the analysis
  vs_excess_link.png  E_bend, E_twist, ΔE_electro, Wr and closest approach of the final state
                      against ΔLk, one line per Cs; a marker per run, the line through the mean
                      of the runs at the same (ΔLk, Cs)
  timeseries.png      E_total, E_K (log), Wr and τ(t) against time: one column per ΔLk, one line
                      per run (two runs at the same (ΔLk, Cs): two line styles, named)
  shapes.png          contact sheet: one tile per run (rows ΔLk, columns Cs, a cell with several
                      runs side by side), its name, ΔLk, Cs, time, class and stop reason on the tile
  sampling_N.png      for each group of runs that differ only in their perturbation (a sweep
                      over rod.perturbation_random.seed at one ΔLk, Cs): one picture per final
                      shape class, with its count and energy (report.md: "Perturbation sampling")
(.pdf or .svg instead of .png with --format; the contact sheet stays PNG, as it holds pictures).
  report.html         with --html: the whole report as one self-contained page that opens offline
                      (python/ibrod_html.py): a 3-D view of each run's rod with a time slider,
                      Wr and ΔLk, the tables, the figures (PNG/SVG embedded) and a picture per cell
Titles carry the grid (n³, box) of the runs.

report.md also says, for each (ΔLk, Cs), whether the twisted circle was stable as the stability
test decided (summary.json stability_tests), and brackets the threshold ΔLk per Cs. The grouping
and stability rules are in python/ibrod_study.py.

ΔLk and Cs come from each run's config.toml (rod.excess_link, solvent.salt_M); the numbers from
summary.json after `ibrod analyze` (with --ibrod BINARY the script runs `BINARY analyze` on every
run first, with --frames `analyze --frames`, and `BINARY render` on runs without a picture). A
quantity that presumes equilibrium (writhe convergence time, τ, limiting energies) is shown as
"not finished" for a run whose stop_reason is not "equilibrium". Needs numpy and matplotlib; use
/usr/bin/python3.
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
from ibrod_plot import FORMATS, Run, log_axis, save  # noqa: E402
from ibrod_study import (CIRCLE_WRITHE, circle_stability, class_census,  # noqa: E402
                         perturbation_label, sampling_groups, stability_bracket)
from matplotlib.lines import Line2D  # noqa: E402

DASH = "—"
NOT_ANALYSED = "not analysed"
NOT_FINISHED = "not finished"


def fmt(v, digits=3):
    if v is None:
        return DASH
    if isinstance(v, float):
        if not np.isfinite(v):
            return DASH
        return f"{v:.{digits}g}"
    return str(v)


def analysed(run):
    return "equilibrium_reached" in run.summary


def final(run, key):
    ts = run.ts
    return float(ts[key][-1]) if key in ts.dtype.names else None


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


def tile_caption(run):
    shape = (run.summary.get("shape") or {}).get("class", DASH)
    stop = run.summary.get("stop_reason", "?")
    return f"t = {fmt(final(run, 'time_us'))} µs, {shape}, {stop}"


def draw_tile(fig, nr, nc, idx, run, view):
    """One tile: the run's rendered picture, else a 3-D line drawing of final_state.csv."""
    pic = final_picture(run, view) if run is not None else None
    if run is not None and pic is None:
        ax = fig.add_subplot(nr, nc, idx, projection="3d")
        draw_final_state_3d(ax, run)
        return ax
    ax = fig.add_subplot(nr, nc, idx)
    ax.set_xticks([])
    ax.set_yticks([])
    for sp in ax.spines.values():
        sp.set_visible(False)
    if pic is not None:
        ax.imshow(mpimg.imread(pic))
    else:
        ax.text(0.5, 0.5, DASH, ha="center", va="center", transform=ax.transAxes)
    return ax


def put_caption(ax, text):
    put = ax.text2D if hasattr(ax, "text2D") else ax.text  # text2D on a 3-D axes
    put(0.5, -0.02, text, ha="center", va="top", fontsize="small", transform=ax.transAxes)


def sheet_layout(grid, dlks, css):
    """Tile positions of the contact sheet: {run: (row, column)}, rows ΔLk, columns Cs with as
    many sub-columns as the fullest cell at that Cs (every run gets its own tile), and the
    number of columns and the first column of each Cs."""
    width = {cs: max(len(grid.get((d, cs), [])) for d in dlks) or 1 for cs in css}
    first, col = {}, 0
    for cs in css:
        first[cs], col = col, col + width[cs]
    where = {}
    for i, dlk in enumerate(dlks):
        for cs in css:
            for k, run in enumerate(sorted(grid.get((dlk, cs), []), key=lambda r: r.name)):
                where[run] = (i, first[cs] + k)
    return where, col, first, width


def contact_sheet(grid, dlks, css, view, out, tile_in=3.6, dpi=100):
    """One tile of tile_in × tile_in inches per run (at dpi: 360 px by default), titled with its
    run name, ΔLk and Cs, captioned with its time, class and stop reason; an empty cell holds a
    dash. Returns the tiles as a list of (run, axes)."""
    where, ncol, first, width = sheet_layout(grid, dlks, css)
    nr = len(dlks)
    fig = plt.figure(figsize=(tile_in * ncol, (tile_in + 0.7) * nr))
    gs = fig.add_gridspec(nr, ncol)
    tiles = []
    for run, (i, j) in sorted(where.items(), key=lambda kv: kv[1]):
        pic = final_picture(run, view)
        if pic is None:
            ax = fig.add_subplot(gs[i, j], projection="3d")
            draw_final_state_3d(ax, run)
        else:
            ax = fig.add_subplot(gs[i, j])
            ax.set_xticks([])
            ax.set_yticks([])
            for sp in ax.spines.values():
                sp.set_visible(False)
            ax.imshow(mpimg.imread(pic))
        ax.set_title(f"{run.name}\nΔLk = {run.excess_link}, Cs = {run.salt_M:g} M",
                     fontsize="medium")
        put = ax.text2D if hasattr(ax, "text2D") else ax.text  # text2D on a 3-D axes
        put(0.5, -0.02, tile_caption(run), ha="center", va="top", fontsize="medium",
            transform=ax.transAxes)
        tiles.append((run, ax))
    for i, dlk in enumerate(dlks):  # empty cells
        for cs in css:
            if not grid.get((dlk, cs)):
                ax = fig.add_subplot(gs[i, first[cs]])
                ax.set_axis_off()
                ax.text(0.5, 0.5, f"ΔLk = {dlk}, Cs = {cs:g} M\n{DASH}", ha="center",
                        va="center", transform=ax.transAxes, fontsize="medium")
    grids = sorted({r.grid for r in where if r.grid})
    if grids:
        fig.suptitle("; ".join(grids))
    fig.tight_layout()
    fig.savefig(out, dpi=dpi)
    plt.close(fig)
    return tiles


def relaxed_circle_electro(grid, cs):
    """E_electro of a run at salt cs that stays circular and reached equilibrium, or None."""
    for (dlk, c), runs in sorted(grid.items()):
        for r in runs:
            if c == cs and r.summary.get("stays_circular") and r.finished:
                return final(r, "E_electro_kT")
    return None


def grids_title(grid):
    """The grids of the runs ("16³ grid, box 200 Å"), for a figure title."""
    return "; ".join(sorted({r.grid for runs in grid.values() for r in runs if r.grid}))


def against_excess_link(grid, dlks, css, out):
    """Final-state quantities against ΔLk: a marker per run (hollow: did not finish), the line of
    each Cs through the mean of the runs at the same (ΔLk, Cs), so that two runs at one point
    never draw a vertical line. Returns the figure's axes (before closing)."""
    panels = [
        ("E_bend (kT)", lambda r, cs: final(r, "E_bend_kT")),
        ("E_twist (kT)", lambda r, cs: final(r, "E_twist_kT")),
        ("ΔE_electro (kT), vs the initial circle", lambda r, cs: final(r, "dE_electro_kT")),
        ("ΔE_electro (kT), vs the relaxed circle",
         lambda r, cs: (None if relaxed_circle_electro(grid, cs) is None
                        else final(r, "E_electro_kT") - relaxed_circle_electro(grid, cs))),
        ("writhe", lambda r, cs: final(r, "writhe")),
        ("closest approach (Å)", lambda r, cs: final(r, "closest_approach_A")),
    ]
    fig, axes = plt.subplots(2, 3, figsize=(12, 6.5), constrained_layout=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (ylabel, value) in zip(axes.flat, panels):
        for k, cs in enumerate(css):
            c = colors[k % len(colors)]
            xs, means, points = [], [], []
            for dlk in dlks:
                vs = []
                for run in grid.get((dlk, cs), []):
                    v = value(run, cs)
                    if v is not None and np.isfinite(v):
                        vs.append(v)
                        points.append((dlk, v, run.finished is True))
                if vs:
                    xs.append(dlk)
                    means.append(float(np.mean(vs)))
            if not xs:
                continue
            ax.plot(xs, means, "-", color=c, label=f"Cs = {cs:g} M")
            for x, y, d in points:
                ax.plot([x], [y], "o", color=c, mfc=c if d else "none")
        if not any(ax.get_lines()):
            ax.text(0.5, 0.5, "no run that stays circular\nand reached equilibrium",
                    ha="center", va="center", transform=ax.transAxes, fontsize="small")
        ax.set_xlabel("ΔLk")
        ax.set_ylabel(ylabel)
        ax.set_xticks(dlks)
        ax.grid(True, alpha=0.3)
    handles, texts = axes.flat[0].get_legend_handles_labels()
    handles += [Line2D([], [], color="k", marker="o", linestyle="none"),
                Line2D([], [], color="k", marker="o", mfc="none", linestyle="none"),
                Line2D([], [], color="k")]
    texts += ["a run, finished", "a run, not finished",
              "mean of the runs at one (ΔLk, Cs)"]
    axes.flat[0].legend(handles, texts, fontsize="small")
    if grids_title(grid):
        fig.suptitle(grids_title(grid))
    save(fig, out, dpi=100)
    plt.close(fig)
    return axes


def timeseries_panels(grid, dlks, css, out):
    """Rows E_total, E_K (log), Wr, τ(t); one column per ΔLk, one line per Cs."""
    nc = len(dlks)
    fig, axes = plt.subplots(4, nc, figsize=(3.6 * nc + 0.6, 9), sharex="col", squeeze=False,
                             constrained_layout=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    styles = ["-", "--", "-.", (0, (1, 1))]
    for j, dlk in enumerate(dlks):
        ax_e, ax_k, ax_w, ax_t = axes[:, j]
        marks = {}
        for k, cs in enumerate(css):
            runs = sorted(grid.get((dlk, cs), []), key=lambda r: r.name)
            for n, run in enumerate(runs):  # two runs at one (ΔLk, Cs): two styles, named
                c, ls = colors[k % len(colors)], styles[n % len(styles)]
                t = run.ts["time_us"]
                lab = f"Cs = {cs:g} M" + (f" ({run.name})" if len(runs) > 1 else "")
                lab += "" if run.finished is not False else f" ({NOT_FINISHED})"
                ax_e.plot(t, run.ts["E_total_kT"], color=c, linestyle=ls, label=lab)
                ek = run.ts["E_kinetic_kT"]
                ax_k.plot(t[ek > 0], ek[ek > 0], color=c, linestyle=ls)
                ax_w.plot(t, run.ts["writhe"], color=c, linestyle=ls)
                loc = [w for w in run.summary.get("relaxation_time_local_us") or [] if w["tau_us"] > 0]
                if loc:
                    ax_t.plot([0.5 * (w["t_start_us"] + w["t_end_us"]) for w in loc],
                              [w["tau_us"] for w in loc], "o", linestyle=ls, color=c, markersize=3)
                    marks["τ(t) on a window"] = Line2D([], [], color="k", marker="o",
                                                         markersize=3, linestyle="none")
                settled = run.summary.get("contacts_settled_time_us")
                if settled is not None:
                    ax_k.axvline(settled, color=c, linestyle=":", linewidth=1)
                    marks["contacts settle"] = Line2D([], [], color="k", linestyle=":",
                                                              linewidth=1)
        ax_e.set_title(f"ΔLk = {dlk}")
        if ax_k.get_lines():
            log_axis(ax_k, "y")
        ax_t.set_xlabel("time (µs)")
        handles, texts = ax_e.get_legend_handles_labels()
        ax_e.legend(handles + list(marks.values()), texts + list(marks.keys()), fontsize="x-small")
        for ax in axes[:, j]:
            ax.grid(True, alpha=0.3)
    axes[0, 0].set_ylabel("E_total (kT)")
    axes[1, 0].set_ylabel("E_K (kT); dotted: contacts settle")
    axes[2, 0].set_ylabel("writhe")
    axes[3, 0].set_ylabel("τ(t) (µs)")
    if grids_title(grid):
        fig.suptitle(grids_title(grid))
    save(fig, out, dpi=100)
    plt.close(fig)
    return axes


def table(grid, dlks, css, cell):
    head = "| ΔLk | " + " | ".join(f"Cs = {cs:g} M" for cs in css) + " |"
    rows = [head, "|---|" + "---|" * len(css)]
    for dlk in dlks:
        cells = []
        for cs in css:
            runs = grid.get((dlk, cs), [])
            cells.append("<br>".join(cell(r) if analysed(r) else NOT_ANALYSED for r in runs)
                         if runs else DASH)
        rows.append(f"| {dlk} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def needs_equilibrium(cell):
    """A table cell of a quantity that presumes equilibrium: "not finished" otherwise."""
    return lambda r: cell(r) if r.finished else NOT_FINISHED


def writhe_cell(r):
    return fmt(r.summary.get("writhe_convergence_time_us"))


def tau_cell(r):
    s = r.summary
    tau = s.get("relaxation_time_table_us")
    if tau is None:
        return s.get("relaxation_contacts_note") or DASH
    if s.get("relaxation_time_method") == "after_last_contact":
        fit = s.get("relaxation_contacts_fit") or {}
        return f"{fmt(tau)} (R² {fmt(fit.get('r2'), 3)})"
    fit = s.get("relaxation_fit") or {}
    return f"{fmt(tau)}† (R² {fmt(fit.get('r2'), 3)})"


def shape_cell(r):
    sh = r.summary.get("shape") or {}
    cls = sh.get("class", DASH)
    if sh.get("class") == "plectonemic":
        cls += f", two-ply {fmt(sh.get('interwound_length_A'))} Å"
    return (f"{cls}, {fmt(sh.get('loops'))} loops, Wr {fmt(final(r, 'writhe'), 3)}, "
            f"{fmt(final(r, 'closest_approach_A'), 3)} Å")


def transients_cell(r):
    tr = r.summary.get("transients")
    if tr is None:
        return DASH
    if not tr:
        return "none"
    frames = r.summary.get("shape_frames") or []

    def named(t):  # the class of the frame nearest to the transient (with --frames)
        if not frames:
            return ""
        f = min(frames, key=lambda f: abs(f["time_us"] - t))
        return f", {f['class']}"
    return "; ".join(f"{fmt(x['time_us'])} µs, {fmt(x['E_total_kT'], 5)} kT{named(x['time_us'])}"
                     for x in tr)


def sampling_sheet(census, view, out):
    """One tile per shape class of a sampling group: the representative's picture, the count and
    the representative's final energy."""
    nc = len(census)
    fig = plt.figure(figsize=(3.0 * nc + 0.6, 3.6))
    for j, e in enumerate(census):
        rep = e["representative"]
        ax = draw_tile(fig, 1, nc, j + 1, rep, view)
        ax.set_title(f"{e['class']} × {e['count']}", fontsize="small")
        done = "" if rep.finished else f", {NOT_FINISHED}"
        put_caption(ax, f"{perturbation_label(rep)}: E_total = {fmt(final(rep, 'E_total_kT'), 5)} kT"
                        f"{done}")
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    plt.close(fig)


def energy_range(e):
    if e["E_min_kT"] is None:
        return DASH
    if fmt(e["E_min_kT"], 5) == fmt(e["E_max_kT"], 5):
        return fmt(e["E_min_kT"], 5)
    return f"{fmt(e['E_min_kT'], 5)} … {fmt(e['E_max_kT'], 5)}"


def sampling_section(groups, view, outdir):
    """report.md lines and figures of the perturbation-sampling groups."""
    md = []
    for i, group in enumerate(groups, 1):
        r0 = group[0]
        census = class_census(group)
        name = f"sampling_{i}.png"
        sampling_sheet(census, view, os.path.join(outdir, name))
        unfinished = sum(1 for r in group if not r.finished)
        md += [f"## Perturbation sampling: ΔLk = {fmt(r0.excess_link)}, Cs = {fmt(r0.salt_M)} M", "",
               f"{len(group)} runs that differ only in their perturbation (`rod.perturbation`, "
               f"`rod.perturbation_random`), {len(census)} final shape class"
               f"{'es' if len(census) != 1 else ''}"
               + (f"; {unfinished} run{'s' if unfinished != 1 else ''} did not reach equilibrium "
                  "(counted by the class of the state where they stopped)" if unfinished else "")
               + ". Energies: final E_total; the picture shows the class's run of lowest energy "
               "among those at equilibrium.", "",
               "| class | runs | at equilibrium | perturbations | E_total (kT) | Wr | picture |",
               "|---|---|---|---|---|---|---|"]
        for e in census:
            rep = e["representative"]
            wr = (fmt(e["writhe_min"], 3) if fmt(e["writhe_min"], 3) == fmt(e["writhe_max"], 3)
                  else f"{fmt(e['writhe_min'], 3)} … {fmt(e['writhe_max'], 3)}")
            md.append(f"| {e['class']} | {e['count']} | {e['equilibrium']} | "
                      f"{', '.join(e['labels'])} | {energy_range(e)} | {wr} | "
                      f"{perturbation_label(rep)} ({rep.name}) |")
        md += ["", f"![Perturbation sampling {i}]({name})", ""]
    return md


def stability_cell(r):
    v = circle_stability(r)
    if v["verdict"] in ("stable", "unstable"):
        de = v["dE_kT"]
        tol = r.config.get("time", {}).get("stability_tolerance_kT")
        kick = f"{fmt(v['kick_A'])} Å, " if v.get("kick_A") is not None else ""
        text = (f"{v['verdict']} (ΔE {de:+.3g} kT"
                + (f", tolerance {fmt(tol)} kT" if tol is not None else "")
                + f"; probe at {fmt(v['time_us'])} µs, seed {v['seed']}, "
                f"{kick}{fmt(v['amplitude_rad'])} rad")
        if v["verdict"] == "unstable":
            text += f"; Wr → {fmt(v['writhe_after'], 3)}"
        return text + ")"
    if v["verdict"] == "left_circle":
        return f"unstable: left the circle untested at {fmt(v['time_us'])} µs"
    if v["verdict"] == "perturbed_away":
        return f"undecided: perturbed away from the circle before a test ({fmt(v['time_us'])} µs)"
    return f"not tested: {v['reason']}"


def stability_lines(grid, dlks, css):
    """The bracket of the threshold ΔLk per Cs."""
    lines = []
    for cs in css:
        verdicts = {}
        for dlk in dlks:
            vs = {circle_stability(r)["verdict"] for r in grid.get((dlk, cs), [])}
            if len(vs) == 1:
                verdicts[dlk] = vs.pop()
            elif vs:  # runs at one ΔLk that disagree: neither bound
                verdicts[dlk] = "mixed"
        lo, hi, ok = stability_bracket(verdicts)
        if lo is None and hi is None:
            text = "no run decides"
        elif not ok:
            text = (f"not one threshold: stable up to ΔLk = {lo}, but unstable already at "
                    f"ΔLk = {hi}")
        elif hi is None:
            text = f"stable up to ΔLk = {lo} (no unstable run: the threshold lies above)"
        elif lo is None:
            text = f"unstable from ΔLk = {hi} (no stable run: the threshold lies below)"
        else:
            text = f"stable up to ΔLk = {lo}, unstable from ΔLk = {hi}: the threshold lies in ({lo}, {hi}]"
        lines.append(f"- Cs = {cs:g} M: {text}")
    return lines


def maybe_run(binary, args):
    r = subprocess.run([binary] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        print(f"ibrod_report: '{' '.join([binary] + args)}' failed ({r.returncode}): {r.stderr.strip()}",
              file=sys.stderr)


def write_runs_csv(runs, path):
    fields = ["run", "excess_link", "salt_M", "stop_reason", "equilibrium_reached", "time_us",
              "writhe", "twist", "E_bend_kT", "E_twist_kT", "dE_electro_kT", "E_total_kT",
              "E_kinetic_kT", "closest_approach_A", "shape", "loops", "crossings",
              "interwound_length_A", "writhe_convergence_time_us", "relaxation_time_table_us",
              "relaxation_time_method", "relaxation_time_us", "relaxation_time_contacts_us",
              "transients", "kinetic_power_law_exponent", "perturbation", "circle_stability"]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(fields)
        for r in runs:
            s, sh = r.summary, r.summary.get("shape") or {}
            tr = s.get("transients")
            w.writerow([r.path, r.excess_link, r.salt_M, s.get("stop_reason"),
                        s.get("equilibrium_reached"), final(r, "time_us"), final(r, "writhe"),
                        final(r, "twist"), final(r, "E_bend_kT"), final(r, "E_twist_kT"),
                        final(r, "dE_electro_kT"), final(r, "E_total_kT"), final(r, "E_kinetic_kT"),
                        final(r, "closest_approach_A"), sh.get("class"), sh.get("loops"),
                        sh.get("crossings"), sh.get("interwound_length_A"),
                        s.get("writhe_convergence_time_us"), s.get("relaxation_time_table_us"),
                        s.get("relaxation_time_method"), s.get("relaxation_time_us"),
                        s.get("relaxation_time_contacts_us"),
                        len(tr) if tr is not None else None, s.get("kinetic_power_law_exponent"),
                        perturbation_label(r), circle_stability(r)["verdict"]])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", nargs="+", metavar="RUN_DIR", help="output directories of ibrod run")
    p.add_argument("-o", "--output", required=True, metavar="REPORT_DIR", help="directory to write")
    p.add_argument("--view", default="oblique", help="which rendered view goes into the contact sheet")
    p.add_argument("--ibrod", metavar="BINARY",
                   help="ibrod binary: analyse every run and render those without a picture first")
    p.add_argument("--frames", action="store_true",
                   help="with --ibrod: `analyze --frames` (the shape of every frame names transients)")
    p.add_argument("--tau-window", metavar="US",
                   help="with --ibrod: `analyze --tau-window US` (windows of τ(t), µs; default 1)")
    p.add_argument("--format", choices=FORMATS, default="png",
                   help="format of the plots (vs_excess_link, timeseries): png, or vector pdf/svg; "
                        "the contact sheet is always PNG")
    p.add_argument("--html", action="store_true",
                   help="also REPORT_DIR/report.html: one self-contained page with a 3-D view of "
                        "each run's rod (rotate, zoom, time slider), the tables and the figures "
                        "(python/ibrod_html.py)")
    p.add_argument("--html-frames", type=int, default=100, metavar="N",
                   help="with --html: at most N frames of each trajectory in the 3-D view")
    a = p.parse_args(argv)

    if a.ibrod:
        for d in a.runs:
            maybe_run(a.ibrod, ["analyze", "--quiet", d] + (["--frames"] if a.frames else []) +
                      (["--tau-window", a.tau_window] if a.tau_window else []))
            if not glob.glob(os.path.join(d, "render", f"rod_{a.view}_t*.png")):
                maybe_run(a.ibrod, ["render", d, "--views", a.view, "--size", "360x360"])

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
        vs, tsname = f"vs_excess_link.{a.format}", f"timeseries.{a.format}"
        against_excess_link(grid, dlks, css, os.path.join(a.output, vs))
        timeseries_panels(grid, dlks, css, os.path.join(a.output, tsname))
        tiles = contact_sheet(grid, dlks, css, a.view, os.path.join(a.output, "shapes.png"))
        figures = [
            ("Final state against ΔLk", vs,
             "E_bend, E_twist, the electrostatic energy relative to the initial circle at the same "
             "Cs (`dE_electro_kT`) and relative to the relaxed circle at the same Cs (the final "
             "state of a run of the sweep at that Cs that stays circular and reached equilibrium; "
             "empty when there is none), writhe and closest approach. A marker per run; hollow: "
             "runs that did not reach equilibrium (their last state, not a limit). The line of "
             "each Cs joins the means of the runs at the same (ΔLk, Cs)."),
            ("Energy, kinetic energy, writhe and τ(t) against time", tsname,
             "One column per ΔLk, one line per run (runs at the same Cs: one colour, line styles "
             "and names tell them apart). τ(t) = −2/(d ln E_K/dt) on windows of "
             "`relaxation_time_local_window_us`; dotted: the contacts stop changing."),
            ("Contact sheet", "shapes.png",
             f"{len(tiles)} tiles, one per run (rows ΔLk, columns Cs; several runs at one "
             "(ΔLk, Cs) side by side): run name, ΔLk, Cs, time of the state, shape class and "
             "stop reason."),
        ]
    write_runs_csv(runs, os.path.join(a.output, "runs.csv"))

    unanalysed = [r.path for r in runs if not analysed(r)]
    md = ["# ibrod sweep report", ""]
    md.append(f"{len(runs)} runs. ΔLk = {', '.join(map(str, dlks)) or DASH}; "
              f"Cs = {', '.join(f'{c:g}' for c in css) or DASH} M. "
              f"\"{NOT_FINISHED}\": the run stopped before reaching equilibrium (summary.json "
              "stop_reason is not \"equilibrium\"), so a number that presumes one is not given.")
    md += ["", "| run | ΔLk | Cs (M) | stop | t (µs) | Wr | closest approach (Å) | E_total (kT) | shape |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        md.append(f"| {r.name} | {fmt(r.excess_link)} | {fmt(r.salt_M)} | "
                  f"{r.summary.get('stop_reason', DASH)} | {fmt(final(r, 'time_us'))} | "
                  f"{fmt(final(r, 'writhe'), 4)} | {fmt(final(r, 'closest_approach_A'), 4)} | "
                  f"{fmt(final(r, 'E_total_kT'), 5)} | "
                  f"{(r.summary.get('shape') or {}).get('class', DASH)} |")
    md += ["", "## Writhe convergence time (µs)", "",
           "Largest t with |Wr(t) − Wr(∞)| > δ, Wr(∞) the final writhe (docs/analysis.md).", "",
           table(grid, dlks, css, needs_equilibrium(writhe_cell)),
           "", "## Relaxation time τ (µs)", "",
           "E_K ∝ exp(−2t/τ) fitted on every row after the set of contacts stops changing "
           "(`relaxation_time_contacts_us`; R² of the log-linear fit). † no trajectory frames: the "
           "final-window fit (`relaxation_time_us`) instead. τ(t) is in the time-series figure.", "",
           table(grid, dlks, css, needs_equilibrium(tau_cell)),
           "", "## Final shapes", "",
           "Class (docs/analysis.md \"Shapes\"), terminal loops, writhe and closest approach of "
           "the last state (of an unfinished run: where it stopped).", "",
           table(grid, dlks, css, shape_cell),
           "", "## Transient states", "",
           "Local minima of E_K on plateaus of the total energy: time, plateau energy and (with "
           "`analyze --frames`) the shape class there.", "",
           table(grid, dlks, css, transients_cell), "",
           "## Stability of the twisted circle", "",
           "Whether the circle was stable, as the stability test decided (`time.stability_*`, "
           "summary.json `stability_tests`): the first test, when it found the rod still "
           f"circular (|Wr| < {CIRCLE_WRITHE}); ΔE is the lowest the kicked copy's E_total "
           "came relative to the unperturbed continuation's during the probe (below "
           "−tolerance: unstable). \"left the circle untested\": a run without perturbation whose "
           f"|Wr| grew past {CIRCLE_WRITHE} before E_K fell below `time.stop_kinetic_kT` "
           "(unstable without the test's help); \"undecided\": a perturbed run did so (the "
           "perturbation may have been larger than the circle's basin).", "",
           table(grid, dlks, css, stability_cell), ""] + stability_lines(grid, dlks, css) + [""]
    groups = sampling_groups(runs)
    md += sampling_section(groups, a.view, a.output)
    if unanalysed:
        md += ["Not analysed (run `ibrod analyze DIR`, or pass `--ibrod BINARY`): " +
               ", ".join(unanalysed), ""]
    for caption, name, text in figures:
        md += [f"## {caption}", "", text, "", f"![{caption}]({name})", ""]
    with open(os.path.join(a.output, "report.md"), "w") as f:
        f.write("\n".join(md))
    print(os.path.join(a.output, "report.md"))
    if a.html:
        from ibrod_html import write_html
        page = os.path.join(a.output, "report.html")
        write_html(page, "\n".join(md), a.output, a.runs, max(1, a.html_frames))
        print(page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
