#!/usr/bin/env python3
"""Issue 16, the equilibrium check (docs/thermal.md, "Writhe and shape against Monte Carlo"):
the distribution of writhe, radius of gyration and the lowest Fourier modes of the ring's shape
from thermal IB runs against a Monte-Carlo sample of the same energy (mc_ring).

    /usr/bin/python3 prototypes/thermal/compare.py --ib RUN [RUN ...] --mc MC.csv \
        [--label 'ΔLk = 0'] [--skip-us 0.1] [--ib2 ... --mc2 ... --label2 ...] \
        [--figure docs/figures/thermal_mc.png]

IB: writhe and energies from timeseries.csv, shapes from the frames of trajectory.h5md, the first
--skip-us of each run dropped (equilibration from the circle). Error bars: each series is cut into
blocks of at least 10 integrated autocorrelation times (τ_int estimated from the series itself,
Sokal's window c = 6), the mean and the standard deviation computed per block, and their errors
are the standard errors over the blocks (of all runs of a group pooled). The MC sample is treated
the same way, its time unit the row (10 sweeps).
"""
import argparse
import csv
import os

import h5py
import numpy as np

STATS = ["writhe", "rg_A", "P2_A2", "P3_A2"]
ENERGIES = ["E_bend_kT", "E_twist_kT", "E_stretch_kT", "E_pairs_kT"]


def trajectory(run):
    """run/trajectory.h5md, or an older run's trajectory.h5."""
    old = os.path.join(run, "trajectory.h5")
    new = os.path.join(run, "trajectory.h5md")
    return old if os.path.exists(old) and not os.path.exists(new) else new


def shape_stats(pos):
    """pos: (frames, n, 3) -> dict of per-frame rg (Å) and Fourier powers P_m (Å²)."""
    c = pos - pos.mean(axis=1, keepdims=True)
    n = pos.shape[1]
    out = {"rg_A": np.sqrt((c**2).sum(axis=2).mean(axis=1))}
    h = np.fft.fft(pos, axis=1) / n  # X̂_m = (1/n) Σ X_k e^{−2πimk/n}
    for m in (1, 2, 3, 4):
        out[f"P{m}_A2"] = (np.abs(h[:, m, :]) ** 2).sum(axis=1)
    return out


def read_ib(run, skip_us):
    rows = list(csv.DictReader(open(run + "/timeseries.csv")))
    t = np.array([float(r["time_us"]) for r in rows])
    keep = t >= skip_us
    ser = {"writhe": np.array([float(r["writhe"]) for r in rows])[keep]}
    for k in ("E_bend_kT", "E_twist_kT", "E_stretch_kT"):
        ser[k] = np.array([float(r[k]) for r in rows])[keep]
    ser["E_pairs_kT"] = np.array(
        [float(r["E_electro_kT"]) + float(r["E_steric_kT"]) for r in rows])[keep]
    ser["link"] = np.array([float(r["link"]) for r in rows])[keep]
    dt_row = t[1] - t[0]
    with h5py.File(trajectory(run), "r") as f:
        g = f["particles/rod/position"]
        pos = g["value"][:]
        tf = g["time"][:]
    scale = 1e-3  # frame times are in ns
    keepf = tf * scale >= skip_us
    ser.update(shape_stats(pos[keepf]))
    dt = {k: dt_row for k in ser}
    for k in ("rg_A", "P1_A2", "P2_A2", "P3_A2", "P4_A2"):
        dt[k] = (tf[1] - tf[0]) * scale
    return ser, dt


def read_mc(path):
    rows = list(csv.DictReader(open(path)))
    ser = {k: np.array([float(r[k]) for r in rows])
           for k in ("writhe", "link", "E_bend_kT", "E_twist_kT", "E_stretch_kT", "E_pairs_kT")}
    ser["rg_A"] = np.sqrt(np.array([float(r["rg2_A2"]) for r in rows]))
    for m in (1, 2, 3, 4):
        ser[f"P{m}_A2"] = np.array([float(r[f"P{m}_A2"]) for r in rows])
    sweeps = float(rows[1]["sweep"]) - float(rows[0]["sweep"])
    return ser, {k: sweeps for k in ser}


def tau_int(x, c=6.0):
    """integrated autocorrelation time in samples (Sokal's automatic window)"""
    x = np.asarray(x) - np.mean(x)
    n = len(x)
    f = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n]
    acf /= acf[0]
    tau = 0.5
    for w in range(1, n):
        tau += acf[w]
        if w >= c * tau:
            break
    return max(tau, 0.5)


