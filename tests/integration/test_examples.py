#!/usr/bin/python3
"""The examples cannot rot silently: every file in examples/ states what to expect and how long it
takes, and reads (`ibrod check`, `ibrod sweep --list`); examples/quickstart.toml, run for its first
1.5 µs, keeps the link, lowers the energy, buckles, and matches the writhe its header states.

Usage: test_examples.py IBROD. Exit status 0 if every check passes; the failures are printed.
Must run with /usr/bin/python3 (numpy from Debian).
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def header(path):
    """The leading comment block of a TOML file, '#' removed."""
    lines = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            if not line.startswith("#"):
                break
            lines.append(line[1:].rstrip("\n"))
    return "\n".join(lines)


def run(ibrod, *args, timeout=300):
    # from the repository root: the examples name their data files by paths from it
    return subprocess.run([ibrod, *args], capture_output=True, text=True, timeout=timeout, cwd=ROOT,
                          stdin=subprocess.DEVNULL, env=dict(os.environ, OMP_WAIT_POLICY="passive"))


def main():
    ibrod = os.path.abspath(sys.argv[1])
    examples = sorted(glob.glob(os.path.join(ROOT, "examples", "**", "*.toml"), recursive=True))
    check(len(examples) >= 20, f"examples found: {len(examples)}")
    for ex in examples:
        name = os.path.relpath(ex, ROOT)
        h = header(ex)
        check(re.search(r"^ *Expected", h, re.M), f"{name}: no 'Expected' section in its header")
        check(re.search(r"^ *Run time:", h, re.M), f"{name}: no 'Run time:' in its header")
        with open(ex, encoding="utf-8") as f:
            is_sweep = "[sweep]" in f.read()
        r = run(ibrod, "sweep", ex, "--list") if is_sweep else run(ibrod, "check", ex)
        check(r.returncode == 0, f"{name}: exit {r.returncode}: {r.stderr}")

    # the quickstart: no warning from check, and its first 1.5 µs as its header states
    qs = os.path.join(ROOT, "examples", "quickstart.toml")
    r = run(ibrod, "check", qs)
    check(r.returncode == 0 and "warning" not in r.stdout, "quickstart: check warns:\n" + r.stdout)
    m = re.search(r"at 1\.5 µs[^:]*: Wr = ([0-9.]+) ± ([0-9.]+)", header(qs))
    check(m is not None, "quickstart: no 'at 1.5 µs ...: Wr = X ± Y' line in its header")
    tmp = tempfile.mkdtemp(prefix="ibrod_examples_")
    try:
        out = os.path.join(tmp, "qs")
        r = run(ibrod, "run", qs, "-o", out, "--set", "time.t_end_us=1.5",
                "--set", "run.fftw_measure=false", "--set", "run.threads=1")
        check(r.returncode == 0, f"quickstart run: exit {r.returncode}: {r.stderr}{r.stdout}")
        if r.returncode == 0:
            d = np.genfromtxt(os.path.join(out, "timeseries.csv"), delimiter=",", names=True)
            check(abs(d["time_us"][-1] - 1.5) < 1e-9, f"quickstart: ends at {d['time_us'][-1]} µs")
            check(np.abs(d["link"] - 6).max() < 1e-9,
                  f"quickstart: Lk drifts by {np.abs(d['link'] - 6).max()}")
            # a gradient flow: the total energy never rises between rows
            rise = np.diff(d["E_total_kT"]).max()
            check(rise <= 1e-6, f"quickstart: E_total rises by {rise} kT between rows")
            # buckling under way: writhe grows over the second half and is well out of plane
            half = d["time_us"] >= 0.75
            check(np.all(np.diff(d["writhe"][half]) > 0), "quickstart: Wr not growing after 0.75 µs")
            if m:
                wr, tol = float(m.group(1)), float(m.group(2))
                check(abs(d["writhe"][-1] - wr) <= tol,
                      f"quickstart: Wr(1.5 µs) = {d['writhe'][-1]:.4f}, header says {wr} ± {tol}")
            check(d["closest_approach_A"].min() > 20, "quickstart: contact before 1.5 µs")
            e0 = re.search(r"first row \(t = 0\):.*E_total = ([0-9.]+) kT", header(qs))
            check(e0 is not None, "quickstart: no 'first row (t = 0): ... E_total = X kT' line")
            if e0:
                check(abs(d["E_total_kT"][0] - float(e0.group(1))) < 0.01,
                      f"quickstart: E_total(0) = {d['E_total_kT'][0]}, header says {e0.group(1)}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all example checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
