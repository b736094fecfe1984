#!/usr/bin/python3
"""The report as one self-contained HTML page (`ibrod report RUN_DIR... -o REPORT_DIR --html`):
REPORT_DIR/report.html opens offline in any browser and can be sent as one file.

It holds
  - an interactive 3-D view of each run's rod (a canvas drawn by the small viewer below, no
    library): drag to rotate, wheel (or the +/- buttons) to zoom, a time slider through the
    frames of trajectory.h5md (at most --html-frames of them, evenly spaced, the last always),
    a play button, and the time, Wr, Tw and ΔLk of the frame shown; a menu picks the run;
  - report.md's text and tables (the writhe convergence and relaxation times, shapes, transient
    states, stability, per ΔLk × Cs) and its figures (time series, final state against ΔLk, the
    contact sheet), embedded as data: URIs;
  - a table with a picture per (ΔLk, Cs) cell (each run's rendered final state; a click shows
    that run in the 3-D view).

Positions are stored as little-endian int16 in units of 0.1 Å about each frame's centroid
(exact to 0.05 Å), base64-encoded: about 5 kB per frame of a 600-point rod.

The page reports what it drew for tests and scripts: the element #viewer-status carries
data-frame (the frame shown), data-ink (canvas pixels that are not background) and data-hash (a
checksum of the canvas pixels). With the URL fragment #selftest it moves the slider itself to the
last frame, as a user would (an input event), and records data-hash-before / data-hash-after.
"""
import base64
import csv
import glob
import html
import json
import os
import re
import tomllib

import numpy as np

MIME = {".png": "image/png", ".svg": "image/svg+xml", ".jpg": "image/jpeg"}


def data_uri(path):
    ext = os.path.splitext(path)[1].lower()
    with open(path, "rb") as f:
        return f"data:{MIME[ext]};base64," + base64.b64encode(f.read()).decode("ascii")


def trajectory_file(run_dir):
    """trajectory.h5md, or an older run's trajectory.h5; None without either."""
    for name in ("trajectory.h5md", "trajectory.h5"):
        p = os.path.join(run_dir, name)
        if os.path.exists(p):
            return p
    return None


def read_frames(run_dir, max_frames):
    """(times µs (T,), positions (T, n, 3) Å) of at most max_frames frames, evenly spaced with
    the last one kept; the final state alone without a trajectory; (None, None) without both."""
    p = trajectory_file(run_dir)
    if p is not None:
        import h5py

        with h5py.File(p, "r", locking=False) as h:
            pos = h["particles/rod/position"]
            unit = pos["time"].attrs.get("unit", b"ns")
            unit = unit.decode() if isinstance(unit, bytes) else str(unit)
            t_us = pos["time"][()] * (1.0 if unit == "µs" else 1e-3)  # ns; µs in the oldest files
            T = len(t_us)
            keep = np.unique(np.round(np.linspace(0, T - 1, min(T, max_frames))).astype(int))
            return t_us[keep], pos["value"][keep.tolist()]
    p = os.path.join(run_dir, "final_state.csv")
    if os.path.exists(p):
        a = np.genfromtxt(p, delimiter=",", names=True)
        X = np.stack([a["x_A"], a["y_A"], a["z_A"]], axis=-1)
        t = None
        s = os.path.join(run_dir, "summary.json")
        if os.path.exists(s):
            with open(s) as f:
                t = (json.load(f).get("final") or {}).get("time_us")
        return np.array([t or 0.0]), X[None]
    return None, None


def read_timeseries(run_dir):
    p = os.path.join(run_dir, "timeseries.csv")
    if not os.path.exists(p):
        return None
    with open(p) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return None
    return {k: np.array([float(r[k]) for r in rows]) for k in ("time_us", "writhe", "twist",
                                                               "link")}


def read_config(run_dir):
    p = os.path.join(run_dir, "config.toml")
    if not os.path.exists(p):
        return {}
    with open(p, "rb") as f:
        return tomllib.load(f)


