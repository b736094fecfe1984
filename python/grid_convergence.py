#!/usr/bin/python3
"""Grid-convergence study of MODEL §7: the same run on grids n, 2n, 4n with the kernel width c
fixed in Å (grid.kernel_width = 1, 2, 4), and the discrete L² norms of the velocity differences
between successive grids at the end time.

    /usr/bin/python3 python/grid_convergence.py                  # 64³/128³/256³, 0.5 µs (long)
    /usr/bin/python3 python/grid_convergence.py --cheap          # 32³/64³/128³, 0.05 µs (minutes)
    /usr/bin/python3 python/grid_convergence.py --grids 16,32,64 --t-end-us 0.02 --base-pairs 100 \\
        --box-A 200 -o runs/conv

Each run writes its final fluid velocity (output.fluid_velocity = true -> DIR/velocity.npy,
shape (3, n, n, n), Å/ns; grid point (i, j, k) at (i, j, k) h). The fine velocity is restricted to
the coarse grid's points (every 2nd point: coarse x_i = i h = fine x_{2i}), and for each pair

    e(n, 2n) = sqrt( h_n³ Σ_{coarse points} |R u_{2n} − u_n|² )          Å/ns · Å^{3/2}

is printed with e / ||u_{2n}|| and the ratio e(n, 2n) / e(2n, 4n) ≈ 2^p (p = 1: first order).
Runs whose velocity.npy already exists are reused (delete the directory to recompute).
"""
import argparse
import json
import math
import os
import subprocess
import sys

import numpy as np


def run_one(args, n, m, out):
    vel = os.path.join(out, "velocity.npy")
    if os.path.exists(vel) and not args.rerun:
        print(f"grid_convergence: {n}³ (kernel_width {m}): reusing {vel}", flush=True)
        return vel
    cmd = [args.ibrod, "run"]
    if args.config:
        cmd.append(args.config)
    sets = {
        "grid.n": n,
        "grid.kernel_width": m,
        "time.t_end_us": args.t_end_us,
        "time.dt_ns": args.dt_ns,
        "time.stop_kinetic_kT": 0,
        "output.fluid_velocity": "true",
        "output.frame_every_steps": 0,
        "run.fftw_measure": "false",
    }
    if args.box_A:
        sets["grid.box_A"] = args.box_A
    if args.base_pairs:
        sets["rod.base_pairs"] = args.base_pairs
    if args.threads:
        sets["run.threads"] = args.threads
    for k, v in sets.items():
        cmd += ["--set", f"{k}={v}"]
    for s in args.set or []:
        cmd += ["--set", s]
    cmd += ["-o", out, "--overwrite"]
    print("grid_convergence: " + " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    if not os.path.exists(vel):
        sys.exit(f"grid_convergence: {vel} was not written (is output.fluid_velocity wired in "
                 "`ibrod run`? see docs/sweeps.md)")
    return vel


def l2(u, h):
    """Discrete L² norm sqrt(h³ Σ |u|²) of a (3, n, n, n) field."""
    return math.sqrt(h ** 3 * float(np.sum(u * u)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ibrod", default="./build/app/ibrod", help="the ibrod binary")
    ap.add_argument("--config", help="base config (default: ibrod's built-in reference run)")
    ap.add_argument("--grids", default="64,128,256",
                    help="comma-separated grid sizes, each twice the previous")
    ap.add_argument("--cheap", action="store_true",
                    help="32,64,128 and --t-end-us 0.05 (unless given)")
    ap.add_argument("--t-end-us", type=float, default=None, help="end time, µs (default 0.5)")
    ap.add_argument("--dt-ns", type=float, default=0.1, help="time step, ns (the same on all grids)")
    ap.add_argument("--box-A", type=float, default=None, help="box edge, Å (default: config's)")
    ap.add_argument("--base-pairs", type=int, default=None, help="rod points (default: config's)")
    ap.add_argument("--threads", type=int, default=0, help="run.threads (0: all cores)")
    ap.add_argument("--set", action="append", help="extra section.key=value for every run")
    ap.add_argument("--rerun", action="store_true", help="recompute runs that exist")
    ap.add_argument("-o", "--output", default="runs/grid_convergence", help="output directory")
    args = ap.parse_args()
    if args.cheap and args.grids == "64,128,256":
        args.grids = "32,64,128"
    if args.t_end_us is None:
        args.t_end_us = 0.05 if args.cheap else 0.5
    grids = [int(g) for g in args.grids.split(",")]
    if len(grids) < 2 or any(b != 2 * a for a, b in zip(grids, grids[1:])):
        sys.exit("grid_convergence: --grids must be at least two sizes, each twice the previous")

    os.makedirs(args.output, exist_ok=True)
    fields = []
    for i, n in enumerate(grids):
        m = 2 ** i  # c = m h fixed in Å
        vel = run_one(args, n, m, os.path.join(args.output, f"n{n}"))
        u = np.load(vel)
        if u.shape != (3, n, n, n):
            sys.exit(f"grid_convergence: {vel} has shape {u.shape}, expected (3, {n}, {n}, {n})")
        with open(os.path.join(args.output, f"n{n}", "config.toml")) as f:
            box = next(float(l.split("=")[1]) for l in f if l.strip().startswith("box_A"))
        fields.append((n, box / n, u))

    rows = []
    print(f"\n{'grids':>12} {'e = ||R u_2n - u_n||':>22} {'e / ||u_2n||':>14} {'ratio':>8} {'order':>7}")
    prev = None
    for (n, h, u), (n2, _, u2) in zip(fields, fields[1:]):
        r = u2[:, ::2, ::2, ::2]  # fine values at the coarse points
        e = l2(r - u, h)
        rel = e / max(l2(r, h), 1e-300)
        ratio = prev / e if prev is not None and e > 0 else None
        order = math.log2(ratio) if ratio and ratio > 0 else None
        rows.append({"n": n, "n_fine": n2, "h_A": h, "error": e, "relative_error": rel,
                     "ratio_to_previous": ratio, "order": order})
        print(f"{f'{n}/{n2}':>12} {e:22.6e} {rel:14.4e} "
              f"{'' if ratio is None else f'{ratio:8.3f}':>8} {'' if order is None else f'{order:7.3f}':>7}")
        prev = e
    result = {"grids": grids, "kernel_widths": [2 ** i for i in range(len(grids))],
              "t_end_us": args.t_end_us, "dt_ns": args.dt_ns, "norm": "sqrt(h^3 sum |du|^2), Å/ns Å^1.5",
              "pairs": rows}
    path = os.path.join(args.output, "grid_convergence.json")
    with open(path, "w") as f:
        json.dump(result, f, indent=2)
    print(f"\ngrid_convergence: ratio ≈ 2 means first order (MODEL §7); written {path}")


if __name__ == "__main__":
    main()
