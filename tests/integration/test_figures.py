#!/usr/bin/python3
"""python/ibrod_plot.py and python/ibrod_report.py on synthetic run directories (no simulation):
log axes carry at least two labelled ticks, every series and mark has a legend entry, titles and
labels carry ΔLk, Cs and the grid, two runs at one (ΔLk, Cs) draw no vertical line, PDF/SVG output
is written, and the contact sheet has one tile per run.

    /usr/bin/python3 -m pytest -q tests/integration/test_figures.py

Registered in CTest (label integration) by tests/CMakeLists.txt.
"""
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import ibrod_plot  # noqa: E402
import ibrod_report  # noqa: E402

COLUMNS = ["time_us", "E_total_kT", "E_kinetic_kT", "writhe", "twist", "E_bend_kT", "E_twist_kT",
           "E_electro_kT", "dE_electro_kT", "closest_approach_A"]


def make_run(root, name, dlk, cs, ek_span=1e4, n=16, finished=True, seed=0):
    """A run directory with a decaying E_K spanning `ek_span` (ratio first/last), a writhe rising
    to ~ΔLk/2, a transient, a writhe convergence time and an E_K fit in summary.json."""
    import json
    d = os.path.join(root, name)
    os.makedirs(d)
    t = np.linspace(0, 2.0, 41)
    ek = 10.0 * ek_span ** (-t / t[-1])
    wr = 0.5 * dlk * (1 - np.exp(-3 * t)) + 0.01 * seed
    rows = np.column_stack([t, 100 - 5 * t + ek, ek, wr, dlk - wr, 20 + 5 * t + seed,
                            30 - 5 * t, 10 + t, t, 60 - 10 * t])
    np.savetxt(os.path.join(d, "timeseries.csv"), rows, delimiter=",", header=",".join(COLUMNS),
               comments="")
    with open(os.path.join(d, "config.toml"), "w") as f:
        f.write(f"[grid]\nn = {n}\nbox_A = 200.0\n\n[rod]\nexcess_link = {dlk}\n\n"
                f"[solvent]\nsalt_M = {cs}\n")
    s = {"stop_reason": "equilibrium" if finished else "end_time",
         "equilibrium_reached": finished,
         "writhe_convergence_time_us": 1.2 if finished else None,
         "relaxation_time_us": 0.5 if finished else None,
         "relaxation_fit": {"t_start_us": 1.0, "t_end_us": 2.0} if finished else None,
         "transients": [{"time_us": 1.0, "E_total_kT": float(rows[20, 1]),
                         "E_kinetic_kT": float(ek[20])}],
         "shape": {"class": "circle", "loops": 1}}
    with open(os.path.join(d, "summary.json"), "w") as f:
        json.dump(s, f)
    phi = np.linspace(0, 2 * np.pi, 50, endpoint=False)
    np.savetxt(os.path.join(d, "final_state.csv"),
               np.column_stack([54 * np.cos(phi), 54 * np.sin(phi), 5 * np.sin(2 * phi)]),
               delimiter=",", header="x_A,y_A,z_A", comments="")
    return d


def labelled_ticks(fig, axis):
    """The non-empty major tick labels of `axis` that lie inside its view."""
    fig.canvas.draw()
    lo, hi = sorted(axis.get_view_interval())
    return [t.get_text() for t, loc in zip(axis.get_ticklabels(), axis.get_ticklocs())
            if t.get_text() and lo * (1 - 1e-9) <= loc <= hi * (1 + 1e-9)]


@pytest.mark.parametrize("span", [1.3, 3.0, 30.0, 1e6])
def test_log_axis_has_two_labelled_ticks(span):
    fig, ax = plt.subplots()
    ax.plot([0, 1], [3.1, 3.1 * span])
    ibrod_plot.log_axis(ax, "y")
    labels = labelled_ticks(fig, ax.yaxis)
    assert len(labels) >= 2, (span, labels, ax.get_ylim())
    assert ax.get_yscale() == "log"
    lo, hi = ax.get_ylim()  # the data stay in view
    assert lo <= 3.1 and hi >= 3.1 * span
    plt.close(fig)


def test_plot_legend_titles_and_log_ticks(tmp_path):
    a = ibrod_plot.Run(make_run(tmp_path, "a", 2, 0.1, ek_span=2.0))
    b = ibrod_plot.Run(make_run(tmp_path, "b", 2, 0.1, ek_span=2.0, seed=1))
    c = ibrod_plot.Run(make_run(tmp_path, "c", 4, 0.1, ek_span=2.0))
    fig = ibrod_plot.figure_runs([a, b, c])
    ax_e, ax_k, ax_w = fig.axes[:3]
    texts = [t.get_text() for t in ax_e.get_legend().get_texts()]
    # one entry per run (the two at ΔLk 2 named), one per kind of mark
    assert sum("ΔLk = 2" in t for t in texts) == 2 and sum("ΔLk = 4" in t for t in texts) == 1
    assert any("(a)" in t for t in texts) and any("(b)" in t for t in texts)
    assert "transient state" in texts and "writhe convergence time" in texts
    assert len(texts) == 5
    assert len(ax_k.get_legend().get_texts()) == 3  # a fitted τ line per run
    # what all runs share (Cs, grid) is in the title
    title = fig._suptitle.get_text()
    assert "Cs = 0.1 M" in title and "16³ grid" in title
    # E_K spans a factor 2 only: still at least two labelled ticks on its log axis
    assert len(labelled_ticks(fig, ax_k.yaxis)) >= 2
    plt.close(fig)