def rod_layout(cfg, n):
    """The rods' layout in the frames' n points, [[offset, points, closed], ...]: one per
    [[rods]] table (its keys over [rod]'s; points = base pairs), or the one rod of [rod]; one rod
    of all n points, [rod]'s kind, where the tables do not add up to n."""
    rod = cfg.get("rod", {})
    layout, offset = [], 0
    for t in cfg.get("rods") or [{}]:
        k = int(t.get("base_pairs", rod.get("base_pairs", n)))
        layout.append([offset, k, bool(t.get("closed", rod.get("closed", True)))])
        offset += k
    return layout if offset == n else [[0, n, bool(rod.get("closed", True))]]


def run_record(run_dir, max_frames):
    """The viewer's data of one run: name, ΔLk, Cs, tube diameter, the rods' layout, frames
    (time, Wr, Tw, Lk at the nearest time-series row) and the int16 positions; None without any
    state."""
    t, X = read_frames(run_dir, max_frames)
    if t is None:
        return None
    cfg = read_config(run_dir)
    rod, steric = cfg.get("rod", {}), cfg.get("steric", {})
    ts = read_timeseries(run_dir)
    frames = []
    for ti in t:
        f = {"t": round(float(ti), 6)}
        if ts is not None:
            i = int(np.argmin(np.abs(ts["time_us"] - ti)))
            f.update(wr=round(float(ts["writhe"][i]), 4), tw=round(float(ts["twist"][i]), 4),
                     lk=round(float(ts["link"][i]), 4))
        frames.append(f)
    centred = X - X.mean(axis=1, keepdims=True)
    q = np.clip(np.round(centred * 10), -32767, 32767).astype("<i2")
    return {
        "name": os.path.basename(os.path.normpath(run_dir)),
        "dlk": rod.get("excess_link"),
        "cs": cfg.get("solvent", {}).get("salt_M"),
        "diameter": float(steric.get("diameter_A", 20.0)),
        "rods": rod_layout(cfg, int(X.shape[1])),
        "n": int(X.shape[1]),
        "frames": frames,
        "pos": base64.b64encode(q.tobytes()).decode("ascii"),
    }


def latest_picture(run_dir):
    pics = glob.glob(os.path.join(run_dir, "render", "rod_*_t*.png"))
    if not pics:
        return None

    def t_of(p):
        m = re.search(r"_t([0-9.]+)\.png$", p)
        return float(m.group(1)) if m else -1.0

    return max(pics, key=t_of)


# ---- report.md → HTML (the few constructs the report writes: headings, paragraphs, lists,
# tables, images, `code`, **bold**)

def inline(text):
    s = html.escape(text, quote=False)
    s = re.sub(r"`([^`]+)`", r"<code>\1</code>", s)
    s = re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", s)
    return s


def image_html(caption, name, base):
    path = os.path.join(base, name)
    if os.path.splitext(name)[1].lower() in MIME and os.path.exists(path):
        return f'<figure><img alt="{html.escape(caption)}" src="{data_uri(path)}"></figure>'
    return f"<p><i>{html.escape(caption)}: {html.escape(name)} (not embedded)</i></p>"


def markdown_html(md, base):
    out, para, rows = [], [], []

    def flush():
        if para:
            out.append("<p>" + inline(" ".join(para)) + "</p>")
            para.clear()
        if rows:
            out.append('<table class="grid">')
            for k, r in enumerate(rows):
                tag = "th" if k == 0 else "td"
                cells = [c.strip() for c in r.strip().strip("|").split("|")]
                out.append("<tr>" + "".join(f"<{tag}>{cell_html(c, base)}</{tag}>" for c in cells)
                           + "</tr>")
            out.append("</table>")
            rows.clear()

    for line in md.splitlines():
        s = line.strip()
        if s.startswith("|"):
            if para:
                flush()
            if not re.fullmatch(r"\|[-:| ]+\|", s):
                rows.append(s)
            continue
        if rows:
            flush()
        m = re.fullmatch(r"(#{1,4}) (.*)", s)
        img = re.fullmatch(r"!\[([^\]]*)\]\(([^)]+)\)", s)
        if not s:
            flush()
        elif m:
            flush()
            level = len(m.group(1)) + 1  # the page's h1 is its own title
            out.append(f"<h{level}>{inline(m.group(2))}</h{level}>")
        elif img:
            flush()
            out.append(image_html(img.group(1), img.group(2), base))
        elif s.startswith("- "):
            flush()
            out.append("<ul><li>" + inline(s[2:]) + "</li></ul>")
        else:
            para.append(s)
    flush()
    return "\n".join(out)


