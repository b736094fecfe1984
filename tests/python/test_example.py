"""examples/python/custom_curve.py runs and prints what docs/python.md says it prints: the
linking number it was built with (1), a writhe near 0, an ellipse that rounds (aspect ratio from
1.5 towards 1) and an elastic energy that falls. And its non-planar curve (--shape coil, a ring
wound 3 times round a torus): ibrod's writhe of the start shape agrees with an independent numpy
Gauss double integral of the smooth curve, the link is the integer nearest that writhe plus the
frame's twist and is conserved, and the total energy never rises."""
import importlib.util
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "examples", "python", "custom_curve.py")


def load_script():
    spec = importlib.util.spec_from_file_location("custom_curve", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_custom_curve_example(tmp_path):
    r = subprocess.run([sys.executable, SCRIPT, str(tmp_path / "out")], capture_output=True,
                       text=True, timeout=300, stdin=subprocess.DEVNULL)
    assert r.returncode == 0, r.stderr
    pairs = {m.group(1).strip(): (float(m.group(2)), float(m.group(3)))
             for m in re.finditer(r"^(\w[\w ]*?)\s+([-+\d.]+) -> ([-+\d.]+)", r.stdout, re.M)}
    lk0, lk1 = pairs["link Lk"]
    assert abs(lk0 - 1) < 1e-6 and abs(lk1 - 1) < 1e-6
    assert abs(pairs["writhe Wr"][1]) < 1e-3
    a0, a1 = pairs["aspect ratio"]
    assert abs(a0 - 1.5) < 1e-3 and a1 < 1.05
    e0, e1 = pairs["elastic energy"]
    assert e1 < e0
    assert os.path.exists(tmp_path / "out" / "final_state.csv")


def test_gauss_writhe_closed_forms():
    """The numpy Gauss integral itself: 0 for a planar circle, and a mirror image flips the sign."""
    cc = load_script()
    circle = lambda t: np.stack([np.cos(t), np.sin(t), 0 * t], axis=1)
    assert abs(cc.gauss_writhe_smooth(circle, 400)) < 1e-12
    wr = cc.gauss_writhe_smooth(cc.coil_curve, 500)
    mirror = lambda t: cc.coil_curve(t) * np.array([1, 1, -1])
    assert abs(cc.gauss_writhe_smooth(mirror, 500) + wr) < 1e-12
    assert abs(wr) > 0.1


def test_custom_coil_writhe_link_energy():
    cc = load_script()
    res = cc.simulate("coil", until_us=0.2, threads=1)
    o = res["obs"]
    # the start shape's writhe: ibrod's exact polygon writhe of the 100 points against the
    # Gauss double integral of the smooth curve in numpy (measured difference 0.0040, the
    # polygon's O(Δs²) error)
    assert abs(o["writhe"][0] - res["wr_numpy"]) < 0.01
    assert abs(res["wr_numpy"]) > 0.3  # a non-planar, chiral start: not the trivial 0
    # the link is the integer nearest numpy's Wr + Tw (Călugăreanu–White), and is conserved
    lk = round(res["wr_numpy"] + res["tw_numpy"])
    assert lk == -1
    assert np.max(np.abs(o["link"] - lk)) < 1e-6
    # a Lk = −1 coil is below the buckling threshold: it unwinds into a flat ring
    assert abs(o["writhe"][-1]) < 0.01
    # the total energy (elastic + electrostatic + steric + the fluid's kinetic) never rises
    E = o["E_total_kT"]
    assert len(E) >= 10
    assert np.all(np.diff(E) <= 1e-9 * abs(E[0]))
    assert E[-1] < E[0]
