#!/usr/bin/env python3
"""Kill/resume trials ([no-data-lost]): runs the small integration configuration once without
interruption, then N times per signal (SIGKILL, SIGTERM, SIGINT) stopped at a random moment and
continued with `ibrod run --resume` until it finishes, and compares timeseries.csv and
final_state.csv byte for byte with the uninterrupted run. Prints one table row per signal and
exits 1 if any trial differs or fails.

    /usr/bin/python3 tests/validation/kill_resume_trials.py ./build/app/ibrod [--trials 10] [--seed 1]
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


def run_to_end(binary, cfg, out, log):
    with open(log, "ab") as f:
        return subprocess.run([binary, "run", cfg, "-o", out], stdout=f, stderr=f).returncode


def trial(binary, cfg, out, sig, rng, log):
    """Start, stop with `sig` after a random delay, resume until done. Returns (ok, stops)."""
    stops = 0
    with open(log, "ab") as f:
        p = subprocess.Popen([binary, "run", cfg, "-o", out], stdout=f, stderr=f)
        time.sleep(rng.uniform(0.05, 1.5))
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
    a = ap.parse_args()
    rng = random.Random(a.seed)
    tmp = tempfile.mkdtemp(prefix="ibrod_kill_resume_")
    cfg = os.path.join(tmp, "c.toml")
    with open(cfg, "w") as f:
        f.write(CONFIG)
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
            ok, stops = trial(a.binary, cfg, out, sig, rng, out + ".log")
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