def cell_html(text, base):
    m = re.fullmatch(r"!\[([^\]]*)\]\(([^)]+)\)", text)
    if m:
        path = os.path.join(base, m.group(2))
        if os.path.exists(path) and os.path.splitext(path)[1].lower() in MIME:
            return f'<img class="cell" alt="{html.escape(m.group(1))}" src="{data_uri(path)}">'
    return inline(text)


def picture_table(records, run_dirs):
    """One picture per (ΔLk, Cs) cell: each run's latest rendered picture (several runs of one
    cell side by side); a click shows that run in the 3-D view."""
    cells, dlks, css = {}, set(), set()
    for i, (rec, d) in enumerate(zip(records, run_dirs)):
        key = (rec["dlk"], rec["cs"])
        dlks.add(rec["dlk"])
        css.add(rec["cs"])
        pic = latest_picture(d)
        img = (f'<img class="cell" src="{data_uri(pic)}" alt="{html.escape(rec["name"])}">'
               if pic else '<span class="nopic">no picture</span>')
        cells.setdefault(key, []).append(
            f'<a href="#viewer" class="pick" data-run="{i}" title="show in the 3-D view">{img}'
            f'<br><small>{html.escape(rec["name"])}</small></a>')
    if not cells:
        return ""
    order = lambda v: (v is None, v if v is not None else 0)  # noqa: E731
    dl, cl = sorted(dlks, key=order), sorted(css, key=order)
    h = ['<table class="grid pictures"><tr><th>ΔLk \\ Cs (M)</th>']
    h += [f"<th>{'—' if c is None else f'{c:g}'}</th>" for c in cl]
    h.append("</tr>")
    for dv in dl:
        h.append(f"<tr><th>{'—' if dv is None else dv}</th>")
        for c in cl:
            h.append("<td>" + " ".join(cells.get((dv, c), [])) + "</td>")
        h.append("</tr>")
    h.append("</table>")
    return "\n".join(h)


