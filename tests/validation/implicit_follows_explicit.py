#!/usr/bin/env python3
"""The implicit scheme against the explicit one on a path-sensitive reference cell (issue 24,
docs/large_dt.md "A local mobility with the kernel's null space"): runs the cell's config with the
explicit scheme (0.1 ns) and with the implicit one (the kernel-overlap local mobility, ROS2 with
error control, the 4.4 ns cap, rows every 0.2 µs and frames every 1 µs) to T µs, side by side,
then `ibrod compare EXPLICIT IMPLICIT --max-dwr 0.1 --max-final-de 0.5`: exit 1 when the writhe
parts by more than 0.1, E_total at T by more than 0.5 kT, or a frame's shape class or loops differ
outside 0.5 µs of a change. Measured on (5, 0.1 M) to 20 µs: max |dWr| 0.053, final dE 0.22 kT,
no shape mismatch; ~17 min explicit and ~5 min implicit on one core each.

With --path the implicit run adds the path settings of docs/large_dt.md §12 (ROS2's stages by
GMRES on the true mobility to 1e-3, the error tolerance 1e-3 Å); measured there on (6, 0.1 M) to
20 µs: max |dWr| 0.0021, against 0.099 with the settings above — the validation test runs that
cell with --path --max-dwr 0.02 (~25 min explicit, ~15 min implicit on one core each).

    /usr/bin/python3 tests/validation/implicit_follows_explicit.py ./build/app/ibrod \
        [--cell examples/reference/dlk5_cs0.1.toml] [--t-end-us 20] [--keep DIR] \
        [--path] [--max-dwr 0.1] [--max-final-de 0.5]
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ibrod")
    ap.add_argument("--cell", default=os.path.join(HERE, "..", "..", "examples", "reference",
                                                   "dlk5_cs0.1.toml"))
    ap.add_argument("--t-end-us", type=float, default=20.0)
    ap.add_argument("--keep", help="keep the two runs in this directory")
    ap.add_argument("--path", action="store_true",
                    help="the path settings of docs/large_dt.md §12 (GMRES on each ROS2 stage, "
                         "error tolerance 1e-3 Å)")
    ap.add_argument("--max-dwr", type=float, default=0.1, help="largest max |dWr| allowed")
    ap.add_argument("--max-final-de", type=float, default=0.5,
                    help="largest |dE_total| at the end allowed, kT")
    a = ap.parse_args()
    work = a.keep or tempfile.mkdtemp(prefix="ibrod-follow-")
    os.makedirs(work, exist_ok=True)
    common = ["--set", f"time.t_end_us={a.t_end_us}", "--set", "run.threads=1"]
    implicit = ["--set", 'time.scheme="implicit"', "--set", "time.dt_ns=4.4", "--set",
                'time.implicit_local_mobility="overlap"', "--set", "time.implicit_order=2",
                "--set", "output.every_us=0.2", "--set", "output.frame_every_us=1"]
    if a.path:
        implicit += ["--set", "time.implicit_krylov_iterations=3", "--set",
                     "time.implicit_krylov_tol=1e-3", "--set", "time.error_tolerance_A=0.001"]
    runs = {"explicit": [], "implicit": implicit}
    procs = {}
    for name, extra in runs.items():
        out = os.path.join(work, name)
        log = open(os.path.join(work, name + ".log"), "w")
        procs[name] = subprocess.Popen([a.ibrod, "run", a.cell, "-o", out, "--overwrite"] +
                                       common + extra, stdout=log, stderr=subprocess.STDOUT)
    failed = [n for n, p in procs.items() if p.wait() != 0]
    if failed:
        print("run failed:", ", ".join(failed), "(logs in", work + ")")
        return 1
    r = subprocess.run([a.ibrod, "compare", os.path.join(work, "explicit"),
                        os.path.join(work, "implicit"), "--max-dwr", str(a.max_dwr),
                        "--max-final-de", str(a.max_final_de)], capture_output=True, text=True)
    print(r.stdout, end="")
    print(r.stderr, end="", file=sys.stderr)
    if not a.keep and r.returncode == 0:
        shutil.rmtree(work, ignore_errors=True)
    return r.returncode


if __name__ == "__main__":
    sys.exit(main())
