#!/usr/bin/env python3
"""The Einstein relation of docs/thermal.md: the centroid diffusion coefficient of a ring in
thermal runs against kT times its mobility from deterministic runs pulled by external.force_pN.

    python3 python/thermal_einstein.py --pull-x DIR --pull-z DIR --force-pN F \
        --thermal DIR [DIR ...] [--lags 10 20 50] [--figure docs/figures/thermal_einstein.png]

Each run directory needs trajectory.h5md (frames). The pulls: the ring in the xy plane pulled along
x (edgewise) and along z (broadside); mobility = slope of the centroid / F. The thermal runs: D(τ)
= ⟨|Δc(τ)|²⟩ / (6τ) over non-overlapping windows of each run, averaged over the runs; its error
bar is the standard error over those independent windows (runs × windows).
"""
import argparse
import json
import os

import h5py
import numpy as np

KB = 1.380649e-16 * 1e16  # g Å² s⁻² K⁻¹


def trajectory(run):
    """run/trajectory.h5md, or an older run's trajectory.h5."""
    old = os.path.join(run, "trajectory.h5")
    new = os.path.join(run, "trajectory.h5md")
    return old if os.path.exists(old) and not os.path.exists(new) else new


def centroids(run):
    with h5py.File(trajectory(run), "r") as f:
        g = f["particles"]
        name = list(g.keys())[0]
        pos = g[name]["position"]["value"][:]
        t = g[name]["position"]["time"][:]
        unit = g[name]["position"]["time"].attrs.get("unit")
    if isinstance(unit, bytes):
        unit = unit.decode()
    scale = {"ns": 1e-9, "us": 1e-6, "µs": 1e-6, "s": 1.0}[str(unit)]
    return t * scale, pos.mean(axis=1)


def temperature(run):
    with open(run + "/summary.json") as f:
        return json.load(f)["temperature_K"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pull-x", required=True)
    ap.add_argument("--pull-z", required=True)
    ap.add_argument("--force-pN", type=float, required=True)
    ap.add_argument("--thermal", nargs="+", required=True)
    ap.add_argument("--lags", type=int, nargs="+", default=[10, 20, 50, 100])
    ap.add_argument("--skip", type=int, default=5, help="frames of the pulls' start-up to skip")
    ap.add_argument("--figure")
    a = ap.parse_args()

    F = a.force_pN * 10.0  # pN → g Å s⁻²
    mob = []
    for run, d in ((a.pull_x, 0), (a.pull_z, 2)):
        t, c = centroids(run)
        mob.append(np.polyfit(t[a.skip:], c[a.skip:, d], 1)[0] / F)  # s/g
    kT = KB * temperature(a.thermal[0])
    M_mean = (2 * mob[0] + mob[1]) / 3  # the ring's orientation-averaged mobility
    D_pred = kT * M_mean * 1e-9  # Å²/ns
    print(f"mobility edgewise {mob[0]:.4g} s/g, broadside {mob[1]:.4g} s/g")
    print(f"kT × mean mobility = {D_pred:.4g} Å²/ns")

    rows = []
    for lag in a.lags:
        samples = []
        for run in a.thermal:
            t, c = centroids(run)
            dt = t[1] - t[0]
            m = (len(c) - 1) // lag
            dc = c[lag : m * lag + 1 : lag] - c[0 : (m - 1) * lag + 1 : lag]
            samples.extend((dc**2).sum(axis=1) / (6 * lag * dt) * 1e-9)  # Å²/ns
        s = np.array(samples)
        D, se = s.mean(), s.std(ddof=1) / np.sqrt(len(s))
        rows.append((lag, lag * dt * 1e9, D, se, len(s)))
        print(f"lag {lag} frames ({lag * dt * 1e9:.3g} ns): D = {D:.4g} ± {se:.2g} Å²/ns "
              f"({len(s)} windows), D / (kT M) = {D / D_pred:.3f} ± {se / D_pred:.3f}")
    if a.figure:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        r = np.array(rows)
        fig, ax = plt.subplots(figsize=(5, 3.4))
        ax.errorbar(r[:, 1], r[:, 2], yerr=r[:, 3], fmt="o", label="thermal runs: ⟨|Δc|²⟩/(6τ)")
        ax.axhline(D_pred, color="k", ls="--", label="kT × mobility (pulled, deterministic)")
        ax.set_xscale("log")
        ax.set_xlabel("lag τ (ns)")
        ax.set_ylabel("D (Å²/ns)")
        ax.set_ylim(0, 1.5 * D_pred)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.figure, dpi=120)


if __name__ == "__main__":
    main()