def blocks(series_list, min_block):
    """means and stds of blocks of length ≥ min_block (samples) from each series"""
    means, stds = [], []
    for x in series_list:
        nb = len(x) // min_block
        for b in range(nb):
            y = x[b * len(x) // nb:(b + 1) * len(x) // nb]
            means.append(y.mean())
            stds.append(y.std())
    return np.array(means), np.array(stds)


def summarize(series_list, dts):
    """mean, std and their errors of a group of series, τ_int (in the series' time unit)"""
    taus = [tau_int(x) for x in series_list]
    tau = max(taus)
    block = max(int(np.ceil(10 * tau)), 2)
    m, s = blocks(series_list, block)
    allx = np.concatenate(series_list)
    nb = len(m)
    return {
        "mean": allx.mean(), "mean_err": m.std(ddof=1) / np.sqrt(nb) if nb > 1 else np.nan,
        "std": allx.std(), "std_err": s.std(ddof=1) / np.sqrt(nb) if nb > 1 else np.nan,
        "tau": tau * dts[0], "n_indep": len(allx) / (2 * tau), "blocks": nb,
    }


def group(ib_runs, mc_path, skip_us):
    ib = [read_ib(r, skip_us) for r in ib_runs]
    mc = read_mc(mc_path)
    res = {}
    for k in STATS + ["P1_A2", "P4_A2"] + ENERGIES:
        res[k] = {
            "ib": summarize([s[k] for s, _ in ib], [d[k] for _, d in ib]),
            "mc": summarize([mc[0][k]], [mc[1][k]]),
        }
    lk_ib = np.concatenate([s["link"] for s, _ in ib])
    return res, ib, mc, (lk_ib.min(), lk_ib.max(), mc[0]["link"].min(), mc[0]["link"].max())


def print_group(label, res, lk):
    print(f"## {label}")
    print(f"Lk over the IB runs {lk[0]:.6f} … {lk[1]:.6f}; over the MC sample {lk[2]:.6f} … {lk[3]:.6f}")
    print("| statistic | IB mean | MC mean | IB std | MC std | (IB − MC)/σ mean | (IB − MC)/σ std "
          "| IB τ_int (µs) | IB indep. samples | MC τ_int (sweeps) | MC indep. samples |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for k, r in res.items():
        a, b = r["ib"], r["mc"]
        zm = (a["mean"] - b["mean"]) / np.hypot(a["mean_err"], b["mean_err"])
        zs = (a["std"] - b["std"]) / np.hypot(a["std_err"], b["std_err"])
        print(f"| {k} | {a['mean']:.4g} ± {a['mean_err']:.2g} | {b['mean']:.4g} ± {b['mean_err']:.2g} "
              f"| {a['std']:.4g} ± {a['std_err']:.2g} | {b['std']:.4g} ± {b['std_err']:.2g} "
              f"| {zm:+.1f} | {zs:+.1f} | {a['tau']:.3g} | {a['n_indep']:.0f} | {b['tau']:.3g} "
              f"| {b['n_indep']:.0f} |")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ib", nargs="+", required=True)
    ap.add_argument("--mc", required=True)
    ap.add_argument("--label", default="ΔLk = 0")
    ap.add_argument("--ib2", nargs="+")
    ap.add_argument("--mc2")
    ap.add_argument("--label2", default="ΔLk = 1")
    ap.add_argument("--skip-us", type=float, default=0.1)
    ap.add_argument("--figure")
    ap.add_argument("--title", default="100 bp ring, 0.1 M, 300 K: thermal IB (16³, Δt = 0.1 ns) vs Monte Carlo of the same energy")
    a = ap.parse_args()
    groups = [(a.label, a.ib, a.mc)]
    if a.ib2 and a.mc2:
        groups.append((a.label2, a.ib2, a.mc2))
    data = []
    for label, ib, mc in groups:
        res, ibs, mcs, lk = group(ib, mc, a.skip_us)
        print_group(label, res, lk)
        data.append((label, res, ibs, mcs))
    if a.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        cols = [("writhe", "Wr"), ("rg_A", "radius of gyration (Å)"),
                ("P2_A2", "|X̂₂|² (Å²)"), ("P3_A2", "|X̂₃|² (Å²)")]
        fig, axes = plt.subplots(len(data), len(cols), figsize=(3.2 * len(cols), 2.8 * len(data)),
                                 squeeze=False)
        for row, (label, res, ibs, mcs) in enumerate(data):
            for col, (k, name) in enumerate(cols):
                ax = axes[row][col]
                x_ib = [s[k] for s, _ in ibs]
                allx = np.concatenate(x_ib + [mcs[0][k]])
                lo, hi = np.percentile(allx, [0.2, 99.8])
                edges = np.linspace(lo, hi, 31)
                centers = 0.5 * (edges[1:] + edges[:-1])
                w = edges[1] - edges[0]
                # IB histogram with error bars from blocks of ≥ 10 τ_int
                tau = max(tau_int(x) for x in x_ib)
                blk = max(int(np.ceil(10 * tau)), 2)
                hs = []
                for x in x_ib:
                    nb = len(x) // blk
                    for b in range(nb):
                        y = x[b * len(x) // nb:(b + 1) * len(x) // nb]
                        hs.append(np.histogram(y, edges)[0] / (len(y) * w))
                hs = np.array(hs)
                h_ib = np.histogram(np.concatenate(x_ib), edges)[0] / (len(np.concatenate(x_ib)) * w)
                e_ib = hs.std(axis=0, ddof=1) / np.sqrt(len(hs))
                h_mc = np.histogram(mcs[0][k], edges)[0] / (len(mcs[0][k]) * w)
                ax.step(centers, h_mc, where="mid", color="k", label="Monte Carlo")
                ax.errorbar(centers, h_ib, yerr=e_ib, fmt="o", ms=3, color="C3", label="thermal IB")
                ax.set_xlabel(name)
                if col == 0:
                    ax.set_ylabel(f"{label}\nprobability density")
                    ax.legend(fontsize=7)
        fig.suptitle(a.title,
                     fontsize=9)
        fig.tight_layout()
        fig.savefig(a.figure, dpi=110)
        print("figure:", a.figure)


if __name__ == "__main__":
    main()
