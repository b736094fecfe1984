#!/usr/bin/env python3
"""Kill/resume trials ([no-data-lost]): runs the small integration configuration once without
interruption, then N times per signal (SIGKILL, SIGTERM, SIGINT) stopped at a random moment and
continued with `ibrod run --resume` until it finishes, and compares timeseries.csv and
final_state.csv byte for byte with the uninterrupted run. Prints one table row per signal and
exits 1 if any trial differs or fails.

    /usr/bin/python3 tests/validation/kill_resume_trials.py ./build/app/ibrod [--trials 10] [--seed 1]
        [--thermal-implicit] [--max-delay 1.5]

--thermal-implicit runs the same ring with thermal noise in the implicit scheme (the overlap
M_loc, a fixed Δt of 0.25 ns, 0.2 µs: issue 28's "bitwise identity for a seed across a kill and
resume"), whose noise is keyed by the seed and the step and whose filter is made again at every
checkpoint, so a resumed run must give the uninterrupted one's bytes as well.
"""
import argparse
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

CONFIG = """[grid]
n = 16
box_A = 200.0
[rod]
base_pairs = 100
excess_link = 2
[time]
dt_ns = 0.1
t_end_us = 0.2
[output]
every_steps = 20
frame_every_steps = 40
checkpoint_every_steps = 50
[run]
threads = 1
fftw_measure = false
"""


THERMAL_IMPLICIT = """[solvent]
thermal = true
"""
THERMAL_IMPLICIT_TIME = """scheme = "implicit"
implicit_local_mobility = "overlap"
"""


def thermal_implicit(config):
    """The configuration with noise in the implicit scheme at a fixed 0.25 ns."""
    config = config.replace("dt_ns = 0.1\n", "dt_ns = 0.25\n" + THERMAL_IMPLICIT_TIME)
    config = config.replace("every_steps = 20\n", "every_steps = 8\n")
    config = config.replace("frame_every_steps = 40\n", "frame_every_steps = 16\n")
    config = config.replace("checkpoint_every_steps = 50\n", "checkpoint_every_steps = 20\n")
    config = config.replace("[run]\n", "[run]\nseed = 7\n")
    return config + THERMAL_IMPLICIT


def run_to_end(binary, cfg, out, log):
    with open(log, "ab") as f:
        return subprocess.run([binary, "run", cfg, "-o", out], stdout=f, stderr=f).returncode


def trial(binary, cfg, out, sig, rng, log, max_delay):
    """Start, stop with `sig` after a random delay, resume until done. Returns (ok, stops)."""
    stops = 0
    with open(log, "ab") as f:
        p = subprocess.Popen([binary, "run", cfg, "-o", out], stdout=f, stderr=f)
        time.sleep(rng.uniform(0.05, max_delay))
        if p.poll() is None:
            p.send_signal(sig)
            stops += 1
        rc = p.wait()
        for _ in range(20):
            if rc == 0 and os.path.exists(os.path.join(out, "summary.json")):
                break
            if not os.path.exists(os.path.join(out, "checkpoint.bin")):
                args = [binary, "run", cfg, "-o", out, "--overwrite"]
            else:
                args = [binary, "run", "--resume", out]
            rc = subprocess.run(args, stdout=f, stderr=f).returncode
    return rc == 0, stops


def same(a, b, name):
    with open(os.path.join(a, name), "rb") as x, open(os.path.join(b, name), "rb") as y:
        return x.read() == y.read()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("--trials", type=int, default=10)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--thermal-implicit", action="store_true")
    ap.add_argument("--max-delay", type=float, default=1.5,
                    help="latest moment of the signal after the start, s")
    a = ap.parse_args()
    rng = random.Random(a.seed)
    tmp = tempfile.mkdtemp(prefix="ibrod_kill_resume_")
    cfg = os.path.join(tmp, "c.toml")
    with open(cfg, "w") as f:
        f.write(thermal_implicit(CONFIG) if a.thermal_implicit else CONFIG)
    ref = os.path.join(tmp, "ref")
    if run_to_end(a.binary, cfg, ref, os.path.join(tmp, "ref.log")) != 0:
        print("the uninterrupted run failed", file=sys.stderr)
        return 1
    bad = 0
    print("signal   trials  stopped  identical  different  failed")
    for sig in (signal.SIGKILL, signal.SIGTERM, signal.SIGINT):
        stopped = identical = different = failed = 0
        for i in range(a.trials):
            out = os.path.join(tmp, f"{sig.name}_{i}")
            ok, stops = trial(a.binary, cfg, out, sig, rng, out + ".log", a.max_delay)
            stopped += stops > 0
            if not ok:
                failed += 1
            elif same(ref, out, "timeseries.csv") and same(ref, out, "final_state.csv"):
                identical += 1
            else:
                different += 1
            shutil.rmtree(out, ignore_errors=True)
        bad += different + failed
        print(f"{sig.name:8s} {a.trials:6d}  {stopped:7d}  {identical:9d}  {different:9d}  {failed:6d}")
    shutil.rmtree(tmp, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