VIEWER_JS = r"""
(function () {
  const runs = JSON.parse(document.getElementById('ibrod-data').textContent);
  const canvas = document.getElementById('view');
  const ctx = canvas.getContext('2d');
  const slider = document.getElementById('frame');
  const label = document.getElementById('label');
  const status = document.getElementById('viewer-status');
  const menu = document.getElementById('run');
  const BG = [250, 250, 248];
  let run = 0, frame = 0, yaw = 0.6, pitch = -0.5, zoom = 1, playing = null;
  const decoded = runs.map(r => {
    const bin = atob(r.pos), buf = new ArrayBuffer(bin.length), u8 = new Uint8Array(buf);
    for (let i = 0; i < bin.length; i++) u8[i] = bin.charCodeAt(i);
    return new Int16Array(buf);  // little-endian on every browser platform in use
  });
  function extent(k) {  // the largest distance from the centroid over the run's frames, Å
    const p = decoded[k]; let m = 1;
    for (let i = 0; i < p.length; i += 3)
      m = Math.max(m, Math.hypot(p[i], p[i + 1], p[i + 2]) / 10);
    return m + runs[k].diameter;
  }
  const extents = runs.map((_, k) => extent(k));
  runs.forEach((r, k) => {
    const o = document.createElement('option');
    o.value = k;
    o.textContent = r.name + (r.dlk != null ? '  (ΔLk = ' + r.dlk + (r.cs != null ? ', Cs = ' + r.cs + ' M' : '') + ')' : '');
    menu.appendChild(o);
  });
  function hue(s) {  // position along the rod, 0..1 → a colour wheel (blue → red → yellow)
    const h = 240 - 300 * s;
    return 'hsl(' + h.toFixed(0) + ',';
  }
  function draw() {
    const r = runs[run], n = r.n, p = decoded[run], off = frame * n * 3;
    const W = canvas.width, H = canvas.height;
    ctx.fillStyle = 'rgb(' + BG.join(',') + ')';
    ctx.fillRect(0, 0, W, H);
    const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    const scale = zoom * 0.45 * Math.min(W, H) / extents[run];
    const P = new Array(n);
    for (let k = 0; k < n; k++) {
      const x = p[off + 3 * k] / 10, y = p[off + 3 * k + 1] / 10, z = p[off + 3 * k + 2] / 10;
      const x1 = cy * x + sy * y, y1 = -sy * x + cy * y;   // yaw about z
      const y2 = cp * y1 - sp * z, z2 = sp * y1 + cp * z;  // pitch about x
      P[k] = [W / 2 + scale * x1, H / 2 - scale * z2, y2];
    }
    // the tube as overlapping shaded beads of the steric diameter, one per point (and one
    // between neighbours), far ones first so that near ones cover them
    const beads = [];
    for (let k = 0; k < n; k++) beads.push([P[k][0], P[k][1], P[k][2], k]);
    for (const [o, nr, closed] of r.rods) {  // each rod's own links: n of a ring, n − 1 if open
      for (let k = 0; k < (closed ? nr : nr - 1); k++) {
        const a = P[o + k], b = P[o + (k + 1) % nr];
        beads.push([(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2, o + k + 0.5]);
      }
    }
    beads.sort((u, v) => v[2] - u[2]);
    const rad = Math.max(1.5, r.diameter * scale / 2);
    for (const [x, y, z, k] of beads) {
      const depth = z / extents[run];  // −1 near … +1 far: far is darker
      const c = hue(k / n) + '65%,';
      const g = ctx.createRadialGradient(x - 0.35 * rad, y - 0.35 * rad, 0.1 * rad, x, y, rad);
      g.addColorStop(0, c + (78 - 12 * depth).toFixed(0) + '%)');
      g.addColorStop(0.55, c + (48 - 12 * depth).toFixed(0) + '%)');
      g.addColorStop(1, c + (30 - 12 * depth).toFixed(0) + '%)');
      ctx.fillStyle = g;
      ctx.beginPath(); ctx.arc(x, y, rad, 0, 2 * Math.PI); ctx.fill();
    }
    // a 100 Å scale bar
    ctx.fillStyle = '#333'; ctx.fillRect(20, H - 24, 100 * scale, 4);
    ctx.font = '13px sans-serif'; ctx.fillText('100 Å', 20, H - 30);
    const f = r.frames[frame];
    let text = 't = ' + f.t.toFixed(4) + ' µs';
    if (f.wr !== undefined) text += '   Wr = ' + f.wr.toFixed(3) + '   Tw = ' + f.tw.toFixed(3);
    if (r.dlk != null) text += '   ΔLk = ' + r.dlk;
    text += '   (frame ' + (frame + 1) + ' of ' + r.frames.length + ')';
    label.textContent = text;
    report();
  }
  function report() {
    const d = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    let ink = 0, hash = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (d[i] !== BG[0] || d[i + 1] !== BG[1] || d[i + 2] !== BG[2]) ink++;
      hash = (hash * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
    }
    status.dataset.run = run; status.dataset.frame = frame;
    status.dataset.ink = ink; status.dataset.hash = hash;
    status.dataset.label = label.textContent;
  }
  function setRun(k) {
    run = k; menu.value = k; slider.max = runs[k].frames.length - 1;
    frame = Math.min(frame, runs[k].frames.length - 1); slider.value = frame; draw();
  }
  slider.addEventListener('input', () => { frame = +slider.value; draw(); });
  menu.addEventListener('change', () => setRun(+menu.value));
  document.querySelectorAll('a.pick').forEach(a => a.addEventListener('click', () => setRun(+a.dataset.run)));
  document.getElementById('zoom-in').addEventListener('click', () => { zoom *= 1.25; draw(); });
  document.getElementById('zoom-out').addEventListener('click', () => { zoom /= 1.25; draw(); });
  document.getElementById('play').addEventListener('click', e => {
    if (playing) { clearInterval(playing); playing = null; e.target.textContent = 'play'; return; }
    e.target.textContent = 'pause';
    playing = setInterval(() => {
      frame = (frame + 1) % runs[run].frames.length; slider.value = frame; draw();
    }, 120);
  });
  canvas.addEventListener('wheel', e => { e.preventDefault(); zoom *= Math.exp(-e.deltaY / 500); draw(); }, {passive: false});
  let drag = null;
  canvas.addEventListener('pointerdown', e => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('pointermove', e => {
    if (!drag) return;
    yaw += (e.clientX - drag[0]) * 0.01;
    pitch = Math.max(-1.57, Math.min(1.57, pitch + (e.clientY - drag[1]) * 0.01));
    drag = [e.clientX, e.clientY]; draw();
  });
  const start = /frame=(\d+)/.exec(location.hash);
  if (start) frame = +start[1];
  setRun(0);
  if (location.hash.indexOf('selftest') >= 0) {  // move the slider as a user would
    status.dataset.hashBefore = status.dataset.hash;
    status.dataset.frameBefore = status.dataset.frame;
    slider.value = slider.max;
    slider.dispatchEvent(new Event('input'));
    status.dataset.hashAfter = status.dataset.hash;
  }
  status.dataset.ready = '1';
})();
"""