@pytest.mark.parametrize("ext", ["pdf", "svg", "png"])
def test_plot_formats(tmp_path, ext):
    d = make_run(tmp_path, "a", 2, 0.1)
    out = tmp_path / f"plot.{ext}"
    subprocess.run([sys.executable, os.path.join(ROOT, "python", "ibrod_plot.py"), d, "-o",
                    str(out), "--logt"], check=True, capture_output=True)
    data = out.read_bytes()
    assert len(data) > 1000
    if ext == "pdf":
        assert data.startswith(b"%PDF")
    elif ext == "svg":
        root = ET.fromstring(data)
        assert root.tag.endswith("svg")
        assert "ΔLk = 2" in data.decode()  # text kept as text in the vector file
    else:
        assert mpimg.imread(str(out)).ndim == 3
    r = subprocess.run([sys.executable, os.path.join(ROOT, "python", "ibrod_plot.py"), d, "-o",
                        str(tmp_path / "plot.jpg")], capture_output=True, text=True)
    assert r.returncode != 0 and "allowed: png, pdf, svg" in r.stderr


def test_report_means_and_tiles(tmp_path):
    # two runs at (2, 0.1), one each at (4, 0.1) and (2, 0.05); (4, 0.05) is empty
    dirs = [make_run(tmp_path, "a", 2, 0.1), make_run(tmp_path, "b", 2, 0.1, seed=4),
            make_run(tmp_path, "c", 4, 0.1, finished=False), make_run(tmp_path, "d", 2, 0.05)]
    runs = [ibrod_plot.Run(d) for d in dirs]
    grid = {}
    for r in runs:
        grid.setdefault((r.excess_link, r.salt_M), []).append(r)
    dlks, css = [2, 4], [0.05, 0.1]
    axes = ibrod_report.against_excess_link(grid, dlks, css, str(tmp_path / "vs.svg"))
    assert (tmp_path / "vs.svg").stat().st_size > 1000
    ax_bend = axes.flat[0]
    lines = [l for l in ax_bend.get_lines() if l.get_linestyle() == "-" and len(l.get_xdata()) > 1]
    assert len(lines) == 1  # Cs = 0.1 (Cs = 0.05 has one point)
    x, y = lines[0].get_xdata(), lines[0].get_ydata()
    assert list(x) == [2, 4]  # no repeated ΔLk: no vertical line
    assert y[0] == pytest.approx((runs[0].ts["E_bend_kT"][-1] + runs[1].ts["E_bend_kT"][-1]) / 2)
    markers = [l for l in ax_bend.get_lines() if l.get_marker() == "o" and l.get_xdata().size]
    assert len(markers) == 4  # one per run
    texts = [t.get_text() for t in ax_bend.get_legend().get_texts()]
    assert {"Cs = 0.05 M", "Cs = 0.1 M", "a run, not finished"} <= set(texts)

    ts_axes = ibrod_report.timeseries_panels(grid, dlks, css, str(tmp_path / "ts.pdf"))
    assert (tmp_path / "ts.pdf").read_bytes().startswith(b"%PDF")
    texts = [t.get_text() for t in ts_axes[0, 0].get_legend().get_texts()]
    assert len([t for t in texts if t.startswith("Cs = ")]) == 3  # a, b, d at ΔLk 2
    assert any("(a)" in t for t in texts) and any("(b)" in t for t in texts)

    tiles = ibrod_report.contact_sheet(grid, dlks, css, "oblique", str(tmp_path / "shapes.png"))
    assert sorted(r.name for r, _ in tiles) == ["a", "b", "c", "d"]
    for run, ax in tiles:
        assert run.name in ax.get_title() and f"ΔLk = {run.excess_link}" in ax.get_title()
    img = mpimg.imread(str(tmp_path / "shapes.png"))
    # 3 columns (Cs 0.05; Cs 0.1 twice) × 2 rows of 360-px tiles
    assert img.shape[1] >= 3 * 300 and img.shape[0] >= 2 * 300


def test_report_cli_svg(tmp_path):
    dirs = [make_run(tmp_path, "a", 2, 0.1), make_run(tmp_path, "b", 2, 0.1, seed=1)]
    out = tmp_path / "rep"
    subprocess.run([sys.executable, os.path.join(ROOT, "python", "ibrod_report.py"), *dirs, "-o",
                    str(out), "--format", "svg"], check=True, capture_output=True)
    for name in ("vs_excess_link.svg", "timeseries.svg"):
        assert ET.parse(out / name).getroot().tag.endswith("svg")
    md = (out / "report.md").read_text()
    assert "(vs_excess_link.svg)" in md and "(timeseries.svg)" in md
    assert "2 tiles, one per run" in md
