#!/usr/bin/env python3
"""Cost per step of the Python module against `ibrod run`, on the same configuration
(docs/python.md). Runs the CLI and Simulation(cfg, output=DIR).run() in turn, REPEATS times each,
both writing a run directory with the same FFTW plans (FFTW_ESTIMATE: measured plans would
differ between the processes on a busy machine), and prints the ms/step each reports (the same clock: the loop of
driver::Run), the fastest of each and their ratio.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_vs_cli.py \
        [--binary build/app/ibrod] [--grid 32] [--steps 2000] [--repeats 3] [--threads 1]
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile

import ibrod


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", default="build/app/ibrod")
    ap.add_argument("--grid", type=int, default=32)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args()

    cfg = ibrod.Config()
    cfg.update({"grid.n": a.grid, "grid.box_A": 300, "rod.base_pairs": 200, "rod.excess_link": 2,
                "time.dt_ns": 0.1, "time.t_end_us": a.steps * 1e-4,
                "output.every_steps": 500, "run.threads": a.threads,
                "run.fftw_measure": False})  # the same FFTW plans in both processes
    cli, py = [], []
    with tempfile.TemporaryDirectory() as tmp:
        toml = os.path.join(tmp, "run.toml")
        with open(toml, "w") as f:
            f.write(cfg.to_toml())
        for r in range(a.repeats):
            out = os.path.join(tmp, f"cli{r}")
            subprocess.run([a.binary, "run", toml, "-o", out], check=True,
                           stdout=subprocess.DEVNULL, stdin=subprocess.DEVNULL)
            with open(os.path.join(out, "summary.json")) as f:
                cli.append(json.load(f)["ms_per_step"])
            res = ibrod.Simulation(cfg, output=os.path.join(tmp, f"py{r}")).run()
            py.append(res["ms_per_step"])
            print(f"repeat {r}: cli {cli[-1]:.4f} ms/step, python {py[-1]:.4f} ms/step", flush=True)
    print(f"cli     min {min(cli):.4f}  median {statistics.median(cli):.4f} ms/step")
    print(f"python  min {min(py):.4f}  median {statistics.median(py):.4f} ms/step")
    print(f"ratio python/cli (min) {min(py) / min(cli):.4f}")


if __name__ == "__main__":
    main()
