#!/usr/bin/python3
"""End to end: `ibrod report RUN_DIR... -o REPORT_DIR --html` writes one self-contained page
(python/ibrod_html.py), and headless Chromium (Debian's chromium) shows the rod in it.

Two short runs of the real binary (ΔLk 2 at 0.1 M and ΔLk 4 at 0.05 M; 16³ grid, 100 base pairs,
300 steps, a frame every 20), then the report with --html. Checks
  - the page loads nothing from outside (no src= or href= but data: URIs and #anchors, no
    <link>), holds the report's tables, figures and a picture per cell;
  - in Chromium (--dump-dom after the page's scripts ran): the viewer drew (data-ready), the
    canvas is not blank (over 2 % of its pixels are not background), the label shows t, Wr and
    ΔLk; with #selftest the page moves the slider to the last frame by an input event, and the
    frame, the label and the canvas pixels change;
  - a screenshot (PNG) of the page: the canvas region holds the coloured tube (over 1 % of its
    pixels saturated colour), not an empty frame.

    /usr/bin/python3 tests/integration/test_html_report.py /path/to/ibrod [--screenshot OUT.png]

--screenshot keeps the screenshot (docs/figures/html_report.png was made so). Registered in CTest
(label integration). Exit status 0 when every check passes.
"""
import html.parser
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

BINARY = None  # from argv
KEEP_SCREENSHOT = None
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def sh(*args, timeout=300):
    r = subprocess.run(list(args), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       stdin=subprocess.DEVNULL, timeout=timeout)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(args)} exited {r.returncode}:\n{r.stdout}")
    return r.stdout


class Status(html.parser.HTMLParser):
    """The attributes of the element #viewer-status in a DOM dump."""

    def __init__(self):
        super().__init__()
        self.attrs = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id") == "viewer-status":
            self.attrs = a


def chromium(tmp, url, *args):
    return sh(CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
              f"--user-data-dir={os.path.join(tmp, 'chromium-profile')}",
              "--virtual-time-budget=10000", *args, url, timeout=120)


class HtmlReport(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="ibrod_html_")
        cls.runs = []
        for dlk, cs in ((2, 0.1), (4, 0.05)):
            d = os.path.join(cls.tmp, f"lk{dlk}_cs{cs:g}")
            sh(BINARY, "run", "-o", d, "--set", "grid.n=16", "--set", "grid.box_A=200",
               "--set", "rod.base_pairs=100", "--set", f"rod.excess_link={dlk}",
               "--set", f"solvent.salt_M={cs}", "--set", "time.t_end_us=0.03",
               "--set", "output.every_steps=10", "--set", "output.frame_every_steps=20",
               "--set", "run.fftw_measure=false", "--set", "run.threads=1")
            cls.runs.append(d)
        cls.rep = os.path.join(cls.tmp, "report")
        out = sh(BINARY, "report", *cls.runs, "-o", cls.rep, "--html")
        cls.page = os.path.join(cls.rep, "report.html")
        assert cls.page in out, out

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_1_self_contained(self):
        with open(self.page) as f:
            text = f.read()
        for attr, value in re.findall(r'\b(src|href)="([^"]*)"', text):
            self.assertTrue(value.startswith("data:") or value.startswith("#"),
                            f"{attr}={value[:60]} loads from outside the page")
        self.assertNotIn("<link", text)
        self.assertNotRegex(text, r"<script[^>]*\bsrc=")
        for words in ("Writhe convergence time", "Relaxation time", "Final shapes",
                      "A picture per cell", 'id="view"', 'type="range"'):
            self.assertIn(words, text)
        # the report's figures (time series, against ΔLk, contact sheet) and one picture per run
        self.assertGreaterEqual(text.count('src="data:image/png;base64,'), 3 + len(self.runs))

    @unittest.skipIf(CHROMIUM is None, "no chromium: scripts/install-deps.sh installs it")
    def test_2_viewer_draws_and_the_slider_moves_the_frame(self):
        dom = chromium(self.tmp, "file://" + self.page + "#selftest", "--dump-dom")
        p = Status()
        p.feed(dom)
        a = p.attrs
        self.assertIsNotNone(a, "no #viewer-status in the DOM")
        self.assertEqual(a.get("data-ready"), "1", "the viewer's script did not finish")
        ink = int(a["data-ink"])
        self.assertGreater(ink, 0.02 * 640 * 640, "the canvas is blank")
        self.assertEqual(a["data-frame-before"], "0")
        self.assertEqual(a["data-frame"], "15")  # frames at steps 0, 20, …, 300
        self.assertNotEqual(a["data-hash-before"], a["data-hash-after"],
                            "moving the slider did not change the picture")
        self.assertRegex(a["data-label"], r"t = 0\.0300 µs +Wr = -?[0-9.]+ +Tw = [0-9.-]+ +ΔLk = 2")

    @unittest.skipIf(CHROMIUM is None, "no chromium: scripts/install-deps.sh installs it")
    def test_3_screenshot_shows_the_rod(self):
        from PIL import Image

        shot = os.path.join(self.tmp, "shot.png")
        chromium(self.tmp, "file://" + self.page + "#frame=15", f"--screenshot={shot}",
                 "--window-size=1200,900")
        img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
        # the canvas: the first 640×640 block of near-(250, 250, 248) pixels framed by its border
        bg = (np.abs(img - [250, 250, 248]).sum(axis=2) <= 3)
        ys, xs = np.nonzero(bg)
        self.assertGreater(len(ys), 100_000, "no canvas background in the screenshot")
        y0, x0 = ys.min(), xs.min()
        canvas = img[y0:y0 + 640, x0:x0 + 640]
        sat = canvas.max(axis=2) - canvas.min(axis=2)
        coloured = (sat > 60).mean()
        self.assertGreater(coloured, 0.01, f"the canvas holds no coloured tube ({coloured:.4f})")
        if KEEP_SCREENSHOT:
            shutil.copy(shot, KEEP_SCREENSHOT)


class RodLayout(unittest.TestCase):
    """The viewer's rods (ibrod_html.rod_layout): each [[rods]] table its own links, so that no
    bead joins one rod's last point to the next rod's first."""

    def test_layout_of_the_rods_tables(self):
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                        "python"))
        from ibrod_html import rod_layout

        two = {"rod": {"base_pairs": 100}, "rods": [{"offset_A": [0, 0, -15]}, {}]}
        self.assertEqual(rod_layout(two, 200), [[0, 100, True], [100, 100, True]])
        mixed = {"rod": {"base_pairs": 50, "closed": False},
                 "rods": [{"closed": True, "base_pairs": 40}, {}]}
        self.assertEqual(rod_layout(mixed, 90), [[0, 40, True], [40, 50, False]])
        self.assertEqual(rod_layout({"rod": {"base_pairs": 50, "closed": False}}, 50),
                         [[0, 50, False]])
        self.assertEqual(rod_layout({}, 30), [[0, 30, True]])
        # tables that do not add up to the frames' points: one rod of them all, [rod]'s kind
        self.assertEqual(rod_layout(two, 150), [[0, 150, True]])


if __name__ == "__main__":
    BINARY = sys.argv[1]
    args = sys.argv[2:]
    if args[:1] == ["--screenshot"]:
        KEEP_SCREENSHOT = os.path.abspath(args[1])
    unittest.main(argv=[sys.argv[0], "-v"])
