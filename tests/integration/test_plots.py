#!/usr/bin/python3
"""End to end: two short runs of the real binary (ΔLk 2 at 0.1 M, ΔLk 3 at 0.05 M; 16³ grid,
100 base pairs, 300 steps) analysed with `ibrod analyze` (one with --frames), one of them drawn
with `ibrod render`, then python/ibrod_plot.py and python/ibrod_report.py on them. Both runs stop
at their end time, not at equilibrium: analyze and the report must say "not finished" and give no
writhe convergence time or τ. Then two tiny sweeps (implicit scheme, 16³): three random-
perturbation seeds at one (ΔLk, Cs), whose report groups the final states by shape class, and
ΔLk = 1, 3 from the unperturbed circle, whose report says which circle the stability test found
stable and brackets the threshold.

    /usr/bin/python3 tests/integration/test_plots.py /path/to/ibrod

Registered in CTest (label integration) by tests/CMakeLists.txt. Exit status 0 when every check
passes.
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLOT = os.path.join(ROOT, "python", "ibrod_plot.py")
REPORT = os.path.join(ROOT, "python", "ibrod_report.py")
PYTHON = "/usr/bin/python3"
BINARY = None  # set from argv


def sh(*args, check=True):
    r = subprocess.run(list(args), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"{' '.join(args)} exited {r.returncode}:\n{r.stdout}")
    return r


class PlotsAndReport(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="ibrod_plots_")
        cls.runs = {}
        for dlk, cs in ((2, 0.1), (3, 0.05)):
            d = os.path.join(cls.tmp, f"lk{dlk}_cs{cs:g}")
            sh(BINARY, "run", "-o", d, "--set", "grid.n=16", "--set", "grid.box_A=200",
               "--set", "rod.base_pairs=100", "--set", f"rod.excess_link={dlk}",
               "--set", f"solvent.salt_M={cs}", "--set", "time.t_end_us=0.03",
               "--set", "output.every_steps=10", "--set", "output.frame_every_steps=20",
               "--set", "run.fftw_measure=false",
               "--set", "run.threads=1")
            r = sh(BINARY, "analyze", "--quiet", d, *(["--frames"] if dlk == 2 else []))
            assert "warning: " in r.stdout and "not finished" in r.stdout, r.stdout
            cls.runs[(dlk, cs)] = d
        cls.a, cls.b = cls.runs[(2, 0.1)], cls.runs[(3, 0.05)]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def png(self, path):
        self.assertTrue(os.path.isfile(path), path)
        img = mpimg.imread(path)
        self.assertEqual(img.ndim, 3)
        return img

    def test_1_analyze_and_render(self):
        for d in self.runs.values():  # analysed in setUpClass
            with open(os.path.join(d, "summary.json")) as f:
                s = json.load(f)
            for key in ("writhe_convergence_time_us", "relaxation_time_us", "transients",
                        "closest_approach_A", "kinetic_power_law_exponent", "final_energies_kT",
                        "shape", "contacts", "relaxation_time_local_us"):
                self.assertIn(key, s)
            self.assertIn("stop_reason", s)  # the run's own keys survive
            # stopped at t_end: null with a reason, never a number
            self.assertEqual(s["stop_reason"], "end_time")
            self.assertFalse(s["equilibrium_reached"])
            self.assertIn("end_time", s["not_finished_reason"])
            for key in ("writhe_convergence_time_us", "relaxation_time_us",
                        "relaxation_time_table_us", "limiting_energies_kT"):
                self.assertIsNone(s[key], key)
            # the final shape of a 300-step run: still the circle; contacts from the frames
            self.assertEqual(s["shape"]["class"], "circle")
            self.assertEqual(s["contacts"]["source"], "trajectory.h5md")
            self.assertEqual(s["contacts"]["frames"], 16)
        with open(os.path.join(self.a, "summary.json")) as f:
            frames = json.load(f)["shape_frames"]  # --frames: one shape per frame
        self.assertEqual(len(frames), 16)
        self.assertEqual(frames[0]["class"], "circle")
        # only run a is rendered, so the report draws b with matplotlib 3-D
        r = sh(BINARY, "render", self.a, "--views", "top,oblique", "--size", "240x180")
        files = [l for l in r.stdout.splitlines() if l.endswith(".png")]
        self.assertEqual(len(files), 2, r.stdout)
        img = self.png(files[0])
        self.assertEqual(img.shape[:2], (180, 240))
        # --time picks the nearest frame of trajectory.h5md (frames every 0.002 µs)
        r = sh(BINARY, "render", self.a, "--time", "0.0123", "--views", "side", "--size", "64x64")
        self.assertIn("frame at t = 0.0120 us", r.stdout)
        self.png(os.path.join(self.a, "render", "rod_side_t0.0120.png"))
        self.assertEqual(sh(BINARY, "render", self.a, "--views", "diagonal", check=False).returncode, 2)
        # an existing picture is never silently replaced: refused (exit 2, naming the file and
        # --force, the file untouched), replaced with --force
        side = os.path.join(self.a, "render", "rod_side_t0.0120.png")
        before = os.stat(side).st_mtime_ns
        r = sh(BINARY, "render", self.a, "--time", "0.0123", "--views", "side", "--size", "80x80",
               check=False)
        self.assertEqual(r.returncode, 2, r.stdout)
        self.assertIn("rod_side_t0.0120.png", r.stdout)
        self.assertIn("--force", r.stdout)
        self.assertEqual(os.stat(side).st_mtime_ns, before)
        self.assertEqual(self.png(side).shape[:2], (64, 64))
        sh(BINARY, "render", self.a, "--time", "0.0123", "--views", "side", "--size", "80x80",
           "--force")
        self.assertEqual(self.png(side).shape[:2], (80, 80))
        # a time outside the trajectory (0 to 0.03 µs): drawn at the last frame, with a warning
        r = sh(BINARY, "render", self.a, "--time", "99", "--views", "side", "--size", "32x32")
        self.assertIn("warning: --time 99.0000 us is outside the trajectory", r.stdout)
        self.assertIn("t = 0.0000 to 0.0300 us", r.stdout)
        self.png(os.path.join(self.a, "render", "rod_side_t0.0300.png"))
        r = sh(BINARY, "render", self.a, "--time", "0.01", "--views", "front", "--size", "32x32")
        self.assertNotIn("warning", r.stdout)
        # --colour twist: the final state coloured by twist density, its range printed. The mean
        # twist density is 360° Tw / L with Tw = ΔLk − Wr (the rod is intrinsically untwisted):
        # it lies in the printed range
        r = sh(BINARY, "render", self.a, "--views", "bottom", "--size", "64x64",
               "--colour", "twist")
        m = re.search(r"twist colour from (\S+) \(blue\) to (\S+) \(red\) deg/nm", r.stdout)
        self.assertIsNotNone(m, r.stdout)
        lo, hi = float(m.group(1)), float(m.group(2))
        fs = np.genfromtxt(os.path.join(self.a, "final_state.csv"), delimiter=",", names=True)
        p = np.column_stack([fs["x_A"], fs["y_A"], fs["z_A"]])
        length_nm = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1).sum() / 10
        ts = np.genfromtxt(os.path.join(self.a, "timeseries.csv"), delimiter=",", names=True)
        mean = 360 * (2 - ts["writhe"][-1]) / length_nm
        self.assertTrue(0 < lo < mean < hi, (lo, mean, hi))

    def test_1b_movie(self):
        # every frame of trajectory.h5md (16: steps 0, 20, …, 300) from the first view, one scale;
        # an MP4 with ffmpeg, else a message saying so
        r = sh(BINARY, "render", self.b, "--movie", "--views", "oblique", "--size", "48x40")
        movie = os.path.join(self.b, "render", "movie_oblique")
        frames = sorted(os.listdir(movie))
        self.assertEqual(frames, [f"frame_{i:05d}.png" for i in range(16)], r.stdout)
        self.assertEqual(self.png(os.path.join(movie, frames[-1])).shape[:2], (40, 48))
        self.assertIn("16 frames (t = 0.0000 to 0.0300 us)", r.stdout)
        # the animated PNG, with or without ffmpeg: 16 frames of 48×40 (its chunks: one acTL
        # announcing 16, one fcTL per frame), and Pillow, an independent reader, plays it
        apng = os.path.join(self.b, "render", "rod_oblique.apng")
        with open(apng, "rb") as f:
            data = f.read()
        self.assertEqual(data[:8], b"\x89PNG\r\n\x1a\n")
        actl = data.index(b"acTL")
        self.assertEqual(int.from_bytes(data[actl + 4:actl + 8], "big"), 16)
        self.assertEqual(data.count(b"fcTL"), 16)
        try:
            from PIL import Image
        except ImportError:
            Image = None
        if Image is not None:
            with Image.open(apng) as im:
                self.assertEqual((im.format, im.size, im.n_frames), ("PNG", (48, 40), 16))
                im.seek(15)
                last = np.asarray(im.convert("RGB"))
            # its last frame is the last frame's PNG
            np.testing.assert_allclose(last / 255.0,
                                       self.png(os.path.join(movie, frames[-1]))[..., :3],
                                       atol=1e-6)
        mp4 = os.path.join(self.b, "render", "rod_oblique.mp4")
        if shutil.which("ffmpeg"):
            self.assertTrue(os.path.getsize(mp4) > 0)
            # the MP4 holds every frame: ffprobe counts the decoded frames of its video stream
            if shutil.which("ffprobe"):
                n = sh("ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                       "-show_entries", "stream=nb_read_frames,width,height", "-of", "csv=p=0",
                       mp4).stdout.strip()
                self.assertEqual(n, "48,40,16", n)  # width, height, frames
        else:
            self.assertIn("ffmpeg not found", r.stdout)
            self.assertFalse(os.path.exists(mp4))
        # again: refused without --force, the frames kept
        self.assertEqual(sh(BINARY, "render", self.b, "--movie", "--views", "oblique",
                            check=False).returncode, 2)
        self.assertEqual(len(os.listdir(movie)), 16)
        shutil.rmtree(os.path.join(self.b, "render"))  # test_3 renders b through the report
        self.assertEqual(sh(BINARY, "analyze", os.path.join(self.tmp, "none"), check=False).returncode, 2)

    def test_2_plot(self):
        out = os.path.join(self.tmp, "plot.png")
        sh(PYTHON, PLOT, self.a, self.b, "-o", out)
        img = self.png(out)
        self.assertGreater(img.shape[0], 500)  # three stacked panels
        # not a run directory: a message and a non-zero status
        r = sh(PYTHON, PLOT, self.tmp, "-o", os.path.join(self.tmp, "x.png"), check=False)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("timeseries.csv", r.stdout)

    def test_3_report(self):
        rep = os.path.join(self.tmp, "report")
        sh(PYTHON, REPORT, self.a, self.b, "-o", rep)
        for name in ("shapes.png", "vs_excess_link.png", "timeseries.png"):
            self.png(os.path.join(rep, name))
        with open(os.path.join(rep, "report.md")) as f:
            md = f.read()
        self.assertIn("| ΔLk | Cs = 0.05 M | Cs = 0.1 M |", md)
        for section in ("## Writhe convergence time", "## Relaxation time", "## Final shapes",
                        "## Transient states"):
            self.assertIn(section, md)
        self.assertNotIn("not analysed", md)
        # the writhe convergence and τ tables: "not finished" in every filled cell
        for section in ("## Writhe convergence time", "## Relaxation time"):
            part = md.split(section)[1].split("## ")[0]
            rows = [l for l in part.splitlines() if l.startswith("| 2 ") or l.startswith("| 3 ")]
            self.assertEqual(len(rows), 2, part)
            for l in rows:
                self.assertIn("not finished", l)
                self.assertNotRegex(l.split("|", 2)[2], r"\d")
        self.assertIn("circle, 1 loops", md.split("## Final shapes")[1])
        with open(os.path.join(rep, "runs.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(sorted(int(r["excess_link"]) for r in rows), [2, 3])
        self.assertTrue(all(r["writhe_convergence_time_us"] == "" for r in rows))  # null
        self.assertTrue(all(r["shape"] == "circle" for r in rows))
        # --ibrod renders the run that has no picture yet
        self.assertFalse(os.path.isdir(os.path.join(self.b, "render")))
        sh(PYTHON, REPORT, self.a, self.b, "-o", rep, "--ibrod", BINARY)
        self.assertTrue(any(f.startswith("rod_oblique_t") for f in os.listdir(os.path.join(self.b, "render"))))
        # `ibrod report` is the same script, with the binary as --ibrod
        rep2 = os.path.join(self.tmp, "report2")
        sh(BINARY, "report", self.a, self.b, "-o", rep2)
        with open(os.path.join(rep2, "report.md")) as f:
            self.assertIn("## Relaxation time", f.read())
        self.assertNotEqual(sh(BINARY, "report", check=False).returncode, 0)  # no run: usage


SWEEP_BASE = """[grid]
n = 16
box_A = 200.0
[time]
scheme = "implicit"
dt_ns = 2.0
t_end_us = {t_end}
stop_kinetic_kT = 1e-8
stability_probe_us = 0.2
stability_method = "dynamic"   # the probe_time_us check below is the dynamic test's
[rod]
base_pairs = 100
excess_link = {dlk}
perturbation = []
{random}
[output]
every_steps = 10
frame_every_steps = 0
checkpoint_every_steps = 0
[run]
threads = 1
fftw_measure = false
[sweep]
{sweep}
"""


class SweepReports(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="ibrod_sweep_report_")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def sweep(self, name, text):
        path = os.path.join(self.tmp, f"{name}.toml")
        with open(path, "w") as f:
            f.write(text)
        out = os.path.join(self.tmp, name)
        sh(BINARY, "sweep", path, "-o", out, "-j", "2")
        runs = sorted(os.path.join(out, d) for d in os.listdir(out)
                      if os.path.isfile(os.path.join(out, d, "summary.json")))
        rep = os.path.join(self.tmp, name + "_report")
        sh(BINARY, "report", *runs, "-o", rep)
        with open(os.path.join(rep, "report.md")) as f:
            md = f.read()
        with open(os.path.join(rep, "runs.csv")) as f:
            rows = list(csv.DictReader(f))
        return rep, md, rows

    def test_perturbation_sampling_groups_the_final_states_by_class(self):
        rep, md, rows = self.sweep("seeds", SWEEP_BASE.format(
            t_end=0.4, dlk=4, random="perturbation_random = { modes = 6, amplitude = 1.0 }",
            sweep='"rod.perturbation_random.seed" = [1, 2, 3]'))
        self.assertEqual(len(rows), 3)
        part = md.split("## Perturbation sampling: ΔLk = 4, Cs = 0.1 M")[1].split("\n## ")[0]
        self.assertIn("3 runs that differ only in their perturbation", part)
        # one table row per class, the counts those of the runs' classes, all seeds listed once
        classes = {}
        for r in rows:
            classes[r["shape"]] = classes.get(r["shape"], 0) + 1
        table = [l for l in part.splitlines() if l.startswith("| ") and not l.startswith("| class")]
        self.assertEqual(len(table), len(classes), part)
        for line in table:
            cells = [c.strip() for c in line.strip("|").split("|")]
            self.assertEqual(int(cells[1]), classes[cells[0]], line)
        seeds = sorted(s.strip() for l in table for s in l.split("|")[4].split(","))
        self.assertEqual(seeds, ["seed 1", "seed 2", "seed 3"])
        img = mpimg.imread(os.path.join(rep, "sampling_1.png"))
        self.assertEqual(img.ndim, 3)
        self.assertGreater(img.shape[1], img.shape[0] * 0.8 * len(classes))  # one tile per class

    def test_circle_stability_brackets_the_threshold(self):
        rep, md, rows = self.sweep("circle", SWEEP_BASE.format(
            t_end=0.3, dlk=1, random="", sweep='"rod.excess_link" = [1, 3]'))
        verdict = {int(r["excess_link"]): r["circle_stability"] for r in rows}
        self.assertEqual(verdict, {1: "stable", 3: "unstable"})
        part = md.split("## Stability of the twisted circle")[1].split("\n## ")[0]
        # ΔE (the kicked copy against the unperturbed continuation): above −tolerance (the
        # default, 1e-6 kT) when stable, below it when not
        d1 = re.search(r"\| 1 \| stable \(ΔE ([-+][0-9.e+-]+) kT, tolerance 1e-06 kT", part)
        d3 = re.search(r"\| 3 \| unstable \(ΔE ([-+][0-9.e+-]+) kT, tolerance 1e-06 kT", part)
        self.assertTrue(d1 and d3, part)
        self.assertGreater(float(d1.group(1)), -1e-6)
        self.assertLess(float(d3.group(1)), -1e-6)
        self.assertIn("- Cs = 0.1 M: stable up to ΔLk = 1, unstable from ΔLk = 3: "
                      "the threshold lies in (1, 3]", part)
        self.assertNotIn("## Perturbation sampling", md)  # a ΔLk sweep is no sampling
        # the probe's recorded length is the simulated time it integrated: 0.2 µs to within one
        # adaptive step (≤ 2 ns), not steps × the last Δt
        for r in rows:
            with open(os.path.join(r["run"], "summary.json")) as f:
                for t in json.load(f)["stability_tests"]:
                    self.assertLessEqual(abs(t["probe_time_us"] - 0.2), 0.0021, t)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: test_plots.py /path/to/ibrod")
    BINARY = sys.argv.pop(1)
    unittest.main(verbosity=2)