CSS = """
body { font-family: sans-serif; max-width: 1200px; margin: 1em auto; padding: 0 1em; color: #222; }
table.grid { border-collapse: collapse; margin: 0.5em 0; }
table.grid td, table.grid th { border: 1px solid #bbb; padding: 3px 6px; vertical-align: top; }
table.grid th { background: #eee; }
figure img { max-width: 100%; }
img.cell { width: 180px; }
#viewer { display: flex; gap: 1em; align-items: flex-start; flex-wrap: wrap; }
#view { border: 1px solid #999; cursor: grab; touch-action: none; }
#controls { flex: 1 1 300px; }
#frame { width: 100%; }
#label { font-family: monospace; margin: 0.5em 0; }
code { background: #f2f2f2; padding: 0 2px; }
"""


def write_html(out_path, report_md, report_dir, run_dirs, max_frames=100, title="ibrod report"):
    """Writes the page to out_path; returns the number of runs in the 3-D view."""
    pairs = [(run_record(d, max_frames), d) for d in run_dirs]
    shown = [r for r, _ in pairs if r is not None]
    shown_dirs = [d for r, d in pairs if r is not None]
    body = [f"<h1>{html.escape(title)}</h1>"]
    if shown:
        body.append(
            '<h2>The rod in 3-D</h2><div id="viewer"><canvas id="view" width="640" '
            'height="640"></canvas><div id="controls"><p><label>run <select id="run"></select>'
            '</label></p><p><label>time <input id="frame" type="range" min="0" max="0" '
            'value="0"></label></p><p id="label"></p><p><button id="play">play</button> '
            '<button id="zoom-in">+</button> <button id="zoom-out">−</button></p><p><small>'
            "Drag to rotate, wheel to zoom. The tube has the steric diameter; its colour runs "
            "along the rod (blue at point 0) and darkens with depth."
            f" Up to {max_frames} frames of each run's trajectory.</small></p>"
            '<div id="viewer-status"></div></div></div>')
        pics = picture_table(shown, shown_dirs)
        if pics:
            body += ["<h2>A picture per cell</h2>", pics]
    body.append(markdown_html(report_md, report_dir))
    data = json.dumps(shown).replace("</", "<\\/")
    page = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(title)}</title><style>{CSS}</style></head><body>\n"
            + "\n".join(body)
            + f'\n<script type="application/json" id="ibrod-data">{data}</script>\n'
            + (f"<script>{VIEWER_JS}</script>" if shown else "")
            + "\n</body></html>\n")
    with open(out_path, "w") as f:
        f.write(page)
    return len(shown)
