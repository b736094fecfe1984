"""examples/python/custom_curve.py runs and prints what docs/python.md says it prints: the
linking number it was built with (1), a writhe near 0, an ellipse that rounds (aspect ratio from
1.5 towards 1) and an elastic energy that falls."""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "examples", "python", "custom_curve.py")


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
