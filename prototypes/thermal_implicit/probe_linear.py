#!/usr/bin/env python3
"""Issue 28: the implicit step's nonlinear evolution from thermal amplitudes against the linear
model (docs/thermal.md, "The implicit step with noise"). DIR holds dump_linear's matrices at the
start state (M, Mloc, K_*) and probe_steps' traj.bin/energies.csv from the same state and config.
For each sample: the displacement after the last noisy step, δ₀, and the deterministic steps that
follow, δ_k (nonlinear, the code) against Bᵏ δ₀ (linear, B = I − Δt A M K): the energies
(E − E(start) of the code; ½ δᵀ K_part δ of the nonlinear δ and of Bᵏ δ₀), in units of
equipartition, and |δ_k − Bᵏ δ₀| / |Bᵏ δ₀| (positions and rotations apart).

    probe_linear.py DIR --dt-ns 1 --noisy 1 --det 10 --samples 4
"""
import argparse
import numpy as np


def load(d, name, N):
    return np.fromfile(f"{d}/{name}.bin").reshape(N, N, order="F")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--dt-ns", type=float, required=True)
    ap.add_argument("--noisy", type=int, required=True)
    ap.add_argument("--det", type=int, required=True)
    ap.add_argument("--samples", type=int, default=1)
    ap.add_argument("--hessian", action="store_true", help="B with the full Hessian H.bin")
    a = ap.parse_args()
    n, ds, kT, mt, mr = np.loadtxt(f"{a.dir}/info.txt")
    n = int(n)
    N = 6 * n
    M = load(a.dir, "M", N)
    M = 0.5 * (M + M.T)
    Ml = load(a.dir, "Mloc", N)
    parts = {p: load(a.dir, "K_" + p, N) for p in ("stretch", "bend", "twist")}
    terms = {"stretch": 3 * n, "bend": 2 * n, "twist": n}
    K = sum(parts.values())
    H = 0.5 * (load(a.dir, "H", N) + load(a.dir, "H", N).T) if a.hessian else K
    dt = a.dt_ns * 1e-9
    A = np.linalg.inv(np.eye(N) + dt * Ml @ K)
    B = np.eye(N) - dt * A @ M @ H
    L = a.noisy + a.det + 1
    T = np.fromfile(f"{a.dir}/traj.bin").reshape(N, -1, order="F")
    E = np.genfromtxt(f"{a.dir}/energies.csv", delimiter=",", names=True)
    t = np.arange(N) % 6 < 3

    def en(d, p):
        return 0.5 * d @ parts[p] @ d / (0.5 * terms[p] * kT)

    for j in range(a.samples):
        print(f"sample {j}: step  code E (stretch bend twist) | ½δKδ of code δ | ½δKδ of Bᵏδ₀ |"
              f" rel. diff pos rot")
        d = T[:, j * L + a.noisy].copy()
        for i in range(a.noisy, L):
            dc = T[:, j * L + i]
            row = E[j * L + i]
            ce = " ".join(f"{row[p]:7.3f}" for p in parts)
            le = " ".join(f"{en(dc, p):7.3f}" for p in parts)
            me = " ".join(f"{en(d, p):7.3f}" for p in parts)
            rp = np.linalg.norm((dc - d)[t]) / max(np.linalg.norm(d[t]), 1e-30)
            rr = np.linalg.norm((dc - d)[~t]) / max(np.linalg.norm(d[~t]), 1e-30)
            print(f"  {i:3d}  {ce} | {le} | {me} | {rp:.3f} {rr:.3f}")
            d = B @ d


if __name__ == "__main__":
    main()
